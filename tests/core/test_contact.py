"""Issue 26, items 4 and 7: `pdw.Contact`'s parameters.

Item 7: LuGre's parameters took ``True`` (as 1.0) and ``"1e5"`` (parsed); the normal laws'
already refused both. Item 4: ``Contact("kelvin_voigt")`` without k, d took the Hunt-Crossley
numbers (k_n = 1e5 N/m^1.5, d_n = 1e6 N s/m^2.5) and read them as N/m and N s/m (a ground
about 14 times stiffer and 9000 times more damped than the calibrated one): rodas4 ground for
minutes and diverged, cdm diverged at once without the promised `StepSizeWarning`.
"""
import warnings

import numpy as np
import pytest

import pdw
from pdw.core.contact import LUGRE_PARAMETERS

#: the documented defaults (docs/contact_laws.md; `pdw.core.contact.KELVIN_VOIGT_DEFAULTS`)
KELVIN_VOIGT_DEFAULTS = {"k": 7318.0, "d": 112.2}


@pytest.mark.parametrize("name", list(LUGRE_PARAMETERS))
@pytest.mark.parametrize("bad", [True, False, "1e5", b"1", 1 + 0j, None.__class__])
def test_lugre_parameters_are_real_numbers(name, bad):
    with pytest.raises(pdw.InvalidInputError, match="contact." + name):
        pdw.Contact(friction="lugre", **{name: bad})


def test_lugre_numbers_still_accepted():
    c = pdw.Contact(friction="lugre", sigma0=np.float64(2e5), sigma1=300, mu_s=0.6)
    assert (c.sigma0, c.sigma1, c.mu_s) == (2e5, 300.0, 0.6)


# --- item 4: Kelvin-Voigt's own numbers -------------------------------------------------------

def test_kelvin_voigt_defaults_are_its_own_calibrated_numbers_and_show():
    from pdw.core import contact
    assert contact.KELVIN_VOIGT_DEFAULTS == KELVIN_VOIGT_DEFAULTS
    c = pdw.Contact("kelvin_voigt")
    assert (c.k, c.d) == (KELVIN_VOIGT_DEFAULTS["k"], KELVIN_VOIGT_DEFAULTS["d"]) == (7318.0, 112.2)
    assert "k=7318.0" in repr(c) and "d=112.2" in repr(c)
    assert c == pdw.Contact("kelvin_voigt", k=7318.0, d=112.2)
    assert c.as_dict() == {"normal": "kelvin_voigt", "friction": "coulomb", "k": 7318.0,
                           "d": 112.2}
    # one given, the other defaulted
    assert pdw.Contact("kelvin_voigt", k=5e3).d == 112.2
    # Params' Hunt-Crossley numbers (other units) never reach the law
    p = pdw.Params.paper().replace(k_n=3e5, d_n=2e6)
    assert c.parameters(p).k_n == 7318.0 and c.parameters(p).d_n == 112.2


def test_kelvin_voigt_default_stiffness_is_the_static_sink_identity():
    """k = W / delta_s with delta_s = (W / k_n)^(2/3) the Hunt-Crossley sink of
    `Params.paper_steady()` (docs/contact_laws.md), to the 4 figures stored."""
    P = pdw.Params.paper_steady()
    k = P.weight / (P.weight / P.k_n) ** (2.0 / 3.0)
    assert KELVIN_VOIGT_DEFAULTS["k"] == pytest.approx(k, rel=1e-4)


