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
* Chunks over executors and recorded subsets: `pdw.sim.chunks`.
"""
from __future__ import annotations

import inspect
import os
from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache

import numpy as np

from ..core import _layout
from ..core.contact import Contact
from ..core.errors import InvalidInputError
from ..core.model import STATE
from .batch import BatchResult, _flags, _rows, simulate_batch
from .chunks import _plist, record_subset, run_chunked
from .simulation import _check_count, simulate


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
        return run_chunked(scalar_batch, kw, executor, chunk_size)
    f0 = _flags(flags0, n)
    plist = _plist(params, n)
    kw = dict(t_end=t_end, dt=dt, variant=variant, method=method, stop_steps=stop_steps,
              periodic_steps=periodic_steps, periodic_tol=periodic_tol,
              fall_hip_height=fall_hip_height, fall_depth=fall_depth, max_speed=max_speed,
              check_step=check_step, **options)

    def one(i):
        return simulate(x[i], params=plist[i], flags0=tuple(int(v) for v in f0[i]),
                        record_every=0, record_forces=False, record_events=True,
                        on_failure="return", **kw)

    nt = (os.cpu_count() or 1) if threads is None else _check_count("threads", threads)
    if nt < 1:
        raise InvalidInputError("threads must be >= 1, got %d" % nt)
    if nt == 1 or n <= 1:
        results = [one(i) for i in range(n)]
    else:
        with ThreadPoolExecutor(min(nt, n)) as ex:
            results = list(ex.map(one, range(n)))
    out = from_results(results, f0, dt=dt, t_end=t_end, method=method, variant=variant)
    out.engine = "scalar"
    if record is not None:
        out.recorded = record_subset(out, record, record_every, x, plist, f0, kw)
    return out


def _final_flags(r, f0):
    """Support flags at the end of a run: each leg's last event (touch-down: 1, lift-off: 0;
    the flags change only there), or its initial flag without an event."""
    flags = [int(f0[0]), int(f0[1])]
    for e in r.events:
        flags[e.leg - 1] = 1 if e.kind == "touch_down" else 0
    return flags


def from_results(results, flags0, *, dt, t_end, method, variant) -> BatchResult:
    """A `BatchResult` from a list of `pdw.Result` (one per walker, in order, with their
    events; ``flags0`` (N, 2) their initial flags)."""
    n = len(results)
    ring, nstep = _layout.STEP_RING, len(_layout.STEP)
    gait = np.full((n, ring, nstep), np.nan)
    nx = len(results[0].x_final) if n else len(STATE)   # the friction law's state (LuGre: 10)
    fx = np.full((n, nx), np.nan)
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
        x_final=np.array([r.x_final for r in results], dtype=float).reshape(n, nx),
        t_final=np.array([r.t_final for r in results], dtype=float),
        n_steps=ints(lambda r: r.n_steps),
        flags_final=np.array([_final_flags(r, f) for r, f in zip(results, flags0)],
                             dtype=np.intc).reshape(n, 2),
        failure_reason=reason, failure_t=ft, failure_x=fx, failure_leg=fleg,
        n_touch_down=ints(lambda r: r.event_counts.get("touch_down", 0)),
        n_lift_off=ints(lambda r: r.event_counts.get("lift_off", 0)),
        n_gait_steps=ints(lambda r: r.n_gait_steps), gait_rows=gait, dt=dt, t_end=t_end,
        method=method, variant=variant)


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
