"""Scenes: everything one simulation needs, as one object or one TOML file (docs/scenes.md).

A `Scene` says which walker (a parameter preset plus overrides, the contact variant), where it
starts (initial state and support flags), how it is integrated (method, dt, tolerances), which
force elements are present, what is recorded, and when the run stops. `run` (or
``pdw.simulate(scene)``) runs it; the CLI runs a scene file with ``pdw run scene.toml``.

What a scene does not need is not paid for: absent force elements select a specialized
generated kernel (`pdw.core.model.kernel_index`), a run that records only the gait descriptors
keeps O(1) memory (the compiled loop computes them online), and a run can stop as soon as its
gait is known (a number of steps, or the last k steps agreeing).

TOML layout (every key optional; defaults are `Scene()`'s)::

    name = "typical gait"
    preset = "paper_steady"          # Params preset: "paper" or "paper_steady"
    variant = "paper"                # docs/model.md section 6: "paper" or "consistent"
    x0 = [0.0, 0.4969, -0.0582, 0.0582, 0.5092, 0.0186, 3.3338, -1.0093]
    flags0 = [0, 1]

    [params]                         # overrides of the preset, any pdw.Params field
    k_hip = 0.9

    [integrator]
    method = "cdm"                   # cdm, verlet, rk4, dopri5, rodas4
    dt = 0.0001                      # step (adaptive methods: the first trial step)
    rtol = 1e-06                     # adaptive methods only: rtol, atol, h_max, event_tol
    atol = 1e-08
    event_tol = 1e-09

    [forces]                         # force elements present
    hip_spring = true
    hip_damper = true
    normal_damping = true
    tangential = true
    friction = true

    [record]
    every = 1                        # full state every k steps (0: none)
    forces = true                    # contact forces at those samples
    energies = false                 # energies at those samples
    events = true                    # the list of touch-downs and lift-offs

    [contact]                        # contact laws (docs/contact_laws.md)
    normal = "hunt_crossley"         # hertz, kelvin_voigt, lankarani_nikravesh, flores
    friction = "coulomb"
    # k, d, e, v_in_min: the law's parameters (unset: the preset's k_n, d_n)

    [ground]                         # the ground (docs/terrain.md); unset: flat
    kind = "flat"                    # steps, profile, plane, sine, random, sum
    # the kind's parameters (edges, heights, width; s, h, order; slope; amplitude,
    # wavelength, phase; sigma, correlation, seed), offset, extent, patches = [{s_a, s_b, k_n, ...}]

    [stop]
    t_end = 3.5                      # [s]
    steps = 0                        # stop after this many complete gait steps (0: no limit)
    periodic = false                 # stop when the last periodic_steps steps agree ...
    periodic_steps = 4
    periodic_tol = 0.001             # ... within this relative tolerance
    max_speed = 1000.0               # diverged above this speed
    on_failure = "raise"             # a diverged run: "raise" or "return"
    # fall_hip_height, fall_depth [m]: the fall thresholds (default 0.5 l, 0.25 l)

Unknown keys and values of the wrong type are errors naming the key (``record.evry``).

Why this module is long: it is the scene's schema, every section's fields with their TOML
types, units, meaning and checks (the field metadata), next to the reading, checking and
writing that use them; split, a field and its check would live apart.
"""
from __future__ import annotations

import dataclasses
import math
import os
import pathlib
from dataclasses import dataclass, field
from typing import Any

from ..core import _layout, _toml
from ..core.contact import Contact
from ..core.errors import InvalidInputError
from ..core.ground import Ground
from ..core.integrators import METHODS
from ..core.params import X0_PAPER, Params
from .simulation import Result, simulate

PRESETS = ("paper", "paper_steady")
ON_FAILURE = ("raise", "return")


def _f(default, kind, doc, check=None):
    """A scene field: its TOML type (``kind``), its meaning, and a value check returning an
    error text or None."""
    if isinstance(default, (dict, list)):
        return field(default_factory=lambda: type(default)(default),
                     metadata=dict(kind=kind, doc=doc, check=check))
    return field(default=default, metadata=dict(kind=kind, doc=doc, check=check))


def _positive(v):
    return None if v > 0 and math.isfinite(v) else "must be finite and > 0"


