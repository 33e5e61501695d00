"""``pdw sweep STUDY.toml``: the command line of `pdw.studies.sweep.run_study`."""
from __future__ import annotations

from ..core.errors import PdwError
from ..studies.study import load_study
from ..studies.sweep import run_study
from .study_plots import plot_study


def add_cli(subparsers):
    """Register ``pdw sweep`` on an argparse subparsers object."""
    s = subparsers.add_parser("sweep", help="run a parameter study described in a TOML file "
                                            "(CSV + JSON provenance + figure)")
    s.add_argument("study", help="the study file (TOML; see docs/studies.md)")
    s.add_argument("--out", help="output folder (default out/studies/<name>)")
    s.add_argument("--workers", type=int, help="pool size (default: all cores)")
    s.add_argument("--backend", choices=("thread", "process", "serial"), default="thread",
                   help="local pool kind (default thread)")
    s.add_argument("--scheduler", help="address of a Dask scheduler (tcp://host:port): run the "
                                       "points on that cluster (needs pdw[dask])")
    s.add_argument("--fresh", action="store_true", help="ignore an existing CSV (start afresh)")
    s.add_argument("--no-figures", action="store_true", help="skip the figure")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.set_defaults(func=cli_main)
    return s


def cli_main(args):
    study = load_study(args.study)
    executor, client = None, None
    if args.scheduler:
        try:
            from distributed import Client
        except ImportError:
            raise PdwError("--scheduler needs Dask: pip install 'pdw[dask]'") from None
        client = Client(args.scheduler)
        executor = client.get_executor()
    try:
        res = run_study(study, args.out, executor=executor, workers=args.workers,
                        backend=args.backend, resume=not args.fresh,
                        progress=not args.no_progress, figures=None if args.no_figures else plot_study)
    finally:
        if client is not None:
            client.close()
    counts = {}
    for r in res.rows:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    print("%s: %d points (%d computed, %d resumed) in %.1f s; status %s"
          % (study.name, len(res.rows), len(res.computed), len(res.resumed), res.wall_s,
             ", ".join("%s %d" % kv for kv in sorted(counts.items()))))
    for p in res.paths.values():
        print("wrote %s" % p)
    return 0
