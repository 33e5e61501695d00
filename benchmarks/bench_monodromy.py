"""The continuous model's monodromy three ways (issue #24, "Speed": the exact monodromy must not
make a branch point slower than finite differences).

Per contact law, at a section point z of paper_steady (the law's gait where it walks; for
lankarani_nikravesh the default gait's z with an approach speed of 0.3 m/s, one step from it):

* ``fd``: central differences of the compiled rodas4 step map (`limit_cycle.jacobian`, fd_step
  1e-5, TIGHT tolerances, 2 dim maps, one worker: what `continue_gait` does by default);
* ``exact C``: `variational.step_jacobian` (engine "compiled": pdw/core/csrc/pdw_cvar.c; rtol
  1e-10, atol 1e-12, Phi's tolerance `variational.PHI_TOL`);
* ``C 1e-9``: exact C with x's tolerances loosened to rtol 1e-9, atol 1e-11 (Phi's unchanged);
* ``exact Py``: the same with engine "python" (SciPy Radau + LSODA, the reference).

and one branch point of `continue_gait` (`ContinuousProblem.evaluate`, monodromy "differences"
against "exact": P(z), dP/dparameter, M and the step's descriptors; with "exact" all from one
variational integration with a parameter column) for the default law in k_hip and d_n, flores
in k_hip, kelvin_voigt in contact.d and lankarani_nikravesh in contact.e, at the case's z. Process CPU time, medians of ROUNDS rounds interleaved (each
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
        "exact C 1e-9": lambda c, z: V.step_jacobian(z, P, contact=c, rtol=1e-9,
                                                     atol=1e-11)["M"],
        "exact Py": lambda c, z: V.step_jacobian(z, P, contact=c, engine="python",
                                                 rtol=LC.TIGHT["rtol"],
                                                 atol=LC.TIGHT["atol"])["M"],
    }
    probs = {}
    branch = [(cases[0], "k_hip"), (cases[0], "d_n"), (cases[1], "k_hip"),
              (cases[2], "contact.d"), (cases[3], "contact.e")]
    for (name, c, z), par in branch:
        for mono in ("differences", "exact"):
            prob = ContinuousProblem(P, par, workers=1, options={"contact": c})
            prob.monodromy = mono
            probs[(name + " in " + par, mono)] = (prob, z)
    cpu = {}
    got = {}
    for _ in range(ROUNDS):
        for name, c, z in cases:
            for way, f in ways.items():
                c0 = time.process_time()
                got[(name, way)] = f(c, z)
                cpu.setdefault((name, way), []).append(time.process_time() - c0)
        for key, (prob, z) in probs.items():
            mu = prob.coord(prob.start_value())
            c0 = time.process_time()
            ev = prob.evaluate(z, mu)
            cpu.setdefault(("branch point",) + key, []).append(time.process_time() - c0)
            assert ev.ok, ev.status
            got[("branch point",) + key] = ev.M
    load1 = os.getloadavg()
    lines = ["The continuous model's monodromy: finite differences, exact compiled, exact Python "
             "(paper_steady; CPU s, medians of %d rounds interleaved)" % ROUNDS,
             "load average before %.2f %.2f %.2f, after %.2f %.2f %.2f (%d cores)"
             % (load0 + load1 + (os.cpu_count(),)),
             "%-26s %8s %8s %8s %8s %6s %6s %6s %8s %8s %8s"
             % ("law", "fd", "exact C", "C 1e-9", "exact Py", "C/fd", "C9/fd", "Py/fd",
                "|dm| fd", "|dm| C", "|dm| C9")]
    for name, _, _ in cases:
        t = {w: statistics.median(cpu[(name, w)]) for w in ways}
        ref = _mult(got[(name, "exact Py")])
        d = {w: float(np.max(np.abs(_mult(got[(name, w)]) - ref)))
             for w in ("fd", "exact C", "exact C 1e-9")}
        lines.append("%-26s %8.4f %8.4f %8.4f %8.4f %6.2f %6.2f %6.1f %8.1e %8.1e %8.1e"
                     % (name, t["fd"], t["exact C"], t["exact C 1e-9"], t["exact Py"],
                        t["exact C"] / t["fd"], t["exact C 1e-9"] / t["fd"],
                        t["exact Py"] / t["fd"], d["fd"], d["exact C"], d["exact C 1e-9"]))
    lines.append("one branch point of continue_gait (ContinuousProblem.evaluate: P(z), "
                 "dP/dparameter, M, descriptors), CPU s:")
    for (name, _, _), par in branch:
        key = name + " in " + par
        tb = {m: statistics.median(cpu[("branch point", key, m)])
              for m in ("differences", "exact")}
        dm = float(np.max(np.abs(_mult(got[("branch point", key, "exact")])
                                 - _mult(got[("branch point", key, "differences")]))))
        lines.append("  %-38s differences %.4f, exact %.4f (exact/differences %.2f); "
                     "multipliers differ by %.1e" % (key, tb["differences"], tb["exact"],
                                                     tb["exact"] / tb["differences"], dm))
    publish("monodromy.txt", lines)


if __name__ == "__main__":
    main()
