"""Numerical stability and loud failure (docs/stability.md): the error hierarchy, the step-size
check of `simulate`, the linear stability regions of the methods, a 10,000-step run on the limit
cycle, and the work-energy balance."""
import math
import warnings

import numpy as np
import pytest

import pdw
from pdw.analysis.numerics import stability_maps as S
from pdw.core.errors import (
    DivergedError,
    FellError,
    InvalidInputError,
    PdwError,
    SimulationError,
    SingularSystemError,
    StepSizeError,
    StepSizeWarning,
)
from pdw.sim import stepsize as SL


def _finite_result(r):
    for a in (r.t, r.x, r.Fn, r.Ft, r.x_final):
        assert np.isfinite(a).all()
    assert all(math.isfinite(v) for e in r.events for v in (e.t, e.x_D, e.y_D))


# ------------------------------------------------------------------------ error hierarchy ----

def test_hierarchy():
    for cls in (DivergedError, SingularSystemError, FellError):
        assert issubclass(cls, SimulationError) and issubclass(cls, PdwError)
    assert issubclass(InvalidInputError, ValueError) and issubclass(InvalidInputError, PdwError)
    assert issubclass(StepSizeError, InvalidInputError)
    assert issubclass(StepSizeWarning, UserWarning)
    for name in ("StepSizeError", "StepSizeWarning"):
        assert getattr(pdw, name) is getattr(pdw.core.errors, name) and name in pdw.__all__


def test_diverged_error_carries_time_state_reason_and_partial_result():
    """Explicit normal damping d_n = 1e7 at dt = 1e-3: the contact runs away."""
    with pytest.raises(DivergedError) as ei:
        pdw.simulate(dt=1e-3, params=pdw.Params(d_n=1e7),
                     integrator=pdw.Integrator(check_step="off"))
    e = ei.value
    assert 0 <= e.t < 3.5 and e.x.shape == (8,) and np.isfinite(e.x).all()
    assert "max_speed" in e.reason and "%.6g" % e.t in str(e)
    assert e.result is not None and e.result.status == "diverged"
    assert e.result.failure["t"] == e.t and e.result.failure["reason"] == e.reason
    _finite_result(e.result)


# a falling walker (hip 10 m up, both legs swing) with a hip damper far too stiff for dt = 1e-3,
# every other stop condition out of the way: only the non-finite check can stop the run
_X_HIGH = np.array(pdw.X0_PAPER)
_X_HIGH[1] = 10.0
_RUNAWAY = dict(x0=_X_HIGH, dt=1e-3, t_end=1.0, params=pdw.Params(d_hip=500.0), flags0=(0, 0),
                integrator=pdw.Integrator(check_step="off"))
_RUNAWAY_LIMITS = dict(max_speed=1e300, fall_hip_height=-1e300, fall_depth=1e300)


@pytest.mark.parametrize("method", ["verlet", "rk4"])
def test_non_finite_state_is_caught_within_the_step(method):
    """The compiled loop (pdw_check_state) stops at the first step whose new state is not
    finite, and keeps the last finite one: no NaN or inf reaches the result."""
    r = pdw.simulate(method=method, limits=pdw.Limits(on_failure="return", **_RUNAWAY_LIMITS),
                     **_RUNAWAY)
    assert r.status == "diverged"
    assert "non-finite" in r.failure["reason"]
    assert np.isfinite(r.failure["x"]).all() and r.failure["t"] < 0.05
    _finite_result(r)
    assert r.t[-1] == r.failure["t"] and np.array_equal(r.x[-1], r.failure["x"])
    with pytest.raises(DivergedError, match="non-finite") as ei:
        pdw.simulate(method=method, limits=pdw.Limits(**_RUNAWAY_LIMITS), **_RUNAWAY)
    assert ei.value.t == r.failure["t"]
    np.testing.assert_array_equal(ei.value.x, r.failure["x"])


@pytest.mark.parametrize("method", ["dopri5", "rodas4"])
def test_adaptive_failure_carries_time_state_reason(method):
    """A walker thrown at the ground at 2000 m/s: over max_speed at once."""
    x0 = np.array(pdw.X0_PAPER)
    x0[5] = -2000.0
    with pytest.raises(DivergedError) as ei:
        pdw.simulate(x0=x0, method=method, t_end=0.1)
    e = ei.value
    assert e.t == 0.0 and e.x.shape == (8,) and e.reason


