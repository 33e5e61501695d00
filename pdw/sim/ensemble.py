"""Ensembles around the batch engine: the scalar path for the methods it refuses, chunks over
``concurrent.futures`` executors, and recorded subsets (docs/ensemble.md).

* `supports(method, variant)`: does `simulate_batch` accept this method? Asked of
  `simulate_batch` itself (an empty batch), so a method that the compiled engine learns later
  (rodas4 per lane) is used as soon as it is there, with no change here.
* `scalar_batch`: the same inputs and the same `BatchResult`, computed walker by walker with
  `pdw.simulate` on a thread pool (any method, any `simulate` option). It is the fallback of
  `simulate_many` and the reference the batch engine is tested against.
* `simulate_many`: `simulate_batch` when the engine supports the method, `scalar_batch`
  otherwise; both take ``executor``/``chunk_size`` and ``record``.
* Chunks (`run_chunked`): the rows of ``x0`` are cut into consecutive chunks of ``chunk_size``
  walkers, each chunk one task ``executor.submit(_run_chunk, kwargs)`` (a module-level
  function of plain data, so process pools and Dask's ``client.get_executor()`` take it); the
  results are put back in the order of ``x0``. Each walker's run does not depend on which chunk,
  lane or thread took it, so a chunked batch is bitwise the unchunked one.
* Recording (`record_subset`): the compiled lane loop records nothing, so the walkers listed in
  ``record`` are run again through the scalar `pdw.simulate` with ``record_every`` in the same
  call; on the bitwise path (cdm, ``vector=False``) that run is the very same arithmetic as the
  walker's lane (its ``x_final`` equals the batch's, tested).
"""
from __future__ import annotations

import inspect
import math
import os
from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache

import numpy as np

from ..core import _layout
from ..core.contact import Contact
from ..core.errors import InvalidInputError
from ..core.model import STATE
from ..core.params import Params
from .batch import BatchResult, _flags, _rows, simulate_batch
from .simulation import NO_STEP_PERIODS, RUNAWAY_ANGLE, RUNAWAY_HIP, _check_count, simulate

#: Keywords of `simulate_batch` that `pdw.simulate` does not take.
_NOT_SIMULATE = ("x0", "params", "flags0", "threads", "lanes", "vector", "executor",
                 "chunk_size", "record", "record_every")


@lru_cache(maxsize=None)
def supports(method, variant="paper") -> bool:
    """True if `simulate_batch` runs ``method`` (it refuses the others with
    `InvalidInputError`); asked with an empty batch, so nothing is simulated."""
    try:
        simulate_batch(np.zeros((0, len(STATE))), t_end=1.0, dt=1e-4, variant=variant,
                       method=method, check_step="off")
    except InvalidInputError:
        return False
    return True


def plain_model(features=None, contact=None) -> bool:
    """True for the model the batch engine runs: every force element, the default contact
    laws (None or a default `pdw.Contact`)."""
    if features is not None and set(features) != set(_layout.FEATURES):
        return False
    return contact is None or Contact.coerce(contact).is_default


def _plist(params, n):
    if params is None or isinstance(params, Params):
        return [Params.paper() if params is None else params] * n
    plist = list(params)
    if len(plist) != n:
        raise InvalidInputError("params must be one Params or a sequence of N = %d, got %d"
                                % (n, len(plist)))
    for i, p in enumerate(plist):
        if not isinstance(p, Params):
            raise InvalidInputError("params row %d must be a pdw.Params, got %s"
                                    % (i, type(p).__name__))
    return plist


