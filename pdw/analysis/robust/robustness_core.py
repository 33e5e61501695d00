"""Result types and the pieces of the robustness measures shared by the hybrid and the compliant
model (`pdw.analysis.robust.robustness`, `pdw.analysis.robust.robustness_continuous`; docs/robustness.md)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...core.errors import InvalidInputError


@dataclass
class MaxStep:
    """Outcome of `max_step`.

    Attributes
    ----------
    height : float
        The largest step height [m] tried that the gait survived and returned from, with every
        smaller height tried also survived (0 if even the smallest failed).
    bracket : (float, float)
        (height, the smallest height above it that failed) [m]; inf when none failed up to
        ``h_max``.
    steps_to_return : int
        Steps after the step at ``height`` until the step length and step time stay within
        ``return_tol`` of the gait's.
    direction, model : str
    return_tol : float
        Relative tolerance of "returned" (step length and step time).
    budget : int
        Steps walked after the step.
    trials : list of dict
        Every height tried: ``height``, ``survived``, ``returned``, ``steps_to_return``,
        ``status``, ``round``.
    monotone : bool
        False if a height above a failure succeeded (the success set is not one interval; the
        result is then the first failure's bracket).
    gait : Gait
        The undisturbed gait.
    stable : bool
        False when the gait's largest Floquet multiplier has modulus >= 1: it returns from no
        disturbance, so ``height`` is 0 and no trial is run.
    """

    height: float
    bracket: tuple
    steps_to_return: int
    direction: str
    model: str
    return_tol: float
    budget: int
    trials: list = field(default_factory=list)
    monotone: bool = True
    gait: Any = None
    stable: bool = True

    def __repr__(self) -> str:
        if not self.stable:
            return "MaxStep(%s, %s: the gait is unstable, height 0)" % (self.model,
                                                                      self.direction)
        return ("MaxStep(%s, %s: height=%.6g m, bracket=(%.6g, %.6g), steps_to_return=%d, "
                "%d trials)" % (self.model, self.direction, self.height, self.bracket[0],
                                self.bracket[1], self.steps_to_return, len(self.trials)))


def returned(L, T, L0, T0, return_tol, hold=5):
    """(returned, steps_to_return) of a disturbed walk: its step lengths ``L`` and times ``T``
    (K,) from the disturbed step on, against the gait's ``L0``, ``T0``. Returned when from some
    step on every step is within ``return_tol`` (relative) of the gait in both, for at least
    ``hold`` steps up to the end; steps_to_return is that step's index (-1 if not)."""
    L, T = np.asarray(L, dtype=float), np.asarray(T, dtype=float)
    ok = (np.abs(L / L0 - 1) <= return_tol) & (np.abs(T / T0 - 1) <= return_tol)
    if len(ok) == 0 or not ok[-1]:
        return False, -1
    bad = np.nonzero(~ok)[0]
    k = int(bad[-1] + 1) if len(bad) else 0
    if len(ok) - k < hold:
        return False, -1
    return True, k


@dataclass
class GaitSensitivity:
    """Outcome of `gait_sensitivity`.

    Attributes
    ----------
    norm : float
        The gait sensitivity norm: sqrt(sum over the indicators i and the steps k >= 0 of
        (d g_i(k) / d e)^2), e the floor-height disturbance [m] at step 0 (Hobbelen & Wisse
        2007, Eq. 2 of their paper; docs/robustness.md).
    per_indicator : dict
        The same norm of each indicator alone (units: the indicator's per metre).
    indicators : tuple of str
    A, B, C, D : ndarray
        The linearized step map x(k+1) = A x(k) + B e(k), g(k) = C x(k) + D e(k) (state: the
        hybrid model's post-impact state, 4; the continuous model's section point and the
        previous step's floor change e_prev, 6 + 1, or 7 + 1 with approach speeds).
    method : str
        "exact" (variational equations, saltations; the hybrid model's impact derivative) or
        "fd" (central differences).
    check : dict
        The cross-check: the norm from central differences of the step map (``fd_norm``; with
        ``method="fd"`` on the continuous model ``fd_norm_half_step``) and their relative
        difference (``rel_diff``), the step (``fd_step``); empty with ``check=False``.
    gait : Gait
    """

    norm: float
    per_indicator: dict
    indicators: tuple
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    method: str
    check: dict = field(default_factory=dict)
    gait: Any = None

    def __repr__(self) -> str:
        return "GaitSensitivity(norm=%.6g, %s, method=%s)" % (
            self.norm, ", ".join("%s=%.4g" % kv for kv in self.per_indicator.items()),
            self.method)


def h2_norm(A, B, C, D) -> float:
    """sqrt(||D||^2 + sum_k ||C A^k B||^2): the H2 norm of the discrete system (A, B, C, D)
    for a unit impulse at step 0, by the discrete Lyapunov equation W = A^T W A + C^T C."""
    from scipy.linalg import solve_discrete_lyapunov

    A, B, C, D = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (A, B, C, D))
    rho = max(abs(np.linalg.eigvals(A))) if len(A) else 0.0
    if not rho < 1.0:
        raise InvalidInputError("the gait is not stable (spectral radius %.6g >= 1): its gait "
                                "sensitivity norm is infinite" % rho)
    W = solve_discrete_lyapunov(A.T, C.T @ C)
    return float(math.sqrt(max(0.0, float(np.sum(D * D) + np.sum(B * (W @ B))))))
