"""How a run ends (docs/model.md section 7): a foot deeper than ``fall_depth`` or the hip lower
than ``fall_hip_height`` is a fall, a velocity above ``max_speed`` a divergence, each at the
first state that crosses the limit, with the right leg and reason. The reference is the same run
recorded without the limit, read here sample by sample (cdm: the feet are checked at each
sample before its forces, a new state before it is accepted; the failure's time and state are
the last good sample's).

Honest statuses (issue 16, findings 6, 7 and 9): a runaway or airborne run is "diverged",
a run without a touch-down "no_steps"; long compiled loops stop at a step budget with a clear
error; energies are finite or the run is diverged; recording grows in chunks; an unestimable
step limit is a warning; a tiny dt is refused.
"""
import warnings

import numpy as np
import pytest

import pdw

DT = 1e-4
REASON = {"foot": "a foot sank deeper than fall_depth below the ground",
          "hip": "the hip dropped below fall_hip_height",
          "speed": "a velocity exceeded max_speed (runaway state)"}


@pytest.fixture(scope="module")
def free():
    """The paper's run, 2 s, every sample, no fall limits in reach."""
    return pdw.simulate(t_end=2.0, dt=DT, integrator=pdw.Integrator(check_step="off"),
                        record=pdw.Record(every=1),
                        limits=pdw.Limits(fall_depth=1.0, fall_hip_height=0.0))


@pytest.mark.parametrize("depth", [0.0035, 0.0041, 0.0042])
def test_a_foot_too_deep_is_a_fall_of_that_leg(free, depth):
    d = -pdw.contact_forces(free.x).y_D                   # (n, 2) penetration of each foot
    n = int(np.argmax((d > depth).any(axis=1)))
    assert (d[n] > depth).any() and not (d[:n] > depth).any()
    leg = int(np.argmax(d[n] > depth)) + 1
    r = pdw.simulate(t_end=2.0, dt=DT, integrator=pdw.Integrator(check_step="off"),
                     record=pdw.Record(every=1),
                     limits=pdw.Limits(fall_depth=depth, on_failure="return"))
    assert r.status == "fell" and r.failure["reason"] == REASON["foot"]
    assert r.failure["leg"] == leg
    assert r.failure["t"] == pytest.approx(free.t[n], abs=1e-12)
    np.testing.assert_array_equal(r.failure["x"], free.x[n])


@pytest.mark.parametrize("height", [0.49, 0.48])
def test_a_low_hip_is_a_fall(free, height):
    n = int(np.argmax(free.x[:, 1] < height))              # the first state below
    assert n > 0 and free.x[n, 1] < height <= free.x[:n, 1].min()
    r = pdw.simulate(t_end=2.0, dt=DT, integrator=pdw.Integrator(check_step="off"),
                     record=pdw.Record(every=1),
                     limits=pdw.Limits(fall_hip_height=height, on_failure="return"))
    assert r.status == "fell" and r.failure["reason"] == REASON["hip"]
    assert r.failure["leg"] is None
    assert r.failure["t"] == pytest.approx(free.t[n - 1], abs=1e-12)
    np.testing.assert_array_equal(r.failure["x"], free.x[n - 1])


@pytest.mark.parametrize("method", ["cdm", "rk4", "rodas4"])
@pytest.mark.parametrize("k", range(4))
def test_each_velocity_is_checked_against_max_speed(k, method):
    """One velocity component at 5 with max_speed = 4 (the others below 4): diverged at the
    first step; with max_speed = 6 the same start is not a divergence at once."""
    x0 = np.array(pdw.X0_PAPER, float)
    x0[4 + k] = 5.0
    assert np.abs(np.delete(x0[4:], k)).max() < 4.0
    kw = dict(t_end=5 * DT, dt=DT / 50 if method == "rk4" else DT, method=method,
              integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=1))
    r = pdw.simulate(x0, limits=pdw.Limits(max_speed=4.0, on_failure="return"), **kw)
    assert r.status == "diverged" and r.failure["reason"] == REASON["speed"], (k, r.status)
    assert r.failure["t"] == 0.0
    ok = pdw.simulate(x0, limits=pdw.Limits(max_speed=6.0, on_failure="return"), **kw)
    assert ok.failure is None or ok.failure["reason"] != REASON["speed"]


# ---- the end-of-run checks of simulate and of the batch (docs/ensemble.md) --------------------

