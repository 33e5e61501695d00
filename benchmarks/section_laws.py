"""Limit cycles with every contact law (pdw.analysis.stepmap.section, docs/contact_laws.md "Limit cycles
with every law"): find_gait on `Params.paper_steady()` with the default law, calibrated LuGre
friction, Flores (e = 0.18), Lankarani-Nikravesh (e = 0.9) and the calibrated Kelvin-Voigt law, at
the Newton tolerances (rtol 1e-10): the section's coordinates, the fixed point, L, P, the
multipliers, the wall time, and the return of a continuous run from the fixed point; and the
spread of the step length over the last 30 steps of a 30 s walk from the paper's start. Writes
benchmarks/results/section_laws.txt (with --update-docs).

Usage: .venv/bin/python benchmarks/section_laws.py   (~30 s on 2 cores)
"""
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
from _results import publish  # noqa: E402

import pdw  # noqa: E402
from pdw import limit_cycle as LC  # noqa: E402
from pdw.analysis.gait_types import GaitNotFoundError  # noqa: E402
from pdw.analysis.numerics.calibration import calibrate, calibrate_lugre  # noqa: E402
from pdw.analysis.stepmap import section as S  # noqa: E402

P = pdw.Params.paper_steady()
LAWS = [("hunt_crossley (default)", pdw.Contact()),
        ("hunt_crossley + lugre (calibrated)", calibrate_lugre(P).contact),
        ("flores e=0.18", pdw.Contact("flores", e=0.18)),
        ("lankarani_nikravesh e=0.9", pdw.Contact("lankarani_nikravesh", e=0.9)),
        ("kelvin_voigt (calibrated)", calibrate(P).contacts["kelvin_voigt"])]


def returns(g, c, t_end=2.4):
    """max |z_k - z*| over the touch-downs of a continuous run from the fixed point."""
    z = g.details["z"]
    x0, a0 = S.start(z, P, c)
    r = pdw.simulate(x0, t_end=t_end, params=P, method="rodas4", flags0=(1, 1), contact=c,
                     integrator=pdw.Integrator(**LC.TIGHT), record=pdw.Record(every=1),
                     approach_speeds0=a0)
    d = []
    for e in (e for e in r.events if e.kind == "touch_down"):
        i = int(np.searchsorted(r.t, e.t))
        held = None if a0 is None else S.held_speeds(r, e.t, a0, P)
        d.append(np.max(np.abs(LC.section_coordinates(r.x[i], e.leg, c, held) - z)))
    return d


def walk(c, t_end=30.0, last=30):
    """(min, max) of the step length L [m] over the ``last`` steps of a walk from the paper's
    start (rodas4, rtol 1e-8), or the run's status if it did not walk."""
    r = pdw.simulate(params=P, t_end=t_end, method="rodas4",
                     integrator=pdw.Integrator(rtol=1e-8, atol=1e-10), record=pdw.Record(every=0),
                     contact=c)
    if not r.walked:
        return r.status
    L = pdw.steps(r).to_dataframe()["L"].to_numpy()[-last:]
    return float(L.min()), float(L.max())


def main():
    lines = ["find_gait(Params.paper_steady(), contact=..., workers=2) at rtol 1e-10, atol 1e-12,"
             " event_tol 1e-12 (tol 1e-9, fd_step 1e-5)", ""]
    for name, c in LAWS:
        t0 = time.perf_counter()
        try:
            g = LC.find_gait(P, contact=c, workers=2)
        except GaitNotFoundError as e:
            lines += ["%s: %s" % (name, e), "  walk from the paper's start: %s" % (walk(c),), ""]
            continue
        wall = time.perf_counter() - t0
        z, names = g.details["z"], g.details["section_names"]
        d = returns(g, c)
        lines += ["%s: %d coordinates %s" % (name, len(z), ", ".join(names)),
                  "  z* = [%s]" % ", ".join("%.6f" % v for v in z),
                  "  L = %.6f m, P = %.6f s (touch-down to touch-down), double support %.6f s"
                  % (g.step_length, g.period, g.double_support),
                  "  |multipliers| = [%s]" % ", ".join("%.3g" % abs(m) for m in g.multipliers),
                  "  dominant multiplier %.5f %+.5fi; stable: %s" % (g.multipliers[0].real,
                                                                    abs(g.multipliers[0].imag),
                                                                    g.stable),
                  "  Newton: %d iterations from %r, residual %.2g; find_gait %.1f s"
                  % (g.details["newton_iterations"], g.details["guess"], g.details["residual"],
                     wall),
                  "  continuous run from z*: max |z_k - z*| at its %d touch-downs = %.2g"
                  % (len(d), max(d)),
                  "  walk from the paper's start, 30 s: L over the last 30 steps in %s m"
                  % ("[%.5f, %.5f]" % w if isinstance(w := walk(c), tuple) else w), ""]
    publish("section_laws.txt", lines)


if __name__ == "__main__":
    main()
