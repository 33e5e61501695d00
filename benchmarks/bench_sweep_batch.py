"""`pdw sweep` points as batches (pdw.studies.points.run_points) against point by point: the same
study (cdm, dt = 1e-4, 16 s per point, paper_steady over k_hip x d_hip), interleaved rounds,
the same rows asserted, wall and process CPU time, load average printed.

Run: `.venv/bin/python benchmarks/bench_sweep_batch.py [ROUNDS] [--update-docs]`.
"""
import os
import sys
import tempfile
import time

from _results import publish

from pdw.studies.study import parse_study
from pdw.studies.sweep import run_study

ROUNDS = int(sys.argv[1]) if len(sys.argv) > 1 else 5
STUDY = """
name = "bench_batch_sweep"
[scene]
preset = "paper_steady"
[scene.integrator]
method = "cdm"
dt = 1e-4
[[axes]]
name = "k_hip"
start = 0.8
stop = 1.1
num = 8
[[axes]]
name = "d_hip"
start = 0.005
stop = 0.015
num = 6
[run]
fallback = false
"""


def main():
    st = parse_study(STUDY)
    n = len(st.points())
    load0 = os.getloadavg()
    times = {False: [], True: []}
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(ROUNDS):
            for batch in (False, True):
                t0, c0 = time.perf_counter(), time.process_time()
                res = run_study(st, os.path.join(tmp, "%d%d" % (r, batch)), workers=2,
                                progress=False, batch=batch)
                times[batch].append((time.perf_counter() - t0, time.process_time() - c0))
                assert res.engine == ("batch" if batch else "scalar")
                rows[batch] = [{k: v for k, v in x.items() if k != "wall_s"} for x in res.rows]
    assert rows[True] == rows[False], "the batched rows differ from the point-by-point rows"
    load1 = os.getloadavg()

    def med(v, j):
        v = sorted(x[j] for x in v)
        return v[len(v) // 2]
    ws, cs = med(times[False], 0), med(times[False], 1)
    wb, cb = med(times[True], 0), med(times[True], 1)
    st_rows = [x["status"] for x in rows[True]]
    statuses = ["%d %s" % (st_rows.count(s), s) for s in sorted(set(st_rows))]
    lines = ["pdw sweep, %d points (paper_steady, k_hip x d_hip, cdm dt 1e-4, 16 s each, "
             "fallback off; statuses %s), thread pool of 2, %d interleaved rounds, medians"
             % (n, ", ".join(statuses), ROUNDS),
             "load average before %.2f %.2f %.2f, after %.2f %.2f %.2f (%d cores)"
             % (load0 + load1 + (os.cpu_count(),)),
             "point by point (run_point):  wall %.3f s, CPU %.3f s" % (ws, cs),
             "batched (points.run_points): wall %.3f s, CPU %.3f s" % (wb, cb),
             "speed-up: wall %.2fx, CPU %.2fx; rows identical (all columns but wall_s)"
             % (ws / wb, cs / cb)]
    publish("bench_sweep_batch.txt", lines)


if __name__ == "__main__":
    main()
