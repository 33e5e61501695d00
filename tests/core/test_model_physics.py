"""Physics sanity of the compiled model, independent of derive/.

Only the public API is used (pdw.rhs, pdw.mass_matrix, pdw.contact_forces, pdw.energies),
together with this module's own formulas for the centre of mass and the feet's material-point
velocities (docs/model.md section 2): M is symmetric positive definite; energy is conserved without
contact and dissipation, and its rate equals the power of the contact forces and the hip damper;
the centre of mass obeys Newton's law with the contact forces; a free leg hangs at theta = gamma
- atan(w / c).
"""
import math

import numpy as np
import pytest

import pdw

P_PAPER = pdw.Params.paper()
PARAM_SETS = {
    "paper": P_PAPER,
    "point_feet": pdw.Params.paper(r=0.0),
    "generic": pdw.Params(l=0.8, c=0.27, w=0.031, r=0.35, J_l=0.11, m_h=3.3, m_l=1.7, k_hip=2.1,
                          d_hip=0.07, gamma=0.09, g=9.81, k_n=3e4, d_n=2e5, k_t=40.0, d_t=300.0,
                          v_s=2e-4, v_d=3e-3, mu_s=0.7, mu_d=0.45),
}
X0_PAPER = np.array([0, 0.4969, -0.0582, 0.0582, 0.5092, 0.0186, 3.3338, -1.0093])   # docs/model.md 8


def E_total(x, p):
    return pdw.energies(x, p)["E"]


def com(x, p):
    """Centre of mass position of the walker, our own formula (docs/model.md section 2)."""
    x = np.atleast_2d(x)
    m = p.m_h + 2 * p.m_l
    pos = p.m_h * x[:, :2].copy()
    for i in (2, 3):
        th = x[:, i]
        e = np.column_stack([np.sin(th), -np.cos(th)])
        n = np.column_stack([np.cos(th), np.sin(th)])
        pos += p.m_l * (x[:, :2] + p.c * e + p.w * n)
    return pos / m


def com_velocity(x, p):
    x = np.atleast_2d(x)
    m = p.m_h + 2 * p.m_l
    v = p.m_h * x[:, 4:6].copy()
    for i in (2, 3):
        th, thd = x[:, i], x[:, i + 4]
        de = np.column_stack([np.cos(th), np.sin(th)]) * thd[:, None]       # d/dt e_i
        dn = np.column_stack([-np.sin(th), np.cos(th)]) * thd[:, None]      # d/dt n_i
        v += p.m_l * (x[:, 4:6] + p.c * de + p.w * dn)
    return v / m


def random_states(rng, p, n, depth=(-0.01, 0.005)):
    """States whose lowest foot is at `depth` (half of them with both feet low), moderate rates."""
    th = rng.uniform(-0.4, 0.4, (n, 2))
    both = rng.uniform(size=n) < 0.5
    th[both, 1] = -th[both, 0] + rng.uniform(-0.005, 0.005, both.sum())
    y_o = p.r + (p.l - p.r) * np.max(np.cos(th), axis=1) + rng.uniform(*depth, n)
    return np.column_stack([rng.uniform(-1, 1, n), y_o, th, rng.uniform(-1, 1, n),
                            rng.uniform(-0.15, 0.15, n), rng.uniform(-1, 1, (n, 2))])


# --- mass matrix --------------------------------------------------------------------------------
@pytest.mark.parametrize("pname", sorted(PARAM_SETS))
def test_mass_matrix_symmetric_positive_definite(pname):
    p = PARAM_SETS[pname]
    rng = np.random.default_rng(11)
    q = np.column_stack([rng.uniform(-5, 5, (300, 2)), rng.uniform(-np.pi, np.pi, (300, 2))])
    q[:20, 3] = q[:20, 2]                                      # legs together
    M = pdw.mass_matrix(q, p)
    assert np.array_equal(M, np.swapaxes(M, 1, 2))
    lam = np.linalg.eigvalsh(M)
    # the Schur complement of the hip block is >= J_l (see test_params), so lambda_min > 0
    assert lam.min() > 0.5 * min(p.J_l, p.m_h + 2 * p.m_l)
    # translation invariance: M depends on the leg angles only
    q2 = q.copy()
    q2[:, :2] += 3.0
    assert np.allclose(pdw.mass_matrix(q2, p), M, rtol=0, atol=1e-14)


