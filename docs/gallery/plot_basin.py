"""
A basin of attraction
=====================

Where the walker ends up from a grid of touch-down states (``pdw.analysis.basins.basin``): every grid
point is one walker of the ensemble engine (`pdw.simulate_batch`, docs/ensemble.md), started
at a touch-down with step angle phi and swing rate thetad2, run until its last four steps
agree (a periodic gait) or it falls. The window is wide enough to hold the basin's edge on
both sides in phi (walkers there fall within a step or two), and t_end = 12 s lets every walker
inside settle (at 6 s most were still converging: "undecided"). A coarse 32 x 32 grid here (a
few seconds); the grid's default is 100 x 100 (docs/ensemble.md).
"""
import matplotlib.pyplot as plt

import pdw
from pdw.analysis.basins import basin

b = basin.basin(pdw.Params.paper_steady(), phi=(0.6, 0.9, 32), thetad2=(-6.0, 1.0, 32),
                t_end=12.0)
print("%d walkers in %.2f s: %.0f %% reach the reference gait (L = %.4f m, P = %.4f s), "
      "%.0f %% fall, %.0f %% undecided"
      % (b.walkers, b.wall_time, 100 * b.fraction(), b.gait_L, b.gait_P,
         100 * b.fraction(basin.FELL), 100 * b.fraction(basin.UNDECIDED)))
basin.plot(b)
plt.tight_layout()
