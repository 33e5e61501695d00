"""Extension points of the continuation engine (issue #24: problem protocol, predictor and step
control as objects, test functions as objects; pdw.analysis.bifurcation.extension, testfunctions)."""
import numpy as np
import pytest

import pdw
from pdw.analysis.bifurcation.continuation import run_continuation
from pdw.analysis.bifurcation.extension import (
    NaturalPredictor,
    ResidualProblem,
    StepControl,
    TangentPredictor,
)
from pdw.analysis.bifurcation.testfunctions import Event, TestFunction


def _cubic(z, lam):
    """G = z^3 - z + lam: folds at lam = +-2 / (3 sqrt 3) (z = -+1/sqrt 3), closed form."""
    x = z[0]
    return np.array([x ** 3 - x + lam]), np.array([[3 * x * x - 1]]), np.array([1.0])


def test_a_residual_problem_has_its_closed_form_folds():
    z0 = np.roots([1, 0, -1, -1.0]).real.max()           # the root at lam = -1
    b = run_continuation(ResidualProblem(_cubic, 1), [z0], -1.0, 1.0, tol=1e-13,
                         detect=("fold", "branch_point"), max_points=400)
    folds = b.of_kind("fold")
    f = 2 / (3 * np.sqrt(3))
    assert [round(v.value, 6) for v in folds] == [round(f, 6), round(-f, 6)]
    assert all(v.located and abs(abs(v.value) - f) < 1e-7 for v in folds)
    assert abs(folds[0].z[0] - 1 / np.sqrt(3)) < 1e-3
    assert "reached stop" in b.stop_reason and not b.of_kind("branch_point")


def test_predictor_and_step_control_objects():
    """The natural predictor object equals method="natural"; a step control with a fixed step
    (grow = shrink = 1) gives equally spaced points in arclength."""
    prob = ResidualProblem(_cubic, 1)
    z0 = np.roots([1, 0, -1, 3.0]).real.min()            # lam = 3: a single root
    a = run_continuation(prob, [z0], 3.0, 2.0, tol=1e-13, method=NaturalPredictor(),
                         detect=())
    b = run_continuation(prob, [z0], 3.0, 2.0, tol=1e-13, method="natural", detect=())
    np.testing.assert_array_equal(a.values, b.values)
    c = run_continuation(prob, [z0], 3.0, 2.0, tol=1e-13, method=TangentPredictor(),
                         step_control=StepControl(0.05, 1e-6, 0.05, grow=1.0, shrink=1.0),
                         detect=())
    ds = c.step_size[1:-1]
    np.testing.assert_allclose(ds, 0.05)
    with pytest.raises(pdw.InvalidInputError, match="step_min"):
        StepControl(0.1, 0.5, 0.1)


def test_a_users_own_test_function_object():
    class Crossing(TestFunction):
        kind, label = "event", "UZ"

        def values(self, engine, pt):
            return {"event:z = 0.5": float(pt.x[0] - 0.5)}

    z0 = np.roots([1, 0, -1, 3.0]).real.min()
    b = run_continuation(ResidualProblem(_cubic, 1), [z0], 3.0, -3.0, tol=1e-13,
                         detect=(), events=[Crossing()])
    (ev,) = b.of_kind("event")
    assert ev.located and abs(ev.value - (0.5 - 0.125)) < 1e-7      # lam = z - z^3 at 0.5
    with pytest.raises(pdw.InvalidInputError, match="events"):
        run_continuation(ResidualProblem(_cubic, 1), [z0], 3.0, -3.0, events=["z"])
    with pytest.raises(pdw.InvalidInputError, match="quantity"):
        Event("height", 0.4)