@pytest.mark.parametrize("overrides", [dict(m_h=0.0, J_l=0.0), dict(c=0.0, w=0.0, J_l=0.0)],
                         ids=["massless_hip_no_inertia", "point_leg_at_hip"])
def test_every_accepted_parameter_set_gives_a_regular_mass_matrix(overrides):
    """BUG (reported): Params accepts m_h = 0 and J_l = 0 (and c = w = J_l = 0); M is then
    singular (legs together / always) and pdw.rhs returns garbage or NaN without an error.
    Either the Params constructor must refuse such a set, or M must be regular."""
    try:
        p = pdw.Params.paper(**overrides)
    except ValueError:
        return                                                  # refused: fine
    q = np.array([0.0, 0.5, 0.1, 0.1])
    lam = np.linalg.eigvalsh(pdw.mass_matrix(q, p))
    assert lam.min() > 1e-9 * lam.max(), (overrides, lam)


# --- energy -------------------------------------------------------------------------------------
def _integrate(p, x0, t_end, flags, extra=None):
    from scipy.integrate import solve_ivp

    def f(t, y):
        xd = pdw.rhs(y[:8], p, flags=flags)
        return xd if extra is None else np.concatenate([xd, extra(y[:8])])

    y0 = x0 if extra is None else np.concatenate([x0, [0.0]])
    sol = solve_ivp(f, (0, t_end), y0, method="DOP853", rtol=1e-11, atol=1e-12, dense_output=True)
    assert sol.success, sol.message
    return sol


@pytest.mark.parametrize("pname,flags,k_hip", [
    ("paper", (0, 0), 0.0), ("generic", (0, 0), 0.0),
    ("paper", (1, 1), 0.95),            # support flags, feet above the ground; conservative spring
    ("point_feet", (0, 0), 2.0),
])
def test_energy_conserved_without_contact_and_damping(pname, flags, k_hip):
    p = PARAM_SETS[pname].replace(k_hip=k_hip, d_hip=0.0)
    x0 = X0_PAPER.copy()
    x0[1] += 3.0                                          # 3 m above the paper's start
    sol = _integrate(p, x0, 0.4, flags)
    ts = np.linspace(0, 0.4, 81)
    X = sol.sol(ts).T
    cs = pdw.contact_forces(X, p, flags=flags)
    assert cs.y_D.min() > 0                              # no contact along the way
    e = pdw.energies(X, p)
    drift = np.abs(e["E"] - e["E"][0]).max() / np.abs(e["T"]).max()
    assert drift < 1e-8, drift
    assert np.ptp(e["T"]) > 0.1 * np.abs(e["T"]).max()    # a real exchange of T and V happened


def test_hip_damper_dissipates_exactly_its_power():
    """E(t) + integral of d_hip (thetad1 - thetad2)^2 dt = E(0) (no contact)."""
    p = P_PAPER.replace(d_hip=0.3)
    x0 = X0_PAPER.copy()
    x0[1] += 1.0
    sol = _integrate(p, x0, 0.4, (0, 0), extra=lambda x: [p.d_hip * (x[6] - x[7]) ** 2])
    Y = sol.sol(np.linspace(0, 0.4, 41)).T
    e = pdw.energies(Y[:, :8], p)["E"]
    balance = e + Y[:, 8] - e[0]
    assert Y[-1, 8] > 0.1                                 # a substantial dissipation
    assert np.abs(balance).max() < 1e-8 * np.abs(pdw.energies(Y[:, :8], p)["T"]).max()
    assert np.all(np.diff(e) < 0)


