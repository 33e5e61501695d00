"""One branch point of the continuous model with the exact monodromy (issue #24 "Speed":
`ContinuousProblem.evaluate` with ``monodromy = "exact"``): P(z), M, dP/dlambda and the step's
descriptors from one variational integration (`variational.step_jacobian` with a parameter
column, `variational.step_summary`) instead of three maps and the variational step beside
them. The descriptors by the map's definitions, so that the admissibility functions and the
corrector's statuses are the same as with finite differences."""
import numpy as np
import pytest

import pdw
from pdw.analysis.stepmap import limit_cycle as LC
from pdw.analysis.stepmap import poincare
from pdw.analysis.stepmap import variational as V
from pdw.analysis.stepmap.gait_maps import ContinuousProblem

pytest.importorskip("scipy")

P = pdw.Params.paper_steady()
LAWS = {"hunt_crossley": None, "flores": pdw.Contact("flores", e=0.18),
        "kelvin_voigt": pdw.Contact("kelvin_voigt")}


#: Kelvin-Voigt's gait at paper_steady (`LC.find_gait(P, contact=...)`, 80 s: its long walks)
Z_KV = np.array([-0.3506236417361184, 0.35055921795943923, 0.8372792655045687,
                 -0.17383873615168385, -1.7262514325957738, -1.5799953318450257])


def _gait(c):
    if c is not None and c.normal == "kelvin_voigt":
        return LC.find_gait(P, contact=c, guess=Z_KV, workers=1).details["z"]
    return LC.find_gait(P, contact=c, workers=1).details["z"]


@pytest.fixture(scope="module", params=sorted(LAWS))
def law_gait(request):
    c = LAWS[request.param]
    return c, _gait(c)


def _map_difference(prob, z, mu, rel):
    """dP/dmu by central differences of the map, relative step ``rel`` of mu."""
    h = rel * abs(mu)
    a, b = prob.images([(z, prob.point_at(mu + h)), (z, prob.point_at(mu - h))])
    return (a - b) / (2 * h)


def test_the_exact_branch_point_equals_the_map_and_its_differences(law_gait):
    """Measured at each law's paper_steady gait: P(z) to 3e-10, period, step length and
    double support to 2e-11, the same event count and admissibility, M to 1.7e-4 of the
    differences' (their own resolution), dP/dk_hip (the parameter column) to 8e-6 of its
    size from central differences of the map with relative steps 1e-3 (whose own change to
    steps 1e-4, continue_gait's relative step, is 5e-7 .. 4e-6)."""
    c, z = law_gait
    ev = {}
    for mono in ("differences", "exact"):
        prob = ContinuousProblem(P, "k_hip", workers=1, options={"contact": c})
        prob.monodromy = mono
        ev[mono] = prob.evaluate(z, P.k_hip)
        assert ev[mono].ok, ev[mono].status
    a, b = ev["differences"], ev["exact"]
    assert np.max(np.abs(a.Pz - b.Pz)) < 1e-9
    for key in ("period", "step_length", "double_support"):
        assert a.info[key] == pytest.approx(b.info[key], abs=1e-9)
    assert a.info["n_events"] == b.info["n_events"]
    for key in a.admissible:
        assert a.admissible[key] == pytest.approx(b.admissible[key], abs=1e-9)
    ref = _map_difference(prob, z, P.k_hip, 1e-3)
    assert np.max(np.abs(b.P_lam - ref)) < 3e-5 * np.abs(ref).max()
    assert np.max(np.abs(a.M - b.M)) < 1e-3 * np.abs(a.M).max()


