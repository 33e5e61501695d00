"""The step-size check for every contact law: measured fixed-step limits and the per-law factors
of `pdw.sim.stepsize.LAW_CALIBRATION` (issue 12; docs/contact_laws.md, docs/stability.md).

For each law calibrated to the paper's ground on `paper_steady` (`pdw.calibration.calibrate`,
`calibrate_lugre`; each has the same static sink, so `typical_start` carries the weight under
each), each variant (paper, consistent) and each fixed-step method (cdm, verlet, rk4), 3.5 s runs
from `typical_start` against a rodas4 reference (rtol 1e-9), as the stability maps of
docs/stability.md:

* "walks" edge: the largest dt at which the run walks with the reference's touch-downs (legs and
  count) -- the maps' "walks" (the edge the default law's check is calibrated on) without their
  energy test, whose ground energy is the Hunt-Crossley spring's;
* "correct" edge: in addition, touch-down times within 1 % of a cycle (the maps' "walks
  correctly", benchmarks/contact_laws.py's cdm limit);
  each by a half-decade scan from 1e-5 s, then 4 log-bisections (resolution 7.5 %);
* reference estimate: the default law's check at the run's parameters,
  ``stepsize._dt_max(contact.parameters(P), method, variant)``;
* factor = (walks edge / estimate of the law) / (the same for hunt_crossley): the law's dt_max
  then sits as far below its walks edge as the default law's does on paper_steady.
  `LAW_CALIBRATION` holds these factors rounded down to two digits.

Then (paper variant) LuGre's bristle damping sigma1 swept (1/3, 1, 3 x the calibrated value, and the default
316.2 s/m): the walks edge of each method, and the check's dt_max (`stepsize.step_limit` with the
contact: LAW_CALIBRATION x min(1, LUGRE_SIGMA1 / sigma1)).

Writes benchmarks/results/step_limits_laws.txt.
Usage: .venv/bin/python benchmarks/step_limits_laws.py   (about a minute)
"""
import dataclasses
import math
import os
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
from _results import publish  # noqa: E402
from contact_laws import P, sim  # noqa: E402

from pdw.analysis.numerics import stability_maps as S  # noqa: E402
from pdw.analysis.numerics.calibration import calibrate, calibrate_lugre  # noqa: E402
from pdw.sim import stepsize  # noqa: E402

METHODS = ("cdm", "verlet", "rk4")
VARIANTS = ("paper", "consistent")
X0 = stepsize.typical_start(P)


def verdict(r, ref):
    """(walks, walks correctly) against the reference."""
    tr, tm = S.touch_downs(ref), S.touch_downs(r)
    if r.status != "walked" or [g for _, g in tm] != [g for _, g in tr]:
        return False, False
    cyc = np.mean(np.diff([t for t, _ in tr])) if len(tr) > 1 else 0.6
    err = max((abs(a - b) for (a, _), (b, _) in zip(tm, tr)), default=0.0)
    return True, err <= max(S.TD_TOL_ABS, S.TD_TOL_REL * cyc)


def limit(contact, method, ref, which, variant="paper"):
    """(largest dt that passes, smallest that does not) by scan + 4 log-bisections."""
    x0 = stepsize.typical_start(P, variant)

    def ok(dt):
        r = sim(contact, x0=x0, t_end=3.5, method=method, dt=dt, record_every=0, variant=variant)
        return verdict(r, ref)[which]

    return S.edge_on_grid(ok, [1e-5 * 10 ** (k / 2) for k in range(0, 9)])


def main():
    t0 = time.perf_counter()
    cal = calibrate(P)
    contacts = dict(cal.contacts, lugre=calibrate_lugre(P).contact)
    lines = ["# fixed-step limits of every contact law on paper_steady (benchmarks/step_limits_laws.py)",
             "load average at start: %s" % (os.getloadavg(),), ""]
    for law, c in contacts.items():
        lines.append("%-20s %s" % (law, c.as_dict()))
    lines += ["", "| law | variant | method | walks up to [s] | fails at [s] | correct up to [s] | "
              "reference estimate [s] | walks / estimate | factor |", "|---|---|---|---|---|---|---|---|---|"]
    ratio, rows = {}, []
    for v in VARIANTS:
        x0 = stepsize.typical_start(P, v)
        for law, c in contacts.items():
            ref = sim(c, x0=x0, t_end=3.5, method="rodas4", rtol=1e-9, atol=1e-11, record_every=0,
                      variant=v)
            for m in METHODS:
                a, b = limit(c, m, ref, 0, v)
                ac, _ = limit(c, m, ref, 1, v)
                est = stepsize._dt_max(c.parameters(P), m, v)
                ratio[law, v, m] = a / est if a else math.nan
                rows.append((law, v, m, a, b, ac, est))
    g = lambda v: "%.3g" % v if v else "none"  # noqa: E731
    for law, v, m, a, b, ac, est in rows:
        lines.append("| %s | %s | %s | %s | %s | %s | %.3g | %.3g | %.3g |" % (
            law, v, m, g(a), g(b), g(ac), est, ratio[law, v, m],
            ratio[law, v, m] / ratio["hunt_crossley", v, m]))
    lines += ["", "LuGre's bristle damping (the walks edge against the check's dt_max):", "",
              "| sigma1 [s/m] | method | walks up to [s] | fails at [s] | check dt_max [s] |",
              "|---|---|---|---|---|"]
    c0 = contacts["lugre"]
    for s1 in (c0.sigma1 / 3, c0.sigma1, 3 * c0.sigma1, 316.2):
        c = dataclasses.replace(c0, sigma1=s1)
        ref = sim(c, x0=X0, t_end=3.5, method="rodas4", rtol=1e-9, atol=1e-11, record_every=0)
        for m in METHODS:
            a, b = limit(c, m, ref, 0)
            lim = stepsize.step_limit(c.parameters(P), m, "paper", c).dt_max
            lines.append("| %.4g | %s | %s | %s | %.3g |" % (s1, m, g(a), g(b), lim))
    lines += ["", "load average at end: %s" % (os.getloadavg(),),
              "total %.0f s" % (time.perf_counter() - t0)]
    publish("step_limits_laws.txt", lines)


if __name__ == "__main__":
    main()
