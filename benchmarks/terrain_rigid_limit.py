"""The compliant model on a step-down against the hybrid (rigid-ground) model as the ground
stiffens (issue 22 item 4; docs/terrain.md "The step-down in the rigid limit"), the step-down
counterpart of benchmarks/rigid_limit.py (flat ground).

`Params.paper_steady()` with k_n from 1e5 to 1e9 N/m^1.5 and d_n = d_n0 (k_n / k_n0)^(4/3)
(benchmarks/rigid_limit.py: the stance contact's damping ratio fixed), the ``consistent``
variant, rodas4 at rtol 1e-8 (`pdw.analysis.robust.robustness_continuous.WALK`), each k from its own
Newton gait (followed from the previous k), on ``Ground.step(L*/2, -H)``:

* the response: the first ``N_STEPS`` step lengths and step times minus the walker's own gait's,
  against the hybrid walker's (its gait, the floor offset -H at the first step); the largest
  difference over the steps, and the raw difference (without subtracting the gaits);
* `pdw.max_step` (down, budget 100, return_tol 1e-3) of the compliant walker at each decade,
  against the hybrid's.

The figure (docs/figures/terrain_rigid_limit.png): the step-time responses and the errors
against k_n. The test (`tests/analysis/robust/test_terrain_rigid_limit.py`, in `make test`) is the 3-point
version of the response part.

Usage: .venv/bin/python benchmarks/terrain_rigid_limit.py [--quick] [--update-docs]
(about 3 minutes of CPU; --quick: no max_step, about 10 s)
"""
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
from _results import FIGURES, publish  # noqa: E402

import pdw  # noqa: E402
from pdw import hybrid as H  # noqa: E402
from pdw.analysis.robust import robustness as R  # noqa: E402
from pdw.analysis.robust import robustness_continuous as RC  # noqa: E402

P0 = pdw.Params.paper_steady()
K_N = (1e5, 3e5, 1e6, 3e6, 1e7, 3e7, 1e8, 3e8, 1e9)
K_MAX_STEP = (1e5, 1e6, 1e7, 1e8, 1e9)
HEIGHT = 0.003
N_STEPS = 6


def scaled(kn):
    return P0.replace(k_n=kn, d_n=P0.d_n * (kn / P0.k_n) ** (4 / 3))


def hybrid_response(gait, height, n):
    y, Y, T = np.asarray(gait.state, dtype=float), [], []
    for k in range(n):
        res = H.step(y, P0, dh=-height if k == 0 else 0.0)
        y = res["y_plus"]
        Y.append(y)
        T.append(res["t_strike"])
    return R.step_lengths(P0, gait.state, np.array(Y)), np.array(T)