def _nonnegative(v):
    return None if v >= 0 else "must be >= 0"


def _one_of(options):
    def check(v):
        return None if v in options else "must be one of %s" % ", ".join(map(repr, options))
    return check


def _method_check(v):
    return _one_of(METHODS)(v)


def _periodic_steps_check(v):
    return None if 2 <= v <= _layout.STEP_RING else "must be in [2, %d]" % _layout.STEP_RING


KINDS = {
    "str": "a string", "float": "a number", "float?": "a number", "int": "an integer",
    "bool": "true or false", "state": "a list of 8 numbers", "flags": "a list of two 0/1 integers",
    "params": "a table of parameter values",
    "ground": "a [ground] table (docs/terrain.md)",
}


def _err(key, text):
    return InvalidInputError("scene key %r %s" % (key, text))


def _coerce(value, kind, key):
    """Check the type of one value (as read from TOML or given in Python) and normalise it."""
    def bad():
        return _err(key, "must be %s, got %r" % (KINDS[kind], value))

    def number(v):
        return isinstance(v, (int, float)) and not isinstance(v, bool)

    if kind == "str":
        if not isinstance(value, str):
            raise bad()
        return value
    if kind in ("float", "float?"):
        if value is None and kind == "float?":
            return None
        if not number(value):
            raise bad()
        return float(value)
    if kind == "int":
        if not isinstance(value, int) or isinstance(value, bool):
            raise bad()
        return int(value)
    if kind == "bool":
        if not isinstance(value, bool):
            raise bad()
        return value
    if kind == "state":
        if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__len__") \
                or len(value) != len(_layout.STATE) or not all(number(v) for v in value):
            raise bad()
        out = tuple(float(v) for v in value)
        for name, v in zip(_layout.STATE, out):
            if not math.isfinite(v):
                raise _err(key, "component %s must be finite, got %r" % (name, v))
        return out
    if kind == "flags":
        if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__len__") \
                or len(value) != 2 or not all(isinstance(v, int) and not isinstance(v, bool)
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
            if not number(v):
                raise _err("%s.%s" % (key, name), "must be a number, got %r" % (v,))
            out[name] = float(v)
        return out
    if kind == "ground":
        if value is None or isinstance(value, Ground):
            return value
        if not isinstance(value, dict):
            raise bad()
        try:
            return Ground.from_dict(value)
        except InvalidInputError as e:
            raise _err(key, "is invalid: %s" % e) from None
    raise AssertionError(kind)


class _Section:
    """A table of a scene: typed, checked fields; from and to plain dicts."""

    SECTION = ""

    def __post_init__(self):
        for f in dataclasses.fields(self):
            key = "%s.%s" % (self.SECTION, f.name) if self.SECTION else f.name
            value = getattr(self, f.name)
            kind = f.metadata["kind"]
            if kind in SECTION_TYPES:
                value = SECTION_TYPES[kind].from_dict(value) if isinstance(value, dict) else value
                if not isinstance(value, SECTION_TYPES[kind]):
                    raise _err(key, "must be a table (%s), got %r"
                               % (SECTION_TYPES[kind].__name__, value))
            else:
                value = _coerce(value, kind, key)
                check = f.metadata["check"]
                problem = check(value) if (check is not None and value is not None) else None
                if problem:
                    raise _err(key, "%s, got %r" % (problem, value))
            object.__setattr__(self, f.name, value)
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
        """Plain dict (nested for sections); None values left out (TOML has no null)."""
        out: dict[str, Any] = {}
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            v = getattr(self, f.name)
            if isinstance(v, _Section):
                out[f.name] = v.to_dict()
            elif isinstance(v, Ground):
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
        d = self.to_dict()
        for key, v in changes.items():
            if key not in d and key not in {f.name for f in dataclasses.fields(self)}:
                full = "%s.%s" % (self.SECTION, key) if self.SECTION else key
                raise _err(full, "is unknown; allowed here: %s"
                           % ", ".join(f.name for f in dataclasses.fields(self)))
            if isinstance(v, dict) and isinstance(d.get(key), dict):
                d[key] = {**d[key], **v}
            elif isinstance(v, _Section):
                d[key] = v.to_dict()
            else:
                d[key] = v
        return type(self).from_dict(d)


