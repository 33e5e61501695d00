"""Speed-up of a sweep on 2 local cores over 1 (pdw.sweep; docs/studies.md, "Scale").

A 120-point study (k_n x k_hip, 20 s of walking per point, rodas4 rtol 1e-7) is run with the
thread and the process pool at 1 and 2 workers; best of ``--repeat`` runs each. Writes
benchmarks/results/sweep_speedup.txt.

Usage: .venv/bin/python benchmarks/sweep_speedup.py [--repeat 3]
"""
import argparse
import os
import pathlib
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
from _results import publish  # noqa: E402

from pdw import sweep  # noqa: E402

STUDY = """
name = "speedup"
title = "speed-up benchmark: k_n x k_hip"
[scene]
preset = "paper_steady"
stop = { t_end = 20.0 }
[[axes]]
name = "k_n"
start = 0.5e5
stop = 2.5e5
num = 40
[[axes]]
name = "k_hip"
values = [0.9, 0.95, 1.0]
[run]
fallback = false
"""


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    study = sweep.parse_study(STUDY)
    n = len(study.points())
    times = {}
    for backend in ("thread", "process"):
        for w in (1, 2):
            best = float("inf")
            for _ in range(args.repeat):
                with tempfile.TemporaryDirectory() as d:
                    t0 = time.perf_counter()
                    res = sweep.run_study(study, d, backend=backend, workers=w, resume=False,
                                          progress=False, figures=False)
                    best = min(best, time.perf_counter() - t0)
            assert all(r["gait"] == "period-1" for r in res.rows)
            times[backend, w] = best
    load = os.getloadavg()
    lines = ["Sweep speed-up (benchmarks/sweep_speedup.py): %d points, 20 s of walking each "
             "(rodas4 rtol 1e-7), best of %d; %d cores; load average (1 min) at the end %.2f"
             % (n, args.repeat, os.cpu_count(), load[0]), "",
             "| backend | workers | wall [s] | per point [ms] | speed-up over 1 worker |",
             "|---|---|---|---|---|"]
    for (b, w), t in times.items():
        lines.append("| %s | %d | %.2f | %.1f | %.2f |" % (b, w, t, 1e3 * t / n,
                                                           times[b, 1] / t))
    publish("sweep_speedup.txt", lines)


if __name__ == "__main__":
    main()
