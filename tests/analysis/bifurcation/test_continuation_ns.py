"""Neimark-Sacker curves in two parameters (issue #24 a; pdw.analysis.bifurcation.codim2), on a planar map
whose NS curve is known in closed form (no walker model in pdw has shown one: see
docs/continuation.md)."""
import numpy as np
import pytest

import pdw
from pdw.analysis.bifurcation.codim2 import compound2, continue_bifurcation
from pdw.analysis.bifurcation.continuation import run_continuation
from pdw.analysis.stepmap.gait_maps import Evaluation, _Problem


class _Henon(_Problem):
    """(x, y) -> (y, -(b + a^2/10) x + a y - y^2), a = Params.m_h, b = Params.k_hip (two
    Params fields with wide ranges stand in for the map's parameters). Fixed point
    x = y = s = a - 1 - b - a^2/10, Jacobian [[0, 1], [-(b + a^2/10), a - 2s]]: det = b + a^2/10,
    so a complex pair crosses the unit circle on b = 1 - a^2/10 (while |a - 2s| < 2)."""

    dim, model = 2, "map"

    def __init__(self, params):
        super().__init__(params, "m_h")
        self.opts = {}

    def evaluate(self, z, mu, jac=True):
        P = self.params_at(mu)
        a, b = P.m_h, P.k_hip
        x, y = float(z[0]), float(z[1])
        self.n_maps += 1
        Pz = np.array([y, -(b + a * a / 10) * x + a * y - y * y])
        M = np.array([[0.0, 1.0], [-(b + a * a / 10), a - 2 * y]])
        Pl = np.array([0.0, -(a / 5) * x + y])
        info = {"period": 1.0, "step_length": 1.0, "double_support": 0.0, "state": Pz,
                "orbit": np.array([z])}
        return Evaluation(True, "ok", Pz, M, Pl, info, {})

    def images(self, points):
        out = []
        for z, P in points:
            a, b = P.m_h, P.k_hip
            out.append(np.array([z[1], -(b + a * a / 10) * z[0] + a * z[1] - z[1] ** 2]))
        return out

    def gait(self, z, mu, ev, mult):
        return pdw.Gait(state=np.asarray(z), period=1.0, step_length=1.0, double_support=0.0,
                        multipliers=mult, model="map")


def test_second_compound_has_the_products_of_the_eigenvalues():
    rng = np.random.default_rng(1)
    M = rng.normal(size=(4, 4))
    mu = np.linalg.eigvals(M)
    prods = sorted((mu[i] * mu[j] for i in range(4) for j in range(i + 1, 4)),
                   key=lambda c: (round(c.real, 9), round(c.imag, 9)))
    got = sorted(np.linalg.eigvals(compound2(M)),
                 key=lambda c: (round(c.real, 9), round(c.imag, 9)))
    assert np.allclose(prods, got, atol=1e-10)


@pytest.fixture(scope="module")
def ns():
    base = pdw.Params.paper_steady(k_hip=0.2, m_h=2.5)
    s = 2.5 - 1 - 0.2 - 0.625
    b = run_continuation(_Henon(base), [s, s], 2.5, 3.2, tol=1e-12)
    (ns,) = b.of_kind("neimark_sacker")
    return ns


def test_neimark_sacker_located_on_the_closed_form(ns):
    assert ns.located and abs(ns.value - np.sqrt(8.0)) < 1e-8 and ns.label == "NS1"


def test_neimark_sacker_curve_follows_b_equal_1_minus_a2_over_10(ns):
    cv = continue_bifurcation(ns, "k_hip", 0.5, tol=1e-12, at=[0.3, 0.4])
    assert cv.kind == "neimark_sacker" and "reached stop" in cv.stop_reason
    a, b = cv.values[:, 0], cv.values[:, 1]
    assert b.max() == pytest.approx(0.5) and len(cv) >= 3
    assert np.max(np.abs(a - np.sqrt(10 * (1 - b)))) < 1e-8          # on the closed form
    assert np.all(np.abs(np.abs(cv.multipliers) - 1.0) < 1e-9)      # a pair on the circle
    assert np.all(np.abs(cv.multipliers.imag) > 0.1)                # complex, not a saddle
