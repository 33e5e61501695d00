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

import os
from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache
from typing import Any, Iterable, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ..core import _layout
from ..core.contact import Contact
from ..core.errors import InvalidInputError
from ..core.model import STATE
from ..core.params import Params
from ..core.progress import Progress
from . import options as _opt
from .batch import BatchResult, _flags, _rows, simulate_batch
from .chunks import _plist, record_subset, run_chunked
from .simulation import _check_count, simulate

_EVENTS_ONLY = _opt.Record(every=0, forces=False, events=True)


@lru_cache(maxsize=None)
def supports(method, variant="paper") -> bool:
    """True if `simulate_batch` runs ``method`` (it refuses the others with
    `InvalidInputError`); asked with an empty batch, so nothing is simulated."""
    try:
        simulate_batch(np.zeros((0, len(STATE))), t_end=1.0, variant=variant,
                       integrator=_opt.Integrator(method=method, dt=1e-4, check_step="off"))
    except InvalidInputError:
        return False
    return True


def plain_model(features=None, contact=None) -> bool:
    """True for the model the batch engine runs: every force element, the default contact
    laws (None or a default `pdw.Contact`)."""
    if features is not None and set(features) != set(_layout.FEATURES):
        return False
    return contact is None or Contact.coerce(contact).is_default


def scalar_batch(x0: ArrayLike, t_end: float | None = None, dt: float | None = None,
                 *_positional, params: Params | Sequence[Params] | None = None,
                 variant: str = "paper", method: str | None = None,
                 integrator: _opt.Integrator | dict | None = None,
                 stop: _opt.Stop | dict | None = None, limits: _opt.Limits | dict | None = None,
                 flags0: ArrayLike = (0, 1), threads: int | None = None, executor: Any = None,
                 chunk_size: int | None = None, record: Sequence[int] | None = None,
                 record_every: int = 1, features: Iterable[str] | None = None,
                 contact: Contact | dict | str | None = None, **_legacy) -> BatchResult:
    """`simulate_batch`'s result computed walker by walker with `pdw.simulate`.

    Parameters are those of `simulate_batch` (``lanes`` and ``vector`` do not apply), and
    `pdw.simulate`'s ``features`` and ``contact``. ``threads`` (default os.cpu_count()) run
    walkers in parallel (the compiled loop releases the GIL). Any method of `pdw.METHODS`.
    The keywords of before (``rtol=``, ``stop_steps=``, ...) work for one release, warning
    (``pdw.sim.options.LEGACY``).
    """
    settled = _opt.settle(
        "scalar_batch", _positional, _legacy, integrator=integrator, stop=stop, limits=limits,
        method=method, dt=dt, t_end=t_end,
        keywords=dict(params=(params, None), variant=(variant, "paper"), method=(method, None),
                      flags0=(flags0, (0, 1)), threads=(threads, None)))
    _opt.no_record("scalar_batch", settled)
    plain = settled.plain
    params = plain.get("params", params)
    variant = plain.get("variant", variant)
    flags0 = plain.get("flags0", flags0)
    threads = plain.get("threads", threads)
    it, st = settled.ran()
    x = _rows(x0)
    n = len(x)
    if executor is not None or chunk_size is not None:
        kw = dict(x0=x, params=params, variant=variant, integrator=it, stop=st,
                  limits=settled.limits, flags0=flags0, threads=threads, record=record,
                  record_every=record_every, features=features, contact=contact)
        return run_chunked(scalar_batch, kw, executor, chunk_size)
    f0 = _flags(flags0, n)
    plist = _plist(params, n)
    kw = dict(variant=variant, integrator=it, stop=st, limits=settled.limits,
              features=features, contact=contact)
    returned = settled.limits.replace(on_failure="return")

    def one(i):
        return simulate(x[i], params=plist[i], flags0=tuple(int(v) for v in f0[i]),
                        record=_EVENTS_ONLY, **{**kw, "limits": returned})

    nt = (os.cpu_count() or 1) if threads is None else _check_count("threads", threads)
    if nt < 1:
        raise InvalidInputError("threads must be >= 1, got %d" % nt)
    if nt == 1 or n <= 1:
        results = [one(i) for i in range(n)]
    else:
        with ThreadPoolExecutor(min(nt, n)) as ex:
            results = list(ex.map(one, range(n)))
    out = from_results(results, f0, dt=settled.dt, t_end=settled.t_end, method=settled.method,
                       variant=variant)
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


def simulate_many(x0: ArrayLike, t_end: float | None = None, dt: float | None = None,
                  *_positional, params: Params | Sequence[Params] | None = None,
                  variant: str = "paper", method: str | None = None,
                  integrator: _opt.Integrator | dict | None = None,
                  stop: _opt.Stop | dict | None = None, limits: _opt.Limits | dict | None = None,
                  flags0: ArrayLike = (0, 1), threads: int | None = None,
                  lanes: int | None = None, vector: bool | None = None, executor: Any = None,
                  chunk_size: int | None = None, record: Sequence[int] | None = None,
                  record_every: int = 1, features: Iterable[str] | None = None,
                  contact: Contact | dict | str | None = None,
                  progress: bool | Progress = False, **_legacy) -> BatchResult:
    """N walkers: the batch engine when it runs ``method``, the scalar path otherwise.

    Parameters
    ----------
    x0, t_end, dt, params, variant, method, integrator, stop, limits, flags0, threads
        As `simulate_batch` (``method``: any of `pdw.METHODS`).
    lanes, vector, progress
        As `simulate_batch` (the batch engine only).
    executor, chunk_size, record, record_every
        As `simulate_batch`.
    features, contact
        As `pdw.simulate`. A non-default force set or contact law selects the scalar path
        (the batch engine has neither).
    **_legacy
        The keywords of before (``rtol=``, ``stop_steps=``, ...) work for one release, warning
        (``pdw.sim.options.LEGACY``).

    Returns
    -------
    BatchResult
        The same result either way; its ``engine`` says which path ran (``"batch"`` or
        ``"scalar"``).
    """
    settled = _opt.settle(
        "simulate_many", _positional, _legacy, integrator=integrator, stop=stop,
        limits=limits, method=method, dt=dt, t_end=t_end,
        keywords=dict(params=(params, None), variant=(variant, "paper"), method=(method, None),
                      flags0=(flags0, (0, 1)), threads=(threads, None)))
    _opt.no_record("simulate_many", settled)
    plain = settled.plain
    it, st = settled.ran()
    kw = dict(params=plain.get("params", params), variant=plain.get("variant", variant),
              integrator=it, stop=st, limits=settled.limits,
              flags0=plain.get("flags0", flags0), threads=plain.get("threads", threads),
              executor=executor, chunk_size=chunk_size, record=record,
              record_every=record_every)
    if plain_model(features, contact) and supports(settled.method, kw["variant"]):
        batch_only: dict[str, Any] = {k: v for k, v in (("lanes", lanes), ("vector", vector))
                                      if v is not None}
        out = simulate_batch(x0, **kw, **batch_only, progress=progress)
        out.engine = "batch"
    else:
        out = scalar_batch(x0, **kw, features=features, contact=contact)
        out.engine = "scalar"
    return out
