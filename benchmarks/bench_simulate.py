"""Speed and memory of the main job: the paper's typical gait, 3.5 s at dt = 1e-4 with the
central difference method (issue 23's goals).

* recording: the run with events only, with full recording and with every 10th state, in turn
  in each round (interleaved), CPU time (time.process_time), medians; ratios to events only;
  peak traced memory (tracemalloc) of each, and the bytes of the samples it records;
* the first call: `pdw.simulate()` (record=Record(every=0), the default step-size check) in fresh
  processes, first and second call of each process, CPU time; and the step check's parts for
  parameters of no preset in fresh processes;
* Python around a run: `pdw.simulate` of 2 steps against the compiled loop `_core.run` of the
  same 2 steps (CPU time per call, the difference is the Python set-up and Result assembly).

The load average is printed with the numbers: the development machine is shared, so read the
ratios (measured side by side), not the absolute times.

Run: `make bench` (or `.venv/bin/python benchmarks/bench_simulate.py [ROUNDS]`). Writes
benchmarks/results/simulate.txt with --update-docs (else out/benchmarks/results/).
"""
import os
import statistics
import subprocess
import sys
import time
import tracemalloc

import numpy as np
from _results import publish

import pdw
from pdw.core import _core, _layout
from pdw.core.model import parameter_vector

ROUNDS = int(sys.argv[1]) if len(sys.argv) > 1 else 21
FRESH = 7
clock = time.process_time
SAMPLE = 8 * (1 + _core.NX + 1 + len(_layout.RECORD_CONTACT))
CASES = [
    ("events only", dict(record=pdw.Record(every=0, forces=False))),
    ("full recording (state, flags, forces every step)", dict(record=pdw.Record(every=1, forces=True))),
    ("state every 10th step", dict(record=pdw.Record(every=10, forces=False))),
]
# the first and second call of a fresh process: the preset parameters (whose step limits are
# precomputed, pdw.sim.stepsize_presets) and parameters of no preset (k_n 10 % up: the check
# computes the limits, cut short, pdw.sim.stepsize._safe)
FIRST_CALL = """
import sys, time, pdw
P = pdw.Params.paper()
P = P if sys.argv[1] == "preset" else P.replace(k_n=1.1 * P.k_n)
R = pdw.Record(every=0)
t = time.process_time(); pdw.simulate(params=P, record=R); t1 = time.process_time()
pdw.simulate(params=P, record=R); t2 = time.process_time()
print(t1 - t, t2 - t1)
"""

# the parts of the step check of new parameters in a fresh process (after `import pdw`), CPU
# time: the representative states, their Jacobians, the stability searches (cut short as in
# `check_step` at dt = 1e-4), the friction load
CHECK_PARTS = """
import time, pdw
from pdw.sim import stepsize as S
c = time.process_time
P = pdw.Params.paper(); P = P.replace(k_n=1.1 * P.k_n)
t0 = c(); X, fl = S.stance_states(P, "paper"); t1 = c()
Js = S._state_jacobians(X, P, fl, "paper"); t2 = c()
S.linear_limits("cdm", Js, enough=lambda h: not 1e-4 > S.CALIBRATION["paper"]["cdm"] * h)
t3 = c(); S._friction_load(P, "paper"); t4 = c()
print(t1 - t0, t2 - t1, t3 - t2, t4 - t3)
"""
PARTS = ("representative states", "Jacobians", "stability searches", "friction load")


def load():
    return "load %.1f %.1f %.1f" % os.getloadavg()


def peak_memory(**kw):
    tracemalloc.start()
    r = pdw.simulate(**kw)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak, r


