"""k_hip (and d_hip) tuned for the mean first-passage time with scipy.optimize on a common-random-
numbers objective (issue 22 item 6; docs/terrain.md, "Tuned for the MFPT"; docs/robustness.md,
"Tuning for the MFPT"): `pdw.analysis.robust.tuning.tune_first_passage`.

Hybrid walker (cheap): i.i.d. step heights N(0, 1.6 mm), 100 walkers censored at 300 steps.
The objective on each of SETS seed sets on a k_hip grid (its roughness and where each statistic
peaks), minimize_scalar (bounded, [0.5, 1.5]) on each set, every optimum re-evaluated on 1000
held-out walkers (the in-sample value's optimism), and Nelder-Mead over (k_hip, d_hip).
Compliant walker: Ground.random(1.5 mm, 0.1 m), 100 walkers (seed 1: the walkers of
robustness_compliant_khip.py's table) censored at 300 steps, on the hard (k_n 2.5e5) and soft
(5e4) ground: minimize_scalar (bounded, [0.5, 1.5], xatol 0.05); the table's peak cell on the
same walkers; the optimum and the paper's 0.95 on 100 held-out walkers (seed 1001: grounds
1001-1100); Nelder-Mead over (k_hip, d_hip) on the hard ground.

Then (each also alone with ``--parts geo|grid|crn``, written to its own file): ``geo`` the
hard ground with the geometric mean of the first-passage times as the objective
(robustness_tuning_geo.txt); ``grid`` both grounds with the table's grid scanned first and
Brent on the best point's neighbours (robustness_tuning_grid.txt); ``crn`` how far the common
random numbers stay common as k_hip moves (robustness_tuning_crn.txt).

Run: `make study` (or `.venv/bin/python benchmarks/robustness_tuning.py [--quick]
[--update-docs]`; about 15 minutes of CPU). Writes robustness_tuning*.txt and
robustness_tuning.png (--update-docs: benchmarks/results/, docs/figures/).
"""
import os
import sys
import time

import numpy as np
from _results import FIGURES, RESULTS

import pdw
from pdw.analysis.robust.tuning import STATISTICS, MfptObjective, statistic, tune_first_passage

QUICK = "--quick" in sys.argv
BASE = pdw.Params.paper_steady()
WALKERS, MAX_STEPS = (10, 40) if QUICK else (100, 300)
SETS = 2 if QUICK else 6                 # hybrid seed sets
HELD = 200 if QUICK else 1000            # hybrid held-out walkers
HELD_SEED = 10 ** 6
GRID = np.round(np.linspace(0.5, 1.5, 11 if QUICK else 21), 4)
#: the compliant grounds and the peak cell of robustness_compliant_khip.py's table (100
#: walkers, seed 1: the objective's walkers)
GROUNDS = (("hard", 2.5e5, 0.80, 57.7), ("soft", 0.5e5, 1.10, 54.3))


def fmt(fp):
    return "%.1f (%.1f-%.1f)" % (fp.mfpt, fp.ci[0], fp.ci[1])


def save(lines):
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "robustness_tuning.txt").write_text("\n".join(lines) + "\n")


