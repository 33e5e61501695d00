"""Fixed points, Floquet multipliers and the cell-mapping basin of the continuous model
(pdw.limit_cycle, pdw.cell_mapping; docs/studies.md). Writes benchmarks/results/limit_cycles.txt
and docs/figures/basin.png.

Usage: .venv/bin/python benchmarks/limit_cycles.py   (a few minutes on 2 cores; `make study`)
"""
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
from _results import FIGURES, publish  # noqa: E402

import pdw  # noqa: E402
from pdw import cell_mapping as CM  # noqa: E402
from pdw import hybrid as H  # noqa: E402
from pdw import limit_cycle as LC  # noqa: E402

P = pdw.Params.paper_steady()


def fmt(a, p=6):
    return "[" + ", ".join(("%.*f" % (p, x)) for x in np.asarray(a)) + "]"


def fmt_mu(m):
    out = []
    for x in m:
        if abs(x.imag) > 1e-12:
            out.append("%.4f%+.4fi" % (x.real, x.imag))
        else:
            out.append("%.3g" % x.real)
    return ", ".join(out)


def fixed_points(lines):
    lines += ["## Fixed points (Newton shooting on the touch-down map, rodas4 rtol 1e-10, "
              "event_tol 1e-12, central differences 1e-5)", ""]
    gaits = {}
    for variant in ("paper", "consistent"):
        t0 = time.perf_counter()
        g = LC.find_gait(P, variant=variant)
        wall = time.perf_counter() - t0
        gaits[variant] = g
        d = g.details
        lines += [
            "%s variant (found from '%s' in %d Newton iterations, residual %.1e, %.1f s):"
            % (variant, d["guess"], d["newton_iterations"], d["residual"], wall),
            "  z* = (theta1, theta2, xd_o, yd_o, thetad1, thetad2) = %s" % fmt(d["z"]),
            "  period %.6f s, step length %.6f m, double support %.3f ms (%.2f %%), swing "
            "period %.6f s, travel %.6f m, v = L/P %.4f m/s"
            % (g.period, g.step_length, 1e3 * g.double_support,
               100 * g.double_support / g.period, d["swing_period"], d["travel"],
               g.step_length / d["swing_period"]),
            "  multipliers (fd 1e-5): %s" % fmt_mu(g.multipliers),
            "  multipliers (fd 1e-4): %s" % fmt_mu(d["multipliers_check"]),
            "  |multipliers|: %s" % ", ".join("%.3g" % abs(m) for m in g.multipliers),
        ]
    # consistent variant: the restart resets the trailing foot's anchor; compare with a run
    r = pdw.simulate(t_end=25, params=P, variant="consistent", method="rodas4",
                     integrator=pdw.Integrator(**LC.TIGHT), record=pdw.Record(every=1, forces=False))
    e = [e for e in r.events if e.kind == "touch_down"][-1]
    i = int(np.argmin(np.abs(r.t - e.t)))
    z = LC.section_coordinates(r.x[i], e.leg)
    st = pdw.steps(r).steady(4)
    g = gaits["consistent"]
    lines += ["  consistent: a 25 s run (no restarts) converges to z within %.1e of z*; its cycle "
              "%.6f s and L %.6f m (map's fixed point: %.6f s, %.6f m): the anchor reset of the "
              "trailing foot at each restart" % (np.max(np.abs(z - g.details["z"])), st["cycle"],
                                                 st["L"], g.period, g.step_length)]
    r = pdw.simulate(t_end=25, params=P, method="rodas4", integrator=pdw.Integrator(**LC.TIGHT),
                     record=pdw.Record(every=1, forces=False))
    e = [e for e in r.events if e.kind == "touch_down"][-1]
    i = int(np.argmin(np.abs(r.t - e.t)))
    z = LC.section_coordinates(r.x[i], e.leg)
    lines += ["  paper: a 25 s run converges to z within %.1e of z*"
              % np.max(np.abs(z - gaits["paper"].details["z"]))]
    gh = H.find_gait(P)
    lines += ["hybrid (pdw.hybrid): period %.6f s, L %.6f m, multipliers %s"
              % (gh.period, gh.step_length, fmt_mu(gh.multipliers)), ""]
    # period-n detection: the paper's d_hip
    d = LC.detect_period(pdw.Params.paper())
    d2 = LC.detect_period(P)
    lines += ["period detection (iterating the map from the paper's x0 settled 4 s): "
              "paper_steady -> %s %s; paper (d_hip = 0.018) -> %s" % (d2["kind"], d2["n"],
                                                                        d["kind"]), ""]
    return gaits


