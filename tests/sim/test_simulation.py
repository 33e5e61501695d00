"""The compiled simulation: the central difference method, support flags, status, bad input."""
import math

import numpy as np
import pytest

import pdw
from pdw import X0_PAPER
from pdw.core import _core
from pdw.core.model import kernel_index, parameter_vector

FLIGHT_X0 = np.array([0.0, 10.0, -0.2, 0.3, 0.5, 0.0, 2.0, -1.0])  # feet ~9.5 m above the ground


def _reference_flight(params, t_end):
    solve_ivp = pytest.importorskip("scipy.integrate").solve_ivp     # the test extra
    sol = solve_ivp(lambda t, x: pdw.rhs(x, params, flags=(0, 0)), (0, t_end), FLIGHT_X0,
                    method="DOP853", rtol=1e-13, atol=1e-13)
    return sol.y[:, -1]


def test_cdm_converges_at_first_order_without_ground():
    """Eq. 17 hands the forces a velocity one step old: the printed scheme is first order."""
    p = pdw.Params.paper()
    ref = _reference_flight(p, 0.5)
    dts = np.array([1e-3, 5e-4, 2.5e-4, 1.25e-4])
    err = []
    for dt in dts:
        r = pdw.simulate(FLIGHT_X0, 0.5, dt, params=p, flags0=(0, 0),
                         integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=0))  # no ground: no contact step limit
        assert r.status == "walked" and r.events == []
        err.append(np.abs(r.x_final - ref).max())
    slope = np.polyfit(np.log(dts), np.log(err), 1)[0]
    assert 0.9 < slope < 1.1, (slope, err)


def test_typical_gait_walks_3_5_s_with_the_paper_variant():
    r = pdw.simulate()
    assert r.status == "walked" and r.failure is None
    assert r.t_final == pytest.approx(3.5)
    td = [e for e in r.events if e.kind == "touch_down"]
    lo = [e for e in r.events if e.kind == "lift_off"]
    assert len(td) >= 5 and len(lo) >= 5
    # legs alternate: touch-downs by 1, 2, 1, 2 ...
    assert all(a.leg != b.leg for a, b in zip(td, td[1:]))
    # the stance force settles near the weight (docs/model.md section 8)
    i2 = (r.t > 1.1) & (r.t < 1.3)            # mid-stance of leg 2
    assert np.all(r.flags[i2, 1] == 1)
    assert r.Fn[i2, 1].mean() == pytest.approx(r.params.weight, rel=0.1)


def test_swing_foot_passing_the_stance_foot_is_not_caught():
    """At mid-stance the swing foot dips below the ground (both feet are 2.6 mm deep at the
    paper's x0) while still uphill of the stance foot: the scuffing guard must ignore it."""
    r = pdw.simulate(t_end=1.0)
    c = pdw.contact_forces(r.x, r.params, flags=(0, 0))
    swing1 = r.flags[:, 0] == 0
    scuff = swing1 & (c.y_D[:, 0] < 0) & (c.x_D[:, 0] <= c.x_D[:, 1])
    assert scuff.any(), "the test needs a scuffing instant"
    for e in r.events:
        if e.kind == "touch_down":
            k = np.searchsorted(r.t, e.t)
            other = 1 - (e.leg - 1)
            assert c.x_D[k, e.leg - 1] > c.x_D[k, other], "touch-down behind the other foot"
    first_td = next(e for e in r.events if e.kind == "touch_down")
    assert first_td.leg == 1 and first_td.t > r.t[scuff].max()


def test_a_foot_touching_down_ahead_is_caught():
    r = pdw.simulate(t_end=1.0)
    td = [e for e in r.events if e.kind == "touch_down"]
    assert td and td[0].leg == 1
    k = np.searchsorted(r.t, td[0].t)
    # flag is set from that step on; the foot was above ground shortly before
    assert r.flags[k, 0] == 1 and r.flags[k - 1, 0] == 0
    assert -1e-3 < td[0].y_D < 0


def test_paper_params_fall_after_a_few_steps_paper_steady_walks():
    """docs/model.md section 8: with d_hip = 0.018 the gait decays and falls after 6-9 steps (4-6 s)."""
    for variant in ("paper", "consistent"):
        r = pdw.simulate(t_end=20.0, variant=variant, record=pdw.Record(every=0))
        assert r.status == "fell", variant
        assert 3.0 < r.failure["t"] < 7.0
        assert 4 <= len(pdw.steps(r)) <= 10
        steady = pdw.simulate(t_end=20.0, variant=variant, params=pdw.Params.paper_steady(),
                              record=pdw.Record(every=0))
        assert steady.status == "walked"
        st = pdw.steps(steady).steady(4)
        assert st["spread_L"] < 1e-3 and st["spread_P"] < 1e-3


