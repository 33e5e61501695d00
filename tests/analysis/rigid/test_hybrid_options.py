"""Every option of the hybrid model's step map (`pdw.hybrid.DEFAULT_OPTIONS`,
pdw/core/csrc/pdw_hybrid_sim.h) reaches its own field: each is shown by an effect that only
that option has (a status, a bound on the step count, the event time's precision, the sample
spacing), and options of the same kind given the same value do not give the same run."""
import math

import numpy as np
import pytest

import pdw
from pdw.analysis.rigid import hybrid

H = pdw.hybrid
COMPASS = H.compass_gait_params()


@pytest.fixture(scope="module")
def gait():
    return H.find_gait(COMPASS).state


@pytest.fixture(scope="module")
def ref(gait):
    r = H.step(gait, COMPASS)
    assert r["status"] == "ok" and 0.5 < r["t_strike"] < 1.0
    return r


def test_options_are_the_c_defaults():
    assert set(H.DEFAULT_OPTIONS) == {"rtol", "atol", "h0", "h_max", "t_max", "event_tol",
                                      "min_step_angle", "fall_angle", "max_steps", "dt_out",
                                      "dh", "max_slope"}


def test_tolerances(gait, ref):
    r, a = H.step(gait, COMPASS, rtol=1e-8), H.step(gait, COMPASS, atol=1e-8)
    assert r["n_steps"] < ref["n_steps"] and a["n_steps"] < ref["n_steps"]
    # sc = atol + rtol max|y|: the same number as rtol or as atol is another tolerance
    assert not np.array_equal(r["y_plus"], a["y_plus"])


def test_first_and_largest_step(gait, ref):
    h0 = H.step(gait, COMPASS, h0=1e-9)
    assert h0["status"] == "ok" and h0["n_steps"] > ref["n_steps"]   # climbs from 1 ns
    hm = H.step(gait, COMPASS, h_max=1e-3)
    assert hm["status"] == "ok" and hm["n_steps"] >= hm["t_strike"] / 1e-3
    assert ref["n_steps"] < hm["t_strike"] / 1e-3 / 5                  # the default is 10 ms


def test_time_limits(gait, ref):
    t = H.step(gait, COMPASS, t_max=0.1)
    assert t["status"] == "no_strike" and 0.1 <= t["t_strike"] < 0.2
    m = H.step(gait, COMPASS, max_steps=3)
    assert m["status"] == "max_steps" and m["n_steps"] == 3


def test_event_tolerance(gait, ref):
    e = H.step(gait, COMPASS, event_tol=1e-3)
    assert e["status"] == "ok"
    assert 1e-9 < abs(e["t_strike"] - ref["t_strike"]) <= 1e-3


def test_angles(gait, ref):
    # the compass gait's legs open to 2 x 0.27 rad: a larger minimum step angle never arms
    assert 2 * abs(gait[0]) < 1.0
    a = H.step(gait, COMPASS, min_step_angle=1.0)
    assert a["status"] != "ok" and a["t_strike"] > ref["t_strike"]
    f = H.step(gait, COMPASS, fall_angle=0.1)            # the stance leg starts at 0.27 rad
    assert f["status"] == "fell" and f["t_strike"] < 0.01


def test_sample_spacing(gait):
    tr = H.simulate_hybrid(COMPASS, gait, 1, dt_out=0.05)
    np.testing.assert_allclose(np.diff(tr.t)[:-1], 0.05, rtol=1e-9)


@pytest.mark.parametrize("opt,value", [("rtol", -1.0), ("atol", 0.0), ("min_step_angle", math.nan),
                                       ("fall_angle", 10.0), ("max_steps", 0), ("dt_out", -1e-3),
                                       ("h_max", math.inf), ("event_tol", "1e-9")])
def test_hybrid_options_are_range_checked(opt, value):
    """rtol = -1 was accepted; min_step_angle = nan reported a good step as "fell"."""
    y = np.array([0.2, -0.2, -1.0, -0.4])
    with pytest.raises(pdw.InvalidInputError, match=opt):
        hybrid.step(y, **{opt: value})


def test_hybrid_state_is_not_reshaped():
    with pytest.raises(pdw.InvalidInputError, match="shape"):
        hybrid.step(np.array([[0.2, -0.2], [-1.0, -0.4]]))
