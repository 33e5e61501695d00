"""Micro-benchmark of the generated model: ns per right-hand side and per Jacobian, timed in a
compiled loop (no Python in the loop), and the operation counts of the generated stages.

Run: `make bench` (or `.venv/bin/python benchmarks/bench_model.py`). Prints a table and writes
benchmarks/results/model.txt.
"""
import platform
import statistics

import numpy as np
from _results import publish

import pdw
from pdw.core import _core, _layout
from pdw.core.model import kernel_index, parameter_vector

N = 2_000_000
REPEATS = 7


def main():
    p = parameter_vector(pdw.Params.paper())
    x0 = np.array(pdw.X0_PAPER)
    cases = [("stance (flags 0,1)", (0, 1)), ("double support (1,1)", (1, 1)), ("flight (0,0)", (0, 0))]
    lines = ["pdw model micro-benchmark (%s, %s)" % (platform.processor() or platform.machine(),
                                                       platform.python_version()),
             "mean ns per evaluation over %d calls, median of %d repeats" % (N, REPEATS), ""]
    lines.append("%-12s %-22s %10s %12s" % ("kernel", "state", "rhs [ns]", "jacobian [ns]"))
    for variant in pdw.VARIANTS:
        k = kernel_index(variant)
        for label, (f1, f2) in cases:
            rhs = statistics.median(_core.bench(k, "rhs", x0, p, f1, f2, 0.0, 0.01, N)
                                    for _ in range(REPEATS))
            jac = statistics.median(_core.bench(k, "jacobian", x0, p, f1, f2, 0.0, 0.01, N // 10)
                                    for _ in range(REPEATS))
            lines.append("%-12s %-22s %10.1f %12.1f" % (variant, label, rhs, jac))
    lines += ["", "operation counts of the generated stages (SymPy count_ops after CSE; a contact-law",
              "kernel emits only its contact stages, the others are its variant's: '-'):"]
    stages = list(next(iter(_layout.OPS.values())))
    w = max(len(name) for name in _layout.OPS)
    lines.append("%-*s " % (w, "kernel") + " ".join("%17s" % s for s in stages))
    for name, ops in _layout.OPS.items():
        lines.append("%-*s " % (w, name) + " ".join("%17s" % ops.get(s, "-") for s in stages))
    publish("model.txt", lines)


if __name__ == "__main__":
    main()
