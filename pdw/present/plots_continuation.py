"""Bifurcation diagrams of continued branches (`pdw.analysis.branch.Branch`, docs/continuation.md).

Stable parts solid, unstable dashed, one colour per period; bifurcations marked: period doubling
(circle), fold (square), Neimark-Sacker (diamond), end of the family (cross).
"""
from __future__ import annotations

import numpy as np

MARKERS = {"period_doubling": ("o", "period doubling"), "fold": ("s", "fold"),
           "neimark_sacker": ("D", "Neimark-Sacker"), "end": ("X", "end of the family")}
QUANTITIES = ("step_length", "period", "double_support", "max_multiplier", "z0", "speed")


def _quantity(branch, y, k=0):
    if y == "max_multiplier":
        return np.max(np.abs(branch.multipliers), axis=1)
    if y == "z0":
        return branch.orbit[:, k, 0]
    if y == "speed":
        return branch.step_length * branch.period_n / branch.period
    if y in ("step_length", "period", "double_support"):
        return getattr(branch, y)
    raise ValueError("y must be one of %s, got %r" % (", ".join(QUANTITIES), y))


def _bif_y(branch, bif, y):
    """The plotted quantity at a bifurcation: its own gait's where known, else interpolated
    between its neighbouring points."""
    if y == "max_multiplier" and bif.multipliers is not None:
        return float(np.max(np.abs(bif.multipliers)))
    if y == "z0" and bif.z is not None:
        return float(bif.z[0])
    if bif.gait is not None and y in ("step_length", "period", "double_support"):
        return float(getattr(bif.gait, y))
    i = min(bif.index, len(branch) - 2) if len(branch) > 1 else 0
    q = _quantity(branch, y)
    if len(branch) == 1:
        return q[0]
    v0, v1 = branch.values[i], branch.values[i + 1]
    w = 0.0 if v1 == v0 else np.clip((bif.value - v0) / (v1 - v0), 0, 1)
    return q[i] + w * (q[i + 1] - q[i])


def plot_branches(branches, ax=None, y="step_length", x_scale=1.0, x_label=None, title=None,
                  path=None):
    """Draw branches on ``ax`` (a new figure if None) and return the axes.

    Parameters
    ----------
    branches : list of Branch
    y : str
        One of `QUANTITIES` (``z0``: the first section coordinate; ``max_multiplier``: the
        largest Floquet multiplier's modulus).
    x_scale : float
        Multiply the parameter by this on the axis (e.g. 180/pi for degrees).
    path : str or Path, optional
        Save the figure there (PNG, 150 dpi).
    """
    import matplotlib
    if ax is None:
        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4.2), layout="constrained")
    colours = {}
    seen = set()
    for br in branches:
        c = colours.setdefault(br.period_n, "C%d" % len(colours))
        origin = br.settings.get("origin")
        # y = z0 draws every point of a period-n orbit (the diagram's n curves)
        for k in range(br.period_n if y == "z0" else 1):
            x = br.values * x_scale
            q = _quantity(br, y, k)
            if origin is not None and y == "z0":       # start at the period doubling
                x = np.concatenate([[origin[0] * x_scale], x])
                orb = np.atleast_2d(origin[1])
                q = np.concatenate([[orb[k % len(orb), 0]], q])
            stable = np.concatenate([[br.stable[0]], br.stable]) if len(x) > len(br) \
                else br.stable
            start = 0
            for i in range(1, len(x) + 1):
                if i == len(x) or stable[i] != stable[start]:
                    seg = slice(start, min(i + 1, len(x)))
                    lab = "period %d" % br.period_n if br.period_n not in seen else None
                    seen.add(br.period_n)
                    ax.plot(x[seg], q[seg], "-" if stable[start] else "--", color=c, lw=1.4,
                            label=lab)
                    start = i
        for b in br.bifurcations:
            mk, name = MARKERS[b.kind]
            lab = name if ("bif", b.kind) not in seen else None
            seen.add(("bif", b.kind))
            ax.plot([b.value * x_scale], [_bif_y(br, b, y)], mk, color="k", mfc="w", ms=7,
                    label=lab, zorder=5)
        if br.settings.get("log"):
            ax.set_xscale("log")
    ax.set_xlabel(x_label or (branches[0].parameter if branches else ""))
    ax.set_ylabel(y.replace("_", " "))
    if title:
        ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    if path is not None:
        ax.figure.savefig(path, dpi=150)
    return ax
