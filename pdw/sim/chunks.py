"""Pieces of an ensemble that do not depend on the engine: chunks over ``concurrent.futures``
executors, recorded subsets, `pdw.simulate`'s end-of-run checks (docs/ensemble.md). Used by
`pdw.simulate_batch` and `pdw.sim.ensemble`.

* Chunks (`run_chunked`): the rows of ``x0`` are cut into consecutive chunks of ``chunk_size``
  walkers, each chunk one task ``executor.submit(_call, fn, kwargs)`` (module-level functions
  of plain data, so process pools and Dask's ``client.get_executor()`` take it); the results
  are put back in the order of ``x0``. Each walker's run does not depend on which chunk, lane
  or thread took it, so a chunked batch is bitwise the unchunked one.
* Recording (`record_subset`): the compiled lane loop records nothing, so the walkers listed in
  ``record`` are run again through the scalar `pdw.simulate` with ``record_every`` in the same
  call; on the bitwise path (cdm, ``vector=False``) that run is the very same arithmetic as the
  walker's lane (its ``x_final`` equals the batch's, tested).
"""
from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

from ..core import checks
from ..core.errors import InvalidInputError
from ..core.params import Params
from .options import Limits, Record
from .simulation import NO_STEP_PERIODS, RUNAWAY_ANGLE, RUNAWAY_HIP, _check_count, simulate

#: Keywords of `simulate_batch` that `pdw.simulate` does not take.
_NOT_SIMULATE = ("x0", "params", "flags0", "threads", "lanes", "vector", "executor",
                 "chunk_size", "record", "record_every")


def _plist(params, n, shared=False):
    """params (None, one Params, or a sequence of n) as a list of Params, checked: n entries,
    or one entry for one shared Params when ``shared``."""
    if params is None or isinstance(params, Params):
        return [Params.paper() if params is None else params] * (1 if shared else n)
    plist = None
    if not isinstance(params, (str, bytes, dict)):
        try:
            plist = list(params)
        except TypeError:
            pass
    if plist is None:
        raise InvalidInputError("params must be a pdw.Params or a sequence of N = %d Params, "
                                "got %r" % (n, params))
    if len(plist) != n:
        raise InvalidInputError("params must be one Params or a sequence of N = %d, got %d"
                                % (n, len(plist)))
    for i, p in enumerate(plist):
        if not isinstance(p, Params):
            raise InvalidInputError("params row %d must be a pdw.Params, got %s"
                                    % (i, type(p).__name__))
    return plist


def honest(b, x0, params):
    """Apply `pdw.simulate`'s end-of-run checks to a batch (in place; returns it): a walker
    that "walked" to its end with its hip more than RUNAWAY_HIP l above its start or a leg
    turned past RUNAWAY_ANGLE is ``"diverged"`` (the scalar run without recording checks its
    final state only, as here); one without any touch-down in NO_STEP_PERIODS pendulum
    periods or more is ``"no_steps"``."""
    x0 = np.asarray(x0, dtype=float)
    plist = _plist(params, len(b))
    for i in np.nonzero(b.status == "walked")[0]:
        p, x = plist[i], b.x_final[i]
        reason = None
        if x[1] > x0[i, 1] + RUNAWAY_HIP * p.l:
            reason = ("runaway: the hip rose to y_o = %.4g m, more than %g l above its start "
                      "(airborne): not walking" % (x[1], RUNAWAY_HIP))
        elif (np.abs(x[2:4]) > RUNAWAY_ANGLE).any():
            reason = ("runaway: a leg turned past %.3g rad (theta1, theta2 = %.4g, %.4g): not "
                      "walking" % (RUNAWAY_ANGLE, x[2], x[3]))
        if reason is not None:
            b.status[i] = b.stop_reason[i] = "diverged"
            b.failure_reason[i], b.failure_t[i], b.failure_leg[i] = reason, b.t_final[i], 0
            b.failure_x[i] = x
            continue
        period = 2 * math.pi * math.sqrt(p.l / p.g) if p.g > 0 else math.inf
        if b.n_touch_down[i] == 0 and b.t_final[i] >= NO_STEP_PERIODS * period:
            b.status[i] = b.stop_reason[i] = "no_steps"
    return b


# --- chunks over executors --------------------------------------------------------------------

def _call(fn, kw):
    """One chunk: ``fn(**kw)`` (module level, so that process pools and Dask can run it)."""
    return fn(**kw)


