"""Property-based tests (hypothesis) over physically meaningful parameters and states, extremes
included: every run either returns a valid result or raises a clear pdw error -- never a crash,
a hang, or a NaN in a result marked walked (docs/stability.md).

Bounded: short runs (t_end <= 0.3 s), a step-count budget for the explicit adaptive method, a
wall-clock watchdog per run; about 20 s in all.
"""
import math
import os
import threading
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import pdw
from pdw.core.errors import (
    InvalidInputError,
    PdwError,
    SimulationError,
    StepSizeWarning,
)
from pdw.sim import stepsize as SL

#: PDW_FUZZ_SCALE=20 (say) runs 20 times the examples, with fresh random draws: a bug hunt.
SCALE = float(os.environ.get("PDW_FUZZ_SCALE", "1"))
SETTINGS = dict(deadline=None, derandomize=SCALE == 1, suppress_health_check=[HealthCheck.too_slow])


def n(k):
    return max(1, int(k * SCALE))

WATCHDOG_S = 20.0          # a run that takes longer has hung (the longest take ~0.3 s)


def log_uniform(lo, hi):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0 ** e)


@st.composite
def params(draw):
    """The paper's walker on any ground: k_n 1e3-1e9, d_n 0 or 1e2-1e8, slope 0-0.2 rad,
    friction 0-2, point or arc feet, friction steepness v_s 1e-6-1e-2, tangential and hip
    elements from absent to ten times the paper's."""
    mu_s = draw(st.sampled_from([0.0, 2.0]) | st.floats(0.0, 2.0))
    v_s = draw(log_uniform(1e-6, 1e-2))
    return pdw.Params(
        k_n=draw(log_uniform(1e3, 1e9)),
        d_n=draw(st.just(0.0) | log_uniform(1e2, 1e8)),
        gamma=draw(st.sampled_from([0.0, 0.2]) | st.floats(0.0, 0.2)),
        mu_s=mu_s, mu_d=mu_s * draw(st.floats(0.5, 1.0)),
        r=draw(st.sampled_from([0.0, 0.2]) | st.floats(0.0, 0.45)),
        v_s=v_s, v_d=10 * v_s,
        k_t=draw(st.just(0.0) | log_uniform(1.0, 1e3)),
        d_t=draw(st.just(0.0) | log_uniform(10.0, 1e4)),
        k_hip=draw(st.floats(0.0, 10.0)),
        d_hip=draw(st.floats(0.0, 0.2)),
    )


@st.composite
def states(draw):
    """Around the typical gait's start: hip 0.3-0.7 m up (feet from 0.2 m deep to 0.2 m in the
    air), legs +-0.6 rad, velocities up to 5 m/s or rad/s; any support flags."""
    x = np.array(pdw.X0_PAPER)
    x[1] = draw(st.floats(0.3, 0.7))
    x[2] = draw(st.floats(-0.6, 0.6))
    x[3] = draw(st.floats(-0.6, 0.6))
    x[4:] = [draw(st.floats(-5.0, 5.0)) for _ in range(4)]
    flags = draw(st.sampled_from([(0, 1), (1, 0), (1, 1), (0, 0)]))
    return x, flags


def bounded(fn, timeout=WATCHDOG_S):
    """Run fn() in a thread (the compiled loops release the GIL); fail if it does not return
    within ``timeout`` seconds -- a hang."""
    out = {}

    def target():
        try:
            out["value"] = fn()
        except BaseException as e:      # noqa: BLE001 -- re-raised below
            out["error"] = e

    th = threading.Thread(target=target, daemon=True)
    th.start()
    th.join(timeout)
    assert not th.is_alive(), "hang: the run did not return within %g s" % timeout
    if "error" in out:
        raise out["error"]
    return out["value"]


def check_result(r, t_end):
    assert r.status in ("walked", "fell", "diverged")
    for a in (r.t, r.x, r.Fn, r.Ft, r.x_final):
        assert np.isfinite(a).all(), "non-finite values in a %s result" % r.status
    # fixed-step methods take round(t_end/dt) steps: t_final is within dt/2 of t_end
    slack = 0.5 * r.dt if r.method in SL.FIXED_STEP else 1e-12
    assert all(0.0 <= e.t <= r.t_final + 1e-12 and math.isfinite(e.x_D) for e in r.events)
    assert r.t_final <= t_end + slack + 1e-12
    if r.status == "walked":
        assert r.failure is None
        assert r.t_final >= t_end - slack - 1e-12
    else:
        f = r.failure
        assert 0.0 <= f["t"] <= r.t_final + 1e-12
        assert f["x"].shape == (8,) and np.isfinite(f["x"]).all()
        assert isinstance(f["reason"], str) and f["reason"] and f["reason"] != "none"


