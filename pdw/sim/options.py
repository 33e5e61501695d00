"""The options of a run, each named once, as validated objects (docs/architecture.md).

`Integrator` (how), `Record` (what is kept), `Stop` (when a run ends of its own) and `Limits`
(when it fell or diverged, and what a divergence does) are frozen dataclasses: every field is
typed, documented and checked when the object is made, with an error
(`pdw.InvalidInputError`) naming the field (``record.every``) and its allowed range. The
same objects are taken by `pdw.simulate`, `pdw.simulate_batch`, `pdw.simulate_many`, and are
the sections of a `pdw.Scene` (``[integrator]``, ``[record]``, ``[stop]``, ``[limits]`` of its
TOML form), so a scene can say everything a run can.

The keywords of before (``record_every=``, ``rtol=``, ``stop_steps=``, ...) and the
positional form (``simulate(x0, 3.5, 1e-4, None, "paper", "rk4")``) keep working for one
release through one table, `LEGACY`: old name -> (option object, field). `resolve` applies it
and warns (`DeprecationWarning`) with the new spelling.

Why this module is long: it is the schema of every option (type, unit, meaning, check) next to
the coercion and the table of the spellings of before that map onto it; split, a field and its
check would live apart.
"""
from __future__ import annotations

import dataclasses
import enum
import math
import numbers
import warnings
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from ..core import _layout
from ..core.checks import MAX_COUNT, unmasked
from ..core.errors import InvalidInputError, PdwDeprecationWarning
from ..core.ground import Ground
from ..core.integrators import METHODS

#: Smallest step [s] (a smaller one makes the step matrices singular in double precision).
DT_MIN = 1e-12
#: What a run takes for an unset ``Integrator.method``, ``Integrator.dt``, ``Stop.t_end``: the
#: paper's method, step [s] and duration [s].
METHOD, DT, T_END = "cdm", 1e-4, 3.5
ON_FAILURE = ("raise", "return")
CHECK_STEP = ("warn", "error", "off")


def _f(default, kind, doc, check=None, c=None):
    """An option field: its type (``kind``, a key of `KINDS`), its meaning, a value check
    returning an error text or None, and ``c``: the name of the field of the compiled loops'
    pdw_run_opts (pdw/core/csrc/pdw_sim.h) that takes its value as is (`c_options`)."""
    meta = dict(kind=kind, doc=doc, check=check, c=c)
    if isinstance(default, (dict, list)):
        return field(default_factory=lambda: type(default)(default), metadata=meta)
    return field(default=default, metadata=meta)


def _positive(v):
    return None if v > 0 and math.isfinite(v) else "must be finite and > 0"


def _nonnegative(v):
    return None if v >= 0 else "must be >= 0"


def _at_least(lo):
    def check(v):
        return None if lo <= v <= MAX_COUNT else "must be in [%d, %d]" % (lo, MAX_COUNT)
    return check


def _one_of(options):
    def check(v):
        return None if v in options else "must be one of %s" % ", ".join(map(repr, options))
    return check


def _method_check(v):
    return _one_of(METHODS)(v)


def _periodic_steps_check(v):
    return None if 2 <= v <= _layout.STEP_RING else "must be in [2, %d]" % _layout.STEP_RING


def _count_check(v):
    return None if 0 <= v <= MAX_COUNT else "must be in [0, %d]" % MAX_COUNT


KINDS = {
    "str": "a string", "str?": "a string", "float": "a number", "float?": "a number", "int": "an integer",
    "int?": "an integer", "bool": "true or false", "state": "a list of 8 numbers",
    "flags": "a list of two 0/1 integers", "params": "a table of parameter values",
    "times?": "a list of numbers", "pair?": "a list of two numbers >= 0",
    "object": "an object", "ground": "a [ground] table (docs/terrain.md)",
}


