"""Instruction counts of the jobs users pay for, under valgrind's callgrind (issue 23): a guard
that a loaded or noisy machine cannot fool, because callgrind counts the same instructions for
the same binaries and inputs whatever else the machine does.

Regions (each counted alone; the import of pdw and numpy and each region's warm-up are not):

* ``paper_run``           the paper's typical gait, `pdw.simulate(record=Record(every=0))` (warm)
* ``paper_run_recorded``  the same with full recording (``Record(every=1)``, warm)
* ``first_call``          the first `pdw.simulate()` of a fresh process after ``import pdw``:
                          the default step-size check included
* ``batch_cdm_64``        `pdw.simulate_batch` of 64 walkers, 0.5 s, cdm (one thread)
* ``batch_rodas4_64``     the same with rodas4
* ``find_gait``           `pdw.find_gait(Params.paper_steady())` (one worker)

How a region is counted: it runs inside ``contextvars.Context.run`` and callgrind collects only
inside that C function (``--collect-atstart=no --toggle-collect=context_run``), dumping after
each call (``--dump-after=context_run``), so every region has its own total.

Usage (from the project root; needs valgrind, else it says so in one line and exits 0)::

    python benchmarks/instructions.py            # count and compare with the baselines
    python benchmarks/instructions.py --update   # count and rewrite the baselines
                                                 # (`make instructions-baseline`; commit why)

The baselines (benchmarks/results/instructions.json) record the versions the counts depend on:
the compiler, glibc (libm), Python, NumPy, valgrind, the machine and its vector ISA. On another
set of versions the comparison says so in one line and is skipped; a region that grew by more
than MARGIN fails (exit 1), printing the old and new counts.
"""
from __future__ import annotations

import argparse
import contextvars
import glob
import json
import os
import pathlib
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
BASELINE = ROOT / "benchmarks" / "results" / "instructions.json"
#: Relative growth of a region's count that fails the guard (counts of one binary are exact;
#: the margin absorbs the few addresses and environment sizes that differ between processes).
MARGIN = 0.03
WARM = ("paper_run", "paper_run_recorded", "batch_cdm_64", "batch_rodas4_64", "find_gait")
FRESH = ("first_call",)
REGIONS = FRESH + WARM


# --- inside valgrind ------------------------------------------------------------------------

def _counted(fn):
    """Run fn inside Context.run: the one call callgrind collects (and dumps after)."""
    return contextvars.copy_context().run(fn)


def _child(which):
    sys.path.insert(0, str(ROOT))       # this tree's pdw (a script's sys.path[0] is its folder)
    import numpy as np

    import pdw
    if which == "fresh":
        _counted(lambda: pdw.simulate())
        return
    P = pdw.Params.paper()
    X = pdw.X0_PAPER + 1e-3 * np.random.default_rng(1).standard_normal((64, len(pdw.STATE)))
    bare, full = pdw.Record(every=0), pdw.Record(every=1)        # made outside the regions
    pdw.simulate(params=P, record=bare)                          # warm-ups, not counted
    pdw.simulate(params=P, record=full)
    pdw.simulate_batch(X[:2], t_end=0.01, method="cdm", threads=1)
    pdw.simulate_batch(X[:2], t_end=0.01, method="rodas4", threads=1)
    jobs = {
        "paper_run": lambda: pdw.simulate(params=P, record=bare),
        "paper_run_recorded": lambda: pdw.simulate(params=P, record=full),
        "batch_cdm_64": lambda: pdw.simulate_batch(X, t_end=0.5, method="cdm", threads=1),
        "batch_rodas4_64": lambda: pdw.simulate_batch(X, t_end=0.5, method="rodas4", threads=1),
        "find_gait": lambda: pdw.find_gait(pdw.Params.paper_steady(), workers=1),
    }
    for name in WARM:
        _counted(jobs[name])


# --- the driver -----------------------------------------------------------------------------

def _first_line(cmd):
    try:
        out = subprocess.run(cmd, capture_output=True, text=True, check=False).stdout
    except OSError:
        return "unknown"
    return out.splitlines()[0].strip() if out.strip() else "unknown"


