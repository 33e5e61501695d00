"""The work of one point of a sweep, and of a group of points as one batch (docs/studies.md,
docs/ensemble.md). `pdw.studies.sweep.run_study` submits these module-level functions of plain
data (a task dict in, a row dict out) to its executor.

`run_point` computes one point (`pdw.simulate` or `pdw.find_gait`). `run_points` computes a
group of points through the ensemble engine (`pdw.simulate_batch`): in ``mode = "simulate"``
every point of a study is one simulation of the same scene with its own parameters (the same
method, variant, start, duration and stop conditions), so a group is one batch with per-walker
`Params`. Its rows are exactly `run_point`'s: the same status, gait class, steady descriptors
and step count (the batch's online gait descriptors are bitwise those `pdw.steps` finds from the
events, and the batch's walkers are bitwise `pdw.simulate`'s runs on the cdm path); the Newton
fallback (``[run] fallback``) of a point that is not period-1 runs per point as before.
``wall_s`` of a batched point is its share of the group's time (plus its own Newton time).

`batchable` says when a study qualifies: ``mode = "simulate"``, a method the batch engine runs
bitwise (`BITWISE_METHODS`: every method of `pdw.METHODS`; a method the engine ran only
within a tolerance would change the rows) and that it supports (`pdw.sim.ensemble.supports`), every force
element and the default contact laws (the engine's kernels), no recorded samples (the scalar
run's end-of-run check then looks at the final state only, as the batch's does),
``on_failure = "return"``, and ``steady`` small enough for the last `STEP_RING` steps the
engine keeps. Other studies run point by point, unchanged.
"""
from __future__ import annotations

import math
import time

import numpy as np

from ..core import _layout
from ..core.errors import InvalidInputError, PdwError
from ..core.integrators import METHODS
from ..core.params import Params
from ..sim import ensemble
from ..sim.scene import Scene
from .study import COLUMNS, Study

#: Methods whose batch runs are bitwise `pdw.simulate`'s (tests/sim/test_batch.py: cdm with
#: ``vector=False`` and every adaptive or fixed-step method of the engine, one lane per walker
#: through the scalar integrator's own steps): only these batch a sweep, so that its rows do not
#: change (tests/sim/test_ensemble.py compares the rows with `run_point`'s for cdm and rodas4).
BITWISE_METHODS = METHODS
#: Points per batched task at most (a task's rows reach the CSV together).
MAX_GROUP = 64


def batchable(study: Study) -> bool:
    """Can the study's points run as batches (module docstring)?"""
    sc, run = study.scene, study.run
    if run["mode"] != "simulate":
        return False
    n = max(run["steady"], 2)
    if 2 * n + 2 > _layout.STEP_RING:
        return False
    if sc.record.every != 0 or sc.limits.on_failure != "return":
        return False
    if not ensemble.plain_model(sc.features, sc.contact.to_contact()):
        return False
    if sc.ground is not None and not sc.ground.is_flat:    # point by point: simulate(ground=)
        return False
    return (sc.integrator.method in BITWISE_METHODS
            and ensemble.supports(sc.integrator.method, sc.variant))


def groups(todo, workers):
    """Cut the points to compute into groups of consecutive points: about four per worker,
    at least one block of lanes (8) and at most `MAX_GROUP` each."""
    size = min(MAX_GROUP, max(8, math.ceil(len(todo) / (4 * max(1, workers)))))
    return [todo[i:i + size] for i in range(0, len(todo), size)]


def run_points(tasks) -> list:
    """Rows of a group of points (``tasks``: `Study.task` dicts of one study), computed with
    one `pdw.sim.ensemble.simulate_many` call (one thread); module-level, so that process
    pools and Dask workers can import it. Falls back to `run_point` per point if the group as
    a whole is refused."""
    from ..sim.gait import Steps
    if not tasks:
        return []
    t0 = time.perf_counter()
    try:
        scene = Scene.from_dict(tasks[0]["scene"])
        params = [Params(**t["params"]) for t in tasks]
        b = ensemble.simulate_many(
            [scene.x0] * len(tasks), params=params, variant=scene.variant,
            flags0=scene.flags0, threads=1, integrator=scene.integrator, stop=scene.stop,
            limits=scene.limits)
    except (PdwError, ValueError):
        return [run_point(t) for t in tasks]
    share = (time.perf_counter() - t0) / len(tasks)
    rows = []
    for i, task in enumerate(tasks):
        t1 = time.perf_counter()
        run = task["run"]
        row = {"index": int(task["index"]), **task["values"]}
        row.update({c: "" for c in COLUMNS})
        row["settings"] = task.get("settings", "")
        st = b.steps(i)
        n_steps = int(b.n_gait_steps[i])
        s = Steps(st.table).steady(run["steady"])
        s["n_steps"] = n_steps
        status = str(b.status[i])
        try:
            row.update(status=status, n_steps=n_steps, t_final=float(b.t_final[i]),
                       source="simulate",
                       gait=_classify(st.table, run["steady"], run["period_tol"])
                       if status == "walked" else "")
            if status == "walked" and n_steps >= run["steady"]:
                row.update({k: s[k] for k in ("L", "P", "v", "cycle", "double_support",
                                              "ds_fraction", "travel")},
                           spread_L=s["spread_L"], spread_cycle=s["spread_cycle"])
            if run["fallback"] and row["gait"] != "period-1":
                _newton_point(row, params[i], scene)
        except (PdwError, ValueError) as e:
            row.update(status="error", error=str(e)[:300])
        row["wall_s"] = share + time.perf_counter() - t1
        rows.append(row)
    return rows


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
    from ..sim.gait import steps
    from ..sim.scene import Scene
    from ..sim.simulation import simulate
    t0 = time.perf_counter()
    row = {"index": int(task["index"]), **task["values"]}
    row.update({c: "" for c in COLUMNS})
    row["settings"] = task.get("settings", "")
    run = task["run"]
    try:
        params = Params(**task["params"])
        scene = Scene.from_dict(task["scene"])
        if run["mode"] == "simulate":
            res = simulate(**{**scene.simulate_kwargs(), "params": params})
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
            _newton_point(row, params, scene)
    except (PdwError, ValueError) as e:
        row.update(status="error", error=str(e)[:300])
    row["wall_s"] = time.perf_counter() - t0
    return row


def _newton_point(row, params, scene):
    """Fill ``row`` from `pdw.find_gait` (default guesses, the scene's contact laws); keeps
    ``row`` if none is found."""
    from ..analysis.gait_types import GaitNotFoundError
    from ..analysis.stepmap.limit_cycle import find_gait
    if scene.ground is not None and not scene.ground.is_flat:
        if row["status"] != "":         # the fallback after a simulated point: keep that row
            return
        raise InvalidInputError("newton mode (find_gait) needs flat ground: a periodic gait "
                                "of a shaped or patched [scene.ground] is not defined")
    c = scene.contact.to_contact()
    law = {} if c.is_default else dict(contact=c)
    try:
        g = find_gait(params, variant=scene.variant, method=scene.integrator.method, workers=1,
                      max_iter=12, **law)
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
