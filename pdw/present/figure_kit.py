"""Shared pieces of the walk figures (`pdw.present.plots`, `pdw.present.animation`): colours,
sizes, the double-support intervals of a run, the walker's geometry in the world frame.

Conventions (docs/model.md section 2): the state is in the slope frame (X downhill along the
slope, Y normal to it, up); leg angles are measured from the slope normal pointing down,
counter-clockwise positive. Leg 1 is drawn in blue, leg 2 in orange in every figure.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

#: Colours of legs 1 and 2 in every figure.
LEG_COLORS = ("tab:blue", "tab:orange")
#: Figure sizes in inches, by function name (the PNGs of `save_all` are FIGSIZE * DPI pixels).
FIGSIZE = {
    "fig_gait": (11.0, 10.0),
    "fig_stick": (15.0, 4.8),
    "fig_contact": (11.0, 7.0),
    "fig_double_support": (9.0, 9.0),
    "animate": (6.0, 3.4),
}
#: Resolution of the PNG files written by `save_all` [dots per inch].
DPI = 110
#: Resolution of the GIF frames [dots per inch].
GIF_DPI = 80
#: Half-angle of the drawn foot arc around the leg axis [rad].
FOOT_ARC_HALF_ANGLE = 0.6
#: Running-mean window of the tangential force in `fig_contact` [s].
FT_SMOOTH = 5e-3
#: Running-mean window of the tangential force in `fig_double_support` [s].
FT_SMOOTH_ZOOM = 1e-3

_SHADE = dict(color="0.85", alpha=0.6, lw=0, zorder=0)


class DoubleSupport(NamedTuple):
    """One double-support interval of a run (both support flags 1).

    Attributes
    ----------
    t_start : float
        Start [s]: the touch-down of ``leg_down`` (or the first recorded time when the run
        starts in double support).
    t_end : float
        End [s]: the lift-off of ``leg_up`` (or the run's final time when it ends in double
        support).
    leg_down : int or None
        The leg (1 or 2) whose touch-down started the interval; None if the run started so.
    leg_up : int or None
        The leg (1 or 2) whose lift-off ended the interval; None if the run ended so.
    """

    t_start: float
    t_end: float
    leg_down: int | None
    leg_up: int | None

    @property
    def duration(self) -> float:
        """Length of the interval [s]."""
        return self.t_end - self.t_start


# --------------------------------------------------------------------------------------------
# helpers

def _new_figure(figsize, **kwargs):
    """A Figure on an Agg canvas, outside pyplot's figure manager."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained", **kwargs)
    FigureCanvasAgg(fig)
    return fig


def _check_recorded(result, forces=False):
    t = np.asarray(result.t)
    if t.size < 2:
        raise ValueError("the result holds fewer than 2 recorded states (simulate with "
                         "record_every >= 1); nothing to plot")
    if forces and (np.size(result.Fn) == 0 or len(result.Fn) != len(t)):
        raise ValueError("the result holds no contact forces (simulate with record_forces=True)")
    return t


def _record_step(t):
    """Typical spacing of the recorded times [s]."""
    return float(np.median(np.diff(t)))


def _running_mean(a, n):
    """Centred running mean over ``n`` samples (edges: the mean of the samples available)."""
    a = np.asarray(a, dtype=float)
    n = int(n)
    if n <= 1 or a.size < 2:
        return a.copy()
    n = min(n, a.size)
    k = np.ones(n)
    num = np.convolve(a, k, mode="same")
    den = np.convolve(np.ones_like(a), k, mode="same")
    return num / den


def _smooth_window(t, window):
    return max(1, int(round(window / _record_step(t))))


def _contact_points(result, x=None):
    """Contact points D_i (docs/model.md section 2) of both legs: arrays (N, 2) of x_D and y_D."""
    p = result.params
    x = np.asarray(result.x if x is None else x)
    th = x[:, 2:4]
    xd = x[:, 0:1] + (p.l - p.r) * np.sin(th)
    yd = x[:, 1:2] - p.r - (p.l - p.r) * np.cos(th)
    return xd, yd


def _to_world(X, Y, gamma):
    """Slope frame (X downhill along the slope, Y normal up) -> world frame (horizontal, up)."""
    cg, sg = math.cos(gamma), math.sin(gamma)
    X = np.asarray(X, dtype=float)
    Y = np.asarray(Y, dtype=float)
    return X * cg + Y * sg, -X * sg + Y * cg


