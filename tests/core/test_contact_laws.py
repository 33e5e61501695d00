"""The family of normal contact laws (derive/contact_laws.py, pdw.Contact, docs/contact_laws.md).

* each compiled law equals its textbook formula, typed here independently in SymPy, at random
  depths, rates and approach speeds, with its partial derivatives;
* a point mass dropped on Lankarani-Nikravesh and Flores bounces back with the coefficient of
  restitution it was set to, within the tolerance stated for each law's range of e;
* every integrator runs every law, the selection reaches the kernel, a scene's [contact] table
  runs as simulate(contact=), and the default is the paper's kernel.
"""
import zlib

import numpy as np
import pytest
import sympy as sp

import pdw
from pdw.analysis.numerics.calibration import drop_test
from pdw.core import _core, _layout
from pdw.core.contact import Contact
from pdw.core.model import kernel_index, parameter_vector

d, dd, vin, k, c, e, vmin = sp.symbols("delta deltad v_in k c e v_min", real=True)
# the textbook laws (Hunt & Crossley 1975 as the paper prints it, Hertz, Kelvin-Voigt,
# Lankarani & Nikravesh 1990, Flores et al. 2011), all clamped at 0 where damped
v0 = sp.Max(vin, vmin)
TEXTBOOK = {
    "hunt_crossley": sp.Max(k * d ** sp.Rational(3, 2) + c * d ** sp.Rational(3, 2) * dd, 0),
    "hertz": k * d ** sp.Rational(3, 2),
    "kelvin_voigt": sp.Max(k * d + c * dd, 0),
    "lankarani_nikravesh": sp.Max(k * d ** sp.Rational(3, 2)
                                  * (1 + 3 * (1 - e ** 2) / 4 * dd / v0), 0),
    "flores": sp.Max(k * d ** sp.Rational(3, 2) * (1 + 8 * (1 - e) / (5 * e) * dd / v0), 0),
}
PARAMS = {"hunt_crossley": dict(k=1e5, d=1e6), "hertz": dict(k=2e5),
          "kelvin_voigt": dict(k=3e4, d=400.0), "lankarani_nikravesh": dict(k=1e5, e=0.7),
          "flores": dict(k=1e5, e=0.4)}
KIN = {n: i for i, n in enumerate(_layout.KIN)}
CON = {n: i for i, n in enumerate(_layout.CONTACT)}


def _compiled(law, variant, delta, deltad, v_in, partials):
    contact = Contact(law, **PARAMS[law])
    p = contact.vector(parameter_vector(contact.parameters(pdw.Params.paper())))
    n = len(delta)
    kin = np.zeros((n, 2 * len(_layout.KIN)))
    kin[:, KIN["y_D"]] = -delta
    kin[:, KIN["v_y"]] = -deltad
    kin[:, KIN["v_in"]] = v_in
    flags = np.tile(np.array([1, 0], dtype=np.intc), (n, 1))
    out = np.zeros((n, 2 * len(_layout.CONTACT)))
    _core.contact_batch(kernel_index(variant, None, law), kin, flags, p, out, partials)
    return out


