"""The speed target of issue 22: a mean first-passage time with a +-10 % confidence interval, at
a roughness where the MFPT is about 100 steps, in at most 5 minutes on 2 cores
(docs/robustness.md, "Speed").

The hybrid walker (`Params.paper_steady()`) on i.i.d. Gaussian step heights of sigma = 1.6 mm
(MFPT about 95 steps): `pdw.first_passage` with walkers added in batches of 100 until the
interval's half-width is at most 10 % of the estimate, with 1 and 2 threads, interleaved, each
ROUNDS times (medians). Then the compliant walker on its own `Ground.random(1.4 mm, 0.1 m)` per
walker (MFPT about 100 steps), censored at 400 steps, 2 threads, once. Wall and process CPU
time; the load average before and after (a shared machine: read CPU time and the ratio).

Run: `make bench` (or `.venv/bin/python benchmarks/bench_mfpt.py [ROUNDS] [--update-docs]`).
Writes mfpt.txt under out/benchmarks/results/ (--update-docs: benchmarks/results/).
"""
import os
import statistics
import sys
import time

from _results import publish

import pdw

ROUNDS = int(sys.argv[1]) if len(sys.argv) > 1 else 3
P = pdw.Params.paper_steady()
SIGMA = 0.0016


def until_ten_percent(gait, threads, seed, **kw):
    """Walkers in batches of 100 (one resumable file: each call runs only the new walkers)
    until the CI is within +-10 %."""
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        n = 0
        while True:
            n += 100
            args = kw or dict(sigma=SIGMA, max_steps=2000)
            fp = pdw.first_passage(P, walkers=n, gait=gait, seed=seed, threads=threads,
                                   path=os.path.join(d, "w.csv"), **args)
            if fp.rel_halfwidth <= 0.10:
                return fp


def main():
    load0 = os.getloadavg()
    gait = pdw.hybrid.find_gait(P)
    runs = {1: [], 2: []}
    out = {}
    for r in range(ROUNDS):
        for threads in (1, 2):
            w0, c0 = time.perf_counter(), time.process_time()
            fp = until_ten_percent(gait, threads, seed=r)
            runs[threads].append((time.perf_counter() - w0, time.process_time() - c0))
            out[threads] = fp
    load1 = os.getloadavg()
    lines = ["MFPT with a +-10 %% confidence interval (95 %%), hybrid walker paper_steady, "
             "step heights N(0, %.1f mm), median of %d rounds" % (SIGMA * 1e3, ROUNDS),
             "load average before %.2f %.2f %.2f, after %.2f %.2f %.2f (2 cores shared)"
             % (*load0, *load1), ""]
    lines.append("%-8s %10s %10s %12s %10s %9s" % ("threads", "wall [s]", "CPU [s]", "MFPT",
                                                  "walkers", "+-"))
    for threads in (1, 2):
        wall = statistics.median(x[0] for x in runs[threads])
        cpu = statistics.median(x[1] for x in runs[threads])
        fp = out[threads]
        lines.append("%-8d %10.2f %10.2f %12.1f %10d %8.1f%%"
                     % (threads, wall, cpu, fp.mfpt, fp.walkers, 100 * fp.rel_halfwidth))
    cg = pdw.find_gait(P)
    w0, c0 = time.perf_counter(), time.process_time()
    fp = until_ten_percent(cg, 2, 0, model="continuous",
                           ground=pdw.Ground.random(0.0014, 0.1), max_steps=400)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    lines += ["", "compliant walker, its own Ground.random(1.4 mm, 0.1 m) per walker, censored at "
              "400 steps, 2 threads:",
              "%-8d %10.2f %10.2f %12.1f %10d %8.1f%%   (%d censored)"
              % (2, wall, cpu, fp.mfpt, fp.walkers, 100 * fp.rel_halfwidth, fp.censored),
              "load average at the end %.2f %.2f %.2f" % os.getloadavg(),
              "", "target: at most 300 s on 2 cores"]
    publish("mfpt.txt", lines)


if __name__ == "__main__":
    main()