def recording(lines):
    P = pdw.Params.paper()
    times = {label: [] for label, _ in CASES}
    for _label, kw in CASES:                    # warm: the step check, the allocator
        pdw.simulate(params=P, **kw)
    for _ in range(ROUNDS):
        for label, kw in CASES:
            t = clock()
            pdw.simulate(params=P, **kw)
            times[label].append(clock() - t)
    base = statistics.median(times[CASES[0][0]])
    lines += ["typical gait: Params.paper(), X0_PAPER, 3.5 s, dt = 1e-4 (35,000 steps), method cdm",
              "CPU time of pdw.simulate (Python set-up included), median of %d interleaved rounds; %s"
              % (ROUNDS, load()), "",
              "%-50s %8s %8s %9s %11s %11s" % ("recording", "ms", "ns/step", "vs events", "peak MB",
                                              "samples MB")]
    for label, kw in CASES:
        t = statistics.median(times[label])
        mem, r = peak_memory(params=P, **kw)
        assert r.status == "walked"
        rec = len(r.t) * (SAMPLE if kw["record"].forces else SAMPLE - 8 * len(_layout.RECORD_CONTACT))
        lines.append("%-50s %8.2f %8.1f %8.2fx %11.3f %11.3f" % (
            label, 1e3 * t, 1e9 * t / r.n_steps, t / base, mem / 1e6, rec / 1e6))


def first_call(lines):
    lines += ["", "first call of a fresh process (simulate(params=P, record=Record(every=0)), the "
              "default step check), %d processes of each kind, interleaved; %s" % (FRESH, load())]
    runs: dict = {"preset": ([], []), "other": ([], [])}
    for _ in range(FRESH):
        for kind, (firsts, seconds) in runs.items():
            out = subprocess.run([sys.executable, "-c", FIRST_CALL, kind], capture_output=True,
                                 text=True, check=True).stdout.split()
            firsts.append(float(out[0]))
            seconds.append(float(out[1]))
    parts = [[float(v) for v in subprocess.run(
        [sys.executable, "-c", CHECK_PARTS], capture_output=True, text=True,
        check=True).stdout.split()] for _ in range(FRESH)]
    for kind, (firsts, seconds) in runs.items():
        a, b = statistics.median(firsts), statistics.median(seconds)
        lines.append("  %-44s first %.2f ms, second %.2f ms: first / second = %.2fx (per "
                     "process: %s)" % ("Params.paper() (preset)" if kind == "preset" else
                                       "Params.paper() with k_n x 1.1 (no preset)", 1e3 * a,
                                       1e3 * b, a / b, ", ".join("%.2f" % (f / s) for f, s
                                                                 in zip(firsts, seconds))))
    lines.append("  the check of k_n x 1.1 in a fresh process, by part (medians of %d more "
                 "processes): %s" % (FRESH, ", ".join(
                     "%s %.3f ms" % (name, 1e3 * statistics.median(p[i] for p in parts))
                     for i, name in enumerate(PARTS))))


def python_overhead(lines, n=2000):
    P = pdw.Params.paper()
    x, p = np.asarray(pdw.X0_PAPER, dtype=float), parameter_vector(P)
    R0 = pdw.Record(every=0)
    opts = dict(dt=1e-4, n_steps=2, record_events=1, fall_hip_height=0.25, fall_depth=0.125,
                max_speed=1e3, rtol=1e-6, atol=1e-8, event_tol=1e-9)
    jobs = {
        "simulate, 2 steps, params given": lambda: pdw.simulate(params=P, t_end=2e-4, record=R0),
        "simulate, 2 steps, defaults": lambda: pdw.simulate(t_end=2e-4, record=R0),
        "_core.run, 2 steps": lambda: _core.run(0, 0, x, p, 0, 1, opts),
    }
    times = {k: [] for k in jobs}
    for f in jobs.values():
        f()
    for _ in range(7):
        for k, f in jobs.items():
            t = clock()
            for _ in range(n // 7):
                f()
            times[k].append((clock() - t) / (n // 7))
    med = {k: statistics.median(v) for k, v in times.items()}
    lines += ["", "Python around a run: CPU time per call, median of 7 interleaved rounds of %d "
              "calls; %s" % (n // 7, load())]
    for k, v in med.items():
        lines.append("  %-40s %7.1f us" % (k, 1e6 * v))
    lines.append("  Python set-up and Result (simulate - _core.run): %.1f us (defaults: %.1f us)"
                 % (1e6 * (med["simulate, 2 steps, params given"] - med["_core.run, 2 steps"]),
                    1e6 * (med["simulate, 2 steps, defaults"] - med["_core.run, 2 steps"])))


def main():
    lines = []
    recording(lines)
    first_call(lines)
    python_overhead(lines)
    publish("simulate.txt", lines)


if __name__ == "__main__":
    main()