@pytest.mark.parametrize("variant", _layout.VARIANTS)
@pytest.mark.parametrize("law", _layout.NORMAL_LAWS)
def test_law_equals_textbook_formula(law, variant):
    rng = np.random.default_rng(zlib.crc32(("%s/%s" % (law, variant)).encode()))
    n = 400
    delta = rng.uniform(1e-6, 0.02, n)
    deltad = rng.uniform(-1.5, 1.5, n)               # loading and unloading, both clamps
    v_in = np.where(rng.random(n) < 0.2, rng.uniform(0, 0.005, n), rng.uniform(0.05, 1.5, n))
    prm = PARAMS[law]
    subs = {k: prm["k"], c: prm.get("d", 0.0), e: prm.get("e", 1.0), vmin: 0.01}
    F = TEXTBOOK[law].subs(subs)
    f = sp.lambdify((d, dd, vin), F, "numpy")
    dfd = sp.lambdify((d, dd, vin), sp.diff(F, d), "numpy")
    dfdd = sp.lambdify((d, dd, vin), sp.diff(F, dd), "numpy")
    out = _compiled(law, variant, delta, deltad, v_in, True)
    want = np.broadcast_to(f(delta, deltad, v_in), (n,)).astype(float)
    scale = np.maximum(np.abs(want), 1e-9)
    assert np.all(np.abs(out[:, CON["F_n"]] - want) <= 1e-12 * scale + 1e-12)
    # the partials where the force is positive (off the clamp's kink)
    on = want > 1e-6
    assert on.sum() > 100 and (~on).sum() > 0 or law == "hertz"
    for name, fn in (("dFn_ddelta", dfd), ("dFn_ddeltad", dfdd)):
        w = np.broadcast_to(fn(delta, deltad, v_in), (n,)).astype(float)
        got = out[:, CON[name]]
        assert np.allclose(got[on], w[on], rtol=1e-11, atol=1e-9), name
    # the second foot (swing) feels nothing
    assert np.all(out[:, len(_layout.CONTACT) + CON["F_n"]] == 0)


# Stated accuracy of the restitution of a point-mass drop (v_in = 0.3 m/s, no gravity):
# Lankarani-Nikravesh is meant for e close to 1, Flores for the whole range.
DROP_TOL = {
    "lankarani_nikravesh": [((0.9, 1.0), 0.015), ((0.8, 0.9), 0.05)],
    "flores": [((0.5, 1.0), 0.035), ((0.3, 0.5), 0.05)],
}


@pytest.mark.parametrize("law", sorted(DROP_TOL))
def test_drop_test_gives_the_set_restitution(law):
    for (lo, hi), tol in DROP_TOL[law]:
        for e_set in np.linspace(lo, hi, 4):
            drop = drop_test(Contact(law, e=float(e_set)), v_in=0.3)
            assert abs(drop.e - e_set) <= tol, (law, e_set, drop.e)


def test_drop_test_limits_of_the_laws():
    """Outside its range Lankarani-Nikravesh cannot dissipate enough (e -> 0 still bounces at
    about 2/3); Hertz is elastic; Hunt-Crossley's restitution falls with the impact speed."""
    assert drop_test(Contact("lankarani_nikravesh", e=0.05)).e > 0.6
    assert abs(drop_test("hertz").e - 1) < 1e-6
    e_slow, e_fast = (drop_test("hunt_crossley", v_in=v).e for v in (0.05, 0.5))
    assert 0 < e_fast < e_slow < 1


def test_flores_with_e_one_is_hertz():
    a = _compiled("flores", "paper", np.array([1e-3, 5e-3]), np.array([0.3, -0.2]),
                  np.array([0.5, 0.5]), False)
    # e = 1 through the contact's vector: the hysteresis factor vanishes
    contact = Contact("flores", k=2e5, e=1.0)
    p = contact.vector(parameter_vector(contact.parameters(pdw.Params.paper())))
    kin = np.zeros((1, 2 * len(_layout.KIN)))
    kin[0, KIN["y_D"]], kin[0, KIN["v_y"]], kin[0, KIN["v_in"]] = -4e-3, 0.7, 0.2
    out = np.zeros((1, 2 * len(_layout.CONTACT)))
    _core.contact_batch(kernel_index("paper", None, "flores"), kin,
                        np.array([[1, 0]], dtype=np.intc), p, out)
    assert out[0, CON["F_n"]] == pytest.approx(2e5 * 4e-3 ** 1.5, rel=1e-14)
    assert a[0, CON["F_n"]] > 1e5 * 1e-3 ** 1.5       # loading: damping adds


