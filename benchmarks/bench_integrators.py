"""Work-precision table of docs/integrators.md: the typical gait (simulate() defaults: x0 =
X0_PAPER, 3.5 s, variant paper), error vs a RODAS4 run at rtol 1e-12 (event_tol 1e-12)."""
import time

import numpy as np

from pdw.sim.options import Integrator, Record
from pdw.sim.simulation import simulate


def best(f, n):
    ts=[]
    for _ in range(n):
        t = time.perf_counter()
        r = f()
        ts.append(time.perf_counter() - t)
    return r, min(ts)
ref = simulate(method="rodas4", integrator=Integrator(rtol=1e-12, atol=1e-14, event_tol=1e-12),
               record=Record(every=0))
evr = np.array([e.t for e in ref.events])
runs = [("cdm", dict(dt=1e-4)), ("cdm", dict(dt=1e-6)), ("verlet", dict(dt=1e-6)), ("rk4", dict(dt=1e-6)),
        ("dopri5", dict(dt=1e-5, rtol=1e-6, atol=1e-8)), ("dopri5", dict(dt=1e-5, rtol=1e-9, atol=1e-11))] + \
       [("rodas4", dict(rtol=rt, atol=rt*1e-2)) for rt in (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)]
print("| method | options | wall [ms] | f evals | Jacobians | steps (rejected) | max error q(3.5 s) | max error event times [s] |")
print("|---|---|---|---|---|---|---|---|")
for m, kw in runs:
    n = 7 if m == "rodas4" or kw.get("dt", 0) >= 1e-4 else 2
    r, w = best(lambda m=m, kw=kw: simulate(method=m, integrator=Integrator(**kw),
                                            record=Record(every=0)), n)
    ev = np.array([e.t for e in r.events])
    eve = "%.1e" % np.abs(ev-evr).max() if len(ev)==len(evr) else "n/a"
    st = r.stats
    print("| %s | %s | %.1f | %d | %d | %d (%d) | %.1e | %s |" % (m, ", ".join("%s=%g" % kv for kv in kw.items()), w*1e3,
          st["rhs"], st["jacobians"], st["steps"], st["rejected"], np.abs(r.x_final[:4]-ref.x_final[:4]).max(), eve))
