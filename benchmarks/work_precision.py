"""Work-precision study (docs/work_precision.md): run time and f evaluations against error, for
pdw's compiled integrators and scipy's solve_ivp (LSODA, Radau, DOP853) driven by the same
compiled right-hand side and symbolic Jacobian (benchmarks/scipy_driver.py), in the style of
SciMLBenchmarks.

Problems
  typical  the paper's typical gait: Params.paper(), X0_PAPER, variant paper, 3.5 s;
           error = max_i |q_i - q_ref,i| at 1 s (a separate run to 1 s) and at 3.5 s.
  steady   the steady gait of Params.paper_steady() from X0_PAPER, 8 s (13 steps);
           error of the step period P and the step length L (pdw.steps) of the last 4 steps:
           max over those steps of |P - P_ref| [s], |L - L_ref| [m].
pdw's adaptive methods locate switches to event_tol = min(1e-9 s, rtol) (the default 1e-9 s
for rtol >= 1e-9). Reference: pdw rodas4 at rtol 1e-12, atol 1e-14, event_tol 1e-12,
cross-checked by rodas4 at rtol 1e-13 (event_tol 1e-13) and dopri5 at rtol 1e-12 (printed, and
rows "reference" in the CSV); atol = 1e-2 rtol for every adaptive run, pdw's and scipy's.

Wall time: median of repeated runs in this one process (the first run included; the number of
repeats shrinks with the run time), perf_counter around the whole call (pdw.simulate /
simulate_scipy, Python set-up included). Writes benchmarks/results/work_precision.csv and
docs/figures/work_precision.png; prints the reference check and the headline.

Run: `make bench` or `.venv/bin/python benchmarks/work_precision.py [--quick]` (--quick: fewer
points and no DOP853, for a smoke test).
"""
import argparse
import csv
import math
import pathlib
import platform
import statistics
import sys
import time

import numpy as np
from _results import FIGURES, RESULTS
from scipy_driver import simulate_scipy

import pdw

ROOT = pathlib.Path(__file__).resolve().parent.parent
FIGURE = FIGURES / "work_precision.png"
CSV = RESULTS / "work_precision.csv"
TARGET = 1e-6                     # headline: error of q(3.5 s)

PROBLEMS = {
    "typical": dict(params=pdw.Params.paper(), x0=pdw.X0_PAPER, variant="paper", t_end=3.5, t_mid=1.0),
    "steady": dict(params=pdw.Params.paper_steady(), x0=pdw.X0_PAPER, variant="paper", t_end=8.0),
}
LAST_STEPS = 4

REF = ("rodas4", dict(rtol=1e-12, atol=1e-14, event_tol=1e-12))
CROSS = [("rodas4", dict(rtol=1e-13, atol=1e-15, event_tol=1e-13)),
         ("dopri5", dict(rtol=1e-12, atol=1e-14, event_tol=1e-12, dt=1e-5))]

PDW_FIXED = {                      # explicit fixed-step methods: slow at tiny steps, few points
    "typical": {"cdm": (1e-4, 1e-5, 1e-6), "verlet": (1e-4, 1e-5, 1e-6), "rk4": (1e-4, 1e-5, 2e-6)},
    "steady": {"cdm": (1e-4, 1e-5, 1e-6), "verlet": (1e-4, 1e-5, 1e-6), "rk4": (1e-4, 1e-5, 2e-6)},
}
PDW_ADAPTIVE = {
    "dopri5": (1e-4, 1e-6, 1e-8),
    "rodas4": (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11),
}
SCIPY = {
    "LSODA": (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-10),
    "Radau": (1e-4, 1e-5, 1e-6, 1e-8),
    "DOP853": (1e-6,),             # explicit: ~28 s per simulated second (stance-limited steps)
}
DOP853_T_END = 1.0                 # ... so it runs the first second of the typical gait only
ATOL_FACTOR = 1e-2                 # atol = 1e-2 rtol everywhere


# ---------------------------------------------------------------------------------- runs

