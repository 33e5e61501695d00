"""`simulate`: one walker, one initial state, one compiled time loop.

The loop (C, GIL released) carries the support flags, the arming of the scuffing
guard and the tangential anchors as discrete state, updated once per step (paper
Fig. 3, docs/model.md sections 5-7). Python is entered once per simulation.

Why this module is long: `simulate` is the one entry point of a run, with about 30
parameters, each typed, documented (numpydoc, units) and checked here before the compiled
loop is entered, and `Result` is what it returns; the checks stay next to the documentation
of what they check.
"""
from __future__ import annotations

import math
import os
import pathlib
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Iterable, Literal, NamedTuple, Protocol

import numpy as np
from numpy.typing import ArrayLike

from ..core import _core, _layout, checks
from ..core import contact as _contact
from ..core import integrators as _integrators
from ..core.errors import (
    DivergedError,
    InvalidInputError,
    SingularSystemError,
)
from ..core.ground import Ground
from ..core.integrators import METHODS
from ..core.model import STATE, check_variant, kernel_index, parameter_vector
from ..core.params import X0_PAPER, Params
from . import dense as _dense
from . import io as _io
from . import stepsize as _stepsize
from .buffers import RecordBuffer
from .gait import Steps, steps_from_rows

if TYPE_CHECKING:                       # annotations only: optional dependencies
    import pandas
    import xarray


class SceneLike(Protocol):
    """What `simulate` takes in place of ``x0``: a `pdw.Scene` (duck-typed, scene.py is above)."""

    def simulate_kwargs(self) -> dict: ...

_STATUS = {i: s for i, s in enumerate(_layout.STATUS)}
_REASONS = {
    0: "none",
    1: "a non-finite value (NaN or infinity) appeared in the state",
    2: "a velocity exceeded max_speed (runaway state)",
    3: "the hip dropped below fall_hip_height",
    4: "a foot sank deeper than fall_depth below the ground",
    5: "the step's linear system was singular",
    6: "the adaptive step size underflowed (the error test never passed)",
    7: "the step budget (max_steps) was used up before t_end",
    8: "the walker left the ground's defined extent (the hip came within a leg length of "
       "Ground.s_range's ends; docs/terrain.md)",
}
#: Smallest step [s] (a smaller one makes the step matrices singular in double precision).
DT_MIN = 1e-12
#: Runaway bounds checked on every recorded and the final state of a run that reached its end:
#: the hip more than RUNAWAY_HIP leg lengths above its start, or a leg turned by more than
#: RUNAWAY_ANGLE [rad] (a full turn).
RUNAWAY_HIP = 2.0
RUNAWAY_ANGLE = 2 * math.pi
#: A run that reached t_end without a single touch-down in at least NO_STEP_PERIODS pendulum
#: periods 2 pi sqrt(l/g) did not walk: status "no_steps".
NO_STEP_PERIODS = 2.0


