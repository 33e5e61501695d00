"""The scalar cdm step against a bare-C central-difference loop (issue 23 item 3).

The paper run (``pdw.simulate`` of ``Params.paper()`` from the paper's x0, cdm at dt = 1e-4 for
3.5 s, no recording: what a user pays, Python included) against the same 35,000 steps of
``benchmarks/bare_cdm.c``: the same generated kinematics, contact and cdm_terms stages in the
loop a user would write (dense 4x4 assembly, Gaussian elimination with partial pivoting, the
contact flags; no recording, stop conditions or state checks). CPU time (``time.process_time``),
the two runs interleaved in each round; the ratio is the median over rounds of (pdw / bare C) in
the same round. The two final states are printed (they differ only by the solvers' rounding).
The 1-minute load average is printed with the result.

The bare loop is compiled by the Makefile with pdw's own flags into ``build/bench/``::

    make build/bench/libbare_cdm.so
    .venv/bin/python benchmarks/bench_cdm_step.py [rounds]        (default 15)

(``make bench`` does both.)
"""
import ctypes
import os
import pathlib
import sys
import time

import numpy as np

import pdw
from pdw.core.model import kernel_index, parameter_vector

sys.path.insert(0, os.path.dirname(__file__))
from _results import ROOT, publish  # noqa: E402

LIB = ROOT / "build" / "bench" / "libbare_cdm.so"
X0 = np.array([0, 0.4969, -0.0582, 0.0582, 0.5092, 0.0186, 3.3338, -1.0093])
T_END, DT = 3.5, 1e-4
FLAGS0 = (0, 1)                 # pdw.simulate's default


def load_bare(path: pathlib.Path = LIB):
    """The bare loop's ``bare_cdm_run`` from the library the Makefile built."""
    if not path.exists():
        raise SystemExit("%s is missing: run `make build/bench/libbare_cdm.so` first" % path)
    lib = ctypes.CDLL(str(path))
    fn = lib.bare_cdm_run
    dp = ctypes.POINTER(ctypes.c_double)
    fn.argtypes = [ctypes.c_int, dp, dp, ctypes.POINTER(ctypes.c_int), ctypes.c_double,
                   ctypes.c_long, dp]
    fn.restype = ctypes.c_long
    return fn


def main(rounds=15):
    bare = load_bare()
    params = pdw.Params.paper()
    k = kernel_index("paper")
    p = np.ascontiguousarray(parameter_vector(params))
    x0 = np.ascontiguousarray(X0)
    flags0 = (ctypes.c_int * 2)(*FLAGS0)
    x_bare = np.empty(8)
    n_steps = int(round(T_END / DT))
    dp = ctypes.POINTER(ctypes.c_double)

    def run_bare():
        t0 = time.process_time()
        n_td = bare(k, p.ctypes.data_as(dp), x0.ctypes.data_as(dp), flags0, DT, n_steps,
                    x_bare.ctypes.data_as(dp))
        return time.process_time() - t0, n_td

    def run_pdw():
        t0 = time.process_time()
        r = pdw.simulate(X0, T_END, DT, params=params, record=pdw.Record(every=0))
        return time.process_time() - t0, r

    run_bare(), run_pdw()                       # warm both
    t_pdw, t_bare, ratios = [], [], []
    for _ in range(rounds):
        a, r = run_pdw()
        b, n_td = run_bare()
        t_pdw.append(a)
        t_bare.append(b)
        ratios.append(a / b)
    if n_td < 0:
        raise SystemExit("the bare loop failed (singular system)")
    dx = np.max(np.abs(r.x_final - x_bare))
    lines = [
        "bench_cdm_step: the paper run (Params.paper(), x0 of the paper, cdm, dt %g, %g s = %d "
        "steps, no recording) against benchmarks/bare_cdm.c; CPU time, %d interleaved rounds"
        % (DT, T_END, n_steps, rounds),
        "  pdw.simulate   %7.3f ms  (%.1f ns/step; %s, %d gait steps, %d events)"
        % (1e3 * np.median(t_pdw), 1e9 * np.median(t_pdw) / n_steps, r.status, r.n_gait_steps,
           sum(r.event_counts.values()) if isinstance(r.event_counts, dict) else -1),
        "  bare C loop    %7.3f ms  (%.1f ns/step; %d touch-downs)"
        % (1e3 * np.median(t_bare), 1e9 * np.median(t_bare) / n_steps, n_td),
        "  ratio pdw / bare C: median %.3f (rounds %.3f-%.3f)"
        % (np.median(ratios), np.min(ratios), np.max(ratios)),
        "  final states agree to %.1e (max abs difference)" % dx,
        "load average (1 min) %.2f on %d CPUs" % (os.getloadavg()[0], os.cpu_count() or 1),
    ]
    publish("cdm_step.txt", lines)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 15)
