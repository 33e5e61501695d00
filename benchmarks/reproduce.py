"""Numbers of docs/reproduction.md: the typical gait (both variants), 20 s runs, the disturbed start.

Run: `.venv/bin/python benchmarks/reproduce.py [typical|long|disturbed|all]`.
"""
import sys

import numpy as np

import pdw
from pdw.present.report import stance_forces, walk_report


def typical():
    for variant in pdw.VARIANTS:
        r = pdw.simulate(variant=variant)
        print("=" * 100)
        print(walk_report(r))
        s = stance_forces(r)
        print("\nnormal force peak (mean over stances): %.1f N = %.2f x weight; settled %.1f N = %.3f x weight"
              % (np.mean([x["Fn_peak"] for x in s]), np.mean([x["Fn_peak"] for x in s]) / r.params.weight,
                 np.mean([x["Fn_settled"] for x in s]),
                 np.mean([x["Fn_settled"] for x in s]) / r.params.weight))


def long():
    print("20 s runs, dt = 1e-4, cdm")
    print("%-13s %-11s %-8s %8s %6s %8s %8s %8s %9s %10s" % (
        "preset", "variant", "status", "t_end", "steps", "L", "P", "v", "DS [ms]", "spread L"))
    for preset in ("paper", "paper_steady"):
        for variant in pdw.VARIANTS:
            r = pdw.simulate(t_end=20.0, params=pdw.Params.preset(preset), variant=variant,
                             record=pdw.Record(every=0))
            st = pdw.steps(r)
            sd = st.steady(4)
            print("%-13s %-11s %-8s %8.3f %6d %8.4f %8.4f %8.4f %9.1f %10.2g" % (
                preset, variant, r.status, r.t_final, len(st), sd["L"], sd["P"], sd["v"],
                1e3 * sd["double_support"], sd["spread_L"]))
            if preset == "paper":
                print("    per-step L: %s" % np.array2string(st["L"], precision=4))
                print("    per-step P: %s" % np.array2string(st["P"], precision=4))
                print("    %s" % r.summary())
            else:
                dL = np.abs(np.diff(st["L"]))
                print("    |L_k+1 - L_k| every 5th step: %s" % np.array2string(dL[::5], precision=2))


def disturbed():
    print("disturbed start (Fig. 9): x0 = %s, flags0 = (1, 0): leg 1 (ahead) in support, leg 2 "
          "(behind) swing" % (pdw.X0_DISTURBED,))
    for preset in ("paper", "paper_steady"):
        for variant in pdw.VARIANTS:
            typ = pdw.steps(pdw.simulate(t_end=20.0, params=pdw.Params.preset(preset), variant=variant,
                                         record=pdw.Record(every=0))).steady(4)
            r = pdw.simulate(pdw.X0_DISTURBED, t_end=20.0, params=pdw.Params.preset(preset),
                             variant=variant, flags0=(1, 0), record=pdw.Record(every=0))
            st = pdw.steps(r)
            sd = st.steady(4)
            print("%-13s %-11s %s" % (preset, variant, r.summary()))
            print("    first L: %s" % np.array2string(st["L"][:6], precision=4))
            print("    last 4 steps: L %.4f P %.4f (typical start: L %.4f P %.4f)"
                  % (sd["L"], sd["P"], typ["L"], typ["P"]))


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "all"
    for name, fn in (("typical", typical), ("long", long), ("disturbed", disturbed)):
        if what in (name, "all"):
            fn()