def hybrid(lines, out):
    sig = 0.0016
    kw = dict(model="hybrid", sigma=sig, walkers=WALKERS, max_steps=MAX_STEPS)
    c0 = time.process_time()
    lines += ["", "HYBRID walker, i.i.d. step heights N(0, %.1f mm), %d walkers censored at %d "
              "steps; held out: %d walkers of seed %d" % (sig * 1e3, WALKERS, MAX_STEPS, HELD,
                                                          HELD_SEED)]
    base = MfptObjective(BASE, ("k_hip",), seed=1, **kw)
    held = base.with_seed(HELD_SEED, walkers=HELD)
    # the objective on a grid, per seed set, all statistics (of the same walkers)
    grids = {}
    for s in range(1, SETS + 1):
        f = base if s == 1 else base.with_seed(s)
        fps = [f.first_passage([k]) for k in GRID]
        grids[s] = np.array([[statistic(fp, n) for n in STATISTICS] for fp in fps])
    lines.append("k_hip grid %s (%d points)" % (GRID[[0, -1]], len(GRID)))
    for j, n in enumerate(STATISTICS):
        A = np.array([grids[s][:, j] for s in grids])
        am = GRID[A.argmax(1)]
        nmax = [int(np.sum((a[1:-1] > a[:-2]) & (a[1:-1] > a[2:]))) for a in A]
        rel = np.std(A, 0, ddof=1) / np.mean(A, 0)
        lines.append("  %-15s peaks at k_hip %s (mean %.3f, sd %.3f); local maxima per grid "
                     "%s; sd over seed sets / mean: %.3f (median over the grid)"
                     % (n, am, am.mean(), am.std(ddof=1) if len(am) > 1 else 0.0, nmax,
                        np.median(rel)))
    lines.append("  seed set 1, mfpt: " + ", ".join("%.2f: %.1f" % (k, v)
                                                   for k, v in zip(GRID, grids[1][:, 0])))
    hg = [held.first_passage([k]) for k in GRID[::2]]
    lines.append("  held out, mfpt: " + ", ".join("%.2f: %s" % (k, fmt(fp))
                                                 for k, fp in zip(GRID[::2], hg)))
    out["hybrid_grid"], out["hybrid_held"] = grids, (GRID[::2], hg)
    # minimize_scalar on each seed set, the optimum on the held-out walkers
    tuned = []
    lines.append("minimize_scalar (bounded [0.5, 1.5], xatol 0.02) on each seed set:")
    for s in range(1, SETS + 1):
        f = base if s == 1 else base.with_seed(s)
        t = tune_first_passage(objective=f, bounds=[(0.5, 1.5)], xatol=0.02)
        h = held.first_passage(t.x)
        tuned.append((s, t.x[0], t.value, h))
        lines.append("  seed set %d: k_hip %.3f, in-sample %.1f, held out %s, %d evaluations; "
                     "grid peak %.2f (%.1f)" % (s, t.x[0], t.value, fmt(h), t.nfev,
                                                GRID[grids[s][:, 0].argmax()],
                                                grids[s][:, 0].max()))
    ins = np.array([t[2] for t in tuned])
    oos = np.array([t[3].mfpt for t in tuned])
    lines.append("  tuned k_hip %.3f +- %.3f (sd over seed sets); in-sample %.1f, held out "
                 "%.1f: optimism %.1f steps (%.0f %%, sd %.0f %%)"
                 % (np.mean([t[1] for t in tuned]), np.std([t[1] for t in tuned], ddof=1)
                    if SETS > 1 else 0.0, ins.mean(), oos.mean(), (ins - oos).mean(),
                    100 * ((ins - oos) / oos).mean(), 100 * np.std((ins - oos) / oos)))
    out["hybrid_tuned"] = tuned
    f2 = MfptObjective(BASE, ("k_hip", "d_hip"), seed=1, **kw)
    t2 = tune_first_passage(objective=f2, bounds=[(0.5, 1.5), (0.0, 0.02)], xatol=0.01,
                            maxiter=12 if QUICK else 40, holdout_seed=HELD_SEED)
    lines.append("Nelder-Mead (k_hip, d_hip) in [0.5, 1.5] x [0, 0.02] from (0.95, 0.010), seed "
                 "set 1: (%.3f, %.4f), in-sample %.1f (start: %.1f), held out (%d walkers) %s, "
                 "%d evaluations" % (t2.x[0], t2.x[1], t2.value, f2.value([0.95, 0.010]),
                                     WALKERS, fmt(t2.holdout), t2.nfev))
    lines.append("(hybrid: %.0f s CPU)" % (time.process_time() - c0))
    print("\n".join(lines[-12:]), flush=True)


