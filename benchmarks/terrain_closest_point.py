"""The error of the shaped-ground contact's tangent-line approximation (docs/terrain.md).

pdw samples the ground once per foot, at s_A = x_A (below the foot arc's centre A), and takes
the gap along the normal of the tangent line there: g_tl = (y_A - h(s_A)) / N - r. The exact gap
is the distance from A to the curve minus r, at the closest point s* (found here by dense
sampling and Newton's method on (s - x_A) + h'(s)(h(s) - y_A) = 0). For feet 3 mm deep (the
typical depth of paper_steady's stance foot, k_n = 1e5) this prints, per ground, the smallest
radius of curvature over r, the largest |g_tl - g_exact| [m] (also relative to the depth) and the
largest angle between the two normals [rad].

    .venv/bin/python benchmarks/terrain_closest_point.py
"""
import os
import sys

import numpy as np

from pdw import Ground

sys.path.insert(0, os.path.dirname(__file__))
from _results import publish  # noqa: E402

R = 0.2                 # foot radius r of paper_steady [m]
DEPTH = 0.003           # penetration [m]
GROUNDS = {
    "plane 0.05 rad": Ground.plane(0.05),
    "steps 5 mm over 1 cm": Ground.steps([1.0], [-0.005], width=0.01),
    "steps 5 mm over 5 cm": Ground.steps([1.0], [-0.005], width=0.05),
    "steps 5 mm over 20 cm": Ground.steps([1.0], [-0.005], width=0.2),
    "steps 5 mm over 40 cm": Ground.steps([1.0], [-0.005], width=0.4),
    "sine 1 mm / 0.5 m": Ground.sine(0.001, 0.5),
    "sine 5 mm / 1 m": Ground.sine(0.005, 1.0),
    "sine 2 mm / 0.2 m": Ground.sine(0.002, 0.2),
    "random 1 mm, 0.1 m": Ground.random(0.001, 0.1, seed=1, extent=(-1.0, 4.0)),
    "random 2 mm, 0.05 m": Ground.random(0.002, 0.05, seed=2, extent=(-1.0, 4.0)),
}


def exact_gap(g, xa, ya):
    """Distance from (xa, ya) to the curve (s, h(s)) minus R, and the normal's angle there."""
    s = xa + np.linspace(-2 * R, 2 * R, 4001)
    h = g.h(s)
    k = np.argmin((s - xa) ** 2 + (h - ya) ** 2)
    t = s[k]
    for _ in range(30):                      # Newton on F(s) = (s - xa) + h'(s) (h(s) - ya)
        hh, d, dd = (float(v) for v in g.evaluate(t))
        F = (t - xa) + d * (hh - ya)
        dF = 1 + d * d + dd * (hh - ya)
        t -= F / dF
    hh, d, _ = (float(v) for v in g.evaluate(t))
    return np.hypot(t - xa, ya - hh) - R, np.arctan(d)


def main():
    lines = ["terrain_closest_point: tangent-line gap at s_A vs the exact closest point; r = %g m, "
             "depth %g mm" % (R, 1e3 * DEPTH),
             "%-22s %12s %14s %12s %12s" % ("ground", "min rho / r", "max |err| [m]", "err / depth",
                                             "normal [rad]")]
    xs = np.linspace(0.3, 2.3, 801)
    for name, g in GROUNDS.items():
        h, d, dd = g.evaluate(xs)
        N = np.sqrt(1 + d * d)
        ya = h + (R - DEPTH) * N                 # tangent-line gap exactly -DEPTH
        errs, angs = [], []
        for xa, y, di in zip(xs, ya, d):
            ge, ang = exact_gap(g, xa, y)
            errs.append(abs(ge - (-DEPTH)))
            angs.append(abs(ang - np.arctan(di)))
        curv = np.abs(dd) / N ** 3
        rho = np.inf if curv.max() == 0 else 1.0 / curv.max()
        lines.append("%-22s %12.3g %14.3g %12.3g %12.3g"
                     % (name, rho / R, max(errs), max(errs) / DEPTH, max(angs)))
    publish("terrain_closest_point.txt", lines)


if __name__ == "__main__":
    main()
