"""Which ground model? The calibrated normal laws compared on the `paper_steady` walker
(issue 12; docs/contact_laws.md).

LuGre friction (on the Hunt-Crossley ground) gets its Stribeck curve matched to Eq. 10 and
critically damped bristles (`pdw.calibration.calibrate_lugre`); its chatter is measured at the
cdm step limit when cdm does not walk at the paper's step. Its rodas4 Jacobian is a central
difference of f (21 right-hand sides, counted as one Jacobian).

Every law gets parameters matched to the paper's Hunt-Crossley ground (`pdw.calibration.calibrate`:
the same static sink under the weight, the same drop-test restitution of a foot landing at the
typical touch-down speed). For each law, from the paper's start:

* gait: rodas4 (rtol 1e-8, atol 1e-10), 8 s, the mean of the last 4 steps: L, P, v, double
  support;
* stance forces: the same run every accepted step recorded (h_max 2e-4 s): the peak normal force
  of the last complete stance, and the settled one (the median over its single support);
* friction chatter under cdm (dt = 1e-4, the paper's step): over the single supports after the
  first 2 s, the fraction of steps with the stance foot's |v_x| > v_s and the fraction of steps
  where v_x changes sign;
* the cdm step-size limit: the largest dt (half-decade scan from 1e-5, then 4 log-bisections)
  at which a 3.5 s cdm run walks with the reference's touch-downs (`pdw.stability.judge`);
* rodas4 cost at 1e-6 error: rtol 1e-3 ... 1e-10 (atol = rtol/100), 3.5 s, the final-state error
  (max norm) against rtol 1e-11; right-hand sides + Jacobians, interpolated (log-log) at 1e-6.

Writes benchmarks/results/contact_laws.txt and docs/figures/contact_laws_stance.png.
Usage: .venv/bin/python benchmarks/contact_laws.py   (a few minutes)
"""
import math
import os
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
from _results import publish  # noqa: E402

import pdw  # noqa: E402
from pdw.analysis.numerics import stability_maps as S  # noqa: E402
from pdw.analysis.numerics.calibration import calibrate, calibrate_lugre  # noqa: E402

P = pdw.Params.paper_steady()
FIG = ROOT / "docs" / "figures" / "contact_laws_stance.png"


def sim(contact, *, rtol=1e-6, atol=1e-8, h_max=None, record_every=1, record_forces=True, **kw):
    """`pdw.simulate` at P under ``contact``, a divergence returned, no step-size check; the
    tolerances and recording as fields of pdw.Integrator and pdw.Record (their defaults)."""
    return pdw.simulate(params=P, contact=contact,
                        integrator=pdw.Integrator(rtol=rtol, atol=atol, h_max=h_max,
                                                  check_step="off"),
                        record=pdw.Record(every=record_every, forces=record_forces),
                        limits=pdw.Limits(on_failure="return"), **kw)


def gait_and_forces(contact):
    r = sim(contact, t_end=8.0, method="rodas4", rtol=1e-8, atol=1e-10, h_max=2e-4,
            record_every=1)
    out = {"status": r.status}
    if r.n_gait_steps < 4:
        return out, r, None
    out.update(r.gait.steady(4))
    td = [e for e in r.events if e.kind == "touch_down"]
    lo = [e for e in r.events if e.kind == "lift_off"]
    # the last complete stance: a touch-down followed by the same leg's lift-off
    for ev in reversed(td):
        end = [e for e in lo if e.leg == ev.leg and e.t > ev.t]
        if end:
            t0, t1, j = ev.t, end[0].t, ev.leg - 1
            break
    m = (r.t >= t0) & (r.t <= t1)
    single = m & (r.flags[:, 1 - j] == 0)
    out["F_peak"] = float(np.max(r.Fn[m, j]))
    out["F_settled"] = float(np.median(r.Fn[single, j]))
    stance = (r.t[m] - t0, r.Fn[m, j], r.Ft[m, j])
    return out, r, stance


def chatter_cdm(contact, dt=1e-4):
    r = sim(contact, t_end=6.0, method="cdm", dt=dt, record_every=1, record_forces=False)
    if r.status != "walked":
        return math.nan, math.nan
    v = []
    for j in range(2):
        m = (r.flags[:, j] == 1) & (r.flags[:, 1 - j] == 0) & (r.t > 2.0)
        if m.any():
            cs = pdw.contact_forces(r.x[m][:, :len(pdw.STATE)], P, flags=(1, 1))
            v.append(cs.v_x[:, j])
    if not v:
        return math.nan, math.nan
    v = np.concatenate(v)
    s = np.sign(v)
    return float(np.mean(np.abs(v) > P.v_s)), float(np.mean(s[1:] != s[:-1]))


def cdm_limit(contact):
    ref = sim(contact, t_end=3.5, method="rodas4", rtol=1e-9, atol=1e-11, record_every=0)

    def ok(dt):
        return _walks(sim(contact, t_end=3.5, method="cdm", dt=dt, record_every=0), ref)

    return S.edge_on_grid(ok, [1e-5 * 10 ** (k / 2) for k in range(0, 9)])