def environment():
    """What the counts depend on: versions of the toolchain and libraries, the machine."""
    import sysconfig

    import numpy as np
    cc = (sysconfig.get_config_var("CC") or "cc").split()[0]
    flags = ""
    try:
        with open("/proc/cpuinfo") as f:
            flags = next((line for line in f if line.startswith("flags")), "")
    except OSError:
        pass
    isa = [f for f in ("sse4_2", "avx", "avx2", "fma", "avx512f") if re.search(r"\b%s\b" % f, flags)]
    return {
        "compiler": _first_line([cc, "--version"]),
        "libc": " ".join(platform.libc_ver()),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "valgrind": _first_line(["valgrind", "--version"]),
        "machine": platform.machine(),
        "isa": " ".join(isa),
    }


def _totals(path):
    with open(path) as f:
        for line in f:
            if line.startswith(("totals:", "summary:")):
                return int(line.split()[1])
    raise RuntimeError("no totals in %s" % path)


def count(which):
    """{region: instructions} of one child process ("fresh" or "warm") under callgrind."""
    names = FRESH if which == "fresh" else WARM
    env = dict(os.environ, PYTHONHASHSEED="0", OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               MKL_NUM_THREADS="1", PYTHONDONTWRITEBYTECODE="1")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "cg.out")
        cmd = ["valgrind", "--tool=callgrind", "--collect-atstart=no",
               "--toggle-collect=context_run", "--dump-after=context_run",
               "--callgrind-out-file=" + out, sys.executable, os.path.abspath(__file__),
               "--child", which]
        r = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, check=False)
        if r.returncode != 0:
            raise RuntimeError("callgrind run failed (%d):\n%s" % (r.returncode, r.stderr[-3000:]))
        dumps = sorted(glob.glob(out + ".*"), key=lambda p: int(p.rsplit(".", 1)[1]))
        counts = [_totals(p) for p in dumps]
    if len(counts) != len(names) or min(counts) == 0:
        raise RuntimeError("expected %d counted regions, got %s (is context_run in this Python's "
                           "symbols?)" % (len(names), counts))
    return dict(zip(names, counts))


def measure():
    out = {}
    for which in ("fresh", "warm"):
        out.update(count(which))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--update", action="store_true", help="rewrite the baselines")
    ap.add_argument("--child", choices=("fresh", "warm"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        _child(args.child)
        return 0
    if shutil.which("valgrind") is None:
        print("instruction counts: skipped (valgrind not installed; apt-get install valgrind)")
        return 0
    env = environment()
    base = json.loads(BASELINE.read_text()) if BASELINE.exists() else None
    if not args.update and base is not None and base["environment"] != env:
        diff = ", ".join("%s %s -> %s" % (k, base["environment"].get(k), v)
                         for k, v in env.items() if base["environment"].get(k) != v)
        print("instruction counts: skipped (baselines recorded with other versions: %s; "
              "`make instructions-baseline` records this machine's)" % diff)
        return 0
    t0 = time.perf_counter()
    new = measure()
    wall = time.perf_counter() - t0
    if args.update or base is None:
        BASELINE.parent.mkdir(parents=True, exist_ok=True)
        BASELINE.write_text(json.dumps({"environment": env, "margin": MARGIN, "counts": new},
                                       indent=1) + "\n")
        for name, n in new.items():
            print("%-20s %14d" % (name, n))
        print("instruction counts: baselines written to %s (%.0f s)" % (BASELINE, wall))
        return 0
    failed = []
    print("%-20s %14s %14s %8s" % ("region", "baseline", "now", "change"))
    for name in REGIONS:
        old, now = base["counts"].get(name), new[name]
        ch = (now - old) / old if old else float("inf")
        print("%-20s %14s %14d %+7.2f%%" % (name, old, now, 100 * ch))
        if old is None or ch > MARGIN:
            failed.append(name)
    if failed:
        print("instruction counts: FAILED, grew by more than %.0f %%: %s (a deliberate change: "
              "`make instructions-baseline`, and say why in the commit)" % (100 * MARGIN,
                                                                            ", ".join(failed)))
        return 1
    print("instruction counts: within %.0f %% of the baselines (%.0f s)" % (100 * MARGIN, wall))
    return 0


if __name__ == "__main__":
    sys.exit(main())
