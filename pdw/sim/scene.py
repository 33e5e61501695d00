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
    # approach_speeds0 = [0.0, 0.0]  # [m/s] of the feet starting in support (default -v_y)

    [params]                         # overrides of the preset, any pdw.Params field
    k_hip = 0.9

    [integrator]
    method = "cdm"                   # cdm, verlet, rk4, dopri5, rodas4
    dt = 0.0001                      # step (adaptive methods: the first trial step)
    rtol = 1e-06                     # adaptive methods only: rtol, atol, h_max, event_tol
    atol = 1e-08
    event_tol = 1e-09
    check_step = "warn"              # fixed-step methods: dt above the stability limit
    # h_max [s], max_steps: largest step and step budget of adaptive methods

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
    dense_output = false             # also the interpolant Result.sol (needs every = 1)
    # t_eval = [0.5, 1.0]            # return the solution at these times [s] (every = 1)

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
    touch_down = 0                   # 1 or 2: stop at that leg's first touch-down (0: off)

    [limits]
    max_speed = 1000.0               # diverged above this speed
    on_failure = "raise"             # a diverged run: "raise" or "return"
    # fall_hip_height, fall_depth [m]: the fall thresholds (default 0.5 l, 0.25 l)

Unknown keys and values of the wrong type are errors naming the key (``record.evry``). The
sections ``[integrator]``, ``[record]``, ``[stop]`` and ``[limits]`` are the option objects of
`pdw.sim.options` that `pdw.simulate` takes, so a scene can say everything a run can (except
``record.out``, a buffer in memory). The fall and divergence keys of ``[stop]`` of before are
read into ``[limits]`` for one release, with a `DeprecationWarning`.

Why this module is long: it is the scene's schema, every section's fields with their TOML
types, units, meaning and checks (the field metadata), next to the reading, checking and
writing that use them; split, a field and its check would live apart.
"""
from __future__ import annotations

import dataclasses
import os
import pathlib
import warnings
from dataclasses import dataclass

from ..core import _layout, _toml
from ..core.contact import Contact
from ..core.errors import InvalidInputError, PdwDeprecationWarning
from ..core.ground import Ground
from ..core.params import X0_PAPER, Params
from . import options as _options
from .options import (  # noqa: F401  (KINDS, _Section, _coerce, _f: their home before)
    KINDS,
    ON_FAILURE,
    Integrator,
    Limits,
    Record,
    Stop,
    _coerce,
    _err,
    _f,
    _one_of,
    _Section,
)
from .simulation import Result, simulate

PRESETS = ("paper", "paper_steady")


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
class ContactLaws(_Section):
    """The normal and friction contact laws and their parameters (`pdw.Contact`,
    docs/contact_laws.md); unset parameters: the preset's k_n, d_n."""

    SECTION = "contact"
    normal: str = _f("hunt_crossley", "str", "normal law", _one_of(_layout.NORMAL_LAWS))
    friction: str = _f("coulomb", "str", "friction law", _one_of(_layout.FRICTION_LAWS))
    k: float | None = _f(None, "float?", "normal stiffness [N/m^1.5; kelvin_voigt N/m] "
                         "(default Params.k_n; kelvin_voigt its calibrated 7318)")
    d: float | None = _f(None, "float?", "normal damping [N s/m^2.5; kelvin_voigt N s/m] "
                         "(default Params.d_n; kelvin_voigt its calibrated 112.2)")
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
                 "limits": Limits, "contact": ContactLaws}
_options._EXTRA_SECTIONS.update(forces=Forces, contact=ContactLaws)
MOVED_TO_LIMITS = _options.MOVED_TO_LIMITS   # keys of [stop] read into [limits], warning


@dataclass(frozen=True)
class Scene(_Section):
    """Everything one simulation needs (see the module docstring for the TOML form).

    Build one in Python (``Scene(preset="paper_steady", record=Record.descriptors_only(),
    stop={"t_end": 20.0, "periodic": True})`` -- a table may be given as a dict), read one
    (`Scene.load`, `Scene.from_toml`), write one (`Scene.save`, `Scene.to_toml`; the text reads
    back to an equal scene), change one (``Scene.replace``), run one (`Scene.run`, `pdw.run`,
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
    limits: Limits = _f(Limits(), "limits", "when the run fell or diverged")
    contact: ContactLaws = _f(ContactLaws(), "contact", "normal and friction contact laws")
    approach_speeds0: tuple | None = _f(None, "pair?", "approach speeds [m/s] of the feet "
                                        "that start in support (default max(-v_y, 0))")
    ground: Ground | None = _f(None, "ground", "the ground walked on (pdw.Ground, "
                               "docs/terrain.md); unset: flat")

    def __post_init__(self):
        stop, limits = _move_limits(self.stop, self.limits)
        object.__setattr__(self, "stop", stop)
        object.__setattr__(self, "limits", limits)
        super().__post_init__()

    def replace(self, **changes) -> Scene:
        """A copy with some fields changed; a table given as a dict updates that table."""
        if isinstance(changes.get("stop"), dict):
            moved = {k: v for k, v in changes["stop"].items() if k in MOVED_TO_LIMITS}
            if moved:
                _warn_moved(moved)
                changes["stop"] = {k: v for k, v in changes["stop"].items() if k not in moved}
                lim = changes.get("limits", {})
                changes["limits"] = {**(lim.to_dict() if isinstance(lim, Limits) else lim),
                                     **moved}
        return super().replace(**changes)

    def _check(self):
        it, st = self.integrator, self.stop         # a scene says its method, dt and t_end
        if it.method is None or it.dt is None:
            object.__setattr__(self, "integrator", _options._with(
                it, method=it.method or _options.METHOD,
                dt=_options.DT if it.dt is None else it.dt))
        if st.t_end is None:
            object.__setattr__(self, "stop", _options._with(st, t_end=_options.T_END))
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
        """The `pdw.simulate` arguments this scene stands for: x0, t_end, dt, the option
        objects (`pdw.sim.options`) and the model (params, variant, features, contact, ...)."""
        kw = dict(x0=self.x0, t_end=self.stop.t_end, dt=self.integrator.dt,
                  params=self.parameters(), variant=self.variant, flags0=self.flags0,
                  integrator=self.integrator, record=self.record, stop=self.stop,
                  limits=self.limits, features=self.features,
                  contact=self.contact.to_contact(), approach_speeds0=self.approach_speeds0)
        if self.ground is not None:
            kw["ground"] = self.ground
        return kw

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


def _warn_moved(moved):
    warnings.warn("scene [stop] keys %s moved to [limits] (pdw.Limits); [stop] reads them for "
                  "one more release" % ", ".join(sorted(moved)), PdwDeprecationWarning, stacklevel=4)


def _move_limits(stop, limits):
    """A [stop] table of before with fall and divergence keys: move them to [limits]."""
    if not isinstance(stop, dict):
        return stop, limits
    moved = {k: stop[k] for k in MOVED_TO_LIMITS if k in stop}
    if not moved:
        return stop, limits
    _warn_moved(moved)
    if isinstance(limits, Limits):
        if limits != Limits():
            both = [k for k in moved if getattr(limits, k) != getattr(Limits(), k)]
            if both:
                raise _err("stop.%s" % both[0], "is given in [limits] too: give it there only")
        limits = limits.to_dict()
    elif isinstance(limits, dict):
        both = [k for k in moved if k in limits]
        if both:
            raise _err("stop.%s" % both[0], "is given in [limits] too: give it there only")
    else:
        return stop, limits
    return ({k: v for k, v in stop.items() if k not in moved}, {**limits, **moved})


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
