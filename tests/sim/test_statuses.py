"""How a run ends (docs/model.md section 7): a foot deeper than ``fall_depth`` or the hip lower
than ``fall_hip_height`` is a fall, a velocity above ``max_speed`` a divergence, each at the
first state that crosses the limit, with the right leg and reason. The reference is the same run
recorded without the limit, read here sample by sample (cdm: the feet are checked at each
sample before its forces, a new state before it is accepted; the failure's time and state are
the last good sample's)."""
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
    return pdw.simulate(t_end=2.0, dt=DT, record_every=1, check_step="off", fall_depth=1.0,
                        fall_hip_height=0.0)


@pytest.mark.parametrize("depth", [0.0035, 0.0041, 0.0042])
def test_a_foot_too_deep_is_a_fall_of_that_leg(free, depth):
    d = -pdw.contact_forces(free.x).y_D                   # (n, 2) penetration of each foot
    n = int(np.argmax((d > depth).any(axis=1)))
    assert (d[n] > depth).any() and not (d[:n] > depth).any()
    leg = int(np.argmax(d[n] > depth)) + 1
    r = pdw.simulate(t_end=2.0, dt=DT, record_every=1, check_step="off", fall_depth=depth,
                     on_failure="return")
    assert r.status == "fell" and r.failure["reason"] == REASON["foot"]
    assert r.failure["leg"] == leg
    assert r.failure["t"] == pytest.approx(free.t[n], abs=1e-12)
    np.testing.assert_array_equal(r.failure["x"], free.x[n])


@pytest.mark.parametrize("height", [0.49, 0.48])
def test_a_low_hip_is_a_fall(free, height):
    n = int(np.argmax(free.x[:, 1] < height))              # the first state below
    assert n > 0 and free.x[n, 1] < height <= free.x[:n, 1].min()
    r = pdw.simulate(t_end=2.0, dt=DT, record_every=1, check_step="off", fall_hip_height=height,
                     on_failure="return")
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
    kw = dict(t_end=5 * DT, dt=DT / 50 if method == "rk4" else DT, method=method, record_every=1,
              check_step="off", on_failure="return")
    r = pdw.simulate(x0, max_speed=4.0, **kw)
    assert r.status == "diverged" and r.failure["reason"] == REASON["speed"], (k, r.status)
    assert r.failure["t"] == 0.0
    ok = pdw.simulate(x0, max_speed=6.0, **kw)
    assert ok.failure is None or ok.failure["reason"] != REASON["speed"]


# ---- the end-of-run checks of simulate and of the batch (docs/ensemble.md) --------------------

@pytest.mark.parametrize("leg", [1, 2])
def test_a_leg_turning_past_a_full_turn_is_a_runaway(leg):
    """Feet far above the ground, one leg spun at 300 rad/s: it passes 2 pi within 0.05 s; the
    run reached its end but is "diverged" (runaway), whichever leg it is."""
    x0 = np.array(pdw.X0_PAPER, float)
    x0[1] += 1.0
    x0[5 + leg] = 300.0
    r = pdw.simulate(x0, t_end=0.05, dt=1e-5, method="rk4", flags0=(0, 0), record_every=10,
                     check_step="off", on_failure="return")
    assert abs(r.x_final[1 + leg]) > 2 * np.pi > abs(r.x_final[4 - leg])       # only this leg
    assert r.status == "diverged" and "runaway" in r.failure["reason"], r.status
    b = pdw.simulate_batch(x0[None, :], t_end=0.05, dt=1e-5, method="rk4", flags0=(0, 0),
                           check_step="off")
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
    b = pdw.simulate_batch(x0, t_end=0.2, check_step="off")
    assert list(b.status) == ["walked"] * 3
    period = 2 * np.pi * np.sqrt(pdw.Params.paper().l / pdw.Params.paper().g)
    b.t_final[:] = 2.01 * period
    b.n_touch_down[:] = [0, 1, 0]
    b.n_lift_off[:] = [2, 0, 0]
    b.t_final[2] = 1.99 * period                          # too short to judge
    honest(b, x0, pdw.Params.paper())
    assert list(b.status) == ["no_steps", "walked", "walked"]
