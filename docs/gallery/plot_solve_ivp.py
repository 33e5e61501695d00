"""
The model in scipy's solve_ivp
==============================

``pdw.ode_function`` gives f(t, x) and its Jacobian for external solvers. One stretch of
stance (leg 2 supporting, no flag change) with scipy's Radau against pdw's own rodas4.
"""
import matplotlib.pyplot as plt
import numpy as np
from scipy.integrate import solve_ivp

import pdw

x0 = np.array(pdw.X0_PAPER)
f = pdw.ode_function(flags=(0, 1))
sol = solve_ivp(f, (0.0, 0.2), x0, method="Radau", jac=f.jac, rtol=1e-9, atol=1e-11,
                dense_output=True)
ours = pdw.simulate(t_end=0.2, integrator=pdw.Integrator(method="rodas4", rtol=1e-9, atol=1e-11))
err = np.abs(sol.sol(ours.t).T - ours.x).max(axis=1)
print("largest difference over the stretch: %.2e" % err.max())

fig, ax = plt.subplots(figsize=(7, 3))
ax.semilogy(ours.t, err + 1e-16)
ax.set_xlabel("t [s]")
ax.set_ylabel("|Radau - rodas4| (max over x)")
fig.tight_layout()
