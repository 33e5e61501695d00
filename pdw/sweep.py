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
describe, timings, executor) and ``<name>.png`` (L, P, v and double support against the first
axis, one line per value of the second, the paper's reported end points as markers).

Scale
-----
Points are independent tasks of the module-level worker `run_point` (a small dict in, a small
dict out), submitted to any ``concurrent.futures``-style executor: by default a thread pool over
the local cores (the compiled loop releases the GIL, so threads run in parallel), or a process
pool (``backend="process"``), or a Dask cluster unchanged (``executor=client.get_executor()``).
Each finished point is appended to the CSV at once (flushed), so an interrupted sweep resumes
from its CSV: rerunning skips the points already there and computes only the others
(``resume=False`` starts afresh). A progress bar is written to stderr (no dependency).
"""
from __future__ import annotations

import concurrent.futures as cf
import csv
import dataclasses
import fcntl
import datetime
import hashlib
import io
import itertools
import json
import math
import os
import pathlib
import platform
import re
import signal
import subprocess
import sys
import tempfile
import threading
import time
import tomllib

import numpy as np

from . import _layout, checks
from .errors import InvalidInputError, PdwError
from .params import Params
from .simulation import METHODS, X0_PAPER

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
           "spread_L", "spread_cycle", "n_steps", "max_multiplier", "t_final", "wall_s", "error",
           "settings")
#: A study name is a plain file name: letters, digits, "_", "-", "+", "." (not first).
NAME_RE = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.+-]{0,99}")
#: Most points one study may have, and most values one axis may have.
MAX_POINTS = 10 ** 6
#: The lock file that keeps a second sweep out of an output folder.
LOCK_NAME = ".pdw-sweep.lock"


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
        """The worker's input for one point (plain data: picklable, small); ``settings`` is
        the hash of everything that affects the point's row (`settings_hash`)."""
        p = self.base_params().as_dict()
        p.update(values)
        task = {"index": index, "values": dict(values), "params": p, "variant": self.variant,
                "method": self.method, "run": dict(self.run)}
        task["settings"] = settings_hash(task)
        return task

    def digest(self) -> str:
        return hashlib.sha256(self.source.encode()).hexdigest()


def settings_hash(task) -> str:
    """16 hex digits of the SHA-256 of everything that decides a point's row: its full
    parameter set, variant, method, the [run] settings and the model's input hash
    (`pdw.INPUT_HASH`). A resumed sweep recomputes every row whose hash differs."""
    key = {"params": task["params"], "variant": task["variant"], "method": task["method"],
           "run": task["run"], "model": _layout.INPUT_HASH}
    text = json.dumps(key, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def check_name(name, where="study"):
    """A study name must be a plain file name (no folder, no "..", no absolute path)."""
    if not isinstance(name, str) or not NAME_RE.fullmatch(name) or name in (".", ".."):
        raise InvalidInputError("%s: name must be a plain file name (letters, digits, '_', '-', "
                                "'+', '.'; not starting with '.'; at most 100 characters), got %r"
                                % (where, name))
    return name


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
    except RecursionError:
        raise InvalidInputError("%s: TOML nested too deeply" % where) from None
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
        if k not in RUN_KEYS:
            raise InvalidInputError("%s [run]: unknown key %r; allowed: %s"
                                    % (where, k, ", ".join(RUN_KEYS)))
        _typecheck(where + " [run]", k, v, RUN_KEYS[k])
        run[k] = v
    if run["mode"] not in ("simulate", "newton"):
        raise InvalidInputError("%s [run]: mode must be 'simulate' or 'newton', got %r"
                                % (where, run["mode"]))
    _check_run(run, where + " [run]")
    if int(np.prod([len(v) for _, v in axes])) > MAX_POINTS:
        raise InvalidInputError("%s: %d points; at most %d" % (
            where, int(np.prod([len(v) for _, v in axes])), MAX_POINTS))
    check_name(data.get("name", name), where)
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


def _check_run(run, where):
    """The [run] table, with the checks `pdw.simulate` applies (pdw.checks)."""
    from .simulation import DT_MIN
    from .simulation import check_state
    run["x0"] = check_state(run["x0"], where + " x0").tolist()
    run["flags0"] = list(checks.flags(where + " flags0", run["flags0"]))
    checks.positive(where + " t_end", run["t_end"])
    checks.number(where + " dt", run["dt"], lo=DT_MIN, hi=run["t_end"])
    checks.number(where + " rtol", run["rtol"], lo=0.0, hi=1.0, lo_open=True)
    checks.positive(where + " atol", run["atol"])
    checks.positive(where + " period_tol", run["period_tol"])
    checks.count(where + " steady", run["steady"], lo=1, hi=10 ** 6)


def load_study(path) -> Study:
    """Read and validate a study file (TOML)."""
    path = pathlib.Path(path)
    try:
        text = path.read_text()
    except OSError as e:
        raise InvalidInputError("cannot read study file %s: %s" % (path, e)) from None
    return parse_study(text, name=path.stem, path=str(path))


# --- the worker -------------------------------------------------------------------------------

def _classify(table, steady, tol):
    """'period-1', 'period-2' or 'none' from the last steps' L and cycle."""
    L, T = table["L"], table["cycle"]
    ok = np.isfinite(L) & np.isfinite(T)
    L, T = L[ok], T[ok]
    n = max(steady, 2)
    if len(L) >= n and max(np.ptp(L[-n:]), np.ptp(T[-n:])) < tol:
        return "period-1"
    if len(L) >= 2 * n and max(np.max(np.abs(L[-n:] - L[-n - 2:-2])),
                               np.max(np.abs(T[-n:] - T[-n - 2:-2]))) < tol:
        return "period-2"
    return "none"


def run_point(task) -> dict:
    """Compute one point of a study (module-level, so that process pools and Dask workers can
    import it). ``task``: `Study.task`. Returns the CSV row (a flat dict of numbers and short
    strings); an invalid point gives ``status = "error"`` instead of raising."""
    from .gait import steps
    from .simulation import simulate
    t0 = time.perf_counter()
    row = {"index": int(task["index"]), **task["values"]}
    row.update({c: "" for c in COLUMNS})
    row["settings"] = task.get("settings", "")
    run = task["run"]
    try:
        params = Params(**task["params"])
        if run["mode"] == "simulate":
            res = simulate(run["x0"], t_end=run["t_end"], dt=run["dt"], params=params,
                           variant=task["variant"], method=task["method"],
                           flags0=tuple(run["flags0"]), record_every=0, record_forces=False,
                           on_failure="return", rtol=run["rtol"], atol=run["atol"])
            st = steps(res)
            s = st.steady(run["steady"])
            row.update(status=res.status, n_steps=len(st), t_final=res.t_final, source="simulate",
                       gait=_classify(st.table, run["steady"], run["period_tol"])
                       if res.status == "walked" else "")
            if res.status == "walked" and len(st) >= run["steady"]:
                row.update({k: s[k] for k in ("L", "P", "v", "cycle", "double_support",
                                              "ds_fraction", "travel")},
                           spread_L=s["spread_L"], spread_cycle=s["spread_cycle"])
        if run["mode"] == "newton" or (run["fallback"] and row["gait"] != "period-1"):
            _newton_point(row, params, task)
    except (PdwError, ValueError) as e:
        row.update(status="error", error=str(e)[:300])
    row["wall_s"] = time.perf_counter() - t0
    return row


def _newton_point(row, params, task):
    """Fill ``row`` from `pdw.find_gait` (default guesses); keeps ``row`` if none is found."""
    from .gait_types import GaitNotFoundError
    from .limit_cycle import find_gait
    try:
        g = find_gait(params, variant=task["variant"], method=task["method"], workers=1,
                      max_iter=12)
    except GaitNotFoundError as e:
        if row["status"] == "":
            row.update(status="no_gait", source="newton", error=str(e)[:200])
        return
    sp = g.details["swing_period"]
    mu = float(np.max(np.abs(g.multipliers)))
    row.update(status="walked" if mu < 1 else "unstable", source="newton",
               gait="period-1" if mu < 1 else "unstable", L=g.step_length, P=sp,
               v=g.step_length / sp, cycle=g.period, double_support=g.double_support,
               ds_fraction=g.double_support / g.period, travel=g.details["travel"],
               spread_L=g.details["residual"], spread_cycle="", max_multiplier=mu, error="")


# --- CSV (resumable) ------------------------------------------------------------------------------

def _header(study):
    return ["index"] + study.axis_names + list(COLUMNS)


def _fmt(v):
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("nan" if math.isnan(v) else repr(v))
    if isinstance(v, (np.floating,)):
        return repr(float(v))
    return str(v)


def _parse(v):
    try:
        return float(v) if v not in ("",) else ""
    except ValueError:
        return v


def read_rows(path, study) -> dict:
    """Rows already in a study's CSV, by index; checks that they belong to ``study`` (same
    columns, same axis values). Malformed lines (a write cut by a kill), rows computed under
    other settings (their ``settings`` hash differs: another preset, method, [run], fixed
    parameter or model) and ``error`` rows are dropped: they are computed again."""
    path = pathlib.Path(path)
    if not path.exists():
        return {}
    text = path.read_text()
    lines = text.splitlines()
    if not lines:
        return {}
    header = next(csv.reader([lines[0]]))
    if header != _header(study):
        raise PdwError("%s: its columns %s are not this study's %s; use a fresh output folder "
                       "or resume=False (--fresh)" % (path, header, _header(study)))
    pts = dict(study.points())
    rows = {}
    for line in lines[1:]:
        rec = next(csv.reader([line]), None)
        if rec is None or len(rec) != len(header):
            continue                                   # torn line
        row = dict(zip(header, rec))
        try:
            k = int(row["index"])
        except ValueError:
            continue
        if k not in pts or any(not np.isclose(float(row[a]), pts[k][a], rtol=1e-12, atol=0)
                               for a in study.axis_names):
            raise PdwError("%s: row %s does not match this study's point %s; use a fresh output "
                           "folder or resume=False (--fresh)" % (path, row["index"], pts.get(k)))
        if row["status"] in ("", "error") or row["settings"] != study.task(k, pts[k])["settings"]:
            continue
        rows[k] = {c: (int(row[c]) if c == "index" else _parse(row[c])) for c in header}
    return rows


def _csv_line(row, header):
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow([_fmt(row.get(c, "")) for c in header])
    return buf.getvalue()


# --- progress -------------------------------------------------------------------------------------

class Progress:
    """A plain progress bar on stderr: redrawn in place on a terminal, a line every 10 %
    otherwise. ``enabled=False`` prints nothing."""

    def __init__(self, total, done=0, label="sweep", stream=None, enabled=True):
        self.total, self.done, self.label = total, done, label
        self.start_done = done
        self.stream = sys.stderr if stream is None else stream
        self.enabled = enabled and total > 0
        self.t0 = time.perf_counter()
        self._last = 0.0
        self._decile = -1
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.update(0)

    def update(self, n=1):
        self.done += n
        if not self.enabled:
            return
        now = time.perf_counter()
        el = now - self.t0
        new = self.done - self.start_done
        left = self.total - self.done
        eta = el / new * left if new > 0 else float("nan")
        frac = self.done / self.total
        text = "%s: [%-30s] %d/%d (%3.0f%%) %.1f s, ETA %s" % (
            self.label, "#" * int(30 * frac), self.done, self.total, 100 * frac, el,
            "%.1f s" % eta if math.isfinite(eta) else "?")
        if self.tty:
            if now - self._last > 0.1 or self.done >= self.total:
                self.stream.write("\r" + text)
                if self.done >= self.total:
                    self.stream.write("\n")
                self.stream.flush()
                self._last = now
        else:
            dec = int(10 * frac)
            if dec != self._decile:
                self._decile = dec
                self.stream.write(text + "\n")
                self.stream.flush()


# --- provenance -----------------------------------------------------------------------------------

def git_describe(path=None):
    """``git describe --always --dirty --tags`` of the repository holding ``path`` (default:
    this package), or None."""
    where = pathlib.Path(path or __file__).resolve().parent
    try:
        out = subprocess.run(["git", "-C", str(where), "describe", "--always", "--dirty",
                              "--tags"], capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None if out.returncode == 0 else None


def provenance(study, **extra) -> dict:
    from . import INPUT_HASH, __version__
    return {
        "study": {"name": study.name, "title": study.title, "path": study.path,
                  "sha256": study.digest(), "toml": study.source},
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
    ``computed`` (indices computed in this call), ``resumed`` (indices read from the CSV)."""

    study: Study
    rows: list
    paths: dict
    computed: list
    resumed: list
    wall_s: float

    def column(self, name):
        return np.array([np.nan if r[name] == "" else r[name] for r in self.rows], dtype=float) \
            if name not in ("status", "gait", "error") else [r[name] for r in self.rows]


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


class _FolderLock:
    """An exclusive lock (fcntl.flock) on ``<out>/.pdw-sweep.lock``: one sweep per folder."""

    def __init__(self, folder):
        self.path = pathlib.Path(folder) / LOCK_NAME
        self.f = None

    def __enter__(self):
        f = open(self.path, "a+")
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            f.seek(0)
            holder = f.read().strip() or "?"
            f.close()
            raise PdwError("%s is in use by another sweep (process %s holds %s): wait for it to "
                           "finish, or write to another folder (--out)"
                           % (self.path.parent, holder, self.path.name)) from None
        f.seek(0)
        f.truncate()
        f.write("%d\n" % os.getpid())
        f.flush()
        self.f = f
        return self

    def __exit__(self, *exc):
        fcntl.flock(self.f, fcntl.LOCK_UN)
        self.f.close()
        return False


def _write_atomic(path, text):
    """Write ``text`` to ``path`` through a temporary file in the same folder (fsync, rename):
    readers see the old file or the new one, never a part."""
    path = pathlib.Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix="." + path.name + ".", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", newline="") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _make_executor(backend, workers):
    n = max(1, int(workers or os.cpu_count() or 1))
    if backend == "thread":
        return cf.ThreadPoolExecutor(n), n
    if backend == "process":
        return cf.ProcessPoolExecutor(n, initializer=_die_with_parent, initargs=(os.getpid(),)), n
    raise InvalidInputError("backend must be 'thread', 'process' or 'serial', got %r" % (backend,))


def run_study(study, out=None, *, executor=None, workers=None, backend="thread", resume=True,
              progress=True, figures=True) -> StudyResult:
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
    progress : bool
        Progress bar on stderr.
    figures : bool
        Write the figure (needs matplotlib).

    If a point's task fails in the executor (a killed worker, an interrupt), the points finished
    so far are already in the CSV; the error is re-raised, and a rerun resumes.
    """
    if not isinstance(study, Study):
        study = load_study(study)
    check_name(study.name)
    out = pathlib.Path(out or pathlib.Path("out") / "studies" / study.name)
    out.mkdir(parents=True, exist_ok=True)
    with _FolderLock(out):
        return _run_locked(study, out, executor, workers, backend, resume, progress, figures)


def _run_locked(study, out, executor, workers, backend, resume, progress, figures):
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
    bar = Progress(len(points), len(done), label=study.name, enabled=progress)
    computed = []
    error = None
    with open(csv_path, "a", newline="") as f:
        def record(row):
            f.write(_csv_line(row, header))
            f.flush()
            done[row["index"]] = row
            computed.append(row["index"])
            bar.update(1)
        try:
            if executor is None and own is None:
                for k, v in todo:
                    record(run_point(study.task(k, v)))
            else:
                ex = executor if executor is not None else own
                futs = [ex.submit(run_point, study.task(k, v)) for k, v in todo]
                try:
                    for fut in cf.as_completed(futs):
                        record(fut.result())
                except BaseException:
                    for fut in futs:
                        fut.cancel()
                    # keep what finished meanwhile
                    for fut in futs:
                        if fut.done() and not fut.cancelled() and fut.exception() is None:
                            row = fut.result()
                            if row["index"] not in done:
                                record(row)
                    raise
        except BaseException as e:      # noqa: BLE001 - re-raised below after bookkeeping
            error = e
        finally:
            if own is not None:
                own.shutdown(wait=error is None, cancel_futures=True)
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
                      wall_s=wall, executor=exec_desc, n_points=len(points),
                      n_resumed=len(points) - len(computed), n_computed=len(computed),
                      cpu_s_points=float(sum(r["wall_s"] for r in rows if r["wall_s"] != "")),
                      status_counts=statuses, csv=csv_path.name)
    paths = {"csv": csv_path, "json": json_path}
    if figures:
        try:
            paths["png"] = plot_study(study, rows, out / (study.name + ".png"))
        except ImportError:
            meta["figure"] = "not written: matplotlib is not installed"
    _write_atomic(json_path, json.dumps(meta, indent=2, default=_jsonable) + "\n")
    return StudyResult(study=study, rows=rows, paths=paths, computed=sorted(computed),
                       resumed=sorted(set(done) - set(computed)), wall_s=wall)


def _jsonable(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)


# --- figures ------------------------------------------------------------------------------------

_PANELS = (("L", "step length L [m]", 1.0), ("P", "step period P [s]", 1.0),
           ("v", "step velocity v [m/s]", 1.0), ("ds_fraction", "double support [% of cycle]", 100.0))


def plot_study(study, rows, path):
    """L, P, v and double support against the first axis (one line per value of the second);
    points that are not period-one are drawn hollow; the paper's end points ([paper] table) as
    black markers. Returns the path."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = study.axis_names
    x_name = names[0]
    fig, axs = plt.subplots(2, 2, figsize=(9, 6.5), constrained_layout=True)
    groups = [None] if len(names) == 1 else sorted({r[names[1]] for r in rows})
    for gi, gv in enumerate(groups):
        sel = [r for r in rows if gv is None or r[names[1]] == gv]
        x = np.array([r[x_name] for r in sel], dtype=float)
        per1 = np.array([r["gait"] == "period-1" for r in sel])
        label = None if gv is None else "%s = %g" % (names[1], gv)
        for ax, (col, ylabel, scale) in zip(axs.flat, _PANELS):
            y = np.array([np.nan if r[col] == "" else r[col] for r in sel], dtype=float) * scale
            line, = ax.plot(x[per1], y[per1], "o-", ms=4, label=label)
            if (~per1).any():
                ax.plot(x[~per1], y[~per1], "o", mfc="none", color=line.get_color(), ms=6)
            ax.set_xlabel(x_name)
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3)
    paper = study.paper
    if paper:
        at = paper.get("at", {})
        lo, hi = float(np.min(study.axes[0][1])), float(np.max(study.axes[0][1]))
        xr = paper.get("range", [lo, hi])
        for ax, (col, _, scale) in zip(axs.flat, _PANELS):
            if col in paper:
                ax.plot(xr, np.array(paper[col], dtype=float) * scale, "k*--", ms=9, lw=0.8,
                        label="paper" + (" (%s)" % ", ".join("%s = %g" % kv for kv in at.items())
                                         if at else ""))
    handles, labels = axs.flat[0].get_legend_handles_labels()
    for ax in axs.flat:
        h, lab = ax.get_legend_handles_labels()
        if len(h) > len(handles):
            handles, labels = h, lab
    if handles:
        axs.flat[0].legend(handles, labels, fontsize=7)
    fig.suptitle("%s\n(%s, variant %s, %s, %s)" % (study.title, study.preset, study.variant,
                                                   study.method, study.run["mode"]), fontsize=9)
    path = pathlib.Path(path)
    tmp = path.with_name("." + path.stem + ".%d.tmp%s" % (os.getpid(), path.suffix))
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, path)
    return path


# --- command line ---------------------------------------------------------------------------------

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
                        progress=not args.no_progress, figures=not args.no_figures)
    finally:
        if client is not None:
            client.close()
    counts = {}
    for r in res.rows:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    print("%s: %d points (%d computed, %d resumed) in %.1f s; status %s"
          % (study.name, len(res.rows), len(res.computed), len(res.resumed), res.wall_s,
             ", ".join("%s %d" % kv for kv in sorted(counts.items()))))
    for k, p in res.paths.items():
        print("wrote %s" % p)
    return 0
