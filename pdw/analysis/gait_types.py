"""Small value types describing a periodic gait (shared by the gait finders).

`Gait` is what a fixed-point search returns: the state on its Poincaré section, the period,
the step length, the double-support time and the Floquet multipliers. The meaning of
``state`` depends on the model that found the gait (``model``); see its docstring.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from ..core.errors import PdwError


@dataclass(frozen=True, eq=False)
class Gait:
    """A period-one gait (a fixed point of a step map).

    Attributes
    ----------
    state : ndarray
        The state on the Poincaré section. For ``model == "hybrid"`` (``pdw.hybrid``): the
        reduced state just after heel strike, after relabelling, [theta_st, theta_sw,
        thetad_st, thetad_sw] (rad, rad/s; angles from the slope normal, docs/model.md section 2),
        with theta_sw = -theta_st (both feet on the ground).
    period : float
        Touch-down to touch-down [s].
    step_length : float
        Footprint spacing along the slope [m] (docs/model.md section 8: the swing foot's contact
        point at touch-down minus the other foot's contact point at its own touch-down).
    double_support : float
        Double-support time per step [s]; 0 for the hybrid model.
    multipliers : ndarray (complex)
        Floquet multipliers: eigenvalues of the Jacobian of the step map on the section,
        by finite differences (``details["fd_step"]``), sorted by decreasing modulus.
    model : str
        Which model found the gait ("hybrid", ...).
    params : object
        The `pdw.Params` of the gait.
    details : mapping
        Model-specific extras (energy lost per step, impulse, residual, tolerances ...).
    """

    state: np.ndarray
    period: float
    step_length: float
    double_support: float
    multipliers: np.ndarray
    model: str = "hybrid"
    params: Any = None
    details: Mapping[str, Any] = field(default_factory=dict)

    @property
    def speed(self) -> float:
        """Mean walking speed along the slope, step_length / period [m/s]."""
        return self.step_length / self.period

    @property
    def stable(self) -> bool:
        """All multipliers strictly inside the unit circle."""
        return bool(np.all(np.abs(self.multipliers) < 1.0))

    def __repr__(self):
        mods = ", ".join("%.4g" % m for m in np.abs(self.multipliers))
        return ("<pdw.Gait (%s model) %s: period %.6g s, step length %.6g m, speed %.4g m/s, "
                "double support %.4g s\n  |multipliers| = [%s]\n  section state = %s>"
                % (self.model, "stable" if self.stable else "unstable", self.period,
                   self.step_length, self.speed, self.double_support, mods,
                   np.array2string(np.asarray(self.state), precision=6, max_line_width=200)))


class GaitNotFoundError(PdwError):
    """No periodic gait was found from any starting guess.

    Attributes
    ----------
    attempts : list of dict
        One entry per starting guess: the guess and what happened to it.
    """

    def __init__(self, message, attempts=()):
        super().__init__(message)
        self.attempts = list(attempts)
