"""Parameter studies at scale: ``pdw sweep study.toml`` (docs/studies.md).

A *study* (a TOML file, `load_study`) sweeps one or two `Params` fields over ranges, the others
fixed (a preset plus overrides), with one contact variant and one integrator. Every point gets
a steady gait, either

* ``mode = "simulate"`` (default): one simulation of ``t_end`` seconds from ``x0`` (default the
  paper's initial condition), the steady descriptors being the mean of the last ``steady`` steps
  (`pdw.steps(...).steady`), classified period-1 / period-2 / none from the step-to-step
  spread; or
* ``mode = "newton"``: `pdw.find_gait` (Newton shooting on the touch-down map) with its
  Floquet multipliers.

`run_study` writes, in the output folder, ``<name>.csv`` (one row per point, with its status),
``<name>.json`` (provenance: the study, the base parameters, versions, pdw.INPUT_HASH, git
describe, timings, executor) and, given a figure function (``pdw sweep`` passes
`pdw.present.study_plots.plot_study`), ``<name>.png`` (L, P, v and double support against the first
axis, one line per value of the second, the paper's reported end points as markers).

Scale
-----
Points are independent tasks of the module-level worker `run_point` (a small dict in, a small
dict out), submitted to any ``concurrent.futures``-style executor: by default a thread pool over
the local cores (the compiled loop releases the GIL, so threads run in parallel), or a process
pool (``backend="process"``), or a Dask cluster unchanged (``executor=client.get_executor()``).
Each finished point is appended to the CSV at once (flushed), so an interrupted sweep resumes
from its CSV: rerunning skips the points already there and computes only the others
(``resume=False`` starts afresh). ``progress=True`` writes a bar to stderr on a terminal (`pdw.core.progress`: tqdm if installed).
"""
from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import datetime
import json
import os
import pathlib
import platform
import signal
import sys
import threading
import time

import numpy as np

from ..core import interrupt, paths
from ..core.errors import InvalidInputError
from ..core.progress import Progress, progress_bar  # noqa: F401 (pdw.sweep.Progress)
from ..core.provenance import source_revision
from .points import _classify, _newton_point, batchable, groups, run_point, run_points  # noqa: F401 (pdw.sweep.run_point)
from .study import COLUMNS, Study, check_name, load_study, parse_study, settings_hash  # noqa: F401 (pdw.sweep.parse_study)
from .table import csv_line, fmt, header, load_sweep, read_rows  # noqa: F401 (pdw.sweep.read_rows)

# --- CSV (resumable): the format is pdw.studies.table's --------------------------------------

_header, _fmt, _csv_line = header, fmt, csv_line       # the names this module used


# --- progress -------------------------------------------------------------------------------------

# --- provenance -----------------------------------------------------------------------------------

def git_describe(path=None):
    """pdw's own source revision (`pdw.core.provenance.source_revision`; ``path``: another
    pdw package directory), or None when pdw is not imported from its git checkout."""
    return source_revision(None if path is None else str(path))


def provenance(study, **extra) -> dict:
    from ..core import __version__
    from ..core._layout import INPUT_HASH
    return {
        "study": {"name": study.name, "title": study.title, "path": study.path,
                  "sha256": study.digest(), "toml": study.source},
        "scene": study.scene.to_dict(),
        "preset": study.preset, "variant": study.variant, "method": study.method,
        "base_params": study.base_params().as_dict(),
        "axes": {a: v.tolist() for a, v in study.axes},
        "run": study.run,
        "code": {"pdw_version": __version__, "input_hash": INPUT_HASH,
                 "git_describe": git_describe()},
        "python": sys.version.split()[0], "numpy": np.__version__,
        "platform": platform.platform(), "cpu_count": os.cpu_count(),
        **extra,
    }


# --- running ----------------------------------------------------------------------------------

@dataclasses.dataclass
class StudyResult:
    """Outcome of `run_study`: ``rows`` (list of dicts sorted by index), ``paths`` written,
    ``computed`` (indices computed in this call), ``resumed`` (indices read from the CSV),
    ``engine`` ("batch": groups of points through `pdw.studies.points.run_points`; "scalar")."""

    study: Study
    rows: list
    paths: dict
    computed: list
    resumed: list
    wall_s: float
    engine: str = "scalar"

    def column(self, name):
        return np.array([np.nan if r[name] == "" else r[name] for r in self.rows], dtype=float) \
            if name not in ("status", "gait", "error") else [r[name] for r in self.rows]


