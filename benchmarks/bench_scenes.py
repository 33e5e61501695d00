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

import pdw
from pdw.scene import Forces, Record, Scene, Stop
from _results import publish

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


def timed(scene, repeats=REPEATS):
    pdw.run(scene)                                  # warm up
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        r = pdw.run(scene)
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), r


def timed_interleaved(scenes, repeats=REPEATS):
    """Median and minimum wall time of each scene, the scenes run in turn in every round so
    that a change of machine load affects them alike. Returns [(median, min, result)]."""
    results = [pdw.run(sc) for sc in scenes]        # warm up
    ts = [[] for _ in scenes]
    for _ in range(repeats):
        for i, sc in enumerate(scenes):
            t0 = time.perf_counter()
            results[i] = pdw.run(sc)
            ts[i].append(time.perf_counter() - t0)
    return [(statistics.median(t), min(t), r) for t, r in zip(ts, results)]


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
             "wall: median of %d runs of pdw.run(scene) in one process (Python set-up and result "
             "included); memory: tracemalloc peak" % REPEATS,
             "python %s" % sys.version.split()[0], "",
             "%-54s %8s %6s %7s %7s %7s %5s %10s %8s" % (
                 "scene", "status", "t_end", "ms", "min ms", "ns/step", "steps", "peak mem",
                 "speed-up")]
    scenes = [BASE.replace(**changes) for _, changes in CASES]
    rows = []
    for (label, _), sc, (t, t_min, r) in zip(CASES, scenes, timed_interleaved(scenes)):
        assert r.walked, (label, r.status)
        rows.append((label, r, t, t_min, peak_memory(sc)))
    t_full = rows[0][2]
    for label, r, t, t_min, mem in rows:
        lines.append("%-54s %8s %6.3f %7.2f %7.2f %7.1f %5d %10s %7.2fx" % (
            label, r.status, r.t_final, 1e3 * t, 1e3 * t_min, 1e9 * t / r.n_steps,
            r.n_gait_steps, _mem(mem), t_full / t))
    by = {label: t for label, _, t, _, _ in rows}
    t_desc = by["gait descriptors only"]
    lines += ["", "descriptors only vs full recording: %.2fx faster (target 1.5x); vs state+forces+"
              "events without energies: %.2fx; vs events only: %.2fx"
              % (t_full / t_desc, by[CASES[1][0]] / t_desc, by["events only"] / t_desc)]
    # O(1) memory of a descriptors-only run
    lines += ["", "descriptors-only memory against run length (tracemalloc peak, steady gait):"]
    desc = BASE.replace(record=Record.descriptors_only())
    for t_end in (0.1, 10.0, 100.0):
        sc = desc.replace(stop={"t_end": t_end})
        pdw.run(sc)
        mem = peak_memory(sc)
        t, r = timed(sc, repeats=3 if t_end > 10 else 11)
        assert r.walked
        lines.append("  %8d steps (%5.1f s, %3d gait steps): peak %s, %.1f ms" % (
            r.n_steps, t_end, r.n_gait_steps, _mem(mem), 1e3 * t))
    publish("scenes.txt", lines)


if __name__ == "__main__":
    main()