def run_pdw(prob, method, t_end, **kw):
    kw.setdefault("dt", 1e-4 if method != "dopri5" else 1e-5)
    if "rtol" in kw:                 # the default event_tol, 1e-9 s, would floor the tight runs
        kw.setdefault("event_tol", min(1e-9, kw["rtol"]))
    r = pdw.simulate(x0=prob["x0"], t_end=t_end, params=prob["params"], variant=prob["variant"],
                     method=method, integrator=pdw.Integrator(**kw),
                     record=pdw.Record(every=0, forces=False), limits=pdw.Limits(on_failure="return"))
    return dict(x=r.x_final, events=r.events, status=r.status, t_final=r.t_final,
                rhs=r.stats["rhs"], jac=r.stats["jacobians"], steps=r.stats["steps"],
                rejected=r.stats["rejected"])


def run_scipy(prob, method, t_end, rtol, atol):
    r = simulate_scipy(method, x0=prob["x0"], t_end=t_end, params=prob["params"],
                       variant=prob["variant"], rtol=rtol, atol=atol)
    return dict(x=r.x_final, events=r.events, status=r.status, t_final=r.t_final,
                rhs=r.stats["rhs"], jac=r.stats["jacobians"], steps=r.stats["steps"],
                rejected=-1)


def clock(fn):
    """(wall [s], CPU time of this process [s], result) of one call."""
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - w0, time.process_time() - c0, out


def repeats(first_wall, quick):
    """How many runs a configuration gets in all (its first included), by its first run."""
    plan = ((0.02, 25), (0.05, 15), (0.3, 7), (1.5, 3)) if not quick else ((0.05, 5), (0.3, 3))
    for limit, n in plan:
        if first_wall <= limit:
            return n
    return 1


# ---------------------------------------------------------------------------------- errors

def q_error(x, ref):
    return float(np.abs(np.asarray(x)[:4] - ref[:4]).max())


def event_error(events, ref_events):
    if len(events) != len(ref_events) or any((a.leg, a.kind) != (b.leg, b.kind)
                                             for a, b in zip(events, ref_events)):
        return math.nan
    return float(max(abs(a.t - b.t) for a, b in zip(events, ref_events)))


def step_errors(events, ref_steps):
    s = pdw.steps(events)
    if len(s) != len(ref_steps):
        return math.nan, math.nan
    sl = slice(-LAST_STEPS, None)
    return (float(np.abs(s["P"][sl] - ref_steps["P"][sl]).max()),
            float(np.abs(s["L"][sl] - ref_steps["L"][sl]).max()))


# ---------------------------------------------------------------------------------- study

def reference(name, prob, rows, log):
    """Reference runs of one problem, and their cross-checks (rows of the CSV)."""
    m, kw = REF
    ref = {"end": run_pdw(prob, m, prob["t_end"], **kw)}
    if "t_mid" in prob:
        ref["mid"] = run_pdw(prob, m, prob["t_mid"], **kw)
    ref["steps"] = pdw.steps(ref["end"]["events"])
    assert ref["end"]["status"] == "walked", ref["end"]["status"]
    log.append("%s: reference %s %s: %d events, %d f evaluations" % (
        name, m, _setting(kw), len(ref["end"]["events"]), ref["end"]["rhs"]))
    for cm, ckw in CROSS:
        t0 = time.perf_counter()
        end = run_pdw(prob, cm, prob["t_end"], **ckw)
        wall = time.perf_counter() - t0
        row = _row(name, "reference", cm, ckw, end, ref, wall, 1)
        if "t_mid" in prob:
            row["err_q_mid"] = q_error(run_pdw(prob, cm, prob["t_mid"], **ckw)["x"], ref["mid"]["x"])
        rows.append(row)
        log.append("  cross-check %-7s %-40s |dq(%g s)| %.1e  |dq(%g s)| %s  events %.1e s  P %.1e s  L %.1e m"
                   % (cm, _setting(ckw), prob.get("t_mid", math.nan), row.get("err_q_mid", math.nan),
                      prob["t_end"], "%.1e" % row["err_q"], row["err_events"], row["err_P"], row["err_L"]))
    return ref


def _setting(kw):
    return ", ".join("%s=%g" % (k, v) for k, v in kw.items() if k not in ("event_tol",) and
                     not (k == "dt" and "rtol" in kw))