def _err(key, text):
    """The error of one key: ``option 'record.every' must be ...`` for the options of a run,
    ``scene key 'x0' ...`` for the rest of a scene."""
    what = "option" if key.split(".")[0] in OPTION_SECTIONS else "scene key"
    return InvalidInputError("%s %r %s" % (what, key, text))


def _number(v):
    return isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_))


def _integer(v):
    if isinstance(v, (bool, np.bool_)):
        return False
    return isinstance(v, numbers.Integral) or (
        isinstance(v, numbers.Real) and math.isfinite(v) and float(v).is_integer())


def _coerce(value, kind, key):
    """Check the type of one value (as read from TOML or given in Python) and normalise it:
    no bool for a number, no string for a list, integral floats (2.0) taken as integers."""
    def bad():
        return _err(key, "must be %s, got %r" % (KINDS[kind], value))

    tv = type(value)
    if kind in ("float", "float?") and (tv is float or tv is int):
        return float(value)
    if (kind in ("int", "int?") and tv is int) or (kind == "bool" and tv is bool) \
            or (kind in ("str", "str?") and tv is str):
        return value
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if value is None and kind.endswith("?"):
        return None
    if kind == "object":
        return value
    if kind == "ground":
        if value is None or isinstance(value, Ground):
            return value
        if not isinstance(value, dict):
            raise bad()
        try:
            return Ground.from_dict(value)
        except InvalidInputError as e:
            raise _err(key, "is invalid: %s" % e) from None
    if kind in ("str", "str?"):
        if not isinstance(value, str):
            raise bad()
        return value
    if kind in ("float", "float?"):
        if not _number(value):
            raise bad()
        return float(value)
    if kind in ("int", "int?"):
        if not _integer(value):
            raise bad()
        return int(value)
    if kind == "bool":
        if not isinstance(value, (bool, np.bool_)):
            raise bad()
        return bool(value)
    if kind in ("state", "times?", "pair?"):
        value = unmasked("scene key %r" % key, value)
        if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__len__") \
                or (kind == "state" and len(value) != len(_layout.STATE)) \
                or (kind == "pair?" and len(value) != 2) \
                or not all(_number(v) for v in np.asarray(value, dtype=object).ravel()) \
                or np.ndim(value) != 1:
            raise bad()
        out = tuple(float(v) for v in value)
        names = _layout.STATE if kind == "state" else range(len(out))
        for name, v in zip(names, out):
            if not math.isfinite(v):
                raise _err(key, "component %s must be finite, got %r" % (name, v))
        if kind == "pair?" and min(out) < 0:
            raise _err(key, "must be >= 0, got %r" % (out,))
        return out
    if kind == "flags":
        if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__len__") \
                or len(value) != 2 or not all(isinstance(v, numbers.Integral)
                                              and not isinstance(v, (bool, np.bool_))
                                              and v in (0, 1) for v in value):
            raise bad()
        return tuple(int(v) for v in value)
    if kind == "params":
        if not isinstance(value, dict):
            raise bad()
        out = {}
        for name, v in value.items():
            if name not in _layout.PARAMS:
                raise _err("%s.%s" % (key, name), "is unknown; allowed: %s"
                           % ", ".join(_layout.PARAMS))
            if not _number(v):
                raise _err("%s.%s" % (key, name), "must be a number, got %r" % (v,))
            out[name] = float(v)
        return out
    raise AssertionError(kind)


_SCHEMAS: dict = {}


def _schema(cls):
    """(name, key, kind, check) of each field of an options class (computed once)."""
    out = _SCHEMAS.get(cls)
    if out is None:
        out = _SCHEMAS[cls] = tuple(
            (f.name, "%s.%s" % (cls.SECTION, f.name) if cls.SECTION else f.name,
             f.metadata["kind"], f.metadata["check"]) for f in dataclasses.fields(cls))
    return out


