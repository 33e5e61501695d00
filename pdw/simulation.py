"""`simulate`: one walker, one initial state, one compiled time loop.

The loop (C, GIL released) carries the support flags, the arming of the scuffing
guard and the tangential anchors as discrete state, updated once per step (paper
Fig. 3, MODEL.md sections 5-7). Python is entered once per simulation.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from . import _core, _layout, stability as _stability
from .errors import DivergedError, InvalidInputError, SingularSystemError
from .model import STATE, check_variant, kernel_index, parameter_vector
from .params import Params

METHODS = tuple(name for name, _, _ in _core.method_table())

#: The paper's initial state of the typical gait (Sec. 3.2), flags (swing, support).
X0_PAPER = (0.0, 0.4969, -0.0582, 0.0582, 0.5092, 0.0186, 3.3338, -1.0093)
#: The disturbed start of the paper's Fig. 9.
X0_DISTURBED = (0.0, 0.4840, 0.3285, -0.3285, 0.6875, 0.1375, -1.4206, -1.2684)

_STATUS = {i: s for i, s in enumerate(_layout.STATUS)}
_REASONS = {
    0: "none",
    1: "a non-finite value (NaN or infinity) appeared in the state",
    2: "a velocity exceeded max_speed (runaway state)",
    3: "the hip dropped below fall_hip_height",
    4: "a foot sank deeper than fall_depth below the ground",
    5: "the step's linear system was singular",
    6: "the adaptive step size underflowed (the error test never passed)",
}


class Event(NamedTuple):
    """A support-flag change (MODEL.md section 5) at time t [s] of leg 1 or 2."""

    t: float
    leg: int          # 1 or 2 (the paper's numbering)
    kind: str         # "touch_down" or "lift_off"
    x_D: float        # contact point along the slope [m]
    y_D: float        # contact point height [m]


@dataclass
class Result:
    """Outcome of `simulate`.

    Attributes
    ----------
    t : ndarray (N,)
        Recorded times [s] (every ``record_every``-th step).
    x : ndarray (N, 8)
        Recorded states, layout `pdw.STATE`.
    flags : ndarray (N, 2)
        Support flags of legs 1, 2 at those times.
    Fn, Ft : ndarray (N, 2)
        Normal and tangential contact forces of feet 1, 2 [N] (empty if not recorded).
    events : list of Event
        Every touch-down and lift-off (always kept, whatever the recording).
    status : str
        ``"walked"`` (reached t_end), ``"fell"`` (see `failure`) or ``"diverged"``.
    failure : dict or None
        For a fall or divergence: ``t`` and ``x`` of the last good state, ``reason`` and ``leg``.
    """

    t: np.ndarray
    x: np.ndarray
    flags: np.ndarray
    Fn: np.ndarray
    Ft: np.ndarray
    events: list
    status: str
    failure: dict | None
    x_final: np.ndarray
    t_final: float
    params: Params
    variant: str
    method: str
    dt: float
    t_end: float
    n_steps: int
    wall_time: float
    stats: dict = field(default_factory=dict)

    @property
    def walked(self) -> bool:
        return self.status == "walked"

    def state(self, name: str) -> np.ndarray:
        """Recorded time series of one state component by name, e.g. ``"thetad1"``."""
        return self.x[:, STATE.index(name)]

    def summary(self) -> str:
        s = "%s: %s, %d steps of %.3g s to t = %.4f s, %d events" % (
            self.method, self.status, self.n_steps, self.dt, self.t_final, len(self.events))
        if self.failure:
            s += "; %s at t = %.4f s" % (self.failure["reason"], self.failure["t"])
        return s


def _check_positive(name, value):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError("%s must be a number, got %r" % (name, value)) from None
    if not math.isfinite(v) or v <= 0:
        raise InvalidInputError("%s must be finite and > 0, got %r" % (name, value))
    return v


def check_state(x0, name="x0"):
    x = np.array(x0, dtype=float).ravel() if np.ndim(x0) else None
    if x is None or x.shape != (_core.NX,):
        raise InvalidInputError("%s must have 8 components %s, got shape %s"
                                % (name, STATE, np.shape(x0)))
    for i, v in enumerate(x):
        if not math.isfinite(v):
            raise InvalidInputError("%s[%d] (%s) must be finite, got %r" % (name, i, STATE[i], v))
    return x


def simulate(x0=X0_PAPER, t_end=3.5, dt=1e-4, params=None, variant="paper", method="cdm",
             flags0=(0, 1), record_every=1, record_forces=True, on_failure="raise",
             fall_hip_height=None, fall_depth=None, max_speed=1e3, rtol=1e-6, atol=1e-8,
             h_max=None, event_tol=1e-9, check_step="warn"):
    """Simulate the walker from ``x0`` for ``t_end`` seconds.

    Parameters
    ----------
    x0 : array_like (8,)
        Initial state [x_o, y_o, theta1, theta2, xd_o, yd_o, thetad1, thetad2] (m, rad, m/s,
        rad/s). Default: the paper's typical gait (`X0_PAPER`).
    t_end : float
        Duration [s].
    dt : float
        Step [s] (the paper: 1e-4).
    params : Params, optional
        Default `Params.paper()`.
    variant : {"paper", "consistent"}
        Contact reading of MODEL.md section 6.
    method : str
        Integrator (`pdw.integrators.INTEGRATORS`, docs/integrators.md): ``"cdm"`` is the
        paper's central difference method (MODEL.md section 7); ``"verlet"``, ``"rk4"`` are
        fixed-step, ``"dopri5"`` and ``"rodas4"`` (stiff, recommended) adaptive.
    flags0 : (int, int)
        Initial support flags of legs 1, 2 (the paper's start: leg 1 swing, leg 2 support).
    record_every : int
        Record every k-th step (0: record nothing but events and the final state).
    record_forces : bool
        Also record the contact forces Fn, Ft.
    on_failure : {"raise", "return"}
        A diverged run raises `pdw.DivergedError` (with the partial result attached), or
        returns a Result with status ``"diverged"``. A fall is a status, never an error.
    fall_hip_height : float, optional
        The walker fell when the hip is lower than this above the slope [m]; default 0.5 l.
    fall_depth : float, optional
        ... or when a foot is deeper than this below the ground [m]; default 0.25 l.
    max_speed : float
        Diverged when any velocity component exceeds this [m/s or rad/s].
    rtol, atol : float
        Relative and absolute error tolerances of adaptive methods (ignored by fixed-step
        ones); for adaptive methods ``dt`` is the first trial step.
    h_max : float, optional
        Largest step of adaptive methods [s] (default: no limit).
    event_tol : float
        Adaptive methods locate each flag switch (touch-down, lift-off, arming) to within this
        time [s] and end a step there (docs/integrators.md); fixed-step methods switch at step
        boundaries.
    check_step : {"warn", "error", "off"}
        Fixed-step methods: compare dt with `pdw.stability.step_limit` (the method's estimated
        stability limit for these parameters) and warn (`pdw.StepSizeWarning`) or refuse
        (`pdw.StepSizeError`) above it, naming the limit and the force that sets it.

    Returns
    -------
    Result
    """
    params = Params.paper() if params is None else params
    if not isinstance(params, Params):
        raise InvalidInputError("params must be a pdw.Params, got %s" % type(params).__name__)
    x = check_state(x0)
    t_end = _check_positive("t_end", t_end)
    dt = _check_positive("dt", dt)
    if dt > t_end:
        raise InvalidInputError("dt = %g must not exceed t_end = %g" % (dt, t_end))
    try:
        check_variant(variant)
    except ValueError as e:
        raise InvalidInputError(str(e)) from None
    if method not in METHODS:
        raise InvalidInputError("method must be one of %s, got %r" % (", ".join(METHODS), method))
    if on_failure not in ("raise", "return"):
        raise InvalidInputError("on_failure must be 'raise' or 'return', got %r" % (on_failure,))
    f0 = tuple(int(f) for f in flags0)
    if len(f0) != 2 or any(f not in (0, 1) for f in f0):
        raise InvalidInputError("flags0 must be two values in {0, 1}, got %r" % (flags0,))
    if int(record_every) != record_every or record_every < 0:
        raise InvalidInputError("record_every must be an integer >= 0, got %r" % (record_every,))
    n_steps = int(round(t_end / dt))
    if n_steps > 2**40:
        raise InvalidInputError("t_end/dt = %g steps is too many" % (t_end / dt))
    hip = 0.5 * params.l if fall_hip_height is None else float(fall_hip_height)
    depth = 0.25 * params.l if fall_depth is None else _check_positive("fall_depth", fall_depth)
    max_speed = _check_positive("max_speed", max_speed)
    rtol = _check_positive("rtol", rtol)
    atol = _check_positive("atol", atol)
    h_max = 0.0 if h_max is None else _check_positive("h_max", h_max)
    event_tol = _check_positive("event_tol", event_tol)
    _stability.check_step(dt, params, method, variant, check_step)

    k = kernel_index(variant)
    p = parameter_vector(params)
    start = time.perf_counter()
    raw = _core.run(k, METHODS.index(method), x, p, f0[0], f0[1], dt, n_steps, int(record_every),
                    bool(record_forces), hip, depth, max_speed, rtol, atol, h_max,
                    event_tol=event_tol)
    wall = time.perf_counter() - start
    return _result(raw, params, variant, method, dt, t_end, wall, on_failure)


def _result(raw, params, variant, method, dt, t_end, wall, on_failure):
    status = _STATUS[raw["status"]]
    rc = raw["contact"]
    ic = {n: i for i, n in enumerate(_layout.RECORD_CONTACT)}
    if rc is not None:
        Fn = rc[:, [ic["F_n1"], ic["F_n2"]]]
        Ft = rc[:, [ic["F_t1"], ic["F_t2"]]]
    else:
        Fn = Ft = np.zeros((0, 2))
    ie = {n: i for i, n in enumerate(_layout.EVENT)}
    events = [Event(float(e[ie["t"]]), int(e[ie["leg"]]) + 1, _layout.EVENT_KIND[int(e[ie["kind"]])],
                    float(e[ie["x_D"]]), float(e[ie["y_D"]])) for e in raw["events"]]
    failure = None
    if status in ("fell", "diverged", "singular"):
        f = raw["failure"]
        failure = {"t": f["t"], "x": f["x"], "reason": _REASONS[f["reason"]],
                   "leg": None if f["leg"] < 0 else f["leg"] + 1}
    res = Result(t=raw["t"], x=raw["x"], flags=raw["flags"], Fn=Fn, Ft=Ft, events=events,
                 status={"done": "walked", "singular": "diverged"}.get(status, status),
                 failure=failure, x_final=raw["x_final"], t_final=raw["t_final"], stats=raw["stats"],
                 params=params, variant=variant, method=method, dt=dt, t_end=t_end,
                 n_steps=raw["n_steps"], wall_time=wall)
    if res.status == "diverged" and on_failure == "raise":
        cls = SingularSystemError if status == "singular" else DivergedError
        raise cls("simulation diverged at t = %.6g s (step %d, dt = %g, method %s): %s; "
                  "last good state %s. Try a smaller dt or a stiff method."
                  % (failure["t"], raw["n_steps"], dt, method, failure["reason"],
                     np.array2string(failure["x"], precision=5)),
                  t=failure["t"], x=failure["x"], reason=failure["reason"], result=res)
    return res
