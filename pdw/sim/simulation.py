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
from . import files as _files
from . import io as _io
from . import options as _opt
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
#: Why a loop failed: PDW_REASON_* -> message (generated: derive/layout.py REASON).
_REASONS = dict(enumerate(_layout.REASON_TEXT))
#: Smallest step [s] (a smaller one makes the step matrices singular in double precision).
DT_MIN = _opt.DT_MIN
#: Runaway bounds checked on every recorded and the final state of a run that reached its end:
#: the hip more than RUNAWAY_HIP leg lengths above its start, or a leg turned by more than
#: RUNAWAY_ANGLE [rad] (a full turn).
RUNAWAY_HIP = 2.0
RUNAWAY_ANGLE = 2 * math.pi
#: A run that reached t_end without a single touch-down in at least NO_STEP_PERIODS pendulum
#: periods 2 pi sqrt(l/g) did not walk: status "no_steps".
NO_STEP_PERIODS = 2.0
_Y_O, _THETA1, _THETA2 = (STATE.index(n) for n in ("y_o", "theta1", "theta2"))
#: The flat ground (`Ground()`, frozen): what a run without ``ground`` walks on.
_FLAT = Ground()
_X0_PAPER = np.array(X0_PAPER, dtype=float)


def _feet(a: str, b: str) -> slice:
    """The columns of record layout RECORD_CONTACT holding a (foot 1) and b (foot 2), as a
    slice: Result.Fn and Result.Ft are views of the recorded forces, not copies."""
    i, j = _layout.RECORD_CONTACT.index(a), _layout.RECORD_CONTACT.index(b)
    cols = slice(i, j + 1, j - i)
    assert list(range(len(_layout.RECORD_CONTACT)))[cols] == [i, j], "RECORD_CONTACT changed"
    return cols