@dataclass(frozen=True)
class Integrator(_Section):
    """How the run is integrated (docs/integrators.md)."""

    SECTION = "integrator"
    method: str = _f("cdm", "str", "integrator: cdm (the paper's), verlet, rk4, dopri5, rodas4",
                     _method_check)
    dt: float = _f(1e-4, "float", "step [s]; adaptive methods: the first trial step", _positive)
    rtol: float = _f(1e-6, "float", "relative tolerance of adaptive methods", _positive)
    atol: float = _f(1e-8, "float", "absolute tolerance of adaptive methods", _positive)
    h_max: float | None = _f(None, "float?", "largest step of adaptive methods [s] (none)",
                             _positive)
    event_tol: float = _f(1e-9, "float", "adaptive methods locate flag switches to this [s]",
                          _positive)


@dataclass(frozen=True)
class Forces(_Section):
    """Which force elements are present (docs/model.md sections 3-4). Absent ones are switched off
    in a specialized kernel, or by zeroing their parameters (`Params.without`)."""

    SECTION = "forces"
    hip_spring: bool = _f(True, "bool", "hip torsional spring k_hip")
    hip_damper: bool = _f(True, "bool", "hip torsional damper d_hip")
    normal_damping: bool = _f(True, "bool", "Hunt-Crossley normal damping d_n")
    tangential: bool = _f(True, "bool", "tangential spring-damper k_t, d_t")
    friction: bool = _f(True, "bool", "friction mu(v_t) F_n")

    def present(self) -> tuple:
        """The features present, in `pdw.core._layout.FEATURES` order."""
        return tuple(f for f in _layout.FEATURES if getattr(self, f))

    @classmethod
    def only(cls, *features) -> "Forces":
        """Exactly these force elements present."""
        unknown = set(features) - set(_layout.FEATURES)
        if unknown:
            raise _err("forces", "has no element(s) %s; allowed: %s"
                       % (", ".join(sorted(unknown)), ", ".join(_layout.FEATURES)))
        return cls(**{f: f in features for f in _layout.FEATURES})


@dataclass(frozen=True)
class Record(_Section):
    """What the run records. The gait descriptors are always computed (online, O(1) memory:
    `Result.gait`)."""

    SECTION = "record"
    every: int = _f(1, "int", "full state every k steps (0: none)", _nonnegative)
    forces: bool = _f(True, "bool", "contact forces at the recorded samples")
    energies: bool = _f(False, "bool", "energies at the recorded samples (needs every > 0)")
    events: bool = _f(True, "bool", "the list of touch-downs and lift-offs (else only counts)")

    def _check(self):
        if self.energies and self.every == 0:
            raise _err("record.energies", "needs recorded states (record.every > 0)")

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
    """When the run ends: t_end, a number of gait steps, a periodic gait, or a fall (always)."""

    SECTION = "stop"
    t_end: float = _f(3.5, "float", "duration [s]", _positive)
    steps: int = _f(0, "int", "stop after this many complete gait steps (0: no limit)",
                    _nonnegative)
    periodic: bool = _f(False, "bool", "stop when the last periodic_steps steps agree")
    periodic_steps: int = _f(4, "int", "k: how many successive steps must agree",
                             _periodic_steps_check)
    periodic_tol: float = _f(1e-3, "float", "relative tolerance on L, travel, P and cycle",
                             _positive)
    fall_hip_height: float | None = _f(None, "float?", "fell when the hip is lower [m] "
                                       "(default 0.5 l)")
    fall_depth: float | None = _f(None, "float?", "fell when a foot is deeper [m] "
                                  "(default 0.25 l)", _positive)
    max_speed: float = _f(1e3, "float", "diverged when a velocity exceeds this", _positive)
    on_failure: str = _f("raise", "str", "a diverged run: raise DivergedError, or return it",
                         _one_of(ON_FAILURE))