def test_singular_system_error_carries_time_state_reason(monkeypatch):
    """The loop status 'singular' (a singular step matrix) maps onto SingularSystemError with
    the failure's time, state and reason (a regular mass matrix makes it unreachable from
    valid input, so the raw loop output of a real run is doctored here)."""
    from pdw.sim import simulation as sim
    captured = {}
    real_run = sim._core.run

    def capture(*args, **kw):
        captured["raw"] = real_run(*args, **kw)
        return captured["raw"]

    monkeypatch.setattr(sim._core, "run", capture)
    r = pdw.simulate(t_end=0.01, integrator=pdw.Integrator(check_step="off"),
                     record=pdw.Record(every=1))
    raw = dict(captured["raw"], status=pdw.core._layout.STATUS.index("singular"),
               failure={"t": 0.005, "x": r.x[50], "reason": 5, "leg": -1})
    with pytest.raises(SingularSystemError) as ei:
        sim._result(raw, r.params, "paper", "cdm", 1e-4, 0.01, 0.0, "raise")
    e = ei.value
    assert e.t == 0.005 and np.array_equal(e.x, r.x[50]) and "singular" in e.reason
    ret = sim._result(raw, r.params, "paper", "cdm", 1e-4, 0.01, 0.0, "return")
    assert ret.status == "diverged" and ret.failure["reason"] == e.reason


def _hybrid_fall():
    with pytest.raises(FellError) as ei:
        pdw.hybrid.step_map(np.array([0.2, -0.2, 0.5, 0.5]))     # rolls back and falls
    return ei.value


def test_fell_error_of_the_hybrid_model_carries_time_and_reason():
    """FellError is raised by the hybrid model's step map (a fall of the continuous model is a
    status, never an error)."""
    e = _hybrid_fall()
    assert 0 < e.t < 5 and e.reason == "fell" and "fell after" in str(e)


def test_fell_error_of_the_hybrid_model_carries_a_state():
    x = _hybrid_fall().x
    assert x.shape == (8,) and np.isfinite(x).all()


def test_fell_is_a_status_with_time_state_reason():
    r = pdw.simulate(t_end=8.0, params=pdw.Params.paper(), record=pdw.Record(every=0))
    assert r.status == "fell"
    f = r.failure
    assert 3.0 < f["t"] < 8.0 and f["x"].shape == (8,) and np.isfinite(f["x"]).all()
    assert f["reason"] in S_REASONS_FELL
    _finite_result(r)


S_REASONS_FELL = ("the hip dropped below fall_hip_height",
                  "a foot sank deeper than fall_depth below the ground")


def test_walked_results_never_hold_nan():
    for method, kw in [("cdm", {}), ("verlet", dict(dt=1e-5)), ("rk4", dict(dt=1e-5)),
                       ("dopri5", dict(t_end=0.4)), ("rodas4", {})]:
        r = pdw.simulate(method=method, **kw)
        assert r.status == "walked"
        _finite_result(r)


# ------------------------------------------------------------------------ step-size check ----

