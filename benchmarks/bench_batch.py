"""The ensemble engine against the scalar loop: walker-steps per second per core.

N walkers of the paper run (cdm, dt = 1e-4, t_end = 3.5 s, initial states around the paper's,
a few of which fall), no recording. Interleaved in one process, round by round: the scalar
`pdw.simulate` over the walkers one after the other (nothing recorded: `pdw.Record(every=0,
events=False)`), and `pdw.simulate_batch` with W lanes: every cdm lane loop this CPU runs at
W = 8 (PDW_BATCH_ISA: "scalar" = the generated scalar stages per lane, then the
structure-of-arrays step compiled for the baseline, AVX2, AVX-512F), bitwise (libm sin/cos),
then the widest at cdm's default W (`pdw.sim.batch.LANES`, 16) bitwise, and at 8 and the default
with vector (libmvec) sin/cos, on 1 thread, then at the default on 2 threads; a batch of 1
walker per call (N calls, default lanes; the serial loop with libm's trig, the lanes with
vector sin/cos); and rodas4 (rtol 1e-6, atol 1e-8) scalar against batch, per accepted step, on
every rodas4 lane loop ("scalar" = the scalar rodas4 per lane, then its structure-of-arrays
try step per instruction set, at W = 8 (its default, `LANES_OTHER`) and 16; bitwise, and once
with vector sin/cos).
Medians of ROUNDS rounds; the load average is printed before and after (the machine is shared:
read the ratios, taken in the same rounds, before the times).

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
from pdw.core import _batch
from pdw.sim.batch import ISA_ENV, LANES, LANES_OTHER

N = int(sys.argv[1]) if len(sys.argv) > 1 else 64
ROUNDS = int(sys.argv[2]) if len(sys.argv) > 2 else 5
T_END, DT, RTOL = 3.5, 1e-4, 1e-6


def states(n):
    rng = np.random.default_rng(0)
    x = np.tile(np.asarray(pdw.X0_PAPER, float), (n, 1))
    x[:, 6] += rng.uniform(-0.3, 0.3, n)
    x[:, 7] += rng.uniform(-0.3, 0.3, n)
    return x


def main():
    x = states(N)
    best = _batch.best_isa()
    load0 = os.getloadavg()

    # the option objects of simulate/simulate_batch (pdw.sim.options)
    cdm = pdw.Integrator(dt=DT, check_step="off")
    ros = pdw.Integrator(method="rodas4", rtol=RTOL, check_step="off")
    quiet = dict(record=pdw.Record(every=0, events=False),
                 limits=pdw.Limits(on_failure="return"))

    def scalar():
        return sum(pdw.simulate(xi, T_END, integrator=cdm, **quiet).n_steps for xi in x)

    def batch(lanes, vector, threads, isa=best):
        def run():
            os.environ[ISA_ENV] = isa
            try:
                return int(pdw.simulate_batch(x, T_END, integrator=cdm, lanes=lanes,
                                              vector=vector, threads=threads).n_steps.sum())
            finally:
                os.environ.pop(ISA_ENV)
        return run

    def batch_of_one(vector=False):
        def run():
            return sum(int(pdw.simulate_batch(xi[None], T_END, integrator=cdm, vector=vector,
                                              threads=1).n_steps.sum())
                       for xi in x)
        return run

    def scalar_rodas():
        return sum(pdw.simulate(xi, T_END, integrator=ros, **quiet).n_steps for xi in x)

    def batch_rodas(lanes, threads, isa=best, vector=False):
        def run():
            os.environ[ISA_ENV] = isa
            try:
                return int(pdw.simulate_batch(x, T_END, integrator=ros, lanes=lanes,
                                              threads=threads, vector=vector).n_steps.sum())
            finally:
                os.environ.pop(ISA_ENV)
        return run

    isas = [n for n in ("scalar", "base", "avx2", "avx512") if _batch.isa_supported(n)]
    W = LANES
    cases = [("scalar simulate, 1 thread", scalar, 1)]
    cases += [("batch W=8 bitwise %s, 1 thr" % n, batch(8, False, 1, n), 1) for n in isas]
    cases += [("batch W=%d bitwise %s, 1 thr" % (W, best), batch(W, False, 1), 1),
              ("batch W=8 vector %s, 1 thr" % best, batch(8, True, 1), 1),
              ("batch W=%d vector %s, 1 thr" % (W, best), batch(W, True, 1), 1),
              ("batch of 1 walker (N calls), bitwise", batch_of_one(), 1),
              ("batch of 1 walker (N calls), vector", batch_of_one(True), 1),
              ("batch W=%d bitwise %s, 2 thr" % (W, best), batch(W, False, 2), 2),
              ("batch W=%d vector %s, 2 thr" % (W, best), batch(W, True, 2), 2),
              ("rodas4: scalar simulate, 1 thr", scalar_rodas, 1)]
    cases += [("rodas4: batch W=8 %s, 1 thr" % n, batch_rodas(8, 1, n), 1) for n in isas]
    cases += [("rodas4: batch W=16 %s, 1 thr" % best, batch_rodas(16, 1), 1),
              ("rodas4: batch W=8 vector %s, 1 thr" % best, batch_rodas(8, 1, vector=True), 1),
              ("rodas4: batch W=%d %s, 2 thr" % (LANES_OTHER, best),
               batch_rodas(LANES_OTHER, 2), 2)]
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
    lines = ["Ensemble engine vs scalar loop: %d walkers, paper run (cdm, dt = %g, t_end = %g s; "
             "rodas4 rtol = %g), %d rounds interleaved, medians" % (N, DT, T_END, RTOL, ROUNDS),
             "load average before %.2f %.2f %.2f, after %.2f %.2f %.2f (%d cores); widest "
             "lane loop this CPU runs: %s" % (load0 + load1 + (os.cpu_count(), best)),
             "%-36s %11s %10s %12s %12s %10s" % ("case", "wall ns/ws", "vs scalar", "CPU ns/ws",
                                                 "ws/CPU-s", "vs scalar"),
             ]
    for name, _, _ in cases:
        base = cases[0][0] if not name.startswith("rodas4") else "rodas4: scalar simulate, 1 thr"
        ref = statistics.median(times[base]) / steps[base]
        ref_cpu = statistics.median(cpu[base]) / steps[base]
        per = statistics.median(times[name]) / steps[name]
        per_cpu = statistics.median(cpu[name]) / steps[name]
        lines.append("%-36s %11.1f %9.2fx %12.1f %12.3g %9.2fx" % (
            name, per * 1e9, ref / per, per_cpu * 1e9, 1 / per_cpu, ref_cpu / per_cpu))
    lines.append("ws = walker-step (rodas4: accepted step, vs the scalar rodas4 loop). wall: elapsed time / walker-steps (2 threads: both cores); "
                 "CPU: process CPU time / walker-steps, i.e. the cost per core (less sensitive "
                 "to a shared machine's load than wall time)")
    publish("batch.txt", lines)


if __name__ == "__main__":
    main()
