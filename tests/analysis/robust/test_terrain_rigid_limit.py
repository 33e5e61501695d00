"""Issue 22 item 4, the last exactness check: the compliant model on a step-down converges to
the hybrid (rigid-ground) model's step-down response as the ground stiffens, as the gait does on
flat ground (docs/studies.md, benchmarks/rigid_limit.py; docs/terrain.md "The step-down in the
rigid limit", study: benchmarks/terrain_rigid_limit.py).

The compliant walker: `Params.paper_steady()` with k_n and d_n = d_n0 (k_n / k_n0)^(4/3) (the
rigid-limit scaling that keeps the stance contact's damping ratio fixed), the ``consistent``
variant (the hybrid model's contact kinematics), rodas4 (rtol 1e-8), from its own period-one
gait, on ``Ground.step(L*/2, -H)``. The hybrid walker: its gait, the floor offset dh = -H at the
first step. The response of each is its step lengths and step times minus its own gait's, over
the first steps after the step-down.
"""
import numpy as np
import pytest

import pdw
from pdw import hybrid as H
from pdw.analysis.robust import robustness as R
from pdw.analysis.robust import robustness_continuous as RC

P0 = pdw.Params.paper_steady()
HEIGHT = 0.003          # a 3 mm step down (half the hybrid gait's largest, 6.1 mm)
N_STEPS = 6
K_N = (1e6, 1e7, 1e8)


def scaled(kn):
    """The rigid-limit family: k_n and d_n = d_n0 (k_n / k_n0)^(4/3)."""
    return P0.replace(k_n=kn, d_n=P0.d_n * (kn / P0.k_n) ** (4 / 3))


def hybrid_response(gait, height, n):
    """(dL (n,), dT (n,)): the hybrid walker's step lengths and step times minus its gait's,
    from the step onto the floor ``height`` lower on (plain `pdw.hybrid.step` calls)."""
    y, Y, T = np.asarray(gait.state, dtype=float), [], []
    for k in range(n):
        res = H.step(y, P0, dh=-height if k == 0 else 0.0)
        assert res["status"] == "ok" and not res["old_foot_down"]
        y = res["y_plus"]
        Y.append(y)
        T.append(res["t_strike"])
    L = R.step_lengths(P0, gait.state, np.array(Y))
    return L - gait.step_length, np.array(T) - gait.period


def compliant_response(params, gait, height, n):
    """The same for the compliant walker on ``Ground.step(L*/2, -height)``."""
    g = pdw.Ground.step(RC.edge_at(gait), -height, width=0.01)
    status, L, T = RC.walk(params, gait, g, n, variant="consistent")
    assert status == "walked" and len(L) >= n
    return L[:n] - gait.step_length, T[:n] - gait.period


@pytest.fixture(scope="module")
def responses():
    gh = H.find_gait(P0)
    ref = hybrid_response(gh, HEIGHT, N_STEPS)
    out, guess = [], gh
    for kn in K_N:
        P = scaled(kn)
        g = pdw.find_gait(P, variant="consistent", guess=guess)
        guess = g
        out.append(compliant_response(P, g, HEIGHT, N_STEPS))
    return ref, out


def test_step_down_response_converges_to_the_hybrid_one_as_the_ground_stiffens(responses):
    (dLh, dTh), comp = responses
    # the response is not trivial: the hybrid walker's steps move by millimetres and 40 ms
    assert np.abs(dLh).max() > 5e-3 and np.abs(dTh).max() > 0.03
    eL = np.array([np.abs(dL - dLh).max() for dL, _ in comp])
    eT = np.array([np.abs(dT - dTh).max() for _, dT in comp])
    # measured (docs/terrain.md): eL 1.35e-3, 4.42e-4, 1.49e-4 m; eT 3.02e-3, 7.49e-4, 3.30e-4 s
    # -- a factor 2.3-4 per decade of k_n, order 0.40-0.60 (the flat gait's is 0.42-0.67)
    for e in (eL, eT):
        ratio = e[:-1] / e[1:]
        assert np.all(ratio > 1.8), e              # monotone, at least ~k^-0.25 per decade
        order = np.log10(e[0] / e[-1]) / np.log10(K_N[-1] / K_N[0])
        assert 0.3 < order < 1.0, (e, order)
    # at the stiffest ground the responses agree to 2 % of the response's size (measured
    # 1.47 % in step length, 0.81 % in step time)
    assert eL[-1] < 0.02 * np.abs(dLh).max(), (eL, np.abs(dLh).max())
    assert eT[-1] < 0.02 * np.abs(dTh).max(), (eT, np.abs(dTh).max())


def test_the_check_can_fail_a_wrong_hybrid_reference(responses):
    """The comparison tells step-down heights 10 % apart: the compliant response at the
    stiffest ground is far nearer the hybrid's at H than at 1.1 H."""
    (dLh, dTh), comp = responses
    gh = H.find_gait(P0)
    dLw, dTw = hybrid_response(gh, 1.1 * HEIGHT, N_STEPS)
    dL, dT = comp[-1]
    assert np.abs(dT - dTw).max() > 5 * np.abs(dT - dTh).max()
    assert np.abs(dL - dLw).max() > 2 * np.abs(dL - dLh).max()