def _no_warning(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter("error", StepSizeWarning)
        return pdw.simulate(**kw)


def test_paper_dt_does_not_warn():
    """The paper's own dt = 1e-4 with cdm, at the paper's parameters (it walks there)."""
    r = _no_warning(record=pdw.Record(every=0))
    assert r.walked
    for method in SL.FIXED_STEP:
        for P in (pdw.Params.paper(), pdw.Params.paper_steady()):
            assert SL.step_limit(P, method).dt_max > 1e-4


def test_step_above_the_limit_warns_with_the_limit_and_the_force():
    lim = SL.step_limit(pdw.Params.paper(), "cdm")
    dt = 2.5 * lim.dt_max
    with pytest.warns(StepSizeWarning) as rec:
        pdw.simulate(dt=dt, record=pdw.Record(every=0),
                     limits=pdw.Limits(on_failure="return"))
    w = rec[0].message
    assert w.dt == dt and w.limit == lim.dt_max and w.force == lim.force
    text = str(w)
    assert "%.2g" % lim.dt_max in text and SL.FORCES[lim.force] in text and "'cdm'" in text
    assert rec[0].filename == __file__       # points at the caller's line


def test_check_step_error_refuses_and_off_is_silent():
    P = pdw.Params(d_n=1e7)
    lim = SL.step_limit(P, "rk4")
    with pytest.raises(StepSizeError, match="%.2g" % lim.dt_max) as ei:
        pdw.simulate(dt=3 * lim.dt_max, params=P, method="rk4",
                     integrator=pdw.Integrator(check_step="error"))
    assert ei.value.limit == lim.dt_max and ei.value.force == lim.force == "d_n"
    _no_warning(dt=3 * lim.dt_max, params=P, method="rk4", integrator=pdw.Integrator(check_step="off"),
                record=pdw.Record(every=0), limits=pdw.Limits(on_failure="return"))
    with pytest.raises(InvalidInputError, match="check_step"):
        pdw.simulate(integrator=pdw.Integrator(check_step="yes"))


def test_adaptive_methods_are_not_checked():
    _no_warning(method="rodas4", dt=0.1, t_end=0.5)
    assert SL.step_limit(method="rodas4").dt_max == math.inf
    d5 = SL.step_limit(method="dopri5")
    assert d5.force == "v_s" and 1e-7 < d5.dt_max < 1e-5


def test_step_limit_names_the_limiting_force():
    assert SL.step_limit(pdw.Params.paper_steady(d_n=1e7), "cdm").force == "d_n"
    lim = SL.step_limit(pdw.Params.paper_steady(d_t=1e4), "cdm")
    assert lim.force == "d_t" and lim.sensitivity["d_t"] < -0.9      # limit ~ 1/d_t
    lim = SL.step_limit(pdw.Params.paper_steady(), "rk4")
    assert lim.dt_chatter < 5e-6                      # the stuck foot's friction mode


@pytest.mark.parametrize("kw, variant", [
    ({}, "paper"), (dict(d_n=1e7), "paper"), (dict(d_t=1e4), "paper"), (dict(k_n=1e4), "paper"),
    (dict(k_t=850), "paper"), ({}, "consistent"), (dict(d_n=2.5e7), "consistent")])
@pytest.mark.parametrize("method", SL.FIXED_STEP)
def test_the_gait_walks_at_the_step_limit(method, kw, variant):
    """At dt = step_limit the typical gait walks (the calibration is conservative), also where
    the friction chatter sets the limit (k_t = 850: the stuck foot at its friction limit)."""
    P = pdw.Params.paper_steady(**kw)
    lim = SL.step_limit(P, method, variant)
    ref = S.reference(P, variant)
    v = S.judge(S.run_fixed(P, method, lim.dt_max, variant), ref)
    assert v.walks, v.reason


def test_friction_bound_limit():
    """k_t = 850: the stuck foot needs 115 % of mu_s F_n; the limit is the chatter's, and the
    message says so. Explicit runs above it fail (cdm at the paper's dt loses a step)."""
    P = pdw.Params.paper_steady(k_t=850)
    lim = SL.step_limit(P, "cdm")
    assert lim.force == "v_s" and lim.friction_load > 1.0
    assert lim.dt_max == pytest.approx(SL.CHATTER_CALIBRATION * lim.dt_chatter)
    assert "static friction" in lim.message(1e-4)
    assert not S.judge(S.run_fixed(P, "cdm", 1e-4), S.reference(P)).walks
    assert SL.step_limit(pdw.Params.paper_steady(), "cdm").friction_load < 0.2


# -------------------------------------------------------------- linear stability regions ----

@pytest.mark.parametrize("method, real, imag", [
    ("cdm", 2.0, 2.0),        # lagged damping z^2 - (1 - a/2) z + a/2: |z|^2 = a/2; leapfrog
    ("verlet", 1.0, 2.0),     # a_n = qdd(q_n, v*) is reused: mu^2 - (1 + 3z/2) mu + z/2 = 0
                              # has mu = -1 at z = -1 (not Heun's -2); Stormer-Verlet: 2
    ("rk4", 2.785, 2.828),    # classical RK4 on the real and imaginary axes
    ("dopri5", 3.307, 0.0),   # DOPRI5 on the real axis (its region misses the imaginary axis)
])
def test_linear_limit_matches_the_stability_regions(method, real, imag):
    lam = 1234.0
    Z, E = np.zeros((4, 4)), np.eye(4)
    damping = np.block([[Z, E], [Z, -lam * E]])          # qdd = -lam qd: real eigenvalue -lam
    spring = np.block([[Z, E], [-lam ** 2 * E, Z]])      # qdd = -lam^2 q: eigenvalues +-i lam
    assert SL.linear_limit(method, damping) * lam == pytest.approx(real, rel=2e-3)
    if imag:
        assert SL.linear_limit(method, spring) * lam == pytest.approx(imag, rel=2e-3)
    assert SL.linear_limit("rodas4", damping) == math.inf


def test_linear_limit_tolerates_physically_unstable_modes():
    """The walker is an inverted pendulum (a slow positive eigenvalue): that is no instability
    of the method."""
    J = np.zeros((8, 8))
    J[:4, 4:] = np.eye(4)
    J[4:, :4] = np.diag([25.0, -1e4, -1e4, -1e4])      # lambda = +5 and +-100 i
    assert SL.linear_limit("cdm", J) == pytest.approx(2 / 100, rel=1e-2)


def test_stance_states_carry_the_weight():
    for kw in ({}, dict(k_n=5e3), dict(k_n=2.5e6), dict(d_n=0.0)):
        P = pdw.Params.paper(**kw)
        X, flags = SL.stance_states(P)
        for x, fl, load in zip(X, flags, (1, 1, 1, SL.DOUBLE_SUPPORT_LOAD)):
            cs = pdw.contact_forces(x, P, flags=fl)
            assert cs.F_n.sum() == pytest.approx(load * P.weight, rel=1e-4)
            assert abs(cs.v_x[fl.index(1)]) < 1e-12
    x = SL.typical_start(pdw.Params.paper())
    assert abs(x[1] - pdw.X0_PAPER[1]) < 2e-4


# --------------------------------------------------------------------------- long runs -------

def _steady(r, skip=100):
    st = pdw.steps(r)
    out = {}
    for name in ("L", "P", "v", "double_support"):
        a = st[name][skip:]
        a = a[np.isfinite(a)]
        out[name] = (a, float(np.mean(a[:100])), float(np.mean(a[-100:])))
    return len(st), out


def test_ten_thousand_steps_stay_on_the_limit_cycle():
    """Params.paper_steady(), 5,800 s (about 10,000 walking steps), rodas4 at rtol 1e-6 (~7 s):
    every descriptor after the first 100 steps equals the last 100 steps' mean to 2e-5
    (relative), and the mean does not drift (first vs last 100 steps: 1e-6)."""
    r = pdw.simulate(params=pdw.Params.paper_steady(), t_end=5800.0, method="rodas4",
                     integrator=pdw.Integrator(rtol=1e-6, atol=1e-8), record=pdw.Record(every=0))
    assert r.status == "walked"
    _finite_result(r)
    n, out = _steady(r)
    assert n >= 9990
    for name, (a, first, last) in out.items():
        scale = abs(last)
        assert np.max(np.abs(a - last)) < 2e-5 * scale, name
        assert abs(first - last) < 1e-6 * scale, name


def test_ten_thousand_steps_with_the_papers_method():
    """The same with cdm at dt = 1e-4 (58 million steps, ~7 s): chatter and first-order error
    shift the cycle (L by 0.1 %), but it stays on it: L, P, v within 2e-3 (relative) of the
    last 100 steps' mean, no drift above 2e-4; the double support, quantized by dt, within
    2 dt and no drift above 1 dt."""
    r = pdw.simulate(params=pdw.Params.paper_steady(), t_end=5800.0, record=pdw.Record(every=0))
    assert r.status == "walked"
    n, out = _steady(r)
    assert n >= 9950
    for name, (a, first, last) in out.items():
        if name == "double_support":
            assert np.max(np.abs(a - last)) < 2 * r.dt and abs(first - last) < r.dt
        else:
            assert np.max(np.abs(a - last)) < 2e-3 * abs(last), name
            assert abs(first - last) < 2e-4 * abs(last), name


# ----------------------------------------------------------------------- energy balance ------

@pytest.fixture(scope="module")
def balance_runs():
    P = pdw.Params.paper_steady()
    return {rtol: pdw.simulate(params=P, method="rodas4",
                               integrator=pdw.Integrator(rtol=rtol, atol=rtol * 1e-2, h_max=1e-3),
                               record=pdw.Record(every=1))
            for rtol in (1e-5, 1e-8)}


def test_energy_balance_closes(balance_runs):
    """Work of gravity = dissipation by the contact forces and the hip damper + change of
    kinetic and potential energy: with rodas4 at rtol 1e-8 the residual stays below 1e-6 J
    over 3.5 s (gravity does ~0.14 J of work per step), 1e-5 of each step's gravity work."""
    r = balance_runs[1e-8]
    b = S.energy_balance(r)
    assert np.max(np.abs(b["residual"])) < 1e-6
    assert len(b["step_relative"]) >= 4
    assert np.max(np.abs(b["step_relative"])) < 1e-5
    assert np.all(b["step_gravity_work"] > 0.1)
    # dissipation is real: the contact forces and the damper take energy out every step
    td = [np.searchsorted(b["t"], e.t) for e in r.events if e.kind == "touch_down"]
    assert all(b["W"][j] < b["W"][i] for i, j in zip(td[:-1], td[1:]))


def test_energy_residual_shrinks_with_the_tolerance(balance_runs):
    coarse = np.max(np.abs(S.energy_balance(balance_runs[1e-5])["residual"]))
    fine = np.max(np.abs(S.energy_balance(balance_runs[1e-8])["residual"]))
    assert fine < coarse / 30


def test_energy_balance_consistent_variant():
    r = pdw.simulate(params=pdw.Params.paper_steady(), variant="consistent", method="rodas4",
                     t_end=1.5, integrator=pdw.Integrator(rtol=1e-8, atol=1e-10, h_max=1e-3),
                     record=pdw.Record(every=1))
    b = S.energy_balance(r)
    assert np.max(np.abs(b["residual"])) < 1e-6


# ------------------------------------------------------------------ the maps' nominal cell ----

def test_maps_nominal_cell_and_claims():
    """The nominal cell of the stability maps at the paper's values (docs/stability.md, ~1 s;
    the maps themselves run in `make study`): cdm walks to ~2.3e-3 s and fails just above;
    step_limit is below that; cdm chatters at every step from 1e-5 to the edge."""
    P = pdw.Params.paper()
    ref = S.reference(P)
    ls = S.largest_step(P, "cdm", ref)
    a, b = ls["walk"]
    assert 1.5e-3 < a < 3e-3 and b < 1.2 * a
    assert SL.step_limit(P, "cdm").dt_max < a
    for dt in (1e-5, 1e-4, 1e-3, 0.9 * a):
        assert S.chatter(P, "cdm", dt).chatters


def test_edge_on_grid_brackets_the_edge():
    """The benchmarks' edge finder: scan, then log-bisect; the bracket holds the true edge and
    is sqrt(10)^(1/2^refine) wide; all-pass and first-fail grids say so."""
    from pdw.analysis.numerics.stability_maps import edge_on_grid
    grid = [1e-5 * 10 ** (k / 2) for k in range(9)]
    seen = []

    def ok(dt):
        seen.append(dt)
        return dt < 3.3e-4
    a, b = edge_on_grid(ok, grid, refine=4)
    assert a < 3.3e-4 <= b and ok(a) and not ok(b)
    assert b / a == pytest.approx(10 ** (0.5 / 16), rel=1e-12)
    assert len(seen) == 5 + 4 + 2          # scan to the first failure, 4 bisections (+ checks)
    assert edge_on_grid(lambda dt: True, grid) == (grid[-1], None)
    assert edge_on_grid(lambda dt: False, grid) == (None, grid[0])
