"""The continuous model's exact monodromy: variational equations with saltation matrices
(issue #24 item 2; pdw.analysis.stepmap.variational), against finite differences away from kinks."""
import numpy as np
import pytest

import pdw
from pdw.analysis.stepmap import limit_cycle as LC
from pdw.analysis.stepmap import variational as V

pytest.importorskip("scipy")


@pytest.fixture(scope="module")
def steady():
    P = pdw.Params.paper_steady()
    return P, pdw.find_gait(P)


def test_step_and_exact_jacobian_match_the_compiled_map_and_its_differences(steady):
    """At paper_steady's fixed point: z' equals the compiled rodas4 map's to 1e-9, M equals
    central differences (fd_step 1e-5, themselves good to ~3e-4 against fd_step 1e-6) to 1e-4,
    and the multipliers agree. Without the one-sided limits at the lift-off (f evaluated on
    the surface, where the tangential spring-damper has already vanished) M is off by 0.18."""
    P, g = steady
    z = g.details["z"]
    r = V.step_jacobian(z, P)
    J, Pz, _ = LC.jacobian(z, P, **LC.TIGHT)
    assert np.max(np.abs(r["z"] - Pz)) < 1e-9
    assert r["T"] == pytest.approx(g.period, abs=1e-9)
    assert [e[1] for e in r["events"] if e[1] not in ("rise", "reentry")][0] == "lift_off"
    assert np.max(np.abs(r["M"] - J)) < 1e-4 * max(1.0, np.abs(J).max())
    m = np.linalg.eigvals(r["M"])
    m = m[np.argsort(-np.abs(m))]
    np.testing.assert_allclose(np.abs(m[:3]), np.abs(g.multipliers[:3]), atol=1e-4)


def test_exact_jacobian_off_the_fixed_point(steady):
    """Off the fixed point (a perturbed section point, another hip stiffness) the same
    agreement with the differences of the variational map's own step (no kink nearby)."""
    P, g = steady
    P2 = P.replace(k_hip=1.1)
    z = g.details["z"] + np.array([2e-3, -1e-3, 5e-3, 0.0, 1e-2, -1e-2])
    r = V.step_jacobian(z, P2)
    J, Pz, _ = LC.jacobian(z, P2, **LC.TIGHT)
    assert np.max(np.abs(r["z"] - Pz)) < 1e-8
    assert np.max(np.abs(r["M"] - J)) < 1e-4 * max(1.0, np.abs(J).max())


def test_scope_is_stated():
    with pytest.raises(pdw.InvalidInputError, match="paper"):
        V.step_jacobian(np.zeros(6), pdw.Params.paper_steady(), variant="consistent")


def test_bifurcation_cross_check_uses_the_exact_monodromy(steady):
    """The continuous problem's cross-check (run at every located bifurcation) compares the
    finite-difference multipliers with the exact ones where the variational version exists:
    at paper_steady's gait they agree to 2e-4 (the differences resolve multipliers to ~1e-4);
    with other multipliers it reports the gap."""
    from pdw.analysis.stepmap.gait_maps import ContinuousProblem
    P, g = steady
    prob = ContinuousProblem(P, "k_hip")
    diff, note = prob.crosscheck(g.details["z"], P.k_hip, g.multipliers)
    assert prob.last_check == "variational" and diff < 1e-3 and note == ""
    diff, note = prob.crosscheck(g.details["z"], P.k_hip, g.multipliers * 1.01)
    assert diff > 1e-3 and "exact" in note


def test_continuation_with_the_exact_monodromy(steady):
    """continue_gait(..., monodromy="exact"): the same branch points as with differences, the
    multipliers equal to them within their resolution, and the gait says which M it has."""
    P, _ = steady
    a = pdw.continue_gait(P, "k_hip", 0.97, max_points=3, step=0.01, monodromy="exact")
    b = pdw.continue_gait(P, "k_hip", 0.97, max_points=3, step=0.01)
    assert len(a) == len(b) >= 2
    np.testing.assert_allclose(a.values, b.values, atol=1e-6)
    np.testing.assert_allclose(np.abs(a.multipliers[:, :3]), np.abs(b.multipliers[:, :3]),
                               atol=2e-4)
    with pytest.raises(pdw.InvalidInputError, match="monodromy"):
        pdw.continue_gait(P, "k_hip", 0.97, monodromy="exact", variant="consistent")
    with pytest.raises(pdw.InvalidInputError, match="monodromy"):
        pdw.continue_gait(P, "k_hip", 0.97, monodromy="adjoint")
