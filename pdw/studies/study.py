"""A parameter study, as data: the TOML file format of ``pdw sweep`` and its validation
(docs/studies.md).

A study sweeps one or two `Params` fields over ranges (``[[axes]]``); everything else is one
`pdw.Scene`, the ``[scene]`` table (the schema of ``pdw run`` and ``pdw walk --scene``: preset,
parameter overrides, variant, x0, flags0, integrator, stop), on top of `SCENE_DEFAULTS`;
``[run]`` says how each point's steady gait is found.
`load_study` / `parse_study` check every key and value and name the key in the error;
`Study.points` lists the parameter sets. Running a study is `pdw.studies.sweep.run_study`.
"""
from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import pathlib

import numpy as np

from ..core import _layout, _toml, checks, paths
from ..core.errors import InvalidInputError
from ..core.params import Params
from ..sim.scene import Scene

STUDY_KEYS = {"name": str, "title": str, "description": str, "scene": dict, "axes": list,
              "run": dict, "paper": dict}
AXIS_KEYS = {"name": str, "values": list, "start": (int, float), "stop": (int, float),
             "num": int, "log": bool}
RUN_KEYS = {"mode": str, "steady": int, "period_tol": (int, float), "fallback": bool}
RUN_DEFAULTS = {"mode": "simulate", "steady": 4, "period_tol": 1e-4, "fallback": True}
#: The scene of a study before its ``[scene]`` table: the steady preset, rodas4 at tight
#: tolerances, 16 s, events and descriptors only, a diverged point returned as a row.
SCENE_DEFAULTS = {"preset": "paper_steady",
                  "integrator": {"method": "rodas4", "rtol": 1e-7, "atol": 1e-9},
                  "record": {"every": 0, "forces": False, "energies": False, "events": True},
                  "stop": {"t_end": 16.0}, "limits": {"on_failure": "return"}}
#: Keys of the earlier study format and where they live now.
MOVED = {"preset": "scene.preset", "variant": "scene.variant", "method": "scene.integrator.method",
         "params": "scene.params", "run.t_end": "scene.stop.t_end", "run.dt": "scene.integrator.dt",
         "run.rtol": "scene.integrator.rtol", "run.atol": "scene.integrator.atol",
         "run.x0": "scene.x0", "run.flags0": "scene.flags0"}
#: Result columns of a point (after the index and the axis values).
COLUMNS = ("status", "gait", "source", "L", "P", "v", "cycle", "double_support", "ds_fraction", "travel",
           "spread_L", "spread_cycle", "n_steps", "max_multiplier", "t_final", "wall_s", "error",
           "settings")
#: A study name is a plain file name (`pdw.core.paths.file_stem`, the rule of every name that
#: becomes a file name).
NAME_RE = paths.NAME_RE
#: Most points one study may have (also the most values of one axis).
MAX_POINTS = 10 ** 6


# --- the study --------------------------------------------------------------------------------

@dataclasses.dataclass
class Study:
    """A parsed study file (see the module docstring and docs/studies.md)."""

    name: str
    title: str
    scene: Scene               # everything but the swept parameters
    axes: list                 # [(name, values ndarray), ...] (1 or 2)
    run: dict                  # mode, steady, period_tol, fallback
    paper: dict
    source: str = ""           # the TOML text
    path: str = ""

    @property
    def preset(self) -> str:
        return self.scene.preset

    @property
    def variant(self) -> str:
        return self.scene.variant

    @property
    def method(self) -> str | None:
        return self.scene.integrator.method

    @property
    def params(self) -> dict:
        """The scene's overrides of its preset (fixed for every point)."""
        return dict(self.scene.params)

    @property
    def axis_names(self):
        return [a for a, _ in self.axes]

    def base_params(self) -> Params:
        return self.scene.parameters()

    def points(self):
        """List of (index, {axis: value}) in a fixed order (first axis fastest)."""
        names = self.axis_names
        grids = [v for _, v in self.axes]
        out = []
        for k, combo in enumerate(itertools.product(*reversed(grids))):
            out.append((k, dict(zip(names, (float(c) for c in reversed(combo))))))
        return out

    def task(self, index, values) -> dict:
        """The worker's input for one point (plain data: picklable, small): the scene as a
        dict and the point's full parameter set."""
        p = self.base_params().as_dict()
        p.update(values)
        task = {"index": index, "values": dict(values), "params": p,
                "scene": self.scene.to_dict(), "run": dict(self.run)}
        task["settings"] = settings_hash(task)
        return task

    def digest(self) -> str:
        return hashlib.sha256(self.source.encode()).hexdigest()