#: The lock file that keeps a second sweep out of an output folder.
LOCK_NAME = ".pdw-sweep.lock"


def _die_with_parent(ppid):
    """Process-pool worker initializer: the worker ends when its parent does (even SIGKILLed).
    Linux: prctl(PR_SET_PDEATHSIG, SIGKILL); everywhere: a thread watching the parent id."""
    try:
        import ctypes
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL))   # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass
    if os.getppid() != ppid:
        os._exit(1)

    def watch():
        while os.getppid() == ppid:
            time.sleep(1.0)
        os._exit(1)
    threading.Thread(target=watch, daemon=True, name="pdw-parent-watch").start()


#: One sweep per output folder (`pdw.core.paths.FolderLock`: portable, removed when released).
_FolderLock = paths.FolderLock
_write_atomic = paths.write_atomic


def _stop_workers(pool):
    """Terminate the worker processes of our own process pool (after Ctrl-C: their running
    points are lost anyway, and the pool's shutdown would otherwise wait for them)."""
    if not isinstance(pool, cf.ProcessPoolExecutor):
        return
    stop = getattr(pool, "terminate_workers", None)          # Python >= 3.14
    if stop is not None:
        stop()
        return
    for proc in list((getattr(pool, "_processes", None) or {}).values()):
        try:
            proc.terminate()
        except (OSError, AttributeError):                   # pragma: no cover - gone already
            pass


def _make_executor(backend, workers):
    n = max(1, int(workers or os.cpu_count() or 1))
    if backend == "thread":
        return cf.ThreadPoolExecutor(n), n
    if backend == "process":
        return cf.ProcessPoolExecutor(n, initializer=_die_with_parent, initargs=(os.getpid(),)), n
    raise InvalidInputError("backend must be 'thread', 'process' or 'serial', got %r" % (backend,))


def run_study(study, out=None, *, executor=None, workers=None, backend="thread", resume=True,
              progress=False, figures=None, batch=True) -> StudyResult:
    """Run a study (a `Study` or a path to its TOML file).

    Parameters
    ----------
    out : path, optional
        Output folder (default ``out/studies/<name>``); holds ``<name>.csv``, ``.json``, ``.png``.
    executor : concurrent.futures.Executor-like, optional
        Anything with ``submit(fn, *args) -> concurrent.futures.Future``, e.g. a
        ``ThreadPoolExecutor``, a ``ProcessPoolExecutor`` or Dask's ``client.get_executor()``.
        It is not shut down here. Default: a new pool of ``backend``.
    workers : int
        Size of the default pool (default: all cores).
    backend : {"thread", "process", "serial"}
        The default pool's kind; "serial" computes in this thread, no pool.
    resume : bool
        Keep the points already in the CSV and compute only the others (default). False
        starts afresh (the CSV is overwritten).
    progress : bool or pdw.Progress
        Progress bar over points (`pdw.core.progress.progress_bar`): False (default) none,
        True on stderr when it is a terminal (``pdw sweep`` does that unless --no-progress).
    figures : callable, optional
        ``figures(study, rows, path) -> path`` draws the study's figure into ``path``
        (``<name>.png``); `pdw.present.study_plots.plot_study` is the standard one (``pdw sweep``
        passes it). None or False: no figure. The figure belongs to the presentation layer, so it is
        passed in rather than imported here (docs/architecture.md).
    batch : bool
        Run the points as batches through the ensemble engine when the study qualifies
        (`pdw.studies.points.batchable`; the rows are the same); False: point by point.

    If a point's task fails in the executor (a killed worker, an interrupt), the points finished
    so far are already in the CSV; the error is re-raised, and a rerun resumes.
    """
    if figures and not callable(figures):
        raise InvalidInputError("figures must be a function (study, rows, path) -> path, e.g. "
                                "pdw.present.study_plots.plot_study, or None; got %r" % (figures,))
    if not isinstance(study, Study):
        study = load_study(study)
    check_name(study.name)
    out = pathlib.Path(out or pathlib.Path("out") / "studies" / study.name)
    out.mkdir(parents=True, exist_ok=True)
    with paths.FolderLock(out, LOCK_NAME, "sweep"):
        return _run_locked(study, out, executor, workers, backend, resume, progress, figures,
                           batch)


