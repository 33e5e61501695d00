"""Symbolic tests: the derivation in derive/ reproduces docs/model.md sections 2-4 and 6 exactly.

Everything docs/model.md prints is TRANSCRIBED HERE by hand, with this module's own SymPy symbols
(same names and assumptions as derive/, so that they compare equal); from derive/ only the
derived side is taken: `mechanics()`, `generalized_forces()`, `contact_kinematics()`,
`material_velocity()`, `friction_coefficient()` and `contact_laws()`. Equality is shown with
``sympy.simplify(derived - transcribed) == 0``.
"""
import pytest

sp = pytest.importorskip("sympy")

from derive import model as dm  # noqa: E402  (the derived side only)


def R(name):
    return sp.Symbol(name, real=True)


# --- our own symbols (docs/model.md notation, derive/layout.py spelling) ---------------------------
x_o, y_o, th1, th2 = R("x_o"), R("y_o"), R("theta1"), R("theta2")
xd_o, yd_o, thd1, thd2 = R("xd_o"), R("yd_o"), R("thetad1"), R("thetad2")
l, c, w, r, J_l = R("l"), R("c"), R("w"), R("r"), R("J_l")
m_h, m_l, k_hip, d_hip, gamma, g = R("m_h"), R("m_l"), R("k_hip"), R("d_hip"), R("gamma"), R("g")
k_n, d_n, k_t, d_t = R("k_n"), R("d_n"), R("k_t"), R("d_t")
v_s, v_d, mu_s, mu_d = R("v_s"), R("v_d"), R("mu_s"), R("mu_d")
F_n1, F_n2, F_t1, F_t2 = R("F_n1"), R("F_n2"), R("F_t1"), R("F_t2")
delta, deltad, v_t, xi = R("delta"), R("deltad"), R("v_t"), R("xi")
s0 = (R("s0_1"), R("s0_2"))
sin_gamma, cos_gamma = R("sin_gamma"), R("cos_gamma")

q = sp.Matrix([x_o, y_o, th1, th2])
qd = sp.Matrix([xd_o, yd_o, thd1, thd2])
qdd = sp.Matrix(sp.symbols("qdd0:4", real=True))
TH, THD = (th1, th2), (thd1, thd2)
s1, c1, s2, c2 = sp.sin(th1), sp.cos(th1), sp.sin(th2), sp.cos(th2)
m = m_h + 2 * m_l
UNGAMMA = {sin_gamma: sp.sin(gamma), cos_gamma: sp.cos(gamma)}

# --- docs/model.md section 3, transcribed ---------------------------------------------------------
M_T = sp.Matrix([
    [m, 0, m_l * (c * c1 - w * s1), m_l * (c * c2 - w * s2)],
    [0, m, m_l * (c * s1 + w * c1), m_l * (c * s2 + w * c2)],
    [m_l * (c * c1 - w * s1), m_l * (c * s1 + w * c1), m_l * (c**2 + w**2) + J_l, 0],
    [m_l * (c * c2 - w * s2), m_l * (c * s2 + w * c2), 0, m_l * (c**2 + w**2) + J_l],
])
C_T = sp.Matrix([
    [0, 0, -m_l * (c * s1 + w * c1) * thd1, -m_l * (c * s2 + w * c2) * thd2],
    [0, 0, m_l * (c * c1 - w * s1) * thd1, m_l * (c * c2 - w * s2) * thd2],
    [0, 0, 0, 0],
    [0, 0, 0, 0],
])
G_T = sp.Matrix([
    -m * g * sp.sin(gamma),
    m * g * sp.cos(gamma),
    k_hip * (th1 - th2) + m_l * g * (c * sp.sin(th1 - gamma) + w * sp.cos(th1 - gamma)),
    k_hip * (th2 - th1) + m_l * g * (c * sp.sin(th2 - gamma) + w * sp.cos(th2 - gamma)),
])
QF_T = sp.Matrix([
    F_t1 + F_t2,
    F_n1 + F_n2,
    F_t1 * ((l - r) * c1 + r) + F_n1 * (l - r) * s1 - d_hip * (thd1 - thd2),
    F_t2 * ((l - r) * c2 + r) + F_n2 * (l - r) * s2 - d_hip * (thd2 - thd1),
])


def _ddt(expr):
    """Total time derivative along (q, qd)."""
    return sum(sp.diff(expr, a) * b for a, b in zip(q, qd))


