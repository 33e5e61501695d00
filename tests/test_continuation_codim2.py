"""Two-parameter continuation of period doublings and folds (issue #24 a; pdw.analysis.codim2)."""
import numpy as np
import pytest

import pdw
from pdw import hybrid as H
from pdw.analysis.codim2 import continue_bifurcation
from pdw.analysis.continuation import continue_gait

COMPASS = H.compass_gait_params()
DEG = np.pi / 180


@pytest.fixture(scope="module")
def pd():
    b = continue_gait(COMPASS, "gamma", 5.0 * DEG, model="hybrid")
    return b.of_kind("period_doubling")[0]


def test_period_doubling_curve_matches_independently_located_doublings(pd):
    """The compass gait's doubling followed in c (leg mass position b; b/a = c/(1 - c)) from
    0.5 to 0.7, over slopes 4.39 -> 1.6 deg: at c = 0.55 and 0.65 the curve's slope equals the
    doubling that a one-parameter continuation in the slope locates at that c, and the
    finite-difference multipliers of find_gait are inside the unit circle just below it and
    below -1 just above it."""
    cv = continue_bifurcation(pd, "c", 0.7, at=[0.55, 0.65])
    assert cv.values.shape == (len(cv), 2) and "reached stop" in cv.stop_reason
    assert cv.values[:, 0].min() < 2.0 * DEG and cv.values[:, 0].max() > 4.0 * DEG
    assert np.all(np.abs(np.abs(cv.multipliers[:, 0]) - 1.0) < 1e-6)      # one at -1 all along
    assert np.all(np.real(cv.multipliers[:, 0]) < 0)
    for c in (0.55, 0.65):
        i = int(np.argmin(np.abs(cv.values[:, 1] - c)))
        assert cv.values[i, 1] == pytest.approx(c, abs=1e-12)
        P = COMPASS.replace(c=c)
        b = continue_gait(P, "gamma", 5.0 * DEG, model="hybrid", value=1.0 * DEG,
                          start=H.find_gait(P.replace(gamma=1.0 * DEG)).state)
        (pd1,) = b.of_kind("period_doubling")
        assert abs(pd1.value - cv.values[i, 0]) < 1e-7
        lo = H.find_gait(P.replace(gamma=cv.values[i, 0] - 0.01 * DEG))
        hi = H.find_gait(P.replace(gamma=cv.values[i, 0] + 0.01 * DEG))
        assert np.all(np.abs(lo.multipliers) < 1.0) and np.min(np.real(hi.multipliers)) < -1.0


def test_fold_curve_in_the_hip_damping():
    """The d_hip = 0.2 compass gait's fold (minimum slope, 2.3356 deg) followed in d_hip: at
    d_hip = 0.25 it equals the fold that a one-parameter continuation in the slope finds."""
    P = COMPASS.replace(d_hip=0.2)
    b = continue_gait(P, "gamma", 0.2 * DEG, model="hybrid", max_points=60)
    (fold,) = b.of_kind("fold")
    cv = continue_bifurcation(fold, "d_hip", 0.3, at=[0.25])
    assert cv.kind == "fold"
    assert np.all(np.min(np.abs(cv.multipliers - 1.0), axis=1) < 1e-5)
    i = int(np.argmin(np.abs(cv.values[:, 1] - 0.25)))
    b2 = continue_gait(COMPASS.replace(d_hip=0.25), "gamma", 0.2 * DEG, model="hybrid",
                       value=3.5 * DEG, max_points=80,
                       start=H.find_gait(COMPASS.replace(d_hip=0.25, gamma=3.5 * DEG)).state)
    (f2,) = b2.of_kind("fold")
    assert abs(f2.value - cv.values[i, 0]) < 1e-7


def test_bad_requests_are_refused(pd):
    with pytest.raises(pdw.InvalidInputError, match="parameter"):
        continue_bifurcation(pd, "gamma", 0.1)
    with pytest.raises(pdw.InvalidInputError, match="parameter"):
        continue_bifurcation(pd, "slope", 0.1)
    with pytest.raises(pdw.InvalidInputError, match="bifurcation"):
        continue_bifurcation("PD1", "c", 0.7)
