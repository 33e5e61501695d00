"""The hybrid (impact-momentum) walker of docs/model.md section 9 (pdw.hybrid, derive/hybrid.py)."""
import pathlib
import sys

import numpy as np
import pytest

import pdw
from pdw import hybrid as H
from pdw.analysis.gait_types import Gait, GaitNotFoundError
from pdw.analysis.rigid import hybrid
from pdw.core.errors import InvalidInputError, SimulationError

ROOT = pathlib.Path(__file__).resolve().parents[3]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

COMPASS = H.compass_gait_params()
STEADY = pdw.Params.paper_steady()
PARAMS = {"compass": COMPASS, "paper_steady": STEADY, "paper_k0": pdw.Params.paper(k_hip=0.0)}


@pytest.fixture(scope="module")
def compass_gait():
    return H.find_gait(COMPASS)


@pytest.fixture(scope="module")
def steady_gait():
    return H.find_gait(STEADY)


def _random_states(n, seed=1):
    rng = np.random.default_rng(seed)
    th = rng.uniform(-0.5, 0.5, size=(n, 2))
    om = rng.uniform(-3.0, 3.0, size=(n, 2))
    return np.hstack([th, om])


# --- the derivation ----------------------------------------------------------------------------

def _lagrangian_reduced(params):
    """Reduced equations built here, independently of derive.hybrid: T and V from the points of
    derive.model with the rolling constraint substituted, then Lagrange's equations."""
    sp = pytest.importorskip("sympy")
    from derive import model as mdl
    P = {mdl.P[n]: getattr(params, n) for n in pdw.core._layout.PARAMS}
    P[mdl.P["sin_gamma"]] = np.sin(params.gamma)
    P[mdl.P["cos_gamma"]] = np.cos(params.gamma)
    t = sp.Symbol("t")
    a, b = sp.Function("a")(t), sp.Function("b")(t)          # theta_st, theta_sw
    l, r = mdl.P["l"], mdl.P["r"]
    sub = {mdl.Q[0]: -(l - r) * sp.sin(a) - r * a, mdl.Q[1]: r + (l - r) * sp.cos(a),
           mdl.Q[2]: a, mdl.Q[3]: b}
    Hp, Gs, _ = mdl.points()
    m_h, m_l, J_l, g = mdl.P["m_h"], mdl.P["m_l"], mdl.P["J_l"], mdl.P["g"]
    sg, cg = mdl.P["sin_gamma"], mdl.P["cos_gamma"]
    pts = [(m_h, Hp.subs(sub))] + [(m_l, G.subs(sub)) for G in Gs]
    T = sum(m / 2 * (sp.diff(pt[0], t) ** 2 + sp.diff(pt[1], t) ** 2) for m, pt in pts)
    T += J_l / 2 * (sp.diff(a, t) ** 2 + sp.diff(b, t) ** 2)
    V = sum(m * g * (pt[1] * cg - pt[0] * sg) for m, pt in pts) \
        + mdl.P["k_hip"] / 2 * (a - b) ** 2
    d = mdl.P["d_hip"]
    Qd = [-d * (sp.diff(a, t) - sp.diff(b, t)), -d * (sp.diff(b, t) - sp.diff(a, t))]
    L = T - V
    eqs = [sp.diff(sp.diff(L, sp.diff(c, t)), t) - sp.diff(L, c) - Q for c, Q in zip((a, b), Qd)]
    ys = sp.symbols("y0:4")
    add = sp.symbols("ydd0:2")
    rep = {sp.diff(a, t, 2): add[0], sp.diff(b, t, 2): add[1]}
    rep2 = {sp.diff(a, t): ys[2], sp.diff(b, t): ys[3]}
    rep3 = {a: ys[0], b: ys[1]}
    eqs = [e.subs(rep).subs(rep2).subs(rep3).subs(P) for e in eqs]
    Mr = sp.Matrix(2, 2, lambda i, j: sp.diff(eqs[i], add[j]))
    fr = sp.Matrix([-e.subs({add[0]: 0, add[1]: 0}) for e in eqs])
    return sp.lambdify([ys], Mr, "numpy"), sp.lambdify([ys], fr, "numpy")


