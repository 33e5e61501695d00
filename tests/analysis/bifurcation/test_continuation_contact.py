"""Continuation over the contact law's parameters: ``"contact.d"``, ``"contact.k"``, ... (issue #24;
docs/continuation.md "Contact parameters"). Kelvin-Voigt's k and d are the Contact's (N/m,
N s/m), never Params' k_n, d_n: continuing it in d_n varied nothing."""
import numpy as np
import pytest

import pdw
from pdw.analysis.bifurcation.codim2 import AugmentedProblem
from pdw.analysis.bifurcation.continuation import continue_gait
from pdw.analysis.stepmap.gait_maps import ContinuousProblem

P0 = pdw.Params.paper_steady()
KV = pdw.Contact("kelvin_voigt", d=100.0)


@pytest.fixture(scope="module")
def kv():
    """Kelvin-Voigt (k 7318 N/m) from d = 100 towards 104 N s/m: three points."""
    return continue_gait(P0, "contact.d", 104.0, step=2.0, max_points=3,
                         options=dict(contact=KV), workers=2)


def test_contact_axes_are_named_with_the_allowed_ones():
    assert KV.axes() == ("contact.k", "contact.d")
    assert pdw.Contact("flores", e=0.2, friction="lugre").axes() == (
        "contact.k", "contact.e", "contact.v_in_min", "contact.sigma0", "contact.sigma1",
        "contact.sigma2", "contact.mu_s", "contact.mu_c", "contact.v_s")
    with pytest.raises(pdw.InvalidInputError, match="allowed: contact.k, contact.d"):
        ContinuousProblem(P0, "contact.e", options=dict(contact=KV))
    with pytest.raises(pdw.InvalidInputError, match=r"contact \(contact.k, contact.d\)"):
        ContinuousProblem(P0, "d_nn", options=dict(contact=KV))
    with pytest.raises(pdw.InvalidInputError, match="rigid ground"):
        continue_gait(P0, "contact.d", 1.0, model="hybrid")
    with pytest.raises(pdw.InvalidInputError, match="params_of"):
        continue_gait(P0, "contact.d", 1.0, params_of=lambda v: P0, value=1.0)
    # the d_n refusal points at the axis that works, with its unit
    with pytest.raises(pdw.InvalidInputError, match=r"not read by the kelvin_voigt law.*"
                                                    r"'contact.d' \(N s/m\)"):
        continue_gait(P0, "d_n", 110.2, options=dict(contact=KV))
    with pytest.raises(pdw.InvalidInputError, match="not read by the hertz law"):
        continue_gait(P0, "d_n", 110.2, options=dict(contact=pdw.Contact("hertz")))


def test_contact_values_and_units():
    assert KV.axis_value("contact.d", P0) == 100.0 and KV.axis_unit("contact.d") == "N s/m"
    hc = pdw.Contact()
    assert hc.axis_value("contact.d", P0) == P0.d_n and hc.axis_unit("contact.d") == "N s/m^2.5"
    fl = pdw.Contact("flores", e=0.2)
    assert fl.axis_value("contact.v_in_min", P0) == 0.01
    assert fl.with_axis("contact.e", 0.5).e == 0.5
    with pytest.raises(pdw.InvalidInputError, match="contact.e = 1.5 is out of range"):
        fl.with_axis("contact.e", 1.5)
    lg = pdw.Contact(friction="lugre")
    assert lg.axis_value("contact.mu_s", P0) == P0.mu_s and lg.axis_unit("contact.v_s") == "m/s"


def test_kelvin_voigt_branch_in_contact_d_moves_the_gait(kv):
    """Each point is the gait of Contact("kelvin_voigt", d=value): find_gait there agrees; the
    flip multiplier moves along the branch (in d_n it stayed -1.44936 at every point)."""
    assert kv.parameter == "contact.d" and len(kv) == 3
    assert kv.values[0] == 100.0 and kv.values[-1] > 100.5
    flip = np.min(np.real(kv.multipliers[:, :2]), axis=1)
    assert np.all(np.abs(np.diff(flip)) > 1e-3)
    g = pdw.find_gait(P0, contact=pdw.Contact("kelvin_voigt", d=float(kv.values[-1])),
                      guess=kv.z[-1], workers=2)
    np.testing.assert_allclose(g.details["z"], kv.z[-1], atol=1e-7)
    assert np.min(np.abs(g.multipliers - flip[-1])) < 1e-4
    assert kv.settings["unit"] == "N s/m"


