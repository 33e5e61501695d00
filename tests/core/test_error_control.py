"""The adaptive methods' step acceptance and order, against textbook formulas typed in here.

Free flight (both feet 5 cm above the ground, flags (0, 0)) is a smooth ODE f = `pdw.rhs`. On
it:

* one Dormand-Prince 5(4) step computed in NumPy from Hairer, Norsett & Wanner I, Table II.5.2
  (not from pdw's tableau file) gives the new state and the error estimate; its RMS norm with
  the scale sc_i = atol + rtol max(|x_i|, |x_new,i|) decides acceptance (docs/integrators.md).
  A first step whose norm is 0.9 must be accepted, one whose norm is 1.1 rejected;
* rodas4 and dopri5 forced to a fixed step (a huge rtol: every step accepted at h_max) converge
  at their orders, 4 and 5.
"""
import numpy as np
import pytest

import pdw

FLAGS = (0, 0)
P = pdw.Params.paper()

# Dormand-Prince 5(4): nodes, coefficients, 5th-order weights b and 4th-order weights bh
A = [[],
     [1 / 5],
     [3 / 40, 9 / 40],
     [44 / 45, -56 / 15, 32 / 9],
     [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729],
     [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656],
     [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]]
B = np.array([35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0])
BH = np.array([5179 / 57600, 0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40])


def _x0():
    """The paper's start lifted 5 cm, legs spreading (no foot passes the other: no arming
    switch, which an adaptive step would locate and end at)."""
    x = np.array(pdw.X0_PAPER, float)
    x[1] += 0.05
    x[6:8] = [-1.0, 1.0]
    return x


def _f(x):
    return pdw.rhs(x, P, flags=FLAGS)


def _dp5(x, h):
    k = []
    for i in range(7):
        k.append(_f(x + h * sum(a * kj for a, kj in zip(A[i], k))))
    k = np.array(k)
    return x + h * B @ k, h * (B - BH) @ k


def _norm(x, xnew, err, rtol, atol):
    sc = atol + rtol * np.maximum(np.abs(x), np.abs(xnew))
    return float(np.sqrt(np.mean((err / sc) ** 2)))


def _h_for(target, x, rtol, atol):
    """The first step whose error norm is `target` (bisection in log h)."""
    lo, hi = 1e-6, 1e-1
    for _ in range(60):
        h = np.sqrt(lo * hi)
        xn, e = _dp5(x, h)
        if _norm(x, xn, e, rtol, atol) < target:
            lo = h
        else:
            hi = h
    return np.sqrt(lo * hi)


@pytest.mark.parametrize("rtol, atol", [(1e-6, 1e-12), (1e-9, 1e-9)])
def test_first_step_is_accepted_by_the_rms_norm(rtol, atol):
    x = _x0()
    for target, rejected in ((0.9, 0), (1.1, 1)):
        h = _h_for(target, x, rtol, atol)
        xn, e = _dp5(x, h)
        assert _norm(x, xn, e, rtol, atol) == pytest.approx(target, rel=1e-3)
        r = pdw.simulate(x, t_end=h, dt=h, method="dopri5", flags0=FLAGS,
                         integrator=pdw.Integrator(rtol=rtol, atol=atol, check_step="off"),
                         record=pdw.Record(every=1))
        assert (r.stats["rejected"] > 0) == bool(rejected), (target, r.stats)
        if not rejected:
            assert r.stats["steps"] == 1
            np.testing.assert_allclose(r.x_final, xn, rtol=1e-13, atol=1e-15)


def _fixed(method, h, t_end):
    return pdw.simulate(_x0(), t_end=t_end, dt=h, method=method, flags0=FLAGS,
                        integrator=pdw.Integrator(h_max=h, rtol=1e3, atol=1e3, check_step="off"),
                        record=pdw.Record(every=0)).x_final


@pytest.mark.parametrize("method, order, h", [("rodas4", 4, 4e-3), ("dopri5", 5, 1e-2)])
def test_fixed_step_order(method, order, h):
    t_end = 0.048
    ref = pdw.simulate(_x0(), t_end=t_end, method="dopri5", flags0=FLAGS,
                       integrator=pdw.Integrator(rtol=1e-13, atol=1e-15, check_step="off"),
                       record=pdw.Record(every=0)).x_final
    e1 = np.max(np.abs(_fixed(method, h, t_end) - ref))
    e2 = np.max(np.abs(_fixed(method, h / 2, t_end) - ref))
    assert e2 > 1e-13, "the error must be above rounding for the order to show"
    assert order - 0.5 < np.log2(e1 / e2) < order + 0.7, (e1, e2, np.log2(e1 / e2))
