"""Robustness studies of issue 22 item 6 on the compliant model (docs/robustness.md, "Studies"):
the largest step-down against k_hip, the slope, k_n and d_n; the MFPT against the roughness for
three k_hip on a hard and a soft ground; a hard floor -> soft mat -> hard floor transition
(steps to re-converge, falls, the survival region in (mat k_n, k_hip)); k_hip and d_hip tuned
by scipy.optimize for the largest step-down.

Run: `make study` (or `.venv/bin/python benchmarks/robustness_compliant.py [--quick]
[--update-docs]`). Writes robustness_compliant.txt under out/benchmarks/results/ and
robustness_compliant*.png under out/benchmarks/figures/ (--update-docs: benchmarks/results/,
docs/figures/). --quick: fewer points and walkers.
"""
import os
import sys
import time

import numpy as np
from _results import FIGURES, publish

import pdw
from pdw.analysis.robust import robustness_continuous as RC

QUICK = "--quick" in sys.argv
BASE = pdw.Params.paper_steady()
BUDGET = 40


def with_(**kw):
    return BASE.replace(**kw)


def gaits_along(name, values, base=None):
    """Continuous gaits along one parameter, each from the previous one (one branch): from the
    base value outward on each side, in steps of at most 10 % of the base value (a jump of
    0.45 in k_hip from the base gait finds no gait; small steps do)."""
    base = BASE if base is None else base
    v0 = getattr(base, name)
    g0 = pdw.find_gait(base)
    out = {}
    for side in ([v for v in values if v < v0][::-1], [v for v in values if v >= v0]):
        prev, at = g0, v0
        for v in sorted(side, key=lambda v: abs(v - v0)):
            g = prev
            n = max(1, int(np.ceil(abs(v - at) / (0.1 * abs(v0)))))
            try:
                for u in np.linspace(at, v, n + 1)[1:]:
                    g = pdw.find_gait(base.replace(**{name: float(u)}), guess=g)
                prev, at = g, v
            except pdw.PdwError:
                g = None
            out[v] = g
    return out


def max_step_axis(name, values, lines, scale=1.0):
    gaits = gaits_along(name, values)
    rows = []
    for v in values:
        g = gaits[v]
        if g is None:
            rows.append((v, np.nan, np.nan, np.nan))
            continue
        m = pdw.max_step(with_(**{name: v}), model="continuous", gait=g, budget=BUDGET,
                         h_tol=5e-5)
        rows.append((v, m.height * 1e3 if m.stable else 0.0, max(abs(g.multipliers)),
                     g.period))
    lines += ["", "%-10s %14s %10s %10s" % (name, "max down [mm]", "|mu|max", "period [s]")]
    lines += ["%-10.4g %14.3f %10.4f %10.4f" % r for r in rows]
    return np.array(rows)


def mfpt_table(lines):
    walkers = 20 if QUICK else 100
    sig = [0.0012, 0.0018] if QUICK else [0.0012, 0.0015, 0.0018]
    khips = (0.5, 0.95, 1.5)
    out = {}
    lines += ["", "MFPT [steps] on Ground.random(sigma, correlation 0.1 m), %d walkers each, "
              "censored at 300 steps" % walkers]
    for ground, k_n in (("hard", 2.5e5), ("soft", 0.5e5)):
        gaits = gaits_along("k_hip", khips, base=with_(k_n=k_n))
        for k in khips:
            P = with_(k_n=k_n, k_hip=k)
            g = gaits[k]
            if g is None:
                lines.append("%s ground k_n %.3g, k_hip %.2f: no gait" % (ground, k_n, k))
                continue
            for s in sig:
                c0 = time.process_time()
                fp = pdw.first_passage(P, model="continuous", ground=pdw.Ground.random(s, 0.1),
                                       walkers=walkers, max_steps=300, gait=g, seed=1)
                out[(ground, k, s)] = fp
                lines.append("%s k_n %.3g, k_hip %.2f, sigma %.1f mm: %s (%.0f s CPU)"
                             % (ground, k_n, k, s * 1e3, fp, time.process_time() - c0))
                print(lines[-1], flush=True)
    return out, sig


