"""Figures of a simulated walk, after the paper's Figs. 4-7 (docs/model.md section 8).

Every ``fig_*`` function takes a `pdw.sim.simulation.Result` and returns a new
`matplotlib.figure.Figure` drawn on an Agg canvas (no pyplot state, no GUI); `animate`
writes an animated GIF and `save_all` writes everything to a folder.

matplotlib (and Pillow, for the GIF) are imported inside the functions, so ``import pdw``
and ``import pdw.present.plots`` do not need them: install the ``plot`` extra to use this module.

Conventions (docs/model.md section 2): the state is in the slope frame (X downhill along the
slope, Y normal to it, up); leg angles are measured from the slope normal pointing down,
counter-clockwise positive. Leg 1 starts as the rear (swing) leg, leg 2 as the stance leg.
Leg 1 is drawn in blue, leg 2 in orange in every figure. A *double support* is an interval
during which both support flags are 1 (docs/model.md section 5).

Functions
---------
fig_gait            paper Fig. 4: leg angles, their rates, hip height and hip velocities vs time
fig_stick           paper Fig. 5: stick picture of the walk down the slope
fig_contact         paper Fig. 6: normal and tangential contact forces vs time
fig_double_support  paper Fig. 7: zoom on one double-support interval
animate             animated GIF of the walker, camera following the hip
save_all            all of the above as PNG files and one GIF in a folder
double_support_intervals   the double supports of a run, from its events
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..core.progress import progress_bar
from .animation import animate
from .figure_kit import (  # noqa: F401 (re-exported by pdw.present.plots)
    _SHADE,
    DPI,
    FIGSIZE,
    FOOT_ARC_HALF_ANGLE,
    FT_SMOOTH,
    FT_SMOOTH_ZOOM,
    GIF_DPI,
    LEG_COLORS,
    DoubleSupport,
    _check_recorded,
    _contact_points,
    _cycle_for,
    _leg_polyline,
    _mark_touch_downs,
    _new_figure,
    _record_step,
    _run_label,
    _running_mean,
    _shade_double_support,
    _smooth_window,
    _to_world,
    _touch_downs,
    double_support_intervals,
    draw_ground,
    ground_height,
)

__all__ = [
    "fig_gait", "fig_stick", "fig_contact", "fig_double_support", "animate", "save_all",
    "double_support_intervals", "DoubleSupport", "FIGSIZE", "DPI", "LEG_COLORS",
]

# --------------------------------------------------------------------------------------------
# Fig. 4

def fig_gait(result):
    """Gait time histories, after the paper's Fig. 4 ("Period-one gait").

    Four panels against time t [s]: (a) leg angles theta_1, theta_2 [rad]; (b) their rates
    [rad/s]; (c) hip height y_o above the slope [m]; (d) hip velocities along the slope
    (x_o dot) and normal to it (y_o dot) [m/s]. Double-support intervals are shaded grey;
    touch-downs are dashed vertical lines in the colour of the leg that lands.

    Parameters
    ----------
    result : pdw.sim.simulation.Result
        A simulated walk with recorded states.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = _check_recorded(result)
    x = np.asarray(result.x)
    fig = _new_figure(FIGSIZE["fig_gait"])
    axs = fig.subplots(4, 1, sharex=True)
    panels = [
        ("(a) leg angles", "angle [rad]",
         [(x[:, 2], r"$\theta_1$ (leg 1)", LEG_COLORS[0]), (x[:, 3], r"$\theta_2$ (leg 2)", LEG_COLORS[1])]),
        ("(b) leg angular velocities", "angular velocity [rad/s]",
         [(x[:, 6], r"$\dot\theta_1$", LEG_COLORS[0]), (x[:, 7], r"$\dot\theta_2$", LEG_COLORS[1])]),
        ("(c) hip height above the slope", r"$y_o$ [m]", [(x[:, 1], r"$y_o$", "k")]),
        ("(d) hip velocities (slope frame)", "velocity [m/s]",
         [(x[:, 4], r"$\dot x_o$ (along slope, downhill +)", "tab:green"),
          (x[:, 5], r"$\dot y_o$ (normal to slope, up +)", "tab:purple")]),
    ]
    for k, (ax, (title, ylabel, curves)) in enumerate(zip(axs, panels)):
        _shade_double_support(ax, result, label=(k == 0))
        _mark_touch_downs(ax, result, label=(k == 0))
        for y, lab, col in curves:
            ax.plot(t, y, color=col, lw=1.2, label=lab)
        ax.set_title(title, loc="left", fontsize=10)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize=8, framealpha=0.9)
    axs[1].axhline(0, color="0.4", lw=0.6)
    axs[3].axhline(0, color="0.4", lw=0.6)
    axs[-1].set_xlabel("time t [s]")
    axs[-1].set_xlim(t[0], t[-1])
    fig.suptitle("Gait time histories (cf. paper Fig. 4, \"Period-one gait\")\n" + _run_label(result),
                 fontsize=11)
    return fig


