"""Wall time of the default model's runs, for comparing two builds (interleave the processes).

Prints, for the pdw on sys.path: the best of 30 paper runs (cdm, dt 1e-4, 3.5 s, nothing
recorded), the best of 8 rodas4 runs of `paper_steady` (rtol 1e-8, atol 1e-10, 3.5 s) and the
best of 3 rk4 runs of `paper_steady` (dt 2e-5), in seconds, then the 1-minute load average.

Usage, old build vs this one, interleaved (docs/contact_laws.md):
    for i in 1 2 3 4 5 6; do PYTHONPATH=/path/to/old .venv/bin/python benchmarks/default_speed.py;
                             .venv/bin/python benchmarks/default_speed.py; done
"""
import os
import time

import pdw


def best(f, n):
    b = float("inf")
    for _ in range(n):
        t0 = time.perf_counter()
        f()
        b = min(b, time.perf_counter() - t0)
    return b


if __name__ == "__main__":
    pdw.simulate(t_end=0.1)
    P = pdw.Params.paper_steady()
    a = best(lambda: pdw.simulate(record=pdw.Record(every=0)), 30)
    b = best(lambda: pdw.simulate(params=P, method="rodas4",
                                  integrator=pdw.Integrator(rtol=1e-8, atol=1e-10),
                                  record=pdw.Record(every=0)), 8)
    c = best(lambda: pdw.simulate(params=P, method="rk4", dt=2e-5,
                                  integrator=pdw.Integrator(check_step="off"),
                                  record=pdw.Record(every=0)), 3)
    print("%s paper cdm %.4f s  rodas4 %.4f s  rk4 %.4f s  load %.2f"
          % (pdw.__file__, a, b, c, os.getloadavg()[0]))