def test_contact_d_of_the_default_law_is_d_n():
    """On the paper's Hunt-Crossley law contact.d starts at Params.d_n and is d_n: the same
    branch (values, z, multipliers) as continuing d_n itself."""
    a = continue_gait(P0, "contact.d", P0.d_n * 1.1, step=0.05 * P0.d_n, max_points=2,
                      workers=2)
    b = continue_gait(P0, "d_n", P0.d_n * 1.1, step=0.05 * P0.d_n, max_points=2, workers=2)
    assert a.values[0] == P0.d_n and len(a) == len(b) == 2
    np.testing.assert_allclose(a.values, b.values, rtol=1e-12)
    np.testing.assert_allclose(a.z, b.z, atol=1e-9)
    np.testing.assert_allclose(a.multipliers, b.multipliers, atol=1e-6)
    assert a.settings["unit"] == "N s/m^2.5"


def test_branch_file_round_trip_keeps_the_contact_axis(tmp_path, kv):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    b = pdw.load(kv.save(tmp_path / "kv.npz"))
    assert b.parameter == "contact.d" and b.settings["unit"] == "N s/m"
    np.testing.assert_array_equal(b.values, kv.values)
    assert b.problem.axis == "contact.d" and b.problem.contact == KV
    assert b.problem.contact_at(b.problem.coord(102.5)).d == 102.5
    ext = b.extend(104.0, max_points=2, workers=2)           # on, in contact.d
    assert ext.parameter == "contact.d" and ext.values[0] == kv.values[-1] < ext.values[1]
    ax = b.plot()
    assert ax.get_xlabel() == "contact.d [N s/m]"
    plt.close("all")


def test_a_second_parameter_may_be_a_contact_one(kv):
    """The codim-2 problem takes a contact parameter as the second parameter: checked and
    started at the contact's value."""
    prob = kv.problem
    with pytest.raises(pdw.InvalidInputError, match="allowed: contact.k, contact.d"):
        AugmentedProblem(prob, "period_doubling", "contact.e", kv.z[0], prob.coord(100.0))
    aug = AugmentedProblem(prob, "period_doubling", "contact.k", kv.z[0], prob.coord(100.0))
    assert aug.start2 == KV.k and aug.unit == "N/m"
    P, c = aug._at(prob.coord(101.0), 7000.0)
    assert (c.k, c.d) == (7000.0, 101.0) and P == P0


def test_a_continuation_spec_takes_a_contact_parameter():
    from pdw.present import continue_spec
    spec = dict(name="kv", model="continuous", preset="paper_steady", parameter="contact.d",
                stop=110.0, contact={"normal": "kelvin_voigt"})
    assert continue_spec.check_spec(dict(spec), "s.toml")["contact"]["d"] == 112.2
    with pytest.raises(pdw.InvalidInputError, match="allowed: contact.k, contact.d"):
        continue_spec.check_spec(dict(spec, parameter="contact.e"), "s.toml")
    with pytest.raises(pdw.InvalidInputError, match="stop = -1.0 is not a valid contact.d"):
        continue_spec.check_spec(dict(spec, stop=-1.0), "s.toml")
    with pytest.raises(pdw.InvalidInputError, match="couple"):
        continue_spec.check_spec(dict(spec, couple={"k_n": 1.0}), "s.toml")


def test_a_user_event_along_a_contact_branch(kv):
    """events=[Event("step_length", L)] on the Kelvin-Voigt contact.d branch: located between
    its first two points; independently, find_gait with Contact(d = the located value) has
    that step length (to 1e-7 m)."""
    from pdw.analysis.bifurcation.testfunctions import Event
    L = 0.5 * (kv.step_length[0] + kv.step_length[1])
    b = continue_gait(P0, "contact.d", 104.0, step=2.0, max_points=2, locate_tol=1e-9,
                      options=dict(contact=KV), workers=2, events=[Event("step_length", L)])
    (ev,) = b.of_kind("event")
    assert ev.located and kv.values[0] < ev.value < kv.values[1]
    g = pdw.find_gait(P0, contact=KV.with_axis("contact.d", ev.value), guess=kv.z[0],
                      workers=2)
    assert abs(g.step_length - L) < 1e-7