def mat_transition(lines):
    """Hard floor, a soft mat on s in [1, 2.5] m, hard floor again: 30 steps from the gait."""
    mats = [5e3, 1e4, 2e4, 5e4] if QUICK else [2e3, 5e3, 1e4, 2e4, 5e4]
    khips = [0.5, 0.95, 1.5] if QUICK else [0.5, 0.75, 0.95, 1.25, 1.5]
    grid = np.zeros((len(khips), len(mats)))
    lines += ["", "Soft mat (k_n, d_n = 10 k_n) on s in [1, 2.5] m of a hard floor (the "
              "preset's), 30 steps from the gait: steps after the mat until the step length "
              "and time are within 1e-3 of the gait's (F: fell)"]
    lines.append("%-8s" % "k_hip" + "".join("%12s" % ("mat %.0e" % m) for m in mats))
    gaits = gaits_along("k_hip", khips)
    for i, k in enumerate(khips):
        P = with_(k_hip=k)
        g = gaits[k]
        if g is None:
            grid[i] = np.nan
            lines.append("%-8.2f no gait" % k)
            continue
        row = []
        for j, m in enumerate(mats):
            ground = pdw.Ground.flat(patches=[pdw.Patch.make(1.0, 2.5, k_n=m, d_n=10 * m)])
            st, L, T = RC.walk(P, g, ground, 30)
            fell = st not in ("walked", "periodic")
            if fell:
                grid[i, j] = -1
                row.append("F")
                continue
            # the step index past the mat: footprints are cumulative step lengths from 0
            x = np.cumsum(L)
            past = int(np.searchsorted(x, 2.5)) + 1
            ret, kk = pdw.analysis.robust.robustness.returned(L[past:], T[past:], g.step_length,
                                                       g.period, 1e-3)
            grid[i, j] = kk if ret else 99
            row.append("%d" % kk if ret else ">%d" % (len(L) - past))
        lines.append("%-8.2f" % k + "".join("%12s" % r for r in row))
    return grid, mats, khips


def tune(lines):
    """k_hip (and d_hip) maximizing the largest step-down, by scipy.optimize on pdw.max_step:
    k_hip alone on a hard and a soft ground (minimize_scalar, bounded), and (k_hip, d_hip)
    together on the preset's ground (Nelder-Mead with bounds)."""
    from scipy.optimize import minimize, minimize_scalar

    def make_neg(base, name_vals):
        g0 = pdw.find_gait(base)
        memo = {}

        def neg(x):
            x = np.atleast_1d(x)
            kw = {n: float(v) for n, v in zip(name_vals, x)}
            key = tuple(round(v, 6) for v in kw.values())
            if key not in memo:
                try:
                    P = base.replace(**kw)
                    g = gait_towards(base, g0, kw)
                    memo[key] = -pdw.max_step(P, model="continuous", gait=g, budget=BUDGET,
                                              h_tol=5e-5).height
                except pdw.PdwError:
                    memo[key] = 0.0
            return memo[key]
        return neg

    lines += ["", "k_hip maximizing the compliant walker's step-down on a given ground (scipy "
              "minimize_scalar, bounded on [0.5, 1.5], xatol 0.01, on pdw.max_step):"]
    for ground, k_n in (("hard", 2.5e5), ("preset", BASE.k_n), ("soft", 0.5e5)):
        c0 = time.process_time()
        neg = make_neg(with_(k_n=k_n), ("k_hip",))
        res = minimize_scalar(neg, bounds=(0.5, 1.5), method="bounded",
                              options=dict(xatol=0.01, maxiter=8 if QUICK else 20))
        lines.append("  %s ground (k_n %.3g): k_hip = %.3f, step-down %.3f mm (k_hip 0.95: "
                     "%.3f mm; 0.5: %.3f mm; 1.5: %.3f mm), %d evaluations, %.0f s CPU"
                     % (ground, k_n, res.x, -res.fun * 1e3, -neg(0.95) * 1e3, -neg(0.5) * 1e3,
                        -neg(1.5) * 1e3, res.nfev, time.process_time() - c0))
        print(lines[-1], flush=True)
    c0 = time.process_time()
    neg = make_neg(BASE, ("k_hip", "d_hip"))
    res = minimize(neg, x0=[0.95, 0.010], method="Nelder-Mead",
                   bounds=[(0.5, 1.5), (0.0, 0.02)],
                   options=dict(maxfev=12 if QUICK else 30, xatol=0.01, fatol=2e-5,
                                initial_simplex=[[0.95, 0.010], [0.6, 0.010], [0.95, 0.005]]))
    lines += ["", "k_hip, d_hip maximizing the compliant walker's step-down (scipy Nelder-Mead "
              "with bounds [0.5, 1.5] x [0, 0.02] on pdw.max_step, %d evaluations): k_hip = "
              "%.4f, d_hip = %.5f, step-down %.3f mm (paper_steady's k_hip 0.95, d_hip 0.010: "
              "%.3f mm), %.0f s CPU"
              % (res.nfev, res.x[0], res.x[1], -res.fun * 1e3, -neg([0.95, 0.010]) * 1e3,
                 time.process_time() - c0)]