class _Section:
    """A table of options: typed, checked fields; from and to plain dicts (TOML tables)."""

    SECTION = ""

    def __post_init__(self):
        types = _section_types()
        for name, key, kind, check in _schema(type(self)):
            value = getattr(self, name)
            if kind in types:
                value = types[kind].from_dict(value) if isinstance(value, dict) else value
                if not isinstance(value, types[kind]):
                    raise _err(key, "must be a table (%s), got %r"
                               % (types[kind].__name__, value))
            else:
                value = _coerce(value, kind, key)
                problem = check(value) if (check is not None and value is not None) else None
                if problem:
                    raise _err(key, "%s, got %r" % (problem, value))
            object.__setattr__(self, name, value)
        self._check()

    def _check(self):
        """Checks across fields (override)."""

    @classmethod
    def from_dict(cls, data: dict, prefix: str | None = None):
        """Build from a (TOML) table; unknown keys are errors naming the key."""
        prefix = cls.SECTION if prefix is None else prefix
        if not isinstance(data, dict):
            raise _err(prefix, "must be a table, got %r" % (data,))
        names = [f.name for f in dataclasses.fields(cls)]  # type: ignore[arg-type]
        for key in data:
            if key not in names:
                full = "%s.%s" % (prefix, key) if prefix else key
                raise _err(full, "is unknown; allowed here: %s" % ", ".join(names))
        return cls(**data)

    def to_dict(self) -> dict:
        """Plain dict (nested for sections); None values and Python objects (``kind`` object:
        a `pdw.RecordBuffer`) left out (TOML has neither)."""
        out: dict[str, Any] = {}
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            v = getattr(self, f.name)
            if f.metadata["kind"] in ("object", "ground"):
                v = v.to_dict() if hasattr(v, "to_dict") else None
            if isinstance(v, _Section):
                out[f.name] = v.to_dict()
            elif isinstance(v, tuple):
                out[f.name] = list(v)
            elif isinstance(v, dict):
                out[f.name] = dict(v)
            elif v is not None:
                out[f.name] = v
        return out

    def replace(self, **changes):
        """A copy with some fields changed; a table given as a dict updates that table."""
        names = {f.name for f in dataclasses.fields(self)}  # type: ignore[arg-type]
        new = {}
        for key, v in changes.items():
            if key not in names:
                full = "%s.%s" % (self.SECTION, key) if self.SECTION else key
                raise _err(full, "is unknown; allowed here: %s"
                           % ", ".join(f.name for f in dataclasses.fields(self)))  # type: ignore
            old = getattr(self, key)
            if isinstance(v, dict) and isinstance(old, _Section):
                v = old.replace(**v)
            new[key] = v
        return dataclasses.replace(self, **new)  # type: ignore[type-var]


@dataclass(frozen=True)
class Integrator(_Section):
    """How a run is integrated (docs/integrators.md).

    ``Integrator(method="rodas4", rtol=1e-8)``; ``simulate(..., method="rodas4")`` is the short
    form when only the method is chosen.
    """

    SECTION = "integrator"
    method: str | None = _f(None, "str?", "integrator: cdm (the paper's; the default), verlet, "
                            "rk4, dopri5, rodas4", _method_check)
    dt: float | None = _f(None, "float?", "step [s] (default 1e-4, the paper's); adaptive "
                          "methods: the first trial step; a run refuses one below DT_MIN)", _positive)
    rtol: float = _f(1e-6, "float", "relative tolerance of adaptive methods", _positive,
                     c="rtol")
    atol: float = _f(1e-8, "float", "absolute tolerance of adaptive methods", _positive,
                     c="atol")
    h_max: float | None = _f(None, "float?", "largest step of adaptive methods [s] (none)",
                             _positive)
    event_tol: float = _f(1e-9, "float", "adaptive methods locate flag switches to this [s]",
                          _positive, c="event_tol")
    max_steps: int | None = _f(None, "int?", "step budget of adaptive methods (default "
                               "10^6 + 2 10^6 t_end/s); fixed-step methods refuse fewer than "
                               "t_end/dt", _at_least(1))
    check_step: str = _f("warn", "str", "fixed-step methods: dt above the estimated stability "
                         "limit warns, is an error, or is not checked (warn, error, off)",
                         _one_of(CHECK_STEP))


