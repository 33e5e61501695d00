"""The continuation spec of ``pdw continue`` (docs/continuation.md), checked whole before the
first point: every table (top level, ``[params]``, ``[couple]``, ``[continuation]`` with its
``options``, ``[contact]``, ``[plot]``), every key's type and range, and the keys that depend on
each other (``start`` and ``stop`` valid values of the parameter and different; ``log`` with
positive values; ``[couple]`` with a start and stop of one sign). A bad value is a
`pdw.InvalidInputError` naming the file, the table and the key, and the allowed range; nothing
is computed or written before the spec passes.

`check_spec` returns the spec with its values in their canonical types (``max_points = 3.0``
becomes 3, ``detect`` a tuple); `pdw.present.cli_continue.load_spec` reads a file and calls it.
"""
from __future__ import annotations

import math

from ..core import _layout, checks, paths
from ..core.contact import AXIS_PREFIX, Contact
from ..core.errors import InvalidInputError
from ..core.params import Params

#: Keys of the top level (tables: params, couple, continuation, contact, plot).
KEYS = {"name", "title", "model", "preset", "variant", "parameter", "stop", "start", "params",
        "couple", "continuation", "contact", "plot"}
MODELS = ("continuous", "hybrid")
PRESETS = ("compass", "simplest", "paper", "paper_steady")
#: The keys of ``[continuation]``: `pdw.continue_gait`'s keyword arguments, plus ``cascade``.
CONTINUATION_KEYS = {"step", "method", "max_points", "step_min", "step_max", "tol",
                     "locate_tol", "log", "detect", "max_newton", "fd_step", "options",
                     "cascade", "period", "workers"}
#: Integer keys of ``[continuation]`` and their ranges.
COUNTS = {"max_points": (2, 10 ** 6), "max_newton": (1, 1000), "cascade": (0, 16),
          "period": (1, 64), "workers": (1, 4096)}
#: Positive real keys of ``[continuation]`` (and their upper bounds, None: none).
POSITIVE = {"step": None, "step_min": 1.0, "step_max": 1.0, "tol": None, "locate_tol": None,
            "fd_step": 1.0}
KINDS = ("fold", "period_doubling", "neimark_sacker", "end")
#: The continuous model's step-map options (`pdw.analysis.stepmap.poincare.step`) and their ranges
#: (lo, hi, open at lo); the hybrid model's are `pdw.hybrid.DEFAULT_OPTIONS`.
CONTINUOUS_OPTIONS = {"rtol": (0.0, 1.0), "atol": (0.0, None), "event_tol": (0.0, None),
                      "t_max": (0.0, None), "dt": (0.0, 1.0)}
PLOT_KEYS = {"y", "x_scale", "x_label"}


def _table(where, spec, key):
    v = spec.get(key, {})
    if not isinstance(v, dict):
        raise InvalidInputError("%s: [%s] must be a table (key = value lines), got %r"
                                % (where, key, v))
    return dict(v)


def _unknown(where, table, keys, label):
    bad = set(table) - set(keys)
    if bad:
        raise InvalidInputError("%s: %sunknown key(s) %s; allowed: %s"
                                % (where, label, sorted(bad), ", ".join(sorted(keys))))


def _text(where, key, v):
    if not isinstance(v, str):
        raise InvalidInputError("%s: %s must be a string, got %r" % (where, key, v))
    return v


def preset(name, **overrides) -> Params:
    """The walker of a spec's ``preset``."""
    from ..analysis.rigid import hybrid as H
    if name == "compass":
        return H.compass_gait_params(**overrides)
    if name == "simplest":
        base = dict(l=1.0, c=1.0, w=0.0, r=0.0, J_l=0.0, m_h=1.0, m_l=1e-4, k_hip=0.0,
                    d_hip=0.0, gamma=0.009, g=1.0)
        return Params(**{**base, **overrides})
    if name in ("paper", "paper_steady"):
        return getattr(Params, name)(**overrides)
    raise InvalidInputError("preset must be compass, simplest, paper or paper_steady, got %r"
                            % (name,))


