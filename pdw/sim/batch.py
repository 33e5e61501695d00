"""`simulate_batch`: N walkers in one call, W lanes of a block in lockstep (docs/ensemble.md).

The compiled engine (pdw/core/csrc/pdw_batch.c) advances a block of W walkers with the paper's
central difference method (docs/model.md section 7), one walker per lane: the sin/cos of all lanes in
one vector loop (glibc's libmvec), the generated stages and the discrete logic (flags, arming,
anchors, events, online gait descriptors) per lane, exactly as `pdw.simulate`; a lane whose
walker finishes takes the next one. Every other method of `pdw.METHODS` (rodas4, dopri5, rk4,
verlet) runs in rounds of one step per lane through the scalar integrator's own C, each lane
with its own time, step size, accept/reject and located events (rodas4 in structure-of-arrays
lanes too). Threads (GIL released) share the batch: each lane takes the next walker from one
shared counter.

Why this module is long: `simulate_batch` takes every option `simulate` takes (the option
objects, their old keywords, a ground per walker), each checked here before the compiled
engine is entered, next to its documentation and its result type `BatchResult` (the chunked
and recorded runs are in `pdw.sim.chunks`).
"""
from __future__ import annotations

import dataclasses
import math
import os
import pathlib
from dataclasses import dataclass, field
from typing import Any, Literal, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ..core import _batch, _layout, checks, interrupt  # type: ignore[attr-defined]
from ..core.errors import InvalidInputError
from ..core.ground import Ground
from ..core.integrators import METHODS
from ..core.integrators import get as _method_info
from ..core.model import STATE, check_variant, kernel_index, parameter_vector
from ..core.params import Params
from ..core.progress import Progress, progress_bar
from . import files as _files
from . import options as _opt
from . import stepsize as _stepsize
from .chunks import _plist, check_record, honest, record_subset, run_chunked
from .gait import Steps, steps_from_rows
from .simulation import _REASONS, Event, Result, _check_count, _check_positive

#: A walker's loop status (layout STATUS) -> its BatchResult status (running: interrupted).
_STATUS = {_layout.STATUS.index(c): s for c, s in (
    ("running", "interrupted"), ("done", "walked"), ("fell", "fell"), ("diverged", "diverged"),
    ("singular", "diverged"), ("periodic", "periodic"))}
_STOP = {i: ("t_end" if i == 0 else name) for i, name in enumerate(_layout.STOP)}
LANES = 16
"""Default lanes per block (walkers advanced in lockstep by one thread) of ``method="cdm"``:
two vector chunks of its lane loops (`CHUNK`), which share one round's fixed costs (16 lanes
against 8: 3.18x against 2.75x the scalar loop bitwise, 5.35x against 4.88x with
``vector=True``, benchmarks/results/batch.txt); no walker's result depends on it
(docs/ensemble.md)."""
LANES_OTHER = 8
"""Default lanes per block of the other methods (rodas4's structure-of-arrays lanes: 1 % slower
at 16 than at 8)."""
CHUNK = 8
"""Lanes per vector chunk of the structure-of-arrays lane loops (``PDW_SOA_CHUNK``): a block of
W lanes computes ceil(W / 8) chunks, whatever its walkers."""
WIDE_CHUNK_COST = 0.9
"""A lane-step's cost in a block of two or more chunks relative to a block of one (the chunks
share a round's fixed costs; benchmarks/bench_batch.py: 0.87 bitwise, 0.91 with vector sin/cos
at 16 lanes against 8): `lane_width`'s cost model."""


