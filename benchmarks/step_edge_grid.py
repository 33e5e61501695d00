"""The walking edge of cdm on a uniform dt grid: is it a clean edge or a ragged one?

`pdw.analysis.numerics.stability_maps.largest_step` bisects in log dt and reports the largest step *below which every
tried step passed*. Near the edge the verdict need not be monotone in dt; this script runs every
dt of a uniform grid (default 1.00 to 3.00 ms in 0.05 ms steps, plus 2.3e-3 exactly) on the
typical gait (3.5 s, `pdw.sim.stepsize.typical_start`, judged against the rodas4 reference by
`pdw.analysis.numerics.stability_maps.judge`) and reports which pass, the last dt below which all pass, and the passes
above the first failure. Writes step_edge_grid.txt (benchmarks/_results.py says where).

Usage: .venv/bin/python benchmarks/step_edge_grid.py [--lo 1e-3] [--hi 3e-3] [--step 5e-5]
"""
import argparse
import os
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
from _results import publish  # noqa: E402

import pdw  # noqa: E402
from pdw.analysis.numerics import stability_maps as S  # noqa: E402
from pdw.sim.stepsize import typical_start  # noqa: E402


def grid_verdicts(params, grid, method="cdm", variant="paper"):
    ref = S.reference(params, variant)
    g_ref = S.energy_gain(ref)
    x0 = typical_start(params, variant)
    return [(dt, S.judge(S.run_fixed(params, method, dt, variant, ref.t_end, x0), ref, g_ref))
            for dt in grid]


def summary(rows):
    walks = [v.walks for _, v in rows]
    first_fail = next((i for i, w in enumerate(walks) if not w), None)
    clean = rows[first_fail - 1][0] if first_fail else None
    above = [dt for (dt, v) in rows[first_fail:] if v.walks] if first_fail is not None else []
    return clean, (rows[first_fail][0] if first_fail is not None else None), above


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--lo", type=float, default=1e-3)
    ap.add_argument("--hi", type=float, default=3e-3)
    ap.add_argument("--step", type=float, default=5e-5)
    args = ap.parse_args(argv)
    n = int(round((args.hi - args.lo) / args.step)) + 1
    grid = sorted(set(np.round(np.linspace(args.lo, args.hi, n), 12).tolist()) | {2.3e-3})
    lines = ["cdm walking edge on a uniform grid: dt %.2f to %.2f ms in %.3f ms steps (+ 2.3e-3); "
             "typical gait, 3.5 s, judged against rodas4 (pdw.analysis.numerics.stability_maps.judge); load average %s"
             % (args.lo * 1e3, args.hi * 1e3, args.step * 1e3, "%.2f %.2f %.2f" % os.getloadavg()),
             ""]
    for label, params in (("Params.paper()", pdw.Params.paper()),
                          ("Params.paper_steady()", pdw.Params.paper_steady())):
        rows = grid_verdicts(params, grid)
        clean, fail, above = summary(rows)
        lines.append("%s: walks at every dt <= %s ms; first failure at %s ms; walks again at %s"
                     % (label, "%.2f" % (clean * 1e3) if clean else "-",
                        "%.2f" % (fail * 1e3) if fail else "-",
                        ", ".join("%.2f" % (d * 1e3) for d in above) + " ms" if above else "none"))
        lines.append("  " + " ".join("%.2f%s" % (dt * 1e3, "+" if v.walks else "x")
                                     for dt, v in rows))
        lines.append("")
    lines.append("(+ walks, x does not; dt in ms)")
    publish("step_edge_grid.txt", lines)


if __name__ == "__main__":
    main()
