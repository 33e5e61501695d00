"""Why the Markov-chain MFPT and the Monte Carlo MFPT differ (issue 22 item 5; docs/robustness.md,
"Why the chain and Monte Carlo differ").

The hybrid walker (`Params.paper_steady()`) with i.i.d. step heights N(0, sigma^2), sigma = 2 mm:
Monte Carlo (`pdw.first_passage`'s process: `_walk_dh` rows from the gait) and the chain
(`pdw.markov_chain`) model the same process -- the same step map, the same failure test, the
same i.i.d. heights relative to the stance foot -- so their difference is the chain's two
discretizations, measured here one at a time:

1. the step heights: Monte Carlo with each Gaussian height replaced by its bin's conditional
   mean (`pdw.analysis.robust.markov.dh_nodes`, n_dh bins), paired with the Gaussian walkers (common
   random numbers: walker i draws the same normals in both), so the difference of the means
   has a small interval;
2. the state mesh: the chain against the binned Monte Carlo of the same n_dh (the remaining
   difference), for both cell representatives (`representative="first"`, the shipped one, and
   ``"centre"``).

Usage: .venv/bin/python benchmarks/markov_vs_mc.py [--update-docs]   (about 2-3 min of CPU)
"""
import math
import os
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
from _results import publish  # noqa: E402

import pdw  # noqa: E402
from pdw import hybrid as H  # noqa: E402
from pdw.analysis.robust import first_passage as FP  # noqa: E402
from pdw.analysis.robust import markov as M  # noqa: E402
from pdw.analysis.robust import robustness as R  # noqa: E402

P = pdw.Params.paper_steady()
SIGMA = 0.002
WALKERS, MAX_STEPS, SEED = 8000, 1000, 11
N_DH = (11, 21, 41, 81)
CHAINS = ((21, 0.02), (41, 0.02), (21, 0.01))


def mc(gait, dh):
    n, _, _, _, _, _ = R._walk_dh(P, gait.state, dh, {}, threads=2)
    failed = n < MAX_STEPS
    steps = np.where(failed, n + 1, MAX_STEPS)
    return FP.mfpt_estimate(steps, failed, max_steps=MAX_STEPS), steps


def main():
    t0, c0 = time.perf_counter(), time.process_time()
    gait = H.find_gait(P)
    x = np.random.default_rng(SEED).normal(0.0, 1.0, (WALKERS, MAX_STEPS))
    gauss, s0 = mc(gait, SIGMA * x)
    lines = ["Markov chain vs Monte Carlo (benchmarks/markov_vs_mc.py): Params.paper_steady(), "
             "hybrid, i.i.d. step heights N(0, (%.1f mm)^2)" % (1e3 * SIGMA),
             "load average at start %.2f %.2f %.2f" % os.getloadavg(),
             "",
             "Monte Carlo, Gaussian heights: %d walkers, MFPT %.3f, 95 %% CI (%.3f, %.3f), "
             "%d censored at %d" % (WALKERS, gauss.mfpt, gauss.ci[0], gauss.ci[1],
                                   int(np.sum(s0 >= MAX_STEPS)), MAX_STEPS),
             "",
             "1. step-height bins alone (the same walkers, heights snapped to their bin's "
             "conditional mean):",
             "| n_dh | MFPT | 95 % CI | paired difference to Gaussian [steps] |",
             "|---|---|---|---|"]
    binned = {}
    for n_dh in N_DH:
        dh, _ = M.dh_nodes(SIGMA, n_dh)
        edges = np.linspace(-5.0, 5.0, n_dh + 1)
        b = np.clip(np.searchsorted(edges, x) - 1, 0, n_dh - 1)
        est, s = mc(gait, dh[b])
        d = (s - s0).astype(float)
        binned[n_dh] = est.mfpt
        lines.append("| %d | %.3f | (%.3f, %.3f) | %+.3f +- %.3f |"
                     % (n_dh, est.mfpt, est.ci[0], est.ci[1], d.mean(),
                        1.96 * d.std() / math.sqrt(WALKERS)))
        print(lines[-1], flush=True)
    lines += ["",
              "2. the state mesh: the chain against the binned Monte Carlo of its n_dh",
              "| n_dh | resolution | representative | cells | chain MFPT | binned MC | "
              "mesh error [steps] | chain - Gaussian MC | 1/(1 - lambda2) | CPU [s] |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for n_dh, res in CHAINS:
        for rep in ("first", "centre"):
            c1 = time.process_time()
            ch = pdw.markov_chain(P, sigma=SIGMA, n_dh=n_dh, resolution=res, gait=gait,
                                  max_cells=300000, representative=rep)
            ref = binned.get(n_dh, math.nan)
            lines.append("| %d | %.3g | %s | %d | %.3f | %.3f | %+.3f | %+.1f %% | %.3f | %.0f |"
                         % (n_dh, res, rep, ch.n_cells, ch.mfpt, ref, ch.mfpt - ref,
                            100 * (ch.mfpt / gauss.mfpt - 1), ch.mfpt_eig,
                            time.process_time() - c1))
            print(lines[-1], flush=True)
    lines += ["", "wall %.0f s, CPU %.0f s, load average at end %.2f %.2f %.2f"
              % (time.perf_counter() - t0, time.process_time() - c0, *os.getloadavg())]
    publish("markov_vs_mc.txt", lines)


if __name__ == "__main__":
    main()