def _walks(r, ref):
    """Walks with the reference's touch-downs (count, legs, times within 1 % of a cycle)."""
    tr = [(e.t, e.leg) for e in ref.events if e.kind == "touch_down"]
    tm = [(e.t, e.leg) for e in r.events if e.kind == "touch_down"]
    if r.status != "walked" or [g for _, g in tm] != [g for _, g in tr]:
        return False
    cyc = np.mean(np.diff([t for t, _ in tr])) if len(tr) > 1 else 0.6
    return max((abs(a - b) for (a, _), (b, _) in zip(tm, tr)), default=0.0) <= \
        max(S.TD_TOL_ABS, S.TD_TOL_REL * cyc)


def rodas_cost(contact, target=1e-6):
    ref = sim(contact, t_end=3.5, method="rodas4", rtol=1e-11, atol=1e-13, record_every=0)
    rows = []
    for k in range(3, 11):
        rtol = 10.0 ** -k
        t0 = time.perf_counter()
        r = sim(contact, t_end=3.5, method="rodas4", rtol=rtol, atol=rtol / 100, record_every=0)
        wall = time.perf_counter() - t0
        if r.status != "walked":
            continue
        err = float(np.max(np.abs(r.x_final - ref.x_final)))
        rows.append((err, r.stats["rhs"] + r.stats["jacobians"], wall))
    rows.sort()
    for i in range(len(rows) - 1):
        (e0, c0, w0), (e1, c1, w1) = rows[i], rows[i + 1]
        if e0 <= target <= e1 and e0 > 0:
            f = math.log(target / e0) / math.log(e1 / e0)
            return c0 * (c1 / c0) ** f, w0 * (w1 / w0) ** f
    return math.nan, math.nan


def main():
    t_start = time.perf_counter()
    cal = calibrate(P)
    lines = ["# calibrated contact laws on paper_steady (benchmarks/contact_laws.py)",
             "load average: %s" % (os.getloadavg(),),
             "typical landing: speed %.4f m/s, effective mass %.4f kg (median of %d touch-downs)"
             % (cal.landing.speed, cal.landing.mass, cal.landing.n),
             "weight %.3f N, static sink %.3f mm, target restitution e = %.4f"
             % (cal.weight, 1e3 * cal.sink["hunt_crossley"], cal.e_target), ""]
    for law, c in cal.contacts.items():
        lines.append("%-20s %-60s drop e = %.4f%s" % (law, c.as_dict(), cal.e_drop[law],
                                                     "" if cal.reachable[law] else " (target not reachable)"))
    lg = calibrate_lugre(P)
    lines.append("%-20s %s; tangential effective mass %.4f kg, bristle frequency %.0f rad/s, "
                 "presliding %.2g m" % ("lugre", lg.contact.as_dict(), lg.mass, lg.omega,
                                        lg.presliding))
    contacts = dict(cal.contacts, lugre=lg.contact)
    lines.append("")
    head = ("| law | status | L [m] | P [s] | v [m/s] | DS [ms] | DS [%] | F_n peak [N] | "
            "F_n settled [N] | cdm slip frac | cdm sign flips | cdm dt limit [s] | "
            "rodas4 evals @1e-6 | rodas4 ms @1e-6 |")
    lines += [head, "|" + "---|" * 14]
    stances = {}
    for law, c in contacts.items():
        g, r, stance = gait_and_forces(c)
        stances[law] = stance
        lim = cdm_limit(c)
        slip, flips = chatter_cdm(c)
        if math.isnan(slip) and lim[0]:
            slip, flips = chatter_cdm(c, lim[0])
            law += " (chatter at dt = %.3g)" % lim[0]
        cost, wall = rodas_cost(c)
        f = lambda k, s=1.0, fmt="%.4f", g=g: fmt % (g[k] * s) if k in g else "—"  # noqa: E731
        lines.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %.3f | %.3f | %s | %.0f | %.1f |" % (
            law, g["status"], f("L"), f("P"), f("v"), f("double_support", 1e3, "%.1f"),
            f("ds_fraction", 100, "%.2f"), f("F_peak", 1, "%.1f"), f("F_settled", 1, "%.2f"),
            slip, flips, "%.3g" % lim[0] if lim[0] else "< 1e-5", cost, 1e3 * wall))
    lines.append("")
    lines.append("total %.0f s" % (time.perf_counter() - t_start))
    publish("contact_laws.txt", lines)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True)
    for law, st in stances.items():
        if st is None:
            continue
        t, fn, ft = st
        style = dict(lw=3.5, alpha=0.45) if law == "hunt_crossley" else dict(lw=1.2)
        ax[0].plot(t, fn, label=law, **style)
        ax[1].plot(t, ft, label=law, **style)
    ax[0].axhline(cal.weight, color="k", lw=0.6, ls=":")
    ax[0].set_ylabel("normal force F_n [N]")
    ax[1].set_ylabel("tangential force F_t [N]")
    ax[1].set_xlabel("time since touch-down [s]")
    ax[0].legend(fontsize=8)
    ax[0].set_title("stance forces of the last complete stance, calibrated laws (paper_steady)")
    fig.tight_layout()
    FIG.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIG, dpi=110)
    print("wrote", FIG)


if __name__ == "__main__":
    main()