def gait_towards(base, g0, kw):
    """The gait at base.replace(**kw), followed from g0 (at base) in 5 steps."""
    g = g0
    for f in np.linspace(0.2, 1.0, 5):
        u = {n: getattr(base, n) + f * (v - getattr(base, n)) for n, v in kw.items()}
        g = pdw.find_gait(base.replace(**u), guess=g)
    return g


def main():
    t0, c0 = time.time(), time.process_time()
    lines = ["Robustness of the compliant walker (Params.paper_steady(), rodas4 rtol 1e-8), "
             "max_step budget %d steps, return_tol 1e-3" % BUDGET,
             "load average at start %.2f %.2f %.2f" % os.getloadavg()]
    n = 4 if QUICK else 6
    ax = {"k_hip": np.linspace(0.5, 1.5, n), "gamma": np.linspace(0.012, 0.035, n),
          "k_n": np.geomspace(0.5e5, 2.5e5, n), "d_n": np.geomspace(0.5e6, 2.5e6, n)}
    rows = {}
    for k, v in ax.items():
        c1 = time.process_time()
        rows[k] = max_step_axis(k, v, lines)
        lines.append("(%.0f s CPU)" % (time.process_time() - c1))
        print("\n".join(lines[-9:]), flush=True)
    c1 = time.process_time()
    grid, mats, khips = mat_transition(lines)
    lines.append("(%.0f s CPU)" % (time.process_time() - c1))
    print("\n".join(lines[-8:]), flush=True)
    tune(lines)
    mf, sig = mfpt_table(lines)
    lines.append("wall %.0f s, CPU %.0f s, load average at end %.2f %.2f %.2f"
                 % (time.time() - t0, time.process_time() - c0, *os.getloadavg()))
    publish("robustness_compliant.txt", lines)
    figures(rows, grid, mats, khips, mf, sig)


def figures(rows, grid, mats, khips, mf, sig):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    FIGURES.mkdir(parents=True, exist_ok=True)
    fig, axs = plt.subplots(1, 4, figsize=(13, 3.3))
    for a, (name, r) in zip(axs, rows.items()):
        a.plot(r[:, 0], r[:, 1], "o-")
        a.set_xlabel(name)
        if name in ("k_n", "d_n"):
            a.set_xscale("log")
        a.grid(alpha=0.3)
    axs[0].set_ylabel("max step-down [mm]")
    fig.suptitle("Compliant walker (paper_steady): largest step-down survived and returned "
                 "from", fontsize=10)
    fig.tight_layout()
    fig.savefig(FIGURES / "robustness_compliant_max_step.png", dpi=110)
    plt.close(fig)
    fig, axs = plt.subplots(1, 2, figsize=(10, 3.6))
    for ground, a in zip(("hard", "soft"), axs):
        for k in (0.5, 0.95, 1.5):
            if (ground, k, sig[0]) not in mf:
                continue
            y = np.array([mf[(ground, k, s)].mfpt for s in sig])
            lo = np.array([mf[(ground, k, s)].ci[0] for s in sig])
            hi = np.array([mf[(ground, k, s)].ci[1] for s in sig])
            a.errorbar(np.array(sig) * 1e3, y, yerr=[y - lo, np.where(np.isfinite(hi), hi, y)
                                                     - y], marker="o", capsize=3,
                       label="k_hip %.2f" % k)
        a.set_yscale("log")
        a.set_title("%s ground" % ground, fontsize=10)
        a.set_xlabel("ground roughness sigma [mm]")
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    axs[0].set_ylabel("mean first-passage time [steps]")
    fig.tight_layout()
    fig.savefig(FIGURES / "robustness_compliant_mfpt.png", dpi=110)
    plt.close(fig)
    fig_mat(grid, mats, khips)


def fig_mat(grid, mats, khips):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, a = plt.subplots(figsize=(5.5, 3.8))
    show = np.where(grid < 0, np.nan, np.minimum(grid, 40))
    im = a.imshow(show, origin="lower", aspect="auto", cmap="viridis")
    for i in range(len(khips)):
        for j in range(len(mats)):
            v = grid[i, j]
            a.text(j, i, "-" if np.isnan(v) else "F" if v < 0 else "%d" % v, ha="center",
                   va="center", color="w" if v >= 0 else "k", fontsize=8)
    a.set_xticks(range(len(mats)), ["%.0e" % m for m in mats])
    a.set_yticks(range(len(khips)), ["%.2f" % k for k in khips])
    a.set_xlabel("mat k_n [N/m^1.5] (d_n = 10 k_n)")
    a.set_ylabel("k_hip [N m/rad]")
    a.set_title("hard -> soft mat -> hard: steps to re-converge (F: fell, -: no gait)",
                fontsize=9)
    fig.colorbar(im, ax=a)
    fig.tight_layout()
    fig.savefig(FIGURES / "robustness_compliant_mat.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
