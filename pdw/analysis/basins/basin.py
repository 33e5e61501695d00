"""Basin of attraction of a period-one gait on a 2-D slice of the touch-down section, by direct
simulation of every grid point with the ensemble engine (`pdw.simulate_batch`; docs/ensemble.md).

The section, its coordinates and the slice are those of `pdw.cell_mapping` (touch-down of the
swing foot, legs relabelled; grid over phi = theta2 - theta1 [rad] and thetad2 [rad/s], the
other four coordinates taken from a reference section point, `cell_mapping.reference_point`).
Unlike cell mapping, no cell-to-cell approximation: each grid point's state (`_section.embed`, flags
(1, 1)) is walked with the paper's central difference method until the last
``periodic_steps`` gait steps agree (the compiled loop's periodicity stop) or until ``t_end``,
and is classed by its outcome:

    FELL        fell or diverged
    GAIT        became periodic with the reference gait's step length and period (within
                ``match_tol``, relative): in the basin
    OTHER       became periodic with another step (another gait)
    UNDECIDED   still walking at t_end, not (yet) periodic
"""
from __future__ import annotations

import hashlib
import json
import os
import pathlib
import time
from dataclasses import dataclass

import numpy as np

from ...core import _layout, checks, paths
from ...core.errors import InvalidInputError
from ...core.params import Params
from ...core.progress import progress_bar
from ...sim.batch import LANES, simulate_batch
from ...sim.options import Stop
from ..stepmap import poincare as _poincare
from ..stepmap import section as _section
from . import cell_mapping as cmap

FELL, GAIT, OTHER, UNDECIDED = 0, 1, 2, 3
OUTCOMES = ("fell", "gait", "other", "undecided")


@dataclass
class Basin:
    """A basin on the (phi, thetad2) slice.

    Attributes
    ----------
    phi, thetad2 : ndarray (na,), (nb,)
        Grid coordinates [rad], [rad/s].
    outcome : ndarray of int (nb, na)
        `FELL`, `GAIT`, `OTHER` or `UNDECIDED` (row: thetad2, column: phi).
    n_steps : ndarray of int (nb, na)
        Gait steps walked (to periodicity, the fall or t_end).
    reference : ndarray (6,)
        The reference section point (its other four coordinates define the slice).
    gait_L, gait_P : float
        Step length [m] and period [s] of the reference gait (the reference point's own walk).
    wall_time : float
        Seconds for the whole grid; ``walkers`` its size.
    cpu_time : float
        Process CPU seconds of the grid's chunks (this process's, all threads; NaN for chunks
        computed on an executor's workers or read from a checkpoint that did not keep it).
    """

    phi: np.ndarray
    thetad2: np.ndarray
    outcome: np.ndarray
    n_steps: np.ndarray
    reference: np.ndarray
    gait_L: float
    gait_P: float
    wall_time: float
    walkers: int
    cpu_time: float = float("nan")

    def fraction(self, outcome=GAIT) -> float:
        """Fraction of the grid with this outcome."""
        return float(np.mean(self.outcome == outcome))


def _last(b, field):
    j = _layout.STEP.index(field)
    idx = np.minimum(b.n_gait_steps, _layout.STEP_RING) - 1
    out = np.full(len(b), np.nan)
    has = b.n_gait_steps > 0
    out[has] = b.gait_rows[np.nonzero(has)[0], idx[has], j]
    return out


def _classify(res, L0, P0, match_tol):
    """Outcome codes of a batch's walkers against the reference gait (L0, P0)."""
    L, P = _last(res, "L"), _last(res, "P")
    same = (np.abs(L - L0) <= match_tol * abs(L0)) & (np.abs(P - P0) <= match_tol * P0)
    out = np.where(res.walked, UNDECIDED, FELL)
    per = res.status == "periodic"
    out[per & same] = GAIT
    out[per & ~same] = OTHER
    return out


