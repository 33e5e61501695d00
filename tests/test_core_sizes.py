"""Issue 26, item 1: every size the compiled layer computes from a caller's count is checked.

A count (steps, record capacity, event capacity, samples) that would overflow a size, or that
no run could finish, is refused with `pdw.InvalidInputError` naming the argument and its allowed
range (or, for an allocation that cannot be made, a MemoryError saying what it needed), before
any memory is touched: never a segfault, a heap overrun or a hang. `pdw.hybrid.find_gait(P,
settle_steps=2**62)` used to segfault (`_hybrid.walk` sized its buffer as n_steps * sizeof(...),
which wrapped). Each call runs in a subprocess, so a crash fails the test instead of the run.
"""
import subprocess
import sys
import textwrap

import pytest

_PRELUDE = """
import numpy as np
import pdw
from pdw.core import _batch, _core, _hybrid
from pdw.core.model import parameter_vector
P = parameter_vector(pdw.Params.paper_steady())
X0 = np.array(pdw.X0_PAPER)
Y0 = np.array([0.2, -0.2, -1.0, -0.3])
BIG = 2 ** 62
"""

#: (call, the argument its error must name, the error class). Every one of these used to
#: crash, hang for ever, or fail with a raw OverflowError / numpy error naming nothing.
CASES = [
    ("pdw.hybrid.find_gait(pdw.Params.paper_steady(), settle_steps=BIG)", "settle_steps",
     "InvalidInputError"),
    ("pdw.hybrid.find_gait(pdw.Params.paper_steady(), settle_steps=2 ** 70)", "settle_steps",
     "InvalidInputError"),
    ("pdw.hybrid.find_gait(pdw.Params.paper_steady(), settle_steps=1.5)", "settle_steps",
     "InvalidInputError"),
    ("pdw.hybrid.find_gait(pdw.Params.paper_steady(), max_iter=BIG)", "max_iter",
     "InvalidInputError"),
    ("_hybrid.walk(P, Y0, 0.0, BIG, {}, 0)", "n_steps", "InvalidInputError"),
    ("_hybrid.walk(P, Y0, 0.0, 2 ** 63 - 1, {}, 0)", "n_steps", "InvalidInputError"),
    ("_hybrid.walk(P, Y0, 0.0, 2 ** 64, {}, 0)", "n_steps", "InvalidInputError"),
    ("_hybrid.walk(P, Y0, 0.0, 3, {}, BIG)", "rec_cap", "InvalidInputError"),
    ("_hybrid.step(P, Y0, {}, 0.0, 0.0, BIG)", "rec_cap", "InvalidInputError"),
    ("_core.run(0, 0, X0, P, 0, 1, dict(dt=1e-4, n_steps=BIG, max_speed=1e3))", "n_steps",
     "InvalidInputError"),
    ("_core.run(0, 0, X0, P, 0, 1, dict(dt=1e-4, n_steps=10, record_every=1, max_speed=1e3), "
     "max_records=BIG)",
     "max_records", "InvalidInputError"),
    ("_core.run(0, 0, X0, P, 0, 1, dict(dt=1e-4, n_steps=10, record_every=1, record_events=1, "
     "max_speed=1e3), event_capacity=BIG)",
     "event_capacity", "InvalidInputError"),
    ("_core.run(0, 0, X0, P, 0, 1, dict(dt=1e-4, n_steps=2 ** 64, max_speed=1e3))", "n_steps",
     "InvalidInputError"),
    ("_core.bench(0, 'rhs', X0, P, 0, 1, 0.0, 0.0, BIG)", "n", "InvalidInputError"),
    # found by the round-three fuzz run: a poll before every step, so never a step (a hang)
    ("_core.run(0, 0, X0, P, 0, 1, dict(dt=1e-4, n_steps=20, record_every=1, max_speed=1e3), "
     "poll_every=1)",
     "poll_every", "InvalidInputError"),
]


def _run(code):
    try:
        return subprocess.run([sys.executable, "-c", textwrap.dedent(_PRELUDE + code)],
                              capture_output=True, text=True, timeout=60)
    except subprocess.TimeoutExpired:
        pytest.fail("the call hung (no answer in 60 s): %s" % code.strip()[:200])


@pytest.mark.parametrize("call,arg,cls", CASES, ids=["%s:%s" % (c[0].split("(")[0], c[1])
                                                      for c in CASES])
def test_an_impossible_count_is_refused_naming_the_argument(call, arg, cls):
    out = _run("""
try:
    %s
except Exception as e:
    print("RAISED", type(e).__name__, "|", e)
else:
    print("RETURNED")
""" % call)
    assert out.returncode == 0, (call, out.returncode, out.stderr[-2000:])
    line = out.stdout.strip().splitlines()[-1]
    assert line.startswith("RAISED " + cls + " |"), (call, line)
    msg = line.split("|", 1)[1]
    assert arg in msg, (call, msg)
    assert "[" in msg or "<=" in msg or "at most" in msg, ("no allowed range given", msg)


def test_batch_run_range_refuses_a_step_count_no_run_could_finish():
    """The ensemble engine's n_steps: a count beyond `pdw.core.checks.MAX_COUNT` would loop for
    ever (2**62 steps); it is refused before the lanes start."""
    out = _run("""
from pdw.sim import batch as B
n = 2
x = np.tile(X0, (n, 1))
outd = B._outputs(n)
try:
    _batch.run_range(0, x, P[None], np.tile(np.array([0, 1], np.intc), (n, 1)),
                     np.full(n, 0.2), np.full(n, 0.1), dict(dt=1e-4, n_steps=BIG, max_speed=1e3),
                     outd, 0, n, 1, False)
except Exception as e:
    print("RAISED", type(e).__name__, "|", e)
else:
    print("RETURNED")
""")
    assert out.returncode == 0, out.stderr[-2000:]
    line = out.stdout.strip().splitlines()[-1]
    assert line.startswith("RAISED InvalidInputError |") and "n_steps" in line, line


def test_counts_within_range_still_run():
    """The checks take nothing away: a count at the top of its range is accepted (the run
    itself is short: an explicit record capacity, a hybrid walk of 2 steps)."""
    import numpy as np

    import pdw
    from pdw.core import _core, _hybrid
    from pdw.core.model import parameter_vector
    p = parameter_vector(pdw.Params.paper_steady())
    res, t, y, k = _hybrid.walk(p, np.array([0.2, -0.2, -1.0, -0.3]), 0.0, 2, {}, 100)
    assert len(res) >= 1
    raw = _core.run(0, 0, np.array(pdw.X0_PAPER), parameter_vector(pdw.Params.paper()), 0, 1,
                    dict(dt=1e-4, n_steps=10, record_every=1, record_events=1, fall_hip_height=0.2,
                         fall_depth=0.1, max_speed=1e3), record_contact=False, max_records=16,
                    event_capacity=8)
    assert len(raw["t"]) == 11
    g = pdw.hybrid.find_gait(pdw.Params.paper_steady(), settle_steps=5)
    assert g.period > 0