def test_kelvin_voigt_default_damping_matches_the_drop_test_restitution():
    """The drop test at the typical landing (0.710 m/s, 0.455 kg, docs/contact_laws.md) gives
    Hunt-Crossley's restitution with the default Kelvin-Voigt numbers; the inherited ones
    (Params.k_n, d_n read as N/m, N s/m) give another ground (e = 0.227)."""
    from pdw.analysis.numerics.calibration import drop_test
    e_hc = drop_test(pdw.Contact(), v_in=0.710, mass=0.455).e
    e_kv = drop_test(pdw.Contact("kelvin_voigt"), v_in=0.710, mass=0.455).e
    assert e_kv == pytest.approx(e_hc, abs=0.01)
    inherited = pdw.Contact("kelvin_voigt", k=pdw.Params.paper().k_n, d=pdw.Params.paper().d_n)
    assert abs(drop_test(inherited, v_in=0.710, mass=0.455).e - e_hc) > 0.05


@pytest.mark.slow
def test_kelvin_voigt_defaults_are_what_calibrate_computes():
    from pdw.analysis.numerics.calibration import calibrate
    kv = calibrate(pdw.Params.paper_steady()).contacts["kelvin_voigt"]
    assert kv.k == pytest.approx(KELVIN_VOIGT_DEFAULTS["k"], rel=1e-4)
    assert kv.d == pytest.approx(KELVIN_VOIGT_DEFAULTS["d"], rel=1e-3)


def test_default_kelvin_voigt_walks_the_typical_gait_under_cdm():
    """The issue's run: cdm diverged at 0.2 ms with the inherited numbers."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", pdw.StepSizeWarning)
        r = pdw.simulate(params=pdw.Params.paper_steady(), contact=pdw.Contact("kelvin_voigt"),
                         record=pdw.Record(every=0))
    assert r.status == "walked" and r.n_gait_steps >= 4


def test_a_stiff_kelvin_voigt_ground_gets_the_step_size_warning():
    """k = 1e5 N/m, d = 1e6 N s/m diverges at 0.2 ms under cdm at dt = 1e-4: the check now
    warns (it estimated 4.9e-4 s before: the law's numbers were read as Hunt-Crossley's); its
    limit is below the measured edge (5e-6 walks 0.3 s, 1e-5 diverges)."""
    c = pdw.Contact("kelvin_voigt", k=1e5, d=1e6)
    with pytest.warns(pdw.StepSizeWarning, match="kelvin_voigt"):
        r = pdw.simulate(t_end=0.01, contact=c, record=pdw.Record(every=0),
                         limits=pdw.Limits(on_failure="return"))
    assert r.status == "diverged"
    with pytest.raises(pdw.StepSizeError):
        pdw.simulate(t_end=0.01, contact=c, integrator=pdw.Integrator(check_step="error"))
    from pdw.sim.stepsize import step_limit
    lim = step_limit(pdw.Params.paper(), "cdm", contact=c)
    assert lim.dt_max < 5e-6
    ok = pdw.simulate(t_end=0.01, dt=lim.dt_max, contact=c,
                      integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=0))
    assert ok.status == "walked"


def test_the_calibrated_kelvin_voigt_limit_is_unchanged():
    """At its calibrated numbers the law's limit is the fitted one (the scaling is 1)."""
    from pdw.sim.stepsize import step_limit
    from pdw.sim.stepsize_laws import LAW_CALIBRATION
    P = pdw.Params.paper()
    kv = step_limit(P, "cdm", contact=pdw.Contact("kelvin_voigt"))
    base = step_limit(P.replace(k_n=7318.0, d_n=112.2), "cdm")
    assert kv.law_factor == LAW_CALIBRATION["paper"]["kelvin_voigt"]["cdm"]
    assert kv.dt_max == pytest.approx(base.dt_max * kv.law_factor, rel=1e-12)


@pytest.mark.parametrize("kw", [dict(k="1e5"), dict(k=True), dict(d=1j),
                                dict(normal="flores", e="0.5")])
def test_contact_parameters_must_be_real_numbers(kw):
    """Contact(k="1e5") was float("1e5"), Contact(k=True) a stiffness of 1."""
    with pytest.raises(pdw.InvalidInputError, match="contact." + [k for k in kw if k != "normal"][0]):
        pdw.Contact(**kw)