@pytest.mark.parametrize("name", ["compass", "paper_steady"])
def test_generated_stance_dynamics_equal_an_independent_lagrangian(name):
    params = PARAMS[name]
    Mf, ff = _lagrangian_reduced(params)
    for y in _random_states(5):
        Mr, fr = H.stance_terms(y, params)
        np.testing.assert_allclose(Mr, np.asarray(Mf(y), float), rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(fr, np.asarray(ff(y), float).ravel(), rtol=1e-11, atol=1e-12)


@pytest.mark.slow
def test_projection_and_lagrangian_routes_agree_symbolically():
    pytest.importorskip("sympy")
    import sympy as sp

    from derive import hybrid as dh
    Ma, fa = dh.reduced_dynamics("projection")
    Mb, fb = dh.reduced_dynamics("lagrangian")
    for x, y in zip(list(Ma) + list(fa), list(Mb) + list(fb)):
        assert sp.simplify(x - y) == 0


def _constraint(x, params, foot):
    """J (2x4) and Jdot qd (2,) of the foot's material-point velocity (docs/model.md section 2)."""
    l, r = params.l, params.r
    th, thd = x[2 + foot], x[6 + foot]
    J = np.zeros((2, 4))
    J[0, 0] = 1.0
    J[0, 2 + foot] = (l - r) * np.cos(th) + r
    J[1, 1] = 1.0
    J[1, 2 + foot] = (l - r) * np.sin(th)
    Jdqd = np.array([-(l - r) * np.sin(th) * thd ** 2, (l - r) * np.cos(th) * thd ** 2])
    return J, Jdqd


@pytest.mark.parametrize("name", sorted(PARAMS))
def test_reduced_accelerations_equal_the_constrained_full_model(name):
    """Full model M qdd = -C qd - G + Q_hip + J^T lambda with J qdd = -Jdot qd (KKT) gives the
    reduced model's accelerations, and lambda is the reduced model's ground force."""
    params = PARAMS[name]
    for y in _random_states(6, seed=2):
        x = H.full_state(y, params)
        M = pdw.mass_matrix(x, params)
        f = M @ pdw.rhs(x, params, flags=(0, 0))[4:]          # -C qd - G + Q_hip
        J, Jdqd = _constraint(x, params, 0)
        np.testing.assert_allclose(J @ x[4:], 0.0, atol=1e-14)   # the embedding satisfies J qd = 0
        K = np.block([[M, -J.T], [J, np.zeros((2, 2))]])
        sol = np.linalg.solve(K, np.concatenate([f, -Jdqd]))
        ydot = H.stance_rhs(y, params)
        np.testing.assert_allclose(sol[2:4], ydot[2:], rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(sol[4:], H.ground_force(y, params), rtol=1e-10, atol=1e-9)


def test_full_state_embedding_puts_the_stance_foot_on_the_ground():
    for params in (COMPASS, STEADY):
        y = _random_states(4, seed=3)
        x = H.full_state(y, params, s0=0.7, stance_leg=2)
        c = pdw.contact_forces(x, params, variant="consistent", flags=(0, 0))
        np.testing.assert_allclose(c.y_D[:, 1], 0.0, atol=1e-14)
        np.testing.assert_allclose(c.v_x[:, 1], 0.0, atol=1e-14)
        np.testing.assert_allclose(c.v_y[:, 1], 0.0, atol=1e-14)
        np.testing.assert_allclose(c.s[:, 1], 0.7, atol=1e-14)
        np.testing.assert_allclose(x[:, 2], y[:, 1])            # leg 1 swings
        np.testing.assert_allclose(x[:, 3], y[:, 0])


# --- the impact map ----------------------------------------------------------------------------

def _angular_momentum(x, params, point):
    """Angular momentum of the walker about a fixed point (z component)."""
    def cross(u, v):
        return u[0] * v[1] - u[1] * v[0]

    q, qd = x[:4], x[4:]
    hip, hipd = q[:2], qd[:2]
    Hz = params.m_h * cross(hip - point, hipd)
    for i in range(2):
        th, thd = q[2 + i], qd[2 + i]
        e = np.array([np.sin(th), -np.cos(th)])
        n = np.array([np.cos(th), np.sin(th)])
        G = hip + params.c * e + params.w * n
        Gd = hipd + thd * (params.c * n - params.w * e)
        Hz += params.m_l * cross(G - point, Gd) + params.J_l * thd
    return Hz


@pytest.mark.parametrize("name", ["compass", "paper_steady"])
def test_impact_map(name, compass_gait, steady_gait):
    params = PARAMS[name]
    gait = compass_gait if name == "compass" else steady_gait
    ym = gait.details["y_minus"]
    res = H.impact(ym, params)
    assert res["status"] == "ok"
    x = H.full_state(ym, params)                      # stance = leg 1, swing (striking) = leg 2
    M = pdw.mass_matrix(x, params)
    J2, _ = _constraint(x, params, 1)
    J1, _ = _constraint(x, params, 0)
    qm, qp = res["qd_minus"], res["qd_plus"]
    np.testing.assert_allclose(qm, x[4:], atol=1e-14)
    np.testing.assert_allclose(J2 @ qp, 0.0, atol=1e-13)                   # new foot stops
    np.testing.assert_allclose(M @ (qp - qm), J2.T @ res["impulse"], atol=1e-12)
    np.testing.assert_allclose(J1 @ qp, res["v_old"], atol=1e-13)
    assert res["v_old"][1] > 0 and not res["old_foot_down"]                 # old foot leaves up
    assert res["impulse"][1] > 0                                            # the ground pushes
    assert res["T_plus"] < res["T_minus"]                                   # energy is lost
    # angular momentum about the impact point is conserved (the impulse acts there)
    point = np.array([x[0] + (params.l - params.r) * np.sin(x[3]), 0.0])
    xp = x.copy()
    xp[4:] = qp
    assert _angular_momentum(xp, params, point) == pytest.approx(
        _angular_momentum(x, params, point), rel=1e-12)
    # relabelling: the new stance is the old swing leg
    np.testing.assert_allclose(res["y_plus"], [ym[1], ym[0], qp[3], qp[2]])


def test_c_solver_matches_numpy():
    from pdw.core import _hybrid
    rng = np.random.default_rng(4)
    A = rng.normal(size=(6, 6))
    b = rng.normal(size=6)
    x = _hybrid.solve(A.copy(), b.copy())
    np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-12)
    with pytest.raises(ArithmeticError):
        _hybrid.solve(np.zeros((3, 3)), np.ones(3))


# --- the compass gait (Goswami, Thuilot & Espiau 1998) -----------------------------------------

def test_compass_gait_fixed_point(compass_gait):
    g = compass_gait
    assert isinstance(g, Gait) and g.model == "hybrid"
    # measured (docs/hybrid.md): period 0.734346 s, step length 0.535445 m, post-impact state
    # [0.271029, -0.271029, -1.092384, -0.377374]
    assert g.period == pytest.approx(0.734346, abs=2e-6)
    assert g.step_length == pytest.approx(0.535445, abs=2e-6)
    np.testing.assert_allclose(g.state, [0.271029, -0.271029, -1.092384, -0.377374], atol=2e-6)
    assert g.state[1] == -g.state[0]
    assert g.double_support == 0.0
    # a fixed point: P(state) = state
    np.testing.assert_allclose(H.step_map(g.state, COMPASS, rtol=1e-12, atol=1e-12), g.state,
                               atol=1e-9)
    # point feet: the footprint spacing is the chord 2 l sin(alpha)
    assert g.step_length == pytest.approx(2 * COMPASS.l * np.sin(g.state[0]), rel=1e-9)


def test_compass_gait_is_stable(compass_gait):
    m = compass_gait.multipliers
    assert m.shape == (3,)
    assert compass_gait.stable
    # measured: a complex pair -0.19973 +- 0.54448 i (|.| = 0.5800) and 0.13157
    np.testing.assert_allclose(np.sort(np.abs(m)), [0.13157, 0.57995, 0.57995], atol=2e-4)
    # the multipliers do not depend on the finite-difference step
    m2, _ = H.floquet(compass_gait.state, COMPASS, fd_step=1e-5)
    np.testing.assert_allclose(np.sort(np.abs(m2)), np.sort(np.abs(m)), atol=1e-5)


def test_compass_gait_physics(compass_gait):
    d = compass_gait.details
    P = COMPASS
    # no damping, no hip spring: T + V is conserved during the stance, to the tolerance
    assert d["stance_energy_drift"] < 1e-9
    # energy is lost at the impact, and on the gait it equals the potential energy released
    # per step down the slope: m g L sin(gamma)
    m = P.m_h + 2 * P.m_l
    assert d["energy_loss"] > 0
    assert d["energy_loss"] == pytest.approx(m * P.g * compass_gait.step_length * np.sin(P.gamma),
                                             rel=1e-8)
    assert d["v_old"][1] > 0 and not d["old_foot_down"]
    assert d["vy_strike"] < 0
    assert d["Fn_min"] > 0                          # the stance foot stays pressed on the ground
    assert 0 < d["friction_needed"] < 1


def test_compass_gait_converges_with_the_tolerance():
    """Period and step length converge as the integration tolerance tightens (h_max large so
    that the error control, not the step cap, sets the step)."""
    out = []
    for tol in (1e-5, 1e-7, 1e-9, 1e-11):
        g = H.find_gait(COMPASS, guess=[0.27, -0.27, -1.09, -0.38], rtol=tol, atol=tol,
                        h_max=0.2, tol=1e-9, fd_step=1e-5)
        out.append((g.period, g.step_length))
    out = np.array(out)
    ref = out[-1]
    err = np.abs(out[:-1] - ref).max(axis=1)
    assert err[-1] < 1e-7
    assert err[0] > err[-1]
    np.testing.assert_allclose(ref, [0.734346, 0.535445], atol=2e-6)


# --- the paper's walker with arc feet -----------------------------------------------------------

def test_paper_steady_hybrid_gait(steady_gait):
    g = steady_gait
    # measured (docs/hybrid.md): period 0.564070 s, step length 0.340248 m,
    # multipliers 0.51617 +- 0.16690 i (|.| = 0.5425) and 5.6e-5
    assert g.stable
    assert g.period == pytest.approx(0.56407, abs=1e-5)
    assert g.step_length == pytest.approx(0.340248, abs=1e-5)
    np.testing.assert_allclose(np.sort(np.abs(g.multipliers))[1:], [0.5425, 0.5425], atol=1e-3)
    # arc feet: the footprint spacing is the chord plus the rolled arc, 2 (l - r) sin a + 2 r a
    a = g.state[0]
    P = STEADY
    assert g.step_length == pytest.approx(2 * (P.l - P.r) * np.sin(a) + 2 * P.r * a, rel=1e-9)
    d = g.details
    assert d["v_old"][1] > 0 and d["energy_loss"] > 0 and d["Fn_min"] > 0


def test_paper_params_have_no_hybrid_gait():
    """With the paper's d_hip = 0.018 no period-one hybrid gait is found either (as for the
    compliant model, docs/model.md section 8)."""
    with pytest.raises(GaitNotFoundError) as info:
        H.find_gait(pdw.Params.paper(), settle_steps=15)
    assert info.value.attempts


# --- trajectories and the step map's contract --------------------------------------------------

def test_simulate_hybrid_converges_to_the_gait(compass_gait):
    y0 = compass_gait.state + np.array([0.01, -0.01, 0.02, -0.02])
    tr = H.simulate_hybrid(COMPASS, y0, 20, dt_out=0.01)
    assert tr.status == "ok" and len(tr.steps) == 20
    np.testing.assert_allclose(tr.steps[-1]["y_plus"], compass_gait.state, atol=1e-4)
    # positions are continuous through the impacts; legs alternate
    i = np.flatnonzero(np.diff(tr.t) == 0)
    assert len(i) == 19
    np.testing.assert_allclose(tr.x[i, :4], tr.x[i + 1, :4], atol=1e-12)
    assert (tr.stance_leg[i] != tr.stance_leg[i + 1]).all()
    # the footprints are spaced by the step lengths
    L = np.array([s["step_length"] for s in tr.steps])
    np.testing.assert_allclose(np.diff(tr.footprints), L[1:], rtol=1e-12)
    # the stance foot stays put (point feet): its contact point is the previous footprint
    c = pdw.contact_forces(tr.x, COMPASS, variant="consistent", flags=(0, 0))
    st = tr.stance_leg - 1
    yD = c.y_D[np.arange(len(st)), st]
    np.testing.assert_allclose(yD, 0.0, atol=1e-13)


def test_step_map_failures_and_bad_input():
    with pytest.raises(SimulationError):           # falls backwards: no heel strike
        H.step_map([0.2, -0.2, 0.3, 0.0], COMPASS)
    res = H.step([0.2, -0.2, 0.3, 0.0], COMPASS)
    assert res["status"] in ("fell", "no_strike")
    with pytest.raises(InvalidInputError):
        H.step_map([0.2, -0.2, 0.3], COMPASS)
    with pytest.raises(InvalidInputError):
        H.step_map([0.2, -0.2, np.nan, 0.0], COMPASS)
    with pytest.raises(InvalidInputError):
        H.step_map([0.2, -0.2, -1.0, 0.0], COMPASS, rtoll=1e-3)


def test_hybrid_record_is_complete_or_not_ok():
    """dt_out = 1e-5 over 10 steps used to end the trajectory at 2.0 s of a 5.64 s walk while
    the status was "ok"; now the record covers every step of the walk."""
    tr = hybrid.simulate_hybrid(n_steps=10, dt_out=1e-5)
    total = sum(s["t_strike"] for s in tr.steps)
    assert tr.status == "ok" and len(tr.steps) == 10
    assert not any(s["rec_full"] for s in tr.steps)
    assert tr.t[-1] == pytest.approx(total, abs=1e-12)
    assert np.all(np.diff(tr.t) >= 0)
    # every dt_out instant of the walk is sampled (besides the steps' start and pre-impact)
    assert len(tr.t) >= int(total / 1e-5)
    # the recorded part is the same walk as a coarse record of it
    coarse = hybrid.simulate_hybrid(n_steps=10, dt_out=1e-3)
    assert [s["t_strike"] for s in coarse.steps] == [s["t_strike"] for s in tr.steps]


def test_hybrid_record_too_large_for_memory_is_an_error_naming_dt_out():
    with pytest.raises(pdw.InvalidInputError, match="dt_out"):
        hybrid.simulate_hybrid(n_steps=2000, dt_out=1e-9)


def test_public_full_state_refuses_a_short_state():
    """pdw.hybrid.full_state([3 values]) used to return memory read past the array."""
    with pytest.raises(pdw.InvalidInputError, match=r"y must have shape \(4,\) or \(N, 4\)"):
        pdw.hybrid.full_state([0.1, -0.1, 1.0])
    with pytest.raises(pdw.InvalidInputError, match="shape"):
        pdw.hybrid.full_state(np.zeros((2, 3)))
    x = pdw.hybrid.full_state([0.2, -0.2, -1.0, -0.3])
    assert x.shape == (8,) and np.isfinite(x).all()