@pytest.mark.parametrize("variant", ["paper", "consistent"])
@pytest.mark.parametrize("pname", sorted(PARAM_SETS))
def test_energy_rate_is_power_of_contact_forces_and_damper(variant, pname):
    """dE/dt along f(x) (central difference of pdw.energies) = sum_i F_ti v_xi + F_ni v_yi at the
    feet's material points (consistent rate) - d_hip (thetad1 - thetad2)^2."""
    p = PARAM_SETS[pname]
    rng = np.random.default_rng(21)
    X = random_states(rng, p, 60)
    flags = np.array([(1, 1), (0, 1), (1, 0)])[rng.integers(0, 3, len(X))]
    s = X[:, 0:1] + (p.l - p.r) * np.sin(X[:, 2:4]) + p.r * X[:, 2:4]
    anchors = s - rng.uniform(-0.01, 0.01, (len(X), 2))
    F = pdw.rhs(X, p, flags=flags, anchors=anchors, variant=variant)
    cs = pdw.contact_forces(X, p, flags=flags, anchors=anchors, variant=variant)
    L = p.l - p.r
    th, thd = X[:, 2:4], X[:, 6:8]
    v_x = X[:, 4:5] + (L * np.cos(th) + p.r) * thd          # Eq. 9, our own
    v_y = X[:, 5:6] + L * np.sin(th) * thd                  # material point, normal
    power = (cs.F_t * v_x + cs.F_n * v_y).sum(axis=1) - p.d_hip * (thd[:, 0] - thd[:, 1]) ** 2
    h = 1e-7
    dE = (E_total(X + h * F, p) - E_total(X - h * F, p)) / (2 * h)
    scale = np.abs(cs.F_n).sum(axis=1) * np.abs(X[:, 4:]).max(axis=1) + 1.0
    assert np.all(np.abs(dE - power) < 2e-6 * scale), np.abs(dE - power).max()
    assert np.count_nonzero(cs.F_n) > 20                    # contact really was on


# --- Newton's law for the centre of mass -----------------------------------------------------
@pytest.mark.parametrize("variant", ["paper", "consistent"])
@pytest.mark.parametrize("pname", sorted(PARAM_SETS))
def test_centre_of_mass_obeys_newton(variant, pname):
    """m a_cm = m g (sin gamma, -cos gamma) + sum_i (F_ti, F_ni): hip spring and damper are internal."""
    p = PARAM_SETS[pname]
    rng = np.random.default_rng(31)
    X = random_states(rng, p, 60)
    flags = np.array([(1, 1), (0, 1), (1, 0), (0, 0)])[rng.integers(0, 4, len(X))]
    F = pdw.rhs(X, p, flags=flags, variant=variant)
    cs = pdw.contact_forces(X, p, flags=flags, variant=variant)
    h = 1e-7
    a_cm = (com_velocity(X + h * F, p) - com_velocity(X - h * F, p)) / (2 * h)
    m = p.m_h + 2 * p.m_l
    want = np.column_stack([m * p.g * math.sin(p.gamma) + cs.F_t.sum(axis=1),
                            -m * p.g * math.cos(p.gamma) + cs.F_n.sum(axis=1)])
    scale = m * p.g + np.abs(cs.F_n).sum(axis=1, keepdims=True) + np.abs(cs.F_t).sum(axis=1, keepdims=True)
    assert np.all(np.abs(m * a_cm - want) < 1e-6 * scale), np.abs(m * a_cm - want).max()
    # and the velocity is the derivative of the position (consistency of our own formulas)
    v_fd = (com(X + h * F, p) - com(X - h * F, p)) / (2 * h)
    assert np.allclose(v_fd, com_velocity(X, p), rtol=0, atol=1e-7)


