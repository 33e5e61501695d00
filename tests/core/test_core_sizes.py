"""Issue 26, item 1: every size the compiled layer computes from a caller's count is checked.

A count (steps, record capacity, event capacity, samples) that would overflow a size, or that
no run could finish, is refused with `pdw.InvalidInputError` naming the argument and its allowed
range (or, for an allocation that cannot be made, a MemoryError saying what it needed), before
any memory is touched: never a segfault, a heap overrun or a hang. `pdw.hybrid.find_gait(P,
settle_steps=2**62)` used to segfault (`_hybrid.walk` sized its buffer as n_steps * sizeof(...),
which wrapped). Each call runs in a subprocess, so a crash fails the test instead of the run.

The compiled boundary's shapes (issue 16, finding 3): every compiled entry point of
`pdw.core._core`, `pdw.core._hybrid` and `pdw.core._batch` checks its array shapes, dtypes and
layouts once per call, before it takes a pointer, and raises ValueError naming the argument;
record buffers and batch outputs of the wrong shape are refused the same way.
"""
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import pdw
from pdw.core import _core
from pdw.core.model import parameter_vector

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


# --- array shapes, dtypes and layouts at the compiled boundary (issue 16, finding 3) ---------

NX, NP, NW = _core.NX, _core.NP, _core.NWORK
P = parameter_vector(pdw.Params.paper())


_SHAPE_PRELUDE = """
import numpy as np
import pdw
from pdw.core import _core, _hybrid
from pdw.core.model import parameter_vector
NX, NP, NW = _core.NX, _core.NP, _core.NWORK
NC = 2 * len(pdw.core._layout.CONTACT)
P = parameter_vector(pdw.Params.paper())
x = np.tile(np.array(pdw.X0_PAPER), (4, 1))
f = np.tile(np.array([0, 1], dtype=np.intc), (4, 1))
a = np.zeros((4, 2))
"""


# (call, the argument its error must name): each used to overrun memory or run on garbage
SHAPE_CASES = [
    ("_core.rhs_batch(0, x, P, f, a, np.empty((1, NX)), np.empty((4, NW)))", "xdot"),
    ("_core.rhs_batch(0, x, P, f, a, np.empty((4, NX)), np.empty((1, NW)))", "work"),
    ("_core.rhs_batch(0, x, P, f, a, np.empty((4, NX)), np.empty((4, 3)))", "work"),
    ("_core.rhs_batch(0, x, P[:3].copy(), f, a, np.empty((4, NX)), np.empty((4, NW)))", "p"),
    ("_core.rhs_batch(0, x, P, f[:1].copy(), a, np.empty((4, NX)), np.empty((4, NW)))", "flags"),
    ("_core.rhs_batch(0, x, P, f, a[:2].copy(), np.empty((4, NX)), np.empty((4, NW)))", "anchors"),
    ("_core.rhs_batch(0, x[:, :3].copy(), P, f, a, np.empty((4, NX)), np.empty((4, NW)))", "x"),
    ("_core.jacobian_batch(0, x, P, f, a, np.empty((4, 8)), np.empty((4, NW)))", "J"),
    ("_core.energies_batch(0, x, P, np.empty((1, 3)))", "e"),
    ("_core.cdm_terms(0, x[0], P, np.zeros(NC), np.empty(4), np.empty(16), np.empty(4))", "M"),
    ("_core.cdm_terms(0, x[0], P, np.zeros(2), np.empty(16), np.empty(16), np.empty(4))",
     "contact"),
    ("_core.precompute(np.ones(3), np.empty(NP))", "params"),
    ("_core.precompute(pdw.Params().as_array(), np.empty(3))", "p"),
    ("_core.run(0, 0, np.zeros(3), P, 0, 1, dict(dt=1e-4, n_steps=10, max_speed=1e3))", "x0"),
    ("_core.bench(0, 'rhs', np.zeros(3), P, 0, 1, 0.0, 0.0, 10)", "x"),
    ("_hybrid.step_batch(P, np.zeros((4, 4)), {}, np.empty((1, 4)), np.empty(4, np.intc))",
     "y_plus"),
    ("_hybrid.step_batch(P, np.zeros((4, 4)), {}, np.empty((4, 4)), np.empty(1, np.intc))",
     "status"),
    ("_hybrid.full_state_batch(P, np.zeros((4, 4)), np.empty((1, 8)))", "x"),
    ("_hybrid.rhs(P, np.zeros(3))", "y"),
    ("_hybrid.energies(P[:5].copy(), np.zeros(4))", "p"),
    ("_hybrid.ground_force(P, np.zeros(4), np.zeros(1))", "ydd"),
    ("_hybrid.impact(P, np.zeros(2))", "y_minus"),
    ("_hybrid.walk(P, np.zeros(2), 0.0, 3, {}, 10)", "y0"),
    ("_hybrid.solve(np.eye(3), np.zeros(2))", "b"),
    ("_hybrid.rhs_jac(P, np.zeros(3))", "y"),
    ("_hybrid.swing_foot_grad(P[:4].copy(), np.zeros(4))", "p"),
    ("_hybrid.impact_jac(P, np.zeros(1))", "y_minus"),
    ("_hybrid.step_jac(P, np.zeros(2), {})", "y0"),
    ("_hybrid.step_jac_batch(P, np.zeros((3, 4)), {}, np.empty((3, 4)), np.empty((1, 4, 4)), "
     "np.empty(3, np.intc))", "DP"),
    ("_hybrid.step_jac_batch(P, np.zeros((3, 4)), {}, np.empty((3, 4)), np.empty((3, 4, 4)), "
     "np.empty(1, np.intc))", "status"),
    ("_hybrid.solve(np.zeros((9, 9)), np.zeros(9))", "A"),
]


