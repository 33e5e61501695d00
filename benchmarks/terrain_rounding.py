"""How far a shaped ground's results moved between two builds (docs/terrain.md "Costs"): each run
of paper_steady over 2 s on a shaped ground (both variants, cdm and rodas4) in this build and in
the build in DIR; the largest difference of the final state relative to its largest component,
of the touch-down times, and of the gait's step periods and lengths; and, for scale, the same
differences of the flat model when theta_1 changes by 1 part in 1e15.

    .venv/bin/python benchmarks/terrain_rounding.py --ref DIR

DIR: a built copy of the other version (``git archive REV | tar -x -C DIR`` and
``python setup.py build_ext --inplace`` there). The runs of the other build are made by a worker
process that imports pdw from DIR.
"""
import json
import os
import subprocess
import sys

import numpy as np

import pdw
from pdw import Ground

sys.path.insert(0, os.path.dirname(__file__))
from _results import publish  # noqa: E402

P = pdw.Params.paper_steady()
GROUNDS = {
    "tilted plane": lambda: Ground.plane(0.01),
    "steps": lambda: Ground.steps([0.6, 1.4], [-0.003, 0.002]),
    "sine": lambda: Ground.sine(0.001, 0.8),
    "random": lambda: Ground.random(0.0005, 0.1, seed=1, extent=(-1.0, 5.0)),
    "patches": lambda: Ground.flat(extent=(-2.0, 50.0)).with_patches(
        [dict(s_a=0.3, s_b=0.6, k_n=8e4), dict(s_a=1.0, s_b=1.4, mu_s=0.45)]),
}
METHODS = {
    "cdm": dict(method="cdm"),
    "rodas4": dict(integrator=pdw.Integrator(method="rodas4", rtol=1e-8, atol=1e-10)),
}
VARIANTS = ("paper", "consistent")


def run(gname, mname, variant):
    """The run's final state, touch-down times, periods and step lengths (JSON-able)."""
    r = pdw.simulate(params=P, variant=variant, ground=GROUNDS[gname](), t_end=2.0,
                     record=pdw.Record(every=0), limits=pdw.Limits(on_failure="return"),
                     **METHODS[mname])
    td = [e.t for e in r.events if e.kind == "touch_down"] if r.events is not None else []
    return dict(status=r.status, x=list(map(float, r.x_final)), td=td,
                P=list(map(float, r.gait["P"])), L=list(map(float, r.gait["L"])))


def _dmax(a, b, k, same):
    """max |a[k] - b[k]| (0 where the runs' event counts differ or there is none)."""
    return float(np.abs(np.array(a[k]) - np.array(b[k])).max()) if same and a[k] else 0.0


def _worker():
    for line in sys.stdin:
        print(json.dumps(run(*json.loads(line))), flush=True)


def main(ref):
    env = dict(os.environ, PYTHONPATH=os.path.abspath(ref))
    proc = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--worker"], env=env,
                            cwd=os.path.abspath(ref), stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)
    lines = ["terrain_rounding: paper_steady, 2 s, this build vs %s; max |dx| / max |x| of the "
             "final state, max |dt| of the touch-downs [s], max |dP| [s], max |dL| [m]" % ref]
    worst = 0.0
    for gname in GROUNDS:
        for mname in METHODS:
            for variant in VARIANTS:
                a = run(gname, mname, variant)
                proc.stdin.write(json.dumps([gname, mname, variant]) + "\n")
                proc.stdin.flush()
                b = json.loads(proc.stdout.readline())
                xa, xb = np.array(a["x"]), np.array(b["x"])
                rel = float(np.abs(xa - xb).max() / np.abs(xb).max())
                same = (a["status"] == b["status"] and len(a["td"]) == len(b["td"])
                        and len(a["P"]) == len(b["P"]))
                worst = max(worst, rel)
                lines.append("  %-13s %-7s %-10s x %.1e  touch-downs %.1e  P %.1e  L %.1e%s"
                             % (gname, mname, variant, rel, _dmax(a, b, "td", same),
                                _dmax(a, b, "P", same), _dmax(a, b, "L", same),
                                "" if same else "  (DIFFERENT status/events: %s vs %s)"
                                % (a["status"], b["status"])))
    proc.stdin.close()
    proc.wait()
    lines.append("largest relative state difference: %.1e" % worst)
    # the scale of a rounding-level change: the flat model (this build) with theta_1 changed by
    # 1 part in 1e15
    for mname in METHODS:
        kw = dict(params=P, t_end=2.0, record=pdw.Record(every=0),
                  limits=pdw.Limits(on_failure="return"), **METHODS[mname])
        x0 = np.array(pdw.X0_PAPER, float)
        x1 = x0.copy()
        x1[2] *= 1.0 + 1e-15
        a, b = pdw.simulate(x0, **kw), pdw.simulate(x1, **kw)
        ta = np.array([e.t for e in a.events if e.kind == "touch_down"])
        tb = np.array([e.t for e in b.events if e.kind == "touch_down"])
        dt = "%.1e" % np.abs(ta - tb).max() if len(ta) == len(tb) else "(counts differ)"
        lines.append("flat model, %s, theta_1 * (1 + 1e-15): x %.1e  touch-downs %s"
                     % (mname, np.abs(a.x_final - b.x_final).max() / np.abs(a.x_final).max(), dt))
    publish("terrain_rounding.txt", lines)


if __name__ == "__main__":
    if "--worker" in sys.argv:
        _worker()
    elif "--ref" in sys.argv:
        main(sys.argv[sys.argv.index("--ref") + 1])
    else:
        raise SystemExit(__doc__)
