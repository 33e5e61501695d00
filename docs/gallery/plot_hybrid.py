"""
The rigid-ground hybrid model
=============================

The impact-momentum model of docs/model.md section 9: its period-one gait, and the gait's
Floquet multipliers against the unit circle (inside: the gait is stable).
"""
import matplotlib.pyplot as plt
import numpy as np

import pdw

g = pdw.hybrid.find_gait()
print(g)

fig, ax = plt.subplots(figsize=(4, 4))
phi = np.linspace(0, 2 * np.pi, 200)
ax.plot(np.cos(phi), np.sin(phi), color="0.6", lw=1)
m = np.asarray(g.multipliers)
ax.plot(m.real, m.imag, "x", ms=9, mew=2)
ax.set_aspect("equal")
ax.set_xlabel("Re")
ax.set_ylabel("Im")
ax.set_title("Floquet multipliers (%s)" % ("stable" if g.stable else "unstable"))
fig.tight_layout()
