"""The Poincaré-map users with and without the ensemble engine (docs/ensemble.md, "Where the
engine is used").

Interleaved in one process, round by round, each case once through the engine
(`pdw.analysis.stepmap.step_maps`: the finite differences and the cell map's images as walkers of one
`simulate_batch(stop_touch_down=1)`, rodas4 in structure-of-arrays lanes) and once with the
engine switched off (`step_maps.batchable` forced False: the thread pool of scalar `step`s, as
before): the Jacobian of the touch-down map at the `paper_steady` gait (find_gait's tolerances,
13 maps), `find_gait` from its default guesses, and a 20 x 20 cell map (LOOSE tolerances, 400
maps). Both give the same numbers (asserted here; tests/analysis/stepmap/test_step_maps.py). Wall and process CPU
time, medians of ROUNDS rounds, with 1 and 2 workers; the load average is printed before and
after (a shared machine: read the ratios, taken in the same rounds).

Run: `make bench` (or `.venv/bin/python benchmarks/bench_step_maps.py [ROUNDS] [--update-docs]`).
Writes step_maps.txt under out/benchmarks/results/ (--update-docs: benchmarks/results/).
"""
import os
import statistics
import sys
import time

import numpy as np
from _results import publish

import pdw
from pdw import cell_mapping as CM
from pdw import limit_cycle as LC
from pdw.analysis.stepmap import step_maps

ROUNDS = int(sys.argv[1]) if len(sys.argv) > 1 else 5
P = pdw.Params.paper_steady()
_BATCHABLE = step_maps.batchable


def engine(on):
    step_maps.batchable = _BATCHABLE if on else (lambda *a, **k: False)


def main():
    load0 = os.getloadavg()
    z = LC.find_gait(P).details["z"]

    def jac(workers):
        return lambda: LC.jacobian(z, P, workers=workers, **LC.TIGHT)[0]

    def gait(workers):
        return lambda: LC.find_gait(P, workers=workers).details["z"]

    def cells(workers):
        return lambda: CM.cell_map(P, phi=(0.55, 0.95, 20), thetad2=(-4.0, 0.0, 20),
                                   workers=workers).image_point

    cases = [("Jacobian, 13 maps (TIGHT)", jac), ("find_gait from its guesses", gait),
             ("cell map 20 x 20 (LOOSE)", cells)]
    rows = [(name, w, on) for name, _ in cases for w in (1, 2) for on in (False, True)]
    make = dict(cases)
    wall = {r: [] for r in rows}
    cpu = {r: [] for r in rows}
    for _ in range(ROUNDS):
        for name, w in dict.fromkeys((r[0], r[1]) for r in rows):
            got = {}
            for on in (False, True):
                engine(on)
                f = make[name](w)
                t0, c0 = time.perf_counter(), time.process_time()
                got[on] = f()
                wall[(name, w, on)].append(time.perf_counter() - t0)
                cpu[(name, w, on)].append(time.process_time() - c0)
            engine(True)
            assert np.array_equal(got[False], got[True], equal_nan=True), name
    load1 = os.getloadavg()
    lines = ["Poincare-map users with the ensemble engine (on) and without (off): paper_steady, "
             "rodas4; %d rounds interleaved, medians; results identical (asserted)" % ROUNDS,
             "load average before %.2f %.2f %.2f, after %.2f %.2f %.2f (%d cores)"
             % (load0 + load1 + (os.cpu_count(),)),
             "%-30s %7s %10s %10s %8s %10s %10s %8s" % ("case", "workers", "wall off", "wall on",
                                                         "wall x", "CPU off", "CPU on", "CPU x")]
    for name, _ in cases:
        for w in (1, 2):
            wo, wn = (statistics.median(wall[(name, w, on)]) for on in (False, True))
            co, cn = (statistics.median(cpu[(name, w, on)]) for on in (False, True))
            lines.append("%-30s %7d %9.3fs %9.3fs %7.2fx %9.3fs %9.3fs %7.2fx"
                         % (name, w, wo, wn, wo / wn, co, cn, co / cn))
    lines.append("off: the thread pool of scalar steps (pdw.limit_cycle.step); on: the points "
                 "through simulate_batch (find_gait's and the Jacobian's first point stays "
                 "scalar: its step dict is wanted); CPU: process CPU time")
    publish("step_maps.txt", lines)


if __name__ == "__main__":
    main()
