"""The survival region of the hard floor -> soft mat -> hard floor transition in (mat k_n,
k_hip), on a finer grid than benchmarks/robustness_compliant.py's table (issue 22 item 6;
docs/terrain.md, "Studies").

`Params.paper_steady()` (its floor: k_n 1e5, d_n 1e6) with a mat of k_n (d_n = 10 k_n, the
preset's ratio) on s in [1, 2.5] m, the gait followed along k_hip from the preset's; 30 steps
from the gait (`robustness_continuous.walk`, rodas4 rtol 1e-8); a cell is the number of steps
after the mat until step length and time are back within 1e-3 of the gait's, or F (fell).

Usage: .venv/bin/python benchmarks/robustness_compliant_mat.py [--update-docs]   (about a
minute of CPU). Writes robustness_compliant_mat_grid.txt and robustness_compliant_mat_grid.png.
"""
import os
import time

import numpy as np
from _results import FIGURES, publish
from robustness_compliant import gaits_along, with_

import pdw
from pdw.analysis.robust import robustness_continuous as RC
from pdw.analysis.robust.robustness_core import returned

KHIPS = tuple(np.round(np.linspace(0.5, 1.5, 11), 3))
MATS = tuple(float("%.3g" % m) for m in np.geomspace(3e3, 3e4, 11))


def main():
    t0, c0 = time.time(), time.process_time()
    gaits = gaits_along("k_hip", KHIPS)
    grid = np.full((len(KHIPS), len(MATS)), np.nan)
    for i, k in enumerate(KHIPS):
        g = gaits[k]
        if g is None:
            continue
        for j, m in enumerate(MATS):
            ground = pdw.Ground.flat(patches=[pdw.Patch.make(1.0, 2.5, k_n=m, d_n=10 * m)])
            st, L, T = RC.walk(with_(k_hip=float(k)), g, ground, 30)
            if st not in ("walked", "periodic"):
                grid[i, j] = -1
                continue
            past = int(np.searchsorted(np.cumsum(L), 2.5)) + 1
            ret, kk = returned(L[past:], T[past:], g.step_length, g.period, 1e-3)
            grid[i, j] = kk if ret else 99
    lines = ["Hard floor -> soft mat on s in [1, 2.5] m -> hard floor "
             "(benchmarks/robustness_compliant_mat.py): paper_steady, mat d_n = 10 k_n, 30 "
             "steps; steps after the mat to re-converge (1e-3), F fell, > not within 30 steps",
             "load average at start/end: see the last line", "",
             "| k_hip \\ mat k_n | " + " | ".join("%.3g" % m for m in MATS) + " |",
             "|---|" + "---|" * len(MATS)]
    for i, k in enumerate(KHIPS):
        cells = ["-" if np.isnan(v) else "F" if v < 0 else ">" if v >= 99 else "%d" % v
                 for v in grid[i]]
        lines.append("| %.2f | %s |" % (k, " | ".join(cells)))
    soft = []
    for i, k in enumerate(KHIPS):
        ok = [m for m, v in zip(MATS, grid[i]) if v >= 0]
        soft.append("%.2f: %s" % (k, "%.3g" % min(ok) if ok else "none"))
    lines += ["", "softest mat survived, per k_hip: " + "; ".join(soft),
              "wall %.0f s, CPU %.0f s, load average at end %.2f %.2f %.2f"
              % (time.time() - t0, time.process_time() - c0, *os.getloadavg())]
    publish("robustness_compliant_mat_grid.txt", lines)
    figure(grid)


def figure(grid):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, a = plt.subplots(figsize=(7.5, 4.6))
    show = np.where(grid < 0, np.nan, np.minimum(grid, 30))
    im = a.imshow(show, origin="lower", aspect="auto", cmap="viridis")
    for i in range(len(KHIPS)):
        for j in range(len(MATS)):
            v = grid[i, j]
            a.text(j, i, "-" if np.isnan(v) else "F" if v < 0 else "%d" % v, ha="center",
                   va="center", color="w" if v >= 0 else "k", fontsize=7)
    a.set_xticks(range(len(MATS)), ["%.2g" % m for m in MATS], rotation=45)
    a.set_yticks(range(len(KHIPS)), ["%.2f" % k for k in KHIPS])
    a.set_xlabel("mat k_n [N/m^1.5] (d_n = 10 k_n)")
    a.set_ylabel("k_hip [N m/rad]")
    a.set_title("hard -> soft mat -> hard: steps to re-converge after the mat (F: fell)",
                fontsize=9)
    fig.colorbar(im, ax=a)
    fig.tight_layout()
    FIGURES.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURES / "robustness_compliant_mat_grid.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
