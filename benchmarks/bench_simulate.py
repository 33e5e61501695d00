"""Speed and memory of the main job: the paper's typical gait, 3.5 s at dt = 1e-4 with the
central difference method, with event recording only and with full recording.

Run: `make bench` (or `.venv/bin/python benchmarks/bench_simulate.py`). Prints a table and
writes benchmarks/results/simulate.txt. Wall times are medians of repeated runs in this one
process; the reference is the issue's 2-4 ms for a compiled central-difference loop.
"""
import statistics
import time
import tracemalloc

from _results import publish

import pdw

REPEATS = 31
REFERENCE_MS = (2.0, 4.0)


def timed(**kw):
    ts = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        r = pdw.simulate(**kw)
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), r


def peak_memory(**kw):
    tracemalloc.start()
    pdw.simulate(**kw)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak


def main():
    cases = [
        ("events only", dict(record_every=0, record_forces=False)),
        ("full recording (state, flags, forces every step)", dict(record_every=1, record_forces=True)),
        ("state every 10th step", dict(record_every=10, record_forces=False)),
    ]
    lines = ["typical gait: Params.paper(), X0_PAPER, 3.5 s, dt = 1e-4 (35,000 steps), method cdm",
             "median of %d runs (wall time of pdw.simulate, Python set-up included)" % REPEATS, "",
             "%-50s %9s %9s %12s %12s" % ("recording", "ms", "ns/step", "vs 2-4 ms", "peak memory")]
    for label, kw in cases:
        t, r = timed(**kw)
        mem = peak_memory(**kw)
        assert r.status == "walked"
        lines.append("%-50s %9.2f %9.1f %5.2f-%5.2fx %9.2f MB" % (
            label, 1e3 * t, 1e9 * t / r.n_steps, 1e3 * t / REFERENCE_MS[1], 1e3 * t / REFERENCE_MS[0],
            mem / 2**20))
    publish("simulate.txt", lines)


if __name__ == "__main__":
    main()