class Event(NamedTuple):
    """A support-flag change (docs/model.md section 5) at time t [s] of leg 1 or 2."""

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
    x : ndarray (N, nx)
        Recorded states, columns `state_names`: layout `pdw.STATE` (nx = 8), with LuGre's
        bristle states z1, z2 [m] after it (nx = 10).
    flags : ndarray (N, 2)
        Support flags of legs 1, 2 at those times.
    Fn, Ft : ndarray (N, 2)
        Normal and tangential contact forces of feet 1, 2 [N] (empty if not recorded).
    events : list of Event
        Every touch-down and lift-off (empty when ``record_events=False``; `event_counts`
        counts them either way).
    status : str
        ``"walked"`` (reached t_end, or the requested number of gait steps, having stepped),
        ``"periodic"`` (stopped because the last steps agreed), ``"fell"`` (see `failure`),
        ``"diverged"`` (non-finite, runaway or airborne state, non-finite energies, step
        budget), ``"no_steps"`` (reached t_end without a touch-down in `NO_STEP_PERIODS`
        pendulum periods or more) or ``"interrupted"`` (Ctrl-C: the partial result rides on
        the ``KeyboardInterrupt`` as ``.result``).
    failure : dict or None
        For a fall or divergence: ``t`` and ``x`` of the last good state, ``reason`` and ``leg``.
    params : Params
        The parameters simulated: with the parameters of absent force elements zeroed
        (`Params.without`) when ``features`` was given.
    gait : Steps
        The gait descriptors computed online in the compiled loop (docs/model.md section 8, the
        definitions of `pdw.steps`): the last ``min(n_gait_steps, pdw.core._layout.STEP_RING)``
        complete steps. A run stopped by a stop condition ends at a touch-down, so its last
        step's double support is NaN (not known yet).
    n_gait_steps : int
        Complete gait steps of the whole run.
    event_counts : dict
        ``{"touch_down": n, "lift_off": n}`` over the whole run.
    stop_reason : str
        ``"t_end"``, ``"steps"`` (stop_steps reached), ``"periodic"``, or the failure status.
    energies : dict or None
        With ``record_energies``: T, V_gravity, V_hip and E [J] at the recorded samples.
    sol : DenseOutput or None
        With ``dense_output=True``: the interpolant between accepted steps (`pdw.sim.dense`).
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
    gait: Steps | None = None
    n_gait_steps: int = 0
    event_counts: dict = field(default_factory=dict)
    events_recorded: bool = True
    stop_reason: str = "t_end"
    energies: dict | None = None
    features: tuple = _layout.FEATURES
    scene: object = None
    sol: object = None
    provenance: dict | None = None
    contact: _contact.Contact | None = None      # the pdw.Contact simulated (laws, parameters)
    ground: Ground | None = None                 # the pdw.Ground walked on (docs/terrain.md)

    @property
    def walked(self) -> bool:
        """Did the walker keep walking to the end of the run (t_end or a stop condition)?"""
        return self.status in ("walked", "periodic")

    @property
    def state_names(self) -> tuple:
        """Names of the columns of `x`: `pdw.STATE`, and the bristle states z1, z2 under the
        LuGre friction law (`pdw.core._layout.STATE_LAYOUTS`)."""
        return self.contact.state_names if self.contact is not None else STATE

    def state(self, name: str) -> np.ndarray:
        """Recorded time series of one state component by name (`state_names`), e.g.
        ``res.state("thetad1")``: ndarray (M,) aligned with ``res.t`` [m, rad, m/s or rad/s]."""
        return self.x[:, self.state_names.index(name)]

    def __repr__(self):
        counts = self.event_counts or {}
        lines = ["<pdw.Result %s: %s variant, %s, t = 0 .. %.6g s of %.6g s, %d steps, %.3g s wall"
                 % (self.status, self.variant, self.method if self.method in ("dopri5", "rodas4")
                    else "%s dt = %.3g s" % (self.method, self.dt), self.t_final, self.t_end,
                    self.n_steps, self.wall_time),
                 "  events: %d touch-downs, %d lift-offs; %d gait steps; stopped by %s"
                 % (counts.get("touch_down", 0), counts.get("lift_off", 0), self.n_gait_steps,
                    self.stop_reason),
                 "  recorded: %d samples%s%s" % (len(self.t), " + forces" if np.size(self.Fn) else "",
                                                  " + energies" if self.energies else "")]
        if self.gait is not None and len(self.gait):
            lines.append("  last step: " + self.gait.describe_step())
        if self.failure:
            lines.append("  failure: %s at t = %.6g s" % (self.failure["reason"], self.failure["t"]))
        return "\n".join(lines) + ">"

    def to_dataframe(self) -> pandas.DataFrame:
        """The recorded samples as a pandas DataFrame (`pdw.sim.io.result_to_dataframe`; needs
        pandas): one row per sample, index t [s], columns the state (`pdw.STATE`), the flags,
        the forces and (if recorded) the energies; units in ``df.attrs["units"]``."""
        return _io.result_to_dataframe(self)

    def to_xarray(self) -> xarray.Dataset:
        """The run as an xarray Dataset (`pdw.sim.io.result_to_xarray`; needs xarray):
        ``x`` (time x state), ``flags`` and forces (time x leg), units in each variable's
        ``attrs["units"]``, provenance and settings in ``ds.attrs``."""
        return _io.result_to_xarray(self)

    def save(self, path: str | os.PathLike) -> pathlib.Path:
        """Write the run with its provenance (pdw version, INPUT_HASH, source revision,
        settings, scene, time); `pdw.load` reads it back.

        Parameters
        ----------
        path : str or path-like
            ``.npz`` (NumPy, compressed, metadata as JSON) or ``.nc`` (NetCDF through xarray).

        Returns
        -------
        pathlib.Path
            The file written.
        """
        return _io.save(self, path)

    def summary(self) -> str:
        """One line: method, status, steps and step size, end time, events, gait steps (and the
        stop condition that ended the run)."""
        n_ev = sum(self.event_counts.values()) if self.event_counts else len(self.events)
        s = "%s: %s, %d steps of %.3g s to t = %.4f s, %d events, %d gait steps" % (
            self.method, self.status, self.n_steps, self.dt, self.t_final, n_ev, self.n_gait_steps)
        if self.stop_reason in ("steps", "periodic"):
            s += " (stopped: %s)" % self.stop_reason
        if self.failure:
            s += "; %s at t = %.4f s" % (self.failure["reason"], self.failure["t"])
        return s


