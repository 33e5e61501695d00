"""Robustness studies of issue 22 item 6 that the hybrid (rigid-ground) model answers
(docs/robustness.md): max step-down against the slope gamma and the hip spring k_hip, the gait
sensitivity norm against k_hip, the MFPT against the roughness sigma for several k_hip, the
Markov chain against Monte Carlo, and k_hip tuned by scipy.optimize for the largest step-down.

Run: `make study` (or `.venv/bin/python benchmarks/robustness_studies.py [--quick]
[--update-docs]`). Writes robustness_studies.txt under out/benchmarks/results/ and the figures
robustness_*.png under out/benchmarks/figures/ (--update-docs: benchmarks/results/,
docs/figures/). --quick: fewer points and walkers (a smoke run, about a minute).
"""
import os
import sys
import time

import numpy as np
from _results import FIGURES, publish

import pdw

QUICK = "--quick" in sys.argv
BASE = pdw.Params.paper_steady()


def with_(**kw):
    return pdw.Params(**{**BASE.as_dict(), **kw})


def gait_along(name, values):
    """The hybrid gait at each value, each found from the previous one (a branch, not a jump
    to another gait): {value: Gait or None}."""
    out, prev = {}, None
    for v in values:
        try:
            g = pdw.hybrid.find_gait(with_(**{name: v}), guess=None if prev is None
                                     else prev.state, settle_steps=0 if prev else 30)
        except pdw.PdwError:
            g = None
        out[v] = g
        prev = g if g is not None else prev
    return out


def max_step_along(name, values, lines, gaits):
    gaits.update(gait_along(name, values))
    rows = []
    for v in values:
        g = gaits[v]
        if g is None:
            rows.append((v, np.nan, np.nan, np.nan, np.nan))
            continue
        m = pdw.max_step(with_(**{name: v}), gait=g, h_tol=2e-5)
        G = pdw.gait_sensitivity(with_(**{name: v}), gait=g, check=False)
        rows.append((v, m.height * 1e3 if m.stable else 0.0, max(abs(g.multipliers)),
                     G.norm, g.period))
    lines.append("")
    lines.append("%-8s %14s %10s %12s %10s" % (name, "max down [mm]", "|mu|max", "GSN(T) [s/m]",
                                              "period [s]"))
    for r in rows:
        lines.append("%-8.4g %14.3f %10.4f %12.4g %10.4f" % r)
    return np.array(rows)


def main():
    t0 = time.time()
    load0 = os.getloadavg()
    lines = ["Robustness of the hybrid walker (Params.paper_steady(), rigid ground)",
             "load average at start %.2f %.2f %.2f" % load0]
    n = 6 if QUICK else 11
    ks = np.linspace(0.5, 1.5, n)
    gs = np.linspace(0.012, 0.04, n)
    gk, gg = {}, {}
    rk = max_step_along("k_hip", ks, lines, gk)
    rg = max_step_along("gamma", gs, lines, gg)

    # MFPT against sigma for three k_hip
    sig = np.array([1.4, 1.6, 1.8, 2.0, 2.5]) * 1e-3
    walkers = 150 if QUICK else 400
    lines += ["", "MFPT [steps] (95 %% CI), i.i.d. step heights N(0, sigma^2), %d walkers, "
              "censored at 3000 steps" % walkers]
    mf = {}
    for k in (0.5, 0.95, 1.5) if not QUICK else (0.5, 1.5):
        P = with_(k_hip=k)
        # on the branch of the paper's k_hip, in steps of at most 0.1: one jump from 0.95 to
        # 0.5 lands on another, unstable period-one gait (period 0.567 s, |mu| 2.30)
        path = np.linspace(0.95, k, 1 + int(np.ceil(abs(k - 0.95) / 0.1)))
        g = gait_along("k_hip", list(path))[path[-1]]
        mu = max(abs(g.multipliers))
        for s in sig:
            fp = pdw.first_passage(P, sigma=s, walkers=walkers, max_steps=3000, gait=g, seed=1)
            mf[(k, s)] = fp
            lines.append("k_hip %.2f (gait period %.4f s, |mu|max %.4f) sigma %.1f mm: %s"
                         % (k, g.period, mu, s * 1e3, fp))

    # Markov chain against Monte Carlo
    lines += ["", "Markov chain (n_dh step-height bins, cells of side res) vs Monte Carlo, "
              "sigma 2 mm, k_hip 0.95"]
    g = pdw.hybrid.find_gait(BASE)
    fp = pdw.first_passage(BASE, sigma=0.002, walkers=600 if QUICK else 4000, max_steps=3000,
                           gait=g, seed=11)
    lines.append("Monte Carlo: %s" % fp)
    for n_dh, res in ([(21, 0.02)] if QUICK else [(21, 0.02), (41, 0.02), (21, 0.01)]):
        w0 = time.time()
        mc = pdw.markov_chain(BASE, sigma=0.002, n_dh=n_dh, resolution=res, gait=g,
                              max_cells=300000)
        lines.append("n_dh %2d res %.3f: %6d cells, MFPT %.2f (fundamental matrix), %.2f "
                     "(1/(1 - lambda2), lambda2 = %.5f), %.0f s"
                     % (n_dh, res, mc.n_cells, mc.mfpt, mc.mfpt_eig, mc.lambda2,
                        time.time() - w0))

    # k_hip tuned for the largest step-down (scipy.optimize on max_step)
    from scipy.optimize import minimize_scalar

    def neg(k):
        try:
            return -pdw.max_step(with_(k_hip=k), h_tol=2e-5).height
        except pdw.PdwError:
            return 0.0
    opt = minimize_scalar(neg, bounds=(0.3, 1.5), method="bounded",
                          options=dict(xatol=1e-2 if QUICK else 2e-3))
    lines += ["", "k_hip maximizing the step-down on [0.3, 1.5] (scipy bounded Brent; "
              "each evaluation pdw.max_step with pdw.hybrid.find_gait's default guesses): "
              "k_hip = %.4f, step-down %.3f mm, %d evaluations" % (opt.x, -opt.fun * 1e3,
                                                                  opt.nfev)]
    lines.append("wall %.0f s, load average at end %.2f %.2f %.2f" % (time.time() - t0,
                                                                      *os.getloadavg()))
    publish("robustness_studies.txt", lines)
    figures(rk, rg, mf, sig)


def figures(rk, rg, mf, sig):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    FIGURES.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.6))
    for a, r, name in ((ax[0], rk, "k_hip [N m/rad]"), (ax[1], rg, "slope gamma [rad]")):
        a.plot(r[:, 0], r[:, 1], "o-")
        a.set_xlabel(name)
        a.set_ylabel("max step-down [mm]")
        a.grid(alpha=0.3)
    fig.suptitle("Hybrid walker (paper_steady): largest step-down survived and returned from",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(FIGURES / "robustness_max_step.png", dpi=120)
    plt.close(fig)
    fig, a = plt.subplots(figsize=(5, 3.6))
    for k in sorted({k for k, _ in mf}):
        y = np.array([mf[(k, s)].mfpt for s in sig])
        lo = np.array([mf[(k, s)].ci[0] for s in sig])
        hi = np.array([mf[(k, s)].ci[1] for s in sig])
        a.errorbar(sig * 1e3, y, yerr=[y - lo, hi - y], marker="o", capsize=3,
                   label="k_hip %.2f" % k)
    a.set_yscale("log")
    a.set_xlabel("step-height sigma [mm]")
    a.set_ylabel("mean first-passage time [steps]")
    a.legend(fontsize=8)
    a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(FIGURES / "robustness_mfpt.png", dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