@dataclass(frozen=True)
class Record(_Section):
    """What a run records. The gait descriptors are always computed (online, O(1) memory:
    `Result.gait`)."""

    SECTION = "record"
    every: int = _f(1, "int", "full state every k steps (0: none)", _count_check,
                    c="record_every")
    forces: bool = _f(True, "bool", "contact forces at the recorded samples")
    energies: bool = _f(False, "bool", "energies at the recorded samples (needs every > 0)")
    events: bool = _f(True, "bool", "the list of touch-downs and lift-offs (else only counts)",
                      c="record_events")
    t_eval: tuple | None = _f(None, "times?", "times [s] at which to return the solution "
                              "(dense output; needs every = 1)")
    dense_output: bool = _f(False, "bool", "also return the interpolant Result.sol "
                            "(needs every = 1)")
    out: Any = _f(None, "object", "a pdw.RecordBuffer to record into (Python only)")

    def _check(self):
        if self.energies and self.every == 0:
            raise _err("record.energies", "needs recorded states (record.every > 0)")
        if (self.t_eval is not None or self.dense_output) and self.every != 1:
            raise _err("record.every", "must be 1 with t_eval or dense_output (they interpolate "
                       "between the accepted steps), got %r" % (self.every,))

    @classmethod
    def full(cls, every: int = 1) -> "Record":
        """Everything: state, flags, contact forces and energies every step, events."""
        return cls(every=every, forces=True, energies=True, events=True)

    @classmethod
    def events_only(cls) -> "Record":
        """The events (and the descriptors), no samples."""
        return cls(every=0, forces=False, energies=False, events=True)

    @classmethod
    def descriptors_only(cls) -> "Record":
        """Only the gait descriptors and event counts: O(1) memory however long the run."""
        return cls(every=0, forces=False, energies=False, events=False)


@dataclass(frozen=True)
class Stop(_Section):
    """When a run ends of its own: t_end, a number of gait steps, a periodic gait, a touch-down.
    (A fall or a divergence always ends it: `Limits`.)"""

    SECTION = "stop"
    t_end: float | None = _f(None, "float?", "duration [s] (default 3.5)", _positive)
    steps: int = _f(0, "int", "stop after this many complete gait steps (0: no limit)",
                    _count_check, c="stop_steps")
    periodic: bool = _f(False, "bool", "stop when the last periodic_steps steps agree")
    periodic_steps: int = _f(4, "int", "k: how many successive steps must agree",
                             _periodic_steps_check)
    periodic_tol: float = _f(1e-3, "float", "relative tolerance on L, travel, P and cycle",
                             _positive, c="periodic_tol")
    touch_down: int = _f(0, "int", "1 or 2: stop at that leg's first touch-down (0: off)",
                         _one_of((0, 1, 2)), c="stop_touch_down")

    @property
    def periodic_k(self) -> int:
        """The compiled loop's periodic window: periodic_steps when periodic, else 0 (off)."""
        return self.periodic_steps if self.periodic else 0


@dataclass(frozen=True)
class Limits(_Section):
    """When a run fell or diverged, and what a divergence does (a fall is a status)."""

    SECTION = "limits"
    fall_hip_height: float | None = _f(None, "float?", "fell when the hip is lower [m] "
                                       "(default 0.5 l)")
    fall_depth: float | None = _f(None, "float?", "fell when a foot is deeper [m] "
                                  "(default 0.25 l)", _positive)
    max_speed: float = _f(1e3, "float", "diverged when a velocity exceeds this [m/s, rad/s]",
                          _positive, c="max_speed")
    on_failure: str = _f("raise", "str", "a diverged run: raise DivergedError, or return it",
                         _one_of(ON_FAILURE))