def _points():
    """Hip H and leg centres of mass G_i of docs/model.md section 2, our own transcription."""
    H = sp.Matrix([x_o, y_o])
    Gs = []
    for th in TH:
        e = sp.Matrix([sp.sin(th), -sp.cos(th)])
        n = sp.Matrix([sp.cos(th), sp.sin(th)])
        Gs.append(H + c * e + w * n)
    return H, Gs


def _T_V():
    H, Gs = _points()
    Hd = H.applyfunc(_ddt)
    T = m_h * (Hd.dot(Hd)) / 2
    Vg = m_h * g * (H[1] * sp.cos(gamma) - H[0] * sp.sin(gamma))
    for Gi, thd in zip(Gs, THD):
        Gd = Gi.applyfunc(_ddt)
        T += m_l * Gd.dot(Gd) / 2 + J_l * thd**2 / 2
        Vg += m_l * g * (Gi[1] * sp.cos(gamma) - Gi[0] * sp.sin(gamma))
    Vh = k_hip * (th1 - th2) ** 2 / 2
    return T, Vg, Vh


def is_zero(expr):
    return sp.simplify(expr) == 0


def is_zero_matrix(mat):
    return sp.simplify(mat) == sp.zeros(*mat.shape)


# --- section 3: M, C qd, C, G, Q_f -------------------------------------------------------------
def test_mass_matrix_matches_model_md(mech):
    assert is_zero_matrix(mech.M - M_T)


def test_coriolis_product_matches_model_md(mech):
    assert is_zero_matrix(mech.Cqd - C_T * qd)


def test_christoffel_matrix_is_the_printed_appendix_c(mech):
    # the central difference method (docs/model.md section 7) depends on C itself, not only on C qd
    assert is_zero_matrix(mech.C - C_T)
    assert is_zero_matrix(mech.C * qd - mech.Cqd)


def test_christoffel_matrix_makes_mdot_minus_2c_skew(mech):
    Mdot = mech.M.applyfunc(_ddt)
    N = Mdot - 2 * mech.C
    assert is_zero_matrix(N + N.T)


def test_gravity_and_spring_vector_matches_model_md(mech):
    assert mech.G.free_symbols - {sin_gamma, cos_gamma} <= set(q) | {m_h, m_l, c, w, g, k_hip}
    assert is_zero_matrix(mech.G.subs(UNGAMMA) - G_T)


def test_generalized_forces_match_model_md():
    assert is_zero_matrix(dm.generalized_forces() - QF_T)


def test_generalized_forces_without_hip_damper_drop_only_d_hip():
    Qf = dm.generalized_forces(features=tuple(f for f in dm.FEATURES if f != "hip_damper"))
    assert is_zero_matrix(Qf - QF_T.subs(d_hip, 0))


def test_energies_match_model_md(mech):
    T, Vg, Vh = _T_V()
    assert is_zero(mech.T - T)
    assert is_zero(mech.V_gravity.subs(UNGAMMA) - Vg)
    assert is_zero(mech.V_hip - Vh)
    # T is the quadratic form of M
    assert is_zero(mech.T - (qd.T * M_T * qd)[0] / 2)


def test_model_md_matrices_are_lagranges_equations():
    """docs/model.md's M, C, G follow from its own T and V (independent of derive/)."""
    T, Vg, Vh = _T_V()
    L = T - Vg - Vh
    eqs = []
    for qi, qdi in zip(q, qd):
        p = sp.diff(L, qdi)
        dpdt = _ddt(p) + sum(sp.diff(p, b) * a for b, a in zip(qd, qdd))
        eqs.append(dpdt - sp.diff(L, qi))
    assert is_zero_matrix(sp.Matrix(eqs) - (M_T * qdd + C_T * qd + G_T))


# --- section 2 and 6: contact kinematics ---------------------------------------------------------
def _kin_transcribed(i, variant):
    th, thd = TH[i], THD[i]
    out = {
        "x_D": x_o + (l - r) * sp.sin(th),                          # Eq. 4
        "y_D": y_o - r - (l - r) * sp.cos(th),                      # Eq. 4
        "v_x": xd_o + ((l - r) * sp.cos(th) + r) * thd,             # Eq. 9
        "s": x_o + (l - r) * sp.sin(th) + r * th,                   # section 6
    }
    if variant == "paper":
        out["v_y"] = yd_o + (l - r) * sp.sin(th) * thd + r * thd     # Eq. 5 as printed
        out["xi"] = (l - r) * sp.sin(th)                             # Eq. 8
    else:
        out["v_y"] = yd_o + (l - r) * sp.sin(th) * thd               # d/dt of Eq. 4
        out["xi"] = out["s"] - s0[i]                                 # slip since touch-down
    out["v_in"] = sp.Symbol("v_in%d" % (i + 1), real=True)        # approach speed at touch-down
    out["z"] = sp.S.Zero                                          # no bristle state (Coulomb)
    return out


