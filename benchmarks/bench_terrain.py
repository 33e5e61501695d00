"""What a ground costs per step (docs/terrain.md, issue 22): CPU time per integration step of the
walker on flat ground (no ground, and ``Ground()``: the same kernel) and on shaped and patched
grounds (the shaped-ground kernel of pdw_terrain.c), for cdm (the paper's method, dt 1e-4) and
rodas4 (rtol 1e-8). Each round runs every configuration once, interleaved; the ratios are the
medians over rounds of (configuration / no ground) in the same round. The 1-minute load average
is printed with the result.

    .venv/bin/python benchmarks/bench_terrain.py [rounds]        (default 7)
    .venv/bin/python benchmarks/bench_terrain.py [rounds] --ref DIR

With ``--ref DIR`` (a built copy of another version, e.g. ``git archive main | tar -x -C DIR``
and ``python setup.py build_ext --inplace`` there) every configuration is also run by a worker
process that imports pdw from DIR, right after this version's run of it in the same round, and
the report gives both versions' times and ratios (interleaved: the same load for both).
"""
import os
import subprocess
import sys
import time

import numpy as np

import pdw
from pdw import Ground

sys.path.insert(0, os.path.dirname(__file__))
from _results import publish  # noqa: E402

P = pdw.Params.paper_steady()
GROUNDS = {
    "none": None,
    "Ground()": Ground(),
    "plane 0": Ground.plane(0.0),
    "steps": Ground.steps([0.6, 1.4], [-0.003, 0.002]),
    "sine": Ground.sine(0.001, 0.8),
    "random": Ground.random(0.0005, 0.1, seed=1, extent=(-1.0, 5.0)),
    "patches": Ground.flat(extent=(-2.0, 50.0)).with_patches(
        [dict(s_a=0.3, s_b=0.6, k_n=8e4), dict(s_a=1.0, s_b=1.4, mu_s=0.45)]),
}
METHODS = {
    "cdm": dict(method="cdm", t_end=2.0),
    "rodas4": dict(integrator=pdw.Integrator(method="rodas4", rtol=1e-8, atol=1e-10), t_end=2.0),
}


def cpu_per_step(ground, opts):
    t0 = time.process_time()
    r = pdw.simulate(params=P, record=pdw.Record(every=0), limits=pdw.Limits(on_failure="return"),
                     ground=ground, **opts)
    return (time.process_time() - t0) / max(r.n_steps, 1), r


def _worker():
    """Measure the configurations named on stdin ("method ground" per line), one reply each."""
    for line in sys.stdin:
        mname, gname = line.split(None, 1)
        c, r = cpu_per_step(GROUNDS[gname.strip()], METHODS[mname])
        print("%r %s %d %d" % (c, r.status, r.n_gait_steps, r.n_steps), flush=True)


def _start_ref(ref):
    env = dict(os.environ, PYTHONPATH=os.path.abspath(ref))
    return subprocess.Popen([sys.executable, os.path.abspath(__file__), "--worker"], env=env,
                            cwd=os.path.abspath(ref), stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)


def _ask(proc, mname, gname):
    proc.stdin.write("%s %s\n" % (mname, gname))
    proc.stdin.flush()
    c, status, gait, steps = proc.stdout.readline().split()
    return float(c), (status, int(gait), int(steps))


def main(rounds=7, ref=None):
    for g in GROUNDS.values():          # build the tables once, outside the timings
        if g is not None and not g.is_flat:
            g.table()
    proc = _start_ref(ref) if ref else None
    lines = ["bench_terrain: CPU time per integration step, paper_steady, t_end 2 s; median of "
             "%d interleaved rounds; ratio to no ground in the same round" % rounds]
    if ref:
        lines.append("ref: the build in %s, each configuration run right after this one's" % ref)
    for mname, opts in METHODS.items():
        per = {k: [] for k in GROUNDS}
        rper = {k: [] for k in GROUNDS}
        info = {}
        for _ in range(rounds):
            for k, g in GROUNDS.items():
                c, r = cpu_per_step(g, opts)
                per[k].append(c)
                info[k] = (r.status, r.n_gait_steps, r.n_steps)
                if proc:
                    rc, rinfo = _ask(proc, mname, k)
                    rper[k].append(rc)
                    # the same run: status and gait steps equal, integration steps within
                    # 1 % (a shaped ground's results may differ at the rounding level between
                    # versions, which can move an adaptive method's step count by a few)
                    if (rinfo[:2] != info[k][:2]
                            or abs(rinfo[2] - info[k][2]) > 0.01 * info[k][2]):
                        raise SystemExit("ref run of %s/%s differs: %s vs %s"
                                         % (mname, k, rinfo, info[k]))
        base = np.array(per["none"])
        lines.append("%s:" % mname)
        for k in GROUNDS:
            ratio = np.median(np.array(per[k]) / base)
            line = ("  %-9s %8.3f us/step  ratio %.3f  (%s, %d gait steps, %d steps)"
                    % (k, 1e6 * np.median(per[k]), ratio, *info[k]))
            if proc:
                rratio = np.median(np.array(rper[k]) / np.array(rper["none"]))
                line += "  ref %.3f us/step ratio %.3f" % (1e6 * np.median(rper[k]), rratio)
            lines.append(line)
    if proc:
        proc.stdin.close()
        proc.wait()
    lines.append("load average (1 min) %.2f on %d CPUs" % (os.getloadavg()[0], os.cpu_count() or 1))
    publish("bench_terrain.txt", lines)


if __name__ == "__main__":
    if "--worker" in sys.argv:
        _worker()
    else:
        args = sys.argv[1:]
        ref = None
        if "--ref" in args:
            i = args.index("--ref")
            ref = args[i + 1]
            del args[i:i + 2]
        main(int(args[0]) if args else 7, ref)
