"""The robustness spec (``pdw robustness SPEC.toml``, docs/robustness.md): one measure of
`pdw.analysis.robust.robustness` (max_step, gait_sensitivity, first_passage, markov_chain), at one
parameter set or along one parameter axis, validated whole before anything runs::

    name = "max_step_k_hip"          # output names
    title = "..."                    # figure title (optional)
    measure = "max_step"             # max_step | gait_sensitivity | first_passage | markov_chain
    model = "hybrid"                 # or "continuous"
    preset = "paper_steady"          # paper | paper_steady

    [params]                         # optional overrides of the preset (pdw.Params fields)
    d_hip = 0.010

    [options]                        # keyword arguments of the measure (pdw.max_step(...))
    direction = "down"

    [sweep]                          # optional: one axis (a study mode)
    parameter = "k_hip"              # a pdw.Params field
    values = [0.5, 0.75, 1.0]        # or start, stop, num (evenly spaced)

    [ground]                         # optional: a pdw.Ground table (docs/terrain.md)

Every error names the key (``options.direction``, ``sweep.values[2]``, ``ground.sigma``).
`run_spec` runs it: rows (one per axis value) of the measure's numbers, with the provenance.
"""
from __future__ import annotations

import dataclasses
import hashlib
import inspect
import math
import os
import platform
import sys
import time
from typing import Any, Callable

import numpy as np

from ..analysis.robust import first_passage as _fp
from ..analysis.robust import markov as _mk
from ..analysis.robust import robustness as _rb
from ..core import _toml, paths
from ..core.errors import InvalidInputError, PdwError
from ..core.params import Params
from ..core.provenance import source_revision

MEASURES: dict[str, Callable[..., Any]] = {"max_step": _rb.max_step, "gait_sensitivity": _rb.gait_sensitivity,
            "first_passage": _fp.first_passage, "markov_chain": _mk.markov_chain}
PRESETS = ("paper", "paper_steady")
_TOP = ("name", "title", "measure", "model", "preset", "params", "options", "sweep", "ground")
#: options that the spec sets itself, never from [options]
_RESERVED = ("params", "gait", "executor", "progress", "model", "ground", "path")
#: the hybrid step map's options, accepted in [options] by every measure
_STEP_OPTIONS = ("rtol", "atol", "h0", "h_max", "t_max", "event_tol", "min_step_angle",
                 "fall_angle", "max_steps")


@dataclasses.dataclass
class RobustnessSpec:
    """A validated spec (`parse_spec`)."""

    name: str
    title: str
    measure: str
    model: str
    preset: str
    params: dict
    options: dict
    parameter: str | None
    values: list
    ground: object
    source: str
    path: str | None

    def digest(self) -> str:
        return hashlib.sha256(self.source.encode()).hexdigest()

    def params_at(self, value=None) -> Params:
        base = Params.paper() if self.preset == "paper" else Params.paper_steady()
        kw = {**base.as_dict(), **self.params}
        if self.parameter is not None:
            kw[self.parameter] = value
        return Params(**kw)


def _num(key, v):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise InvalidInputError("%s must be a finite number, got %r" % (key, v))
    return float(v)


def load_spec(path) -> RobustnessSpec:
    """Read and validate a spec file."""
    with open(os.fspath(path), "rb") as f:
        raw = f.read()
    return parse_spec(raw.decode(), path=os.fspath(path))