def run_checked(**kw):
    """simulate under the watchdog: a Result (checked) or a pdw error (checked); nothing else."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", StepSizeWarning)
            r = bounded(lambda: pdw.simulate(**kw))
    except SimulationError as e:
        assert math.isfinite(e.t) and e.x is not None and np.isfinite(e.x).all() and e.reason
        assert e.result is not None
        check_result(e.result, kw["t_end"])
        return e.result
    except InvalidInputError as e:
        assert str(e)
        return None
    check_result(r, kw["t_end"])
    return r


@settings(max_examples=n(60), **SETTINGS)
@given(P=params(), s=states(), method=st.sampled_from(["cdm", "verlet", "rk4"]),
       dt=log_uniform(1e-5, 1e-2), variant=st.sampled_from(["paper", "consistent"]),
       on_failure=st.sampled_from(["raise", "return"]))
def test_fixed_step_runs_return_a_valid_result_or_a_pdw_error(P, s, method, dt, variant, on_failure):
    x0, flags = s
    run_checked(x0=x0, flags0=flags, params=P, method=method, dt=dt, t_end=0.3, variant=variant,
                on_failure=on_failure, record_every=1)


@settings(max_examples=n(40), **SETTINGS)
@given(P=params(), s=states(), rtol=log_uniform(1e-7, 1e-3),
       variant=st.sampled_from(["paper", "consistent"]))
def test_rodas4_runs_return_a_valid_result_or_a_pdw_error(P, s, rtol, variant):
    x0, flags = s
    run_checked(x0=x0, flags0=flags, params=P, method="rodas4", rtol=rtol, atol=rtol * 1e-2,
                dt=1e-4, t_end=0.3, variant=variant, on_failure="return", record_every=3)


@pytest.mark.parametrize("method", ["rodas4", "dopri5"])
def test_adaptive_runs_end_at_t_end(method):
    r = pdw.simulate(method=method, t_end=0.25, dt=0.1, record_every=0)
    assert r.t_final == pytest.approx(0.25)      # ended at 0.2 s = round(t_end/dt)*dt before the fix


@settings(max_examples=n(15), **SETTINGS)
@given(P=params(), s=states())
def test_dopri5_runs_return_a_valid_result_or_a_pdw_error(P, s):
    """dopri5 is explicit: its steps are bounded by ~3/|lambda| of the stuck friction (1e-9 s on
    the stiffest ground); t_end is cut to about 2e5 such steps."""
    x0, flags = s
    h = SL.step_limit(P, "dopri5").dt_max
    t_end = float(min(0.3, max(2e5 * h, 1e-3)))
    t_end = round(t_end / 1e-5) * 1e-5     # a multiple of dt (test_adaptive_runs_end_at_t_end)
    run_checked(x0=x0, flags0=flags, params=P, method="dopri5", rtol=1e-5, atol=1e-7,
                dt=1e-5, t_end=t_end, on_failure="return", record_every=0)


@settings(max_examples=n(40), **SETTINGS)
@given(P=params(), method=st.sampled_from(list(pdw.METHODS)),
       variant=st.sampled_from(["paper", "consistent"]))
def test_step_limit_is_defined_everywhere(P, method, variant):
    lim = bounded(lambda: SL.step_limit(P, method, variant), timeout=10.0)
    assert lim.dt_max > 0 and not math.isnan(lim.dt_max)
    if method in SL.FIXED_STEP:
        assert math.isfinite(lim.dt_max) and lim.force in SL.FORCES
        assert str(lim.dt_max)[:3] in lim.message(1.0) or "%.2g" % lim.dt_max in lim.message(1.0)
    X, flags = SL.stance_states(P, variant)
    assert np.isfinite(X).all()


@settings(max_examples=n(40), **SETTINGS)
@given(P=params(), s=states(), variant=st.sampled_from(["paper", "consistent"]))
def test_model_functions_are_finite(P, s, variant):
    """rhs, jacobian, contact forces and energies at any state and parameters: finite."""
    x, flags = s
    for f in (pdw.rhs, pdw.jacobian):
        assert np.isfinite(f(x, P, flags=flags, variant=variant)).all()
    cs = pdw.contact_forces(x, P, flags=flags, variant=variant)
    assert all(np.isfinite(getattr(cs, k)).all() for k in ("F_n", "F_t", "mu", "v_x", "y_D"))
    assert (cs.F_n >= 0).all()
    assert np.isfinite(pdw.energies(x, P)["E"])


@settings(max_examples=n(30), **SETTINGS)
@given(field=st.sampled_from(["dt", "t_end", "max_speed", "rtol", "atol", "h_max", "event_tol",
                              "fall_depth"]),
       value=st.sampled_from([0.0, -1.0, math.nan, math.inf, -math.inf, "x", None]))
def test_bad_numbers_raise_invalid_input_naming_the_field(field, value):
    if value is None and field in ("h_max", "fall_depth", "dt", "t_end"):
        return                          # None is their default (no limit, l/4, 1e-4, 3.5)
    with pytest.raises(InvalidInputError, match=field) as ei:
        pdw.simulate(**{"t_end": 0.01, field: value})
    assert isinstance(ei.value, PdwError)
