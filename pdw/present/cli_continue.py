"""``pdw continue SPEC.toml``: a continuation from a TOML file -> CSV, JSON provenance, diagram.

The spec (docs/continuation.md; examples in pdw/examples/continuations/, run by
``pdw continue --example NAME``)::

    name = "compass_cascade"          # output names
    title = "..."                     # figure title (optional)
    model = "hybrid"                  # or "continuous"
    preset = "compass"                # compass | simplest | paper | paper_steady
    variant = "paper"                 # continuous model's contact variant
    parameter = "gamma"               # a Params field, or (continuous) a parameter of the
                                      # [contact] laws, e.g. "contact.d" (pdw.Contact.axes)
    stop = 0.0925                     # continue until here
    start = 0.0524                    # optional: the parameter's value at the start

    [params]                          # optional overrides of the preset
    d_hip = 0.010

    [couple]                          # optional: other fields as powers of the parameter,
    d_n = 1.3333333333                # d_n = d_n0 (value / value0)^(4/3)  (params_of)

    [continuation]                    # keyword arguments of pdw.continue_gait, plus
    step = 0.001                      # cascade = 2: switch at the period doublings twice
    cascade = 2

    [contact]                         # optional (continuous model): the contact laws, as a
    normal = "flores"                 # scene's [contact] / pdw.Contact (docs/contact_laws.md)
    e = 0.18

    [plot]
    y = "step_length"                 # pdw.present.plots_continuation.QUANTITIES
    x_scale = 57.29577951308232       # e.g. radians -> degrees
    x_label = "slope [deg]"

Writes ``<out>/<name>.csv`` (the points of every branch, with ``branch`` and ``period_n``
columns), ``<out>/<name>.json`` (provenance: spec, code version, settings, per-branch summary
with the bifurcations, map evaluations, wall time) and ``<out>/<name>.png`` (not with
``--no-figures``, which needs no matplotlib; without it and without matplotlib the command
stops before the work, exit code 4). The whole spec is checked first
(`pdw.present.continue_spec.check_spec`: every key's type and range, exit code 2); ``name``
must be a plain file name (`pdw.core.paths.file_stem`).
"""
from __future__ import annotations

import csv
import hashlib
import json
import os
import pathlib
import platform
import sys
import time

import numpy as np

from .. import examples
from ..analysis.bifurcation.branch import _jsonable
from ..analysis.bifurcation.continuation import continue_gait, follow_cascade
from ..core import _toml
from ..core.contact import AXIS_PREFIX, Contact
from ..core.errors import InvalidInputError
from . import continue_spec, deps

KEYS, CONTINUATION_KEYS = continue_spec.KEYS, continue_spec.CONTINUATION_KEYS
preset = continue_spec.preset


def load_spec(path) -> dict:
    """Read a continuation spec and check all of it (`pdw.present.continue_spec.check_spec`):
    a bad value anywhere is an `InvalidInputError` naming the key, before any work."""
    try:
        text = pathlib.Path(path).read_text()
    except OSError as e:
        raise InvalidInputError("cannot read continuation file %s: %s" % (path, e)) from None
    try:
        spec = _toml.loads(text)
    except _toml.TOMLDecodeError as e:
        raise InvalidInputError("%s: not valid TOML: %s" % (path, e)) from None
    spec = continue_spec.check_spec(spec, str(path))
    spec["_source"], spec["_path"] = text, str(path)
    return spec