_TYPES = {"str": "str", "str?": "str, optional", "float": "float", "float?": "float, optional",
          "int": "int", "int?": "int, optional", "bool": "bool", "times?": "array_like, optional",
          "pair?": "(float, float), optional", "object": "object, optional",
          "ground": "pdw.Ground or dict, optional"}


def _document(cls):
    """Append a numpydoc Parameters section made from the fields' metadata to the docstring."""
    lines = ["", "    Parameters", "    ----------"]
    for f in dataclasses.fields(cls):
        lines.append("    %s : %s" % (f.name, _TYPES.get(f.metadata["kind"], f.metadata["kind"])))
        lines.append("        %s (default %r)." % (f.metadata["doc"][0].upper() + f.metadata["doc"][1:],
                                                   f.default))
    cls.__doc__ = (cls.__doc__ or "").rstrip() + "\n" + "\n".join(lines) + "\n"
    return cls


for _cls in (Integrator, Record, Stop, Limits):
    _document(_cls)


def _moved_to_limits(init):
    def __init__(self, *args, **kwargs):
        moved = sorted(k for k in kwargs if k in MOVED_TO_LIMITS)
        if moved:
            raise InvalidInputError("Stop(%s=...): the fall and divergence bounds moved to "
                                    "pdw.Limits: write limits=pdw.Limits(%s=...)"
                                    % (moved[0], moved[0]))
        init(self, *args, **kwargs)
    __init__.__doc__ = init.__doc__
    return __init__


#: Fields of `Stop` of before that are `Limits`' now.
MOVED_TO_LIMITS = ("fall_hip_height", "fall_depth", "max_speed", "on_failure")
Stop.__init__ = _moved_to_limits(Stop.__init__)  # type: ignore[method-assign]

OPTION_SECTIONS = {"integrator": Integrator, "record": Record, "stop": Stop, "limits": Limits}
_EXTRA_SECTIONS: dict = {}


def _section_types():
    """Sections that a field can hold as a table (the options, and the scene's own tables,
    registered by pdw.sim.scene)."""
    return {**OPTION_SECTIONS, **_EXTRA_SECTIONS}


#: The defaults, made once (a run without options pays for no construction).
DEFAULTS = {name: cls() for name, cls in OPTION_SECTIONS.items()}


# --- outcomes ---------------------------------------------------------------------------------

class Outcome(str, enum.Enum):
    """How a run ended: one value, from which `Result.status` and `Result.stop_reason` follow
    (``Outcome.STEPS.status == "walked"``, ``Outcome.STEPS.stop_reason == "steps"``).

    T_END: walked to t_end. STEPS: walked the requested number of gait steps (`Stop.steps <pdw.steps>`).
    TOUCH_DOWN: stopped at the requested touch-down (``Stop.touch_down``). PERIODIC: the last
    steps agreed (``Stop.periodic``). FELL: the hip dropped or a foot sank too deep (`Limits`).
    DIVERGED: a non-finite, runaway or singular state, or the step budget used up. NO_STEPS:
    reached t_end without a touch-down in two pendulum periods or more. INTERRUPTED: Ctrl-C.
    """

    T_END = "t_end"
    STEPS = "steps"
    TOUCH_DOWN = "touch_down"
    PERIODIC = "periodic"
    FELL = "fell"
    DIVERGED = "diverged"
    NO_STEPS = "no_steps"
    INTERRUPTED = "interrupted"

    @property
    def status(self) -> str:
        """``"walked"``, ``"periodic"``, ``"fell"``, ``"diverged"``, ``"no_steps"`` or
        ``"interrupted"``."""
        return "walked" if self in (Outcome.T_END, Outcome.STEPS, Outcome.TOUCH_DOWN) \
            else self.value

    @property
    def stop_reason(self) -> str:
        """``"t_end"``, ``"steps"``, ``"touch_down"``, ``"periodic"``, or the failure status."""
        return self.value

    @classmethod
    def of(cls, status: str, stop_reason: str) -> "Outcome":
        """The outcome of a (status, stop_reason) pair."""
        return cls(stop_reason if status in ("walked", "periodic") else status)


