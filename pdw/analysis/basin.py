"""Basin of attraction of a period-one gait on a 2-D slice of the touch-down section, by direct
simulation of every grid point with the ensemble engine (`pdw.simulate_batch`; docs/ensemble.md).

The section, its coordinates and the slice are those of `pdw.cell_mapping` (touch-down of the
swing foot, legs relabelled; grid over phi = theta2 - theta1 [rad] and thetad2 [rad/s], the
other four coordinates taken from a reference section point, `cell_mapping.reference_point`).
Unlike cell mapping, no cell-to-cell approximation: each grid point's state (`lc.embed`, flags
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

import time
from dataclasses import dataclass

import numpy as np

from ..core.errors import InvalidInputError
from ..core.params import Params
from ..sim.batch import simulate_batch
from . import cell_mapping as cmap
from . import limit_cycle as lc

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

    def fraction(self, outcome=GAIT) -> float:
        """Fraction of the grid with this outcome."""
        return float(np.mean(self.outcome == outcome))


def _last(b, field):
    from ..core import _layout
    j = _layout.STEP.index(field)
    idx = np.minimum(b.n_gait_steps, _layout.STEP_RING) - 1
    out = np.full(len(b), np.nan)
    has = b.n_gait_steps > 0
    out[has] = b.gait_rows[np.nonzero(has)[0], idx[has], j]
    return out


def basin(params=None, phi=(0.69, 0.81, 100), thetad2=(-3.2, -0.4, 100), *, t_end=8.0,
          dt=1e-4, periodic_steps=4, periodic_tol=1e-3, match_tol=0.02, reference=None,
          threads=None, lanes=8, vector=False) -> Basin:
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
        Passed to `pdw.simulate_batch`.
    """
    p = Params.paper_steady() if params is None else params
    if not isinstance(p, Params):
        raise InvalidInputError("params must be a pdw.Params, got %s" % type(p).__name__)
    (a0, a1, na), (b0, b1, nb) = phi, thetad2
    if int(na) < 1 or int(nb) < 1:
        raise InvalidInputError("grid sizes must be >= 1, got %r, %r" % (na, nb))
    z_ref = cmap.reference_point(p) if reference is None else lc._z(reference, "reference")
    if z_ref is None:
        raise InvalidInputError("the paper's initial condition does not reach a touch-down "
                                "with these params: give a reference section point")
    rest = cmap.rest_of(z_ref, p)
    A, B = np.linspace(a0, a1, int(na)), np.linspace(b0, b1, int(nb))
    x0 = [lc.embed(z_ref, p)]
    for b in B:
        for a in A:
            x0.append(lc.embed(cmap.cell_state(a, b, rest, p), p))
    start = time.perf_counter()
    res = simulate_batch(np.array(x0), t_end=t_end, dt=dt, params=p, flags0=(1, 1),
                         periodic_steps=periodic_steps, periodic_tol=periodic_tol,
                         threads=threads, lanes=lanes, vector=vector)
    wall = time.perf_counter() - start
    L, P = _last(res, "L"), _last(res, "P")
    if res.status[0] != "periodic":
        raise InvalidInputError("the reference point does not settle into a periodic gait "
                                "within t_end = %g s (status %s)" % (t_end, res.status[0]))
    same = (np.abs(L - L[0]) <= match_tol * abs(L[0])) & (np.abs(P - P[0]) <= match_tol * P[0])
    out = np.where(res.walked, UNDECIDED, FELL)
    per = res.status == "periodic"
    out[per & same] = GAIT
    out[per & ~same] = OTHER
    return Basin(phi=A, thetad2=B, outcome=out[1:].reshape(len(B), len(A)),
                 n_steps=res.n_gait_steps[1:].reshape(len(B), len(A)), reference=z_ref,
                 gait_L=float(L[0]), gait_P=float(P[0]), wall_time=wall, walkers=len(x0) - 1)


def plot(b: Basin, ax=None, title=None):
    """Outcome map of a `Basin` (matplotlib): the reference gait's basin, falls, other gaits."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.5))
    cmap_ = ListedColormap(["#d9d9d9", "#2b8cbe", "#fdae61", "#ffffbf"])
    dphi = (b.phi[1] - b.phi[0]) / 2 if len(b.phi) > 1 else 0.5e-3
    dth = (b.thetad2[1] - b.thetad2[0]) / 2 if len(b.thetad2) > 1 else 0.5e-2
    ax.imshow(b.outcome, origin="lower", aspect="auto", cmap=cmap_, vmin=-0.5, vmax=3.5,
              interpolation="nearest",
              extent=(b.phi[0] - dphi, b.phi[-1] + dphi, b.thetad2[0] - dth, b.thetad2[-1] + dth))
    ax.plot(b.reference[1] - b.reference[0], b.reference[5], "k+", ms=10, label="reference")
    ax.set_xlabel(r"$\phi = \theta_2 - \theta_1$ at touch-down [rad]")
    ax.set_ylabel(r"$\dot\theta_2$ at touch-down [rad/s]")
    from matplotlib.patches import Patch
    ax.legend(handles=[Patch(color=c, label=n) for c, n in zip(cmap_.colors, OUTCOMES)],
              loc="upper right", fontsize=8)
    ax.set_title(title or "basin (%d x %d, %.0f%% gait)" % (len(b.phi), len(b.thetad2),
                                                            100 * b.fraction()))
    return ax
