"""1/N = 1/sqrt(1 + h'^2) of the shaped-ground kernel (pdw_terrain.c, docs/terrain.md "Costs"):
for |h'| <= 2^-4.5 (h'^2 <= 2^-9) the binomial series through h'^10 in place of a square root and
a division (its omitted tail is below (231/1024) h'^12 <= 1.3e-17). Both forms must be within
1 ulp of the exact value (computed here in exact rational arithmetic and rounded once), and
level ground (h' = 0) must give 1 exactly."""
from fractions import Fraction

import numpy as np
import pytest

from pdw.core import _core

QMAX = 2.0 ** -9       # pdw_terrain.c INVN_QMAX


def _exact(dh):
    """1/sqrt(1 + dh^2) correctly rounded: Newton's method on exact rationals, then rounded."""
    q = 1 + Fraction(dh) ** 2
    y = Fraction(1.0 / np.sqrt(float(q)))
    for _ in range(3):                      # quadratic convergence from ~1e-16: far below 1e-50
        y = y * (3 - q * y * y) / 2
    return float(y)


def _values():
    rng = np.random.default_rng(7)
    edge = np.sqrt(QMAX)
    dh = np.concatenate([
        rng.uniform(0.0, edge, 400),                     # the series' range
        rng.uniform(edge, 2.0, 200),                     # the square root's
        rng.uniform(0.0, 1e-4, 100),                     # small slopes
        np.nextafter(edge, [0.0, 1.0]),                  # both sides of the switch
        [edge, 0.0, 1e-300],
    ])
    signs = np.where(rng.random(dh.size) < 0.5, -1.0, 1.0)
    return dh * signs


def test_inverse_normal_is_within_one_ulp_of_the_exact_value():
    dh = _values()
    got = _core.ground_inv_normals(dh)
    exact = np.array([_exact(v) for v in dh])
    ulps = np.abs(got - exact) / np.spacing(exact)
    assert ulps.max() <= 1.0, (dh[ulps.argmax()], ulps.max())
    # and against the square-root form the kernel used before (two roundings): within 2 ulp
    ref = 1.0 / np.sqrt(1.0 + dh * dh)
    assert np.max(np.abs(got - ref) / np.spacing(ref)) <= 2.0


@pytest.mark.parametrize("n", [1, 2, 3])
def test_level_ground_gives_one_exactly(n):
    assert np.all(_core.ground_inv_normals(np.zeros(n)) == 1.0)
    assert np.all(_core.ground_inv_normals(-np.zeros(n)) == 1.0)


def test_pairs_and_odd_lengths_agree():
    """The two-foot (vector) evaluation and the one-foot one give the same bits."""
    dh = _values()
    pairs = _core.ground_inv_normals(dh)
    single = np.array([_core.ground_inv_normals(np.array([v]))[0] for v in dh])
    assert np.array_equal(pairs, single)


def _full_series(dh):
    """The full series of pdw_terrain.c inv_norm_series, the same IEEE sums in NumPy."""
    c1, c2, c3, c4, c5 = -0.5, 0.375, -0.3125, 0.2734375, -0.24609375
    q = dh * dh
    q2 = q * q
    q4 = q2 * q2
    return ((1.0 + c1 * q) + q2 * (c2 + c3 * q)) + q4 * (c4 + c5 * q)


def test_short_series_is_the_full_series_bitwise():
    """For h'^2 <= 2^-14 the kernel drops the series' last sum (below half an ulp, so it never
    changes the result): the same bits as the full series, alone and in pairs, up to the
    switch and just past it (where the full series is taken)."""
    rng = np.random.default_rng(11)
    edge = 2.0 ** -7                                       # sqrt(INVN_Q4MAX)
    dh = np.concatenate([rng.uniform(0.0, edge, 3000), rng.uniform(0.0, 1e-3, 1000),
                         np.nextafter(edge, [0.0, 1.0]), [edge, 0.0],
                         rng.uniform(edge, np.sqrt(QMAX), 500)])
    dh = np.concatenate([dh, -dh])
    full = _full_series(dh)
    assert _core.ground_inv_normals(dh).tobytes() == full.tobytes()
    single = np.array([_core.ground_inv_normals(np.array([v]))[0] for v in dh[:800]])
    assert single.tobytes() == full[:800].tobytes()
