"""A parameter study, as data: the TOML file format of ``pdw sweep`` and its validation
(docs/studies.md).

A study sweeps one or two `Params` fields over ranges (``[[axes]]``), the others fixed (a
preset plus ``[params]`` overrides), with one contact variant and one integrator (``[run]``).
`load_study` / `parse_study` check every key and value and name the key in the error;
`Study.points` lists the parameter sets. Running a study is `pdw.studies.sweep.run_study`.
"""
from __future__ import annotations

import dataclasses
import hashlib
import itertools
import pathlib
import tomllib

import numpy as np

from ..core import _layout
from ..core.errors import InvalidInputError
from ..core.integrators import METHODS
from ..core.params import X0_PAPER, Params

STUDY_KEYS = {"name": str, "title": str, "preset": str, "variant": str, "method": str,
              "params": dict, "axes": list, "run": dict, "paper": dict, "description": str}
AXIS_KEYS = {"name": str, "values": list, "start": (int, float), "stop": (int, float),
             "num": int, "log": bool}
RUN_KEYS = {"mode": str, "t_end": (int, float), "dt": (int, float), "steady": int,
            "rtol": (int, float), "atol": (int, float), "x0": list, "flags0": list,
            "period_tol": (int, float), "fallback": bool}
RUN_DEFAULTS = {"mode": "simulate", "t_end": 16.0, "dt": 1e-4, "steady": 4, "rtol": 1e-7,
                "atol": 1e-9, "x0": list(X0_PAPER), "flags0": [0, 1], "period_tol": 1e-4,
                "fallback": True}
#: Result columns of a point (after the index and the axis values).
COLUMNS = ("status", "gait", "source", "L", "P", "v", "cycle", "double_support", "ds_fraction", "travel",
           "spread_L", "spread_cycle", "n_steps", "max_multiplier", "t_final", "wall_s", "error")


# --- the study --------------------------------------------------------------------------------

@dataclasses.dataclass
class Study:
    """A parsed study file (see the module docstring and docs/studies.md)."""

    name: str
    title: str
    preset: str
    variant: str
    method: str
    params: dict
    axes: list                 # [(name, values ndarray), ...] (1 or 2)
    run: dict
    paper: dict
    source: str = ""           # the TOML text
    path: str = ""

    @property
    def axis_names(self):
        return [a for a, _ in self.axes]

    def base_params(self) -> Params:
        return Params.preset(self.preset, **self.params)

    def points(self):
        """List of (index, {axis: value}) in a fixed order (first axis fastest)."""
        names = self.axis_names
        grids = [v for _, v in self.axes]
        out = []
        for k, combo in enumerate(itertools.product(*reversed(grids))):
            out.append((k, dict(zip(names, (float(c) for c in reversed(combo))))))
        return out

    def task(self, index, values) -> dict:
        """The worker's input for one point (plain data: picklable, small)."""
        p = self.base_params().as_dict()
        p.update(values)
        return {"index": index, "values": dict(values), "params": p, "variant": self.variant,
                "method": self.method, "run": dict(self.run)}

    def digest(self) -> str:
        return hashlib.sha256(self.source.encode()).hexdigest()


def _typecheck(where, key, value, typ):
    types = typ if isinstance(typ, tuple) else (typ,)
    ok = isinstance(value, types) and not (isinstance(value, bool) and bool not in types)
    if not ok:
        names = "/".join(t.__name__ for t in types)
        raise InvalidInputError("%s: key %r must be of type %s, got %r" % (where, key, names, value))


def parse_study(text, name="study", path="") -> Study:
    """Parse and validate a study from TOML text. Errors name the offending key."""
    where = path or name
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InvalidInputError("%s: not valid TOML: %s" % (where, e)) from None
    for k, v in data.items():
        if k not in STUDY_KEYS:
            raise InvalidInputError("%s: unknown key %r; allowed: %s"
                                    % (where, k, ", ".join(STUDY_KEYS)))
        _typecheck(where, k, v, STUDY_KEYS[k])
    preset = data.get("preset", "paper_steady")
    variant = data.get("variant", "paper")
    method = data.get("method", "rodas4")
    if variant not in _layout.VARIANTS:
        raise InvalidInputError("%s: variant must be one of %s, got %r"
                                % (where, ", ".join(_layout.VARIANTS), variant))
    if method not in METHODS:
        raise InvalidInputError("%s: method must be one of %s, got %r"
                                % (where, ", ".join(METHODS), method))
    fields = set(_layout.PARAMS)
    params = dict(data.get("params", {}))
    for k, v in params.items():
        if k not in fields:
            raise InvalidInputError("%s: [params] has unknown field %r; allowed: %s"
                                    % (where, k, ", ".join(_layout.PARAMS)))
        _typecheck(where + " [params]", k, v, (int, float))
    axes_in = data.get("axes", [])
    if not 1 <= len(axes_in) <= 2:
        raise InvalidInputError("%s: need one or two [[axes]], got %d" % (where, len(axes_in)))
    axes = []
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
            if ax["num"] < 1:
                raise InvalidInputError("%s: num must be >= 1" % w)
            if ax.get("log", False):
                if ax["start"] <= 0 or ax["stop"] <= 0:
                    raise InvalidInputError("%s: a log axis needs start, stop > 0" % w)
                vals = np.geomspace(ax["start"], ax["stop"], ax["num"])
            else:
                vals = np.linspace(ax["start"], ax["stop"], ax["num"])
        axes.append((an, vals))
    run = dict(RUN_DEFAULTS)
    for k, v in data.get("run", {}).items():
        if k not in RUN_KEYS:
            raise InvalidInputError("%s [run]: unknown key %r; allowed: %s"
                                    % (where, k, ", ".join(RUN_KEYS)))
        _typecheck(where + " [run]", k, v, RUN_KEYS[k])
        run[k] = v
    if run["mode"] not in ("simulate", "newton"):
        raise InvalidInputError("%s [run]: mode must be 'simulate' or 'newton', got %r"
                                % (where, run["mode"]))
    if len(run["x0"]) != 8 or len(run["flags0"]) != 2:
        raise InvalidInputError("%s [run]: x0 needs 8 numbers and flags0 two" % where)
    if run["steady"] < 1 or run["t_end"] <= 0 or run["dt"] <= 0:
        raise InvalidInputError("%s [run]: steady >= 1, t_end > 0, dt > 0 required" % where)
    study = Study(name=data.get("name", name), title=data.get("title", data.get("name", name)),
                  preset=preset, variant=variant, method=method, params=params, axes=axes,
                  run=run, paper=dict(data.get("paper", {})), source=text, path=str(path))
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
