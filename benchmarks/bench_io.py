"""Cost of pdw where it meets other software (issue 14).

1. Per call: the model object ``pdw.ode_function`` (f and jac), ``pdw.rhs`` on its fast path
   (one float64 state, default features) and on the general, checked path (what every call
   cost before: ``features`` given forces it), against the bare kernel in a C loop.
2. ``simulate()`` (default: cdm, dt 1e-4, 3.5 s) in a fresh process, first call, with full
   recording vs ``record_every=0``, and a second call in the same process (memory reused).

Interleaved repetitions, medians; the load average is printed (the machine is shared).
Run: ``.venv/bin/python benchmarks/bench_io.py [--update-docs] [--before DIR]``.

``--before DIR``: also time f, jac and ``pdw.rhs`` of another build of pdw (a source tree
built in place, e.g. ``git archive <rev> | tar -x -C DIR && cd DIR && python setup.py
build_ext --inplace``), in fresh processes interleaved with this build's, for a before/after
measured in one run.
"""
import os
import pathlib
import subprocess
import sys
import timeit

import numpy as np
from _results import publish

import pdw
from pdw.core import _core
from pdw.core.model import parameter_vector

BEFORE = None
if "--before" in sys.argv:
    i = sys.argv.index("--before")
    BEFORE = str(pathlib.Path(sys.argv[i + 1]).resolve())
    del sys.argv[i:i + 2]

X = np.array(pdw.X0_PAPER)
PER_CALL = r"""
import sys, timeit, numpy as np, pdw
X = np.array(pdw.X0_PAPER)
f = pdw.ode_function()
for fn in (lambda: f(0.0, X), lambda: f.jac(0.0, X), lambda: pdw.rhs(X)):
    print(min(timeit.repeat(fn, number=20000, repeat=5)) / 20000 * 1e6)
"""
FRESH = r"""
import time, sys, pdw
mode = sys.argv[1]
out = pdw.RecordBuffer(35002) if mode == "out" else None
if out is not None:
    out.x[:] = 0; out.t[:] = 0; out.flags[:] = 0; out.contact[:] = 0   # allocated before timing
opts = dict(integrator=pdw.Integrator(check_step="off"),
            record=pdw.Record(every=0 if mode == "none" else 1, out=out))
ts = []
for _ in range(4):
    t0 = time.perf_counter(); pdw.simulate(**opts)
    ts.append(time.perf_counter() - t0)
print(*ts)
"""


def per_call(fn, n):
    return min(timeit.repeat(fn, number=n, repeat=5)) / n * 1e6


def before_after(rounds=7):
    """f, jac and pdw.rhs per call [us] of the build in BEFORE and of this one, in fresh
    processes, interleaved."""
    here = str(pathlib.Path(pdw.__file__).resolve().parent.parent)
    got = {"before": [], "after": []}
    for _ in range(rounds):
        for name, path in (("before", BEFORE), ("after", here)):
            out = subprocess.run([sys.executable, "-c", PER_CALL], capture_output=True, text=True,
                                 check=True, cwd=path, env=dict(os.environ, PYTHONPATH=path))
            got[name].append([float(v) for v in out.stdout.split()])
    lines = ["# before (%s) / after (this build), fresh processes, median of %d interleaved: "
             "f(t, x), jac(t, x), pdw.rhs(x) [us]" % (BEFORE, rounds)]
    for name, v in got.items():
        lines.append("%-42s %s" % (name, "  ".join("%7.3f" % u for u in np.median(np.array(v), axis=0))))
    return lines


def main():
    f = pdw.ode_function()
    XL = X.tolist()    # a list takes the general path, the code every call ran before
    rows = {k: [] for k in ("kernel rhs (C loop)", "kernel jacobian (C loop)", "ode_function f(t, x)",
                            "ode_function f, converting path (f.general)",
                            "ode_function jac(t, x)", "ode_function batch, per state (N=10^4)",
                            "pdw.rhs fast path", "pdw.rhs general path (list input)")}
    XB = np.tile(X, (10_000, 1))
    p = parameter_vector(None)
    for _ in range(3):
        rows["kernel rhs (C loop)"].append(_core.bench(0, "rhs", X, p, 0, 1, 0, 0, 10**6) / 1e3)
        rows["kernel jacobian (C loop)"].append(_core.bench(0, "jacobian", X, p, 0, 1, 0, 0, 10**5) / 1e3)
        rows["ode_function f(t, x)"].append(per_call(lambda: f(0.0, X), 20_000))
        rows["ode_function f, converting path (f.general)"].append(per_call(lambda: f.general(0.0, X), 20_000))
        rows["ode_function jac(t, x)"].append(per_call(lambda: f.jac(0.0, X), 20_000))
        rows["ode_function batch, per state (N=10^4)"].append(per_call(lambda: f.batch(XB), 20) / 1e4)
        rows["pdw.rhs fast path"].append(per_call(lambda: pdw.rhs(X), 10_000))
        rows["pdw.rhs general path (list input)"].append(per_call(lambda: pdw.rhs(XL), 2_000))
    lines = ["# bench_io: per-call cost [us] (median of 3 interleaved rounds, each the best of 5)",
             "# load average before: %s" % (os.getloadavg(),)]
    for k, v in rows.items():
        lines.append("%-42s %8.3f us" % (k, np.median(v)))
    if BEFORE:
        lines += before_after()
    modes = {"full recording, fresh arrays": "fresh", "full recording, out=RecordBuffer": "out",
             "record_every=0": "none"}
    got = {m: [] for m in modes.values()}
    for _ in range(5):
        for m in modes.values():
            out = subprocess.run([sys.executable, "-c", FRESH, m], capture_output=True,
                                 text=True, check=True).stdout.split()
            got[m].append([float(v) * 1e3 for v in out])
    lines.append("# simulate() default (cdm, dt 1e-4, 3.5 s) in a fresh process: runs 1..4 [ms],"
                 " median of 5 interleaved processes")
    for name, m in modes.items():
        a = np.median(np.array(got[m]), axis=0)
        lines.append("%-42s %s" % (name, "  ".join("%7.2f" % v for v in a)))
    lines.append("# load average after: %s" % (os.getloadavg(),))
    publish("io.txt", lines)


if __name__ == "__main__":
    main()
