"""The rigid-ground limit of each dissipative normal law (issue 12; docs/contact_laws.md).

The hybrid model's heel strike is perfectly inelastic (docs/model.md section 9); a compliant law
approaches it only if, as the ground stiffens, its impact restitution goes to 0. The scaling:

* hunt_crossley: d_n = d_n0 (k/k0)^(4/3), which keeps the linearised damping ratio at the
  static sink fixed (benchmarks/rigid_limit.py) -- its drop-test restitution at the typical
  landing then falls as k grows;
* kelvin_voigt and flores: matched to Hunt-Crossley at every k exactly as `pdw.calibration`
  does at k0 (same static sink, same drop-test restitution at the typical landing);
* lankarani_nikravesh: the same stiffness and its most dissipative setting (e = 0.01): it
  cannot go below a restitution of about 2/3, so it is not expected to converge.

Each law at each k: the consistent variant (the hybrid model's contact kinematics), rodas4
(rtol 1e-9), from the previous k's final touch-down state, until the last 4 steps agree to
1e-5 (or 16 s): the steady cycle (touch-down to touch-down), step length and double support,
against the hybrid gait; the rate is the log-log slope over the last three k.

Usage: .venv/bin/python benchmarks/contact_rigid_limit.py   (a few minutes)
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
from pdw import hybrid as H  # noqa: E402
from pdw.analysis.numerics.calibration import _bisect, drop_test, typical_landing  # noqa: E402
from pdw.core.contact import Contact  # noqa: E402

P0 = pdw.Params.paper_steady()
K = (1e5, 1e6, 1e7, 1e8)
LAWS = ("hunt_crossley", "kelvin_voigt", "flores", "lankarani_nikravesh")


def contacts_at(k, landing):
    """Every law's Contact at stiffness k (Hunt-Crossley scaled, the others matched to it)."""
    P = P0.replace(k_n=k, d_n=P0.d_n * (k / P0.k_n) ** (4 / 3))
    v, m = landing.speed, landing.mass
    e_of = lambda c: drop_test(c, P, v_in=v, mass=m).e  # noqa: E731
    hc = Contact("hunt_crossley", k=k, d=P.d_n)
    e_t = e_of(hc)
    sink = (P.weight / k) ** (2 / 3)
    kv_k = P.weight / sink
    d = _bisect(lambda x: e_of(Contact("kelvin_voigt", k=kv_k, d=x)), 1e-2, 1e7, e_t, log=True)
    e_f = _bisect(lambda x: e_of(Contact("flores", k=k, e=x)), 1e-3, 1.0, e_t)
    out = {"hunt_crossley": hc,
           "kelvin_voigt": Contact("kelvin_voigt", k=kv_k, d=d) if d else None,
           "flores": Contact("flores", k=k, e=e_f) if e_f else None,
           "lankarani_nikravesh": Contact("lankarani_nikravesh", k=k, e=0.01)}
    return P, e_t, out, {law: (e_of(c) if c else math.nan) for law, c in out.items()}


def main():
    t_start = time.perf_counter()
    gh = H.find_gait(P0)
    landing = typical_landing(P0, "consistent")
    lines = ["# rigid-ground limit per normal law (benchmarks/contact_rigid_limit.py)",
             "load average: %s" % (os.getloadavg(),),
             "hybrid gait: period %.6f s, L %.6f m; landing (consistent, HC at k0): %.4f m/s, "
             "%.3f kg" % (gh.period, gh.step_length, landing.speed, landing.mass), "",
             "| law | k | parameters | drop e | status | cycle [s] | L [m] | DS [ms] | "
             "cycle - hybrid [s] | L - hybrid [m] |", "|" + "---|" * 10]
    res = {law: [] for law in LAWS}
    state = {law: (pdw.X0_PAPER, (0, 1)) for law in LAWS}
    for k in K:
        P, e_t, cs, e_drop = contacts_at(k, landing)
        for law in LAWS:
            c = cs[law]
            if c is None:
                lines.append("| %s | %.0e | (restitution %.3g not reachable) | | | | | | | |"
                             % (law, k, e_t))
                continue
            x0, f0 = state[law]
            r = pdw.simulate(x0, params=P, variant="consistent", contact=c, t_end=16.0,
                             method="rodas4", integrator=pdw.Integrator(rtol=1e-9, atol=1e-11),
                             record=pdw.Record(every=0),
                             stop=pdw.Stop(periodic=True, periodic_steps=4, periodic_tol=1e-5),
                             limits=pdw.Limits(on_failure="return"), flags0=f0)
            prm = ", ".join("%s=%.4g" % (n, v) for n, v in c.as_dict().items()
                            if n not in ("normal", "friction"))
            if r.n_gait_steps < 4 or not r.walked:
                lines.append("| %s | %.0e | %s | %.3f | %s | | | | | |" % (law, k, prm, e_drop[law],
                                                                        r.status))
                continue
            st = r.gait.steady(4)
            res[law].append((k, st["cycle"], st["L"], st["double_support"]))
            state[law] = (r.x_final, (1, 1))
            lines.append("| %s | %.0e | %s | %.3f | %s | %.6f | %.6f | %.2f | %+.2e | %+.2e |" % (
                law, k, prm, e_drop[law], r.stop_reason, st["cycle"], st["L"],
                1e3 * st["double_support"], st["cycle"] - gh.period, st["L"] - gh.step_length))
    lines.append("")
    for law, rows in res.items():
        if len(rows) < 3:
            lines.append("%s: fewer than 3 stiffnesses walked, no rate" % law)
            continue
        k = np.log([r[0] for r in rows[-3:]])
        for name, i, ref in (("cycle", 1, gh.period), ("L", 2, gh.step_length), ("DS", 3, 0.0)):
            y = np.abs([r[i] - ref for r in rows[-3:]])
            slope = np.polyfit(k, np.log(y), 1)[0] if np.all(y > 0) else math.nan
            lines.append("%s, last three k: |%s - hybrid| ~ k^%.2f" % (law, name, slope))
    lines.append("total %.0f s" % (time.perf_counter() - t_start))
    publish("contact_rigid_limit.txt", lines)


if __name__ == "__main__":
    main()
