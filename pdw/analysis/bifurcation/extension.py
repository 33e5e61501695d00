"""Extension points of the continuation engine: problems, predictors, step control.

* **Problem protocol** (`ContinuationProblem`): what `run_continuation` needs of a problem. The
  engine solves G(z, lambda) = P(z) - z = 0 from ``evaluate`` (P, M = dP/dz, dP/dlambda). A
  problem given as a residual (G, dG/dz, dG/dlambda) is adapted by `ResidualProblem`
  (P = z + G, M = I + dG/dz, dP/dlambda = dG/dlambda); the gait maps of
  `pdw.analysis.stepmap.gait_maps` and the augmented problem of `pdw.analysis.bifurcation.codim2` are problems.
* **Predictors** (`TangentPredictor`: pseudo-arclength, the default; `NaturalPredictor`: a step
  in the parameter alone): ``predict(engine, point, ds) -> (x_pred, border)``, the corrector
  solving [G(x); border . (x - x_pred)] = 0.
* **Step control** (`StepControl`): the first step and its bounds, and how ds changes after a
  correction in a given number of Newton iterations or after a failure.
"""
from __future__ import annotations

from typing import Any, Callable, Protocol

import numpy as np

from ...core.errors import InvalidInputError
from ..gait_types import Gait
from ..stepmap.gait_maps import Evaluation


class ContinuationProblem(Protocol):
    """What the engine needs of a problem (duck-typed; `pdw.analysis.stepmap.gait_maps`)."""

    dim: int
    model: str
    parameter: str
    period: int
    ADMISSIBLE: dict
    n_maps: int

    def value(self, mu: float) -> float: ...          # parameter coordinate -> value

    def coord(self, value: float) -> float: ...       # value -> parameter coordinate

    def evaluate(self, z: Any, mu: float, jac: bool = True) -> Evaluation: ...

    def gait(self, z: Any, mu: float, ev: Evaluation, multipliers: Any) -> Gait: ...


class ResidualProblem:
    """A problem given by its residual: ``residual(z, lam) -> (G (n,), dG/dz (n, n),
    dG/dlam (n,))``, continued in ``lam`` (named ``parameter``). The engine sees P = z + G;
    the "multipliers" of a point are then the eigenvalues of I + dG/dz, so only the fold and
    branch-point test functions (and user events) mean anything: use
    ``detect=("fold", "branch_point")``."""

    model = "residual"
    ADMISSIBLE: dict = {}
    period = 1

    def __init__(self, residual: Callable, dim: int, parameter: str = "lambda"):
        if not callable(residual):
            raise InvalidInputError("residual must be callable (z, lam) -> (G, G_z, G_lam)")
        self.residual, self.dim, self.parameter = residual, int(dim), str(parameter)
        self.n_maps = 0
        self.opts: dict = {}

    def value(self, mu):
        return float(mu)

    def coord(self, value):
        return float(value)

    def evaluate(self, z, mu, jac=True) -> Evaluation:
        self.n_maps += 1
        z = np.asarray(z, dtype=float)
        try:
            G, Gz, Gl = self.residual(z, float(mu))
        except (ArithmeticError, ValueError) as e:
            return Evaluation(False, "residual failed: %s" % e)
        G = np.asarray(G, dtype=float).reshape(self.dim)
        if not np.isfinite(G).all():
            return Evaluation(False, "non-finite residual")
        info = {"period": 0.0, "step_length": 0.0, "double_support": 0.0, "state": z.copy(),
                "orbit": z[None, :].copy()}
        return Evaluation(True, "ok", z + G,
                          np.eye(self.dim) + np.asarray(Gz, dtype=float).reshape(self.dim,
                                                                                 self.dim),
                          np.asarray(Gl, dtype=float).reshape(self.dim), info, {})

    def gait(self, z, mu, ev, multipliers) -> Gait:
        return Gait(state=np.asarray(z), period=0.0, step_length=0.0, double_support=0.0,
                    multipliers=multipliers, model=self.model)


class TangentPredictor:
    """Pseudo-arclength: predict x + ds t along the unit tangent; border t (passes folds)."""

    natural = False

    def predict(self, engine, pt, ds):
        return pt.x + ds * pt.tangent, pt.tangent


class NaturalPredictor:
    """Natural continuation: u + ds along the tangent scaled to a unit step in u; border e_u
    (the parameter is fixed by the step; it cannot pass a fold)."""

    natural = True

    def predict(self, engine, pt, ds):
        e = np.zeros(engine.n + 1)
        e[-1] = 1.0
        d = pt.tangent / pt.tangent[-1] if abs(pt.tangent[-1]) > 1e-12 else e
        return pt.x + ds * d, e


PREDICTORS = {"pseudo_arclength": TangentPredictor, "natural": NaturalPredictor}


class StepControl:
    """Arclength step control (scaled coordinates: the requested range is 1).

    ``first`` is the first step; after a correction in <= ``fast`` Newton iterations the step
    grows by ``grow`` (up to ``step_max``), after >= ``slow`` it shrinks by ``shrink`` (down
    to ``step_min``); a failed correction halves it (`failed`: below ``step_min`` the family
    ends)."""

    def __init__(self, first=0.02, step_min=1e-6, step_max=0.1, grow=1.5, shrink=0.7, fast=2,
                 slow=5):
        if not 0 < step_min <= step_max:
            raise InvalidInputError("step_min (%r) must be > 0 and not exceed step_max (%r)"
                                    % (step_min, step_max))
        if not (grow >= 1.0 and 0.0 < shrink <= 1.0 and 0 <= fast < slow):
            raise InvalidInputError("StepControl: need grow >= 1, 0 < shrink <= 1 and "
                                    "fast < slow, got %r, %r, %r, %r"
                                    % (grow, shrink, fast, slow))
        self.first = min(max(first, step_min), step_max)
        self.step_min, self.step_max = step_min, step_max
        self.grow, self.shrink, self.fast, self.slow = grow, shrink, fast, slow

    def accepted(self, ds, iterations):
        if iterations <= self.fast:
            return min(ds * self.grow, self.step_max)
        if iterations >= self.slow:
            return max(ds * self.shrink, self.step_min)
        return ds

    def failed(self, ds):
        """The halved step, or None below ``step_min`` (the end of the family)."""
        ds *= 0.5
        return None if ds < self.step_min else ds
