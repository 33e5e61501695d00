"""``pdw sweep STUDY.toml`` (or ``--example NAME``): the command line of
`pdw.studies.sweep.run_study`.

Where the points run: a local pool (``--backend thread|process|serial``, ``--workers N``), a
local Dask cluster started for this sweep (``--dask-local``, ``--workers N`` processes), or a
running Dask cluster (``--scheduler ADDRESS``). Options that would be ignored in a combination
are refused rather than silently dropped.
"""
from __future__ import annotations

import contextlib
import os

from .. import examples
from ..core.errors import PdwError
from ..studies.study import load_study
from ..studies.sweep import run_study
from .deps import require
from .study_plots import plot_study


def add_cli(subparsers):
    """Register ``pdw sweep`` on an argparse subparsers object."""
    s = subparsers.add_parser("sweep", help="run a parameter study described in a TOML file "
                                            "(CSV + JSON provenance + figure)")
    s.add_argument("study", nargs="?", help="the study file (TOML; see docs/studies.md)")
    s.add_argument("--example", help="run an example study shipped with pdw "
                                     "(pdw run --list-examples lists them)")
    s.add_argument("--out", help="output folder (default out/studies/<name>)")
    s.add_argument("--workers", type=int, help="local pool size, or the number of workers of "
                                               "--dask-local (default: all cores)")
    s.add_argument("--backend", choices=("thread", "process", "serial"),
                   help="local pool kind (default thread); not with a Dask option")
    where = s.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:port): "
                                           "run the points on that cluster (needs pdw[dask])")
    where.add_argument("--dask-local", action="store_true",
                       help="start a local Dask cluster (--workers processes, one thread each) "
                            "for this sweep (needs pdw[dask])")
    s.add_argument("--fresh", action="store_true", help="ignore an existing CSV (start afresh)")
    s.add_argument("--no-figures", action="store_true", help="skip the figure")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.set_defaults(func=cli_main)
    return s


def _dask():
    require("distributed", purpose="--scheduler and --dask-local")
    import distributed
    return distributed


def cli_main(args):
    if (args.study is None) == (args.example is None):
        raise PdwError("give a study file or --example NAME (one of them)")
    if args.backend is not None and (args.scheduler or args.dask_local):
        raise PdwError("--backend chooses a local pool; it cannot be combined with "
                       "--scheduler or --dask-local")
    if args.workers is not None and args.scheduler:
        raise PdwError("--workers sizes a local pool or --dask-local; a --scheduler cluster "
                       "has its own workers")
    study = load_study(examples.study_path(args.example) if args.example else args.study)
    # what the command needs, before the work (exit code 4: pdw.present.deps)
    if args.scheduler or args.dask_local:
        _dask()
    if not args.no_figures:
        require("matplotlib", purpose="the figure")
    executor = None
    with contextlib.ExitStack() as stack:
        if args.scheduler or args.dask_local:
            distributed = _dask()
            if args.dask_local:
                cluster = stack.enter_context(distributed.LocalCluster(
                    n_workers=args.workers or os.cpu_count() or 1, threads_per_worker=1,
                    dashboard_address=None))
                client = stack.enter_context(distributed.Client(cluster))
            else:
                client = stack.enter_context(distributed.Client(args.scheduler))
            executor = client.get_executor()
        res = run_study(study, args.out, executor=executor, workers=args.workers,
                        backend=args.backend or "thread", resume=not args.fresh,
                        progress=not args.no_progress,
                        figures=None if args.no_figures else plot_study)
    counts = {}
    for r in res.rows:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    print("%s: %d points (%d computed, %d resumed) in %.1f s; status %s"
          % (study.name, len(res.rows), len(res.computed), len(res.resumed), res.wall_s,
             ", ".join("%s %d" % kv for kv in sorted(counts.items()))))
    for p in res.paths.values():
        print("wrote %s" % p)
    return 0