def parse_spec(text, path=None) -> RobustnessSpec:
    """Validate a spec's TOML text whole; raises `InvalidInputError` naming the key."""
    try:
        d = _toml.loads(text)
    except _toml.TOMLDecodeError as e:
        raise InvalidInputError("%s: not valid TOML: %s" % (path or "spec", e)) from None
    unknown = sorted(set(d) - set(_TOP))
    if unknown:
        raise InvalidInputError("unknown key(s) %s; allowed: %s" % (", ".join(unknown),
                                                                    ", ".join(_TOP)))
    name = paths.file_stem(d.get("name"), "%s: name" % (path or "spec"))   # names the files
    title = d.get("title", name)
    if not isinstance(title, str):
        raise InvalidInputError("title must be a string, got %r" % (title,))
    measure = d.get("measure")
    if measure not in MEASURES:
        raise InvalidInputError("measure must be one of %s, got %r" % (", ".join(MEASURES),
                                                                       measure))
    model = d.get("model", "hybrid")
    if model not in _rb.MODELS:
        raise InvalidInputError("model must be one of %s, got %r" % (", ".join(_rb.MODELS), model))
    if measure == "markov_chain" and model != "hybrid":
        raise InvalidInputError("model = %r: measure markov_chain is for the hybrid model only"
                                % model)
    preset = d.get("preset", "paper_steady")
    if preset not in PRESETS:
        raise InvalidInputError("preset must be one of %s, got %r" % (", ".join(PRESETS), preset))
    fields = set(Params().as_dict())
    params = d.get("params", {})
    if not isinstance(params, dict):
        raise InvalidInputError("params must be a table, got %r" % (params,))
    for k, v in params.items():
        if k not in fields:
            raise InvalidInputError("params.%s is not a pdw.Params field; allowed: %s"
                                    % (k, ", ".join(sorted(fields))))
        params[k] = _num("params." + k, v)
    options = d.get("options", {})
    if not isinstance(options, dict):
        raise InvalidInputError("options must be a table, got %r" % (options,))
    fn = MEASURES[measure]
    sig = inspect.signature(fn)
    allowed = [n for n, p in sig.parameters.items()
               if p.kind == p.KEYWORD_ONLY and n not in _RESERVED] + list(_STEP_OPTIONS)
    for k in options:
        if k not in allowed:
            raise InvalidInputError("options.%s is not an option of pdw.%s; allowed: %s"
                                    % (k, measure, ", ".join(allowed)))
    parameter, values = None, [None]
    sweep = d.get("sweep")
    if sweep is not None:
        if not isinstance(sweep, dict):
            raise InvalidInputError("sweep must be a table, got %r" % (sweep,))
        extra = sorted(set(sweep) - {"parameter", "values", "start", "stop", "num"})
        if extra:
            raise InvalidInputError("sweep.%s is not a key of [sweep]; allowed: parameter, "
                                    "values, start, stop, num" % extra[0])
        parameter = sweep.get("parameter")
        if not isinstance(parameter, str) or parameter not in fields:
            raise InvalidInputError("sweep.parameter must be a pdw.Params field, got %r"
                                    % (parameter,))
        if "values" in sweep:
            if any(k in sweep for k in ("start", "stop", "num")):
                raise InvalidInputError("sweep: give values or start/stop/num, not both")
            vals = sweep["values"]
            if not isinstance(vals, list) or not vals:
                raise InvalidInputError("sweep.values must be a non-empty list, got %r" % (vals,))
            values = [_num("sweep.values[%d]" % i, v) for i, v in enumerate(vals)]
        else:
            for k in ("start", "stop", "num"):
                if k not in sweep:
                    raise InvalidInputError("sweep.%s is missing (or give sweep.values)" % k)
            num = sweep["num"]
            if isinstance(num, bool) or not isinstance(num, int) or not 1 <= num <= 10 ** 5:
                raise InvalidInputError("sweep.num must be an integer in [1, 100000], got %r"
                                        % (num,))
            values = list(np.linspace(_num("sweep.start", sweep["start"]),
                                      _num("sweep.stop", sweep["stop"]), num))
    ground = None
    wants_ground = measure == "first_passage" and model == "continuous"
    if "ground" in d:
        if not wants_ground:
            raise InvalidInputError("ground: only measure = 'first_passage' with model = "
                                    "'continuous' takes a [ground] table (max_step and "
                                    "gait_sensitivity build their own step; the hybrid model's "
                                    "first_passage and markov_chain take options.sigma)")
        from ..core.ground import Ground

        ground = Ground.from_dict(d["ground"])
        if ground.kind != "random":
            raise InvalidInputError("ground.kind must be 'random' for first_passage, got %r"
                                    % ground.kind)
    elif wants_ground:
        raise InvalidInputError("ground: first_passage with model = 'continuous' needs a "
                                "[ground] table of kind = 'random' (sigma, correlation)")
    if measure in ("first_passage", "markov_chain") and model == "hybrid" \
            and "sigma" not in options:
        raise InvalidInputError("options.sigma [m] is missing: the hybrid model's %s needs "
                                "the step heights' standard deviation" % measure)
    spec = RobustnessSpec(name=name, title=title, measure=measure, model=model, preset=preset,
                          params=params, options=options, parameter=parameter, values=values,
                          ground=ground, source=text, path=path)
    for v in values:                 # every parameter set is valid before anything runs
        try:
            spec.params_at(v)
        except InvalidInputError as e:
            where = "sweep.values" if v is not None else "params"
            raise InvalidInputError("%s: %s" % (where, e)) from None
    return spec


# --- running -----------------------------------------------------------------------------------

def _row(measure, value, out, gait=None) -> dict:
    """The numbers of one measure's result, as one CSV row (with the gait's period [s] and
    largest Floquet multiplier modulus: a walk from an unstable gait says so)."""
    row = _row_of(measure, value, out)
    if gait is not None:
        row.update(gait_period=gait.period, gait_mu_max=float(np.max(np.abs(gait.multipliers))))
    return row