def _check_positive(name, value):
    return checks.positive(name, value)


def check_state(x0, name="x0"):
    """x0: the mechanical state (`pdw.STATE`) or a friction law's (`Contact.run_state`)."""
    n = np.shape(x0)[0] if np.ndim(x0) == 1 else _core.NX
    shape = (n,) if n in {len(v) for v in _layout.STATE_LAYOUTS.values()} else (_core.NX,)
    return checks.real_array(name, x0, [shape], labels=STATE if shape == (_core.NX,) else None)


_DEFAULTS = dict(t_end=3.5, dt=1e-4, params=None, variant="paper", method="cdm", flags0=(0, 1),
                 record_every=1, record_forces=True, on_failure="raise", fall_hip_height=None,
                 fall_depth=None, max_speed=1e3, rtol=1e-6, atol=1e-8, h_max=None, event_tol=1e-9,
                 features=None, record_events=True, record_energies=False, stop_steps=0,
                 periodic_steps=0, periodic_tol=1e-3, check_step="warn", t_eval=None,
                 dense_output=False, out=None, max_steps=None,
                 contact=None, approach_speeds0=None, stop_touch_down=0, ground=None)


def simulate(x0: ArrayLike | SceneLike = X0_PAPER, t_end: float = 3.5, dt: float = 1e-4,
             params: Params | None = None, variant: Literal["paper", "consistent"] = "paper",
             method: str = "cdm", flags0: tuple[int, int] = (0, 1), record_every: int = 1,
             record_forces: bool = True, on_failure: Literal["raise", "return"] = "raise",
             fall_hip_height: float | None = None, fall_depth: float | None = None,
             max_speed: float = 1e3, rtol: float = 1e-6, atol: float = 1e-8,
             h_max: float | None = None, event_tol: float = 1e-9, *,
             features: Iterable[str] | None = None, record_events: bool = True,
             record_energies: bool = False, stop_steps: int = 0, periodic_steps: int = 0,
             periodic_tol: float = 1e-3, check_step: Literal["warn", "error", "off"] = "warn",
             t_eval: ArrayLike | None = None, dense_output: bool = False,
             out: RecordBuffer | None = None, max_steps: int | None = None,
             contact: _contact.Contact | dict | str | None = None,
             approach_speeds0: tuple[float, float] | None = None,
             stop_touch_down: int = 0, ground: Ground | dict | None = None) -> Result:
    """Simulate the walker from ``x0`` for ``t_end`` seconds (or run a `pdw.Scene`).

    ``simulate(scene)`` runs the scene (as `pdw.run`); no other argument may be given then.

    Parameters
    ----------
    x0 : array_like (8,) or (nx,), or Scene
        Initial state [x_o, y_o, theta1, theta2, xd_o, yd_o, thetad1, thetad2] (m, rad, m/s,
        rad/s), with LuGre friction optionally followed by the bristle states z1, z2 [m]
        (default 0; nx = 10). Default: the paper's typical gait (`X0_PAPER`).
    t_end : float
        Duration [s].
    dt : float
        Step [s] (the paper: 1e-4).
    params : Params, optional
        Default `Params.paper()`.
    variant : {"paper", "consistent"}
        Contact reading of docs/model.md section 6.
    method : str
        Integrator (`pdw.core.integrators.INTEGRATORS`, docs/integrators.md): ``"cdm"`` is the
        paper's central difference method (docs/model.md section 7); ``"verlet"``, ``"rk4"`` are
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
    features : iterable of str, optional
        Force elements present (`pdw.core._layout.FEATURES`; default all). The absent ones are
        switched off: a specialized generated kernel if there is one, else the general kernel
        with their parameters zeroed (`Params.without`). Under LuGre friction the same, except
        that a run without ``friction`` has no bristles: it runs the normal law with the
        default friction law switched off (8-entry state; `pdw.Contact.for_features`).
    record_events : bool
        Keep the list of events (False: only their counts and the online gait analysis, O(1)
        memory however long the run).
    record_energies : bool
        Also return the energies at the recorded samples (needs ``record_every > 0``).
    stop_steps : int
        Stop after this many complete gait steps (0: no limit); status ``"walked"``,
        ``stop_reason`` ``"steps"``.
    periodic_steps, periodic_tol : int, float
        With ``periodic_steps = k >= 2``: stop (status ``"periodic"``) as soon as the last k
        steps agree, each of L, travel, P and cycle within ``periodic_tol`` relative
        (``max - min <= tol * abs(latest)``). 0: off.
    stop_touch_down : {0, 1, 2}
        1 or 2: stop at that leg's first touch-down (status ``"walked"``, ``stop_reason``
        ``"touch_down"``); the final state is the event's (located to ``event_tol`` by the
        adaptive methods). The touch-down Poincare map's end (`pdw.limit_cycle`). 0: off.
    check_step : {"warn", "error", "off"}
        Fixed-step methods: compare dt with `pdw.sim.stepsize.step_limit` (the method's estimated
        stability limit for these parameters) and warn (`pdw.StepSizeWarning`) or refuse
        (`pdw.StepSizeError`) above it, naming the limit and the force that sets it. With
        another contact law, the default law's estimate times the law's factor fitted on its
        measured limits (`pdw.sim.stepsize.LAW_CALIBRATION`, docs/contact_laws.md).
    t_eval : array_like (M,), optional
        Times [s] (non-decreasing, in [0, t_end]) at which to return the solution, as
        ``solve_ivp``: ``Result.t`` is then t_eval (up to the run's end) and ``x``, ``flags``,
        ``Fn``, ``Ft`` (and ``energies``) are their values there, from the method's dense
        output (`pdw.sim.dense`: quintic Hermite for methods of order >= 4, cubic for cdm and
        verlet), every state entry (LuGre's bristle states too). Needs ``record_every=1``.
    dense_output : bool
        Also return the interpolant: ``Result.sol(t)`` -> (nx,) or (len(t), nx), exact at
        every accepted step (``Result.sol.t``); nx = 8, or 10 with LuGre (`pdw.Contact.nx`).
    out : RecordBuffer, optional
        Record into these reusable arrays (`pdw.sim.buffers.RecordBuffer`) instead of fresh
        ones: no page faults on a repeated run, of any contact law. The Result's t, x, flags,
        Fn, Ft are then views into ``out``, overwritten by the next run that uses it.
    max_steps : int, optional
        Budget of integration steps of the adaptive methods (default 10^6 + 2 10^6 t_end/s);
        a run that uses it up stops early, saying so. Fixed-step methods take t_end/dt steps
        and refuse a budget below that.
    contact : pdw.Contact, dict or str, optional
        Normal and friction contact laws and their parameters (`pdw.Contact`,
        docs/contact_laws.md); default the paper's Hunt-Crossley and smooth Coulomb laws.
    approach_speeds0 : (float, float), optional
        Approach speeds [m/s] (>= 0) of the feet that start in support (the damping of
        lankarani_nikravesh and flores); default max(-v_y(x0), 0) of each.
    ground : pdw.Ground or dict, optional
        The ground walked on (shape h(s) and contact patches, docs/terrain.md); default flat
        (today's kernel, bitwise). A shaped or patched ground runs the shaped-ground kernel;
        a walker that leaves its defined extent stops with status ``"off_ground"``.

    Returns
    -------
    Result
    """
    scene_kwargs = getattr(x0, "simulate_kwargs", None)
    if callable(scene_kwargs):                      # a pdw.Scene (duck-typed: scene.py is above)
        given = sorted(k for k, v in locals().items()
                       if k in _DEFAULTS and not _same(v, _DEFAULTS[k]))
        if given:
            raise InvalidInputError("simulate(scene) takes no other arguments (got %s): set them "
                                    "in the scene" % ", ".join(given))
        res = simulate(**scene_kwargs())
        res.scene = x0
        return res
    params = Params.paper() if params is None else params
    if not isinstance(params, Params):
        raise InvalidInputError("params must be a pdw.Params, got %s" % type(params).__name__)
    x = check_state(x0)
    t_end = _check_positive("t_end", t_end)
    dt = checks.number("dt", dt, lo=DT_MIN)
    if dt > t_end:
        raise InvalidInputError("dt = %g must not exceed t_end = %g" % (dt, t_end))
    try:
        check_variant(variant)
    except ValueError as e:
        raise InvalidInputError(str(e)) from None
    checks.choice("method", method, METHODS)
    checks.choice("on_failure", on_failure, ("raise", "return"))
    f0 = checks.flags("flags0", flags0)
    record_every = checks.count("record_every", record_every)
    if not t_end / dt <= checks.MAX_COUNT:           # also inf (t_end near the largest float)
        raise InvalidInputError("t_end/dt = %g steps is too many (at most %d)"
                                % (t_end / dt, checks.MAX_COUNT))
    n_steps = int(round(t_end / dt))
    adaptive = _core.method_table()[METHODS.index(method)][2]
    if max_steps is None:
        budget = 10 ** 6 + int(2e6 * t_end) if adaptive else 0
    else:
        budget = checks.count("max_steps", max_steps, lo=1)
        if not adaptive and n_steps > budget:
            raise InvalidInputError("t_end/dt = %d steps exceeds max_steps = %d: raise max_steps "
                                    "or take a larger dt" % (n_steps, budget))
    hip = 0.5 * params.l if fall_hip_height is None else checks.number("fall_hip_height",
                                                                        fall_hip_height)
    depth = 0.25 * params.l if fall_depth is None else _check_positive("fall_depth", fall_depth)
    max_speed = _check_positive("max_speed", max_speed)
    rtol = _check_positive("rtol", rtol)
    atol = _check_positive("atol", atol)
    h_max = 0.0 if h_max is None else _check_positive("h_max", h_max)
    event_tol = _check_positive("event_tol", event_tol)
    feats = checks.features(features, _layout.FEATURES)
    for name, flag in (("record_forces", record_forces), ("record_events", record_events),
                       ("record_energies", record_energies)):
        if not isinstance(flag, (bool, np.bool_)):
            raise InvalidInputError("%s must be True or False, got %r" % (name, flag))
    if record_energies and not record_every:
        raise InvalidInputError("record_energies needs recorded states (record_every > 0)")
    stop_steps = _check_count("stop_steps", stop_steps)
    stop_touch_down = checks.leg_or_off("stop_touch_down", stop_touch_down)
    periodic_steps = _check_count("periodic_steps", periodic_steps)
    if periodic_steps == 1 or periodic_steps > _layout.STEP_RING:
        raise InvalidInputError("periodic_steps must be 0 (off) or in [2, %d], got %d"
                                % (_layout.STEP_RING, periodic_steps))
    periodic_tol = _check_positive("periodic_tol", periodic_tol)
    if not isinstance(dense_output, (bool, np.bool_)):
        raise InvalidInputError("dense_output must be True or False, got %r" % (dense_output,))
    if t_eval is not None:
        t_eval = _dense.check_t_eval(t_eval, t_end)
    if (t_eval is not None or dense_output) and record_every != 1:
        raise InvalidInputError("t_eval and dense_output interpolate between the accepted steps: "
                                "record_every must be 1, got %r" % (record_every,))

    contact = _contact.Contact.coerce(contact)
    x = contact.run_state(x, feats)
    contact = contact.for_features(feats)       # LuGre without friction: no bristle states
    params = contact.parameters(params)
    k = kernel_index(variant, feats, contact.normal, contact.friction)
    if feats != _layout.FEATURES:
        params = params.without(feats)
    p = contact.vector(parameter_vector(params), feats, params)     # validates the law's values
    ground = Ground.coerce(ground)
    try:        # every contact law: the law's factor on the default estimate (stepsize.py)
        for ps in ground.patched_params(params):    # and every patch's properties
            _stepsize.check_step(dt, ps, method, variant, check_step, contact)
    except (np.linalg.LinAlgError, FloatingPointError, OverflowError) as e:
        _stepsize.step_unknown(dt, method, check_step, e)
    v_in0 = None if approach_speeds0 is None else tuple(checks.real_array(
        "approach_speeds0", approach_speeds0, [(2,)], lo=0.0))
    start = time.perf_counter()
    buffers = None
    if out is not None and not isinstance(out, RecordBuffer):
        raise InvalidInputError("out must be a pdw.RecordBuffer, got %s" % type(out).__name__)
    if out is not None and record_every:
        rows = n_steps // int(record_every) + 2
        if _integrators.get(method).adaptive:     # unknown step count: what the buffer has
            rows = max(min(rows, 4096), out.capacity)
        buffers = out.arrays(rows, contact.nx)
    raw = _core.run(k, METHODS.index(method), x, p, f0[0], f0[1], dt, n_steps, int(record_every),
                    bool(record_forces), hip, depth, max_speed, rtol, atol, h_max,
                    event_tol=event_tol, record_events=bool(record_events), stop_steps=stop_steps,
                    periodic_k=periodic_steps, periodic_tol=periodic_tol, t_end=t_end,
                    max_steps=budget, buffers=buffers, approach_speeds0=v_in0,
                    stop_touch_down=stop_touch_down,
                    ground=None if ground.is_flat else _core.CGround(ground.table()))
    wall = time.perf_counter() - start
    energies = None
    if record_energies and raw["interrupted"] is None:
        en = np.empty((len(raw["x"]), len(_layout.ENERGY)))
        if len(en):
            _core.energies_batch(k, np.ascontiguousarray(raw["x"]), p, en)
        energies = {name: en[:, i] for i, name in enumerate(_layout.ENERGY)}
        energies["E"] = en.sum(axis=1)
    res = _result(raw, params, variant, method, dt, t_end, wall, on_failure, feats,
                  bool(record_events), energies, x)
    res.contact = contact
    res.ground = ground
    if t_eval is not None or dense_output:
        res = _dense.attach(res, t_eval, dense_output, params, variant, feats,
                            _integrators.get(method).order, record_energies, contact)
    return res