def compliant(lines, out):
    ground = pdw.Ground.random(0.0015, 0.1)
    lines += ["", "COMPLIANT walker, Ground.random(1.5 mm, 0.1 m), %d walkers (seed 1) censored "
              "at %d steps; held out: %d walkers of seed 1001" % (WALKERS, MAX_STEPS, WALKERS)]
    for name, k_n, peak, peak_table in GROUNDS:
        c0 = time.process_time()
        P = BASE.replace(k_n=k_n)
        f = MfptObjective(P, ("k_hip",), model="continuous", ground=ground, walkers=WALKERS,
                          max_steps=MAX_STEPS, seed=1)
        t = tune_first_passage(objective=f, bounds=[(0.5, 1.5)], xatol=0.05,
                               maxiter=4 if QUICK else 12)
        vpk = f.value([peak])
        held = f.with_seed(1001)
        h, h95 = held.first_passage(t.x), held.first_passage([0.95])
        lines.append("%s (k_n %.3g): k_hip %.3f, in-sample %s, %d evaluations %s; the table's "
                     "peak cell k_hip %.2f on the same walkers %.1f (table: %.1f); held out: "
                     "at %.3f %s, at 0.95 %s (%.0f s CPU)"
                     % (name, k_n, t.x[0], fmt(t.first_passage), t.nfev,
                        ["%.3f: %.1f" % (x[0], v) for x, v in t.evaluations], peak, vpk,
                        peak_table, t.x[0], fmt(h), fmt(h95), time.process_time() - c0))
        print(lines[-1], flush=True)
        out[name] = (t, h, h95)
        save(lines)
    c0 = time.process_time()
    t1 = out["hard"][0]
    f2 = MfptObjective(BASE.replace(k_n=2.5e5), ("k_hip", "d_hip"), model="continuous",
                       ground=ground, walkers=WALKERS, max_steps=MAX_STEPS, seed=1)
    t2 = tune_first_passage(objective=f2, bounds=[(0.5, 1.5), (0.0, 0.02)],
                            x0=[t1.x[0], 0.010], xatol=0.02, maxiter=5 if QUICK else 14,
                            holdout_seed=1001)
    lines.append("hard, Nelder-Mead (k_hip, d_hip) in [0.5, 1.5] x [0, 0.02] from (%.3f, 0.010): "
                 "(%.3f, %.4f), in-sample %s, held out %s, %d evaluations %s (%.0f s CPU)"
                 % (t1.x[0], t2.x[0], t2.x[1], fmt(t2.first_passage), fmt(t2.holdout), t2.nfev,
                    ["(%.3f, %.4f): %.1f" % (x[0], x[1], v) for x, v in t2.evaluations],
                    time.process_time() - c0))
    print(lines[-1], flush=True)
    out["hard2"] = t2


def compliant_geo():
    """The hard ground again with the geometric mean of the first-passage times as the
    objective (the per-walker log T correlate across k_hip far better than the MFPT, which the
    few longest walks dominate): on the grid of robustness_compliant_khip.py and by
    minimize_scalar, the same walkers; its optimum on the held-out walkers."""
    t0, c0 = time.time(), time.process_time()
    lines = ["Compliant walker, hard ground (k_n 2.5e5), Ground.random(1.5 mm, 0.1 m), %d "
             "walkers (seed 1) censored at %d steps; objective: the geometric mean of the "
             "first-passage times (statistic='geometric_mean') [steps]" % (WALKERS, MAX_STEPS),
             "load average at start %.2f %.2f %.2f" % os.getloadavg()]
    f = MfptObjective(BASE.replace(k_n=2.5e5), ("k_hip",), model="continuous",
                      ground=pdw.Ground.random(0.0015, 0.1), walkers=WALKERS,
                      max_steps=MAX_STEPS, seed=1, statistic="geometric_mean")
    grid = (0.5, 0.8, 1.1) if QUICK else (0.5, 0.65, 0.8, 0.95, 1.1, 1.25, 1.5)
    for k in grid:
        fp = f.first_passage([k])
        lines.append("  k_hip %.2f: geometric mean %.1f, MFPT %s" % (k, f.value([k]), fmt(fp)))
        print(lines[-1], flush=True)
    t = tune_first_passage(objective=f, bounds=[(0.5, 1.5)], xatol=0.05,
                           maxiter=4 if QUICK else 12)
    h = f.with_seed(1001).first_passage(t.x)
    lines.append("minimize_scalar (bounded [0.5, 1.5], xatol 0.05) on the geometric mean: "
                 "k_hip %.3f, geometric mean %.1f, MFPT %s in-sample, %d evaluations %s; held "
                 "out (seed 1001) MFPT %s, geometric mean %.1f"
                 % (t.x[0], t.value, fmt(t.first_passage), t.nfev,
                    ["%.3f: %.1f" % (x[0], v) for x, v in t.evaluations], fmt(h),
                    statistic(h, "geometric_mean")))
    lines.append("wall %.0f s, CPU %.0f s, load average at end %.2f %.2f %.2f"
                 % (time.time() - t0, time.process_time() - c0, *os.getloadavg()))
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "robustness_tuning_geo.txt").write_text("\n".join(lines) + "\n")
    print("\n".join(lines[-2:]))


