"""LuGre friction (issue 12, docs/contact_laws.md): the compiled law against its textbook
formula, the bristle dynamics against their closed form, the reset at touch-down, every
integrator, the state layout of results, and what is refused."""
import math

import numpy as np
import pytest
import sympy as sp

import pdw
from pdw.analysis.numerics.calibration import calibrate_lugre
from pdw.core import _core, _layout
from pdw.core.contact import Contact, lugre_stribeck
from pdw.core.model import kernel_index, parameter_vector

KIN = {n: i for i, n in enumerate(_layout.KIN)}
CON = {n: i for i, n in enumerate(_layout.CONTACT)}
NK, NC = len(_layout.KIN), len(_layout.CONTACT)
LUGRE = Contact(friction="lugre", sigma0=1e5, sigma1=45.0, sigma2=0.3, mu_s=0.5, mu_c=0.4,
                v_s=6.6e-4)


def _textbook():
    """F_n (Hunt-Crossley, Eqs. 3, 6), LuGre's dz/dt and friction force, typed from Canudas de
    Wit et al. (1995), per unit normal force, independently of derive/."""
    d, dd, v, z, k, c, s0, s1, s2, ms, mc, vs = sp.symbols(
        "delta deltad v z k d sigma0 sigma1 sigma2 mu_s mu_c v_s", real=True)
    Fn = sp.Max(0, k * d ** sp.Rational(3, 2) + c * d ** sp.Rational(3, 2) * dd)
    g = mc + (ms - mc) * sp.exp(-(v / vs) ** 2)
    zdot = v - s0 * sp.Abs(v) / g * z
    F = -(s0 * z + s1 * zdot + s2 * v) * Fn
    args = (d, dd, v, z, k, c, s0, s1, s2, ms, mc, vs)
    return sp.lambdify(args, Fn), sp.lambdify(args, zdot), sp.lambdify(args, F)


def _stage(contact, params, delta, deltad, v, z, flags=(1, 0)):
    """The compiled contact stage of the LuGre kernel for foot 1 at the given scalars."""
    k = kernel_index("paper", None, contact.normal, contact.friction)
    p = contact.vector(parameter_vector(contact.parameters(params)), None, params)
    n = len(delta)
    kin = np.zeros((n, 2 * NK))
    kin[:, KIN["y_D"]] = -np.asarray(delta)
    kin[:, KIN["v_y"]] = -np.asarray(deltad)
    kin[:, KIN["v_x"]] = v
    kin[:, KIN["z"]] = z
    kin[:, KIN["xi"]] = 1.0          # the paper's gate (Eq. 11): no spring-damper for xi > 0
    out = np.zeros((n, 2 * NC))
    _core.contact_batch(k, kin, np.tile(np.array(flags, dtype=np.intc), (n, 1)), p, out)
    return out


