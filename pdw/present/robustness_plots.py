"""Figures of the robustness measures (docs/robustness.md): a measure along a parameter axis
(`plot_spec`), the trials of one `max_step`, the survival curve of one `first_passage`."""
from __future__ import annotations

import math

import numpy as np

_MAIN = {"max_step": ("height", "largest step height [mm]", 1e3),
         "gait_sensitivity": ("norm", "gait sensitivity norm", 1.0),
         "first_passage": ("mfpt", "mean first-passage time [steps]", 1.0),
         "markov_chain": ("mfpt", "MFPT, Markov chain [steps]", 1.0)}


def plot_spec(spec, rows, results, path):
    """The figure of a robustness spec's run: the measure against the axis (with its bracket
    or confidence interval), or, for one point, that result's own figure. Returns ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    key, label, scale = _MAIN[spec.measure]
    if spec.parameter is not None:
        x = np.array([r["value"] for r in rows], dtype=float)
        y = np.array([r[key] for r in rows], dtype=float) * scale
        lo = hi = None
        if spec.measure == "max_step":
            hi = np.array([min(r["bracket_hi"], 1e9) for r in rows]) * scale
            lo = np.array([r["bracket_lo"] for r in rows]) * scale
        elif spec.measure == "first_passage":
            lo = np.array([r["ci_lo"] for r in rows])
            hi = np.array([r["ci_hi"] for r in rows])
        ax.plot(x, y, "o-", color="C0")
        if lo is not None:
            ax.fill_between(x, lo, np.where(np.isfinite(hi), hi, np.nan), color="C0",
                            alpha=0.2, lw=0)
        ax.set_xlabel(spec.parameter)
        ax.set_ylabel(label)
        if spec.measure in ("first_passage", "markov_chain"):
            ax.set_yscale("log")
    else:
        _single(ax, spec.measure, results[0], label, scale)
    ax.set_title(spec.title, fontsize=10)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _single(ax, measure, res, label, scale):
    if measure == "max_step":
        t = res.trials
        h = np.array([x["height"] for x in t]) * scale
        ok = np.array([x["survived"] and x["returned"] for x in t])
        ax.plot(h[ok], np.ones(ok.sum()), "o", color="C2", label="survived and returned")
        ax.plot(h[~ok], np.zeros((~ok).sum()), "x", color="C3", label="failed")
        ax.axvline(res.height * scale, color="k", lw=0.8)
        ax.set_xlabel("step height [mm] (%s)" % res.direction)
        ax.set_yticks([0, 1])
        ax.legend(fontsize=8)
    elif measure == "gait_sensitivity":
        names = list(res.per_indicator)
        ax.bar(names, [res.per_indicator[n] for n in names], color="C0")
        ax.set_ylabel("norm of each indicator (per metre of floor height)")
    elif measure == "first_passage":
        s = np.sort(res.steps[res.failed])
        n = res.walkers
        surv = 1.0 - np.arange(1, len(s) + 1) / n
        ax.step(s, surv, where="post", color="C0", label="walkers still walking")
        k = np.arange(0, res.max_steps + 1)
        if res.failures and math.isfinite(res.mfpt):
            ax.plot(k, (1 - 1 / res.mfpt) ** k, "--", color="C1",
                    label="geometric, MFPT %.4g" % res.mfpt)
        ax.set_xlabel("steps")
        ax.set_ylabel("fraction walking")
        ax.set_yscale("log")
        ax.legend(fontsize=8)
    else:
        ax.hist(res.m, bins=40, color="C0")
        ax.set_xlabel("expected steps to failure from each cell")
        ax.set_ylabel("cells")