@dataclass(frozen=True)
class ContactLaws(_Section):
    """The normal and friction contact laws and their parameters (`pdw.Contact`,
    docs/contact_laws.md); unset parameters: the preset's k_n, d_n."""

    SECTION = "contact"
    normal: str = _f("hunt_crossley", "str", "normal law", _one_of(_layout.NORMAL_LAWS))
    friction: str = _f("coulomb", "str", "friction law", _one_of(_layout.FRICTION_LAWS))
    k: float | None = _f(None, "float?", "normal stiffness [N/m^1.5; kelvin_voigt N/m]")
    d: float | None = _f(None, "float?", "normal damping [N s/m^2.5; kelvin_voigt N s/m]")
    e: float | None = _f(None, "float?", "coefficient of restitution (lankarani_nikravesh, flores)")
    v_in_min: float | None = _f(None, "float?", "smallest approach speed [m/s] (idem)")
    sigma0: float | None = _f(None, "float?", "LuGre bristle stiffness per unit normal force [1/m]")
    sigma1: float | None = _f(None, "float?", "LuGre bristle damping per unit normal force [s/m]")
    sigma2: float | None = _f(None, "float?", "LuGre viscous friction per unit normal force [s/m]")
    mu_s: float | None = _f(None, "float?", "LuGre static friction coefficient [-]")
    mu_c: float | None = _f(None, "float?", "LuGre Coulomb friction coefficient [-]")
    v_s: float | None = _f(None, "float?", "LuGre Stribeck velocity [m/s]")

    def _check(self):
        try:
            self.to_contact()
        except InvalidInputError as e:
            raise _err("contact", "is invalid: %s" % e) from None

    def to_contact(self):
        """The `pdw.Contact` of this table."""
        return Contact(**{f.name: getattr(self, f.name) for f in dataclasses.fields(self)})


SECTION_TYPES = {"integrator": Integrator, "forces": Forces, "record": Record, "stop": Stop,
                 "contact": ContactLaws}