def test_free_fall_at_rest_has_no_angular_acceleration():
    """All bodies fall alike: with zero velocities, no contact and no hip spring, theta'' = 0 and
    the hip accelerates at g (any configuration)."""
    rng = np.random.default_rng(41)
    for p in PARAM_SETS.values():
        p = p.replace(k_hip=0.0)
        X = np.zeros((50, 8))
        X[:, :4] = rng.uniform(-1.5, 1.5, (50, 4))
        xd = pdw.rhs(X, p, flags=(0, 0))
        g = p.g
        assert np.allclose(xd[:, 4], g * math.sin(p.gamma), rtol=0, atol=1e-12 * g)
        assert np.allclose(xd[:, 5], -g * math.cos(p.gamma), rtol=0, atol=1e-12 * g)
        assert np.allclose(xd[:, 6:], 0.0, rtol=0, atol=1e-12 * g / p.l)


# --- the hanging leg -------------------------------------------------------------------------
def _dV_dtheta(p, th1, th2=0.3, h=1e-5):
    """Generalized gravity + spring torque on leg 1, dV/dtheta1, from pdw.energies (V = E - T)."""
    def V(t1):
        x = np.array([0.2, 0.6, t1, th2, 0, 0, 0, 0])
        e = pdw.energies(x, p)
        return e["V_gravity"] + e["V_hip"]
    H = 1e-3
    return (V(th1 + h) - V(th1 - h)) / (2 * h), (V(th1 + H) - 2 * V(th1) + V(th1 - H)) / H**2


def _rest_angle(p):
    return p.gamma - math.atan(p.w / p.c)


@pytest.mark.parametrize("w", [0.0, -0.0025, 0.02])
@pytest.mark.parametrize("gamma", [0.02, -0.1, 0.3])
def test_free_leg_rests_at_true_vertical_shifted_by_mass_offset(w, gamma):
    p = P_PAPER.replace(w=w, gamma=gamma, k_hip=0.0)
    rest = _rest_angle(p)
    if w == 0:
        assert rest == gamma                                   # true vertical
    G, K = _dV_dtheta(p, rest)
    scale = p.m_l * p.g * math.hypot(p.c, p.w)
    assert abs(G) < 1e-8 * scale, G
    assert K > 0.99 * scale                                    # a minimum (stable hanging)
    # and nowhere else nearby: off by 0.05 rad the torque restores
    assert _dV_dtheta(p, rest + 0.05)[0] > 0.04 * scale
    assert _dV_dtheta(p, rest - 0.05)[0] < -0.04 * scale
    if w != 0:                                                 # the offset matters
        assert abs(_dV_dtheta(p, gamma)[0]) > 0.5 * scale * abs(math.atan(p.w / p.c))


def test_gravity_torque_from_rhs_equals_energy_gradient():
    """G = -M qdd at zero velocity without contact (rhs) equals grad V (energies)."""
    rng = np.random.default_rng(51)
    for p in PARAM_SETS.values():
        for _ in range(10):
            q = np.concatenate([rng.uniform(-1, 1, 2), rng.uniform(-1, 1, 2)])
            x = np.concatenate([q, np.zeros(4)])
            qdd = pdw.rhs(x, p, flags=(0, 0))[4:]
            G_rhs = -pdw.mass_matrix(q, p) @ qdd
            h = 1e-6
            G_fd = np.empty(4)
            for k in range(4):
                e = np.zeros(8)
                e[k] = h
                vp, vm = pdw.energies(x + e, p), pdw.energies(x - e, p)
                G_fd[k] = (vp["V_gravity"] + vp["V_hip"] - vm["V_gravity"] - vm["V_hip"]) / (2 * h)
            assert np.allclose(G_rhs, G_fd, rtol=1e-7, atol=1e-7 * p.m_h * p.g)


