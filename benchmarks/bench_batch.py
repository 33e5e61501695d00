"""The ensemble engine against the scalar loop: walker-steps per second per core.

N walkers of the paper run (cdm, dt = 1e-4, t_end = 3.5 s, initial states around the paper's,
a few of which fall), no recording. Interleaved in one process, round by round: the scalar
`pdw.simulate` over the walkers one after the other (record_every=0, record_events=False), and
`pdw.simulate_batch` with W lanes, bitwise (scalar libm sin/cos) and vector (libmvec sin/cos),
on 1 thread, then on 2 threads. Medians of ROUNDS rounds; the load average is printed before
and after (the machine is shared: read the ratios, taken in the same rounds, before the times).

Run: `make bench` (or `.venv/bin/python benchmarks/bench_batch.py [N] [ROUNDS] [--update-docs]`).
Writes batch.txt under out/benchmarks/results/ (--update-docs: benchmarks/results/).
"""
import os
import statistics
import sys
import time

import numpy as np
from _results import publish

import pdw

N = int(sys.argv[1]) if len(sys.argv) > 1 else 64
ROUNDS = int(sys.argv[2]) if len(sys.argv) > 2 else 5
T_END, DT = 3.5, 1e-4


def states(n):
    rng = np.random.default_rng(0)
    x = np.tile(np.asarray(pdw.X0_PAPER, float), (n, 1))
    x[:, 6] += rng.uniform(-0.3, 0.3, n)
    x[:, 7] += rng.uniform(-0.3, 0.3, n)
    return x


def main():
    x = states(N)
    load0 = os.getloadavg()

    def scalar():
        n = 0
        for xi in x:
            n += pdw.simulate(xi, t_end=T_END, dt=DT, record_every=0, record_events=False,
                              on_failure="return", check_step="off").n_steps
        return n

    def batch(lanes, vector, threads):
        return lambda: int(pdw.simulate_batch(x, t_end=T_END, dt=DT, lanes=lanes, vector=vector,
                                              threads=threads, check_step="off").n_steps.sum())

    cases = [("scalar simulate, 1 thread", scalar, 1),
             ("batch W=1 bitwise, 1 thread", batch(1, False, 1), 1),
             ("batch W=8 bitwise, 1 thread", batch(8, False, 1), 1),
             ("batch W=8 vector, 1 thread", batch(8, True, 1), 1),
             ("batch W=16 vector, 1 thread", batch(16, True, 1), 1),
             ("batch W=8 bitwise, 2 threads", batch(8, False, 2), 2),
             ("batch W=8 vector, 2 threads", batch(8, True, 2), 2)]
    times = {name: [] for name, _, _ in cases}
    cpu = {name: [] for name, _, _ in cases}
    steps = {}
    for _ in range(ROUNDS):
        for name, f, _ in cases:
            t0, c0 = time.perf_counter(), time.process_time()
            steps[name] = f()
            times[name].append(time.perf_counter() - t0)
            cpu[name].append(time.process_time() - c0)
    load1 = os.getloadavg()
    ref = statistics.median(times[cases[0][0]]) / steps[cases[0][0]]
    ref_cpu = statistics.median(cpu[cases[0][0]]) / steps[cases[0][0]]
    lines = ["Ensemble engine vs scalar loop: %d walkers, paper run (cdm, dt = %g, t_end = %g s), "
             "%d rounds interleaved, medians" % (N, DT, T_END, ROUNDS),
             "load average before %.2f %.2f %.2f, after %.2f %.2f %.2f (%d cores)"
             % (load0 + load1 + (os.cpu_count(),)),
             "%-30s %11s %10s %12s %12s %10s" % ("case", "wall ns/ws", "vs scalar", "CPU ns/ws",
                                                 "ws/CPU-s", "vs scalar"),
             ]
    for name, _, _ in cases:
        per = statistics.median(times[name]) / steps[name]
        per_cpu = statistics.median(cpu[name]) / steps[name]
        lines.append("%-30s %11.1f %9.2fx %12.1f %12.3g %9.2fx" % (
            name, per * 1e9, ref / per, per_cpu * 1e9, 1 / per_cpu, ref_cpu / per_cpu))
    lines.append("ws = walker-step. wall: elapsed time / walker-steps (2 threads: both cores); "
                 "CPU: process CPU time / walker-steps, i.e. the cost per core (less sensitive "
                 "to a shared machine's load than wall time)")
    publish("batch.txt", lines)


if __name__ == "__main__":
    main()
