"""The basin of attraction of the `paper_steady` gait on the (phi, thetad2) slice of the
touch-down section, with the ensemble engine (pdw.analysis.basins.basin), and the scalar path's time
for the same grid extrapolated from a random sample of grid points run with scalar
`pdw.simulate` in the same run (same threads), with the verdict agreement on that sample; on
that sample, scalar and batch runs are also timed against each other in interleaved rounds.

Run: `.venv/bin/python benchmarks/basin_study.py [N] [SAMPLE] [--update-docs]` (N x N grid,
default 400; SAMPLE scalar runs, default 200). Resumable: the grid is computed in chunks and
checkpointed to out/benchmarks/basin_<N>.ckpt.npz after each chunk; rerunning the same command
after an interruption computes only the missing chunks (the batch time reported is the sum over
all chunks). Writes basin_paper_steady.png, basin.txt and basin.npz under out/benchmarks/ (with
--update-docs: docs/figures/, benchmarks/results/).
"""
import os
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from _results import FIGURES, RESULTS, ROOT, publish  # noqa: E402

import pdw  # noqa: E402
from pdw.analysis.basins import basin as B  # noqa: E402
from pdw.analysis.basins import cell_mapping as cmap  # noqa: E402
from pdw.analysis.stepmap import limit_cycle as lc  # noqa: E402

N = int(sys.argv[1]) if len(sys.argv) > 1 else 400
SAMPLE = int(sys.argv[2]) if len(sys.argv) > 2 else 200
ROUNDS = 3
PHI, THD2, T_END = (0.55, 0.95), (-4.0, 0.0), 8.0
FIG = FIGURES / "basin_paper_steady.png"
THREADS = os.cpu_count() or 1


def scalar_outcome(r, b):
    """The basin's class of one scalar run (the rules of pdw.analysis.basins.basin)."""
    if r.status == "periodic":
        same = (abs(r.gait["L"][-1] - b.gait_L) <= 0.02 * abs(b.gait_L)
                and abs(r.gait["P"][-1] - b.gait_P) <= 0.02 * b.gait_P)
        return B.GAIT if same else B.OTHER
    return B.UNDECIDED if r.status == "walked" else B.FELL


def main():
    load0 = os.getloadavg()
    ckpt = ROOT / "out" / "benchmarks" / ("basin_%d.ckpt.npz" % N)
    b = B.basin(phi=PHI + (N,), thetad2=THD2 + (N,), t_end=T_END, chunk_size=8000,
                checkpoint=ckpt, progress=True)
    # the scalar path on a random sample of the same grid points: pdw.simulate, same threads
    p = pdw.Params.paper_steady()
    rest = cmap.rest_of(b.reference, p)
    rng = np.random.default_rng(0)
    flat = rng.choice(N * N, size=min(SAMPLE, N * N), replace=False)
    jb, ia = np.divmod(flat, N)                  # row: thetad2 (j), column: phi (i)

    X = np.array([lc.embed(cmap.cell_state(b.phi[ia[k]], b.thetad2[jb[k]], rest, p), p)
                  for k in range(len(flat))])

    def one(k):
        return pdw.simulate(X[k], t_end=T_END, params=p, flags0=(1, 1),
                            integrator=pdw.Integrator(check_step="off"),
                            record=pdw.Record(every=0, forces=False, events=False),
                            stop=pdw.Stop(periodic=True, periodic_steps=4),
                            limits=pdw.Limits(on_failure="return"))

    def scalar():
        with ThreadPoolExecutor(THREADS) as ex:
            return list(ex.map(one, range(len(flat))))

    def batch():
        return pdw.simulate_batch(X, t_end=T_END, params=p, flags0=(1, 1),
                                  stop=pdw.Stop(periodic=True, periodic_steps=4),
                                  threads=THREADS, integrator=pdw.Integrator(check_step="off"))
    # the sample, scalar and batch interleaved (ROUNDS rounds, medians)
    times = {"scalar": [], "batch": []}
    for _ in range(ROUNDS):
        for name, fn in (("scalar", scalar), ("batch", batch)):
            t0, c0 = time.perf_counter(), time.process_time()
            out = fn()
            times[name].append((time.perf_counter() - t0, time.process_time() - c0))
            if name == "scalar":
                runs = out
    med = {k: [sorted(t[j] for t in v)[len(v) // 2] / len(flat) for j in (0, 1)]
           for k, v in times.items()}
    per_scalar, cpu_scalar = med["scalar"]
    same_class = sum(scalar_outcome(r, b) == b.outcome[jb[k], ia[k]] for k, r in enumerate(runs))
    same_steps = sum(r.n_gait_steps == b.n_steps[jb[k], ia[k]] for k, r in enumerate(runs))
    load1 = os.getloadavg()
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    B.plot(b, ax=ax, title="paper_steady basin, %d x %d touch-down states (cdm, dt = 1e-4)"
           % (N, N))
    fig.tight_layout()
    FIG.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIG, dpi=120)
    per_batch = b.wall_time / b.walkers
    lines = ["Basin of paper_steady on phi in %s rad x thetad2 in %s rad/s, %d x %d, t_end %g s, "
             "periodic_steps 4" % (PHI, THD2, N, N, T_END),
             "load average before %.2f %.2f %.2f, after %.2f %.2f %.2f (%d cores)"
             % (load0 + load1 + (os.cpu_count(),)),
             "reference gait: L = %.4f m, P = %.4f s" % (b.gait_L, b.gait_P),
             "outcomes: " + ", ".join("%s %.1f %%" % (n, 100 * b.fraction(k))
                                      for k, n in enumerate(B.OUTCOMES)),
             "batch engine (simulate_batch, bitwise path, %d threads, chunks of 8000, "
             "checkpointed): %.1f s for %d walkers (%.3f ms each)"
             % (THREADS, b.wall_time, b.walkers, 1e3 * per_batch),
             "  process CPU time of the grid's chunks: %.1f s (%.3f ms per walker)"
             % (b.cpu_time, 1e3 * b.cpu_time / b.walkers),
             "sample of %d random grid points, %d interleaved rounds, medians per walker, %d "
             "threads: scalar simulate %.3f ms wall, %.3f ms CPU; simulate_batch %.3f ms wall, "
             "%.3f ms CPU; batch/scalar speed-up %.2fx wall, %.2fx CPU"
             % (len(flat), ROUNDS, THREADS, 1e3 * per_scalar, 1e3 * cpu_scalar,
                1e3 * med["batch"][0], 1e3 * med["batch"][1], per_scalar / med["batch"][0],
                cpu_scalar / med["batch"][1]),
             "verdict agreement on the sample: %d/%d same class, %d/%d same number of gait steps"
             % (same_class, len(flat), same_steps, len(flat)),
             "scalar path for this grid, extrapolated from the sample's scalar median: %.0f s wall, "
             "%.0f s CPU (%d threads); the grid's batch time over it: wall %.2fx, CPU %.2fx"
             % (per_scalar * b.walkers, cpu_scalar * b.walkers, THREADS,
                per_scalar / per_batch, cpu_scalar * b.walkers / b.cpu_time),
             "figure: %s" % FIG.relative_to(FIG.parents[2])]
    publish("basin.txt", lines)
    np.savez_compressed(RESULTS / "basin.npz", phi=b.phi, thetad2=b.thetad2, outcome=b.outcome,
                        n_steps=b.n_steps)


if __name__ == "__main__":
    main()
