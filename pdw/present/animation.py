"""The animated GIF of a walk: the walker in the world frame, the camera following the hip."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .figure_kit import (
    FIGSIZE,
    GIF_DPI,
    LEG_COLORS,
    _check_recorded,
    _leg_polyline,
    _new_figure,
    _to_world,
    _touch_downs,
    draw_ground,
    ground_height,
)

# --------------------------------------------------------------------------------------------
# animation

def animate(result, path, fps=25, duration=None, max_playback=12.0):
    """Write an animated GIF of the walker, the camera following the hip.

    World frame (the slope descends to the right at gamma), equal aspect, a 1.4 m wide
    window centred on the hip; legs in their colours (thick while in support), arc feet,
    hip dot, hatched ground, footprints appearing at their touch-downs, and a clock that
    also says "double support" when both feet are in support.

    Parameters
    ----------
    result : pdw.sim.simulation.Result
        A simulated walk with recorded states.
    path : str or Path
        The GIF file to write (parent folders are created).
    fps : float
        Frames per second of the GIF.
    duration : float, optional
        Playback length [s]. Default: the simulated time (real time), but at most
        ``max_playback`` seconds (longer runs play faster), which keeps the file small.
    max_playback : float
        See ``duration``.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    from matplotlib.animation import PillowWriter

    t = _check_recorded(result)
    if fps <= 0:
        raise ValueError("fps must be > 0, got %r" % (fps,))
    x = np.asarray(result.x)
    flags = np.asarray(result.flags)
    p = result.params
    gam = p.gamma
    span = float(t[-1] - t[0])
    play = min(span, float(max_playback)) if duration is None else float(duration)
    if play <= 0:
        raise ValueError("duration must be > 0, got %r" % (duration,))
    n_frames = max(2, int(round(play * fps)) + 1)
    times = np.linspace(t[0], t[-1], n_frames)
    idx = np.clip(np.searchsorted(t, times), 0, len(t) - 1)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)

    fig = _new_figure(FIGSIZE["animate"])
    ax = fig.subplots()
    ax.set_aspect("equal")
    X_lo = min(x[:, 0].min(), 0.0) - 1.0
    X_hi = x[:, 0].max() + 1.0
    draw_ground(ax, result, X_lo, X_hi, 0.3, gam)      # its shape and patches
    legs = [ax.plot([], [], color=LEG_COLORS[k], lw=2.5, solid_capstyle="round",
                    label="leg %d" % (k + 1))[0] for k in (0, 1)]
    feet = [ax.plot([], [], color=LEG_COLORS[k], lw=2.5)[0] for k in (0, 1)]
    hip, = ax.plot([], [], "o", color="k", ms=7, zorder=5)
    tds = _touch_downs(result)
    prints = [ax.plot([], [], "^", color=LEG_COLORS[k], mec="k", ms=7, ls="none")[0] for k in (0, 1)]
    clock = ax.text(0.02, 0.95, "", transform=ax.transAxes, va="top", fontsize=10,
                    family="monospace")
    ax.set_title(r"walker on a %.3g rad slope (variant %r); thick leg: support"
                 % (gam, result.variant), fontsize=9)
    ax.legend(loc="upper right", fontsize=7, framealpha=0.9)
    ax.set_xlabel("x [m]", fontsize=8)
    ax.set_ylabel("y [m]", fontsize=8)
    ax.tick_params(labelsize=7)
    half_w = 0.7

    def update(i):
        s = x[i]
        for k in (0, 1):
            (lx, ly), (fx, fy) = _leg_polyline(s, k, p)
            legs[k].set_data(*_to_world(lx, ly, gam))
            feet[k].set_data(*_to_world(fx, fy, gam))
            lw = 3.0 if flags[i, k] else 1.6
            legs[k].set_linewidth(lw)
            feet[k].set_linewidth(lw)
            done = [e for e in tds if e.leg == k + 1 and e.t <= t[i]]
            if done:
                prints[k].set_data(*_to_world(np.array([e.x_D for e in done]),
                                              np.array([ground_height(result, e.x_D)
                                                        for e in done]), gam))
            else:
                prints[k].set_data([], [])
        hx, hy = _to_world(s[0], s[1], gam)
        hip.set_data([hx], [hy])
        gy0 = _to_world(s[0], ground_height(result, s[0]), gam)[1]
        ax.set_xlim(hx - half_w, hx + half_w)
        ax.set_ylim(gy0 - 0.12, gy0 + 0.62)
        clock.set_text("t = %5.2f s%s" % (t[i], "  double support" if flags[i].all() else ""))

    writer = PillowWriter(fps=fps)
    with writer.saving(fig, str(path), dpi=GIF_DPI):
        for i in idx:
            update(int(i))
            writer.grab_frame()
    return path
