"""What a scene's needs cost: the same gait under scenes of decreasing needs (docs/scenes.md).

The steady typical gait (Params.paper_steady(), X0_PAPER, the paper's central difference method
at dt = 1e-4) for up to 10 s, recorded in full, then with less and less: events only, gait
descriptors only (computed online in the compiled loop), the tangential spring-damper
switched off (a specialized generated kernel, paper_no_tangential), and descriptors only with
the run stopped as soon as four successive steps agree within 0.1 % (with all forces, and
without the tangential spring-damper). For each: the median wall time of
`pdw.run(scene)` over repeated runs in this one process (Python set-up and result included) and
the peak traced memory (tracemalloc, which sees NumPy's buffers). Then the memory of a
descriptors-only run of 10^3 steps against one of 10^6 steps.

Run: `make bench` (or `.venv/bin/python benchmarks/bench_scenes.py`). Prints a table and
writes benchmarks/results/scenes.txt.
"""
import statistics
import sys
import time
import tracemalloc

from _results import publish

import pdw
from pdw.sim.scene import Forces, Record, Scene, Stop

REPEATS = 21
T_END = 10.0
BASE = Scene(name="steady typical gait", preset="paper_steady",
             integrator={"method": "cdm", "dt": 1e-4}, stop=Stop(t_end=T_END))
PERIODIC = {"periodic": True, "periodic_steps": 4, "periodic_tol": 1e-3}

CASES = [
    ("full: state, forces, energies every step; events", dict(record=Record.full())),
    ("state, forces every step; events (no energies)",
     dict(record=Record(every=1, forces=True, energies=False, events=True))),
    ("state every 10th step; events", dict(record=Record(every=10, forces=False, events=True))),
    ("events only", dict(record=Record.events_only())),
    ("gait descriptors only", dict(record=Record.descriptors_only())),
    ("descriptors only, no tangential spring-damper (kernel)",
     dict(record=Record.descriptors_only(), forces=Forces(tangential=False))),
    ("descriptors only, stop when periodic (k=4, 0.1%)",
     dict(record=Record.descriptors_only(), stop=PERIODIC)),
    ("... and no tangential spring-damper (kernel)",
     dict(record=Record.descriptors_only(), stop=PERIODIC,
          forces=Forces(tangential=False))),
]


def timed_interleaved(scenes, repeats=REPEATS):
    """Median wall time and median CPU time (of this thread, which runs the compiled loop) of
    each scene; the scenes run in turn in every round so that a change of machine load affects
    them alike. Returns [(wall, cpu, result)]."""
    results = [pdw.run(sc) for sc in scenes]        # warm up
    wall = [[] for _ in scenes]
    cpu = [[] for _ in scenes]
    for _ in range(repeats):
        for i, sc in enumerate(scenes):
            t0, c0 = time.perf_counter(), time.thread_time()
            results[i] = pdw.run(sc)
            c1, t1 = time.thread_time(), time.perf_counter()
            wall[i].append(t1 - t0)
            cpu[i].append(c1 - c0)
    return [(statistics.median(w), statistics.median(c), r)
            for w, c, r in zip(wall, cpu, results)]


def peak_memory(scene):
    tracemalloc.start()
    r = pdw.run(scene)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    del r
    return peak


def _mem(b):
    return "%.2f MB" % (b / 2**20) if b >= 2**20 else "%.1f kB" % (b / 1024)


def main():
    lines = ["scenes of decreasing needs: Params.paper_steady(), X0_PAPER, method cdm, dt = 1e-4, "
             "t_end = %g s (%d steps)" % (T_END, round(T_END / 1e-4)),
             "median of %d rounds of pdw.run(scene), the scenes in turn (Python set-up and result "
             "included): wall time, and CPU time of the running thread (robust to other jobs); "
             "memory: tracemalloc peak" % REPEATS,
             "python %s" % sys.version.split()[0], "",
             "%-54s %8s %6s %7s %7s %7s %5s %10s %8s" % (
                 "scene", "status", "t_end", "wall ms", "cpu ms", "ns/step", "steps", "peak mem",
                 "speed-up")]
    scenes = [BASE.replace(**changes) for _, changes in CASES]
    rows = []
    for (label, _), sc, (wall, cpu, r) in zip(CASES, scenes, timed_interleaved(scenes)):
        assert r.walked, (label, r.status)
        rows.append((label, r, wall, cpu, peak_memory(sc)))
    full_wall, full_cpu = rows[0][2], rows[0][3]
    for label, r, wall, cpu, mem in rows:
        lines.append("%-54s %8s %6.3f %7.2f %7.2f %7.1f %5d %10s %7.2fx" % (
            label, r.status, r.t_final, 1e3 * wall, 1e3 * cpu, 1e9 * cpu / r.n_steps,
            r.n_gait_steps, _mem(mem), full_cpu / cpu))
    lines.append("(ns/step and speed-up from the CPU time; wall-time speed-ups: %s)"
                 % ", ".join("%.2fx" % (full_wall / w) for _, _, w, _, _ in rows))
    by = {label: c for label, _, _, c, _ in rows}
    t_desc = by["gait descriptors only"]
    lines += ["", "descriptors only (CPU time) vs full recording: %.2fx faster (target 1.5x); vs "
              "state+forces+events without energies: %.2fx; vs events only: %.2fx"
              % (full_cpu / t_desc, by[CASES[1][0]] / t_desc, by["events only"] / t_desc)]
    # O(1) memory of a descriptors-only run
    lines += ["", "descriptors-only memory against run length (tracemalloc peak, steady gait):"]
    desc = BASE.replace(record=Record.descriptors_only())
    for t_end in (0.1, 10.0, 100.0):
        sc = desc.replace(stop={"t_end": t_end})
        pdw.run(sc)
        mem = peak_memory(sc)
        ((wall, cpu, r),) = timed_interleaved([sc], repeats=3 if t_end > 10 else 11)
        assert r.walked
        lines.append("  %8d steps (%5.1f s, %3d gait steps): peak %s, %.1f ms (cpu %.1f ms)" % (
            r.n_steps, t_end, r.n_gait_steps, _mem(mem), 1e3 * wall, 1e3 * cpu))
    lines += ["", "the generated kernels: CPU ns per evaluation at a double-support state (both feet "
              "penetrating), best of 9 x 2e5 (rhs) / 5e4 (Jacobian) calls:"]
    lines += kernel_costs()
    publish("scenes.txt", lines)


def kernel_costs():
    import numpy as np

    from pdw.core import _core
    from pdw.core.model import parameter_vector
    x = np.array(pdw.X0_PAPER)
    x[1] -= 0.002                                   # both feet ~5 mm deep
    p = parameter_vector(pdw.Params.paper())
    out = []
    for k, (name, _, _) in enumerate(_core.kernel_table()):
        cost = {}
        for what, n in (("rhs", 200000), ("jacobian", 50000)):
            ts = []
            for _ in range(9):
                c0 = time.thread_time()
                _core.bench(k, what, x, p, 1, 1, 0.0, 0.01, n)
                ts.append((time.thread_time() - c0) / n)
            cost[what] = min(ts)
        out.append("  %-54s rhs %6.1f ns   jacobian %6.1f ns" % (
            name, 1e9 * cost["rhs"], 1e9 * cost["jacobian"]))
    return out


if __name__ == "__main__":
    main()