_FN, _FT = _feet("F_n1", "F_n2"), _feet("F_t1", "F_t2")


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
        Recorded states, columns ``state_names``: layout `pdw.STATE` (nx = 8), with LuGre's
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
        budget), ``"no_steps"`` (reached t_end without a touch-down in ``NO_STEP_PERIODS``
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
    sol : pdw.sim.dense.DenseOutput or None
        With ``dense_output=True``: the interpolant between accepted steps (``pdw.sim.dense``).
    integrator, record, stop, limits : pdw.Integrator, pdw.Record, pdw.Stop, pdw.Limits
        The options the run was made with (``pdw.sim.options``; ``integrator`` with the method
        and dt run, ``stop`` with the t_end run).
    outcome : Outcome
        How the run ended (`pdw.sim.options.Outcome`), of which `status` and `stop_reason`
        are the two readings.
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
    integrator: _opt.Integrator | None = None    # the options it ran with (pdw.sim.options)
    record: _opt.Record | None = None
    stop: _opt.Stop | None = None
    limits: _opt.Limits | None = None
    ground: Ground | None = None                 # the pdw.Ground walked on (docs/terrain.md)

    @property
    def outcome(self) -> _opt.Outcome:
        """How the run ended, one `pdw.sim.options.Outcome`; `status` and `stop_reason` are
        its two readings (``Outcome.STEPS``: status ``"walked"``, stop_reason ``"steps"``)."""
        return _opt.Outcome.of(self.status, self.stop_reason)

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
        """Recorded time series of one state component by name (``state_names``), e.g.
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
        """The recorded samples as a pandas DataFrame (``pdw.sim.io.result_to_dataframe``; needs
        pandas): one row per sample, index t [s], columns the state (`pdw.STATE`), the flags,
        the forces and (if recorded) the energies; units in ``df.attrs["units"]``."""
        return _io.result_to_dataframe(self)

    def to_xarray(self) -> xarray.Dataset:
        """The run as an xarray Dataset (``pdw.sim.files.result_to_xarray``; needs xarray):
        ``x`` (time x state), ``flags`` and forces (time x leg), units in each variable's
        ``attrs["units"]``, provenance and settings in ``ds.attrs``."""
        return _files.result_to_xarray(self)

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
            The file written (``pdw.sim.files``: every Result pdw returns -- any status, contact
            law, dense output, features, t_eval -- is read back by `pdw.load` as it was, NaN
            and inf data included).
        """
        return _files.save(self, path)

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
    """x0: the mechanical state (`pdw.STATE`) or a friction law's (`Contact.run_state`): a
    fresh C-contiguous float64 array."""
    if x0 is X0_PAPER:                  # the default: a copy of the checked array
        return _X0_PAPER.copy()
    if type(x0) is np.ndarray and x0.dtype == np.float64 and x0.shape == (_core.NX,):
        x = x0.copy()                   # the common case: one copy, one finiteness test
        if math.isfinite(x.sum()):      # (a sum overflowing to inf: the full check below)
            return x
    n = np.shape(x0)[0] if np.ndim(x0) == 1 else _core.NX
    shape = (n,) if n in {len(v) for v in _layout.STATE_LAYOUTS.values()} else (_core.NX,)
    return checks.real_array(name, x0, [shape], labels=STATE if shape == (_core.NX,) else None)


def simulate(x0: ArrayLike | SceneLike = X0_PAPER, t_end: float | None = None,
             dt: float | None = None, *_positional, params: Params | None = None,
             variant: Literal["paper", "consistent"] = "paper", method: str | None = None,
             integrator: _opt.Integrator | dict | None = None,
             record: _opt.Record | dict | None = None, stop: _opt.Stop | dict | None = None,
             limits: _opt.Limits | dict | None = None,
             contact: _contact.Contact | dict | str | None = None,
             features: Iterable[str] | None = None, flags0: tuple[int, int] = (0, 1),
             approach_speeds0: tuple[float, float] | None = None,
             ground: Ground | dict | None = None,
             **_legacy) -> Result:
    """Simulate the walker from ``x0`` for ``t_end`` seconds (or run a `pdw.Scene`).

    ``simulate(scene)`` runs the scene (as `pdw.run`); no other argument may be given then.

    Parameters
    ----------
    x0 : array_like (8,) or (nx,), or Scene
        Initial state [x_o, y_o, theta1, theta2, xd_o, yd_o, thetad1, thetad2] (m, rad, m/s,
        rad/s), with LuGre friction optionally followed by the bristle states z1, z2 [m]
        (default 0; nx = 10). Default: the paper's typical gait (`X0_PAPER`).
    t_end : float, optional
        Duration [s] (default ``stop.t_end``, 3.5).
    dt : float, optional
        Step [s] (default ``integrator.dt``, the paper's 1e-4); adaptive methods: the first
        trial step.
    params : Params, optional
        Default `Params.paper()`.
    variant : {"paper", "consistent"}
        Contact reading of docs/model.md section 6.
    method : str, optional
        Integrator (``pdw.core.integrators.INTEGRATORS``, docs/integrators.md), the short form
        of ``integrator=Integrator(method=...)``: ``"cdm"`` (default) is the paper's central
        difference method (docs/model.md section 7); ``"verlet"``, ``"rk4"`` are fixed-step,
        ``"dopri5"`` and ``"rodas4"`` (stiff, recommended) adaptive.
    integrator : pdw.Integrator, optional
        How the run is integrated: method, dt, the tolerances rtol and atol, h_max and
        event_tol of the adaptive methods (which locate each flag switch to within event_tol
        [s] and end a step there; fixed-step methods switch at step boundaries), their step
        budget max_steps (default 10^6 + 2 10^6 t_end/s; fixed-step methods take t_end/dt
        steps and refuse a budget below that), and check_step: fixed-step methods compare dt
        with ``pdw.sim.stepsize.step_limit`` (the method's estimated stability limit for these
        parameters; with another contact law, times the law's factor
        ``pdw.sim.stepsize.LAW_CALIBRATION``) and warn (`pdw.StepSizeWarning`, ``"warn"``),
        refuse (`pdw.StepSizeError`, ``"error"``) or do not check (``"off"``). Fields:
        `pdw.sim.options.Integrator`.
    record : pdw.Record, optional
        What is recorded: ``every`` k-th step (0: nothing but events and the final state),
        ``forces`` (Fn, Ft), ``energies`` (needs every > 0), ``events`` (False: only their
        counts and the online gait analysis, O(1) memory however long the run), ``t_eval``
        (times [s], non-decreasing, in [0, t_end]: ``Result.t`` is then t_eval up to the run's
        end and x, flags, Fn, Ft, energies their values there from the method's dense output,
        ``pdw.sim.dense``), ``dense_output`` (also ``Result.sol(t)``, exact at every accepted
        step), ``out`` (a `pdw.RecordBuffer`: record into its reusable arrays; the Result's
        arrays are then views into it). t_eval and dense_output need every = 1.
    stop : pdw.Stop, optional
        When the run ends of its own before t_end: ``steps`` complete gait steps (status
        ``"walked"``, ``stop_reason`` ``"steps"``), ``periodic`` (status ``"periodic"`` as soon as
        the last ``periodic_steps`` steps agree, each of L, travel, P and cycle within
        ``periodic_tol`` relative: ``max - min <= tol * abs(latest)``), ``touch_down`` (1 or
        2: at that leg's first touch-down, the final state the event's; the touch-down
        Poincare map's end, ``pdw.limit_cycle``). Its ``t_end`` is the default of ``t_end``.
    limits : pdw.Limits, optional
        When the run fell or diverged: ``fall_hip_height`` (the hip lower than this above the
        slope [m]; default 0.5 l), ``fall_depth`` (a foot deeper than this below the ground
        [m]; default 0.25 l), ``max_speed`` (a velocity component above this [m/s or rad/s]:
        diverged), and ``on_failure``: a diverged run raises `pdw.DivergedError` (with the
        partial result attached, ``"raise"``) or returns a Result with status ``"diverged"``
        (``"return"``). A fall is a status, never an error.
    contact : pdw.Contact, dict or str, optional
        Normal and friction contact laws and their parameters (`pdw.Contact`,
        docs/contact_laws.md); default the paper's Hunt-Crossley and smooth Coulomb laws.
    features : iterable of str, optional
        Force elements present (``pdw.core._layout.FEATURES``; default all). The absent ones are
        switched off: a specialized generated kernel if there is one, else the general kernel
        with their parameters zeroed (`Params.without`). Under LuGre friction the same, except
        that a run without ``friction`` has no bristles: it runs the normal law with the
        mechanical state only (`pdw.Contact.for_features`).
    flags0 : (int, int)
        Initial support flags of legs 1, 2 (the paper's start: leg 1 swing, leg 2 support).
    approach_speeds0 : (float, float), optional
        Approach speeds [m/s] (>= 0) of the feet that start in support (the damping of
        lankarani_nikravesh and flores); default max(-v_y(x0), 0) of each.
    ground : pdw.Ground or dict, optional
        The ground walked on (shape h(s) and contact patches, docs/terrain.md); default flat
        (today's kernel, bitwise). A shaped or patched ground runs the shaped-ground kernel;
        a walker that leaves its defined extent stops with status ``"off_ground"``.
    **_legacy
        The keywords of before (``record_every=``, ``rtol=``, ``stop_steps=``, ...) and the
        positional form ``simulate(x0, t_end, dt, params, variant, method, ...)``: they work
        for one release, each with a `DeprecationWarning` naming its new spelling
        (``pdw.sim.options.LEGACY``).

    Returns
    -------
    Result
    """
    scene_kwargs = getattr(x0, "simulate_kwargs", None)
    if callable(scene_kwargs):                      # a pdw.Scene (duck-typed: scene.py is above)
        given = [k for k, v in dict(t_end=t_end, dt=dt, params=params, method=method,
                                    integrator=integrator, record=record, stop=stop,
                                    limits=limits, contact=contact, features=features,
                                    approach_speeds0=approach_speeds0, ground=ground).items()
                 if v is not None] + (["variant"] if variant != "paper" else []) \
            + (["flags0"] if not _same(flags0, (0, 1)) else []) + sorted(_legacy) \
            + (["positional arguments"] if _positional else [])
        if given:
            raise InvalidInputError("simulate(scene) takes no other arguments (got %s): set them "
                                    "in the scene" % ", ".join(given))
        res = simulate(**scene_kwargs())
        res.scene = x0
        return res
    settled = _opt.settle(
        "simulate", _positional, _legacy, integrator=integrator, record=record, stop=stop,
        limits=limits, method=method, dt=dt, t_end=t_end,
        keywords=dict(params=(params, None), variant=(variant, "paper"), method=(method, None),
                      flags0=(flags0, (0, 1))))
    it, rec, st, lim, method, dt, t_end, plain = settled
    params = plain.get("params", params)
    variant = plain.get("variant", variant)
    flags0 = plain.get("flags0", flags0)
    # The option objects checked every field when they were made (`pdw.sim.options`): what is
    # checked here is what they cannot know (the plain arguments, the limits derived from l, the
    # step count t_end/dt, the budget of a fixed-step method, t_eval against t_end).
    h_max, max_steps, check_step = it.h_max, it.max_steps, it.check_step
    periodic_steps = st.periodic_k
    fall_hip_height, fall_depth, on_failure = lim.fall_hip_height, lim.fall_depth, lim.on_failure
    params = Params.paper() if params is None else params
    if not isinstance(params, Params):
        raise InvalidInputError("params must be a pdw.Params, got %s" % type(params).__name__)
    x = check_state(x0)
    t_end = _check_positive("t_end", t_end)
    dt = checks.number("dt", dt, lo=DT_MIN)
    if dt > t_end:
        raise InvalidInputError("dt = %g must not exceed t_end = %g" % (dt, t_end))
    if type(variant) is not str or variant not in _layout.VARIANTS:
        try:
            check_variant(variant)
        except ValueError as e:
            raise InvalidInputError(str(e)) from None
    if type(method) is not str or method not in METHODS:
        checks.choice("method", method, METHODS)
    f0 = (0, 1) if type(flags0) is tuple and flags0 == (0, 1) else checks.flags("flags0", flags0)
    if not t_end / dt <= checks.MAX_COUNT:           # also inf (t_end near the largest float)
        raise InvalidInputError("t_end/dt = %g steps is too many (at most %d)"
                                % (t_end / dt, checks.MAX_COUNT))
    n_steps = int(round(t_end / dt))
    adaptive = _integrators.get(method).adaptive
    if max_steps is None:
        budget = 10 ** 6 + int(2e6 * t_end) if adaptive else 0
    else:
        budget = max_steps
        if not adaptive and n_steps > budget:
            raise InvalidInputError("t_end/dt = %d steps exceeds max_steps = %d: raise max_steps "
                                    "or take a larger dt" % (n_steps, budget))
    hip = 0.5 * params.l if fall_hip_height is None else checks.number("fall_hip_height",
                                                                        fall_hip_height)
    depth = 0.25 * params.l if fall_depth is None else fall_depth
    h_max = 0.0 if h_max is None else h_max
    feats = checks.features(features, _layout.FEATURES)
    record_every, record_forces, record_energies = rec.every, rec.forces, rec.energies
    t_eval, dense_output, out = rec.t_eval, rec.dense_output, rec.out
    if t_eval is not None:
        t_eval = _dense.check_t_eval(t_eval, t_end)

    contact = _contact.Contact.coerce(contact)
    x = contact.run_state(x, feats)
    contact = contact.for_features(feats)       # LuGre without friction: no bristle states
    params = contact.parameters(params)
    k = kernel_index(variant, feats, contact.normal, contact.friction)
    if feats != _layout.FEATURES:
        params = params.without(feats)
    p = contact.vector(parameter_vector(params), feats, params)     # validates the law's values
    ground = _FLAT if ground is None else Ground.coerce(ground)
    try:        # every contact law: the law's factor on the default estimate (stepsize.py)
        for ps in ground.patched_params(params) if ground.patches else (params,):  # and patches
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
    opts = _opt.c_options(it, rec, st, lim, dt=dt, n_steps=n_steps, t_end=t_end, h_max=h_max,
                          max_steps=budget, periodic_k=periodic_steps, fall_hip_height=hip,
                          fall_depth=depth)
    raw = _core.run(k, METHODS.index(method), x, p, f0[0], f0[1], opts,
                    record_contact=bool(record_forces), buffers=buffers, approach_speeds0=v_in0,
                    ground=None if ground.is_flat else ground.compiled(_core.CGround))
    wall = time.perf_counter() - start
    energies = None
    if record_energies and raw["interrupted"] is None:
        en = np.empty((len(raw["x"]), len(_layout.ENERGY)))
        if len(en):
            _core.energies_batch(k, np.ascontiguousarray(raw["x"]), p, en)
        energies = {name: en[:, i] for i, name in enumerate(_layout.ENERGY)}
        energies["E"] = en.sum(axis=1)
    res = _result(raw, params, variant, method, dt, t_end, wall, on_failure, feats,
                  rec.events, energies, x)
    res.contact = contact
    res.integrator, res.stop = settled.ran((method, dt, t_end))
    res.record, res.limits = rec, lim
    res.ground = ground
    if t_eval is not None or dense_output:
        res = _dense.attach(res, t_eval, dense_output, params, variant, feats,
                            _integrators.get(method).order, record_energies, contact)
    return res


def _check_count(name, value):
    return checks.count(name, value)


def _same(a, b):
    """Is an argument its default? (for simulate(scene))"""
    if a is None or b is None:
        return a is b
    try:
        return bool(np.array_equal(np.asarray(a, dtype=object), np.asarray(b, dtype=object)))
    except (TypeError, ValueError):
        return False


def _honest(raw, status, params, x0, energies):
    """The status of a run that reached its end, checked: a runaway or airborne state, or
    non-finite energies, make it "diverged" (raw["failure"] filled in: the first offending
    sample); no touch-down at all in a long enough run makes it "no_steps"."""
    if status != "done":
        return status
    X, T = raw["x"], raw["t"]
    n = len(X)

    def sample(i):                  # (t, x) of sample i of the recorded ones and the final state
        return (float(T[i]), X[i]) if i < n else (float(raw["t_final"]), raw["x_final"])

    hip_max = x0[_Y_O] + RUNAWAY_HIP * params.l
    # one compiled pass over the samples, no copy of them (issue 23)
    i = _core.first_runaway(X, hip_max, RUNAWAY_ANGLE) if n else -1
    if i < 0 and _core.first_runaway(raw["x_final"][None, :], hip_max, RUNAWAY_ANGLE) == 0:
        i = n
    reason = None
    if i >= 0:
        xi = sample(i)[1]
        if xi[_Y_O] > hip_max:
            reason = ("runaway: the hip rose to y_o = %.4g m, more than %g l above its start "
                      "(airborne): not walking" % (xi[_Y_O], RUNAWAY_HIP))
        else:
            reason = ("runaway: a leg turned past %.3g rad (theta1, theta2 = %.4g, %.4g): not "
                      "walking" % (RUNAWAY_ANGLE, xi[_THETA1], xi[_THETA2]))
    elif energies is not None and not all(np.isfinite(v).all() for v in energies.values()):
        i = int(np.argmax(~np.isfinite(energies["E"])))
        reason = "the energies are not finite at a finite state (overflow)"
    if reason is not None:
        t_i, x_i = sample(max(i - 1, 0))   # the last good sample before the offending one
        raw["failure"] = {"t": t_i, "x": x_i.copy(), "leg": -1, "reason": reason}
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
    if rc is not None:              # views of the recorded forces (feet 1, 2), no copies
        Fn = rc[:, _FN]
        Ft = rc[:, _FT]
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
    if status == "fell" and raw["failure"]["reason"] == _layout.REASON.index("off_ground"):
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
                  "Raise max_steps, or loosen rtol/atol."
                  if raw["failure"]["reason"] == _layout.REASON.index("budget") else
                  "Try a smaller dt or a stiff method.")
        raise cls("simulation diverged at t = %.6g s (step %d, dt = %g, method %s): %s; "
                  "last good state %s. %s"
                  % (failure["t"], raw["n_steps"], dt, method, failure["reason"],
                     np.array2string(failure["x"], precision=5), advice),
                  t=failure["t"], x=failure["x"], reason=failure["reason"], result=res)
    return res


# the Result's file kind (pdw.sim.files owns the format; the classes are registered here, where
# they are defined)
_files.register(_files.FORMAT, Result, _files.result_to_file,
                lambda arrays, meta: _files.result_from_file(arrays, meta, Result, Event),
                to_xarray=_files.result_to_xarray)