@pytest.mark.parametrize("variant", ["paper", "consistent"])
@pytest.mark.parametrize("foot", [0, 1])
def test_contact_kinematics_match_model_md(foot, variant):
    derived = dm.contact_kinematics(foot, variant)
    mine = _kin_transcribed(foot, variant)
    assert set(derived) == set(mine)
    # under LuGre friction the foot's bristle state z_i, the rest unchanged
    lugre = dm.contact_kinematics(foot, variant, "lugre")
    assert lugre["z"] == sp.Symbol("z%d" % (foot + 1), real=True)
    assert all(lugre[k] == derived[k] for k in derived if k != "z")
    for name, expr in mine.items():
        assert is_zero(derived[name] - expr), (foot, variant, name, derived[name])
    # only the foot's own angle enters
    other = {th1, thd1} if foot == 1 else {th2, thd2}
    assert not any(e.free_symbols & other for e in derived.values())


@pytest.mark.parametrize("foot", [0, 1])
def test_consistent_rates_are_time_derivatives(foot):
    kin = dm.contact_kinematics(foot, "consistent")
    assert is_zero(kin["v_y"] - _ddt(kin["y_D"]))        # consistent Eq. 5
    assert is_zero(kin["v_x"] - _ddt(kin["s"]))          # ds/dt = v_x (Eq. 9)
    assert is_zero(kin["v_x"] - _ddt(kin["xi"]))         # anchored xi moves with the slip
    paper = dm.contact_kinematics(foot, "paper")
    assert is_zero(paper["v_y"] - kin["v_y"] - r * THD[foot])   # the printed extra r*thetad


def test_invalid_variant_is_rejected():
    with pytest.raises(ValueError, match="variant"):
        dm.contact_kinematics(0, "rigid")


@pytest.mark.parametrize("foot", [0, 1])
def test_material_velocity_is_the_rolling_arc_point(foot):
    """Velocity of the leg's material point at D_i, from rigid-body kinematics: v_A + omega x (D - A)."""
    th, thd = TH[foot], THD[foot]
    A = sp.Matrix([x_o, y_o]) + (l - r) * sp.Matrix([sp.sin(th), -sp.cos(th)])
    vA = A.applyfunc(_ddt)
    rel = sp.Matrix([0, -r])                       # D - A
    v = vA + thd * sp.Matrix([-rel[1], rel[0]])    # omega e_z x rel
    assert is_zero_matrix(dm.material_velocity(foot) - v)


# --- section 4: friction coefficient, Eq. 10 ----------------------------------------------------
def _step(x, x0, h0, x1, h1):
    D = (x - x0) / (x1 - x0)
    return h0 + (h1 - h0) * D**2 * (3 - 2 * D)


MU_BRANCHES = [   # (expression, lower end, upper end), in the order of docs/model.md section 4
    (mu_d, None, -v_d),
    (_step(v_t, -v_d, mu_d, -v_s, mu_s), -v_d, -v_s),
    (_step(v_t, -v_s, mu_s, v_s, -mu_s), -v_s, v_s),
    (_step(v_t, v_s, -mu_s, v_d, -mu_d), v_s, v_d),
    (-mu_d, v_d, None),
]
# values of mu at the breakpoints -v_d, -v_s, 0, v_s, v_d
MU_AT = {-v_d: mu_d, -v_s: mu_s, 0: 0, v_s: -mu_s, v_d: -mu_d}


def _mu_transcribed(v):
    return sp.Piecewise(*[(e.subs(v_t, v), v <= hi) for e, _, hi in MU_BRANCHES[:-1]],
                        (MU_BRANCHES[-1][0].subs(v_t, v), True))


@pytest.fixture(scope="module")
def mu_pieces():
    mu = dm.friction_coefficient(v_t)
    assert isinstance(mu, sp.Piecewise) and len(mu.args) == 5
    return [a.expr for a in mu.args]