def compliant_grid():
    """Both compliant grounds again, the MFPT as the objective, Brent preceded by a scan of
    robustness_compliant_khip.py's grid (`tune_first_passage(grid=...)`: Brent on the best grid
    point's neighbours); the optimum on the held-out walkers."""
    t0, c0 = time.time(), time.process_time()
    grid = (0.5, 0.8, 1.1) if QUICK else (0.5, 0.65, 0.8, 0.95, 1.1, 1.25, 1.5)
    lines = ["Compliant walker, Ground.random(1.5 mm, 0.1 m), %d walkers (seed 1) censored at %d "
             "steps; objective the MFPT; tune_first_passage(grid=%s, xatol=0.02): Brent on the "
             "best grid point's neighbours" % (WALKERS, MAX_STEPS, list(grid)),
             "load average at start %.2f %.2f %.2f" % os.getloadavg()]
    for name, k_n, _, _ in GROUNDS:
        c1 = time.process_time()
        f = MfptObjective(BASE.replace(k_n=k_n), ("k_hip",), model="continuous",
                          ground=pdw.Ground.random(0.0015, 0.1), walkers=WALKERS,
                          max_steps=MAX_STEPS, seed=1)
        t = tune_first_passage(objective=f, bounds=[(0.5, 1.5)], grid=grid, xatol=0.02,
                               maxiter=4 if QUICK else 12, holdout_seed=1001)
        lines.append("%s (k_n %.3g): k_hip %.3f, in-sample %s, %d evaluations %s; held out "
                     "(seed 1001) %s (%.0f s CPU)"
                     % (name, k_n, t.x[0], fmt(t.first_passage), t.nfev,
                        ["%.3f: %.1f" % (x[0], v) for x, v in t.evaluations], fmt(t.holdout),
                        time.process_time() - c1))
        print(lines[-1], flush=True)
    lines.append("wall %.0f s, CPU %.0f s, load average at end %.2f %.2f %.2f"
                 % (time.time() - t0, time.process_time() - c0, *os.getloadavg()))
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "robustness_tuning_grid.txt").write_text("\n".join(lines) + "\n")


