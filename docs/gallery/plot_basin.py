"""
A basin of attraction
=====================

Where the walker ends up from a grid of touch-down states (`pdw.analysis.basin`): every grid
point is one walker of the ensemble engine (`pdw.simulate_batch`, docs/ensemble.md), started
at a touch-down with step angle phi and swing rate thetad2, run until its last four steps
agree (a periodic gait) or it falls; "undecided" walkers are still walking, not yet periodic,
at t_end = 6 s. A coarse 24 x 24 grid here (a few seconds); the grid's default is 100 x 100
(docs/ensemble.md).
"""
import matplotlib.pyplot as plt

import pdw
from pdw.analysis import basin

b = basin.basin(pdw.Params.paper_steady(), phi=(0.69, 0.81, 24), thetad2=(-3.2, -0.4, 24),
                t_end=6.0)
print("%d walkers in %.2f s: %.0f %% reach the reference gait (L = %.4f m, P = %.4f s)"
      % (b.walkers, b.wall_time, 100 * b.fraction(), b.gait_L, b.gait_P))
basin.plot(b)
plt.tight_layout()
