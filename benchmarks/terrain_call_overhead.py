"""What a ground costs per call and per step (docs/terrain.md "Costs"): CPU time of
``pdw.simulate`` (cdm, paper_steady, no recording) for 0.01 s and 2 s, with no ground, the 52 m
sine of bench_terrain.py, the same sine on 6 m and the bench's random ground; medians of
interleaved rounds. The 0.01 s run is the per-call cost (set-up, the compiled ground, the
result), the slope between the two the marginal cost per integration step, which the per-call
cost does not reach. The Ground objects are made once, as a user's study reuses them.

    .venv/bin/python benchmarks/terrain_call_overhead.py [rounds]     (default 9)
"""
import os
import sys
import time

import numpy as np

import pdw
from pdw import Ground

P = pdw.Params.paper_steady()
GROUNDS = {"none": None, "sine 52 m": Ground.sine(0.001, 0.8),
           "sine 6 m": Ground.sine(0.001, 0.8, extent=(-1.0, 5.0)),
           "random 6 m": Ground.random(0.0005, 0.1, seed=1, extent=(-1.0, 5.0))}
T_SHORT, T_LONG = 0.01, 2.0


def run(g, t_end):
    t0 = time.process_time()
    r = pdw.simulate(params=P, method="cdm", t_end=t_end, record=pdw.Record(every=0),
                     limits=pdw.Limits(on_failure="return"), ground=g)
    return time.process_time() - t0, r.n_steps


def main(rounds):
    for g in GROUNDS.values():
        run(g, T_SHORT)
    res = {k: {T_SHORT: [], T_LONG: []} for k in GROUNDS}
    steps = {}
    for _ in range(rounds):
        for k, g in GROUNDS.items():
            for t in (T_SHORT, T_LONG):
                c, n = run(g, t)
                res[k][t].append(c)
                steps[k, t] = n
    print("terrain_call_overhead: cdm, paper_steady, medians of %d interleaved rounds; load "
          "average %.2f on %d CPUs" % (rounds, os.getloadavg()[0], os.cpu_count()))
    base = None
    for k in GROUNDS:
        a, b = np.median(res[k][T_SHORT]), np.median(res[k][T_LONG])
        slope = (b - a) / (steps[k, T_LONG] - steps[k, T_SHORT])
        base = slope if base is None else base
        print("  %-11s per call (%.2f s run) %6.1f us   per step (slope) %5.1f ns  ratio %.3f"
              % (k, T_SHORT, a * 1e6, slope * 1e9, slope / base))


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 and sys.argv[1].isdigit() else 9)