def test_recording_is_optional_and_events_are_always_kept():
    full = pdw.simulate(t_end=1.5)
    none = pdw.simulate(t_end=1.5, record=pdw.Record(every=0))
    every10 = pdw.simulate(t_end=1.5, record=pdw.Record(every=10, forces=False))
    assert none.x.shape == (0, 8) and none.events == full.events
    assert every10.events == full.events
    assert len(full.t) == 15001 and len(every10.t) == 1501
    np.testing.assert_array_equal(every10.x, full.x[::10])
    assert every10.Fn.shape == (0, 2)
    np.testing.assert_array_equal(none.x_final, full.x_final)


def test_event_buffer_grows_and_the_loop_resumes_exactly():
    p = parameter_vector(pdw.Params.paper_steady())
    k = kernel_index("paper")
    args = (k, 0, np.array(X0_PAPER), p, 0, 1,
            dict(dt=1e-4, n_steps=60000, record_events=1, fall_hip_height=0.25, fall_depth=0.125,
                 max_speed=1e3))
    small = _core.run(*args, event_capacity=4)
    big = _core.run(*args, event_capacity=1000)
    assert len(big["events"]) > 8
    np.testing.assert_array_equal(small["events"], big["events"])
    np.testing.assert_array_equal(small["x_final"], big["x_final"])


def test_divergence_stops_with_time_state_and_reason():
    """Explicit normal damping d_n = 1e7 at dt = 1e-3 is unstable (the state runs away); the
    step-size check warns before the run, naming the normal damping."""
    p = pdw.Params(d_n=1e7)
    with pytest.raises(pdw.DivergedError) as ei, pytest.warns(pdw.StepSizeWarning, match="d_n"):
        pdw.simulate(dt=1e-3, t_end=3.5, params=p)
    err = ei.value
    assert 0 <= err.t < 3.5 and err.x.shape == (8,) and np.isfinite(err.x).all()
    assert "diverged at t =" in str(err) and err.reason
    assert err.result is not None and err.result.status == "diverged"
    r = pdw.simulate(dt=1e-3, t_end=3.5, params=p, integrator=pdw.Integrator(check_step="off"),
                     limits=pdw.Limits(on_failure="return"))
    assert r.status == "diverged" and r.failure["t"] == err.t
    assert np.isfinite(r.x).all()


@pytest.mark.parametrize("kwargs, field", [
    (dict(x0=[0, 0.5, 0, 0]), "x0"),
    (dict(x0=[0, math.nan, 0, 0, 0, 0, 0, 0]), "y_o"),
    (dict(dt=0.0), "dt"),
    (dict(dt=-1e-4), "dt"),
    (dict(dt=math.inf), "dt"),
    (dict(t_end=math.nan), "t_end"),
    (dict(t_end=1e-5, dt=1e-4), "dt"),
    (dict(variant="papr"), "variant"),
    (dict(method="euler"), "method"),
    (dict(flags0=(1, 2)), "flags0"),
    (dict(record=dict(every=-1)), r"record\.every"),            # a table, read by simulate
    (dict(limits=dict(on_failure="ignore")), r"limits\.on_failure"),
])
def test_bad_input_raises_a_clear_error(kwargs, field):
    with pytest.raises(pdw.InvalidInputError, match=field):
        pdw.simulate(**kwargs)
    assert issubclass(pdw.InvalidInputError, ValueError)


def test_simulate_refuses_a_t_end_whose_step_count_overflows():
    """t_end = 1.8e304 with dt = 1e-4: t_end/dt is inf, and round(inf) was a raw OverflowError
    (found by the fuzzer)."""
    with pytest.raises(pdw.InvalidInputError, match="t_end/dt"):
        pdw.simulate(t_end=1.797693134862316e+304)


X0 = np.array(pdw.X0_PAPER)


@pytest.mark.parametrize("flags0", ["01", (1,), (0.9, 1.9), (0, 1, 0), (0, 5)])
def test_simulate_refuses_malformed_flags0(flags0):
    with pytest.raises(pdw.InvalidInputError, match="flags0"):
        pdw.simulate(t_end=0.01, flags0=flags0)


@pytest.mark.parametrize("x0,what", [
    (np.tile(X0[:4], (2, 1)), "shape"),                 # (2, 4): 8 numbers, not a state
    (X0.reshape(2, 4), "shape"),
    (X0 + 0j, "real"),                                   # complex
    ([str(v) for v in X0], "real"),                      # strings
    (X0[:7], "shape"),
])
def test_simulate_refuses_states_that_are_not_states(x0, what):
    with pytest.raises(pdw.InvalidInputError, match=what):
        pdw.simulate(x0=x0, t_end=0.01)


@pytest.mark.parametrize("value", [math.nan, math.inf, "0.2", True])
def test_fall_hip_height_must_be_a_finite_number(value):
    """fall_hip_height = nan switched fall detection off."""
    with pytest.raises(pdw.InvalidInputError, match="fall_hip_height"):
        pdw.simulate(t_end=0.01, limits=pdw.Limits(fall_hip_height=value))


@pytest.mark.parametrize("value", [math.nan, None, 2 ** 70, 1.5, -1, "1", True])
def test_record_every_errors_name_the_field(value):
    with pytest.raises(pdw.InvalidInputError, match=r"record\.every"):
        pdw.simulate(t_end=0.01, record=pdw.Record(every=value))
