"""Chaos, measured: Lyapunov exponents, orbit diagrams, Feigenbaum ratios (issue #24 f)."""
import numpy as np
import pytest

import pdw
from pdw import hybrid as H
from pdw.analysis.rigid import chaos

COMPASS = H.compass_gait_params()
DEG = np.pi / 180


def test_lyapunov_exponent_of_a_stable_gait_is_log_of_its_largest_multiplier():
    """Closed form at a stable fixed point: lambda = log max |mu| (mu from find_gait's
    finite-difference Jacobian, independent of the exact one used by lyapunov)."""
    P = COMPASS.replace(gamma=4.0 * DEG)
    r = chaos.lyapunov(P, n_steps=2000, n_transient=50)
    g = H.find_gait(P)
    assert r["exponent"] == pytest.approx(np.log(np.max(np.abs(g.multipliers))), abs=3e-3)


def test_lyapunov_exponent_in_the_chaotic_regime_matches_two_nearby_walks():
    """At 5.1 deg (beyond the cascade's accumulation, 5.035 deg) the exponent is positive and
    equals Benettin's brute-force estimate from two walks kept 1e-8 apart (no Jacobian)."""
    P = COMPASS.replace(gamma=5.1 * DEG)
    s0 = H.find_gait(COMPASS.replace(gamma=4.5 * DEG)).state
    r = chaos.lyapunov(P, n_steps=1500, n_transient=300, start=s0)
    a = s0.copy()
    for _ in range(300):
        a = H.step_map(a, P)
    d0, u = 1e-8, np.array([1.0, -1.0, 1.0, 1.0]) / np.sqrt(3.0)
    b, tot = a + d0 * u, 0.0
    for _ in range(1500):
        a, b = H.step_map(a, P), H.step_map(b, P)
        dv = b - a
        d = np.linalg.norm(dv[[0, 2, 3]])
        tot += np.log(d / d0)
        b = a + dv * (d0 / d)
    assert r["exponent"] > 0.15
    assert abs(r["exponent"] - tot / 1500) < 0.02


def test_orbit_diagram_has_one_value_below_the_first_doubling_and_two_above():
    vals = np.array([4.2, 4.3, 4.5, 4.6]) * DEG
    od = chaos.orbit_diagram(COMPASS, "gamma", vals, n_steps=400, keep=50)
    assert not od["fell"].any() and od["theta"].shape == (4, 50)
    for i, v in enumerate(vals):
        spread = np.ptp(od["theta"][i])
        if v < 4.3909 * DEG:
            g = H.find_gait(COMPASS.replace(gamma=v))
            assert spread < 1e-7 and abs(od["theta"][i, -1] - g.state[0]) < 1e-7
        else:
            assert spread > 1e-3 and np.unique(np.round(od["theta"][i], 7)).size == 2


def test_feigenbaum_ratios_of_the_logistic_map():
    """The logistic map's doublings r = 3, 1 + sqrt(6) (closed forms), 3.544090, 3.564407
    (literature): ratios 4.751 and 4.656, near delta = 4.669."""
    d = chaos.feigenbaum_ratios([3.0, 1 + np.sqrt(6.0), 3.544090, 3.564407])
    np.testing.assert_allclose(d, [4.7514, 4.6562], atol=2e-3)
    with pytest.raises(pdw.InvalidInputError, match="values"):
        chaos.feigenbaum_ratios([1.0, 2.0])