@dataclass(frozen=True)
class Scene(_Section):
    """Everything one simulation needs (see the module docstring for the TOML form).

    Build one in Python (``Scene(preset="paper_steady", record=Record.descriptors_only(),
    stop={"t_end": 20.0, "periodic": True})`` -- a table may be given as a dict), read one
    (`Scene.load`, `Scene.from_toml`), write one (`Scene.save`, `Scene.to_toml`; the text reads
    back to an equal scene), change one (`Scene.replace`), run one (`Scene.run`, `pdw.run`,
    ``pdw.simulate(scene)``).
    """

    SECTION = ""
    name: str = _f("", "str", "a label")
    preset: str = _f("paper", "str", "parameter preset (pdw.Params.preset)", _one_of(PRESETS))
    params: dict = _f({}, "params", "overrides of the preset's parameters")
    variant: str = _f("paper", "str", "contact variant (docs/model.md section 6)",
                      _one_of(_layout.VARIANTS))
    x0: tuple = _f(X0_PAPER, "state", "initial state [x_o, y_o, theta1, theta2, rates]")
    flags0: tuple = _f((0, 1), "flags", "initial support flags of legs 1, 2")
    integrator: Integrator = _f(Integrator(), "integrator", "integration method and settings")
    forces: Forces = _f(Forces(), "forces", "force elements present")
    record: Record = _f(Record(), "record", "what is recorded")
    stop: Stop = _f(Stop(), "stop", "when the run stops")
    contact: ContactLaws = _f(ContactLaws(), "contact", "normal and friction contact laws")
    ground: Ground | None = _f(None, "ground", "the ground walked on (pdw.Ground, docs/terrain.md); "
                               "unset: flat")

    def _check(self):
        for name, value in self.params.items():
            try:
                Params.preset(self.preset, **{name: value})
            except ValueError as e:
                raise _err("params.%s" % name, "is invalid: %s" % e) from None
        try:
            self.parameters()
        except ValueError as e:
            raise _err("params", "is invalid: %s" % e) from None
        if self.integrator.dt > self.stop.t_end:
            raise _err("integrator.dt", "= %g must not exceed stop.t_end = %g"
                       % (self.integrator.dt, self.stop.t_end))

    def __hash__(self):
        return hash(self.to_toml())

    # --- what the scene means -----------------------------------------------------------
    def parameters(self) -> Params:
        """The preset with the overrides (all force elements' parameters as given; `run`
        zeroes those of absent elements)."""
        return Params.preset(self.preset, **self.params)

    @property
    def features(self) -> tuple:
        """The force elements present (`Forces.present`)."""
        return self.forces.present()

    def simulate_kwargs(self) -> dict:
        """The `pdw.simulate` arguments this scene stands for."""
        st, it, rec = self.stop, self.integrator, self.record
        return dict(
            x0=self.x0, t_end=st.t_end, dt=it.dt, params=self.parameters(), variant=self.variant,
            method=it.method, flags0=self.flags0, record_every=rec.every,
            record_forces=rec.forces, on_failure=st.on_failure,
            fall_hip_height=st.fall_hip_height, fall_depth=st.fall_depth,
            max_speed=st.max_speed, rtol=it.rtol, atol=it.atol, h_max=it.h_max,
            event_tol=it.event_tol, features=self.features, record_events=rec.events,
            record_energies=rec.energies, stop_steps=st.steps,
            periodic_steps=st.periodic_steps if st.periodic else 0,
            periodic_tol=st.periodic_tol, contact=self.contact.to_contact(), ground=self.ground)

    def run(self) -> Result:
        """Run the scene (`pdw.simulate` with the scene's settings).

        Returns
        -------
        Result
            With ``result.scene`` set to this scene (saved with the result's provenance).
        """
        return simulate(self)

    # --- TOML ----------------------------------------------------------------------------
    @classmethod
    def from_toml(cls, text: str, source: str = "scene") -> Scene:
        """Read a scene from TOML text (docs/scenes.md).

        Parameters
        ----------
        text : str
            The TOML document.
        source : str
            Where the text came from, for error messages.

        Returns
        -------
        Scene

        Raises
        ------
        InvalidInputError
            Invalid TOML, an unknown key, a wrong type or an invalid value, naming the key.
        """
        try:
            data = _toml.loads(text)
        except _toml.TOMLDecodeError as e:
            raise InvalidInputError("%s: not valid TOML: %s" % (source, e)) from None
        except RecursionError:
            raise InvalidInputError("%s: TOML nested too deeply" % source) from None
        try:
            return cls.from_dict(data)
        except InvalidInputError as e:
            raise InvalidInputError("%s: %s" % (source, e)) from None

    @classmethod
    def load(cls, path: str | os.PathLike) -> Scene:
        """Read a scene file (TOML, docs/scenes.md; `Scene.save` writes one).

        Parameters
        ----------
        path : str or path-like
            The file.

        Returns
        -------
        Scene

        Raises
        ------
        InvalidInputError
            The file cannot be read, or its content is not a valid scene (naming the key).
        """
        path = pathlib.Path(path)
        try:
            text = path.read_text()
        except OSError as e:
            raise InvalidInputError("cannot read scene file %s: %s" % (path, e)) from None
        return cls.from_toml(text, source=str(path))

    def to_toml(self) -> str:
        """TOML text of the scene; `Scene.from_toml` reads it back to an equal scene."""
        return _toml.dumps(self.to_dict(), "pdw scene (docs/scenes.md); run it with `pdw run FILE`")

    def save(self, path: str | os.PathLike) -> pathlib.Path:
        """Write the scene as a TOML file (`Scene.to_toml`); `Scene.load` reads it back to an
        equal scene. Returns the path written."""
        path = pathlib.Path(path)
        path.write_text(self.to_toml())
        return path


def run(scene: Scene | str | os.PathLike) -> Result:
    """Run a scene: ``pdw.run("walk.toml")`` or ``pdw.run(scene)``.

    Parameters
    ----------
    scene : Scene, str or path-like
        A `Scene`, or the path of a scene file (TOML, docs/scenes.md; read with `Scene.load`).

    Returns
    -------
    Result
        The simulated run (`pdw.simulate`), ``result.scene`` set.

    Raises
    ------
    InvalidInputError
        Anything else than a scene or a path, or an invalid scene file.
    """
    if isinstance(scene, (str, pathlib.Path)):
        scene = Scene.load(scene)
    if not isinstance(scene, Scene):
        raise InvalidInputError("run() needs a pdw.Scene or a scene file path, got %s"
                                % type(scene).__name__)
    return scene.run()