def test_friction_branches_match_eq10(mu_pieces):
    for derived, (mine, _, _) in zip(mu_pieces, MU_BRANCHES):
        assert is_zero(derived - mine)


def test_friction_values_at_breakpoints(mu_pieces):
    for k, (_, lo, hi) in enumerate(MU_BRANCHES):
        for end in (lo, hi):
            if end is not None:
                assert is_zero(mu_pieces[k].subs(v_t, end) - MU_AT[end]), (k, end)
    assert is_zero(mu_pieces[2].subs(v_t, 0))          # mu(0) = 0


def test_friction_is_c1_continuous(mu_pieces):
    # value and slope agree at every breakpoint: cubic steps have zero slope at both ends
    for k in range(4):
        bp = MU_BRANCHES[k][2]
        for a, b in ((mu_pieces[k], mu_pieces[k + 1]), (sp.diff(mu_pieces[k], v_t), sp.diff(mu_pieces[k + 1], v_t))):
            assert is_zero(a.subs(v_t, bp) - b.subs(v_t, bp)), (k, a, b)


def test_friction_is_odd(mu_pieces):
    for k in range(5):
        assert is_zero(mu_pieces[k] + mu_pieces[4 - k].subs(v_t, -v_t)), k


def test_friction_slope_at_zero_is_steep(mu_pieces):
    # |dmu/dv| at 0 = 3 mu_s / (2 v_s) (docs/model.md: about 0.75 / v_s)
    assert is_zero(sp.diff(mu_pieces[2], v_t).subs(v_t, 0) + 3 * mu_s / (2 * v_s))


# exact rational parameter sets: docs/model.md section 1 and an unrelated one
PARAM_SETS = [
    {k_n: 10**5, d_n: 10**6, k_t: 90, d_t: 900, v_s: sp.Rational(1, 10**4), v_d: sp.Rational(1, 10**3),
     mu_s: sp.Rational(1, 2), mu_d: sp.Rational(2, 5)},
    {k_n: 37, d_n: 11, k_t: 3, d_t: 7, v_s: sp.Rational(1, 3), v_d: sp.Rational(5, 4),
     mu_s: sp.Rational(3, 10), mu_d: sp.Rational(9, 10)},
]
PARAM_SETS = [{k: sp.S(v) for k, v in P.items()} for P in PARAM_SETS]   # exact, never floats


@pytest.mark.parametrize("pset", range(len(PARAM_SETS)))
def test_friction_piecewise_conditions_exact(pset):
    """The full Piecewise (with its conditions) at exact rational slip velocities in every branch."""
    P = PARAM_SETS[pset]
    vs, vd = P[v_s], P[v_d]
    mu = dm.friction_coefficient(v_t).xreplace(P)
    mine = _mu_transcribed(v_t).xreplace(P)
    fracs = [sp.Rational(k, 7) for k in range(-21, 22)]
    vals = sorted({vs * f for f in fracs} | {vd * f for f in fracs} | {-vd, -vs, 0, vs, vd})
    for v in vals:
        a, b = mu.subs(v_t, v), mine.subs(v_t, v)
        assert a.is_Rational and a == b, (v, a, b)
        assert mu.subs(v_t, -v) == -a                              # odd
        assert abs(a) <= max(P[mu_s], P[mu_d])
        if v != 0:
            assert a * v < 0                                        # opposes slip
    assert mu.subs(v_t, 0) == 0
    assert mu.subs(v_t, -vd) == P[mu_d] and mu.subs(v_t, -vs) == P[mu_s]
    assert mu.subs(v_t, vs) == -P[mu_s] and mu.subs(v_t, vd) == -P[mu_d]
    assert mu.subs(v_t, 10 * vd) == -P[mu_d] and mu.subs(v_t, -10 * vd) == P[mu_d]


# --- section 4: normal and tangential laws (Eqs. 3, 6, 7, 11) ---------------------------------
def _laws_transcribed(variant, P):
    """F_n, F_t of one penetrating support foot at exact values (docs/model.md section 4)."""
    def laws(dl, dld, vt, x):
        fn = P[k_n] * dl**sp.Rational(3, 2) + P[d_n] * dl**sp.Rational(3, 2) * dld
        fn = max(fn, 0)                                            # the ground cannot pull
        mu = _mu_transcribed(vt).xreplace(P)
        sd = -sp.sign(x) * P[k_t] * abs(x)**sp.Rational(3, 2) - P[d_t] * abs(x)**sp.Rational(3, 2) * vt
        if variant == "paper" and x > 0:                           # Eq. 11's gate
            sd = 0
        return fn, sd + mu * fn, mu
    return laws