@pytest.mark.parametrize("method", pdw.METHODS)
def test_every_method_runs_every_law(method):
    """A short run from the paper's start (the first touch-down at ~0.34 s captures an
    approach speed) under every law; a law changes the trajectory, the default does not."""
    P = pdw.Params.paper_steady()
    kw = dict(params=P, t_end=0.45, method=method, dt=5e-5 if method != "cdm" else 1e-4,
              integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=0))
    ref = pdw.simulate(**kw)
    assert np.array_equal(pdw.simulate(contact=Contact(), **kw).x_final, ref.x_final)
    for law, prm in (("hertz", {}), ("kelvin_voigt", dict(k=7.3e3, d=150.0)),
                     ("lankarani_nikravesh", dict(e=0.8)), ("flores", dict(e=0.3))):
        r = pdw.simulate(contact=Contact(law, **prm), **kw)
        assert r.walked and r.event_counts["touch_down"] >= 1, (law, r.summary())
        assert r.contact.normal == law
        assert np.max(np.abs(r.x_final - ref.x_final)) > 1e-6, law


def test_scene_contact_table_runs_as_simulate():
    text = ('preset = "paper_steady"\n[integrator]\nmethod = "rodas4"\n[stop]\nt_end = 0.5\n'
            '[record]\nevery = 0\n[contact]\nnormal = "flores"\ne = 0.3\n')
    scene = pdw.Scene.from_toml(text)
    assert pdw.Scene.from_toml(scene.to_toml()) == scene
    a = scene.run()
    b = pdw.simulate(params=pdw.Params.paper_steady(), t_end=0.5, method="rodas4",
                     contact=dict(normal="flores", e=0.3), record=pdw.Record(every=0))
    assert np.array_equal(a.x_final, b.x_final)
    with pytest.raises(pdw.InvalidInputError, match="contact"):
        pdw.Scene.from_toml('[contact]\nnormal = "flores"\n')        # e is required
    with pytest.raises(pdw.InvalidInputError, match="contact.d"):
        pdw.Scene.from_toml('[contact]\nnormal = "hertz"\nd = 3.0\n')  # hertz has no damping


@pytest.mark.parametrize("bad, match", [
    (dict(normal="coulomb"), "contact.normal"), (dict(friction="dahl"), "contact.friction"),
    (dict(normal="flores", e=1.5), "contact.e"), (dict(normal="flores", e=0.0), "contact.e"),
    (dict(normal="kelvin_voigt", k=-1.0), "contact.k"), (dict(normal="hertz", e=0.5), "contact.e"),
    (dict(normal="flores", e=0.5, v_in_min=0.0), "contact.v_in_min"), (dict(kk=1), "kk"),
])
def test_bad_contact_is_named(bad, match):
    with pytest.raises(pdw.InvalidInputError, match=match):
        pdw.simulate(t_end=0.01, contact=bad)


def test_calibration_matches_sink_and_restitution():
    """Calibrated at a given landing: Kelvin-Voigt carries the weight at the Hunt-Crossley
    sink; Kelvin-Voigt and Flores drop with the Hunt-Crossley restitution; Lankarani-Nikravesh
    cannot dissipate that much (flagged). Flores has Hunt-Crossley's form, so matched at the
    landing speed its damping k chi / v_in is Hunt-Crossley's d_n."""
    from pdw.analysis.numerics.calibration import Landing, calibrate
    P = pdw.Params.paper_steady()
    cal = calibrate(P, landing=Landing(speed=0.7, mass=0.45, n=1))
    kv = cal.contacts["kelvin_voigt"]
    assert kv.k * cal.sink["kelvin_voigt"] == pytest.approx(P.weight, rel=1e-12)
    assert cal.sink["hertz"] == pytest.approx((P.weight / P.k_n) ** (2 / 3), rel=1e-12)
    for law in ("kelvin_voigt", "flores"):
        assert cal.reachable[law] and abs(cal.e_drop[law] - cal.e_target) < 1e-6, law
    assert not cal.reachable["lankarani_nikravesh"] and cal.e_drop["lankarani_nikravesh"] > 0.6
    e = cal.contacts["flores"].e
    assert P.k_n * 8 * (1 - e) / (5 * e) / 0.7 == pytest.approx(P.d_n, rel=1e-5)


