"""``pdw robustness SPEC.toml`` (or ``--example NAME``): one robustness measure at one
parameter set or along one axis (`pdw.studies.robustness_spec`, docs/robustness.md).

Writes ``<out>/<name>.csv`` (one row per axis value), ``<out>/<name>.json`` (provenance: the
spec and its sha256, code version, input hash, git revision, Python, NumPy, platform, load,
wall and CPU time) and ``<out>/<name>.png``. The spec is validated whole before anything runs
(an error names the key; exit status 2). A first_passage spec keeps its finished walkers in
``<out>/<name>.walkers<i>.csv``: run again after a kill, it resumes (``--fresh``: start over).
"""
from __future__ import annotations

import csv
import json
import math
import os
import pathlib

from .. import examples
from ..core.errors import PdwError
from ..studies.robustness_spec import load_spec, run_spec
from . import deps


def add_cli(subparsers):
    """Register ``pdw robustness`` on an argparse subparsers object."""
    s = subparsers.add_parser("robustness", help="a robustness measure (max_step, "
                                                 "gait_sensitivity, first_passage, markov_chain) "
                                                 "from a TOML spec: CSV + JSON provenance + figure")
    s.add_argument("spec", nargs="?", help="the spec file (TOML; see docs/robustness.md)")
    s.add_argument("--example", help="run an example spec shipped with pdw "
                                     "(pdw/examples/robustness/)")
    s.add_argument("--out", help="output folder (default out/robustness/<name>)")
    s.add_argument("--fresh", action="store_true",
                   help="first_passage: ignore the files of finished walkers (start afresh)")
    s.add_argument("--no-figures", action="store_true", help="skip the figure")
    s.set_defaults(func=cli_main)
    return s


def cli_main(args):
    if (args.spec is None) == (args.example is None):
        raise PdwError("give a spec file or --example NAME (one of them)")
    path = examples.robustness_path(args.example) if args.example else args.spec
    spec = load_spec(path)
    if not args.no_figures:                 # checked before the work (pdw.present.deps)
        deps.require("matplotlib", purpose="the figure")
    out = pathlib.Path(args.out or os.path.join("out", "robustness", spec.name))
    out.mkdir(parents=True, exist_ok=True)

    def path_for(i):
        p = out / ("%s.walkers%d.csv" % (spec.name, i))
        if args.fresh and p.exists():
            p.unlink()
        return p

    def show(row):
        print("  " + ", ".join("%s=%s" % (k, _fmt(v)) for k, v in row.items()), flush=True)

    print("%s: %s (%s model), %d point(s)" % (spec.name, spec.measure, spec.model,
                                               len(spec.values)))
    rows, results, prov = run_spec(spec, path_for=path_for, on_row=show)
    paths = {"csv": out / (spec.name + ".csv"), "json": out / (spec.name + ".json")}
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(paths["csv"], "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in keys})
    paths["json"].write_text(json.dumps({**prov, "rows": rows}, indent=1, default=_jsonable))
    if not args.no_figures:
        from .robustness_plots import plot_spec
        paths["png"] = plot_spec(spec, rows, results, out / (spec.name + ".png"))
    for p in paths.values():
        print("wrote %s" % p)
    return 0


def _fmt(v):
    return "%.6g" % v if isinstance(v, float) and math.isfinite(v) else str(v)


def _jsonable(v):
    if hasattr(v, "tolist"):
        return v.tolist()
    if isinstance(v, (pathlib.Path,)):
        return str(v)
    return repr(v)