def _row_of(measure, value, out) -> dict:
    if measure == "max_step":
        return dict(value=value, height=out.height, bracket_lo=out.bracket[0],
                    bracket_hi=out.bracket[1], steps_to_return=out.steps_to_return,
                    trials=len(out.trials), monotone=out.monotone, stable=out.stable,
                    period=out.gait.period if out.gait is not None else math.nan)
    if measure == "gait_sensitivity":
        return dict(value=value, norm=out.norm,
                    **{"norm_" + k: v for k, v in out.per_indicator.items()},
                    fd_rel_diff=out.check.get("rel_diff", math.nan))
    if measure == "first_passage":
        return dict(value=value, mfpt=out.mfpt, ci_lo=out.ci[0], ci_hi=out.ci[1],
                    walkers=out.walkers, failures=out.failures, censored=out.censored,
                    exposure=out.exposure, km_mean=out.km_mean)
    return dict(value=value, mfpt=out.mfpt, mfpt_eig=out.mfpt_eig, lambda2=out.lambda2,
                n_cells=out.n_cells, complete=out.complete)


def run_spec(spec: RobustnessSpec, *, executor=None, path_for=None, on_row=None):
    """Run a spec: (rows, results, provenance). ``path_for(i)``: the file of finished walkers
    of axis point i (first_passage's resumable file), or None. ``on_row(row)`` after each."""
    fn = MEASURES[spec.measure]
    rows, results = [], []
    t0, c0 = time.time(), time.process_time()
    prev = None
    for i, v in enumerate(spec.values):
        kw = dict(spec.options)
        prev = kw["gait"] = _gait_along(spec, spec.params_at(v), prev)
        if spec.model != "hybrid" or spec.measure != "markov_chain":
            kw["model"] = spec.model
        if spec.ground is not None:
            kw["ground"] = spec.ground
        if spec.measure == "first_passage":
            kw["executor"] = executor
            if path_for is not None:
                kw["path"] = path_for(i)
        try:
            out = fn(spec.params_at(v), **kw)
        except PdwError as e:
            raise type(e)("%s at %s = %r: %s" % (spec.measure, spec.parameter or "params", v,
                                                 e)) from None
        row = _row(spec.measure, v, out, kw["gait"])
        rows.append(row)
        results.append(out)
        if on_row is not None:
            on_row(row)
    prov = provenance(spec, wall_s=time.time() - t0, cpu_s=time.process_time() - c0)
    return rows, results, prov


def _gait_along(spec, params, prev):
    """The gait at this axis point, followed from the previous point's (one branch of gaits
    along the axis, as the studies do); the default guesses when that fails or at the first,
    and when the followed gait is unstable (|multiplier| >= 1) while the default guesses find a
    stable one: a long step along the axis can land on another, unstable branch (the hybrid
    walker from k_hip 0.95 to 0.5 in one step: period 0.567 s, |mu| 2.30, where the stable
    gait has 0.668 s, 0.388), and walks from it measure that branch, not the walker."""
    from ..analysis.gait_types import GaitNotFoundError
    from ..analysis.rigid import hybrid as _hy
    from ..analysis.stepmap import limit_cycle as _lc

    find = _hy.find_gait if spec.model == "hybrid" else _lc.find_gait
    step = {k: v for k, v in spec.options.items() if k in _STEP_OPTIONS} \
        if spec.model == "hybrid" else {}
    if prev is not None:
        try:
            if spec.model == "hybrid":
                g = find(params, guess=prev.state, settle_steps=0, **step)
            else:
                g = find(params, guess=prev)
        except (GaitNotFoundError, PdwError):
            return find(params, **step)
        if np.max(np.abs(g.multipliers)) < 1.0:
            return g
        try:
            d = find(params, **step)
        except (GaitNotFoundError, PdwError):
            return g
        return d if np.max(np.abs(d.multipliers)) < 1.0 else g
    return find(params, **step)


def provenance(spec, **extra) -> dict:
    from ..core import __version__
    from ..core._layout import INPUT_HASH

    return {
        "spec": {"name": spec.name, "path": spec.path, "sha256": spec.digest(),
                 "toml": spec.source},
        "measure": spec.measure, "model": spec.model, "preset": spec.preset,
        "base_params": spec.params_at(spec.values[0]).as_dict(),
        "sweep": {"parameter": spec.parameter, "values": [v for v in spec.values]},
        "code": {"pdw_version": __version__, "input_hash": INPUT_HASH,
                 "git_describe": source_revision(None)},
        "python": sys.version.split()[0], "numpy": np.__version__,
        "platform": platform.platform(), "cpu_count": os.cpu_count(),
        "load_avg": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
        **extra,
    }