def test_approach_speed_is_captured_at_touch_down():
    """cdm with Flores: at each touch-down the foot's -v_y is stored; the recorded normal force
    through the following stance is the Flores formula with that v_in (and none other)."""
    P = pdw.Params.paper_steady()
    c = Contact("flores", e=0.3)
    r = pdw.simulate(params=P, contact=c, t_end=1.2, dt=1e-4, method="cdm")
    tds = [ev for ev in r.events if ev.kind == "touch_down"]
    assert len(tds) >= 2
    chi = 8 * (1 - 0.3) / (5 * 0.3)
    for ev in tds:
        n = int(round(ev.t / r.dt))
        assert r.t[n] == pytest.approx(ev.t)
        j = ev.leg - 1
        v_in = -pdw.contact_forces(r.x[n], P, flags=(1, 1)).v_y[j]
        assert v_in > 0.01
        # samples n+1 .. n+200 of this stance, the foot penetrating
        idx = np.arange(n + 1, n + 200)
        cs = pdw.contact_forces(r.x[idx], P, flags=(1, 1))
        delta, deltad = -cs.y_D[:, j], -cs.v_y[:, j]
        pen = (delta > 0) & (r.flags[idx, j] == 1)
        want = np.maximum(P.k_n * delta ** 1.5 * (1 + chi * deltad / v_in), 0.0)
        assert pen.sum() > 50
        assert np.allclose(r.Fn[idx[pen], j], want[pen], rtol=1e-10, atol=1e-9)
        other = np.maximum(P.k_n * delta ** 1.5 * (1 + chi * deltad / (1.2 * v_in)), 0.0)
        assert not np.allclose(r.Fn[idx[pen], j], other[pen], rtol=1e-3)


def test_flores_fixed_point_reproduces_itself_under_simulate():
    """find_gait with Flores carries the approach speeds through the section (the trailing
    foot's is its 7th coordinate, v_in1): its fixed point is the continuous run's periodic
    orbit. From the fixed point's state (on a period-1 orbit the trailing foot's approach speed
    is the landing one), a continuous run returns to the same section point at every
    touch-down; with both feet re-initialised it does not."""
    from pdw.analysis.stepmap import limit_cycle as LC
    from pdw.core.model import contact_forces
    c = Contact("flores", e=0.18)
    P = pdw.Params.paper_steady()
    g = LC.find_gait(P, contact=c, workers=2)
    z, tol = g.details["z"], 1e-9
    assert g.details["residual"] < tol and len(z) == 7
    x0 = LC.embed(z, P, c)
    v2 = -float(contact_forces(x0, P, flags=(1, 1)).v_y[1])
    assert v2 > 0.5                                  # a landing, not a resting foot
    assert z[6] == pytest.approx(v2, abs=1e-8)
    z = z[:6]

    def returns(a0):
        r = pdw.simulate(x0, t_end=3.0, params=P, method="rodas4", flags0=(1, 1), contact=c,
                         integrator=pdw.Integrator(**LC.TIGHT), record=pdw.Record(every=1),
                         approach_speeds0=a0)
        out = []
        for e in (e for e in r.events if e.kind == "touch_down"):
            i = int(np.searchsorted(r.t, e.t))
            out.append(np.max(np.abs(LC.section_coordinates(r.x[i], e.leg) - z)))
        return np.array(out)

    d = returns((v2, v2))
    assert len(d) >= 4 and d[0] < 10 * tol and d.max() < 1e-7, d
    assert returns(None)[0] > 1e-2                   # the re-initialised section is far off
