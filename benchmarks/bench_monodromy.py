"""The continuous model's monodromy three ways (issue #24, "Speed": the exact monodromy must not
make a branch point slower than finite differences).

Per contact law, at a section point z of paper_steady (the law's gait where it walks; for
lankarani_nikravesh the default gait's z with an approach speed of 0.3 m/s, one step from it):

* ``fd``: central differences of the compiled rodas4 step map (`limit_cycle.jacobian`, fd_step
  1e-5, TIGHT tolerances, 2 dim maps, one worker: what `continue_gait` does by default);
* ``exact C``: `variational.step_jacobian` (engine "compiled": pdw/core/csrc/pdw_cvar.c; rtol
  1e-10, atol 1e-12, Phi's tolerance `variational.PHI_TOL`);
* ``exact Py``: the same with engine "python" (SciPy Radau + LSODA, the reference).

and, for the default law, one branch point of `continue_gait` in k_hip
(`ContinuousProblem.evaluate`, monodromy "differences" against "exact": the map at z, its
parameter differences and M). Process CPU time, medians of ROUNDS rounds interleaved (each
round runs every case once, in turn); the load average is printed before and after (a shared
machine: read the ratios, taken in the same rounds). The multipliers' largest difference to the
Python version's (``|dm|``) is printed for both fd and exact C.

Run: `make bench` (or `.venv/bin/python benchmarks/bench_monodromy.py [ROUNDS] [--update-docs]`).
Writes monodromy.txt under out/benchmarks/results/ (--update-docs: benchmarks/results/).
"""
import os
import statistics
import sys
import time

import numpy as np
from _results import publish

import pdw
from pdw import limit_cycle as LC
from pdw.analysis.stepmap import variational as V
from pdw.analysis.stepmap.gait_maps import ContinuousProblem

ROUNDS = int(sys.argv[1]) if len(sys.argv) > 1 else 3
P = pdw.Params.paper_steady()


def _mult(M):
    return np.sort_complex(np.linalg.eigvals(M))


def _cases():
    z0 = LC.find_gait(P, workers=1).details["z"]
    out = [("hunt_crossley (default)", None, z0)]
    for name, c in (("flores e=0.18", pdw.Contact("flores", e=0.18)),
                    ("kelvin_voigt", pdw.Contact("kelvin_voigt"))):
        out.append((name, c, LC.find_gait(P, contact=c, workers=1).details["z"]))
    out.append(("lankarani_nikravesh e=0.5", pdw.Contact("lankarani_nikravesh", e=0.5),
                np.r_[z0, 0.3]))
    return out


def main():
    load0 = os.getloadavg()
    cases = _cases()
    ways = {
        "fd": lambda c, z: LC.jacobian(z, P, fd_step=1e-5, **LC.TIGHT, contact=c, workers=1)[0],
        "exact C": lambda c, z: V.step_jacobian(z, P, contact=c, rtol=LC.TIGHT["rtol"],
                                                atol=LC.TIGHT["atol"])["M"],
        "exact Py": lambda c, z: V.step_jacobian(z, P, contact=c, engine="python",
                                                 rtol=LC.TIGHT["rtol"],
                                                 atol=LC.TIGHT["atol"])["M"],
    }
    z0 = cases[0][2]
    probs = {}
    for mono in ("differences", "exact"):
        probs[mono] = ContinuousProblem(P, "k_hip", workers=1)
        probs[mono].monodromy = mono
    cpu = {}
    got = {}
    for _ in range(ROUNDS):
        for name, c, z in cases:
            for way, f in ways.items():
                c0 = time.process_time()
                got[(name, way)] = f(c, z)
                cpu.setdefault((name, way), []).append(time.process_time() - c0)
        for mono, prob in probs.items():
            c0 = time.process_time()
            ev = prob.evaluate(z0, P.k_hip)
            cpu.setdefault(("branch point", mono), []).append(time.process_time() - c0)
            assert ev.ok, ev.status
            got[("branch point", mono)] = ev.M
    load1 = os.getloadavg()
    lines = ["The continuous model's monodromy: finite differences, exact compiled, exact Python "
             "(paper_steady; CPU s, medians of %d rounds interleaved)" % ROUNDS,
             "load average before %.2f %.2f %.2f, after %.2f %.2f %.2f (%d cores)"
             % (load0 + load1 + (os.cpu_count(),)),
             "%-27s %9s %9s %9s %8s %8s %10s %10s" % ("law", "fd", "exact C", "exact Py",
                                                     "C/fd", "Py/fd", "|dm| fd", "|dm| C")]
    for name, _, _ in cases:
        t = {w: statistics.median(cpu[(name, w)]) for w in ways}
        ref = _mult(got[(name, "exact Py")])
        dfd = float(np.max(np.abs(_mult(got[(name, "fd")]) - ref)))
        dc = float(np.max(np.abs(_mult(got[(name, "exact C")]) - ref)))
        lines.append("%-27s %9.4f %9.4f %9.4f %8.2f %8.1f %10.1e %10.1e"
                     % (name, t["fd"], t["exact C"], t["exact Py"], t["exact C"] / t["fd"],
                        t["exact Py"] / t["fd"], dfd, dc))
    tb = {m: statistics.median(cpu[("branch point", m)]) for m in probs}
    dm = float(np.max(np.abs(_mult(got[("branch point", "exact")])
                             - _mult(got[("branch point", "differences")]))))
    lines.append("one branch point of continue_gait (k_hip, default law, ContinuousProblem."
                 "evaluate): differences %.4f s, exact %.4f s (exact/differences %.2f); "
                 "multipliers differ by %.1e" % (tb["differences"], tb["exact"],
                                                 tb["exact"] / tb["differences"], dm))
    publish("monodromy.txt", lines)


if __name__ == "__main__":
    main()
