"""The pdw error hierarchy: every failure says when, where and why."""
from __future__ import annotations

import numpy as np


class PdwError(Exception):
    """Base class of every error pdw raises on purpose."""


class InvalidInputError(PdwError, ValueError):
    """A parameter, state, step size or option outside its allowed range (names the field)."""


class SimulationError(PdwError):
    """A simulation that could not go on.

    Attributes
    ----------
    t : float
        Time of the last good state [s].
    x : ndarray, shape (8,)
        That state.
    reason : str
        What went wrong, in words.
    result : Result or None
        What was computed up to the failure (recorded samples and events).
    """

    def __init__(self, message, t=float("nan"), x=None, reason="", result=None):
        super().__init__(message)
        self.t = float(t)
        self.x = None if x is None else np.asarray(x, dtype=float)
        self.reason = reason
        self.result = result


class DivergedError(SimulationError):
    """The state became non-finite or ran away (a velocity above the limit): the step is too
    large for the method at these parameters, or the parameters are unphysical."""


class SingularSystemError(SimulationError):
    """The step's linear system (mass matrix or central-difference matrix) was singular."""


class FellError(SimulationError):
    """The walker fell (raised only when a caller asked for a fall to be an error)."""


class StepSizeError(InvalidInputError):
    """A fixed step size above the method's estimated stability limit for the parameters
    (`pdw.simulate(..., check_step="error") <pdw.simulate>`, ``pdw.sim.stepsize.step_limit``).

    Attributes: ``dt`` (the step asked for), ``limit`` (the estimated limit [s]) and ``force``
    (the force element that sets it)."""

    def __init__(self, message, dt=float("nan"), limit=float("nan"), force=""):
        super().__init__(message)
        self.dt = float(dt)
        self.limit = float(limit)
        self.force = force


class StepSizeWarning(UserWarning):
    """A fixed step size above the method's estimated stability limit (`pdw.simulate` with the
    default ``check_step="warn"``); same attributes as `StepSizeError`."""

    def __init__(self, message, dt=float("nan"), limit=float("nan"), force=""):
        super().__init__(message)
        self.dt = float(dt)
        self.limit = float(limit)
        self.force = force


class PdwDeprecationWarning(DeprecationWarning):
    """A spelling of before that still works for one release: an old keyword or positional
    argument of `pdw.simulate` / `pdw.simulate_batch`, a scene key that moved, an old import
    path of ``pdw.analysis``. The message names the new spelling. A `DeprecationWarning`, so
    ``-W error::DeprecationWarning`` catches it; its own class lets a program (or pdw's own
    tests) turn pdw's deprecations into errors without a third party's."""