# --- contact forces -------------------------------------------------------------------------------
def test_static_sink_under_the_walkers_weight_is_about_5_mm():
    """docs/model.md section 1: k_n = 1e5 gives a static sink of about 5 mm under the walker's weight."""
    p = P_PAPER
    lo, hi = 0.0, 0.02
    for _ in range(60):                                      # bisection on the depth, leg vertical
        d = 0.5 * (lo + hi)
        x = np.array([0.0, p.l - d, 0.0, 0.3, 0, 0, 0, 0])
        Fn = pdw.contact_forces(x, p, flags=(1, 0)).F_n[0]
        lo, hi = (d, hi) if Fn < p.weight else (lo, d)
    assert 0.0045 < d < 0.006, d
    assert d == pytest.approx((p.weight / p.k_n) ** (2 / 3), rel=1e-9)


def test_paper_initial_state_stance_force_is_the_weight_only_with_printed_eq5():
    """docs/model.md section 6: at the paper's initial state the stance force equals the walker's weight
    under the printed Eq. 5 (variant paper), not under the consistent rate."""
    p = P_PAPER
    paper = pdw.contact_forces(X0_PAPER, p, flags=(0, 1), variant="paper")
    cons = pdw.contact_forces(X0_PAPER, p, flags=(0, 1), variant="consistent")
    assert paper.F_n[0] == 0 and cons.F_n[0] == 0            # leg 1 swings
    assert paper.F_n[1] == pytest.approx(p.weight, rel=0.02)
    assert abs(cons.F_n[1] / p.weight - 1) > 0.3
    assert paper.y_D[1] == pytest.approx(-0.0026, abs=1e-4)   # "both feet are 2.6 mm deep"
    assert paper.y_D[0] == pytest.approx(-0.0026, abs=1e-4)


@pytest.mark.parametrize("variant", ["paper", "consistent"])
def test_friction_opposes_slip_and_ground_never_pulls(variant):
    p = P_PAPER.replace(k_t=1e-12, d_t=1e-12)                 # friction alone (spring-damper ~ 0)
    rng = np.random.default_rng(61)
    X = random_states(rng, p, 200)
    s = X[:, 0:1] + (p.l - p.r) * np.sin(X[:, 2:4]) + p.r * X[:, 2:4]
    cs = pdw.contact_forces(X, p, flags=(1, 1), anchors=s, variant=variant)
    on = cs.F_n > 0
    assert on.sum() > 50
    assert np.all(cs.F_n >= 0)
    assert np.all(cs.F_t[on] * cs.v_x[on] <= 0)
    fast = on & (np.abs(cs.v_x) > p.v_d)
    assert fast.sum() > 20
    assert np.allclose(np.abs(cs.F_t[fast]), p.mu_d * cs.F_n[fast], rtol=1e-6)


def test_forces_act_only_on_penetrating_support_feet():
    p = P_PAPER
    rng = np.random.default_rng(71)
    X = random_states(rng, p, 100, depth=(-0.01, -0.002))     # the lowest foot penetrates
    for flags in [(0, 0), (1, 0), (0, 1), (1, 1)]:
        cs = pdw.contact_forces(X, p, flags=flags)
        for i in range(2):
            pen = cs.y_D[:, i] < 0
            if flags[i] == 0:
                assert np.all(cs.F_n[:, i] == 0) and np.all(cs.F_t[:, i] == 0)
            else:
                assert np.all(cs.F_n[~pen, i] == 0) and np.all(cs.F_t[~pen, i] == 0)
                assert np.count_nonzero(cs.F_n[pen, i]) > 0.5 * pen.sum() > 5
    # swing legs are as if there were no ground; so are support feet above the ground
    lifted = X.copy()
    lifted[:, 1] += 5.0
    a = pdw.rhs(X, p, flags=(0, 0))
    b = pdw.rhs(lifted, p, flags=(1, 1))
    assert np.allclose(a, b, rtol=1e-13, atol=1e-13)
    assert not np.allclose(a, pdw.rhs(X, p, flags=(1, 1)), rtol=1e-3)