def _leg_polyline(state, leg, params, n_arc=25):
    """Slope-frame polyline of one leg: hip -> foot end, then the foot arc.

    The arc is rigidly attached to the leg: radius r about A_i = H + (l - r) e_i, spanning
    ``FOOT_ARC_HALF_ANGLE`` either side of the leg axis (it contains the lowest point D_i
    while |theta_i| < that angle).
    """
    xo, yo = state[0], state[1]
    th = state[2 + leg]
    lr = params.l - params.r
    ax, ay = xo + lr * math.sin(th), yo - lr * math.cos(th)
    ex, ey = xo + params.l * math.sin(th), yo - params.l * math.cos(th)
    phi = np.linspace(th - FOOT_ARC_HALF_ANGLE, th + FOOT_ARC_HALF_ANGLE, n_arc)
    arc_x = ax + params.r * np.sin(phi)
    arc_y = ay - params.r * np.cos(phi)
    return (np.array([xo, ex]), np.array([yo, ey])), (arc_x, arc_y)


def _touch_downs(result):
    return [e for e in result.events if e.kind == "touch_down"]


def double_support_intervals(result) -> list[DoubleSupport]:
    """The double-support intervals of a run, from its events.

    Parameters
    ----------
    result : pdw.sim.simulation.Result
        A simulated walk. The initial support flags are read from ``result.flags[0]``.

    Returns
    -------
    list of DoubleSupport
        In time order. An interval still open at the end of the run ends at
        ``result.t_final`` with ``leg_up=None``.
    """
    flags = np.asarray(result.flags)
    on = [bool(flags[0, 0]), bool(flags[0, 1])] if flags.size else [False, False]
    t0 = float(result.t[0]) if np.size(result.t) else 0.0
    out = []
    start, down = (t0, None) if all(on) else (None, None)
    for e in sorted(result.events, key=lambda e: e.t):
        i = e.leg - 1
        if e.kind == "touch_down":
            on[i] = True
            if all(on) and start is None:
                start, down = e.t, e.leg
        else:
            if all(on) and start is not None:
                out.append(DoubleSupport(float(start), float(e.t), down, e.leg))
                start = None
            on[i] = False
    if start is not None:
        out.append(DoubleSupport(float(start), float(result.t_final), down, None))
    return out


def _cycle_for(result, ds):
    """Cycle time (between successive touch-downs) around a double support, or None."""
    tds = sorted(e.t for e in _touch_downs(result))
    if ds.leg_down is None or len(tds) < 2:
        return None
    k = int(np.argmin([abs(t - ds.t_start) for t in tds]))
    if k > 0:
        return tds[k] - tds[k - 1]
    return tds[k + 1] - tds[k]


def _shade_double_support(ax, result, label=True):
    for j, ds in enumerate(double_support_intervals(result)):
        ax.axvspan(ds.t_start, ds.t_end, label="double support" if (label and j == 0) else None,
                   **_SHADE)


def _mark_touch_downs(ax, result, label=True):
    seen = set()
    for e in _touch_downs(result):
        lab = None
        if label and e.leg not in seen:
            lab = "touch-down, leg %d" % e.leg
            seen.add(e.leg)
        ax.axvline(e.t, color=LEG_COLORS[e.leg - 1], ls="--", lw=0.9, alpha=0.8, label=lab,
                   zorder=1)


def _run_label(result):
    s = "%s, variant %r, dt = %g s, %s" % (result.method, result.variant, result.dt, result.status)
    if getattr(result, "failure", None):
        s += " (%s at t = %.3f s)" % (result.failure["reason"], result.failure["t"])
    return s


PATCH_COLOR = "tab:olive"


def draw_ground(ax, result, X_lo, X_hi, depth, gamma, *, z=0, lw=1.5):
    """Draw the ground of ``result`` (its `pdw.Ground`, flat when none) in the world frame
    between X_lo and X_hi along the slope [m]: the surface h(s), hatched below to ``depth``
    under its lowest point, and each contact patch as a coloured band on the surface (labelled
    with the properties it sets). Returns (world x, world y) of the surface."""
    g = getattr(result, "ground", None)
    n = 2 if g is None or (g.kind == "flat" and not g.patches) else 1200
    s = np.linspace(X_lo, X_hi, n)
    h = np.zeros_like(s) if g is None else np.asarray(g.h(s), dtype=float)
    gx, gy = _to_world(s, h, gamma)
    bx, by = _to_world(s[::-1], np.full(n, h.min() - depth), gamma)
    ax.fill(np.r_[gx, bx], np.r_[gy, by], facecolor="0.92", edgecolor="none", hatch="///",
            zorder=z)
    ax.plot(gx, gy, color="k", lw=lw, zorder=z + 3)
    for k, p in enumerate(() if g is None else g.patches):
        inside = (s >= p.s_a) & (s <= p.s_b)
        if inside.any():
            ax.plot(gx[inside], gy[inside], color=PATCH_COLOR, lw=4 * lw, alpha=0.6,
                    solid_capstyle="butt", zorder=z + 2,
                    label="patch: " + ", ".join("%s = %.3g" % kv for kv in p.values) if k == 0
                    else None)
    return gx, gy


def ground_height(result, s):
    """h(s) [m] of the result's ground (0 when flat or none)."""
    g = getattr(result, "ground", None)
    return 0.0 if g is None else float(g.h(s))