def run_spec(spec, out=None, progress=False, *, figures=True):
    """Run a spec (checked again here: `pdw.present.continue_spec.check_spec`): (branches,
    paths written); ``progress`` (False, True or a `pdw.Progress`) as in `pdw.continue_gait`;
    ``figures=False``: no diagram (no matplotlib needed)."""
    spec = {**continue_spec.check_spec(spec, spec.get("_path", "spec")),
            **{k: v for k, v in spec.items() if k.startswith("_")}}
    params = preset(spec.get("preset", "paper_steady"), **spec.get("params", {}))
    par = spec["parameter"]
    couple = dict(spec.get("couple", {}))
    kw = dict(spec.get("continuation", {}))
    depth = int(kw.pop("cascade", 0))
    if spec.get("contact"):
        kw["options"] = {**kw.get("options", {}), "contact": Contact.coerce(spec["contact"])}
    if par.startswith(AXIS_PREFIX):          # a contact parameter: the start is the contact's
        law = Contact.coerce(spec.get("contact"))
        if spec.get("start") is not None:
            law = law.with_axis(par, spec["start"])
        kw["options"] = {**kw.get("options", {}), "contact": law}
        start = law.axis_value(par, params)
    else:
        start = spec.get("start", getattr(params, par, None))
    params_of = None
    if couple:
        p0 = params.replace(**{par: start})
        v0 = float(start)

        def params_of(v, p0=p0, v0=v0, couple=couple):
            return p0.replace(**{par: v}, **{f: getattr(p0, f) * (v / v0) ** e
                                             for f, e in couple.items()})
    if start is not None and not par.startswith(AXIS_PREFIX):
        params = params.replace(**{par: start})
    common = dict(model=spec.get("model", "continuous"), variant=spec.get("variant", "paper"),
                  params_of=params_of, value=start, progress=progress, **kw)
    t0 = time.perf_counter()
    if depth > 0:
        branches = follow_cascade(params, par, spec["stop"], depth=depth, **common)
    else:
        branches = [continue_gait(params, par, spec["stop"], **common)]
    wall = time.perf_counter() - t0
    out = pathlib.Path(out or os.path.join("out", "continuation", spec["name"]))
    out.mkdir(parents=True, exist_ok=True)
    paths = {"csv": out / ("%s.csv" % spec["name"]), "json": out / ("%s.json" % spec["name"]),
             "png": out / ("%s.png" % spec["name"])}
    if not figures:
        del paths["png"]
    _write_csv(branches, paths["csv"])
    with open(paths["json"], "w") as fh:
        json.dump(_provenance(spec, branches, wall), fh, indent=2, default=_jsonable)
    if figures:
        from .plots_continuation import plot_branches
        plot = spec["plot"]
        ax = plot_branches(branches, y=plot["y"], x_scale=plot["x_scale"],
                           x_label=plot.get("x_label"), title=spec.get("title"),
                           path=paths["png"])
        import matplotlib.pyplot as plt
        plt.close(ax.figure)
    return branches, paths


def _write_csv(branches, path):
    rows = [{"branch": k, **r} for k, b in enumerate(branches) for r in b.rows()]
    fields = []
    for r in rows:
        fields += [f for f in r if f not in fields]
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields, restval="")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("%.17g" % v if isinstance(v, float) else v) for k, v in r.items()})


def _provenance(spec, branches, wall):
    from ..core import __version__
    from ..core._layout import INPUT_HASH
    from ..studies.sweep import git_describe
    src = spec["_source"]
    return {"spec": {"path": spec["_path"], "sha256": hashlib.sha256(src.encode()).hexdigest(),
                     "toml": src},
            "code": {"pdw_version": __version__, "input_hash": INPUT_HASH,
                     "git_describe": git_describe()},
            "python": sys.version.split()[0], "numpy": np.__version__,
            "platform": platform.platform(), "cpu_count": os.cpu_count(),
            "wall_time_s": wall, "map_evaluations": sum(b.n_maps for b in branches),
            "branches": [b.summary() for b in branches]}


def add_cli(subparsers):
    """Register ``pdw continue`` on an argparse subparsers object."""
    s = subparsers.add_parser("continue", help="follow a gait through a parameter: branches, "
                                               "stability, bifurcations (CSV + JSON + diagram)")
    s.add_argument("spec", nargs="?", help="the continuation file (TOML; see docs/continuation.md)")
    s.add_argument("--example", help="run an example continuation shipped with pdw (%s)"
                                     % ", ".join(examples.continuations()))
    s.add_argument("--out", help="output folder (default out/continuation/<name>)")
    s.add_argument("--no-figures", action="store_true",
                   help="skip the diagram (no matplotlib needed)")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.set_defaults(func=cli_main)
    return s


def cli_main(args):
    if (args.spec is None) == (args.example is None):
        raise InvalidInputError("give a continuation file or --example NAME (one of them)")
    spec = load_spec(examples.continuation_path(args.example) if args.example else args.spec)
    if not args.no_figures:
        deps.require("matplotlib", purpose="the diagram")
    branches, paths = run_spec(spec, args.out, progress=not args.no_progress,
                               figures=not args.no_figures)
    for b in branches:
        print("period %d: %d points, %s in [%.8g, %.8g], %d map evaluations, %.1f s; %s"
              % (b.period_n, len(b), b.parameter, b.values.min(), b.values.max(), b.n_maps,
                 b.wall_time, b.stop_reason))
        for f in b.bifurcations:
            print("  " + f.describe())
    for p in paths.values():
        print("wrote %s" % p)
    return 0
