"""The figure of a parameter study (``pdw sweep``): L, P, v and double support against the
first axis, one line per value of the second (docs/studies.md); the points without a gait
(the walker fell, or the run diverged) marked along the bottom of every panel."""
from __future__ import annotations

import os
import pathlib

import numpy as np

#: How points without steady values are marked (at the bottom of each panel): status ->
#: (marker, colour, legend label).
NO_GAIT = {"fell": ("x", "tab:red", "fell (no gait)"), "diverged": ("+", "0.3", "diverged")}
_PANELS = (("L", "step length L [m]", 1.0), ("P", "step period P [s]", 1.0),
           ("v", "step velocity v [m/s]", 1.0), ("ds_fraction", "double support [% of cycle]", 100.0))


def plot_study(study, rows, path):
    """L, P, v and double support against the first axis (one line per value of the second);
    points that are not period-one are drawn hollow; points whose walker fell (or whose run
    diverged) as `NO_GAIT` markers along the bottom of every panel, in the legend; the paper's
    end points ([paper] table) as black markers. Returns the path."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = study.axis_names
    x_name = names[0]
    fig, axs = plt.subplots(2, 2, figsize=(9, 6.5), constrained_layout=True)
    groups = [None] if len(names) == 1 else sorted({r[names[1]] for r in rows})
    for gv in groups:
        sel = [r for r in rows if gv is None or r[names[1]] == gv]
        x = np.array([r[x_name] for r in sel], dtype=float)
        per1 = np.array([r["gait"] == "period-1" for r in sel])
        label = None if gv is None else "%s = %g" % (names[1], gv)
        for ax, (col, ylabel, scale) in zip(axs.flat, _PANELS):
            y = np.array([np.nan if r[col] == "" else r[col] for r in sel], dtype=float) * scale
            line, = ax.plot(x[per1], y[per1], "o-", ms=4, label=label)
            if (~per1).any():
                ax.plot(x[~per1], y[~per1], "o", mfc="none", color=line.get_color(), ms=6)
            ax.set_xlabel(x_name)
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3)
    for status, (marker, colour, label) in NO_GAIT.items():
        xs = np.array([r[x_name] for r in rows if r["status"] == status], dtype=float)
        if len(xs):
            for ax in axs.flat:
                ax.plot(xs, np.full(len(xs), 0.03), marker, color=colour, ms=8, mew=1.8, ls="",
                        transform=ax.get_xaxis_transform(), clip_on=False,
                        label="%s: %d point%s" % (label, len(xs), "s" * (len(xs) != 1)))
    paper = study.paper
    if paper:
        at = paper.get("at", {})
        lo, hi = float(np.min(study.axes[0][1])), float(np.max(study.axes[0][1]))
        xr = paper.get("range", [lo, hi])
        for ax, (col, _, scale) in zip(axs.flat, _PANELS):
            if col in paper:
                ax.plot(xr, np.array(paper[col], dtype=float) * scale, "k*--", ms=9, lw=0.8,
                        label="paper" + (" (%s)" % ", ".join("%s = %g" % kv for kv in at.items())
                                         if at else ""))
    handles, labels = axs.flat[0].get_legend_handles_labels()
    for ax in axs.flat:
        h, lab = ax.get_legend_handles_labels()
        if len(h) > len(handles):
            handles, labels = h, lab
    if handles:
        axs.flat[0].legend(handles, labels, fontsize=7)
    fig.suptitle("%s\n(%s, variant %s, %s, %s)" % (study.title, study.preset, study.variant,
                                                   study.method, study.run["mode"]), fontsize=9)
    path = pathlib.Path(path)
    tmp = path.with_name("." + path.stem + ".%d.tmp%s" % (os.getpid(), path.suffix))
    fig.savefig(tmp, dpi=110)         # atomic: a reader sees the old figure or the new one
    plt.close(fig)
    os.replace(tmp, path)
    return path
