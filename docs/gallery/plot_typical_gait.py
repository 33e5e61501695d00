"""
The typical gait
================

The paper's typical gait (Sec. 3.2) with the stiff integrator, sampled where we ask
(``t_eval``), its step table, and the support flags of both legs.
"""
import matplotlib.pyplot as plt
import numpy as np

import pdw

t = np.linspace(0.0, 3.5, 701)
res = pdw.simulate(integrator=pdw.Integrator(method="rodas4", rtol=1e-7, atol=1e-9),
                   record=pdw.Record(t_eval=t))
print(res.summary())
print(res.gait.to_text())

fig, ax = plt.subplots(2, 1, sharex=True, figsize=(7, 4.5))
ax[0].plot(res.t, res.state("theta1"), label=r"$\theta_1$")
ax[0].plot(res.t, res.state("theta2"), label=r"$\theta_2$")
ax[0].set_ylabel("leg angle [rad]")
ax[0].legend()
ax[1].plot(res.t, res.Fn[:, 0], label="foot 1")
ax[1].plot(res.t, res.Fn[:, 1], label="foot 2")
ax[1].set_ylabel("normal force [N]")
ax[1].set_xlabel("t [s]")
ax[1].legend()
fig.tight_layout()