# --- the spellings of before ------------------------------------------------------------------

#: Old keyword -> (option object, field). `resolve` maps them for one release, warning.
LEGACY = {
    "rtol": ("integrator", "rtol"), "atol": ("integrator", "atol"),
    "h_max": ("integrator", "h_max"), "event_tol": ("integrator", "event_tol"),
    "max_steps": ("integrator", "max_steps"), "check_step": ("integrator", "check_step"),
    "record_every": ("record", "every"), "record_forces": ("record", "forces"),
    "record_events": ("record", "events"), "record_energies": ("record", "energies"),
    "t_eval": ("record", "t_eval"), "dense_output": ("record", "dense_output"),
    "out": ("record", "out"),
    "stop_steps": ("stop", "steps"), "periodic_steps": ("stop", "periodic_steps"),
    "periodic_tol": ("stop", "periodic_tol"), "stop_touch_down": ("stop", "touch_down"),
    "fall_hip_height": ("limits", "fall_hip_height"), "fall_depth": ("limits", "fall_depth"),
    "max_speed": ("limits", "max_speed"), "on_failure": ("limits", "on_failure"),
}
#: The old positional order after (x0, t_end, dt) of each entry point.
POSITIONAL = {
    "simulate": ("params", "variant", "method", "flags0", "record_every", "record_forces",
                 "on_failure", "fall_hip_height", "fall_depth", "max_speed", "rtol", "atol",
                 "h_max", "event_tol"),
    "simulate_batch": ("params", "variant", "method", "flags0", "threads", "lanes", "vector",
                       "stop_steps", "periodic_steps", "periodic_tol", "fall_hip_height",
                       "fall_depth", "max_speed", "check_step", "rtol", "atol", "h_max",
                       "event_tol", "max_steps"),
    "simulate_many": ("params", "variant", "method", "flags0", "threads"),
    "scalar_batch": ("params", "variant", "method", "flags0", "threads", "stop_steps",
                     "periodic_steps", "periodic_tol", "fall_hip_height", "fall_depth",
                     "max_speed", "check_step"),
}
_CLASS_NAME = {"integrator": "Integrator", "record": "Record", "stop": "Stop",
               "limits": "Limits"}


def new_spelling(old: str) -> str:
    """How an old keyword is written now, e.g. ``record=pdw.Record(every=...)``."""
    section, name = LEGACY[old]
    if old == "periodic_steps":
        return "stop=pdw.Stop(periodic=True, periodic_steps=...) (0: periodic=False)"
    return "%s=pdw.%s(%s=...)" % (section, _CLASS_NAME[section], name)


def _legacy_fields(old, value):
    """The fields an old keyword's value sets (periodic_steps = 0 meant off)."""
    section, name = LEGACY[old]
    if old == "periodic_steps":
        if _integer(value) and int(value) == 0:
            return {"periodic": False}
        return {"periodic": True, "periodic_steps": value}
    return {name: value}