def _same(a, b):
    """Is an argument its default? (for simulate(scene))"""
    if a is None or b is None:
        return a is b
    try:
        return bool(np.array_equal(np.asarray(a, dtype=object), np.asarray(b, dtype=object)))
    except (TypeError, ValueError):
        return False


def _check_count(name, value):
    return checks.count(name, value)


def _honest(raw, status, params, x0, energies):
    """The status of a run that reached its end, checked: a runaway or airborne state, or
    non-finite energies, make it "diverged" (raw["failure"] filled in: the first offending
    sample); no touch-down at all in a long enough run makes it "no_steps"."""
    if status != "done":
        return status
    X = raw["x"] if len(raw["x"]) else np.empty((0, len(raw["x_final"])))
    T = raw["t"]
    X = np.vstack([X, raw["x_final"][None, :]])
    T = np.append(T, raw["t_final"])
    hip_max = x0[1] + RUNAWAY_HIP * params.l
    bad = (X[:, 1] > hip_max) | (np.abs(X[:, 2:4]) > RUNAWAY_ANGLE).any(axis=1)
    reason = None
    if bad.any():
        i = int(np.argmax(bad))
        if X[i, 1] > hip_max:
            reason = ("runaway: the hip rose to y_o = %.4g m, more than %g l above its start "
                      "(airborne): not walking" % (X[i, 1], RUNAWAY_HIP))
        else:
            reason = ("runaway: a leg turned past %.3g rad (theta1, theta2 = %.4g, %.4g): not "
                      "walking" % (RUNAWAY_ANGLE, X[i, 2], X[i, 3]))
    elif energies is not None and not all(np.isfinite(v).all() for v in energies.values()):
        i = int(np.argmax(~np.isfinite(energies["E"])))
        reason = "the energies are not finite at a finite state (overflow)"
    if reason is not None:
        i = max(i - 1, 0)                  # the last good sample before the offending one
        raw["failure"] = {"t": float(T[i]), "x": X[i].copy(), "leg": -1, "reason": reason}
        return "diverged"
    period = 2 * math.pi * math.sqrt(params.l / params.g) if params.g > 0 else math.inf
    if raw["event_counts"]["touch_down"] == 0 and raw["t_final"] >= NO_STEP_PERIODS * period:
        return "no_steps"
    return status


