"""The touch-down Poincare map (`pdw.analysis.stepmap.poincare.step`, docs/studies.md "Limit cycles")
with a fixed-step method, and `pdw.limit_cycle.floquet` against an independent Jacobian.

A fixed-step run samples the touch-down only on the step grid; `step` interpolates linearly
between the two samples that straddle the crossing of the swing foot's contact point through
the ground (height y_D1 = y_o - r - (l - r) cos theta1). The tests ask for more than "close to
the adaptive map": the interpolated state's foot height is zero to 1e-3 of one step's change of
that height, its time lies between the two samples, and the state is the same convex
combination of the two samples as the time.
"""
import math

import numpy as np
import pytest

import pdw
from pdw.analysis.basins import cell_mapping
from pdw.analysis.stepmap import limit_cycle, poincare

P = pdw.Params.paper_steady()


@pytest.fixture(scope="module")
def z_ref():
    return cell_mapping.reference_point(P)


def _height(x):
    return x[1] - P.r - (P.l - P.r) * math.cos(x[2])


@pytest.mark.parametrize("method, dt", [("cdm", 1e-4), ("cdm", 3e-5), ("verlet", 5e-6)])
def test_fixed_step_section_is_at_the_crossing(z_ref, method, dt):
    s = poincare.step(z_ref, P, method=method, dt=dt, record=True)
    assert s["status"] == "ok"
    res, x = s["result"], s["x_touch"]
    i = int(np.searchsorted(res.t, s["period"]))          # first sample at or after the crossing
    y0, y1 = _height(res.x[i - 1]), _height(res.x[i])
    assert y0 >= 0.0 > y1
    change = y0 - y1                                      # one step's change of the height
    assert change > 1e-7
    assert abs(_height(x)) <= 1e-3 * change, (_height(x), change)
    assert res.t[i - 1] <= s["period"] <= res.t[i]
    frac = (s["period"] - res.t[i - 1]) / (res.t[i] - res.t[i - 1])
    np.testing.assert_allclose(x, res.x[i - 1] + frac * (res.x[i] - res.x[i - 1]), rtol=0,
                               atol=1e-9)
    # the section coordinates of that state (legs relabelled: leg 1 touched down)
    np.testing.assert_array_equal(s["z"], x[[3, 2, 4, 5, 7, 6]])
    assert s["step_length"] == pytest.approx(x[0] + (P.l - P.r) * math.sin(x[2]), abs=1e-15)


def test_fixed_step_map_tends_to_the_adaptive_one(z_ref):
    """Halving dt of the first-order cdm roughly halves the distance to the accurate map: the
    interpolation adds no error of its own of the order of a step."""
    exact = poincare.step(z_ref, P)["z"]
    err = [np.max(np.abs(poincare.step(z_ref, P, method="cdm", dt=dt)["z"] - exact))
           for dt in (1e-4, 5e-5)]
    assert err[1] < 0.75 * err[0], err


def test_floquet_multipliers_are_the_eigenvalues_of_the_map_jacobian(z_ref):
    """floquet's Jacobian against central differences of `step_map` taken here, and its
    multipliers against numpy's eigenvalues of that Jacobian, sorted by decreasing modulus."""
    h = 1e-5
    n = len(z_ref)
    J = np.empty((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = h
        J[:, k] = (poincare.step_map(z_ref + e, P) - poincare.step_map(z_ref - e, P)) / (2 * h)
    mult, Jf = limit_cycle.floquet(z_ref, P, fd_step=h)
    np.testing.assert_allclose(Jf, J, rtol=1e-9, atol=1e-9)
    ev = np.linalg.eigvals(J)
    ev = ev[np.argsort(-np.abs(ev), kind="stable")]
    assert np.all(np.diff(np.abs(mult)) <= 1e-12)            # decreasing modulus
    np.testing.assert_allclose(np.abs(mult), np.abs(ev), rtol=1e-7, atol=1e-10)
    for lam in mult[:3]:                                      # each one a root of det(J - lam I)
        assert np.min(np.abs(ev - lam)) < 1e-7
    assert np.abs(mult[0]) > 0.1 and np.abs(mult[-1]) < 1e-3   # spread: the order is tested
