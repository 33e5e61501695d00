"""Stability regions in two parameters (issue #24 a): Goswami's compass-gait regions in the
issue's axes (slope, b/a) and (slope, m_H/m), from `continue_bifurcation` with a derived second
parameter (``params_of``), checked against a brute-force scan of multipliers."""
import numpy as np
import pytest

import pdw
from pdw import hybrid as H
from pdw.analysis.bifurcation.codim2 import continue_bifurcation
from pdw.analysis.bifurcation.continuation import continue_gait

COMPASS = H.compass_gait_params()
DEG = np.pi / 180


def b_over_a(P, r):
    """Goswami's beta = b/a (b: hip to leg mass, a: leg mass to foot; l = a + b)."""
    return P.replace(c=r / (1.0 + r) * P.l)


def mass_ratio(P, r):
    """Goswami's mu = m_H/m (m: one leg's mass, held)."""
    return P.replace(m_h=r * P.m_l)


@pytest.fixture(scope="module")
def branch():
    return continue_gait(COMPASS, "gamma", 15.0 * DEG, model="hybrid", max_points=400)


def _scan_doubling(P, lo=0.5 * DEG, hi=7.0 * DEG, n=66):
    """The first slope where the period-1 gait's finite-difference multipliers leave the unit
    circle through -1, by a scan of `H.find_gait` over n slopes then bisection to 1e-10 rad.
    Independent of the continuation: Newton shooting and central differences only."""
    def mult(g, guess):
        gt = H.find_gait(P.replace(gamma=g), guess, settle_steps=0)
        return np.min(np.real(gt.multipliers)), gt.state
    state = H.find_gait(P.replace(gamma=lo)).state
    prev = lo
    for g in np.linspace(lo, hi, n)[1:]:
        m, s = mult(g, state)
        if m < -1.0:
            a, b = prev, g
            while b - a > 1e-10:
                c = 0.5 * (a + b)
                mc, sc = mult(c, state)
                if mc < -1.0:
                    b = c
                else:
                    a, state = c, sc
            return 0.5 * (a + b)
        prev, state = g, s
    raise AssertionError("no doubling up to %g deg" % (hi / DEG))


@pytest.mark.parametrize("name, of, start, stop, checks", [
    ("b/a", b_over_a, 1.0, 0.5, [0.6, 0.8]),
    ("b/a", b_over_a, 1.0, 2.0, [1.5]),
    ("m_H/m", mass_ratio, 2.0, 0.5, [1.0]),
    ("m_H/m", mass_ratio, 2.0, 6.0, [4.0]),
])
def test_goswami_doubling_curve_against_a_brute_force_scan(branch, name, of, start, stop,
                                                           checks):
    pd = branch.of_kind("period_doubling")[0]
    cv = continue_bifurcation(pd, name, stop, params_of=of, value=start, at=checks)
    assert cv.parameters == ("gamma", name) and "reached stop" in cv.stop_reason
    assert np.all(np.abs(np.abs(cv.multipliers[:, 0]) - 1.0) < 1e-6)
    for r in checks:
        i = int(np.argmin(np.abs(cv.values[:, 1] - r)))
        assert cv.values[i, 1] == pytest.approx(r, abs=1e-12)
        assert abs(cv.values[i, 0] - _scan_doubling(of(COMPASS, r))) < 1e-6


def test_existence_edge_in_b_over_a_against_one_parameter_ends(branch):
    """The end of the family (the trailing foot stays down, v_old_up -> 0) followed in b/a:
    at b/a = 0.6 it is the end that a one-parameter continuation in the slope locates there,
    and the curve passes the corner where the doubling curve ends (located there)."""
    pd = branch.of_kind("period_doubling")[0]
    dc = continue_bifurcation(pd, "b/a", 0.2, params_of=b_over_a, value=1.0)
    assert "v_old_up" in dc.stop_reason
    (end,) = dc.branch.of_kind("end")                  # located on the doubling curve
    corner = (end.z[-1], end.value)                     # (gamma, b/a)
    (ep,) = branch.of_kind("end")
    cv = continue_bifurcation(ep, "b/a", 0.3, params_of=b_over_a, value=1.0,
                              at=[0.6, corner[1]])
    assert cv.kind == "end" and "reached stop" in cv.stop_reason
    i = int(np.argmin(np.abs(cv.values[:, 1] - 0.6)))
    P = b_over_a(COMPASS, 0.6)
    b = continue_gait(P, "gamma", 20 * DEG, model="hybrid", value=3 * DEG, max_points=400,
                      start=H.find_gait(P.replace(gamma=3 * DEG)).state)
    (e1,) = b.of_kind("end")
    assert abs(e1.value - cv.values[i, 0]) < 1e-6
    assert abs(cv.at(corner[1]) - corner[0]) < 1e-6