def scalar_batch(x0, t_end=3.5, dt=1e-4, params=None, variant="paper", method="cdm",
                 flags0=(0, 1), threads=None, stop_steps=0, periodic_steps=0, periodic_tol=1e-3,
                 fall_hip_height=None, fall_depth=None, max_speed=1e3, check_step="warn", *,
                 executor=None, chunk_size=None, record=None, record_every=1,
                 **options) -> BatchResult:
    """`simulate_batch`'s result computed walker by walker with `pdw.simulate`.

    Parameters are those of `simulate_batch` (``lanes`` and ``vector`` do not apply); any
    further ``options`` of `pdw.simulate` (``rtol``, ``atol``, ``event_tol``, ``h_max``,
    ``features``, ``contact``) are passed on. ``threads`` (default os.cpu_count()) run walkers
    in parallel (the compiled loop releases the GIL). Any method of `pdw.METHODS`.
    """
    x = _rows(x0)
    n = len(x)
    if executor is not None or chunk_size is not None:
        kw = dict(x0=x, t_end=t_end, dt=dt, params=params, variant=variant, method=method,
                  flags0=flags0, threads=threads, stop_steps=stop_steps,
                  periodic_steps=periodic_steps, periodic_tol=periodic_tol,
                  fall_hip_height=fall_hip_height, fall_depth=fall_depth, max_speed=max_speed,
                  check_step=check_step, record=record, record_every=record_every, **options)
        return run_chunked(kw, executor, chunk_size, scalar=True)
    f0 = _flags(flags0, n)
    plist = _plist(params, n)
    kw = dict(t_end=t_end, dt=dt, variant=variant, method=method, stop_steps=stop_steps,
              periodic_steps=periodic_steps, periodic_tol=periodic_tol,
              fall_hip_height=fall_hip_height, fall_depth=fall_depth, max_speed=max_speed,
              check_step=check_step, **options)

    def one(i):
        return simulate(x[i], params=plist[i], flags0=tuple(int(v) for v in f0[i]),
                        record_every=0, record_forces=False, record_events=False,
                        on_failure="return", **kw)

    nt = (os.cpu_count() or 1) if threads is None else _check_count("threads", threads)
    if nt < 1:
        raise InvalidInputError("threads must be >= 1, got %d" % nt)
    if nt == 1 or n <= 1:
        results = [one(i) for i in range(n)]
    else:
        with ThreadPoolExecutor(min(nt, n)) as ex:
            results = list(ex.map(one, range(n)))
    out = from_results(results, dt=dt, t_end=t_end, method=method, variant=variant)
    out.engine = "scalar"
    if record is not None:
        out.recorded = record_subset(out, record, record_every, x, plist, f0, kw)
    return out


def from_results(results, *, dt, t_end, method, variant) -> BatchResult:
    """A `BatchResult` from a list of `pdw.Result` (one per walker, in order)."""
    n = len(results)
    ring, nstep = _layout.STEP_RING, len(_layout.STEP)
    gait = np.full((n, ring, nstep), np.nan)
    fx = np.full((n, len(STATE)), np.nan)
    ft = np.full(n, np.nan)
    fleg = np.zeros(n, dtype=np.intc)
    reason = np.array(["none"] * n, dtype=object)
    for i, r in enumerate(results):
        k = min(r.n_gait_steps, ring)
        if k:
            gait[i, :k] = np.column_stack([np.asarray(r.gait[f], float)[:k] - (f == "leg")
                                           for f in _layout.STEP])
        if r.failure:
            reason[i] = r.failure["reason"]
            ft[i] = r.failure["t"]
            fx[i] = r.failure["x"]
            fleg[i] = r.failure["leg"] or 0
    ints = lambda key: np.array([key(r) for r in results], dtype=np.int_)  # noqa: E731
    return BatchResult(
        status=np.array([r.status for r in results], dtype=object),
        stop_reason=np.array([r.stop_reason for r in results], dtype=object),
        x_final=np.array([r.x_final for r in results], dtype=float).reshape(n, len(STATE)),
        t_final=np.array([r.t_final for r in results], dtype=float),
        n_steps=ints(lambda r: r.n_steps),
        flags_final=np.array([r.flags_final for r in results], dtype=np.intc).reshape(n, 2),
        failure_reason=reason, failure_t=ft, failure_x=fx, failure_leg=fleg,
        n_touch_down=ints(lambda r: r.event_counts.get("touch_down", 0)),
        n_lift_off=ints(lambda r: r.event_counts.get("lift_off", 0)),
        n_gait_steps=ints(lambda r: r.n_gait_steps), gait_rows=gait, dt=dt, t_end=t_end,
        method=method, variant=variant)


def honest(b: BatchResult, x0, params) -> BatchResult:
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


# --- chunks over executors -------------------------------------------------------------------

def _run_chunk(kw):
    """One chunk (module level, so that process pools and Dask can run it)."""
    scalar = kw.pop("_scalar", False)
    return (scalar_batch if scalar else simulate_batch)(**kw)


def concat(parts) -> BatchResult:
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
    return BatchResult(**arrays, dt=p0.dt, t_end=p0.t_end, method=p0.method,
                       variant=p0.variant, recorded=recorded, engine=p0.engine)


