"""Every path of the ensemble engine against scalar `pdw.simulate`'s outcomes: each lane loop
this CPU runs (``PDW_BATCH_ISA`` = scalar, base, avx2, avx512) with the bitwise trig
(``vector=False``) and with libmvec's sin/cos (``vector=True``), for cdm and rodas4.

Each walker's status, stop reason, end time, event counts and gait steps must be the scalar
run's; its final state bit for bit on the bitwise path, and on the vector path within a stated
tolerance: libmvec's sin/cos differ from libm's in the last bits, which moves a flag switch of
the fixed-step cdm by a step now and then (so 0.05 in any state component after 1.2 s,
measured up to 0.031), and rodas4's adaptive steps by rounding (1e-4, measured up to 4e-6).
A wrong angle fed to the vector routines makes walkers fall that walk: the outcomes catch it.
"""
import numpy as np
import pytest

import pdw
from pdw.core import _batch
from pdw.sim.batch import ISA_ENV, simulate_batch

T_END = 1.2
ISAS = [n for n in _batch.ISAS if _batch.isa_supported(n)]
METHODS = {"cdm": {}, "rodas4": dict(rtol=1e-6, atol=1e-8)}
VECTOR_TOL = {"cdm": 0.05, "rodas4": 1e-4}


def _states(n, seed):
    rng = np.random.default_rng(seed)
    x = np.tile(np.asarray(pdw.X0_PAPER, float), (n, 1))
    x[:, 6] += rng.uniform(-2.5, 0.5, n)      # strongly negative thetad1: falls
    x[:, 7] += rng.uniform(-0.5, 0.5, n)
    return x


X = _states(16, seed=5)


@pytest.fixture(scope="module", params=list(METHODS))
def scalar_runs(request):
    method = request.param
    runs = [pdw.simulate(x, t_end=T_END, method=method, record=pdw.Record(every=0),
                         limits=pdw.Limits(on_failure="return"),
                         integrator=pdw.Integrator(check_step="off", **METHODS[method]))
            for x in X]
    assert {r.status for r in runs} == {"walked", "fell"}
    return method, runs


@pytest.mark.parametrize("vector", [False, True], ids=["bitwise", "vector"])
@pytest.mark.parametrize("isa", ISAS)
def test_every_isa_and_trig_path_has_the_scalar_outcomes(isa, vector, scalar_runs, monkeypatch):
    method, runs = scalar_runs
    monkeypatch.setenv(ISA_ENV, isa)
    b = simulate_batch(X, t_end=T_END, method=method, lanes=8, threads=1, vector=vector,
                       integrator=pdw.Integrator(check_step="off", **METHODS[method]))
    tol = VECTOR_TOL[method] if vector else 0.0
    for i, r in enumerate(runs):
        assert b.status[i] == r.status, (i, b.status[i], r.status)
        assert b.stop_reason[i] == r.stop_reason, i
        assert b.n_touch_down[i] == r.event_counts["touch_down"], i
        assert b.n_lift_off[i] == r.event_counts["lift_off"], i
        assert b.n_gait_steps[i] == r.n_gait_steps, i
        if r.status == "walked":
            assert b.t_final[i] == r.t_final
            np.testing.assert_allclose(b.x_final[i], r.x_final, rtol=0, atol=tol, err_msg=str(i))
            g_b, g_r = b.steps(i), r.gait
            for name in ("L", "P", "cycle"):
                np.testing.assert_allclose(g_b[name], g_r[name], rtol=0, atol=tol, err_msg=name)
        else:
            assert abs(b.t_final[i] - r.t_final) <= (0.05 if vector else 0.0), i