def concat(parts):
    """Concatenate `BatchResult`s (walkers in the order of ``parts``); ``recorded`` keys are
    shifted to the concatenated numbering."""
    parts = list(parts)
    if not parts:
        raise InvalidInputError("concat needs at least one BatchResult")
    arrays = {}
    for name in ("status", "stop_reason", "x_final", "t_final", "n_steps", "flags_final",
                 "failure_reason", "failure_t", "failure_x", "failure_leg", "n_touch_down",
                 "n_lift_off", "n_gait_steps", "gait_rows"):
        arrays[name] = np.concatenate([getattr(p, name) for p in parts])
    recorded, off = {}, 0
    for p in parts:
        recorded.update({off + k: v for k, v in p.recorded.items()})
        off += len(p)
    p0 = parts[0]
    return type(p0)(**arrays, dt=p0.dt, t_end=p0.t_end, method=p0.method, variant=p0.variant,
                    recorded=recorded, engine=p0.engine)


def run_chunked(fn, kw, executor, chunk_size, progress=None):
    """``fn(**kw)`` (`simulate_batch` or `pdw.sim.ensemble.scalar_batch`; ``kw`` its keyword
    arguments, ``x0`` (N, 8) validated) in chunks of ``chunk_size`` consecutive walkers over
    ``executor`` (anything with ``submit(fn, *args) -> Future``; None: one after the other in
    this thread), reassembled in order. Per-walker inputs (``params`` as a sequence, ``flags0``
    (N, 2), ``record``) are cut with the chunk. ``progress``: a `pdw.core.progress.Progress`
    (updated by walkers) or None."""
    x = kw["x0"]
    n = len(x)
    size = _check_count("chunk_size", chunk_size) if chunk_size is not None else max(n, 1)
    if size < 1:
        raise InvalidInputError("chunk_size must be >= 1, got %d" % size)
    params, flags0 = kw.get("params"), np.asarray(kw.get("flags0", (0, 1)))
    per_walker_params = not (params is None or isinstance(params, Params))
    if per_walker_params:
        params = _plist(params, n)
    record = [] if kw.get("record") is None else check_record(kw["record"], n)
    tasks = []
    for lo in range(0, max(n, 1), size):
        hi = min(n, lo + size)
        c = dict(kw, x0=x[lo:hi])
        if per_walker_params:
            c["params"] = list(params[lo:hi])
        if flags0.ndim == 2:
            c["flags0"] = flags0[lo:hi]
        if isinstance(kw.get("ground"), (list, tuple)):     # one Ground per walker
            c["ground"] = list(kw["ground"][lo:hi])
        if "record" in kw:
            c["record"] = [i - lo for i in record if lo <= i < hi] or None
        tasks.append(c)
    if executor is None:
        parts = []
        for c in tasks:
            parts.append(fn(**c))
            if progress is not None:
                progress.update(len(c["x0"]))
    else:
        futs = [executor.submit(_call, fn, c) for c in tasks]
        parts = []
        for c, f in zip(tasks, futs):
            parts.append(f.result())
            if progress is not None:
                progress.update(len(c["x0"]))
    return concat(parts)


# --- recorded subsets ------------------------------------------------------------------------

def check_record(record, n) -> list:
    """The sorted distinct walker indices of ``record``: a sequence of integers in [0, n) (no
    1.5, True, "1" or a string of digits: `pdw.core.checks.count`); else `InvalidInputError`
    naming the entry."""
    if isinstance(record, (str, bytes, dict)) or not isinstance(record, Iterable) \
            or (isinstance(record, np.ndarray) and record.ndim != 1):
        raise InvalidInputError("record must be a sequence of walker indices (integers in "
                                "[0, %d)), got %r" % (n, record))
    items = list(record)
    if items and n == 0:
        raise InvalidInputError("record must list walker indices in [0, 0), got %r" % (items[0],))
    return sorted(set(checks.count("record[%d]" % j, i, lo=0, hi=n - 1)
                      for j, i in enumerate(items)))


def record_subset(b, record, record_every, x0, params, flags0, options) -> dict:
    """``{i: Result}``: walkers ``record`` run again through `pdw.simulate` with
    ``record_every`` (states, flags, forces and events recorded, ``on_failure="return"``),
    with the batch's other inputs ``options`` (its keywords that `pdw.simulate` also takes:
    variant, the option objects ``integrator``, ``stop``, ``limits``, features, contact)."""
    n = len(b)
    idx = check_record(record, n)
    every = _check_count("record_every", record_every)
    if every < 1:
        raise InvalidInputError("record_every must be >= 1 for recorded walkers, got %d" % every)
    plist = _plist(params, n)
    f0 = np.broadcast_to(np.asarray(flags0), (n, 2))
    kw = {k: v for k, v in options.items() if k not in _NOT_SIMULATE and k != "ground"}
    kw["limits"] = (kw.get("limits") or Limits()).replace(on_failure="return")
    kw["record"] = Record(every=every)
    grounds = options.get("ground")         # None, or each walker's Ground (simulate_batch)
    return {i: simulate(x0[i], params=plist[i], flags0=(int(f0[i][0]), int(f0[i][1])),
                        **(kw if grounds is None else dict(kw, ground=grounds[i])))
            for i in idx}