def main(quick=False):
    t_all, c_all = time.perf_counter(), time.process_time()
    gh = H.find_gait(P0)
    Lh, Th = hybrid_response(gh, HEIGHT, N_STEPS)
    dLh, dTh = Lh - gh.step_length, Th - gh.period
    ms_h = pdw.max_step(P0, gait=gh)
    rows, curves, guess = [], {}, gh
    for kn in K_N:
        P = scaled(kn)
        c0 = time.process_time()
        g = pdw.find_gait(P, variant="consistent", guess=guess)
        guess = g
        status, L, T = RC.walk(P, g, pdw.Ground.step(RC.edge_at(g), -HEIGHT, width=0.01),
                               N_STEPS, variant="consistent")
        L, T = L[:N_STEPS], T[:N_STEPS]
        dL, dT = L - g.step_length, T - g.period
        curves[kn] = dT
        row = dict(k_n=kn, d_n=P.d_n, status=status, eL=np.abs(dL - dLh).max(),
                   eT=np.abs(dT - dTh).max(), rawL=np.abs(L - Lh).max(),
                   rawT=np.abs(T - Th).max(), cpu=time.process_time() - c0)
        if not quick and kn in K_MAX_STEP:
            c1 = time.process_time()
            m = pdw.max_step(P, model="continuous", gait=g, variant="consistent")
            row.update(ms=m.height, ms_hi=m.bracket[1], ms_cpu=time.process_time() - c1)
        rows.append(row)
    lines = ["Step-down in the rigid limit (benchmarks/terrain_rigid_limit.py%s): "
             "Params.paper_steady(), d_n = 1e6 (k_n/1e5)^(4/3), consistent variant, rodas4 "
             "rtol 1e-8" % (" --quick" if quick else ""),
             "step-down H = %.1f mm at L*/2 (Ground.step, width 1 cm); first %d steps"
             % (1e3 * HEIGHT, N_STEPS),
             "hybrid response dL [mm]: %s" % " ".join("%+.3f" % (1e3 * v) for v in dLh),
             "hybrid response dT [ms]: %s" % " ".join("%+.2f" % (1e3 * v) for v in dTh),
             "hybrid max step-down: %.3f mm (bracket %.3f-%.3f mm)"
             % (1e3 * ms_h.height, 1e3 * ms_h.bracket[0], 1e3 * ms_h.bracket[1]),
             "",
             "| k_n | d_n | response error L [m] | response error T [s] | raw error L [m] | "
             "raw error T [s] | max step-down [mm] | CPU [s] |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ms = ("%.3f (to %.3f)" % (1e3 * r["ms"], 1e3 * r["ms_hi"]) if "ms" in r else "")
        lines.append("| %.0e | %.2e | %.3e | %.3e | %.3e | %.3e | %s | %.1f |"
                     % (r["k_n"], r["d_n"], r["eL"], r["eT"], r["rawL"], r["rawT"], ms,
                        r["cpu"] + r.get("ms_cpu", 0.0)))
    k = np.log10([r["k_n"] for r in rows])
    for name in ("eL", "eT", "rawL", "rawT"):
        slope = np.polyfit(k[-5:], np.log10([r[name] for r in rows][-5:]), 1)[0]
        lines.append("last five k_n: %s ~ k_n^%.2f" % (name, slope))
    plot(rows, curves, dTh)
    lines += ["", "figure: %s (%.0f s wall, %.0f s CPU)"
              % (FIGURES / "terrain_rigid_limit.png", time.perf_counter() - t_all,
                 time.process_time() - c_all)]
    publish("terrain_rigid_limit%s.txt" % ("_quick" if quick else ""), lines)


def plot(rows, curves, dTh):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(1, 2, figsize=(11, 4.4), constrained_layout=True)
    ax = axs[0]
    steps = np.arange(N_STEPS)
    for i, kn in enumerate((1e5, 1e6, 1e7, 1e9)):
        if kn in curves:
            ax.plot(steps, 1e3 * curves[kn], "o-", ms=4, color="C%d" % i,
                    label=r"compliant, $k_n$ = %.0e" % kn)
    ax.plot(steps, 1e3 * dTh, "k*--", label="hybrid (rigid ground)")
    ax.set_xlabel("step after the %.0f mm step-down" % (1e3 * HEIGHT))
    ax.set_ylabel("step time - gait's [ms]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax = axs[1]
    kk = [r["k_n"] for r in rows]
    ax.loglog(kk, [r["eT"] for r in rows], "o-", label="response error, step time [s]")
    ax.loglog(kk, [r["eL"] for r in rows], "s-", label="response error, step length [m]")
    ax.loglog(kk, [r["rawT"] for r in rows], "o:", label="raw error, step time [s]")
    ax.loglog(kk, [r["rawL"] for r in rows], "s:", label="raw error, step length [m]")
    ax.set_xlabel(r"$k_n$ [N/m$^{1.5}$]  ($d_n \propto k_n^{4/3}$)")
    ax.set_ylabel("largest difference to the hybrid model, first %d steps" % N_STEPS)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.suptitle("Step-down in the rigid limit: the compliant walker's response converges to "
                 "the hybrid walker's (Params.paper_steady(), consistent variant)", fontsize=10)
    FIGURES.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURES / "terrain_rigid_limit.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