def test_params_of_needs_a_start_value_and_a_params(branch):
    pd = branch.of_kind("period_doubling")[0]
    with pytest.raises(pdw.InvalidInputError, match="value="):
        continue_bifurcation(pd, "b/a", 0.5, params_of=b_over_a)
    with pytest.raises(pdw.InvalidInputError, match="params_of must be a callable"):
        continue_bifurcation(pd, "b/a", 0.5, params_of=3, value=1.0)
    with pytest.raises(pdw.InvalidInputError, match="params_of must return"):
        continue_bifurcation(pd, "b/a", 0.5, params_of=lambda P, r: r, value=1.0)


# --- the paper walker on rigid ground (hybrid): its region in (k_hip, d_hip) ----------------

def _walk(y, P, n=400):
    """400 steps of the hybrid map from y: 'falls', 'settles' (last step moves < 1e-8) or
    'walks' (on, unsettled)."""
    prev = y
    for _ in range(n):
        try:
            prev, y = y, H.step_map(y, P)
        except pdw.FellError:
            return "falls"
    return "settles" if np.max(np.abs(y - prev)) < 1e-8 else "walks"


def test_paper_walker_fold_curve_in_k_hip_against_long_walks():
    """The d_hip fold of paper_steady on rigid ground followed in k_hip: at k_hip = 0.5 and
    2.5, a walker started on the family's gait 1 % below the fold's d_hip settles on a gait
    in 400 steps, and 1 % above it falls (independent: the step map only)."""
    P = pdw.Params.paper_steady()
    b = continue_gait(P, "d_hip", 0.1, model="hybrid")
    (fold,) = b.of_kind("fold")
    cv = continue_bifurcation(fold, "k_hip", 3.0, at=[2.5])
    lo = continue_bifurcation(fold, "k_hip", 0.0, at=[0.5])
    for c, k in ((lo, 0.5), (cv, 2.5)):
        i = int(np.argmin(np.abs(c.values[:, 1] - k)))
        d_fold = c.values[i, 0]
        Q = P.replace(k_hip=k, d_hip=0.005)
        y0 = H.find_gait(Q).state
        assert _walk(y0, Q.replace(d_hip=0.99 * d_fold)) == "settles"
        assert _walk(y0, Q.replace(d_hip=1.01 * d_fold)) == "falls"


def test_paper_walker_doubling_at_no_hip_spring_against_long_walks():
    """At k_hip = 0 the family (continued from paper_steady) doubles at d_hip = 0.0067; the
    doubling curve starts there at k_hip = 0 (one-sided difference at the field's edge) and
    closes at d_hip -> 0 near k_hip = 0.12. Long walks: at k_hip = 0.05 the walker settles on
    the period-1 gait above the curve and walks on unsettled (period 2) below it."""
    P = pdw.Params.paper_steady()
    bk = continue_gait(P, "k_hip", 0.0, model="hybrid")
    b0 = continue_gait(P.replace(k_hip=0.0), "d_hip", 0.0, model="hybrid", start=bk.state[-1])
    (pd,) = b0.of_kind("period_doubling")
    cv = continue_bifurcation(pd, "k_hip", 1.0, at=[0.05])
    assert cv.values[0, 1] == 0.0 and 0.10 < cv.values[-1, 1] < 0.13
    i = int(np.argmin(np.abs(cv.values[:, 1] - 0.05)))
    d_pd = cv.values[i, 0]
    y0 = bk.state[int(np.argmin(np.abs(bk.values - 0.05)))]
    Q = P.replace(k_hip=0.05)
    assert _walk(y0, Q.replace(d_hip=d_pd + 5e-4), n=2000) == "settles"
    assert _walk(y0, Q.replace(d_hip=d_pd - 5e-4), n=2000) == "walks"