def lane_width(walkers: int, lanes: int) -> int:
    """The lanes of a thread that runs about ``walkers`` walkers with at most ``lanes`` lanes.

    A block computes ceil(W / `CHUNK`) chunks in every round, and its walkers run in about
    ceil(walkers / W) generations (a finished walker's lane takes the next): the width of
    the least chunk-rounds (`WIDE_CHUNK_COST` for blocks of several chunks), the wider on a
    tie. Speed only: no walker's result depends on it (docs/ensemble.md, "Threads").

    Parameters
    ----------
    walkers : int
        The thread's share of the batch (>= 1).
    lanes : int
        The most lanes it may take (`simulate_batch`'s ``lanes``, >= 1).

    Returns
    -------
    int
        W in [1, min(walkers, lanes)]: e.g. with 16 lanes, 16 for 64 walkers, 8 for 24 or 40
        (a second generation of 16 lanes would run half empty), 12 for 12.
    """
    widths = {min(lanes, walkers)} | {min(w, walkers) for w in range(CHUNK, lanes + 1, CHUNK)}

    def cost(w: int) -> float:
        chunks = -(-w // CHUNK)
        return -(-walkers // w) * chunks * (1.0 if chunks == 1 else WIDE_CHUNK_COST)
    return min(sorted(widths, reverse=True), key=cost)


ISA_ENV = "PDW_BATCH_ISA"
"""Environment variable that picks the cdm lane loop: ``scalar`` (every lane through the
generated scalar stages), ``base`` (the structure-of-arrays step at the x86-64 baseline, SSE2),
``avx2`` or ``avx512``; default: the widest this CPU runs (`pdw.core._batch.best_isa`). Every
choice gives the same bits with ``vector=False``; the tests force each one."""


def batch_isa() -> str:
    """The cdm lane loop `simulate_batch` uses: $PDW_BATCH_ISA, else the widest supported."""
    name = os.environ.get(ISA_ENV, "").strip().lower()
    if not name:
        return _batch.best_isa()
    if name not in _batch.ISAS:
        raise InvalidInputError("%s must be one of %s, got %r"
                                % (ISA_ENV, tuple(_batch.ISAS), name))
    if not _batch.isa_supported(name):
        raise InvalidInputError("%s = %r: this CPU does not run it (it runs %s)"
                                % (ISA_ENV, name, [n for n in _batch.ISAS
                                                   if _batch.isa_supported(n)]))
    return name


@dataclass
class BatchResult:
    """Outcome of `simulate_batch`: one row per walker, in the order of ``x0``.

    Attributes
    ----------
    status : ndarray of str (N,)
        ``"walked"``, ``"periodic"``, ``"fell"`` or ``"diverged"``, as `Result.status`.
    stop_reason : ndarray of str (N,)
        ``"t_end"``, ``"steps"``, ``"periodic"``, or the failure status.
    x_final : ndarray (N, 8)
        State at ``t_final`` (layout `pdw.STATE`); for a failure the last state reached.
    t_final : ndarray (N,)
        Time of ``x_final`` [s].
    n_steps : ndarray of int (N,)
        Integration steps taken.
    flags_final : ndarray of int (N, 2)
        Support flags of legs 1, 2 at the end.
    failure_reason : ndarray of str (N,)
        Why a walker fell or diverged (``"none"`` otherwise); ``failure_t`` [s] (N,),
        ``failure_x`` (N, 8) the last good state (NaN if none), ``failure_leg`` (N,) 1, 2 or 0.
    n_touch_down, n_lift_off, n_gait_steps : ndarray of int (N,)
        Event counts and complete gait steps (docs/model.md section 8) of each walker.
    gait_rows : ndarray, shape (N, S, C)
        S = ``STEP_RING``, C = ``len(STEP)`` of ``pdw.core._layout``.
        The last ``min(n_gait_steps, STEP_RING)`` steps of each walker, oldest first (layout
        ``pdw.core._layout.STEP``, legs 0/1), NaN beyond; `steps(i) <pdw.steps>` gives them as `Steps`.
    dt, t_end : float
        Step and end time [s]; ``method``, ``variant``: as given.
    recorded : dict
        ``{i: Result}`` for the walkers listed in ``record`` (`simulate_batch`), else empty.
    engine : str
        ``"batch"`` (the compiled lanes) or ``"scalar"`` (``pdw.sim.ensemble.scalar_batch``).
    """

    status: np.ndarray
    stop_reason: np.ndarray
    x_final: np.ndarray
    t_final: np.ndarray
    n_steps: np.ndarray
    flags_final: np.ndarray
    failure_reason: np.ndarray
    failure_t: np.ndarray
    failure_x: np.ndarray
    failure_leg: np.ndarray
    n_touch_down: np.ndarray
    n_lift_off: np.ndarray
    n_gait_steps: np.ndarray
    gait_rows: np.ndarray
    dt: float
    t_end: float
    method: str
    variant: str
    recorded: dict = field(default_factory=dict)
    engine: str = "batch"

    def __len__(self) -> int:
        return len(self.status)

    def __repr__(self) -> str:
        n = len(self)
        how = self.method if self.method in ("dopri5", "rodas4") else \
            "%s dt = %.3g s" % (self.method, self.dt)
        names, counts = np.unique(np.asarray(self.status, dtype=str), return_counts=True)
        order = np.argsort(-counts, kind="stable")
        status = ", ".join("%d %s" % (counts[i], names[i]) for i in order) or "none"
        arrays = ", ".join(
            "%s %s" % (f.name, "x".join(map(str, getattr(self, f.name).shape)))
            for f in dataclasses.fields(self) if isinstance(getattr(self, f.name), np.ndarray)
            and getattr(self, f.name).ndim > 1)
        lines = ["<pdw.BatchResult: %d walker%s, %s variant, %s, t_end = %.6g s, engine %s"
                 % (n, "" if n == 1 else "s", self.variant, how, self.t_end, self.engine),
                 "  status: %s" % status,
                 "  per walker (N,): status, stop_reason, t_final, n_steps, n_touch_down, "
                 "n_lift_off, n_gait_steps, failure_*",
                 "  %s; steps(i), to_dataframe()" % arrays]
        if self.recorded:
            lines.append("  recorded: walkers %s" % ", ".join(map(str, sorted(self.recorded)[:8]))
                         + (", ..." if len(self.recorded) > 8 else ""))
        return "\n".join(lines) + ">"

    @property
    def walked(self) -> np.ndarray:
        """(N,) bool: did each walker keep walking to the end (t_end or a stop condition)?"""
        return np.isin(self.status, ("walked", "periodic"))

    def steps(self, i: int) -> Steps:
        """The last gait steps of walker i (at most STEP_RING), as `pdw.steps` gives them."""
        n = min(int(self.n_gait_steps[i]), _layout.STEP_RING)
        return steps_from_rows(self.gait_rows[i, :n])

    def save(self, path) -> pathlib.Path:
        """Write the batch (every per-walker array, its settings, the recorded walkers'
        `Result` s) with its provenance to ``path`` (``.npz``); `pdw.load` reads it back as a
        BatchResult (`pdw.sim.files`)."""
        return _files.save(self, path)

    def to_dataframe(self):
        """One row per walker: status, stop_reason, t_final, the final state (columns
        ``x_<name>``), event counts, failure reason and time, and the last step's descriptors
        (columns ``last_<field>``). Needs pandas."""
        import pandas as pd
        cols = {"status": self.status, "stop_reason": self.stop_reason, "t_final": self.t_final,
                "n_steps": self.n_steps}
        for j, name in enumerate(STATE):
            cols["x_" + name] = self.x_final[:, j]
        cols.update(n_touch_down=self.n_touch_down, n_lift_off=self.n_lift_off,
                    n_gait_steps=self.n_gait_steps, failure_reason=self.failure_reason,
                    failure_t=self.failure_t)
        last = np.full((len(self), len(_layout.STEP)), np.nan)
        has = self.n_gait_steps > 0
        idx = np.minimum(self.n_gait_steps, _layout.STEP_RING) - 1
        last[has] = self.gait_rows[np.nonzero(has)[0], idx[has]]
        for j, name in enumerate(_layout.STEP):
            cols["last_" + name] = last[:, j]
        return pd.DataFrame(cols)


def _rows(x0):
    """x0 as a C-contiguous float (N, 8) array: real numbers only (no strings, complex or
    booleans), finite (`pdw.core.checks.real_array`)."""
    x0 = checks.unmasked("x0", x0)
    x = np.asarray(x0) if not isinstance(x0, (str, bytes)) else x0
    if isinstance(x, np.ndarray) and x.dtype.kind in "iuf" and x.ndim == 2 \
            and x.shape[1] == len(STATE) and not np.isfinite(x).all():
        r, c = np.argwhere(~np.isfinite(x))[0]
        raise InvalidInputError("x0 row %d, column %d (%s) must be finite, got %r"
                                % (r, c, STATE[c], x[r, c]))
    return checks.real_array("x0", x0, [(-1, len(STATE))], STATE)


def _flags(flags0, n):
    """(N, 2) intc flags from a pair or an (N, 2) array of integers in {0, 1} (no 0.9, no
    strings: `pdw.core.checks.flags`)."""
    try:
        rows = not isinstance(flags0, (str, bytes)) and np.shape(flags0) == (n, 2)
    except ValueError:                        # a ragged sequence
        rows = False
    f = None if rows else checks.flags("flags0", flags0, n)
    if f is None:                             # name the first bad row
        for r, row in enumerate(np.asarray(flags0)):
            try:
                checks.flags("flags0 row %d" % r, row)
            except InvalidInputError as e:
                raise InvalidInputError("%s (flags0 must be (2,) or (N, 2) = (%d, 2))"
                                        % (e, n)) from None
        f = checks.flags("flags0", flags0, n)
    if isinstance(f, tuple):
        f = np.tile(np.array(f, dtype=np.intc), (n, 1))
    return np.ascontiguousarray(f, dtype=np.intc)


def simulate_batch(x0: ArrayLike, t_end: float | None = None, dt: float | None = None,
                   *_positional, params: Params | Sequence[Params] | None = None,
                   variant: Literal["paper", "consistent"] = "paper", method: str | None = None,
                   integrator: _opt.Integrator | dict | None = None,
                   stop: _opt.Stop | dict | None = None, limits: _opt.Limits | dict | None = None,
                   flags0: ArrayLike = (0, 1), threads: int | None = None, lanes: int | None = None,
                   vector: bool = False, executor: Any = None, chunk_size: int | None = None,
                   record: Sequence[int] | None = None, record_every: int = 1,
                   progress: bool | Progress = False,
                   ground: Ground | dict | Sequence[Ground | dict | None] | None = None,
                   **_legacy) -> BatchResult:
    """Simulate N walkers at once: the result of `pdw.simulate` for each, without recording.

    Parameters
    ----------
    x0 : array (N, 8)
        Initial states, layout `pdw.STATE` [m, rad, m/s, rad/s].
    t_end, dt : float, optional
        End time and step [s], as `simulate` (n_steps = round(t_end/dt); defaults
        ``stop.t_end`` and ``integrator.dt``).
    params : Params or sequence of N Params, optional
        One parameter set for all walkers (default: the paper's) or one per walker.
    variant : {"paper", "consistent"}
    method : {"cdm", "verlet", "rk4", "dopri5", "rodas4"}, optional
        The short form of ``integrator=Integrator(method=...)`` (default "cdm"). "cdm" (the
        paper's central difference method, docs/model.md section 7) runs the lockstep lane
        loop; every other method of `pdw.METHODS` runs per lane through the scalar
        integrator's C, one (accepted) step per lane per round: each lane keeps its own time,
        step size, accept/reject and event location, and every walker is bitwise its
        `simulate` run (docs/ensemble.md). For the adaptive methods dt is the first step.
    integrator, stop, limits : pdw.Integrator, pdw.Stop, pdw.Limits, optional
        As `simulate` (``pdw.sim.options``): the tolerances and step budget (of each walker),
        the stop conditions, the fall and divergence bounds (``fall_hip_height`` and
        ``fall_depth`` default to 0.5 l and 0.25 l of each walker's parameters). A divergence
        is a status here (``"diverged"``), never an error (``limits.on_failure`` does not
        apply); the end-of-run checks of `simulate` (runaway, ``"no_steps"``) are applied to
        the final states (``pdw.sim.chunks.honest``).
    flags0 : (2,) or (N, 2) ints in {0, 1}
        Initial support flags of legs 1, 2.
    threads : int, optional
        Threads (GIL released), W lanes each, sharing the batch (each lane takes the next
        walker); default: os.cpu_count().
    lanes : int, optional
        Walkers per block advanced in lockstep by one thread (1 ... 64; default ``LANES`` = 16
        for cdm, ``LANES_OTHER`` = 8 for the other methods; a thread's share of a smaller batch
        takes fewer). Speed only: no walker's result depends on it, nor on ``threads``.
    vector : bool
        False (default): the scalar libm sin/cos, so that every walker is bitwise its
        `simulate` run. True (cdm and rodas4): the sin/cos of a block through glibc's vector
        routines (libmvec, within 4 ulp of libm's); flag switches on the step grid (cdm) and
        the adaptive step sequence (rodas4) turn those last bits into shifts of events, so final
        states then agree with `simulate` in outcome, not to 1e-12 (docs/ensemble.md). The
        results do not depend on the lane, thread or chunk a walker runs in. True permits the
        vector trig, it does not require it: a batch of at most 2 walkers
        (``pdw.core._batch.SERIAL_WALKERS``), too few for the lanes to pay, runs the scalar
        loop with libm's sin/cos, bitwise its `simulate` runs as with False.
    executor : concurrent.futures.Executor-like, optional
        Cut the batch into chunks of ``chunk_size`` consecutive walkers, each one task
        ``executor.submit`` (a thread or process pool, Dask's ``client.get_executor()``), the
        results put back in order: bitwise the unchunked batch. Each chunk runs ``threads``
        threads (give ``threads=1`` with a pool of one worker per core).
    chunk_size : int, optional
        Walkers per chunk (default: N / 8 with an executor); without an executor the chunks
        run one after the other in this thread.
    record : sequence of int, optional
        Walkers whose trajectories are wanted: they are run again through the **scalar**
        `pdw.simulate` in this call (the compiled lane loop records nothing), with
        ``record_every`` and the same inputs (forces and events recorded,
        ``on_failure="return"``), and returned in ``BatchResult.recorded`` as `Result` objects. On the
        bitwise path (``vector=False``) those runs are the lanes' arithmetic: same ``x_final``.
    record_every : int
        Sampling of the recorded walkers (every k-th step, >= 1).
    progress : bool or Progress
        A progress bar over the walkers (``pdw.core.progress``): True draws on stderr when it is
        a terminal, a `Progress` of the caller's gets N added to its total. The batch then
        runs in chunks (``chunk_size``, default N / 50 but at least one block per thread),
        bitwise the unchunked batch.
    ground : pdw.Ground, dict, or sequence of N (Ground, dict or None), optional
        The ground of all walkers, or of each (its own seed, step height, patch;
        docs/terrain.md). Walkers on a shaped or patched ground run the shaped-ground kernel
        through the per-lane scalar stages (``vector=False``), and so do the flat walkers of
        such a batch: every walker bitwise its `simulate` run. Status ``"off_ground"``: the
        walker left its ground's defined extent.
    **_legacy
        The keywords of before (``rtol=``, ``stop_steps=``, ``max_speed=``, ...) and the
        positional form: they work for one release, each with a `DeprecationWarning` naming
        its new spelling (``pdw.sim.options.LEGACY``).

    Returns
    -------
    BatchResult
        Per-walker arrays (status, x_final, t_final, failure, event counts, last gait steps).

    Raises
    ------
    KeyboardInterrupt
        On Ctrl-C, within a second (the lane loops poll every 512 lockstep steps, in every
        thread): ``.result`` is the partial `BatchResult`, whose unfinished walkers have status
        ``"interrupted"`` and their state when stopped (or at t = 0 if never started).
    """
    # run_chunked's chunks of a larger batch keep the lanes whatever their size (the vector
    # trig of a walker must not depend on the chunk it is in)
    small_serial = _legacy.pop("_small_serial", True)
    settled = _opt.settle(
        "simulate_batch", _positional, _legacy, integrator=integrator, stop=stop,
        limits=limits, method=method, dt=dt, t_end=t_end,
        keywords=dict(params=(params, None), variant=(variant, "paper"), method=(method, None),
                      flags0=(flags0, (0, 1)), threads=(threads, None), lanes=(lanes, None),
                      vector=(vector, False)))
    it, _, st, lim, method, dt, t_end, plain = settled
    _opt.no_record("simulate_batch", settled)
    params = plain.get("params", params)
    variant = plain.get("variant", variant)
    flags0 = plain.get("flags0", flags0)
    threads = plain.get("threads", threads)
    lanes = plain.get("lanes", lanes)
    if lanes is None:
        lanes = LANES if method == "cdm" else LANES_OTHER
    vector = plain.get("vector", vector)
    x = _rows(x0)
    n = len(x)
    if record is not None:
        check_record(record, n)              # before the run, not after it
    bar = None if progress is False or progress is None else \
        progress_bar(progress, n, "simulate_batch")
    if bar is not None and chunk_size is None:
        chunk_size = max(lanes * ((os.cpu_count() or 1) if threads is None else int(threads)),
                         math.ceil(n / 50), 1)
    if executor is not None or chunk_size is not None:
        it_run, st_run = settled.ran()
        kw = dict(x0=x, params=params, variant=variant, integrator=it_run, stop=st_run,
                  limits=lim, flags0=flags0, threads=threads, lanes=lanes, vector=vector,
                  record=record, record_every=record_every,
                  ground=ground if ground is None or isinstance(ground, (Ground, dict))
                  else _ground_list(ground, n))
        if chunk_size is None:
            chunk_size = max(1, math.ceil(n / 8))
        kw["_small_serial"] = small_serial and n <= _batch.SERIAL_WALKERS
        try:
            return run_chunked(simulate_batch, kw, executor, chunk_size, progress=bar)
        finally:
            if progress is True and bar is not None:
                bar.close()
    rtol, atol, h_max, event_tol, max_steps, check_step = (
        it.rtol, it.atol, it.h_max, it.event_tol, it.max_steps, it.check_step)
    stop_steps, periodic_steps, periodic_tol, stop_touch_down = (
        st.steps, st.periodic_k, st.periodic_tol, st.touch_down)
    fall_hip_height, fall_depth, max_speed = lim.fall_hip_height, lim.fall_depth, lim.max_speed
    t_end = _check_positive("t_end", t_end)
    dt = _check_positive("dt", dt)
    if dt > t_end:
        raise InvalidInputError("dt = %g must not exceed t_end = %g" % (dt, t_end))
    try:
        check_variant(variant)
    except ValueError as e:
        raise InvalidInputError(str(e)) from None
    if method not in METHODS:
        raise InvalidInputError("method must be one of %s, got %r" % (METHODS, method))
    if vector and method not in ("cdm", "rodas4"):
        raise InvalidInputError("vector=True (vector sin/cos) applies to methods 'cdm' and "
                                "'rodas4' only, got method %r" % (method,))
    adaptive = _method_info(method).adaptive
    rtol = _check_positive("rtol", rtol)
    atol = _check_positive("atol", atol)
    h_max = 0.0 if h_max is None else _check_positive("h_max", h_max)
    event_tol = _check_positive("event_tol", event_tol)
    if max_steps is None:
        budget = 10 ** 6 + int(2e6 * t_end) if adaptive else 0     # as simulate's
    else:
        budget = _check_count("max_steps", max_steps)
        if budget < 1:
            raise InvalidInputError("max_steps must be >= 1, got %d" % budget)
    plist = _plist(params, n, shared=True)      # one shared Params or a checked row each
    f0 = _flags(flags0, n)
    if not t_end / dt <= checks.MAX_COUNT:           # also inf (t_end near the largest float)
        raise InvalidInputError("t_end / dt = %g steps is too many (at most %d)"
                                % (t_end / dt, checks.MAX_COUNT))
    n_steps = int(round(t_end / dt))
    if not isinstance(vector, (bool, np.bool_)):
        raise InvalidInputError("vector must be True or False, got %r" % (vector,))
    stop_steps = _check_count("stop_steps", stop_steps)
    stop_touch_down = checks.leg_or_off("stop_touch_down", stop_touch_down)
    periodic_steps = _check_count("periodic_steps", periodic_steps)
    if periodic_steps == 1 or periodic_steps > _layout.STEP_RING:
        raise InvalidInputError("periodic_steps must be 0 (off) or in [2, %d], got %d"
                                % (_layout.STEP_RING, periodic_steps))
    periodic_tol = _check_positive("periodic_tol", periodic_tol)
    max_speed = _check_positive("max_speed", max_speed)
    lanes = _check_count("lanes", lanes)
    if not 1 <= lanes <= _batch.MAX_LANES:
        raise InvalidInputError("lanes must be in [1, %d], got %d" % (_batch.MAX_LANES, lanes))
    threads = (os.cpu_count() or 1) if threads is None else _check_count("threads", threads)
    if threads < 1:
        raise InvalidInputError("threads must be >= 1, got %d" % threads)
    k = kernel_index(variant, None)
    grounds = _ground_list(ground, n)
    if grounds is not None and vector:
        raise InvalidInputError("vector=True (vector sin/cos) does not apply to walkers on a "
                                "shaped or patched ground: give vector=False")
    cground = None if grounds is None else _compiled_grounds(grounds)
    distinct = {}
    for p in plist:
        if id(p) not in distinct:
            distinct[id(p)] = p
            for ps in _patched(p, grounds):
                _stepsize.check_step(dt, ps, method, variant, check_step)
    pvec = np.ascontiguousarray([parameter_vector(p) for p in plist])
    ls = np.array([p.l for p in plist], dtype=float)
    hip = np.broadcast_to(0.5 * ls if fall_hip_height is None
                          else checks.number("fall_hip_height", fall_hip_height), (n,))
    depth = np.broadcast_to(0.25 * ls if fall_depth is None
                            else _check_positive("fall_depth", fall_depth), (n,))
    hip = np.ascontiguousarray(hip, dtype=float)
    depth = np.ascontiguousarray(depth, dtype=float)
    out = _outputs(n)
    if not adaptive and max_steps is not None and n_steps > budget:
        raise InvalidInputError("t_end/dt = %d steps exceeds max_steps = %d: raise max_steps "
                                "or take a larger dt" % (n_steps, budget))
    t_stop = t_end if adaptive else n_steps * dt
    copts = _opt.c_options(it, st, lim, dt=dt, n_steps=n_steps, t_end=t_stop, h_max=h_max,
                           max_steps=budget, periodic_k=periodic_steps)
    opts = dict(method=METHODS.index(method), isa=_batch.ISAS[batch_isa()])
    if cground is not None:         # the per-lane scalar stages: bitwise the scalar runs
        opts.update(isa=-1, grounds=cground)
    if n:
        # a batch of at most SERIAL_WALKERS walkers runs the scalar loop also with vector=True
        # (libm's trig: bitwise simulate): the lanes would cost more than they save
        lane_trig = bool(vector) and not (small_serial and n <= _batch.SERIAL_WALKERS)
        # threads: at most one per chunk of walkers; lanes: for a thread's share of the
        # walkers, so that a block does not compute empty chunks (the lanes' count changes no
        # walker's result: each lane's arithmetic is its own)
        used = min(threads, -(-n // min(lanes, CHUNK)))
        width = lane_width(-(-n // used), lanes)
        args = (k, x, pvec, f0, hip, depth, copts, out, 0, n, width, lane_trig)
        # the threads share the batch: each lane of each takes the next walker from one
        # counter, so no lane idles while a walker waits (pdw_batch_take)
        shared = np.zeros(1, dtype=np.int_) if threads > 1 else None
        try:
            interrupt.thread_map(lambda _: _batch.run_range(*args, next_walker=shared, **opts),
                                 range(used), threads)
        except KeyboardInterrupt as e:
            # Ctrl-C: the walkers finished so far, the running ones as they are, the others at
            # their start; every unfinished one "interrupted"
            unstarted = np.isnan(out["t_final"])
            out["x_final"][unstarted] = x[unstarted]
            out["t_final"][unstarted] = 0.0
            e.result = _result(out, dt, t_stop, method, variant)  # type: ignore[attr-defined]
            raise
    res = _result(out, dt, t_stop, method, variant)
    honest(res, x, plist if len(plist) == n else plist[0])
    if record is not None:
        res.recorded = record_subset(
            res, record, record_every, x, plist if len(plist) == n else plist[0], f0,
            dict(zip(("integrator", "stop"), settled.ran()), variant=variant, limits=lim,
                 ground=grounds))
    return res


def _ground_list(ground, n):
    """None (every walker on flat ground) or a list of n `pdw.Ground` from ``ground``: None, one
    Ground (or [ground] dict) for all, or a sequence of n (Ground, dict or None each)."""
    if ground is None:
        return None
    if isinstance(ground, (Ground, dict)):
        g = Ground.coerce(ground)
        return None if g.is_flat else [g] * n
    if isinstance(ground, (str, bytes)):
        raise InvalidInputError("ground must be a pdw.Ground, a dict or a sequence of N = %d, got "
                                "%r" % (n, ground))
    try:
        gl = list(ground)
    except TypeError:
        raise InvalidInputError("ground must be a pdw.Ground, a dict or a sequence of N = %d, got "
                                "%s" % (n, type(ground).__name__)) from None
    if len(gl) != n:
        raise InvalidInputError("ground must be one Ground or a sequence of N = %d, got %d"
                                % (n, len(gl)))
    out = []
    for i, g in enumerate(gl):
        try:
            out.append(Ground.coerce(g))
        except InvalidInputError as e:
            raise InvalidInputError("ground[%d]: %s" % (i, e)) from None
    return None if all(g.is_flat for g in out) else out


def _compiled_grounds(grounds):
    """The compiled ground of each walker (None: flat), one per distinct Ground object."""
    made = {}
    out = []
    for g in grounds:
        if g.is_flat:
            out.append(None)
            continue
        if id(g) not in made:
            made[id(g)] = g.compiled(_batch.CGround)
        out.append(made[id(g)])
    return out


def _patched(p, grounds):
    """p and p with each distinct ground's patches (the step-size check)."""
    if grounds is None:
        return [p]
    out, seen = [p], set()
    for g in grounds:
        if id(g) not in seen and g.patches:
            seen.add(id(g))
            out += g.patched_params(p)[1:]
    return out


def _outputs(n):
    ring, nstep = _layout.STEP_RING, len(_layout.STEP)
    return {"status": np.zeros(n, np.intc), "stop_reason": np.zeros(n, np.intc),
            "flags_final": np.zeros((n, 2), np.intc), "x_final": np.zeros((n, len(STATE))),
            "t_final": np.full(n, np.nan), "n_steps": np.zeros(n, np.int_),
            "n_gait_steps": np.zeros(n, np.int_), "n_touch_down": np.zeros(n, np.int_),
            "n_lift_off": np.zeros(n, np.int_), "gait": np.zeros((n, ring, nstep)),
            "fail_reason": np.zeros(n, np.intc), "fail_leg": np.zeros(n, np.intc),
            "fail_t": np.zeros(n), "fail_x": np.zeros((n, len(STATE)))}


def _result(out, dt, t_end, method, variant):
    status = np.array([_STATUS[s] for s in out["status"]], dtype=object)
    off = (status == "fell") & (out["fail_reason"] == _layout.REASON.index("off_ground"))
    status[off] = "off_ground"          # the walker left its ground's defined extent
    stop = np.array([_STOP[r] if r else (s if s in ("fell", "diverged", "interrupted") else "t_end")
                     for r, s in zip(out["stop_reason"], status)], dtype=object)
    return BatchResult(
        status=status, stop_reason=stop, x_final=out["x_final"], t_final=out["t_final"],
        n_steps=out["n_steps"], flags_final=out["flags_final"],
        failure_reason=np.array([_REASONS[r] if r else "none" for r in out["fail_reason"]],
                                dtype=object),
        failure_t=out["fail_t"], failure_x=out["fail_x"], failure_leg=out["fail_leg"] + 1,
        n_touch_down=out["n_touch_down"], n_lift_off=out["n_lift_off"],
        n_gait_steps=out["n_gait_steps"], gait_rows=out["gait"], dt=dt, t_end=t_end,
        method=method, variant=variant)


# the BatchResult's file kind (pdw.sim.files owns the format)
_files.register(_files.BATCH_FORMAT, BatchResult, _files.batch_to_file,
                lambda arrays, meta: _files.batch_from_file(arrays, meta, BatchResult, Result,
                                                            Event))