def _run_shapes(code, *flags):
    return subprocess.run([sys.executable, *flags, "-c", textwrap.dedent(_SHAPE_PRELUDE + code)],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("call,arg", SHAPE_CASES, ids=[c[0].split("(")[0] + ":" + c[1] for c in SHAPE_CASES])
def test_wrong_shapes_raise_value_error_naming_the_argument(call, arg):
    """In a subprocess (also under python -O, where an assert would vanish): the call raises
    ValueError naming the argument and both shapes; it neither crashes nor returns."""
    code = """
try:
    %s
except ValueError as e:
    print("VALUEERROR", e)
else:
    print("RETURNED")
""" % call
    # the entry points that had only an assert are also run under -O (where asserts vanish)
    had_assert = any(n in call for n in ("precompute", "solve", "full_state_batch", "step_batch",
                                         "step_jac_batch"))
    for flags in ((), ("-O",)) if had_assert else ((),):
        out = _run_shapes(code, *flags)
        assert out.returncode == 0, (call, flags, out.returncode, out.stderr[-2000:])
        line = out.stdout.strip().splitlines()[-1]
        assert line.startswith("VALUEERROR"), (call, line)
        msg = line[len("VALUEERROR "):]
        assert msg.startswith(arg + " ") or ("%s must" % arg) in msg or arg in msg.split()[0], msg
        assert "shape" in msg or "rows" in msg, msg


def _array_args(fn):
    """(name, C type, ndim, const) of fn's typed-memoryview arguments, read from the typed
    signature Cython embeds in __doc__, and the names of all its arguments."""
    from pdw.core import _batch, _hybrid  # noqa: F401 - the modules under test
    head = fn.__doc__.split("\n", 1)[0]
    sig = head[head.index("(") + 1:head.rindex(")")]
    raw = [p for p in re.split(r",(?![^\[]*\])", sig) if p.strip()]
    parts = [p.split("=")[0].split() for p in raw]
    # the required arguments (no default), with a valid scalar for the non-array ones
    scalar = {"int": 0, "long": 0, "double": 0.0, "bint": False, "str": "rhs", "dict": {}}
    names = [(p[-1], scalar.get(p[0], None)) for p, r in zip(parts, raw)
             if "=" not in r and p != ["*"]]      # keyword-only ones after "*" have defaults
    arrays = []
    for p in parts:
        m = re.fullmatch(r"(const )?(double|int|long)\[([:, 0-9]*)\] (\w+)", " ".join(p))
        if m:
            arrays.append((m.group(4), m.group(2), m.group(3).count(",") + 1, bool(m.group(1))))
    return arrays, names


def _entry_points():
    from pdw.core import _batch, _hybrid
    out = []
    for mod in (_core, _hybrid, _batch):
        for name in sorted(dir(mod)):
            fn = getattr(mod, name)
            if callable(fn) and not name.startswith("_") and "[" in (fn.__doc__ or "")[:300] \
                    and _array_args(fn)[0]:
                out.append((mod.__name__.rsplit(".", 1)[1], name))
    return out


ENTRY_POINTS = _entry_points()


_WANT = {"double": np.float64, "int": np.intc, "long": np.int_}


def test_every_typed_entry_point_is_covered():
    """The dtype/layout test below reaches every compiled entry point that takes arrays."""
    names = {n for _, n in ENTRY_POINTS}
    assert {"run", "rhs_batch", "jacobian_batch", "precompute", "run_range", "step_batch",
            "solve", "walk"} <= names, names
    assert len(ENTRY_POINTS) >= 25, ENTRY_POINTS


@pytest.mark.parametrize("mod,name", ENTRY_POINTS, ids=["%s.%s" % e for e in ENTRY_POINTS])
def test_wrong_dtype_layout_or_type_names_the_argument(mod, name):
    """Cython converts a typed-memoryview argument before the body runs, and its own messages
    ("Buffer dtype mismatch ...", "ndarray is not C-contiguous") name no argument: every entry
    point names it, with the expected array and what was given. Each array argument in turn
    gets a wrong dtype, a non-contiguous view, a wrong ndim, a list (and a read-only array for
    an output), the others being right; the call must fail naming exactly that argument."""
    from pdw.core import _batch, _hybrid
    fn = getattr({"_core": _core, "_hybrid": _hybrid, "_batch": _batch}[mod], name)
    arrays, names = _array_args(fn)
    good = {a: np.zeros((3,) * nd, dtype=_WANT[t]) for a, t, nd, _ in arrays}
    for a, t, nd, const in arrays:
        if a not in dict(names):
            continue                       # an optional array argument: not reached here
        wrong_dtype = np.float32 if t == "double" else np.float64
        bad = [np.zeros((3,) * nd, dtype=wrong_dtype),
               np.zeros((3,) * (nd - 1) + (6,), dtype=_WANT[t])[..., ::2],
               np.zeros((3,) * (nd + 1), dtype=_WANT[t]),
               np.zeros((3,) * nd).tolist()]
        if not const:
            ro = np.zeros((3,) * nd, dtype=_WANT[t])
            ro.flags.writeable = False
            bad.append(ro)
        for value in bad:
            args = [value if n == a else good.get(n, v) for n, v in names]
            with pytest.raises((ValueError, TypeError)) as err:
                fn(*args)
            assert str(err.value).startswith(a + " must be a C-contiguous %d-D" % nd), \
                (name, a, type(value), str(err.value))


def test_batch_outputs_of_the_wrong_dtype_are_named():
    """run_range's output arrays come in a dict: a wrong one is named by its key."""
    from pdw.core import _batch
    from pdw.sim import batch
    x0 = np.array([pdw.X0_PAPER])
    b = pdw.simulate_batch(x0, t_end=0.01, dt=1e-4)     # the right call works ...
    assert b.status[0] == "walked"
    calls = []
    real = _batch.run_range

    def spy(*args, **kw):
        calls.append((args, kw))
        return real(*args, **kw)
    mp = pytest.MonkeyPatch()
    mp.setattr(_batch, "run_range", spy)
    try:
        batch.simulate_batch(x0, t_end=0.01, dt=1e-4, threads=1)
    finally:
        mp.undo()
    args, kw = calls[0]
    i_out = next(i for i, v in enumerate(args) if isinstance(v, dict) and "status" in v)
    for key in ("n_steps", "x_final", "gait"):
        out = dict(args[i_out])
        out[key] = out[key].astype(np.float32 if out[key].dtype != np.float32 else np.float64)
        bad = list(args)
        bad[i_out] = out
        with pytest.raises(ValueError, match=r"^out\['%s'\] must be a C-contiguous" % key):
            real(*bad, **kw)


def test_flags_outside_0_1_are_refused_by_the_compiled_batch():
    x = np.array([pdw.X0_PAPER])
    with pytest.raises(ValueError, match=r"flags\[0, 1\] must be 0 or 1, got 2"):
        _core.rhs_batch(0, x, P, np.array([[0, 2]], dtype=np.intc), np.zeros((1, 2)),
                        np.empty((1, NX)), np.empty((1, NW)))


def test_right_shapes_still_compute_the_same_numbers():
    """The checks change no number: the batch equals the public pdw.rhs row by row."""
    rng = np.random.default_rng(3)
    X = np.array(pdw.X0_PAPER) + rng.normal(0, 0.01, (5, NX))
    xdot = np.empty((5, NX))
    _core.rhs_batch(0, X, P, np.tile(np.array([0, 1], np.intc), (5, 1)), np.zeros((5, 2)),
                    xdot, np.empty((5, NW)))
    for i in range(5):
        assert np.array_equal(xdot[i], pdw.rhs(X[i]))


_ENTRY_PRELUDE = """
import numpy as np
import pdw
from pdw.core import _core, _batch
from pdw.core.model import parameter_vector
from pdw.sim.batch import _outputs
from pdw.sim.buffers import RecordBuffer
NX, NP = _core.NX, _core.NP
P = parameter_vector(pdw.Params.paper())
X = np.tile(np.array(pdw.X0_PAPER), (2, 1))
F = np.tile(np.array([0, 1], dtype=np.intc), (2, 1))
H, D = np.full(2, 0.5), np.full(2, 0.1)
O = dict(dt=1e-4, n_steps=50, record_every=1, record_events=1, fall_hip_height=0.2,
         fall_depth=0.1, max_speed=1e3)
def rr(x=X, p=P[None], f=F, dt=1e-4, n=50, stop=0, pk=0, out=None):
    return _batch.run_range(0, x, p, f, H, D, dict(dt=dt, n_steps=n, max_speed=1e3,
                                                   stop_steps=stop, periodic_k=pk,
                                                   periodic_tol=1e-3),
                            _outputs(len(x)) if out is None else out, 0, len(x), 4, False)
def tampered(**arrays):
    b = RecordBuffer(100)
    for k, v in arrays.items():
        setattr(b, k, v)
    return b
def bufs(n=100, nx=NX, nc=4):
    return (np.zeros(n), np.zeros((n, nx)), np.zeros((n, 2), np.intc), np.zeros((n, nc)))
"""


# (call, a word its ValueError must contain): each used to write out of bounds (a heap
# corruption: "double free or corruption"), run on garbage or run with a meaningless value
CRASH_CASES = [
    ("pdw.simulate(t_end=0.005, out=tampered(contact=np.zeros((100, 1))))", "out.contact"),
    ("pdw.simulate(t_end=0.005, out=tampered(x=np.zeros((1, NX))))", "out.x"),
    ("pdw.simulate(t_end=0.05, out=tampered(t=np.zeros(5000)))", "out.x"),
    ("pdw.simulate(t_end=0.005, out=tampered(flags=np.zeros((100, 2))))", "out.flags"),
    ("_core.run(0, 0, X[0], P, 0, 1, O, buffers=bufs(nc=1))",
     "contact"),
    ("_core.run(0, 0, X[0], P, 0, 1, O, "
     "buffers=bufs()[:1] + (np.zeros((3, NX)),) + bufs()[2:])", "x"),
    ("rr(f=np.array([[7, 1], [0, 1]], np.intc))", "flags0"),
    ("rr(dt=float('nan'))", "dt"),
    ("rr(n=-5)", "n_steps"),
    ("rr(pk=99)", "periodic_k"),
    ("rr(out={k: v for k, v in _outputs(2).items() if k != 'fail_x'})", "fail_x"),
    ("rr(out=dict(_outputs(2), fail_x=np.zeros((1, NX))))", "fail_x"),
    ("_core.OdeFunction(0, P[:3].copy(), 0, 1, 0.0, 0.0)", "p"),
    ("_core.OdeFunction(0, P, 7, 1, 0.0, 0.0)", "flags"),
    ("pdw.ode_function().set_discrete(0, 1, float('nan'), 0.0)", "anchors"),
]


def _run_entry(code):
    return subprocess.run([sys.executable, "-c", textwrap.dedent(_ENTRY_PRELUDE + code)],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("call,word", CRASH_CASES, ids=[c[1] + ":" + c[0][:40] for c in CRASH_CASES])
def test_compiled_boundary_of_the_new_entry_points_refuses_before_touching_memory(call, word):
    out = _run_entry("""
try:
    %s
except ValueError as e:
    print("VALUEERROR", e)
else:
    print("RETURNED")
""" % call)
    assert out.returncode == 0, (call, out.returncode, out.stderr[-2000:])
    line = out.stdout.strip().splitlines()[-1]
    assert line.startswith("VALUEERROR"), (call, line)
    assert word in line, line