def _row(problem, kind, method, kw, out, ref, wall, n):
    row = dict(problem=problem, kind=kind, method=method, setting=_setting(kw),
               param=("dt" if "rtol" not in kw else "rtol"),
               value=kw.get("rtol", kw.get("dt")), t_end=out["t_final"], status=out["status"],
               wall_ms=1e3 * wall, repeats=n, rhs=out["rhs"], jacobians=out["jac"], steps=out["steps"],
               rejected=out["rejected"], err_q_mid=math.nan, wall_mid_ms=math.nan, err_q=math.nan,
               err_events=math.nan, err_P=math.nan, err_L=math.nan, cpu_ms=math.nan,
               cpu_mid_ms=math.nan)
    if out["status"] != "walked" or abs(out["t_final"] - ref["end"]["t_final"]) > 1e-9:
        return row
    row["err_q"] = q_error(out["x"], ref["end"]["x"])
    row["err_events"] = event_error(out["events"], ref["end"]["events"])
    row["err_P"], row["err_L"] = step_errors(out["events"], ref["steps"])
    return row


def configs(name, quick):
    out = []
    for m, dts in PDW_FIXED[name].items():
        for dt in (dts[:2] if quick else dts):
            out.append(("pdw", m, dict(dt=dt)))
    for m, rtols in PDW_ADAPTIVE.items():
        for rt in (rtols[::3] if quick else rtols):
            out.append(("pdw", m, dict(rtol=rt, atol=ATOL_FACTOR * rt)))
    for m, rtols in SCIPY.items():
        if m == "DOP853" and (quick or name != "typical"):
            continue
        for rt in (rtols[::2] if quick else rtols):
            out.append(("scipy", m, dict(rtol=rt, atol=ATOL_FACTOR * rt)))
    return out


class Job:
    """One timed configuration: a method, its setting, a problem and an end time."""

    def __init__(self, name, prob, kind, method, kw, t_end):
        self.name, self.prob, self.kind, self.method, self.kw, self.t_end = (
            name, prob, kind, method, kw, t_end)
        self.walls, self.cpus, self.out = [], [], None

    def run(self):
        runner = run_pdw if self.kind == "pdw" else run_scipy
        w, c, out = clock(lambda: runner(self.prob, self.method, self.t_end, **self.kw))
        self.walls.append(w)
        self.cpus.append(c)
        if self.out is None:
            self.out = out


def study(problems, rows, log, quick):
    """Every configuration once (results, errors), then further runs in rounds over all of
    them, so that the load of a shared machine spreads evenly over the methods; wall time =
    median of each configuration's runs."""
    jobs, refs = [], {}
    for name, prob in problems.items():
        print("== %s" % name, flush=True)
        refs[name] = reference(name, prob, rows, log)
        for kind, m, kw in configs(name, quick):
            end = None if m == "DOP853" else Job(name, prob, kind, m, kw, prob["t_end"])
            mid = Job(name, prob, kind, m, kw, prob["t_mid"]) if "t_mid" in prob else None
            for j in (end, mid):
                if j is not None:
                    j.run()
                    jobs.append(j)
            print("  %-6s %-7s %-24s first run %9.2f ms" % (
                kind, m, _setting(kw), 1e3 * (end or mid).walls[0]), flush=True)
            rows.append(dict(_job=(end, mid)))
    rounds = max(repeats(j.walls[0], quick) for j in jobs)
    for k in range(2, rounds + 1):
        print("== round %d of %d" % (k, rounds), flush=True)
        for j in jobs:
            if repeats(j.walls[0], quick) >= k:
                j.run()
    for i, row in enumerate(rows):
        if "_job" not in row:
            continue
        end, mid = row["_job"]
        j = end or mid
        ref = refs[j.name]
        if end is not None:
            new = _row(j.name, j.kind, j.method, j.kw, end.out, ref,
                       statistics.median(end.walls), len(end.walls))
            new["cpu_ms"] = 1e3 * statistics.median(end.cpus)
        else:                                   # DOP853: the first second only
            new = _row(j.name, j.kind, j.method, j.kw, dict(status="1 s only", t_final=mid.t_end,
                       rhs=mid.out["rhs"], jac=mid.out["jac"], steps=mid.out["steps"], rejected=-1),
                       ref, math.nan, len(mid.walls))
        if mid is not None:
            new["wall_mid_ms"] = 1e3 * statistics.median(mid.walls)
            new["cpu_mid_ms"] = 1e3 * statistics.median(mid.cpus)
            if mid.out["status"] == "walked":
                new["err_q_mid"] = q_error(mid.out["x"], ref["mid"]["x"])
        rows[i] = new
        log.append("  %-7s %-6s %-7s %-24s %9.2f ms (%d) %9d f  |dq(1s)| %8.1e  |dq(end)| %8.1e  "
                   "events %8.1e  P %8.1e  L %8.1e  %s"
                   % (new["problem"], new["kind"], new["method"], new["setting"], new["wall_ms"],
                      new["repeats"], new["rhs"], new["err_q_mid"], new["err_q"],
                      new["err_events"], new["err_P"], new["err_L"], new["status"]))