def test_compiled_lugre_equals_textbook_at_random_states():
    params = pdw.Params.paper()
    rng = np.random.default_rng(12)
    n = 400
    delta = rng.uniform(1e-5, 1e-2, n)
    deltad = rng.uniform(-0.5, 0.5, n)
    v = rng.choice([-1, 1], n) * 10 ** rng.uniform(-6, 0, n)     # across the Stribeck range
    z = rng.uniform(-1e-5, 1e-5, n)
    out = _stage(LUGRE, params, delta, deltad, v, z)
    Fn, zdot, F = _textbook()
    lp = LUGRE.lugre_parameters(params)
    a = (params.k_n, params.d_n, lp["sigma0"], lp["sigma1"], lp["sigma2"], lp["mu_s"], lp["mu_c"],
         lp["v_s"])
    want_fn = np.array([float(Fn(*s, *a)) for s in zip(delta, deltad, v, z)])
    want_zd = np.array([float(zdot(*s, *a)) for s in zip(delta, deltad, v, z)])
    want_f = np.array([float(F(*s, *a)) for s in zip(delta, deltad, v, z)])
    assert (want_fn > 0).sum() > 100 and (want_fn == 0).sum() > 50      # loading and clamped
    np.testing.assert_allclose(out[:, CON["F_n"]], want_fn, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(out[:, CON["zdot"]], want_zd, rtol=1e-11, atol=1e-15)
    np.testing.assert_allclose(out[:, CON["F_t"]], want_f, rtol=1e-10, atol=1e-10)
    # the relaxation rate: zdot = v - z_rate z
    np.testing.assert_allclose(out[:, CON["zdot"]], v - out[:, CON["z_rate"]] * z,
                               rtol=1e-12, atol=1e-18)
    # a swing foot (flag 0): no force, frozen bristles
    off = _stage(LUGRE, params, delta[:5], deltad[:5], v[:5], z[:5], flags=(0, 0))
    assert not off[:, [CON["F_t"], CON["zdot"], CON["z_rate"]]].any()


@pytest.mark.parametrize("v", [-0.3, -2e-4, 5e-5, 1e-3, 0.8])
def test_bristle_steady_state_and_transient_closed_form(v):
    """At constant sliding v: z_ss = g(v) sign(v)/sigma0, where dz/dt = 0 and the force is
    -(g(v) sign(v) + sigma2 v) F_n; from z0, z(t) = z_ss + (z0 - z_ss) exp(-sigma0 |v| t/g(v)),
    checked by integrating the compiled dz/dt."""
    from scipy.integrate import solve_ivp
    params = pdw.Params.paper()
    lp = LUGRE.lugre_parameters(params)
    g = lp["mu_c"] + (lp["mu_s"] - lp["mu_c"]) * math.exp(-(v / lp["v_s"]) ** 2)
    z_ss = g * math.copysign(1.0, v) / lp["sigma0"]
    delta = 3e-3
    ss = _stage(LUGRE, params, [delta], [0.0], v, z_ss)[0]
    Fn = params.k_n * delta ** 1.5
    assert abs(ss[CON["zdot"]]) <= 1e-12 * abs(v)
    assert ss[CON["F_t"]] == pytest.approx(-(g * math.copysign(1.0, v) + lp["sigma2"] * v) * Fn,
                                           rel=1e-12)
    a = lp["sigma0"] * abs(v) / g
    z0 = -2 * z_ss

    def rhs(t, z):
        return [_stage(LUGRE, params, [delta], [0.0], v, z[0])[0, CON["zdot"]]]

    T = 5.0 / a
    ts = np.linspace(0, T, 11)
    sol = solve_ivp(rhs, (0, T), [z0], t_eval=ts, rtol=1e-11, atol=1e-16, method="LSODA")
    closed = z_ss + (z0 - z_ss) * np.exp(-a * ts)
    np.testing.assert_allclose(sol.y[0], closed, rtol=1e-7, atol=1e-9 * abs(z_ss))


def _walk(method="rodas4", dt=2e-5, t_end=1.6, contact=None):
    contact = calibrate_lugre().contact if contact is None else contact
    tol = dict(rtol=1e-8, atol=1e-10) if method in ("rodas4", "dopri5") else {}
    return pdw.simulate(params=pdw.Params.paper_steady(), t_end=t_end, dt=dt, method=method,
                        contact=contact, integrator=pdw.Integrator(check_step="off", **tol),
                        record=pdw.Record(every=1))


def test_state_layout_and_reset_at_touch_down():
    r = _walk()
    names = _layout.STATE_LAYOUTS["lugre"]
    assert r.x.shape[1] == len(names) == _core.kernel_nx(kernel_index("paper", None,
                                                                     "hunt_crossley", "lugre"))
    assert r.state_names == names and r.x_final.shape == (len(names),)
    tds = [e for e in r.events if e.kind == "touch_down"]
    assert len(tds) >= 3
    stood = {2}                                     # leg 2 starts in stance (flags0 = (0, 1))
    for e in tds:
        col = names.index("z%d" % e.leg)
        i = int(np.searchsorted(r.t, e.t))
        assert r.t[i] == e.t
        assert r.x[i, col] == 0.0                   # reset at the touch-down
        if e.leg in stood:                          # ... from the previous stance's value
            assert abs(r.x[i - 1, col]) > 1e-7
        stood.add(e.leg)
    # in swing (flag 0) the bristle state is frozen
    for leg in (0, 1):
        sw = r.flags[:, leg] == 0
        runs = np.flatnonzero(np.diff(sw.astype(int)) == 1)
        for s in runs[:2]:
            j = s + 1
            k = j + int(np.argmin(sw[j:])) if not sw[j:].all() else len(sw)
            col = names.index("z%d" % (leg + 1))
            assert np.all(r.x[j:k, col] == r.x[j, col])
    # a sliding stance foot's bristle stays within the steady-state bound mu_s / sigma0
    lp = r.contact.lugre_parameters(r.params)
    assert np.abs(r.x[:, 8:]).max() <= 1.01 * lp["mu_s"] / lp["sigma0"]


@pytest.mark.parametrize("method", ["cdm", "verlet", "rk4", "dopri5"])
def test_every_integrator_walks_with_lugre_like_rodas4(method):
    ref = _walk("rodas4", t_end=2.0)
    r = _walk(method, t_end=2.0, dt=1e-5)
    assert r.status == "walked" and r.n_gait_steps >= 2
    n = min(ref.n_gait_steps, r.n_gait_steps)
    L_ref, L = np.asarray(ref.gait.table["L"])[:n], np.asarray(r.gait.table["L"])[:n]
    tol = 1e-4 if method == "dopri5" else 5e-3          # first-order cdm: dt = 1e-5
    np.testing.assert_allclose(L, L_ref, atol=tol)


def test_lugre_calibrated_walk_matches_the_paper_gait():
    """Calibrated to Eq. 10 (calibrate_lugre), LuGre walks the paper's gait to within 1 %."""
    kw = dict(t_end=8.0, method="rodas4", integrator=pdw.Integrator(rtol=1e-8, atol=1e-10),
              record=pdw.Record(every=0))
    P = pdw.Params.paper_steady()
    ref = pdw.simulate(params=P, **kw)
    r = pdw.simulate(params=P, contact=calibrate_lugre(P).contact, **kw)
    for f in ("L", "P"):
        a = np.mean(ref.gait.table[f][-4:])
        b = np.mean(r.gait.table[f][-4:])
        assert abs(b - a) <= 0.01 * a, (f, a, b)


def test_calibration_identities():
    P = pdw.Params.paper_steady()
    c = calibrate_lugre(P)
    lp = c.contact.lugre_parameters(P)
    st = lugre_stribeck(P)
    g = lambda v: lp["mu_c"] + (lp["mu_s"] - lp["mu_c"]) * math.exp(-(v / lp["v_s"]) ** 2)  # noqa: E731
    assert g(0.0) == P.mu_s and g(1.0) == pytest.approx(P.mu_d, abs=1e-12)
    assert g(0.5 * (P.v_s + P.v_d)) == pytest.approx(0.5 * (P.mu_s + P.mu_d), rel=1e-12)
    assert st["v_s"] == lp["v_s"] and lp["sigma2"] == 0.0
    # critically damped bristle mode of the mid-stance foot: sigma1 F = 2 sqrt(sigma0 F m)
    assert lp["sigma1"] * c.weight == pytest.approx(2 * math.sqrt(lp["sigma0"] * c.weight * c.mass))


def test_exports_carry_the_bristle_columns(tmp_path):
    r = _walk("rodas4", t_end=0.5)
    df = r.to_dataframe()
    assert list(df.columns[:10]) == list(_layout.STATE_LAYOUTS["lugre"])
    np.testing.assert_array_equal(df["z2"].to_numpy(), r.x[:, 9])
    assert df.attrs["units"]["z1"] == "m"
    pytest.importorskip("xarray")
    ds = r.to_xarray()
    assert list(ds["state"].values) == list(_layout.STATE_LAYOUTS["lugre"])
    r.save(tmp_path / "run.npz")
    back = pdw.load(tmp_path / "run.npz")
    assert back.contact == r.contact and back.state_names == r.state_names
    np.testing.assert_array_equal(back.x, r.x)


def test_x0_mechanical_or_full():
    c = calibrate_lugre().contact
    x8 = np.array(pdw.simulate(t_end=1e-3).x[0])
    a = pdw.simulate(x8, t_end=0.05, contact=c, integrator=pdw.Integrator(check_step="off"))
    b = pdw.simulate(np.concatenate([x8, [0.0, 0.0]]), t_end=0.05, contact=c,
                     integrator=pdw.Integrator(check_step="off"))
    np.testing.assert_array_equal(a.x, b.x)
    with pytest.raises(pdw.InvalidInputError, match="x0"):
        pdw.simulate(np.concatenate([x8, [0.0, 0.0]]), t_end=0.05)


@pytest.mark.parametrize("kwargs, match", [
    (dict(contact=dict(sigma0=1e5)), "lugre friction law"),
    (dict(contact=dict(friction="lugre", sigma0=0.0)), r"contact.sigma0 .* > 0"),
    (dict(contact=dict(friction="lugre", sigma1=-1.0)), r"contact.sigma1 .* >= 0"),
    (dict(contact=dict(friction="lugre", v_s=float("nan"))), "contact.v_s"),
    (dict(contact=dict(friction="lugre", mu_c=0.0)), "contact.mu_c"),
    (dict(approach_speeds0=(-1.0, 0.0)), r"approach_speeds0\[0\] must be >= 0"),
    (dict(approach_speeds0=(0.1,)), "approach_speeds0 must have shape"),
])
def test_refused_with_reasons(kwargs, match):
    with pytest.raises(pdw.InvalidInputError, match=match):
        pdw.simulate(t_end=0.01, record=pdw.Record(every=1), **kwargs)


def test_a_frictionless_preset_needs_lugre_coefficients():
    P = pdw.Params.paper().replace(mu_s=0.0, mu_d=0.0)
    with pytest.raises(pdw.InvalidInputError, match=r"contact.mu_s .*Params.mu_s"):
        pdw.simulate(params=P, t_end=0.01, contact=dict(friction="lugre"))
    r = pdw.simulate(params=P, t_end=0.01, contact=dict(friction="lugre", mu_s=0.5, mu_c=0.4),
                     integrator=pdw.Integrator(check_step="off"))
    assert np.isfinite(r.x).all()


def test_the_section_carries_the_trailing_bristle():
    """find_gait's section under LuGre has a 7th coordinate, the trailing foot's bristle [um]
    (tests/analysis/stepmap/test_section_laws.py finds the gait); a 6-coordinate point is refused, naming it."""
    from pdw.analysis.stepmap import limit_cycle
    c = Contact(friction="lugre")
    assert limit_cycle.section_names(c) == limit_cycle.SECTION + ("z1_um",)
    with pytest.raises(pdw.InvalidInputError, match=r"7 components .*z1_um"):
        limit_cycle.step(np.zeros(6), contact=c)
    x = limit_cycle.embed([-0.36, 0.38, 0.86, -0.19, -1.8, -1.67, 2.5], pdw.Params.paper(), c)
    assert x[8] == 2.5e-6 and x[9] == 0.0


def test_simulate_many_runs_lugre_on_the_scalar_path():
    """The ensemble's scalar path carries the 10-entry state of a LuGre run."""
    from pdw.sim.ensemble import simulate_many
    c = calibrate_lugre().contact
    x0 = np.tile(np.array(pdw.X0_PAPER), (2, 1))
    out = simulate_many(x0, t_end=0.05, dt=2e-5, contact=c,
                        integrator=pdw.Integrator(check_step="off"))
    one = pdw.simulate(x0[0], t_end=0.05, dt=2e-5, contact=c,
                       integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=0))
    assert out.x_final.shape == (2, len(_layout.STATE_LAYOUTS["lugre"]))
    np.testing.assert_array_equal(out.x_final[0], one.x_final)


def test_rodas4_with_lugre_is_not_held_back_by_its_jacobian():
    """rodas4 needs the true Jacobian; the LuGre kernels' is a central difference. With a step
    of cbrt(eps) (6e-6) it straddled |v|'s kink at a stuck foot's creeping slip, and rodas4 took
    ~70x dopri5's steps (416 808 against 5 411 for 1 s at rtol 1e-10); with sqrt(eps) about as
    many (docs/contact_laws.md, "Integrators"). Step counts, not times: deterministic."""
    c = calibrate_lugre().contact
    P = pdw.Params.paper_steady()
    kw = dict(params=P, t_end=0.6, integrator=pdw.Integrator(rtol=1e-10, atol=1e-12, check_step="off"),
              contact=c, record=pdw.Record(every=0))
    ros = pdw.simulate(method="rodas4", **kw)
    dp = pdw.simulate(method="dopri5", **kw)
    assert ros.walked and dp.walked
    assert ros.stats["steps"] < 2 * dp.stats["steps"], (ros.stats, dp.stats)
    np.testing.assert_allclose(ros.x_final[:8], dp.x_final[:8], rtol=0, atol=1e-7)