@pytest.mark.parametrize("parameter", ["d_n", "gamma", "m_h"])
def test_the_parameter_column_against_map_differences(parameter):
    """Parameters of f alone (a damping, the slope, a mass): the variational step's column
    against central differences of the map with relative steps 1e-3 (measured 1e-6, 1.7e-6,
    5.8e-7 of its size; the differences' own spread to steps 1e-4: 3.5e-6, 1.8e-6, 4.2e-7)."""
    z = LC.find_gait(P, workers=1).details["z"]
    prob = ContinuousProblem(P, parameter, workers=1)
    prob.monodromy = "exact"
    mu = prob.coord(prob.start_value())
    ev = prob.evaluate(z, mu)
    assert ev.ok, ev.status
    ref = _map_difference(prob, z, mu, 1e-3)
    assert np.max(np.abs(ev.P_lam - ref)) < 1e-5 * np.abs(ref).max()


def test_a_parameter_of_the_section_takes_map_differences():
    """The leg length moves the section's embedding and the event functions, which the
    parameter column does not differentiate: dP/dl then comes from two maps, the same as the
    finite-difference branch point's (bitwise: the same maps)."""
    z = LC.find_gait(P, workers=1).details["z"]
    ev = {}
    for mono in ("differences", "exact"):
        prob = ContinuousProblem(P, "l", workers=1)
        prob.monodromy = mono
        ev[mono] = prob.evaluate(z, P.l)
        assert ev[mono].ok, ev[mono].status
    np.testing.assert_array_equal(ev["exact"].P_lam, ev["differences"].P_lam)
    with pytest.raises(pdw.InvalidInputError, match="dparam"):
        V.step_jacobian(z, P, dparam=((P.replace(l=P.l + 1e-6), None),
                                      (P.replace(l=P.l - 1e-6), None), 2e-6))


def test_step_summary_follows_the_map_through_a_pending_lift_off():
    """Kelvin-Voigt's gait: its feet rise before they lift off (pending, "rise" events that
    switch no flag), which the map's event count does not see either."""
    c = LAWS["kelvin_voigt"]
    z = _gait(c)
    r = V.step_jacobian(z, P, contact=c)
    assert "rise" in [kind for _, kind, _ in r["events"]]
    s, m = V.step_summary(r, P), poincare.step(z, P, contact=c)
    assert s["status"] == "ok" and s["n_events"] == m["n_events"]
    assert s["swing_period"] == pytest.approx(m["swing_period"], abs=1e-9)


def test_a_fall_is_the_maps_status():
    """A state from which the walker falls over backwards (hip rising at 0.5 m/s, legs
    swinging back): the variational step still reaches a "touch-down" (at 1.35 s, the walker
    upside down, theta -3.5 rad), the map says "fell"; so does the exact branch point."""
    z = LC.find_gait(P, workers=1).details["z"].copy()
    z[3:] = (0.5, -4.0, -3.0)
    r = V.step_jacobian(z, P, max_events=80)
    assert V.step_summary(r, P)["status"] == "fell"
    assert poincare.step(z, P)["status"] == "fell"
    prob = ContinuousProblem(P, "k_hip", workers=1)
    prob.monodromy = "exact"
    ev = prob.evaluate(z, P.k_hip)
    assert not ev.ok and ev.status == "fell"


def test_the_parameter_column_at_the_edge_of_the_range_is_one_sided():
    """The hip damper at d_hip = 0, the edge of its range (d_hip >= 0): the column takes the
    models at 0 and 1e-8 (one-sided, 1e-2 of the problem's difference step at mu = 0). The
    map's one-sided differences approach it as O(h): 1.5e-3, 1.5e-4, 1.5e-5 of its size at
    steps 1e-3, 1e-4, 1e-5 (measured)."""
    P0 = P.replace(d_hip=0.0)
    z = LC.find_gait(P, workers=1).details["z"]
    prob = ContinuousProblem(P0, "d_hip", workers=1)
    prob.monodromy = "exact"
    assert prob.lam_offsets(0.0)[1] == 0.0
    ev = prob.evaluate(z, 0.0)
    assert ev.ok, ev.status
    a, b = prob.images([(z, prob.point_at(1e-5)), (z, prob.point_at(0.0))])
    ref = (a - b) / 1e-5
    assert np.max(np.abs(ev.P_lam - ref)) < 5e-5 * np.abs(ref).max()
