"""Two-parameter continuation of period doublings and folds (issue #24 a; pdw.analysis.bifurcation.codim2)."""
import numpy as np
import pytest

import pdw
from pdw import hybrid as H
from pdw.analysis.bifurcation.codim2 import continue_bifurcation
from pdw.analysis.bifurcation.continuation import continue_gait

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


# --- d. criticality of period doublings ------------------------------------------------------

class _Flip:
    """z' = -(1 + a) z + c z^3 (period n composed): the fixed point 0 flips at a = 0; the
    2-cycle +-x has c x^2 = a, so it exists for a > 0 (the unstable side) when c > 0
    (supercritical) and for a < 0 when c < 0 (subcritical): the closed form the test uses."""

    model, parameter, ADMISSIBLE = "map", "a", {}

    def __init__(self, c, period=1):
        self.c, self.period, self.dim, self.n_maps, self.opts = c, period, 1, 0, {}

    def value(self, mu):
        return float(mu)

    def coord(self, v):
        return float(v)

    def evaluate(self, z, mu, jac=True):
        from pdw.analysis.stepmap.gait_maps import Evaluation
        x, d, dl = float(z[0]), 1.0, 0.0
        for _ in range(self.period):
            self.n_maps += 1
            dl = -(1 + mu) * dl - x + 3 * self.c * x * x * dl
            d *= -(1 + mu) + 3 * self.c * x * x
            x = -(1 + mu) * x + self.c * x ** 3
        info = {"period": 1.0, "step_length": 1.0, "double_support": 0.0,
                "state": np.array([x]), "orbit": np.array([z])}
        return Evaluation(True, "ok", np.array([x]), np.array([[d]]), np.array([dl]), info, {})

    def gait(self, z, mu, ev, mult):
        return pdw.Gait(state=np.asarray(z), period=1.0, step_length=1.0, double_support=0.0,
                        multipliers=mult, model="map")


@pytest.mark.parametrize("c, expected", [(1.0, "supercritical"), (-1.0, "subcritical")])
def test_criticality_of_a_flip_from_the_period_two_branch(c, expected):
    from pdw.analysis.bifurcation.continuation import run_continuation
    b = run_continuation(_Flip(c), [0.0], -0.5, 0.5, tol=1e-12)
    (pd,) = b.of_kind("period_doubling")
    assert abs(pd.value) < 1e-6
    cr = b.criticality(pd, amplitude=0.05)
    assert cr["criticality"] == expected
    x = float(cr["gait"].state[0])
    assert abs(c * x * x - cr["value"]) < 1e-8            # on the closed-form 2-cycle


def test_compass_gait_first_doubling_is_supercritical(pd):
    """Independently, by a long walk: 0.02 deg above the doubling the walker started on the
    period-1 gait settles on a small period-2 orbit (supercritical: it stays near), not away."""
    b = continue_gait(COMPASS, "gamma", 5.0 * DEG, model="hybrid")
    cr = b.criticality(b.of_kind("period_doubling")[0])
    assert cr["criticality"] == "supercritical" and cr["stable"]
    P = COMPASS.replace(gamma=pd.value + 0.02 * DEG)
    y = H.find_gait(P).state + np.array([1e-4, -1e-4, 0.0, 0.0])
    zs = []
    for _ in range(3000):
        y = H.step_map(y, P)
        zs.append(y[0])
    a, b2 = zs[-2], zs[-1]
    assert abs(a - b2) > 1e-5 and abs(a - b2) < 0.02            # a small 2-cycle ...
    assert abs(zs[-3] - b2) < 1e-9                               # ... that repeats


# --- b. branch points ----------------------------------------------------------------------------

class _Pitchfork(_Flip):
    """z' = z + a z - z^3: the branch z = 0 for every a, crossed at a = 0 by z^2 = a."""

    def evaluate(self, z, mu, jac=True):
        from pdw.analysis.stepmap.gait_maps import Evaluation
        x = float(z[0])
        self.n_maps += 1
        info = {"period": 1.0, "step_length": 1.0, "double_support": 0.0,
                "state": np.array([x]), "orbit": np.array([z])}
        return Evaluation(True, "ok", np.array([x + mu * x - x ** 3]),
                          np.array([[1 + mu - 3 * x * x]]), np.array([x]), info, {})


def test_branch_point_located_and_switched_onto_the_crossing_branch():
    from pdw.analysis.bifurcation.continuation import run_continuation
    b = run_continuation(_Pitchfork(0.0), [0.0], -0.5, 0.5, tol=1e-12,
                         detect=("fold", "branch_point"))
    (bp,) = b.of_kind("branch_point")
    assert bp.located and abs(bp.value) < 1e-6 and bp.label == "BP1"
    assert not b.of_kind("fold")
    g = b.switch(bp, amplitude=0.05)
    x, a = float(g.state[0]), g.details["value"]
    assert abs(x) > 1e-3 and abs(x * x - a) < 1e-10             # on z^2 = a
    b2 = run_continuation(_Pitchfork(0.0), [x], a, 0.5, tol=1e-12)
    assert b2.values[-1] == pytest.approx(0.5) and abs(b2.z[-1, 0] ** 2 - 0.5) < 1e-10