@pytest.mark.parametrize("leg", [1, 2])
def test_a_leg_turning_past_a_full_turn_is_a_runaway(leg):
    """Feet far above the ground, one leg spun at 300 rad/s: it passes 2 pi within 0.05 s; the
    run reached its end but is "diverged" (runaway), whichever leg it is."""
    x0 = np.array(pdw.X0_PAPER, float)
    x0[1] += 1.0
    x0[5 + leg] = 300.0
    r = pdw.simulate(x0, t_end=0.05, dt=1e-5, method="rk4", flags0=(0, 0),
                     integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=10),
                     limits=pdw.Limits(on_failure="return"))
    assert abs(r.x_final[1 + leg]) > 2 * np.pi > abs(r.x_final[4 - leg])       # only this leg
    assert r.status == "diverged" and "runaway" in r.failure["reason"], r.status
    b = pdw.simulate_batch(x0[None, :], t_end=0.05, dt=1e-5, method="rk4", flags0=(0, 0),
                           integrator=pdw.Integrator(check_step="off"))
    assert b.status[0] == "diverged" and "runaway" in b.failure_reason[0]


def test_batch_reports_every_loop_status_as_simulate_does():
    """The batch's names of the compiled loops' statuses are simulate's public ones
    (`Result.status`): "done" is "walked", a singular step matrix is "diverged" (as
    `SingularSystemError` is a `DivergedError`)."""
    from pdw.core import _layout
    from pdw.sim import batch
    public = {"running": "interrupted", "done": "walked", "singular": "diverged"}
    for code, name in batch._STATUS.items():
        loop = _layout.STATUS[code]
        assert name == public.get(loop, loop), (code, loop, name)
    assert set(batch._STATUS) >= {_layout.STATUS.index(s) for s in ("done", "fell", "diverged",
                                                                     "singular", "periodic")}


def test_batch_no_steps_is_judged_on_touch_downs():
    """`pdw.sim.chunks.honest`: a walker that reached its end after two pendulum periods
    without a touch-down did not walk ("no_steps"), whatever its lift-offs; one touch-down
    is enough to be "walked"."""
    from pdw.sim.chunks import honest
    x0 = np.tile(np.asarray(pdw.X0_PAPER, float), (3, 1))
    b = pdw.simulate_batch(x0, t_end=0.2, integrator=pdw.Integrator(check_step="off"))
    assert list(b.status) == ["walked"] * 3
    period = 2 * np.pi * np.sqrt(pdw.Params.paper().l / pdw.Params.paper().g)
    b.t_final[:] = 2.01 * period
    b.n_touch_down[:] = [0, 1, 0]
    b.n_lift_off[:] = [2, 0, 0]
    b.t_final[2] = 1.99 * period                          # too short to judge
    honest(b, x0, pdw.Params.paper())
    assert list(b.status) == ["no_steps", "walked", "walked"]


