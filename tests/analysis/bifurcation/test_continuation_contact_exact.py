"""continue_gait(monodromy="exact") and the bifurcation cross-check for every contact law with
Coulomb friction (issue #24; before, both used the default law only and refused a Contact)."""
import numpy as np
import pytest

import pdw
from pdw.analysis.bifurcation.continuation import continue_gait
from pdw.analysis.stepmap.gait_maps import multiplier_gap

pytest.importorskip("scipy")
P0 = pdw.Params.paper_steady()


@pytest.mark.slow
@pytest.mark.parametrize("contact, axis, stop, step, tol", [
    (pdw.Contact("kelvin_voigt"), "contact.d", 110.0, 0.3, 1e-3),
    (pdw.Contact("flores", e=0.18), "contact.e", 0.2, 0.004, 2e-4),
    (pdw.Contact("lankarani_nikravesh", e=0.01), "contact.k", 1.2e5, 4e3, 2e-4),
], ids=["kelvin_voigt", "flores", "lankarani_nikravesh"])
def test_exact_monodromy_along_a_contact_branch_of_every_law(contact, axis, stop, step, tol):
    """Two points in a contact parameter of each law, with the exact monodromy (the law's own
    variational equations, `options["contact"]` passed through) and with differences: the same
    branch (values to 1e-6 of the step, z to 1e-7), multipliers within the differences'
    resolution ``tol`` (2e-4; Kelvin-Voigt 1e-3: its map has kinks near the gait, the flip
    multiplier -1.44935 exact against -1.44971 by differences, measured), the gait carries its
    point's contact, and the cross-check at a point runs the variational equations of that
    law."""
    kw = dict(step=step, max_points=2, options=dict(contact=contact), workers=2)
    a = continue_gait(P0, axis, stop, monodromy="exact", **kw)
    b = continue_gait(P0, axis, stop, **kw)
    assert len(a) == len(b) == 2
    np.testing.assert_allclose(a.values, b.values, atol=1e-6 * step)
    np.testing.assert_allclose(a.z, b.z, atol=1e-7)
    for ma, mb in zip(a.multipliers, b.multipliers):
        assert multiplier_gap(ma, mb) < tol
    prob = b.problem
    mu = prob.coord(float(b.values[-1]))
    gap, note = prob.crosscheck(b.z[-1], mu, b.multipliers[-1])
    assert prob.last_check == "variational" and gap < tol and note == ""
    g = prob.gait(b.z[-1], mu, prob.evaluate(b.z[-1], mu), b.multipliers[-1])
    assert getattr(g.details["options"]["contact"], axis[len("contact."):]) == b.values[-1]


def test_exact_monodromy_refuses_lugre_with_the_reason():
    with pytest.raises(pdw.InvalidInputError, match="Coulomb friction"):
        continue_gait(P0, "gamma", 0.03, monodromy="exact",
                      options=dict(contact=pdw.Contact(friction="lugre")))


@pytest.mark.slow
def test_a_fold_curve_with_both_parameters_contact_ones():
    """The fold of paper_steady(d_hip = 0.014) in d_n (2.54e6, docs/continuation.md) followed in
    the contact's own parameters, "contact.d" and then "contact.k" (the default law: they are
    d_n and k_n): the same curve as in (d_n, k_n), point for point at k = 1.02e5 (to 1e-6), and
    the curve's axes carry the law's units."""
    from pdw.analysis.bifurcation.codim2 import continue_bifurcation
    P = pdw.Params.paper_steady(d_hip=0.014)
    curves = []
    for p1, p2 in (("d_n", "k_n"), ("contact.d", "contact.k")):
        b = continue_gait(P, p1, 1e8, log=True, max_points=30, workers=2)
        fold = b.of_kind("fold")[0]
        curves.append(continue_bifurcation(fold, p2, 1.02e5, step=500.0, fd_step=1e-4,
                                           max_points=12, at=[1.02e5]))
    a, c = curves
    assert c.parameters == ("contact.d", "contact.k")
    assert c.units == ("N s/m^2.5", "N/m^1.5")
    assert "reached stop" in a.stop_reason and "reached stop" in c.stop_reason
    assert abs(c.values[-1, 0] / a.values[-1, 0] - 1.0) < 1e-6
    assert c.values[-1, 1] == a.values[-1, 1] == 1.02e5
