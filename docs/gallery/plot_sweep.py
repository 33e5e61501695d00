"""
A parameter sweep
=================

A study (docs/studies.md) sweeps `pdw.Params` fields over ranges; each point is one `pdw.Scene`
run to its steady gait, and the table of steady descriptors is written as CSV (resumable)
with a JSON record of how it was made. Here the hip mass m_h over five values, cdm at the
paper's step for 8 s, the steady values the mean of the last four steps (the shipped studies
use rodas4 for 16 s and a Newton search where that does not settle; ``pdw sweep`` runs them
from the command line). The ``gait`` column says whether the last steps agreed to the
study's period_tol (``period-1``) or were still drifting (``none``: the values are then the
mean of a gait still settling).
"""
import tempfile

import matplotlib.pyplot as plt

import pdw
from pdw.studies.study import parse_study

study = parse_study('''
name = "gallery_m_h"
[scene]
preset = "paper_steady"
integrator = { method = "cdm", dt = 1e-4 }
stop = { t_end = 8.0 }
[[axes]]
name = "m_h"
start = 1.0
stop = 3.0
num = 5
[run]
fallback = false        # no Newton search where 8 s do not settle the gait: say so instead
''')
out = tempfile.mkdtemp()
res = pdw.sweep.run_study(study, out, progress=False)
print("%d points in %.2f s (CSV and JSON in %s)" % (len(res.rows), res.wall_s, out))
for r in res.rows:
    print("m_h = %.2f kg: %-8s %-10s L = %.4f m, P = %.4f s" % (
        r["m_h"], r["status"], r["gait"], r["L"] or float("nan"), r["P"] or float("nan")))

fig, ax = plt.subplots(figsize=(6, 3.5))
m_h, L = res.column("m_h"), res.column("L")
settled = [g == "period-1" for g in res.column("gait")]
ax.plot(m_h, L, "-", color="0.6")
for x, y, ok in zip(m_h, L, settled):
    ax.plot(x, y, "o", color="C0", mfc="C0" if ok else "white")
ax.set_title("filled: settled (period-1), open: still settling at 8 s")
ax.set_xlabel("hip mass m_h [kg]")
ax.set_ylabel("steady step length L [m]")
fig.tight_layout()
