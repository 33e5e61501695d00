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
