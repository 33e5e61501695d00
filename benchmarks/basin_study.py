"""The basin of attraction of the `paper_steady` gait on the (phi, thetad2) slice of the
touch-down section, with the ensemble engine (pdw.analysis.basin), and the scalar path's time
for the same grid extrapolated from a sample of scalar `pdw.simulate` runs.

Run: `.venv/bin/python benchmarks/basin_study.py [N] [SAMPLE] [--update-docs]` (N x N grid,
default 100; SAMPLE scalar runs, default 40). Writes basin_paper_steady.png, basin.txt and
basin.npz under out/benchmarks/ (with --update-docs: docs/figures/, benchmarks/results/).
"""
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from _results import FIGURES, RESULTS, publish  # noqa: E402

import pdw  # noqa: E402
from pdw.analysis import basin as B  # noqa: E402
from pdw.analysis import cell_mapping as cmap  # noqa: E402
from pdw.analysis import limit_cycle as lc  # noqa: E402

N = int(sys.argv[1]) if len(sys.argv) > 1 else 100
SAMPLE = int(sys.argv[2]) if len(sys.argv) > 2 else 40
PHI, THD2, T_END = (0.55, 0.95), (-4.0, 0.0), 8.0
FIG = FIGURES / "basin_paper_steady.png"


def main():
    load0 = os.getloadavg()
    b = B.basin(phi=PHI + (N,), thetad2=THD2 + (N,), t_end=T_END)
    # the scalar path on a random sample of the same grid points: pdw.simulate one by one
    p = pdw.Params.paper_steady()
    rest = cmap.rest_of(b.reference, p)
    rng = np.random.default_rng(0)
    ia, ib = rng.integers(0, N, SAMPLE), rng.integers(0, N, SAMPLE)
    t0 = time.perf_counter()
    agree = 0
    for i, j in zip(ia, ib):
        x = lc.embed(cmap.cell_state(b.phi[i], b.thetad2[j], rest, p), p)
        r = pdw.simulate(x, t_end=T_END, params=p, flags0=(1, 1), record_every=0,
                         record_events=False, periodic_steps=4, on_failure="return")
        agree += r.n_gait_steps == b.n_steps[j, i]
    per_scalar = (time.perf_counter() - t0) / SAMPLE
    load1 = os.getloadavg()
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    B.plot(b, ax=ax, title="paper_steady basin, %d x %d touch-down states (cdm, dt = 1e-4)"
           % (N, N))
    fig.tight_layout()
    FIG.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIG, dpi=120)
    lines = ["Basin of paper_steady on phi in %s rad x thetad2 in %s rad/s, %d x %d, t_end %g s, "
             "periodic_steps 4" % (PHI, THD2, N, N, T_END),
             "load average before %.2f %.2f %.2f, after %.2f %.2f %.2f (%d cores)"
             % (load0 + load1 + (os.cpu_count(),)),
             "reference gait: L = %.4f m, P = %.4f s" % (b.gait_L, b.gait_P),
             "outcomes: " + ", ".join("%s %.1f %%" % (n, 100 * b.fraction(k))
                                      for k, n in enumerate(B.OUTCOMES)),
             "batch engine: %.1f s for %d walkers (%.2f ms each, %d threads)"
             % (b.wall_time, b.walkers, 1e3 * b.wall_time / b.walkers, os.cpu_count()),
             "scalar simulate, 1 thread: %.2f ms per walker on %d random grid points "
             "(%d/%d same number of gait steps as the batch)" % (1e3 * per_scalar, SAMPLE, agree,
                                                                 SAMPLE),
             "extrapolated scalar time for this grid: %.0f s (1 thread), %.0f s (2 threads, ideal)"
             % (per_scalar * b.walkers, per_scalar * b.walkers / 2),
             "extrapolated for 400 x 400: batch %.0f s, scalar 1 thread %.0f s"
             % (b.wall_time / b.walkers * 160000, per_scalar * 160000),
             "figure: %s" % FIG.relative_to(FIG.parents[2])]
    publish("basin.txt", lines)
    np.savez_compressed(RESULTS / "basin.npz", phi=b.phi,
                        thetad2=b.thetad2, outcome=b.outcome, n_steps=b.n_steps)


if __name__ == "__main__":
    main()