def run_chunked(kw, executor, chunk_size, scalar=False, progress=None) -> BatchResult:
    """Split the batch ``kw`` (the keyword arguments of `simulate_batch` / `scalar_batch`,
    ``x0`` (N, 8) validated) into chunks of ``chunk_size`` walkers over ``executor`` (anything
    with ``submit(fn, arg) -> Future``; None: this thread), reassembled in order. Per-walker
    inputs (``params`` as a sequence, ``flags0`` (N, 2), ``record``) are cut with the chunk.
    ``progress``: a `pdw.core.progress.Progress` (updated by walkers) or None."""
    x = kw["x0"]
    n = len(x)
    size = max(1, _check_count("chunk_size", chunk_size)) if chunk_size is not None else n
    params, flags0 = kw.get("params"), np.asarray(kw.get("flags0", (0, 1)))
    per_walker_params = not (params is None or isinstance(params, Params))
    record = sorted(set(int(i) for i in kw.get("record") or ()))
    tasks = []
    for lo in range(0, max(n, 1), size):
        hi = min(n, lo + size)
        c = dict(kw, x0=x[lo:hi])
        if per_walker_params:
            c["params"] = list(params[lo:hi])
        if flags0.ndim == 2:
            c["flags0"] = flags0[lo:hi]
        if "record" in kw:
            c["record"] = [i - lo for i in record if lo <= i < hi] or None
        c["_scalar"] = scalar
        tasks.append(c)
    if executor is None:
        parts = []
        for c in tasks:
            parts.append(_run_chunk(c))
            if progress is not None:
                progress.update(len(c["x0"]))
    else:
        futs = [executor.submit(_run_chunk, c) for c in tasks]
        parts = []
        for c, f in zip(tasks, futs):
            parts.append(f.result())
            if progress is not None:
                progress.update(len(c["x0"]))
    return concat(parts)


# --- recorded subsets ------------------------------------------------------------------------

def record_subset(b: BatchResult, record, record_every, x0, params, flags0, options) -> dict:
    """``{i: Result}``: walkers ``record`` run again through `pdw.simulate` with
    ``record_every`` (states, flags, forces and events recorded, ``on_failure="return"``),
    with the batch's other inputs ``options`` (its keywords that `pdw.simulate` also takes)."""
    n = len(b)
    idx = sorted(set(int(i) for i in record))
    bad = [i for i in idx if not 0 <= i < n]
    if bad:
        raise InvalidInputError("record must list walker indices in [0, %d), got %d"
                                % (n, bad[0]))
    every = _check_count("record_every", record_every)
    if every < 1:
        raise InvalidInputError("record_every must be >= 1 for recorded walkers, got %d" % every)
    plist = _plist(params, n)
    f0 = _flags(flags0, n)
    kw = {k: v for k, v in options.items() if k not in _NOT_SIMULATE}
    return {i: simulate(x0[i], params=plist[i], flags0=tuple(int(v) for v in f0[i]),
                        record_every=every, on_failure="return", **kw) for i in idx}


def simulate_many(x0, t_end=3.5, dt=1e-4, params=None, variant="paper", method="cdm",
                  flags0=(0, 1), threads=None, *, executor=None, chunk_size=None, record=None,
                  record_every=1, **options) -> BatchResult:
    """N walkers: the batch engine when it runs ``method``, the scalar path otherwise.

    Parameters
    ----------
    x0, t_end, dt, params, variant, method, flags0, threads
        As `simulate_batch` (``method``: any of `pdw.METHODS`).
    executor, chunk_size, record, record_every
        As `simulate_batch`.
    options
        Further options: those of `simulate_batch` (stop conditions, fall thresholds,
        ``lanes``, ``vector``, ...) and, for the scalar path, any `pdw.simulate` option
        (``rtol``, ``atol``, ``event_tol``, ``h_max``, ``features``, ``contact``). A non-default
        force set or contact law also selects the scalar path (the batch engine has neither).

    Returns
    -------
    BatchResult
        The same result either way; its ``engine`` says which path ran (``"batch"`` or
        ``"scalar"``).
    """
    batch_only = {k: options.pop(k) for k in ("lanes", "vector") if k in options}
    scalar_only = {k: options.pop(k) for k in ("rtol", "atol", "event_tol", "h_max", "features",
                                               "contact") if k in options}
    plain = plain_model(scalar_only.get("features"), scalar_only.get("contact"))
    kw = dict(x0=x0, t_end=t_end, dt=dt, params=params, variant=variant, method=method,
              flags0=flags0, threads=threads, executor=executor, chunk_size=chunk_size,
              record=record, record_every=record_every, **options)
    if plain and supports(method, variant):
        accepted = inspect.signature(simulate_batch).parameters
        out = simulate_batch(**kw, **batch_only,
                             **{k: v for k, v in scalar_only.items() if k in accepted})
        out.engine = "batch"
    else:
        out = scalar_batch(**kw, **scalar_only)
        out.engine = "scalar"
    return out
