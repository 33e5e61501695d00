"""Bifurcation diagrams of continued branches (`pdw.analysis.bifurcation.branch.Branch`, docs/continuation.md).

Stable parts solid, unstable dashed, one colour per branch; bifurcations marked and labelled
(AUTO-style, e.g. PD1): period doubling (circle), fold (square), Neimark-Sacker (diamond),
branch point (triangle), end of the family (cross), user event (star); a bifurcation that was
only detected, not located, is drawn hollow grey with its bracket as a horizontal bar. Both
axes carry units; y is a named quantity (`QUANTITIES`). `plot_curves` draws two-parameter
curves (`pdw.continue_bifurcation`).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..core.params import Params

MARKERS = {"period_doubling": ("o", "period doubling"), "fold": ("s", "fold"),
           "neimark_sacker": ("D", "Neimark-Sacker"), "end": ("X", "end of the family"),
           "branch_point": ("^", "branch point"), "event": ("*", "user event")}
#: y quantities: (axis name, unit). ``z0`` is the first section coordinate (every point of a
#: period-n orbit), named by the model's section.
QUANTITIES = {"step_length": ("step length", "m"), "period": ("period of the cycle", "s"),
              "double_support": ("double support", "s"),
              "max_multiplier": ("largest |Floquet multiplier|", "-"), "speed": ("speed", "m/s"),
              "z0": ("first section coordinate", "rad")}
_Z0 = {"hybrid": "stance leg angle theta_st after heel strike",
       "continuous": "trailing leg angle theta1 at touch-down"}


def _unit(parameter):
    f = {f.name: f for f in dataclasses.fields(Params)}.get(parameter)
    return f.metadata.get("unit", "") if f is not None else ""


def x_axis_label(parameter, x_scale=1.0, unit=None):
    """'gamma [deg]' (x_scale 180/pi on gamma), 'd_n [N s/m^2.5]', 'k_n [N/m^1.5 x 1e-05]',
    'contact.d [N s/m]' (``unit``: the branch's own, e.g. a contact parameter's, whose unit
    depends on the law; default the `Params` field's)."""
    u = unit or _unit(parameter)
    if u == "rad" and abs(x_scale - 180 / np.pi) < 1e-9:
        return "%s [deg]" % parameter
    if x_scale != 1.0:
        return "%s [%s x %g]" % (parameter, u or "-", x_scale)
    return "%s [%s]" % (parameter, u or "-")


def y_axis_label(y, model=""):
    name, unit = QUANTITIES[y]
    if y == "z0":
        name = _Z0.get(model, name)
    return "%s [%s]" % (name, unit)


def _quantity(branch, y, k=0):
    if y == "max_multiplier":
        return np.max(np.abs(branch.multipliers), axis=1)
    if y == "z0":
        return branch.orbit[:, k, 0]
    if y == "speed":
        return branch.step_length * branch.period_n / branch.period
    if y in ("step_length", "period", "double_support"):
        return getattr(branch, y)
    from ..core.errors import InvalidInputError
    raise InvalidInputError("y must be one of %s, got %r" % (", ".join(QUANTITIES), y))


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
                  path=None, labels=None):
    """Draw branches on ``ax`` (a new figure if None) and return the axes.

    Parameters
    ----------
    branches : list of Branch
        Overlaid, one colour each (C0, C1, ...).
    y : str
        One of `QUANTITIES`: step_length [m], period [s], double_support [s],
        max_multiplier [-], speed [m/s], z0 (the first section coordinate [rad]; every point
        of a period-n orbit).
    x_scale : float
        Multiply the parameter by this on the axis (180/pi: degrees for an angle).
    x_label : str, optional
        Default: the parameter with its unit (`x_axis_label`).
    labels : list of str, optional
        Legend entries, one per branch (default "period n").
    path : str or Path, optional
        Save the figure there (PNG, 150 dpi).
    """
    import matplotlib
    if y not in QUANTITIES:
        from ..core.errors import InvalidInputError
        raise InvalidInputError("y must be one of %s, got %r" % (", ".join(QUANTITIES), y))
    if ax is None:
        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4.2), layout="constrained")
    seen = set()
    j0 = getattr(ax, "_pdw_branches", 0)     # branches already drawn here: the next colours
    for j, br in enumerate(branches):
        c = "C%d" % ((j0 + j) % 10)
        name = labels[j] if labels is not None else "period %d" % br.period_n
        origin = br.settings.get("origin")
        named = False
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
                    ax.plot(x[seg], q[seg], "-" if stable[start] else "--", color=c, lw=1.4,
                            label=None if named else name)
                    named = True
                    start = i
        for b in br.bifurcations:
            mk, bname = MARKERS.get(b.kind, ("*", b.kind))
            located = getattr(b, "located", True)
            key = ("bif", b.kind, located)
            lab = None if key in seen else (bname if located else bname + " (not located)")
            seen.add(key)
            yb = _bif_y(br, b, y)
            if not located and b.bracket is not None:
                ax.plot([b.bracket[0] * x_scale, b.bracket[1] * x_scale], [yb, yb], "-",
                        color="0.5", lw=3, alpha=0.5, zorder=4)
            ax.plot([b.value * x_scale], [yb], mk, color="k" if located else "0.5", mfc="w",
                    ms=7, label=lab, zorder=5)
            if getattr(b, "label", ""):
                ax.annotate(b.label, (b.value * x_scale, yb), textcoords="offset points",
                            xytext=(4, 5), fontsize=7)
        if br.settings.get("log"):
            ax.set_xscale("log")
    ax._pdw_branches = j0 + len(branches)
    ax.set_xlabel(x_label or (x_axis_label(branches[0].parameter, x_scale,
                                           branches[0].settings.get("unit"))
                               if branches else ""))
    ax.set_ylabel(y_axis_label(y, branches[0].model if branches else ""))
    if title:
        ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    if path is not None:
        ax.figure.savefig(path, dpi=150)
    return ax


def plot_curves(curves, ax=None, x_scale=1.0, y_scale=1.0, labels=None, title=None,
                path=None):
    """Two-parameter curves (`pdw.BifurcationCurve`): the second parameter on x, the first
    (the bifurcation's own) on y, with units, one colour each; returns the axes."""
    import matplotlib
    if ax is None:
        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4.2), layout="constrained")
    for j, cv in enumerate(curves):
        name = labels[j] if labels is not None else "%s curve" % cv.kind.replace("_", " ")
        ax.plot(cv.values[:, 1] * x_scale, cv.values[:, 0] * y_scale, "-", color="C%d" % j,
                lw=1.6, label=name)
    if curves:
        units = getattr(curves[0], "units", ("", ""))
        ax.set_xlabel(x_axis_label(curves[0].parameters[1], x_scale, units[1]))
        ax.set_ylabel(x_axis_label(curves[0].parameters[0], y_scale, units[0]))
    if title:
        ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    if path is not None:
        ax.figure.savefig(path, dpi=150)
    return ax