def crn_correlation():
    """How common the random numbers stay as k_hip moves: per walker, the first-passage time
    T at k_hip + dk against the one at k_hip on the same walkers (the fraction unchanged, the
    correlation of log T) and the MFPT, hybrid and compliant (hard ground, 40 walkers)."""
    t0, c0 = time.time(), time.process_time()
    lines = ["The same walkers at nearby k_hip: fraction of walkers whose steps are unchanged, "
             "correlation of log T, MFPT [steps]",
             "load average at start %.2f %.2f %.2f" % os.getloadavg()]
    cases = (("hybrid, step heights N(0, 1.6 mm), 100 walkers",
              MfptObjective(BASE, model="hybrid", sigma=0.0016, walkers=100,
                            max_steps=MAX_STEPS, seed=1), (0.70, 0.705, 0.71, 0.75, 0.80)),
             ("compliant, hard ground, Ground.random(1.5 mm, 0.1 m), 40 walkers",
              MfptObjective(BASE.replace(k_n=2.5e5), model="continuous",
                            ground=pdw.Ground.random(0.0015, 0.1), walkers=40,
                            max_steps=MAX_STEPS, seed=1), (0.80, 0.805, 0.81, 0.85)))
    for name, f, ks in cases[:1] if QUICK else cases:
        T0 = f.first_passage([ks[0]]).steps.astype(float)
        lines.append(name + ":")
        for k in ks:
            T = f.first_passage([k]).steps.astype(float)
            lines.append("  k_hip %.3f: unchanged %.2f, corr(log T) %.3f, MFPT %.1f"
                         % (k, np.mean(T == T0), np.corrcoef(np.log(T0), np.log(T))[0, 1],
                            f.value([k])))
    lines.append("wall %.0f s, CPU %.0f s, load average at end %.2f %.2f %.2f"
                 % (time.time() - t0, time.process_time() - c0, *os.getloadavg()))
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "robustness_tuning_crn.txt").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def main():
    part = sys.argv[sys.argv.index("--parts") + 1] if "--parts" in sys.argv else None
    if part == "crn":
        crn_correlation()
        return
    if part == "geo":
        compliant_geo()
        return
    if part == "grid":
        compliant_grid()
        return
    t0, c0 = time.time(), time.process_time()
    lines = ["MFPT tuned with scipy.optimize on a common-random-numbers objective "
             "(pdw.analysis.robust.tuning): Params.paper_steady(), objective the censored "
             "MLE MFPT E/F [steps] (95 % Garwood interval in parentheses)",
             "load average at start %.2f %.2f %.2f" % os.getloadavg()]
    out = {}
    hybrid(lines, out)
    save(lines)
    compliant(lines, out)
    lines.append("wall %.0f s, CPU %.0f s, load average at end %.2f %.2f %.2f"
                 % (time.time() - t0, time.process_time() - c0, *os.getloadavg()))
    save(lines)
    print("written to %s" % (RESULTS / "robustness_tuning.txt"))
    figure(out)
    compliant_geo()
    compliant_grid()
    crn_correlation()


def figure(out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 3.8))
    for s, g in out["hybrid_grid"].items():
        a.plot(GRID, g[:, 0], "-", lw=0.8, alpha=0.6, label="seed set %d (in-sample)" % s)
    ks, hg = out["hybrid_held"]
    y = np.array([fp.mfpt for fp in hg])
    a.errorbar(ks, y, yerr=[y - [fp.ci[0] for fp in hg], [fp.ci[1] for fp in hg] - y], fmt="ko",
               capsize=3, label="held out (%d walkers)" % HELD)
    for s, x, v, h in out["hybrid_tuned"]:
        a.plot([x], [v], "v", color="C%d" % (s - 1), ms=8)
        a.plot([x], [h.mfpt], "ks", mfc="none", ms=7)
    a.set_xlabel("k_hip [N m/rad]")
    a.set_ylabel("MFPT [steps]")
    a.set_title("hybrid, step heights N(0, 1.6 mm): triangles tuned (in-sample), squares held "
                "out", fontsize=8)
    a.legend(fontsize=6)
    a.grid(alpha=0.3)
    for i, (name, *_r) in enumerate(GROUNDS):
        t, h, h95 = out[name]
        ev = np.array([(x[0], v) for x, v in t.evaluations])
        o = np.argsort(ev[:, 0])
        b.plot(ev[o, 0], ev[o, 1], "o:", color="C%d" % i, label="%s ground: optimizer's "
               "points (in-sample)" % name)
        for x, fp in ((t.x[0], h), (0.95, h95)):
            b.errorbar([x + 0.01 * (i - 0.5)], [fp.mfpt], yerr=[[fp.mfpt - fp.ci[0]],
                                                                [fp.ci[1] - fp.mfpt]],
                       fmt="s", color="C%d" % i, mfc="none", capsize=3)
    b.set_xlabel("k_hip [N m/rad]")
    b.set_title("compliant, Ground.random(1.5 mm, 0.1 m): squares held out (tuned, 0.95)",
                fontsize=8)
    b.legend(fontsize=7)
    b.grid(alpha=0.3)
    fig.tight_layout()
    FIGURES.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURES / "robustness_tuning.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