def basin(lines, gait):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    z = gait.details["z"]
    fp = (z[1] - z[0], z[5])
    t0 = time.perf_counter()
    cm = CM.cell_map(P, phi=(0.40, 0.96, 140), thetad2=(-5.0, 1.5, 80))
    wall = time.perf_counter() - t0
    A, B = cm.centers()
    lines += ["## Cell mapping (simple cell mapping, pdw.cell_mapping; rodas4 rtol 1e-7)", "",
              "grid: phi = theta2 - theta1 in [0.40, 0.96] rad (140 cells of %.4f), thetad2 in "
              "[-5.0, 1.5] rad/s (80 cells of %.4f); %d map evaluations in %.1f s"
              % (np.diff(cm.a_edges)[0], np.diff(cm.b_edges)[0], cm.info["evaluations"], wall),
              "reference (other 4 coordinates): first touch-down of the paper's x0: %s"
              % fmt(cm.info["reference"]), cm.summary(),
              "Newton's fixed point: phi* = %.5f, thetad2* = %.5f; its cell %d is in group %d"
              % (fp[0], fp[1], cm.cell_of(*fp), cm.group[cm.cell_of(*fp)])]
    for n, _cells, (a, b) in cm.periodic_cells():
        lines.append("  periodic group of period %d at (%.5f, %.4f): offset from Newton "
                     "(%.2f, %.2f) cells" % (n, a, b, (a - fp[0]) / np.diff(cm.a_edges)[0],
                                             (b - fp[1]) / np.diff(cm.b_edges)[0]))
    # the full dynamics from every second cell's centre state
    t0 = time.perf_counter()
    conv, nsteps = CM.point_mapping_basin(cm, z, n_steps=12, tol=1e-3)
    wall = time.perf_counter() - t0
    scm = cm.group >= 0
    lines += ["point mapping check (full 6-D map iterated up to 12 steps from each cell's centre "
              "state, converged = within 1e-3 of z*; %.0f s): %d cells converge, the cell map's "
              "basin has %d cells; they agree on %.1f %% of the cells (%d in the cell map's basin "
              "only, %d in the point map's only)"
              % (wall, conv.sum(), scm.sum(), 100 * np.mean(conv == scm), np.sum(scm & ~conv),
                 np.sum(conv & ~scm)), ""]
    fig, axs = plt.subplots(1, 2, figsize=(12, 5), constrained_layout=True)
    CM.plot_basin(cm, axs[0], fixed_point=fp,
                  title="simple cell mapping, %d x %d cells: basin of the period-one gait "
                        "(blue),\nsink (dark grey: falls in the first step; light grey: later, "
                        "or leaves the grid)" % cm.shape)
    na, nb = cm.shape
    code = np.where(conv & scm, 2, np.where(conv, 1, np.where(scm, 3, 0))).reshape(na, nb).T
    from matplotlib.colors import ListedColormap
    axs[1].pcolormesh(cm.a_edges, cm.b_edges, code, shading="flat", vmin=-0.5, vmax=3.5,
                      cmap=ListedColormap(["#bdbdbd", "#ff7f0e", "#1f77b4", "#d62728"]))
    axs[1].plot(*fp, "wx", ms=9, mew=2)
    axs[1].set_xlabel(axs[0].get_xlabel())
    axs[1].set_ylabel(axs[0].get_ylabel())
    axs[1].set_title("check with the full map (12 steps), %.1f %% agree: blue both converge,\n"
                     "orange only the point map, red only the cell map, grey neither"
                     % (100 * np.mean(conv == scm)), fontsize=9)
    fig.suptitle("Basin of attraction of the period-one gait on the touch-down section "
                 "(Params.paper_steady(), paper variant); x: Newton's fixed point", fontsize=10)
    FIGURES.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURES / "basin.png", dpi=110)
    plt.close(fig)
    return cm


def main():
    t0 = time.perf_counter()
    lines = ["Limit cycles of the continuous model, Params.paper_steady() "
             "(benchmarks/limit_cycles.py)", ""]
    gaits = fixed_points(lines)
    basin(lines, gaits["paper"])
    lines.append("total %.0f s" % (time.perf_counter() - t0))
    publish("limit_cycles.txt", lines)


if __name__ == "__main__":
    main()
