"""The compliant walker's mean first-passage time against the hip spring k_hip on a hard and a
soft rough ground, at one roughness (issue 22 item 6; docs/terrain.md, "Studies"): does the
best k_hip depend on the ground?

`Params.paper_steady()` with k_n = 2.5e5 (hard) or 5e4 (soft) N/m^1.5 (d_n kept), the gaits
followed along k_hip from the preset's (`robustness_compliant.gaits_along`), `pdw.first_passage`
on `Ground.random(1.5 mm, 0.1 m)` (each walker its own ground, seed 1 + i: the walkers of
benchmarks/robustness_compliant.py at k_hip 0.5, 0.95, 1.5), 100 walkers censored at 300 steps.

Usage: .venv/bin/python benchmarks/robustness_compliant_khip.py [--update-docs]
(about 4 minutes of CPU). Writes robustness_compliant_khip.txt and the figure
robustness_compliant_khip.png. ``--walkers N --khips a,b,...`` (the refinement near the best
k_hip): N walkers (the first 100 are the default run's) at those k_hip, written to
robustness_compliant_khip_N.txt / .png.
"""
import os
import sys
import time

import numpy as np
from _results import FIGURES, publish
from robustness_compliant import gaits_along, with_

import pdw

SIGMA = 0.0015
KHIPS = (0.5, 0.65, 0.8, 0.95, 1.1, 1.25, 1.5)
GROUNDS = (("hard", 2.5e5), ("soft", 0.5e5))
WALKERS = 100
SUFFIX = ""
if "--walkers" in sys.argv:
    WALKERS = int(sys.argv[sys.argv.index("--walkers") + 1])
    SUFFIX = "_%d" % WALKERS
if "--khips" in sys.argv:
    KHIPS = tuple(float(v) for v in sys.argv[sys.argv.index("--khips") + 1].split(","))


def main():
    t0, c0 = time.time(), time.process_time()
    lines = ["MFPT [steps] against k_hip (benchmarks/robustness_compliant_khip.py): "
             "paper_steady, Ground.random(%.1f mm, 0.1 m), %d walkers each, censored at 300 "
             "steps, seed 1" % (1e3 * SIGMA, WALKERS),
             "load average at start %.2f %.2f %.2f" % os.getloadavg(), "",
             "| ground | k_n | " + " | ".join("k_hip %.2f" % k for k in KHIPS) + " |",
             "|---|---|" + "---|" * len(KHIPS)]
    res = {}
    for ground, k_n in GROUNDS:
        gaits = gaits_along("k_hip", KHIPS, base=with_(k_n=k_n))
        cells = []
        for k in KHIPS:
            g = gaits[k]
            if g is None:
                cells.append("no gait")
                continue
            fp = pdw.first_passage(with_(k_n=k_n, k_hip=k), model="continuous",
                                   ground=pdw.Ground.random(SIGMA, 0.1), walkers=WALKERS,
                                   max_steps=300, gait=g, seed=1)
            res[(ground, k)] = fp
            cells.append("%.1f (%.1f-%.1f)" % (fp.mfpt, fp.ci[0], fp.ci[1]))
            print(ground, k, fp, flush=True)
        lines.append("| %s | %.3g | %s |" % (ground, k_n, " | ".join(cells)))
    lines += ["", "wall %.0f s, CPU %.0f s, load average at end %.2f %.2f %.2f"
              % (time.time() - t0, time.process_time() - c0, *os.getloadavg())]
    publish("robustness_compliant_khip%s.txt" % SUFFIX, lines)
    figure(res)


def figure(res):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, a = plt.subplots(figsize=(6, 3.8))
    for i, (ground, k_n) in enumerate(GROUNDS):
        ks = [k for k in KHIPS if (ground, k) in res]
        y = np.array([res[(ground, k)].mfpt for k in ks])
        lo = np.array([res[(ground, k)].ci[0] for k in ks])
        hi = np.array([res[(ground, k)].ci[1] for k in ks])
        a.errorbar(np.array(ks) + 0.01 * (i - 0.5), y, yerr=[y - lo, hi - y], marker="o",
                   capsize=3, label="%s ground (k_n %.2g)" % (ground, k_n))
    a.set_xlabel("k_hip [N m/rad]")
    a.set_ylabel("mean first-passage time [steps]")
    a.set_title("Compliant walker on Ground.random(%.1f mm, 0.1 m): MFPT vs hip spring"
                % (1e3 * SIGMA), fontsize=9)
    a.grid(alpha=0.3)
    a.legend(fontsize=8)
    fig.tight_layout()
    FIGURES.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURES / ("robustness_compliant_khip%s.png" % SUFFIX), dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
