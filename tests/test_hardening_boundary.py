"""Issue 16, finding 3: the compiled boundary is memory-safe.

Every compiled entry point of `pdw.core._core` and `pdw.core._hybrid` checks its array shapes once per
call, before it takes a pointer, and raises ValueError naming the argument, the expected and
the given shape. The calls that used to read or write out of bounds run in a subprocess: a
crash (segfault, abort) fails the test instead of killing the test run.
"""
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import pdw
from pdw.core import _core
from pdw.core.model import parameter_vector

NX, NP, NW = _core.NX, _core.NP, _core.NWORK
P = parameter_vector(pdw.Params.paper())

_PRELUDE = """
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
CASES = [
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
    ("_core.run(0, 0, np.zeros(3), P, 0, 1, 1e-4, 10, 1, True, 0.2, 0.1, 1e3)", "x0"),
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


def _run(code, *flags):
    return subprocess.run([sys.executable, *flags, "-c", textwrap.dedent(_PRELUDE + code)],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("call,arg", CASES, ids=[c[0].split("(")[0] + ":" + c[1] for c in CASES])
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
        out = _run(code, *flags)
        assert out.returncode == 0, (call, flags, out.returncode, out.stderr[-2000:])
        line = out.stdout.strip().splitlines()[-1]
        assert line.startswith("VALUEERROR"), (call, line)
        msg = line[len("VALUEERROR "):]
        assert msg.startswith(arg + " ") or ("%s must" % arg) in msg or arg in msg.split()[0], msg
        assert "shape" in msg or "rows" in msg, msg


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


def test_public_full_state_refuses_a_short_state():
    """pdw.hybrid.full_state([3 values]) used to return memory read past the array."""
    with pytest.raises(pdw.InvalidInputError, match=r"y must have shape \(4,\) or \(N, 4\)"):
        pdw.hybrid.full_state([0.1, -0.1, 1.0])
    with pytest.raises(pdw.InvalidInputError, match="shape"):
        pdw.hybrid.full_state(np.zeros((2, 3)))
    x = pdw.hybrid.full_state([0.2, -0.2, -1.0, -0.3])
    assert x.shape == (8,) and np.isfinite(x).all()


def test_work_precision_doc_does_not_send_users_to_private_batches():
    """docs/work_precision.md told users to call _core.rhs_batch; the public face is pdw.rhs."""
    import pathlib
    text = (pathlib.Path(__file__).resolve().parent.parent / "docs" / "work_precision.md").read_text()
    assert "_core.rhs_batch" not in text and "pdw.rhs" in text