def _run_locked(study, out, executor, workers, backend, resume, progress, figures, batch):
    csv_path, json_path = out / (study.name + ".csv"), out / (study.name + ".json")
    header = _header(study)
    t_start = time.perf_counter()
    started = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    done = read_rows(csv_path, study) if resume else {}
    points = study.points()
    todo = [(k, v) for k, v in points if k not in done]
    # rewrite the CSV with what is kept (drops torn lines and stale rows), then append as
    # points finish
    _write_atomic(csv_path, ",".join(header) + "\n"
                  + "".join(_csv_line(done[k], header) for k in sorted(done)))

    own = None
    if executor is None and backend != "serial" and todo:
        own, nw = _make_executor(backend, workers)
        exec_desc = "%s pool, %d workers" % (backend, nw)
    elif executor is not None:
        exec_desc = "%s.%s" % (type(executor).__module__, type(executor).__qualname__)
    else:
        exec_desc = "serial"
    bar = progress_bar(progress, len(points), study.name, done=len(done))
    token = interrupt.Token(interrupt.current())
    computed = []
    error = None
    # points that share the scene run as batches (pdw.studies.points), one task a group
    engine = "batch" if batch and todo and batchable(study) else "scalar"
    if engine == "batch":
        fn, units = run_points, [[study.task(k, v) for k, v in g]
                                 for g in groups(todo, workers or os.cpu_count() or 1)]
    else:
        fn, units = run_point, [study.task(k, v) for k, v in todo]
    with open(csv_path, "a", newline="") as f:
        def record(out):
            for row in (out if engine == "batch" else [out]):
                if row["index"] in done:      # already written (the interrupt path)
                    continue
                f.write(_csv_line(row, header))
                f.flush()
                done[row["index"]] = row
                computed.append(row["index"])
                bar.update(1)
        try:
            if executor is None and own is None:
                for u in units:
                    record(fn(u))
            else:
                ex = executor if executor is not None else own
                # a thread's task gets a cancel token: on Ctrl-C its compiled loops stop at
                # their next poll (pdw.core.interrupt) instead of running to the end
                threads = isinstance(ex, cf.ThreadPoolExecutor)
                futs = [ex.submit(interrupt.call_with_token, token, fn, u) if threads
                        else ex.submit(fn, u) for u in units]
                try:
                    for fut in cf.as_completed(futs):
                        record(fut.result())
                except BaseException:
                    token.set()
                    for fut in futs:
                        fut.cancel()
                    _stop_workers(own)
                    # keep what finished meanwhile
                    for fut in futs:
                        if fut.done() and not fut.cancelled() and fut.exception() is None:
                            record(fut.result())
                    raise
        except BaseException as e:      # noqa: BLE001 - re-raised below after bookkeeping
            error = e
        finally:
            if own is not None:
                # after an interrupt the running tasks stop within a poll (threads) or were
                # terminated (processes): waiting for them is short
                own.shutdown(wait=True, cancel_futures=True)
    if error is not None:
        raise error
    rows = [done[k] for k, _ in points]
    # final CSV in index order (atomic)
    _write_atomic(csv_path, ",".join(header) + "\n" + "".join(_csv_line(r, header) for r in rows))
    wall = time.perf_counter() - t_start
    statuses = {}
    for r in rows:
        statuses[r["status"]] = statuses.get(r["status"], 0) + 1
    meta = provenance(study, started=started,
                      finished=datetime.datetime.now(datetime.timezone.utc).isoformat(
                          timespec="seconds"),
                      wall_s=wall, executor=exec_desc, engine=engine, n_points=len(points),
                      n_resumed=len(points) - len(computed), n_computed=len(computed),
                      cpu_s_points=float(sum(r["wall_s"] for r in rows if r["wall_s"] != "")),
                      status_counts=statuses, csv=csv_path.name)
    paths = {"csv": csv_path, "json": json_path}
    if figures:
        try:
            paths["png"] = figures(study, rows, out / (study.name + ".png"))
        except ImportError:
            meta["figure"] = "not written: matplotlib is not installed"
    _write_atomic(json_path, json.dumps(meta, indent=2, default=_jsonable) + "\n")
    return StudyResult(study=study, rows=rows, paths=paths, computed=sorted(computed),
                       resumed=sorted(set(done) - set(computed)), wall_s=wall, engine=engine)


def _jsonable(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)