# ---------------------------------------------------------------------------------- headline

def time_to_error(rows, err_key, wall_key, target):
    """Wall time at which a method's curve (rows ordered loose -> tight) reaches ``target``:
    log-log interpolation between the last point above and the first at or below it;
    ("measured" | "interpolated" | "extrapolated", ms)."""
    pts = [(r[err_key], r[wall_key]) for r in rows
           if math.isfinite(r[err_key]) and math.isfinite(r[wall_key]) and r[err_key] > 0]
    if not pts:
        return None, math.nan
    for k, (e, w) in enumerate(pts):
        if e <= target:
            if k == 0:
                return "measured (first point already below)", w
            (e0, w0) = pts[k - 1]
            s = (math.log(target) - math.log(e0)) / (math.log(e) - math.log(e0))
            return "interpolated", math.exp(math.log(w0) + s * (math.log(w) - math.log(w0)))
    if len(pts) < 2:
        return None, math.nan
    (e0, w0), (e1, w1) = pts[-2], pts[-1]
    if not e1 < e0:
        return None, math.nan
    s = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
    return "extrapolated", math.exp(math.log(w0) + s * (math.log(w1) - math.log(w0)))


def headline(rows):
    typ = [r for r in rows if r["problem"] == "typical" and r["kind"] != "reference"]
    by = {}
    for r in typ:
        by.setdefault((r["kind"], r["method"]), []).append(r)
    lines = []
    for err_key, wall_key, label in (("err_q", "wall_ms", "wall time to reach |dq(3.5 s)|"),
                                     ("err_q", "cpu_ms", "CPU time to reach |dq(3.5 s)|"),
                                     ("err_q_mid", "wall_mid_ms", "wall time to reach |dq(1 s)|")):
        res = {key: time_to_error(rs, err_key, wall_key, TARGET) for key, rs in by.items()}
        lines += ["", "headline: %s = %.0e on the typical gait" % (label, TARGET)]
        order = sorted(res.items(), key=lambda kv: kv[1][1] if math.isfinite(kv[1][1]) else 1e99)
        for (kind, m), (how, ms) in order:
            if math.isfinite(ms):
                lines.append("  %-6s %-7s %10.1f ms  (%s)" % (kind, m, ms, how))
        best_ms, best = min((ms, m) for (kind, m), (how, ms) in res.items()
                            if kind == "pdw" and math.isfinite(ms))
        lines.append("  best pdw method: %s, %.1f ms; slower by:" % (best, best_ms))
        for (kind, m), (how, ms) in order:
            if math.isfinite(ms) and m != best:
                lines.append("    %-6s %-7s %7.0fx  (%s)" % (kind, m, ms / best_ms, how))
        for m in ("cdm", "verlet", "rk4"):             # fixed step: the finest step measured
            r = min(by[("pdw", m)], key=lambda r: r["value"])
            lines.append("    %s at dt = %g, the finest measured: %.0f ms for %.1e (%.0fx the time "
                         "of %s at %.0e, at %.0fx its error)"
                         % (m, r["value"], r[wall_key], r[err_key], r[wall_key] / best_ms, best,
                            TARGET, r[err_key] / TARGET))
    return lines


# ---------------------------------------------------------------------------------- output

COLUMNS = ("problem", "kind", "method", "setting", "param", "value", "t_end", "status", "wall_ms",
           "cpu_ms", "repeats", "rhs", "jacobians", "steps", "rejected", "wall_mid_ms", "cpu_mid_ms",
           "err_q_mid", "err_q", "err_events", "err_P", "err_L")