def _key(p, A, B, opts):
    """What decides a basin's numbers (a checkpoint of other settings is not reused)."""
    text = json.dumps({"params": p.as_dict(), "phi": A.tolist(), "thetad2": B.tolist(),
                       "opts": opts, "model": _layout.INPUT_HASH}, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _save(path, **arrays):
    """Write the checkpoint atomically (a temporary file in the same folder, then rename)."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = paths.temp_file(path, suffix=".tmp.npz")
    os.close(fd)
    try:
        np.savez(tmp, **arrays)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def basin(params=None, phi=(0.69, 0.81, 100), thetad2=(-3.2, -0.4, 100), *, t_end=8.0,
          dt=1e-4, periodic_steps=4, periodic_tol=1e-3, match_tol=0.02, reference=None,
          threads=None, lanes=LANES, vector=False, chunk_size=4096, checkpoint=None,
          executor=None, progress=False) -> Basin:
    """Basin of the gait reached from ``reference`` on a ``phi`` x ``thetad2`` grid.

    Parameters
    ----------
    params : Params, optional
        Default `Params.paper_steady()` (the preset with a stable period-one gait).
    phi, thetad2 : (lo, hi, n)
        Grid ranges [rad], [rad/s] and sizes (the defaults are `cell_mapping.cell_map`'s).
    t_end, dt : float
        Longest walk and step of the central difference method [s].
    periodic_steps, periodic_tol : int, float
        Periodicity test of `pdw.simulate` (the last k steps agree within tol, relative).
    match_tol : float
        A periodic walk is the reference gait when its last step length and period are within
        this (relative) of the reference's.
    reference : (6,) section point, optional
        Default `cell_mapping.reference_point(params)` (first touch-down of the paper's initial
        condition, found with rodas4).
    threads, lanes, vector
        Passed to `pdw.simulate_batch` (per chunk).
    chunk_size : int
        Grid points per `simulate_batch` call (row-major: thetad2 slowest). Each chunk's
        outcomes are final (no walker depends on another), so chunks can be saved and resumed.
    checkpoint : path, optional
        An ``.npz`` file written (atomically) after every chunk; a later call with the same
        settings (parameters, grid, options, model hash) takes the chunks already there and
        computes only the rest. A checkpoint of other settings is ignored and overwritten.
    executor : concurrent.futures.Executor-like, optional
        Run the chunks as ``executor.submit(simulate_batch, ...)`` tasks (a process pool, a
        Dask client's executor); each chunk then uses ``threads`` threads (default 1 here).
    progress : bool or pdw.Progress
        A progress bar over grid points on stderr (`pdw.core.progress.progress_bar`).

    Returns
    -------
    Basin
        ``wall_time`` is the compute time of all chunks, those of a resumed checkpoint
        included.
    """
    p = Params.paper_steady() if params is None else params
    if not isinstance(p, Params):
        raise InvalidInputError("params must be a pdw.Params, got %s" % type(p).__name__)
    (a0, a1, na), (b0, b1, nb) = cmap.grid_axis("phi", phi), cmap.grid_axis("thetad2", thetad2)
    chunk_size = checks.count("chunk_size", chunk_size, lo=1)
    z_ref = cmap.reference_point(p) if reference is None else _poincare._z(reference, "reference")
    if z_ref is None:
        raise InvalidInputError("the paper's initial condition does not reach a touch-down "
                                "with these params: give a reference section point")
    rest = cmap.rest_of(z_ref, p)
    A, B = np.linspace(a0, a1, int(na)), np.linspace(b0, b1, int(nb))
    opts = dict(t_end=t_end, dt=dt, params=p, flags0=(1, 1), lanes=lanes, vector=vector,
                stop=Stop(periodic=periodic_steps > 0, periodic_steps=periodic_steps or 4,
                          periodic_tol=periodic_tol))
    ref = simulate_batch(_section.embed(z_ref, p)[None, :], threads=1, **opts)
    if ref.status[0] != "periodic":
        raise InvalidInputError("the reference point does not settle into a periodic gait "
                                "within t_end = %g s (status %s)" % (t_end, ref.status[0]))
    L0, P0 = float(_last(ref, "L")[0]), float(_last(ref, "P")[0])
    x0 = np.array([_section.embed(cmap.cell_state(a, b, rest, p), p) for b in B for a in A])
    n = len(x0)
    key = _key(p, A, B, {**{k: v for k, v in opts.items() if k != "params"},
                         "match_tol": match_tol, "reference": z_ref.tolist()})
    outcome = np.full(n, -1, dtype=np.int8)
    steps = np.zeros(n, dtype=np.int64)
    wall = cpu = 0.0
    if checkpoint is not None and os.path.exists(checkpoint):
        with np.load(checkpoint) as ck:
            if str(ck["key"]) == key and ck["outcome"].shape == (n,):
                outcome, steps, wall = ck["outcome"].copy(), ck["n_steps"].copy(), float(ck["wall"])
                cpu = float(ck["cpu"]) if "cpu" in ck.files else float("nan")
    bounds = [(lo, min(n, lo + chunk_size)) for lo in range(0, n, chunk_size)]
    todo = [(lo, hi) for lo, hi in bounds if (outcome[lo:hi] < 0).any()]
    bar = progress_bar(progress, n, "basin", done=n - sum(hi - lo for lo, hi in todo))
    nthreads = threads if threads is not None else (1 if executor is not None else None)

    def finish(lo, hi, res, seconds, cpu_seconds):
        nonlocal wall, cpu
        outcome[lo:hi] = _classify(res, L0, P0, match_tol)
        steps[lo:hi] = res.n_gait_steps
        wall += seconds
        cpu += cpu_seconds
        if checkpoint is not None:
            _save(checkpoint, key=np.array(key), outcome=outcome, n_steps=steps,
                  wall=np.array(wall), cpu=np.array(cpu))
        bar.update(hi - lo)

    try:
        if executor is None:
            for lo, hi in todo:
                t0, c0 = time.perf_counter(), time.process_time()
                res = simulate_batch(x0[lo:hi], threads=nthreads, **opts)
                finish(lo, hi, res, time.perf_counter() - t0, time.process_time() - c0)
        else:
            t0 = time.perf_counter()
            futs = [executor.submit(simulate_batch, x0[lo:hi], threads=nthreads, **opts)
                    for lo, hi in todo]
            for (lo, hi), f in zip(todo, futs):
                res = f.result()
                t1 = time.perf_counter()
                finish(lo, hi, res, t1 - t0, float("nan"))
                t0 = t1
    finally:
        bar.close()
    shape = (len(B), len(A))
    return Basin(phi=A, thetad2=B, outcome=outcome.astype(int).reshape(shape),
                 n_steps=steps.reshape(shape), reference=z_ref, gait_L=L0, gait_P=P0,
                 wall_time=wall, walkers=n, cpu_time=cpu)


def plot(b: Basin, ax=None, title=None):
    """Outcome map of a `Basin` (matplotlib): the reference gait's basin, falls, other gaits."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.5))
    colors = ["#d9d9d9", "#2b8cbe", "#fdae61", "#ffffbf"]
    cmap_ = ListedColormap(colors)
    dphi = (b.phi[1] - b.phi[0]) / 2 if len(b.phi) > 1 else 0.5e-3
    dth = (b.thetad2[1] - b.thetad2[0]) / 2 if len(b.thetad2) > 1 else 0.5e-2
    ax.imshow(b.outcome, origin="lower", aspect="auto", cmap=cmap_, vmin=-0.5, vmax=3.5,
              interpolation="nearest",
              extent=(b.phi[0] - dphi, b.phi[-1] + dphi, b.thetad2[0] - dth, b.thetad2[-1] + dth))
    ax.plot(b.reference[1] - b.reference[0], b.reference[5], "k+", ms=10, label="reference")
    ax.set_xlabel(r"$\phi = \theta_2 - \theta_1$ at touch-down [rad]")
    ax.set_ylabel(r"$\dot\theta_2$ at touch-down [rad/s]")
    from matplotlib.patches import Patch
    ax.legend(handles=[Patch(color=c, label=n) for c, n in zip(colors, OUTCOMES)],
              loc="upper right", fontsize=8)
    ax.set_title(title or "basin (%d x %d, %.0f%% gait)" % (len(b.phi), len(b.thetad2),
                                                            100 * b.fraction()))
    return ax