# --------------------------------------------------------------------------------------------
# Fig. 5

def fig_stick(result, every=0.05):
    """Stick picture of the walk, after the paper's Fig. 5 ("Stick picture").

    Drawn in the *world* frame (x horizontal, y vertical, both [m]), i.e. the slope frame
    rotated by -gamma, so the ground is a line descending to the right at the slope angle
    gamma, with equal aspect (at gamma = 0.02 rad the ground drops 2 cm per metre). A snapshot
    every ``every`` seconds: each leg (hip to foot, then its arc foot of radius r) in its own
    colour, a thick line while the leg is a support leg and a thin one while it swings; the
    hip is a black dot and its path a grey line. Snapshots at the middle of each double
    support are drawn bold in dark colours. Triangles on the ground mark the footprints (the
    contact point x_D of each touch-down), numbered in order.

    Parameters
    ----------
    result : pdw.sim.simulation.Result
        A simulated walk with recorded states.
    every : float
        Time between snapshots [s].

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.lines import Line2D

    t = _check_recorded(result)
    x = np.asarray(result.x)
    flags = np.asarray(result.flags)
    p = result.params
    gam = p.gamma
    fig = _new_figure(FIGSIZE["fig_stick"])
    ax = fig.subplots()

    def draw(i, colors, lw_support, lw_swing, alpha, z):
        for leg in (0, 1):
            (lx, ly), (fx, fy) = _leg_polyline(x[i], leg, p)
            lw = lw_support if flags[i, leg] else lw_swing
            ax.plot(*_to_world(lx, ly, gam), color=colors[leg], lw=lw, alpha=alpha, zorder=z,
                    solid_capstyle="round")
            ax.plot(*_to_world(fx, fy, gam), color=colors[leg], lw=lw, alpha=alpha, zorder=z)
        hx, hy = _to_world(x[i, 0], x[i, 1], gam)
        ax.plot(hx, hy, "o", color="k", ms=3.5, alpha=min(1.0, alpha + 0.2), zorder=z + 1)

    step = max(1, int(round(every / _record_step(t))))
    for i in range(0, len(t), step):
        draw(i, LEG_COLORS, 1.6, 0.7, 0.55, 2)
    dss = double_support_intervals(result)
    dark = ("navy", "saddlebrown")
    for ds in dss:
        i = int(np.argmin(np.abs(t - 0.5 * (ds.t_start + ds.t_end))))
        draw(i, dark, 2.4, 2.4, 1.0, 5)
    # hip path
    ax.plot(*_to_world(x[:, 0], x[:, 1], gam), color="0.5", lw=0.8, ls=":", zorder=1)
    # ground
    X_lo = min(x[:, 0].min(), 0.0) - 0.4
    X_hi = x[:, 0].max() + 0.4
    depth = 0.06
    gx, gy = draw_ground(ax, result, X_lo, X_hi, depth, gam)    # its shape and patches
    # footprints
    for n, e in enumerate(_touch_downs(result), start=1):
        fx, fy = _to_world(e.x_D, ground_height(result, e.x_D), gam)
        ax.plot(fx, fy, marker="^", color=LEG_COLORS[e.leg - 1], ms=9, mec="k", mew=0.6,
                zorder=6, ls="none")
        ax.annotate("%d" % n, (fx, fy), xytext=(0, -12), textcoords="offset points",
                    ha="center", va="top", fontsize=8, zorder=6,
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.85))
    ax.set_aspect("equal")
    ax.set_xlim(gx[0], gx[-1])
    hip_top = float(np.max(_to_world(x[:, 0], x[:, 1], gam)[1]))
    ground_low = float(np.min(gy))
    ax.set_ylim(ground_low - depth, hip_top + 0.08)
    ax.set_xlabel("horizontal position x [m] (world frame)")
    ax.set_ylabel("height y [m]")
    ax.grid(alpha=0.25)
    handles = [
        Line2D([], [], color=LEG_COLORS[0], lw=1.6, label="leg 1 (thick: support, thin: swing)"),
        Line2D([], [], color=LEG_COLORS[1], lw=1.6, label="leg 2"),
        Line2D([], [], color="k", marker="o", ls="none", ms=4, label="hip"),
        Line2D([], [], color="0.5", ls=":", label="hip path"),
        Line2D([], [], color="navy", lw=2.4, label="mid double support"),
        Line2D([], [], color="0.6", marker="^", mec="k", ls="none", ms=8,
               label="footprint (touch-down $x_D$), numbered"),
    ]
    fig.legend(handles=handles, loc="outside lower center", fontsize=8, ncol=6, framealpha=0.9)
    fig.suptitle("Stick picture, one snapshot every %.3g s (cf. paper Fig. 5): walking downhill "
                 r"to the right on a slope $\gamma$ = %.3g rad = %.2f°" "\n%s"
                 % (every, gam, math.degrees(gam), _run_label(result)), fontsize=10)
    return fig


# --------------------------------------------------------------------------------------------
# Fig. 6

def _runs(mask):
    """(start, stop) index pairs of the runs of True in a boolean array."""
    m = np.asarray(mask, dtype=bool).astype(int)
    d = np.diff(np.r_[0, m, 0])
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def _friction_sign_changes(result, window=20e-3):
    """Per single support: the time the smoothed tangential force turns from - to +.

    For each run of single support of a leg (its flag 1, the other leg's 0), the tangential
    force of that leg is smoothed with a ``window`` running mean (the raw force chatters step
    to step) and the last negative -> positive crossing is returned.

    Returns
    -------
    list of (float, int)
        (time [s], leg 1|2), in time order.
    """
    t = np.asarray(result.t)
    flags = np.asarray(result.flags).astype(bool)
    Ft = np.asarray(result.Ft)
    n = _smooth_window(t, window)
    out = []
    for leg in (0, 1):
        for s, e in _runs(flags[:, leg] & ~flags[:, 1 - leg]):
            if e - s < 3 * n:
                continue
            ft = _running_mean(Ft[s:e, leg], n)
            up = np.flatnonzero((ft[:-1] < 0) & (ft[1:] > 0))
            if up.size:
                out.append((float(t[s + up[-1] + 1]), leg + 1))
    return sorted(out)


def fig_contact(result):
    """Contact forces against time, after the paper's Fig. 6 ("Contact forces").

    (a) Normal forces F_n1, F_n2 [N] (positive: the ground pushes the foot up, normal to the
    slope), their sum, and the walker's weight normal to the slope,
    (m_h + 2 m_l) g cos(gamma), as a dashed reference line. (b) Tangential forces F_t1, F_t2
    [N] (positive downhill, along the slope). The raw tangential force of the paper's central
    difference integration alternates in sign from one time step to the next while the foot
    sticks, so it is drawn faint, with a ``FT_SMOOTH`` running mean on top; black-edged
    markers show where that mean changes from negative to positive during a stance (the
    paper's "friction changes from the negative to positive"). Double supports are shaded.

    Parameters
    ----------
    result : pdw.sim.simulation.Result
        A simulated walk with recorded states and contact forces.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = _check_recorded(result, forces=True)
    Fn = np.asarray(result.Fn)
    Ft = np.asarray(result.Ft)
    W = result.params.weight
    fig = _new_figure(FIGSIZE["fig_contact"])
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    _shade_double_support(ax1, result)
    _shade_double_support(ax2, result, label=False)
    for leg in (0, 1):
        ax1.plot(t, Fn[:, leg], color=LEG_COLORS[leg], lw=1.1, label=r"$F_{n%d}$ (foot %d)" % (leg + 1, leg + 1))
    ax1.axhline(W, color="k", ls="--", lw=1, label="weight %.1f N" % W)
    ax1.set_ylabel("normal force [N]")
    ax1.set_title("(a) normal contact forces", loc="left", fontsize=10)
    ax1.legend(loc="upper right", fontsize=8, ncol=4, framealpha=0.9)
    ax1.set_ylim(bottom=min(0.0, Fn.min()) - 2, top=max(Fn.max(), W) * 1.15)
    n = _smooth_window(t, FT_SMOOTH)
    for leg in (0, 1):
        ax2.plot(t, Ft[:, leg], color=LEG_COLORS[leg], lw=0.3, alpha=0.25)
        ax2.plot(t, _running_mean(Ft[:, leg], n), color=LEG_COLORS[leg], lw=1.3,
                 label=r"$F_{t%d}$, %.3g ms running mean" % (leg + 1, FT_SMOOTH * 1e3))
    ax2.plot([], [], color="0.5", lw=0.6, alpha=0.5, label="raw (chatters every step)")
    changes = _friction_sign_changes(result)
    for j, (tc, leg) in enumerate(changes):
        ax2.plot(tc, 0, "o", color=LEG_COLORS[leg - 1], mec="k", ms=7, zorder=5,
                 label="friction − → + (mean)" if j == 0 else None)
    ax2.axhline(0, color="k", lw=0.6)
    ax2.set_ylabel("tangential force [N]\n(+ downhill)")
    ax2.set_xlabel("time t [s]")
    ax2.set_title("(b) tangential contact forces", loc="left", fontsize=10)
    ax2.legend(loc="upper right", fontsize=8, ncol=4, framealpha=0.9)
    sm = np.array([_running_mean(Ft[:, k], n) for k in (0, 1)])
    lim = 1.25 * max(np.abs(sm).max(), 1.0)
    ax2.set_ylim(-lim, lim)
    ax2.text(0.005, 0.03, "raw |F_t| reaches %.0f N (clipped)" % np.abs(Ft).max(),
             transform=ax2.transAxes, fontsize=8, color="0.3")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    ax2.set_xlim(t[0], t[-1])
    fig.suptitle("Contact forces (cf. paper Fig. 6)\n" + _run_label(result), fontsize=11)
    return fig


# --------------------------------------------------------------------------------------------
# Fig. 7

def fig_double_support(result, which=-1, margin=None):
    """Zoom on one double-support interval, after the paper's Fig. 7(a).

    Three panels against time [s] from a little before the touch-down of the landing leg to a
    little after the lift-off of the trailing leg: (a) normal forces of both feet [N] with the
    weight as reference; (b) tangential forces [N] (faint: raw; solid: ``FT_SMOOTH_ZOOM``
    running mean); (c) heights y_D of both contact points above the slope [mm] (negative:
    penetration into the ground). The double support (both support flags 1) is shaded and its
    duration annotated in ms, with its share of the walking cycle (time between successive
    touch-downs) and the paper's numbers for comparison; the title also gives how long both
    normal forces are positive (the flags can outlast the force: a foot may stop pushing
    before its lift-off condition, docs/model.md Eq. 18a, is met).

    Parameters
    ----------
    result : pdw.sim.simulation.Result
        A simulated walk with recorded states and contact forces.
    which : int
        Which double support, an index into `double_support_intervals` (``-1``: the last
        complete one, that is the last one that both starts with a touch-down and ends
        with a lift-off).
    margin : float, optional
        Time shown either side of the interval [s]; default max(0.6 * duration, 10 ms).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        If the run has no double support (or ``which`` is out of range).
    """
    t = _check_recorded(result, forces=True)
    dss = double_support_intervals(result)
    complete = [d for d in dss if d.leg_down is not None and d.leg_up is not None]
    if not dss:
        raise ValueError("the run has no double support (status %s, %d events)"
                         % (result.status, len(result.events)))
    if which == -1 and complete:
        ds = complete[-1]
    else:
        try:
            ds = dss[which]
        except IndexError:
            raise ValueError("which = %r is out of range: the run has %d double supports"
                             % (which, len(dss))) from None
    dur = ds.duration
    m = max(0.6 * dur, 0.01) if margin is None else float(margin)
    t0, t1 = ds.t_start - m, ds.t_end + m
    sel = (t >= t0) & (t <= t1)
    tt = t[sel]
    Fn = np.asarray(result.Fn)[sel]
    Ft = np.asarray(result.Ft)
    W = result.params.weight
    _, yd = _contact_points(result, np.asarray(result.x)[sel])

    fig = _new_figure(FIGSIZE["fig_double_support"])
    axs = fig.subplots(3, 1, sharex=True)
    for ax in axs:
        ax.axvspan(ds.t_start, ds.t_end, **_SHADE)
        ax.grid(alpha=0.3)
    for leg in (0, 1):
        c = LEG_COLORS[leg]
        axs[0].plot(tt, Fn[:, leg], color=c, lw=1.3, label=r"$F_{n%d}$" % (leg + 1))
    axs[0].plot(tt, Fn.sum(axis=1), color="0.35", lw=0.8, ls="-.", label=r"$F_{n1}+F_{n2}$")
    axs[0].axhline(W, color="k", ls="--", lw=1, label="weight %.1f N" % W)
    axs[0].set_ylabel("normal force [N]")
    axs[0].set_title("(a) normal forces", loc="left", fontsize=10)
    n = _smooth_window(t, FT_SMOOTH_ZOOM)
    for leg in (0, 1):
        c = LEG_COLORS[leg]
        axs[1].plot(tt, Ft[sel, leg], color=c, lw=0.4, alpha=0.3)
        axs[1].plot(tt, _running_mean(Ft[:, leg], n)[sel], color=c, lw=1.3,
                    label=r"$F_{t%d}$ (%.3g ms mean)" % (leg + 1, FT_SMOOTH_ZOOM * 1e3))
    axs[1].plot([], [], color="0.5", lw=0.6, alpha=0.5, label="raw")
    axs[1].axhline(0, color="k", lw=0.6)
    axs[1].set_ylabel("tangential force [N]\n(+ downhill)")
    axs[1].set_title("(b) tangential forces", loc="left", fontsize=10)
    for leg in (0, 1):
        axs[2].plot(tt, yd[:, leg] * 1e3, color=LEG_COLORS[leg], lw=1.3,
                    label=r"$y_{D%d}$ (foot %d)" % (leg + 1, leg + 1))
    axs[2].axhline(0, color="k", lw=1, label="ground surface")
    axs[2].set_ylabel("contact point height [mm]\n(< 0: penetration)")
    axs[2].set_title("(c) lowest points of the feet", loc="left", fontsize=10)
    axs[2].set_xlabel("time t [s]")
    lo = max(yd.min() * 1e3, -30.0)
    hi = min(yd.max() * 1e3, 15.0)
    axs[2].set_ylim(lo - 0.15 * (hi - lo), hi + 0.15 * (hi - lo))
    for ax in axs:
        for e in result.events:
            if t0 <= e.t <= t1:
                ax.axvline(e.t, color=LEG_COLORS[e.leg - 1],
                           ls="--" if e.kind == "touch_down" else ":", lw=1)
        ax.legend(loc="upper right", fontsize=8, ncol=2, framealpha=0.9)
    # annotate the interval
    cyc = _cycle_for(result, ds)
    ax = axs[0]
    ytop = max(Fn.max(), W)
    ax.set_ylim(min(0.0, Fn.min()) - 3, ytop * 1.35)
    ax.annotate("", xy=(ds.t_start, ytop * 1.12), xytext=(ds.t_end, ytop * 1.12),
                arrowprops=dict(arrowstyle="<->", color="k", lw=1))
    txt = "%.1f ms" % (dur * 1e3)
    if cyc:
        txt += " (%.2f %% of cycle %.4f s)" % (100 * dur / cyc, cyc)
    ax.text(0.5 * (ds.t_start + ds.t_end), ytop * 1.15, txt, ha="center", va="bottom",
            fontsize=9)
    how = []
    if ds.leg_down is not None:
        how.append("touch-down of leg %d at %.4f s (dashed)" % (ds.leg_down, ds.t_start))
    if ds.leg_up is not None:
        how.append("lift-off of leg %d at %.4f s (dotted)" % (ds.leg_up, ds.t_end))
    both = _runs((Fn > 0).all(axis=1))
    if both:
        a, b = max(both, key=lambda ab: ab[1] - ab[0])
        step = _record_step(t)
        both_txt = ("both F_n > 0 for %.1f ms (%.4f–%.4f s)"
                    % ((tt[b - 1] - tt[a] + step) * 1e3, tt[a], tt[b - 1]))
    else:
        both_txt = "the two normal forces never overlap"
    fig.suptitle("Double support phase (cf. paper Fig. 7(a)): flags both 1 for %s\n%s; %s\n"
                 "paper: 2.214–2.231 s, 17 ms, 2.71 %% of a 0.6275 s cycle.   %s"
                 % (txt, ", ".join(how), both_txt, _run_label(result)), fontsize=10)
    axs[-1].set_xlim(t0, t1)
    return fig


# --------------------------------------------------------------------------------------------

def save_all(result, outdir, progress=False) -> list[Path]:
    """Write every figure as PNG (``DPI``) and the animation as GIF into ``outdir``.

    Files: ``fig4_gait.png``, ``fig5_stick.png``, ``fig6_contact.png``,
    ``fig7_double_support.png`` (only when the run has a double support) and ``walker.gif``.
    The contact figures need recorded forces; without them they are skipped.

    Parameters
    ----------
    result : pdw.sim.simulation.Result
        A simulated walk.
    outdir : str or Path
        Output folder, created if missing.
    progress : bool or pdw.Progress
        A bar over the files on stderr when it is a terminal (`pdw.core.progress`).

    Returns
    -------
    list of pathlib.Path
        The files written, in the order above.
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    has_forces = np.size(result.Fn) > 0 and len(result.Fn) == len(result.t)
    jobs = [("fig4_gait.png", fig_gait), ("fig5_stick.png", fig_stick)]
    if has_forces:
        jobs.append(("fig6_contact.png", fig_contact))
        if double_support_intervals(result):
            jobs.append(("fig7_double_support.png", fig_double_support))
    written = []
    bar = progress_bar(progress, len(jobs) + 1, "figures")
    for name, fn in bar.track(jobs):
        fig = fn(result)
        path = outdir / name
        fig.savefig(path, dpi=DPI)
        written.append(path)
    written.append(animate(result, outdir / "walker.gif"))
    bar.update()
    return written
