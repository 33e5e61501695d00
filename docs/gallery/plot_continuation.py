"""
Continuation of a gait in the slope
===================================

`pdw.continue_gait` follows a period-one gait as one parameter moves, with the Floquet
multipliers of every point and the bifurcations on the way (docs/continuation.md). Here the
rigid-ground compass gait (the hybrid model, exact derivatives: a fraction of a second) from
its slope of 3 degrees to 7 degrees: its step length grows with the slope, and a period
doubling (a multiplier through -1, near 4.4 degrees) ends its stability.
"""
import matplotlib.pyplot as plt
import numpy as np

import pdw

DEG = np.pi / 180
params = pdw.hybrid.compass_gait_params()
branch = pdw.continue_gait(params, "gamma", 7.0 * DEG, model="hybrid")
print(branch)
for b in branch.bifurcations:
    print("%s at gamma = %.4f deg" % (b.kind, b.value / DEG))

fig, ax = plt.subplots(figsize=(6, 3.5))
ok = branch.stable
ax.plot(branch.values[ok] / DEG, branch.step_length[ok], "b.", label="stable")
ax.plot(branch.values[~ok] / DEG, branch.step_length[~ok], "r.", label="unstable")
for b in branch.bifurcations:
    ax.axvline(b.value / DEG, color="k", lw=0.8, ls=":")
ax.set_xlabel("slope gamma [deg]")
ax.set_ylabel("step length [m]")
ax.legend()
fig.tight_layout()