def resolve(fn: str, positional: tuple, legacy: dict, objects: dict, stacklevel: int = 3):
    """Map the old spellings of ``fn`` onto option objects, warning once per old spelling.

    Parameters
    ----------
    fn : str
        ``"simulate"``, ``"simulate_batch"`` or ``"simulate_many"`` (for the messages and the
        positional order, `POSITIONAL`).
    positional : tuple
        Arguments given by position after (x0, t_end, dt).
    legacy : dict
        Old keywords given (keys of `LEGACY`); anything else is an error naming it.
    objects : dict
        ``{"integrator": Integrator or None, ...}``: the objects given.

    Returns
    -------
    (dict, dict)
        The objects (None where neither the object nor an old keyword was given) and the
        plain keywords given by position (``params``, ``variant``, ...).

    Raises
    ------
    InvalidInputError
        Too many positional arguments, an unknown keyword, an object and an old keyword for
        one of its fields both given, or an invalid value (naming the field).
    """
    order = POSITIONAL[fn]
    if len(positional) > len(order):
        raise InvalidInputError("%s takes at most %d positional arguments (x0, t_end, dt and, "
                                "deprecated, %s), got %d" % (fn, 3 + len(order), ", ".join(order),
                                                             3 + len(positional)))
    plain = {}
    for name, value in zip(order, positional):
        warnings.warn("%s: passing %s by position is deprecated; write %s(x0, t_end, dt, %s)"
                      % (fn, name, fn, new_spelling(name) if name in LEGACY else name + "=..."),
                      PdwDeprecationWarning, stacklevel=stacklevel)
        if name in LEGACY:
            if name in legacy:
                raise InvalidInputError("%s got %s both by position and by keyword" % (fn, name))
            legacy = {**legacy, name: value}
        else:
            plain[name] = value
    fields: dict = {}
    for old, value in legacy.items():
        if old not in LEGACY:
            raise InvalidInputError("%s got an unexpected keyword argument %r" % (fn, old))
        if not any(old == n for n in order[:len(positional)]):
            warnings.warn("%s(%s=...) is deprecated; write %s" % (fn, old, new_spelling(old)),
                          PdwDeprecationWarning, stacklevel=stacklevel)
        section = LEGACY[old][0]
        if objects.get(section) is not None:
            raise InvalidInputError("%s got both %s= and the old keyword %s= (its field %s.%s): "
                                    "give it in the object" % (fn, section, old, section,
                                                               LEGACY[old][1]))
        fields.setdefault(section, {}).update(_legacy_fields(old, value))
    out = dict(objects)
    for section, values in fields.items():
        try:
            out[section] = OPTION_SECTIONS[section](**values)
        except InvalidInputError as e:          # name the keyword the caller wrote
            text = str(e)
            for old in legacy:
                key = "%s.%s" % LEGACY[old]
                if LEGACY[old][0] == section and repr(key) in text:
                    text = text.replace(repr(key), "%r (now %r)" % (old, key), 1)
                    break
            raise InvalidInputError(text) from None
    return out, plain


def options_of(**given) -> dict:
    """The option objects of a run: those given, the defaults for the others."""
    return {name: DEFAULTS[name] if given.get(name) is None else given[name]
            for name in OPTION_SECTIONS}


def check_type(name: str, value, cls):
    """``value`` is None or a ``cls`` (a dict is read as its table)."""
    if value is None or isinstance(value, cls):
        return value
    if isinstance(value, dict):
        return cls.from_dict(value)
    raise InvalidInputError("%s must be a pdw.%s (or a dict of its fields), got %s"
                            % (name, cls.__name__, type(value).__name__))


def c_options(*objects, **derived) -> dict:
    """A run's options as the compiled loops read them: one record of the fields of
    pdw_run_opts (pdw/core/csrc/pdw_sim.h) by name, which `pdw.core._core.run` and
    `pdw.core._batch.run_range` take whole and fill into the struct with one filler
    (pdw/core/_opts.pxi). Each field of the option objects with a C name
    (``_f(..., c=NAME)``) under that name, unset (None) ones left out; then ``derived``: what
    a run derives itself (dt, n_steps, t_end, h_max, the step budget max_steps, the periodic
    window periodic_k, the fall limits of l), by field name. A field given by neither is 0 in
    the struct (off)."""
    out: dict = {}
    for obj in objects:
        own = obj.__dict__.get("_c")            # made once per (frozen) object
        if own is None:
            own = {}
            for f in dataclasses.fields(obj):
                name, value = f.metadata.get("c"), getattr(obj, f.name)
                if name is not None and value is not None:
                    own[name] = int(value) if isinstance(value, bool) else value
            obj.__dict__["_c"] = own
        out.update(own)
    out.update(derived)
    return out