def settings_hash(task) -> str:
    """16 hex digits of the SHA-256 of everything that decides a point's row: its full
    parameter set, the scene (variant, start, integrator, duration...), the [run] settings and
    the model's input hash (`pdw.INPUT_HASH`). A resumed sweep recomputes every row whose hash
    differs."""
    key = {"params": task["params"], "scene": task["scene"], "run": task["run"],
           "model": _layout.INPUT_HASH}
    text = json.dumps(key, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def check_name(name, where="study"):
    """A study name must be a plain file name (no folder, no "..", no absolute path):
    `pdw.core.paths.file_stem`."""
    return paths.file_stem(name, where)


def _typecheck(where, key, value, typ):
    types = typ if isinstance(typ, tuple) else (typ,)
    ok = isinstance(value, types) and not (isinstance(value, bool) and bool not in types)
    if not ok:
        names = "/".join(t.__name__ for t in types)
        raise InvalidInputError("%s: key %r must be of type %s, got %r" % (where, key, names, value))


def _moved(where, key):
    raise InvalidInputError("%s: key %r is now %r: a study's walker, start, integrator and "
                            "duration are its [scene] table, a pdw.Scene (docs/studies.md)"
                            % (where, key, MOVED[key]))


def study_scene(table: dict | None = None) -> Scene:
    """The scene of a study: `SCENE_DEFAULTS` updated by the study's ``[scene]`` table (a
    `pdw.Scene` in TOML form; a table given there updates that table of the defaults)."""
    base = Scene.from_dict({k: dict(v) if isinstance(v, dict) else v
                            for k, v in SCENE_DEFAULTS.items()})
    return base.replace(**(table or {}))


def parse_study(text, name="study", path="") -> Study:
    """Parse and validate a study from TOML text. Errors name the offending key."""
    where = path or name
    try:
        data = _toml.loads(text)
    except _toml.TOMLDecodeError as e:
        raise InvalidInputError("%s: not valid TOML: %s" % (where, e)) from None
    except RecursionError:
        raise InvalidInputError("%s: TOML nested too deeply" % where) from None
    for k, v in data.items():
        if k in MOVED:
            _moved(where, k)
        if k not in STUDY_KEYS:
            raise InvalidInputError("%s: unknown key %r; allowed: %s"
                                    % (where, k, ", ".join(STUDY_KEYS)))
        _typecheck(where, k, v, STUDY_KEYS[k])
    try:
        scene = study_scene(data.get("scene"))
    except InvalidInputError as e:
        raise InvalidInputError("%s: [scene]: %s" % (where, e)) from None
    fields = set(_layout.PARAMS)
    params = scene.params
    axes_in = data.get("axes", [])
    if not 1 <= len(axes_in) <= 2:
        raise InvalidInputError("%s: need one or two [[axes]], got %d" % (where, len(axes_in)))
    axes: list[tuple[str, np.ndarray]] = []
    for i, ax in enumerate(axes_in):
        w = "%s [[axes]] #%d" % (where, i + 1)
        if not isinstance(ax, dict):
            raise InvalidInputError("%s: must be a table" % w)
        for k, v in ax.items():
            if k not in AXIS_KEYS:
                raise InvalidInputError("%s: unknown key %r; allowed: %s"
                                        % (w, k, ", ".join(AXIS_KEYS)))
            _typecheck(w, k, v, AXIS_KEYS[k])
        an = ax.get("name")
        if an not in fields:
            raise InvalidInputError("%s: name must be a Params field (%s), got %r"
                                    % (w, ", ".join(_layout.PARAMS), an))
        if an in params or an in [a for a, _ in axes]:
            raise InvalidInputError("%s: %r is swept and also fixed (or swept twice)" % (w, an))
        if "values" in ax:
            if any(k in ax for k in ("start", "stop", "num", "log")):
                raise InvalidInputError("%s: give either values or start/stop/num" % w)
            vals = ax["values"]
            if not vals or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                   for v in vals):
                raise InvalidInputError("%s: values must be a non-empty list of numbers" % w)
            vals = np.array(vals, dtype=float)
        else:
            missing = [k for k in ("start", "stop", "num") if k not in ax]
            if missing:
                raise InvalidInputError("%s: missing %s (or give values)" % (w, ", ".join(missing)))
            checks.count(w + ": num", ax["num"], lo=1, hi=MAX_POINTS)
            checks.number(w + ": start", ax["start"])
            checks.number(w + ": stop", ax["stop"])
            if ax.get("log", False):
                if ax["start"] <= 0 or ax["stop"] <= 0:
                    raise InvalidInputError("%s: a log axis needs start, stop > 0" % w)
                vals = np.geomspace(ax["start"], ax["stop"], ax["num"])
            else:
                vals = np.linspace(ax["start"], ax["stop"], ax["num"])
        axes.append((an, vals))
    run = dict(RUN_DEFAULTS)
    for k, v in data.get("run", {}).items():
        if "run." + k in MOVED:
            _moved(where + " [run]", "run." + k)
        if k not in RUN_KEYS:
            raise InvalidInputError("%s [run]: unknown key %r; allowed: %s"
                                    % (where, k, ", ".join(RUN_KEYS)))
        _typecheck(where + " [run]", k, v, RUN_KEYS[k])
        run[k] = v
    if run["mode"] not in ("simulate", "newton"):
        raise InvalidInputError("%s [run]: mode must be 'simulate' or 'newton', got %r"
                                % (where, run["mode"]))
    checks.count(where + " [run] steady", run["steady"], lo=1, hi=10 ** 6)
    checks.positive(where + " [run] period_tol", run["period_tol"])
    n_points = int(np.prod([float(len(v)) for _, v in axes]))
    if n_points > MAX_POINTS:
        raise InvalidInputError("%s: %d points; at most %d" % (where, n_points, MAX_POINTS))
    check_name(data.get("name", name), where)
    study = Study(name=data.get("name", name), title=data.get("title", data.get("name", name)),
                  scene=scene, axes=axes, run=run, paper=dict(data.get("paper", {})),
                  source=text, path=str(path))
    try:                                   # every point's parameters must be valid
        base = study.base_params()
        for _, values in study.points():
            base.replace(**values)
    except ValueError as e:
        raise InvalidInputError("%s: %s" % (where, e)) from None
    return study


def load_study(path) -> Study:
    """Read and validate a study file (TOML)."""
    path = pathlib.Path(path)
    try:
        text = path.read_text()
    except OSError as e:
        raise InvalidInputError("cannot read study file %s: %s" % (path, e)) from None
    return parse_study(text, name=path.stem, path=str(path))
