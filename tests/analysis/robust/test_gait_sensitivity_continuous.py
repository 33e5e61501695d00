"""The compliant model's gait sensitivity norm from the exact linearization (issue 22 item 5):
the touch-down map's variational equations with the ground heights under the trailing and the
landing foot as parameters (pdw.analysis.stepmap.variational_ground), against central
differences of the compiled map on a stepped pdw.Ground (docs/robustness.md)."""
import numpy as np
import pytest

import pdw
from pdw.analysis.robust import robustness_continuous as RC
from pdw.analysis.stepmap import variational as V
from pdw.analysis.stepmap import variational_ground as VG

P = pdw.Params.paper_steady()
NAMES = ("step_time", "step_length")


@pytest.fixture(scope="module")
def cgait():
    return pdw.find_gait(P)


@pytest.fixture(scope="module")
def G(cgait):
    return pdw.gait_sensitivity(P, model="continuous", gait=cgait, indicators=NAMES,
                                fd_step=1e-5)


def test_ground_step_jacobian_keeps_the_map_and_its_monodromy(cgait):
    """The augmented state leaves the map alone: z' is the gait's fixed point, T and L its
    period and step length, M the compiled engine's exact monodromy (the two engines agree to
    ~1e-7, docs/continuation.md)."""
    z0 = np.asarray(cgait.details["z"], dtype=float)
    J = VG.ground_step_jacobian(z0, P)
    assert np.abs(J["z"] - z0).max() < 1e-8
    assert J["T"] == pytest.approx(cgait.period, abs=1e-9)
    assert J["L"] == pytest.approx(cgait.step_length, abs=1e-9)
    M = V.step_jacobian(z0, P)["M"]
    assert np.abs(J["M"] - M).max() < 1e-5 * np.abs(M).max()
    assert J["B"].shape == (6, 2) and J["dT"].shape == J["dL"].shape == (8,)
    # the landing height moves the touch-down time by 1/(grad g . f) (the hybrid model's dT/dh)
    assert J["dT"][7] < 0 and abs(J["B"][:, 1]).max() > 1.0


def test_exact_system_matches_central_differences_of_the_compiled_map(cgait, G):
    """A, B, C, D (x = (z, e_prev), input e) against central differences (h = 1e-5) of the
    compiled rodas4 map (rtol 1e-10) on Ground.steps([-L/2, L/2], [e_prev, e]). The map is
    reproducible to ~1e-10, so the differences carry ~1e-10 / h = 1e-5 of noise, plus an h^2
    truncation measured at ~1e-6 relative (the FD norm moves by 1e-5 between h = 1e-5 and 2e-6
    at rtol 1e-12, toward the exact one): tolerance 1e-4 + 1e-5 |J|. Measured: largest
    |exact - fd| 6e-4 on entries up to 590 (the trailing height's column), 1.3e-5 elsewhere.
    Dropping the parameter part of the lift-off's saltation moves that column by 0.16 and
    dropping df/dh_trail by 3, so the test can fail."""
    assert G.method == "exact"
    z0 = np.asarray(cgait.details["z"], dtype=float)
    Jf = RC._jacobian_fd(P, z0, NAMES, RC.edge_at(cgait), 1e-5, {})
    fd = RC._system(Jf, len(z0))
    for name, ex, f in zip("ABCD", (G.A, G.B, G.C, G.D), fd):
        assert ex.shape == f.shape, name
        err = np.abs(ex - f) / (1e-4 + 1e-5 * np.abs(f))
        assert err.max() < 1.0, (name, err.max())
    # the disturbance acts: a floor change moves the next section point and the indicators
    assert np.abs(G.B).max() > 10 and np.abs(G.D).min() > 0.5


def test_exact_norm_matches_the_finite_difference_norm(G):
    """The norm against the cross-check's (h = 1e-5: measured 1.05e-5 relative; the exact norm
    is 14.912423 at rtol 1e-10, 1e-11 and 1e-12 alike, the FD one 14.912416 at h = 2e-6 with
    the map at rtol 1e-12)."""
    assert G.check["fd_step"] == 1e-5
    assert G.check["rel_diff"] < 1e-4
    assert G.norm == pytest.approx(G.check["fd_norm"], rel=1e-4)
    assert set(G.per_indicator) == set(NAMES)
    assert G.norm ** 2 == pytest.approx(sum(v ** 2 for v in G.per_indicator.values()),
                                        rel=1e-9)


def test_a_disagreeing_cross_check_warns(cgait, monkeypatch):
    """An exact Jacobian that is off by 1 % in the landing height's column: the cross-check
    warns (the threshold REL_CHECK = 1e-3)."""
    true = RC._jacobian_fd

    def off(params, z0, names, options):
        J = true(params, z0, names, RC.edge_at(cgait), 1e-5, options)
        J[:, -1] *= 1.01
        return J

    monkeypatch.setattr(RC, "_jacobian_exact", off)
    with pytest.warns(UserWarning, match="not resolved"):
        G = pdw.gait_sensitivity(P, model="continuous", gait=cgait, indicators=NAMES,
                                 fd_step=1e-5)
    assert G.check["rel_diff"] > RC.REL_CHECK


def test_bad_method_and_unsupported_variant_are_refused(cgait):
    with pytest.raises(pdw.InvalidInputError, match="method"):
        pdw.gait_sensitivity(P, model="continuous", gait=cgait, method="newton")
    with pytest.raises(pdw.InvalidInputError, match="method='fd'"):
        pdw.gait_sensitivity(P, model="continuous", gait=cgait, variant="consistent")


@pytest.mark.slow
def test_exact_system_with_approach_speeds_matches_central_differences():
    """Lankarani-Nikravesh (e = 0.01): seven section coordinates (the trailing foot's approach
    speed), the state carrying (v_in1, v_in2) before the two heights; the stance foot rises and
    re-enters within the step. Measured: the norm 15.626, the differences' (h = 1e-5) 6.5e-6
    from it, the largest |exact - fd| 6.7e-4 on entries up to 520."""
    c = pdw.Contact("lankarani_nikravesh", e=0.01)
    g = pdw.find_gait(P, contact=c, workers=2)
    z0 = np.asarray(g.details["z"], dtype=float)
    assert len(z0) == 7
    G = pdw.gait_sensitivity(P, model="continuous", gait=g, indicators=NAMES, contact=c,
                             fd_step=1e-5)
    assert G.method == "exact" and G.check["rel_diff"] < 1e-4
    fd = RC._system(RC._jacobian_fd(P, z0, NAMES, RC.edge_at(g), 1e-5, dict(contact=c)), 7)
    for name, ex, f in zip("ABCD", (G.A, G.B, G.C, G.D), fd):
        err = np.abs(ex - f) / (1e-4 + 1e-5 * np.abs(f))
        assert err.max() < 1.0, (name, err.max())