def _result(raw, params, variant, method, dt, t_end, wall, on_failure,
            features=_layout.FEATURES, events_recorded=True, energies=None, x0=None):
    if raw.get("interrupted") is not None:
        status = "interrupted"
    else:
        status = _STATUS[raw["status"]]
        if x0 is not None:
            status = _honest(raw, status, params, x0, energies)
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
        failure = {"t": f["t"], "x": f["x"], "reason": _REASONS.get(f["reason"], f["reason"]),
                   "leg": None if f["leg"] < 0 else f["leg"] + 1}
    public = {"done": "walked", "singular": "diverged"}.get(status, status)
    if status == "fell" and raw["failure"]["reason"] == 8:
        public = "off_ground"           # the walker left the ground's defined extent
    stop = _layout.STOP[raw["stop_reason"]]
    res = Result(t=raw["t"], x=raw["x"], flags=raw["flags"], Fn=Fn, Ft=Ft, events=events,
                 status=public,
                 failure=failure, x_final=raw["x_final"], t_final=raw["t_final"], stats=raw["stats"],
                 params=params, variant=variant, method=method, dt=dt, t_end=t_end,
                 n_steps=raw["n_steps"], wall_time=wall, gait=steps_from_rows(raw["gait"]),
                 n_gait_steps=int(raw["n_gait_steps"]), event_counts=dict(raw["event_counts"]),
                 events_recorded=events_recorded,
                 stop_reason=stop if stop != "none" else ("t_end" if public == "walked" else public),
                 energies=energies, features=tuple(features))
    if status == "interrupted":
        exc = raw["interrupted"]
        exc.result = res
        raise exc
    if res.status == "diverged" and on_failure == "raise":
        cls = SingularSystemError if status == "singular" else DivergedError
        advice = ("Check the masses and inertias (Params) and dt." if status == "singular" else
                  "Raise max_steps, or loosen rtol/atol." if raw["failure"]["reason"] == 7 else
                  "Try a smaller dt or a stiff method.")
        raise cls("simulation diverged at t = %.6g s (step %d, dt = %g, method %s): %s; "
                  "last good state %s. %s"
                  % (failure["t"], raw["n_steps"], dt, method, failure["reason"],
                     np.array2string(failure["x"], precision=5), advice),
                  t=failure["t"], x=failure["x"], reason=failure["reason"], result=res)
    return res