def check_spec(spec: dict, where: str = "spec") -> dict:
    """The spec with every value checked and in its canonical type (module docstring).

    Parameters
    ----------
    spec : dict
        The parsed TOML file.
    where : str
        The file's name, for the messages.
    """
    if not isinstance(spec, dict):
        raise InvalidInputError("%s: a continuation spec is a table, got %r" % (where, spec))
    spec = dict(spec)
    if "ground" in spec:
        raise InvalidInputError(
            "%s: [ground]: a continuation follows a gait, a fixed point of the step map, which "
            "needs the same ground under every step (the uniform slope of the model); a tilted "
            "plane Ground.plane(slope=d) is the walker on slope gamma + d (docs/terrain.md, "
            "exactness checks): continue in gamma instead; shaped ground and patches are for a "
            "scene, a study or `pdw robustness`" % where)
    _unknown(where, {k: v for k, v in spec.items() if not k.startswith("_")}, KEYS, "")
    for k in ("name", "parameter", "stop"):
        if k not in spec:
            raise InvalidInputError("%s: missing %r" % (where, k))
    paths.file_stem(spec["name"], "%s: name" % where)
    if "title" in spec:
        _text(where, "title", spec["title"])
    model = checks.choice("%s: model" % where, spec.setdefault("model", "continuous"), MODELS)
    name = checks.choice("%s: preset" % where, spec.setdefault("preset", "paper_steady"), PRESETS)
    checks.choice("%s: variant" % where, spec.setdefault("variant", "paper"), _layout.VARIANTS)
    # [contact]: the continuous model's contact laws (before the parameter: it may be one of
    # the contact's, "contact.<name>")
    law = Contact()
    if "contact" in spec:
        if model != "continuous":
            raise InvalidInputError("%s: [contact] is a section of the continuous model's specs; "
                                    "model = %r has rigid ground" % (where, model))
        try:
            law = Contact.coerce(_table(where, spec, "contact"))
        except InvalidInputError as e:
            raise InvalidInputError("%s: [contact] %s" % (where, e)) from None
        spec["contact"] = law.as_dict()
    par = spec["parameter"]
    axis = isinstance(par, str) and par.startswith(AXIS_PREFIX)
    if axis and model != "continuous":
        raise InvalidInputError("%s: parameter %r: model = %r has rigid ground, no contact "
                                "law; allowed: a Params field (%s)"
                                % (where, par, model, ", ".join(Params.__dataclass_fields__)))
    if axis and par not in law.axes():
        raise InvalidInputError("%s: parameter %r is not a parameter of the [contact] laws "
                                "(%s normal, %s friction); allowed: %s, or a Params field"
                                % (where, par, law.normal, law.friction, ", ".join(law.axes())))
    if not axis and (not isinstance(par, str) or par not in Params.__dataclass_fields__):
        raise InvalidInputError("%s: parameter must be a Params field (%s)%s, got %r"
                                % (where, ", ".join(Params.__dataclass_fields__),
                                   " or a parameter of the [contact] laws (%s)"
                                   % ", ".join(law.axes()) if model == "continuous" else "",
                                   par))
    # the walker: the preset with [params]
    spec["params"] = overrides = _table(where, spec, "params")
    _unknown(where, overrides, Params.__dataclass_fields__, "[params] ")
    for k, v in overrides.items():
        checks.number("%s: [params] %s" % (where, k), v)
    try:
        params = preset(name, **overrides)
    except ValueError as e:
        raise InvalidInputError("%s: [params] %s" % (where, e)) from None
    # start and stop: values of the parameter
    start = spec.get("start")
    if start is None:
        start = law.axis_value(par, params) if axis else getattr(params, par)
    else:
        start = spec["start"] = checks.number("%s: start" % where, start)
    stop = spec["stop"] = checks.number("%s: stop" % where, spec["stop"])
    for key, v in (("start", start), ("stop", stop)):
        try:
            law.with_axis(par, v) if axis else params.replace(**{par: v})
        except (ValueError, InvalidInputError) as e:
            raise InvalidInputError("%s: %s = %r is not a valid %s: %s"
                                    % (where, key, v, par, e)) from None
    if stop == start:
        raise InvalidInputError("%s: stop must differ from the start value %r of %s, got %r"
                                % (where, start, par, stop))
    # [couple]: other fields as powers of the parameter
    spec["couple"] = couple = _table(where, spec, "couple")
    if couple and axis:
        raise InvalidInputError("%s: [couple] scales Params fields with a Params parameter; "
                                "the parameter %r is the contact's" % (where, par))
    _unknown(where, couple, set(Params.__dataclass_fields__) - {par},
             "[couple] (fields other than the parameter %r) " % par)
    for k, expo in couple.items():
        couple[k] = checks.number("%s: [couple] %s" % (where, k), expo, lo=-100.0, hi=100.0)
    if couple:
        if not (start != 0 and stop / start > 0):
            raise InvalidInputError("%s: [couple] scales fields by (value / start)^exponent: "
                                    "start (%r) and stop (%r) must be nonzero and of one sign"
                                    % (where, start, stop))
        for v in (start, stop):
            try:
                params.replace(**{par: v}, **{f: getattr(params.replace(**{par: start}), f)
                                              * (v / start) ** e for f, e in couple.items()})
            except (ValueError, OverflowError) as err:
                raise InvalidInputError("%s: [couple] at %s = %r: %s" % (where, par, v, err)) \
                    from None
    # [continuation]
    spec["continuation"] = cont = _table(where, spec, "continuation")
    _unknown(where, cont, CONTINUATION_KEYS, "[continuation] ")
    w = "%s: [continuation] " % where
    for k, (lo, hi) in COUNTS.items():
        if k in cont:
            cont[k] = checks.count(w + k, cont[k], lo=lo, hi=hi)
    for k, top in POSITIVE.items():
        if k in cont:
            cont[k] = checks.number(w + k, cont[k], lo=0.0, lo_open=True, hi=top)
    if cont.get("step_min", 0.0) > cont.get("step_max", math.inf):
        raise InvalidInputError("%sstep_min (%r) must be <= step_max (%r)"
                                % (w, cont["step_min"], cont["step_max"]))
    if "method" in cont:
        checks.choice(w + "method", cont["method"], ("pseudo_arclength", "natural"))
    if "log" in cont:
        if not isinstance(cont["log"], bool):
            raise InvalidInputError("%slog must be true or false, got %r" % (w, cont["log"]))
        if cont["log"] and not (start > 0 and stop > 0):
            raise InvalidInputError("%slog = true needs start and stop > 0, got %r and %r"
                                    % (w, start, stop))
    if "detect" in cont:
        d = cont["detect"]
        if not isinstance(d, (list, tuple)) or any(not isinstance(x, str) or x not in KINDS
                                                     for x in d):
            raise InvalidInputError("%sdetect must be a list of %s, got %r"
                                    % (w, ", ".join(map(repr, KINDS)), d))
        cont["detect"] = tuple(d)
    if "options" in cont:
        cont["options"] = _options(w + "options", cont["options"], model)
    if cont.get("period", 1) > 1 and model == "hybrid":
        raise InvalidInputError("%speriod = %d: a hybrid period-n start needs a switched "
                                "branch; use cascade = N" % (w, cont["period"]))
    # [plot]
    spec["plot"] = plot = _table(where, spec, "plot")
    _unknown(where, plot, PLOT_KEYS, "[plot] ")
    from .plots_continuation import QUANTITIES
    checks.choice("%s: [plot] y" % where, plot.setdefault("y", "step_length"), QUANTITIES)
    x_scale = checks.number("%s: [plot] x_scale" % where, plot.setdefault("x_scale", 1.0))
    if x_scale == 0:
        raise InvalidInputError("%s: [plot] x_scale must be a nonzero number, got 0" % where)
    plot["x_scale"] = x_scale
    if "x_label" in plot:
        _text(where, "[plot] x_label", plot["x_label"])
    return spec


def _options(where, options, model) -> dict:
    if not isinstance(options, dict):
        raise InvalidInputError("%s must be a table, got %r" % (where, options))
    if model == "hybrid":
        from ..analysis.rigid import hybrid as H
        try:
            return H._options(options)
        except InvalidInputError as e:
            raise InvalidInputError("%s: %s" % (where, e)) from None
    _unknown(where, options, CONTINUOUS_OPTIONS, "")
    out = {}
    for k, v in options.items():
        lo, hi = CONTINUOUS_OPTIONS[k]
        out[k] = checks.number("%s %s" % (where, k), v, lo=lo, lo_open=True, hi=hi)
    return out