def _law_grid(P):
    vs, vd = P[v_s], P[v_d]
    deltas = [sp.Rational(1, 100) ** 2, sp.Rational(7, 100) ** 2]           # exact delta^1.5
    kd = P[k_n] / P[d_n]                                                    # clamp at deltad = -k_n/d_n
    deltads = [-3 * kd, -kd / 2, 0, 2 * kd]
    vts = [-2 * vd, -(vs + vd) / 2, -vs / 3, 0, vs / 2, (vs + vd) / 2, 3 * vd]
    xis = [-sp.Rational(3, 100) ** 2, 0, sp.Rational(2, 100) ** 2]
    return [(a, b, cc, dd) for a in deltas for b in deltads for cc in vts for dd in xis]


@pytest.mark.parametrize("variant", ["paper", "consistent"])
@pytest.mark.parametrize("pset", range(len(PARAM_SETS)))
def test_contact_laws_match_model_md(variant, pset):
    P = PARAM_SETS[pset]
    laws = dm.contact_laws(variant)
    exprs = {k: laws[k].xreplace(P) for k in ("F_n", "F_t", "mu")}
    mine = _laws_transcribed(variant, P)
    clamped = 0
    for dl, dld, vt, x in _law_grid(P):
        sub = {delta: dl, deltad: dld, v_t: vt, xi: x}
        fn, ft, mu = mine(dl, dld, vt, x)
        got = [exprs[k].xreplace(sub) for k in ("F_n", "F_t", "mu")]
        for a, b in zip(got, (fn, ft, mu)):
            assert a.is_Rational and is_zero(a - b), (variant, sub, got, (fn, ft, mu))
        clamped += fn == 0
    assert clamped > 0                          # the Hunt-Crossley clamp was exercised


@pytest.mark.parametrize("variant", ["paper", "consistent"])
def test_contact_partials_are_derivatives_of_the_laws(variant):
    """dFn/ddelta, dFn/ddeltad, dFt/dxi, dFt/dv (used by the Jacobian) vs SymPy's own derivatives
    of the transcribed laws, off the switching surfaces."""
    P = PARAM_SETS[0]
    laws = {k: e.xreplace(P) for k, e in dm.contact_laws(variant).items()}
    pos = sp.Symbol("pos", positive=True)
    mu = _mu_transcribed(v_t).xreplace(P)
    fn = (P[k_n] + P[d_n] * deltad) * pos**sp.Rational(3, 2)
    sd = -sp.sign(xi) * P[k_t] * sp.Abs(xi)**sp.Rational(3, 2) - P[d_t] * sp.Abs(xi)**sp.Rational(3, 2) * v_t
    vs, vd = P[v_s], P[v_d]
    for dl in (sp.Rational(1, 100) ** 2, sp.Rational(3, 100) ** 2):
        for dld in (-sp.Rational(1, 20), sp.Rational(1, 5)):            # no clamp
            for vt in (-2 * vd, -(vs + vd) / 2, vs / 3, (vs + vd) / 3, 3 * vd):
                for x in (-sp.Rational(4, 100) ** 2, sp.Rational(1, 100) ** 2):
                    gate = 0 if (variant == "paper" and x > 0) else 1
                    ft = gate * sd + mu * fn
                    sub = {delta: dl, deltad: dld, v_t: vt, xi: x}
                    at = {pos: dl, deltad: dld, v_t: vt, xi: x}
                    expect = {
                        "dFn_ddelta": sp.diff(fn, pos).subs(at),
                        "dFn_ddeltad": sp.diff(fn, deltad).subs(at),
                        "dFt_dxi": sp.diff(ft, xi).subs(at),
                        "dFt_dv": sp.diff(ft, v_t).subs(at),
                    }
                    for k, e in expect.items():
                        assert is_zero(laws[k].xreplace(sub) - e), (variant, k, sub)


def test_features_fold_their_parameters():
    laws = dm.contact_laws("consistent", features=("hip_spring", "hip_damper", "tangential"))
    assert laws["mu"] == 0
    assert d_n not in laws["F_n"].free_symbols
    laws = dm.contact_laws("consistent", features=("friction", "normal_damping"))
    assert not ({k_t, d_t} & laws["F_t"].free_symbols)
