"""Which fixed steps walk with LuGre friction (docs/contact_laws.md, "LuGre friction").

For the calibrated law (`pdw.calibration.calibrate_lugre`) and for Canudas de Wit et al.'s
sigma1 = sqrt(1e5): cdm, verlet and rk4 on `paper_steady` for 3 s from the paper's start at
dt = 1e-4, 5e-5, 2e-5, 1e-5 s; prints the status and the number of complete gait steps.
Usage: .venv/bin/python benchmarks/lugre_steps.py   (about a minute)
"""
import dataclasses
import math
import os

import pdw
from pdw.analysis.numerics.calibration import calibrate_lugre

P = pdw.Params.paper_steady()
cal = calibrate_lugre(P).contact
print("load average %.2f" % os.getloadavg()[0])
for label, c in (("calibrated sigma1 = %.2f" % cal.sigma1, cal),
                 ("sigma1 = sqrt(1e5)", dataclasses.replace(cal, sigma1=math.sqrt(1e5)))):
    for m in ("cdm", "verlet", "rk4"):
        row = []
        for dt in (1e-4, 5e-5, 2e-5, 1e-5):
            r = pdw.simulate(params=P, t_end=3.0, dt=dt, method=m, contact=c,
                             integrator=pdw.Integrator(check_step="off"),
                             record=pdw.Record(every=0), limits=pdw.Limits(on_failure="return"))
            row.append("%g: %s (%d steps)" % (dt, r.status, r.n_gait_steps))
        print("%-26s %-7s %s" % (label, m, "; ".join(row)))