class Settled(NamedTuple):
    """The options of one call, settled: the four objects (defaults where not given), the
    method, dt and t_end to run, and the plain arguments given by (deprecated) position."""

    integrator: Integrator
    record: Record
    stop: Stop
    limits: Limits
    method: str
    dt: float
    t_end: float
    plain: dict

    def ran(self, checked: tuple | None = None) -> tuple:
        """(Integrator, Stop) with the method, dt and t_end run: what a run reports, and what
        one call passes on to another without giving a value twice. ``checked``: (method, dt,
        t_end) as validated by the run (the copies are then made without checking again)."""
        it, st = self.integrator, self.stop
        method, dt, t_end = (self.method, self.dt, self.t_end) if checked is None else checked
        new = dataclasses.replace if checked is None else _with
        if it.method != method or it.dt != dt:
            it = new(it, method=method, dt=float(dt))
        if st.t_end != t_end:
            st = new(st, t_end=float(t_end))
        return it, st


def no_record(fn: str, settled: Settled) -> None:
    """The ensembles record no samples (their ``record`` lists walkers to rerun): an old
    ``record_*`` keyword given to them is an error, not ignored."""
    if settled.record is not DEFAULTS["record"]:
        raise InvalidInputError("%s records no samples: record_every (walkers listed in "
                                "record=) is its only recording option" % fn)


def _with(obj, **changes):
    """A copy of an option object with already validated field values (no checks)."""
    new = object.__new__(type(obj))
    new.__dict__.update(obj.__dict__)
    new.__dict__.update(changes)
    new.__dict__.pop("_c", None)                # c_options of the copy: made anew
    return new


def settle(fn: str, positional: tuple, legacy: dict, *, integrator=None, record=None, stop=None,
           limits=None, method=None, dt=None, t_end=None, keywords=None) -> Settled:
    """The one path from a call's arguments to its options (`simulate`, `simulate_batch`,
    `simulate_many`): old spellings mapped (`resolve`), dicts read as tables, ``method``,
    ``dt`` and ``t_end`` given as arguments checked against the objects (given twice, they
    must agree), defaults filled in.

    ``keywords``: ``{name: (value, default)}`` of the plain keywords, so that one given both
    by position and by keyword is an error.
    """
    plain: dict = {}
    if positional or legacy:
        objs, plain = resolve(fn, positional, legacy, dict(integrator=integrator, record=record,
                                                           stop=stop, limits=limits),
                              stacklevel=4)
        integrator, record, stop, limits = (objs["integrator"], objs["record"], objs["stop"],
                                            objs["limits"])
        for name in plain:
            value, default = (keywords or {}).get(name, (None, None))
            if value is not default and not _equal(value, default):
                raise InvalidInputError("%s got %s both by position and by keyword" % (fn, name))
        method = plain.pop("method", method)
    it = DEFAULTS["integrator"] if integrator is None else \
        check_type("integrator", integrator, Integrator)
    rec = DEFAULTS["record"] if record is None else check_type("record", record, Record)
    st = DEFAULTS["stop"] if stop is None else check_type("stop", stop, Stop)
    lim = DEFAULTS["limits"] if limits is None else check_type("limits", limits, Limits)
    method = _agree("method", method, it, METHOD)
    dt = _agree("dt", dt, it, DT)
    t_end = _agree("t_end", t_end, st, T_END)
    return Settled(it, rec, st, lim, method, dt, t_end, plain)


def _equal(a, b):
    try:
        return bool(np.array_equal(np.asarray(a, dtype=object), np.asarray(b, dtype=object)))
    except (TypeError, ValueError):
        return False


def _agree(name, value, obj, default):
    """The argument ``value``, else the object's field, else ``default``; given both ways,
    they must agree."""
    other = getattr(obj, name)
    if value is None:
        return default if other is None else other
    if other is not None:
        try:
            same = bool(value == other)
        except (TypeError, ValueError):
            same = False
        if not same:
            raise InvalidInputError("%s = %r and %s.%s = %r disagree: give it once"
                                    % (name, value, obj.SECTION, name, other))
    return value
