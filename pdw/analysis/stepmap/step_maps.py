"""Many touch-down step maps at once (docs/ensemble.md, "Where the engine is used"): the finite
differences of `pdw.limit_cycle.jacobian` (so `find_gait` and `floquet`) and of continuation
(`pdw.analysis.stepmap.gait_maps`) through `compose_points`, `pdw.cell_mapping.cell_map`'s images
through `map_images`: through the ensemble engine (`images`) where it takes them, else on a
thread pool of scalar steps (`map_batch`, `_compose`).

One step of the map (`pdw.limit_cycle.step`) is a run from the section point's state with
flags (1, 1) until leg 1's next touch-down, whose located state gives z'. Here every point is a
walker of one `pdw.simulate_batch` call with ``stop_touch_down=1`` (the run ends at that event,
``x_final`` its state) and the first time window of `step` (`first_window`), the same method,
tolerances and first step: the same run as `step`'s, so z' is **bitwise** the scalar map's
(tested). rodas4, the default of these users, runs in the engine's structure-of-arrays lanes.
A point whose batch run did not end at leg 1's touch-down inside that window with leg 2 still
on the ground (a fall, a divergence, no touch-down yet, a flight phase, a start that is not a
valid state) gets ``None``: the caller runs `step` for it, which says what happened (and runs the
second window). Fixed-step methods (the section is interpolated between samples), period-n maps
and the models the engine does not run (a non-default force set or contact law) stay with the
scalar `step` (`batchable`).
"""
from __future__ import annotations

import inspect
import math
import os

import numpy as np

from ...core import interrupt
from ...core.contact import Contact
from ...core.errors import InvalidInputError
from ...core.integrators import INTEGRATORS, METHODS
from ...core.progress import progress_bar
from ...sim.batch import simulate_batch
from ...sim.ensemble import plain_model, supports
from ...sim.options import Integrator, Stop
from . import section as _section
from .poincare import expected_end, step

#: Lanes per block of the engine for step maps (a finite-difference Jacobian is 12 walkers)
MAX_LANES = 16


def first_window(t_hint, t_max, dt):
    """The end time of `pdw.limit_cycle.step`'s first run [s]: `expected_end`, at most
    ``t_max``, at least 10 dt."""
    return max(min(expected_end(t_hint), t_max), 10 * dt)


def batchable(method, period=1, options=None) -> bool:
    """Can the ensemble engine take these step maps bitwise? An adaptive method the engine runs
    (rodas4, dopri5: the event is located, the section state is the event's), period 1, the
    engine's model (default force set and contact laws), nothing recorded."""
    opts = options or {}
    if method not in METHODS or not INTEGRATORS[method].adaptive or period != 1:
        return False
    if opts.get("record") or not plain_model(None, opts.get("contact")):
        return False
    return supports(method)


def images(points, params, variant, method, options, *, threads=1):
    """z' = P(z) of every point through one `simulate_batch` call.

    Parameters
    ----------
    points : sequence of array (6,)
        Section points (`pdw.limit_cycle.SECTION`; the engine's laws have no extra coordinate).
    params : Params or sequence of Params
        One parameter set, or one per point.
    variant, method : str
    options : dict
        `pdw.limit_cycle.step`'s options (``dt``, ``rtol``, ``atol``, ``event_tol``, ``t_max``,
        ``t_hint``); those not given take `step`'s defaults.
    threads : int
        Threads of the engine.

    Returns
    -------
    list of (array (6,) or None)
        z', or None where `step` must decide (module docstring).
    """
    n = len(points)
    if n == 0:
        return []
    options = {**_step_defaults(), **options}
    plist = list(params) if isinstance(params, (list, tuple)) else [params] * n
    law = Contact.coerce(options.get("contact"))
    x0, ok = np.zeros((n, 8)), np.zeros(n, dtype=bool)
    for i, (z, p) in enumerate(zip(points, plist)):
        try:
            x0[i], v_in0 = _section.start(z, p, law, variant)
        except InvalidInputError:
            continue
        ok[i] = v_in0 is None           # the engine's laws hold no approach speeds
    out = [None] * n
    idx = np.flatnonzero(ok)
    if len(idx) == 0:
        return out
    dt = options["dt"]
    threads = max(1, int(threads))
    lanes = min(MAX_LANES, max(8, math.ceil(len(idx) / threads)))
    b = simulate_batch(x0[idx], first_window(options.get("t_hint"), options["t_max"], dt), dt,
                       params=[plist[i] for i in idx], variant=variant, flags0=(1, 1),
                       threads=threads, lanes=lanes,
                       integrator=Integrator(method=method, rtol=options["rtol"],
                                             atol=options["atol"],
                                             event_tol=options["event_tol"]),
                       stop=Stop(touch_down=1))
    for j, i in enumerate(idx):
        if b.stop_reason[j] == "touch_down" and b.flags_final[j, 1] == 1:
            out[i] = _section.section_coordinates(b.x_final[j], 1, law, None)
    return out