def test_cdm_blowup_with_stiff_ground_is_not_walked():
    """cdm, dt = 1e-3, k_n = 1e9 used to return "walked" with the hip 14 m up and the legs at
    -118 rad after no step (only a StepSizeWarning)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pdw.StepSizeWarning)
        r = pdw.simulate(dt=1e-3, params=pdw.Params(k_n=1e9),
                         limits=pdw.Limits(on_failure="return"))
        assert r.status == "diverged" and not r.walked
        assert "runaway" in r.failure["reason"]
        assert r.failure["t"] < r.t_final
        with pytest.raises(pdw.DivergedError, match="runaway"):
            pdw.simulate(dt=1e-3, params=pdw.Params(k_n=1e9))


def test_a_run_without_any_touch_down_is_not_walked():
    """A walker standing astride (legs at +-0.3 rad) on flat ground for 4 s never steps:
    "no_steps", not "walked"."""
    p = pdw.Params(gamma=0.0)
    x0 = np.zeros(8)
    x0[2:4] = (0.3, -0.3)
    x0[1] = p.r + (p.l - p.r) * np.cos(0.3) - 2e-4
    r = pdw.simulate(x0=x0, params=p, t_end=4.0, flags0=(1, 1), method="rodas4",
                     record=pdw.Record(every=0), limits=pdw.Limits(on_failure="return"))
    assert r.event_counts["touch_down"] == 0
    assert r.status == "no_steps" and not r.walked
    # the typical gait still walks
    assert pdw.simulate(t_end=3.5, record=pdw.Record(every=0)).status == "walked"


def test_a_stiff_friction_law_stops_at_the_step_budget():
    """rodas4 with a valid v_s = 1e-12 took 1.8 M steps for 10 ms; now it stops at max_steps."""
    r = pdw.simulate(method="rodas4", params=pdw.Params(v_s=1e-12), t_end=0.01,
                     integrator=pdw.Integrator(max_steps=20000), record=pdw.Record(every=0),
                     limits=pdw.Limits(on_failure="return"))
    assert r.status == "diverged" and "step budget" in r.failure["reason"]
    assert r.stats["steps"] + r.stats["rejected"] == 20000
    with pytest.raises(pdw.DivergedError, match="max_steps"):
        pdw.simulate(method="dopri5", params=pdw.Params(d_hip=1e12), t_end=1.0,
                     integrator=pdw.Integrator(max_steps=5000), record=pdw.Record(every=0))


def test_a_fixed_step_run_longer_than_the_budget_is_refused():
    with pytest.raises(pdw.InvalidInputError, match="max_steps"):
        pdw.simulate(t_end=10.0, dt=1e-4, integrator=pdw.Integrator(max_steps=1000))


def test_polling_changes_no_number():
    """The loop returns to Python every POLL_EVERY iterations and resumes exactly: a run with a
    poll every 7 iterations equals one with none, bit for bit (fixed and adaptive)."""
    from pdw.core import _core
    from pdw.core.model import kernel_index, parameter_vector
    p = parameter_vector(pdw.Params.paper())
    x0 = np.array(pdw.X0_PAPER)
    for m in (0, pdw.METHODS.index("rodas4"), pdw.METHODS.index("rk4")):
        o = dict(dt=1e-4, n_steps=8000, record_every=3, record_events=1, fall_hip_height=0.25,
                 fall_depth=0.125, max_speed=1e3, rtol=1e-6, atol=1e-8, event_tol=1e-9,
                 t_end=0.8)
        a = _core.run(kernel_index("paper"), m, x0, p, 0, 1, o, poll_every=0)
        b = _core.run(kernel_index("paper"), m, x0, p, 0, 1, o, poll_every=7, max_records=5)
        assert a["status"] == b["status"] == 1
        for key in ("t", "x", "flags", "contact", "events", "x_final"):
            assert np.array_equal(a[key], b[key]), (m, key)


def test_non_finite_energies_at_a_finite_state_make_the_run_diverged():
    """Result.energies used to hold inf/NaN while x was finite (velocities near 1e160 with
    max_speed out of the way): the status check now calls that run diverged, at the last
    sample before the first non-finite energy."""
    from pdw.sim.simulation import _honest
    r = pdw.simulate(t_end=0.01, integrator=pdw.Integrator(check_step="off"),
                     record=pdw.Record(every=1, energies=True))
    raw = {"x": r.x, "t": r.t, "x_final": r.x_final, "t_final": r.t_final,
           "event_counts": {"touch_down": 1}, "failure": None}
    energies = {k: v.copy() for k, v in r.energies.items()}
    assert _honest(dict(raw), "done", r.params, r.x[0], energies) == "done"
    energies["T"][40] = np.inf
    energies["E"][40] = np.inf
    raw2 = dict(raw)
    assert _honest(raw2, "done", r.params, r.x[0], energies) == "diverged"
    assert raw2["failure"]["t"] == r.t[39] and "energies" in raw2["failure"]["reason"]


def test_an_early_fall_of_a_very_long_run_reserves_no_record_for_t_end():
    """t_end = 1e5 s at dt = 1e-4 (1e9 steps) used to reserve the record for all of them (raw
    MemoryError); the record now grows in chunks, and this walker falls after 1.2 s."""
    x0 = np.array(pdw.X0_PAPER)
    x0[4] = x0[6] = 0.0
    r = pdw.simulate(x0=x0, t_end=1e5, dt=1e-4, record=pdw.Record(every=1),
                     limits=pdw.Limits(on_failure="return"))
    assert r.status == "fell" and r.t_final < 2
    assert len(r.t) >= r.n_steps and r.t[-1] <= r.t_final
    assert np.array_equal(r.t[:100], np.arange(100) * 1e-4)


def test_an_unestimable_step_limit_is_a_step_size_warning():
    """A valid v_s <= 1e-150 made the default step check fail with LinAlgError."""
    p = pdw.Params(v_s=1e-160)
    with pytest.warns(pdw.StepSizeWarning):
        try:
            pdw.simulate(params=p, t_end=1e-3, dt=1e-4, limits=pdw.Limits(on_failure="return"))
        except np.linalg.LinAlgError:               # pragma: no cover - the finding
            pytest.fail("LinAlgError from the step check")


def test_tiny_dt_is_refused_and_singular_advice_is_not_smaller_dt():
    with pytest.raises(pdw.InvalidInputError, match="dt"):
        pdw.simulate(dt=1e-160, t_end=1e-150)
    import inspect
    src = inspect.getsource(pdw.sim.simulation._result)
    assert "Check the masses and inertias" in src