def write_csv(rows):
    RESULTS.mkdir(parents=True, exist_ok=True)
    with open(CSV, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: ("%.4g" % r[k] if isinstance(r[k], float) else r[k]) for k in COLUMNS})


STYLE = {"cdm": ("#7f7f7f", "s"), "verlet": ("#bcbd22", "v"), "rk4": ("#17becf", "^"),
         "dopri5": ("#1f77b4", "D"), "rodas4": ("#d62728", "o"),
         "LSODA": ("#2ca02c", "P"), "Radau": ("#9467bd", "X"), "DOP853": ("#8c564b", "*")}


def figure(rows, machine):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    panels = [("typical", "wall_mid_ms", "err_q_mid", "wall time to 1 s [ms]",
               "error of q at 1 s", "typical gait (paper), first 1 s"),
              ("typical", "wall_ms", "err_q", "wall time [ms]", "error of q at 3.5 s",
               "typical gait (paper), 3.5 s"),
              ("typical", "rhs", "err_q", "f evaluations", "error of q at 3.5 s",
               "typical gait (paper), 3.5 s"),
              ("steady", "wall_ms", "err_P", "wall time [ms]", "error of step period P [s]",
               "steady gait (paper_steady), 8 s, last %d steps" % LAST_STEPS),
              ("steady", "wall_ms", "err_L", "wall time [ms]", "error of step length L [m]",
               "steady gait (paper_steady), 8 s, last %d steps" % LAST_STEPS),
              ("steady", "rhs", "err_P", "f evaluations", "error of step period P [s]",
               "steady gait (paper_steady), 8 s, last %d steps" % LAST_STEPS)]
    fig, axes = plt.subplots(2, 3, figsize=(16, 9.5))
    for ax, (prob, xk, yk, xl, yl, title) in zip(axes.flat, panels):
        for m, (col, mk) in STYLE.items():
            rs = [r for r in rows if r["problem"] == prob and r["method"] == m and r["kind"] != "reference"
                  and math.isfinite(float(r[yk])) and float(r[xk]) > 0 and math.isfinite(float(r[xk]))]
            if not rs:
                continue
            kind = rs[0]["kind"]
            xs = [float(r[xk]) for r in rs]
            ys = [max(float(r[yk]), 1e-13) for r in rs]
            ax.loglog(xs, ys, marker=mk, color=col, ls="-" if kind == "pdw" else "--", lw=1.6,
                      ms=7 if mk != "*" else 11, label=("pdw " if kind == "pdw" else "scipy ") + m
                      + (" (first 1 s only)" if m == "DOP853" else ""))
        if yk in ("err_q", "err_q_mid"):
            ax.axhline(TARGET, color="k", lw=0.8, ls=":")
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="major", alpha=0.4)
        ax.grid(True, which="minor", alpha=0.12)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.945), ncol=8,
               fontsize=9, frameon=False)
    fig.suptitle("Work-precision of the walker (solid: pdw's compiled integrators; dashed: scipy "
                 "solve_ivp on the same compiled f and Jacobian)\nreference rodas4 rtol 1e-12; "
                 "wall times are medians in one run on %s" % machine, fontsize=11)
    fig.tight_layout(rect=(0, 0, 1, 0.925))
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer points, no DOP853 (smoke test)")
    ap.add_argument("--replot", action="store_true", help="only redraw the figure from the CSV")
    args = ap.parse_args(argv)
    machine = "%s, Python %s" % (platform.machine(), platform.python_version())
    if args.replot:
        with open(CSV) as fh:
            figure(list(csv.DictReader(fh)), machine)
        return 0
    t0 = time.perf_counter()
    rows, log = [], []
    study(PROBLEMS, rows, log, args.quick)
    write_csv(rows)
    figure(rows, machine)
    lines = log + headline(rows)
    lines.append("total %.0f s; wrote %s and %s" % (time.perf_counter() - t0, CSV.relative_to(ROOT),
                                                    FIGURE.relative_to(ROOT)))
    print("\n".join(lines))


if __name__ == "__main__":
    sys.exit(main())