# --- the users' entry points: many maps, on threads or through the engine -------------------

def _workers(workers):
    return max(1, int(workers if workers is not None else (os.cpu_count() or 1)))


def map_images(Z, params=None, variant="paper", method="rodas4", *, workers=None,
               progress=False, chunk_size=2048, **options):
    """(Z', status) of every row of Z (N, len(z)): P(z) (NaN where the step failed) and
    `step`'s status, the same as `map_batch`'s ``z`` and ``status``. Through the ensemble
    engine in chunks of ``chunk_size`` rows where it takes the maps
    (`pdw.analysis.stepmap.step_maps.batchable`; ``workers`` threads), `step` for the rest; otherwise
    `map_batch`. ``progress``: one unit per row."""
    Z = np.atleast_2d(np.asarray(Z, dtype=float))
    n = len(Z)
    out, status = np.full(Z.shape, np.nan), np.full(n, "ok", dtype=object)
    if not batchable(method, 1, options):
        for i, s in enumerate(map_batch(Z, params, variant, method, workers=workers,
                                        progress=progress, **options)):
            out[i], status[i] = s["z"], s["status"]
        return out, status
    bar = progress_bar(progress, n, "step map")
    nw = _workers(workers)
    left = []
    for lo in range(0, n, int(chunk_size)):
        rows = range(lo, min(n, lo + int(chunk_size)))
        for i, im in zip(rows, images(Z[rows.start:rows.stop], params, variant, method,
                                      options, threads=nw)):
            if im is None:
                left.append(i)
            else:
                out[i] = im
                if bar is not None:
                    bar.update(1)
    fn = lambda i: step(Z[i], params, variant, method, **options)   # noqa: E731
    for i, s in zip(left, interrupt.thread_map(fn, left, min(nw, max(1, len(left))), bar)):
        out[i], status[i] = s["z"], s["status"]
    return out, status


def map_batch(Z, params=None, variant="paper", method="rodas4", *, workers=None,
              progress=False, **options):
    """Steps from every row of Z (N, len(z)), in ``workers`` threads: list of step dicts
    (``progress``: False, True or a `pdw.Progress`, one unit per row)."""
    Z = np.atleast_2d(np.asarray(Z, dtype=float))
    bar = progress_bar(progress, len(Z), "step map")
    fn = lambda z: step(z, params, variant, method, **options)   # noqa: E731
    return interrupt.thread_map(fn, Z, min(_workers(workers), len(Z)), bar)


def _compose(z, n, params, variant, method, options):
    """P^n(z) and the steps (None if a step failed)."""
    steps, t_hint = [], options.get("t_hint")
    for _ in range(n):
        s = step(z, params, variant, method, **{**options, "t_hint": t_hint})
        steps.append(s)
        if s["status"] != "ok":
            return None, steps
        z, t_hint = s["z"], s["period"]
    return z, steps


def _step_defaults():
    """`step`'s keyword defaults (dt, t_max, the tolerances, t_hint)."""
    sig = inspect.signature(step)
    return {k: v.default for k, v in sig.parameters.items()
            if v.kind == v.KEYWORD_ONLY and v.default is not inspect.Parameter.empty}


def compose_points(points, period, params, variant, method, options, workers=None):
    """``[(P^n(z) or None, steps)]`` for every point, as `_compose` gives them: the first
    point's with its step dicts, the others' through the ensemble engine where it takes them
    (`pdw.analysis.stepmap.step_maps.batchable`: z' bitwise `step`'s; their steps are then
    ``[{"status": "ok", "z": z'}]``), else, and for every point the engine leaves, `_compose`.
    ``params``: one `Params` or one per point. The first point runs in its own thread beside
    the engine's batch (``workers - 1`` threads); Ctrl-C stops both (`pdw.core.interrupt`)."""
    nw = _workers(workers)
    plist = list(params) if isinstance(params, (list, tuple)) else [params] * len(points)

    def one(i):
        return _compose(points[i], period, plist[i], variant, method, options)

    if len(points) < 3 or not batchable(method, period, options):
        # Ctrl-C stops every thread at its next poll (pdw.core.interrupt)
        return interrupt.thread_map(one, range(len(points)), min(nw, len(points)))
    tasks = [lambda: one(0),
             lambda: images(points[1:], plist[1:], variant, method, options,
                            threads=max(1, nw - 1))]
    first, imgs = interrupt.thread_map(lambda task: task(), tasks, min(nw, 2))
    outs = [first] + [(im, [{"status": "ok", "z": im}]) for im in imgs]
    left = [1 + i for i, im in enumerate(imgs) if im is None]
    for i, o in zip(left, interrupt.thread_map(one, left, min(nw, max(1, len(left))))):
        outs[i] = o
    return outs
