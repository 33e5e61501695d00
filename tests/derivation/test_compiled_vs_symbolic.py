"""The compiled model (pdw.rhs, pdw.jacobian, pdw.mass_matrix, pdw.contact_forces, pdw.energies)
against an independent evaluation of the symbolic derivation.

The reference lambdifies the expressions of derive/model.py (M, C qd, C, G, Q_f, contact
kinematics, force laws, energies) and composes them here, with this module's own gating (forces
only on a support foot, flag 1, that penetrates, y_D < 0) and its own linear solve. It shares
no code with derive/stages.py, derive/emit.py or generated/.
"""
import numpy as np
import pytest

sp = pytest.importorskip("sympy")

import pdw  # noqa: E402
from derive import model as dm  # noqa: E402
from pdw.core import _core  # noqa: E402
from pdw.core.model import kernel_index, parameter_vector  # noqa: E402

RTOL = 1e-12
N_STATES = 240


def R(name):
    return sp.Symbol(name, real=True)


XS = [R(n) for n in pdw.STATE]
PS = [R(n) for n in pdw.Params.__dataclass_fields__]
SG, CG = R("sin_gamma"), R("cos_gamma")
FS = [R(n) for n in ("F_n1", "F_n2", "F_t1", "F_t2")]
ANCH = [R("s0_1"), R("s0_2")]
LAWVARS = [R(n) for n in ("delta", "deltad", "v_t", "xi")]
KIN = ("x_D", "y_D", "v_x", "v_y", "s", "xi")


def close(a, b, scale=1.0, rtol=RTOL):
    """Norm-wise relative comparison |a - b| <= rtol (|b| + scale), max norms."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, (a.shape, b.shape)
    err = np.max(np.abs(a - b)) if a.size else 0.0
    return err <= rtol * (np.max(np.abs(b)) + scale)


def _lists(e):
    """Matrices as nested lists (the "math" printer has no Matrix)."""
    if isinstance(e, sp.MatrixBase):
        return e.tolist()
    if isinstance(e, (list, tuple)):
        return [_lists(a) for a in e]
    return e


class Reference:
    """Lambdified derive/model.py expressions + our own composition."""

    def __init__(self, mech):
        args = XS + PS + [SG, CG]
        lam = lambda e, extra=(): sp.lambdify(args + list(extra), _lists(e), modules="math")  # noqa: E731
        self.M = lam(mech.M)
        self.Cqd = lam(mech.Cqd)
        self.C = lam(mech.C)
        self.G = lam(mech.G)
        self.Qf = lam(dm.generalized_forces(), FS)
        self.E = lam([mech.T, mech.V_gravity, mech.V_hip])
        self.kin = {(v, i): lam([dm.contact_kinematics(i, v)[k] for k in KIN], ANCH)
                    for v in dm.VARIANTS for i in range(2)}
        self.laws = {}
        for v in dm.VARIANTS:
            laws = dm.contact_laws(v)
            self.laws[v] = sp.lambdify(LAWVARS + PS, [laws["F_n"], laws["F_t"], laws["mu"]], modules="math")

    @staticmethod
    def _args(x, params):
        pv = [getattr(params, n) for n in pdw.Params.__dataclass_fields__]
        return list(map(float, x)) + pv + [np.sin(params.gamma), np.cos(params.gamma)]

    def contact(self, x, params, flags, anchors, variant):
        """Per-foot dict of kinematics and forces, gated by our own rule."""
        a = self._args(x, params)
        pv = a[len(XS):len(XS) + len(PS)]
        out = []
        for i in range(2):
            kin = dict(zip(KIN, self.kin[variant, i](*a, *anchors)))
            active = flags[i] == 1 and kin["y_D"] < 0.0
            if active:
                Fn, Ft, mu = self.laws[variant](-kin["y_D"], -kin["v_y"], kin["v_x"], kin["xi"], *pv)
            else:
                Fn = Ft = mu = 0.0
            kin.update(F_n=float(Fn), F_t=float(Ft), mu=float(mu), active=active)
            out.append(kin)
        return out

    def rhs(self, x, params, flags, anchors, variant):
        a = self._args(x, params)
        feet = self.contact(x, params, flags, anchors, variant)
        F = [feet[0]["F_n"], feet[1]["F_n"], feet[0]["F_t"], feet[1]["F_t"]]
        M = np.array(self.M(*a), float)
        f = (np.array(self.Qf(*a, *F), float) - np.array(self.Cqd(*a), float)
             - np.array(self.G(*a), float)).ravel()
        qdd = np.linalg.solve(M, f)
        return np.concatenate([np.asarray(x[4:], float), qdd]), feet, M, f

    def energies(self, x, params):
        return np.array(self.E(*self._args(x, params)), float)


@pytest.fixture(scope="module")
def ref(mech):
    return Reference(mech)


# --- random states covering every branch ---------------------------------------------------------
PARAMS = {
    "paper": pdw.Params.paper(),
    "point_feet": pdw.Params.paper(r=0.0),
    # unrelated values, so that no coincidence of the paper's numbers hides an error
    "generic": pdw.Params(l=0.8, c=0.27, w=0.031, r=0.35, J_l=0.11, m_h=3.3, m_l=1.7, k_hip=2.1,
                          d_hip=0.07, gamma=0.09, g=9.81, k_n=3e4, d_n=2e5, k_t=40.0, d_t=300.0,
                          v_s=2e-4, v_d=3e-3, mu_s=0.7, mu_d=0.45),
}
CASES = [("paper", "paper"), ("consistent", "paper"), ("paper", "point_feet"),
         ("consistent", "point_feet"), ("paper", "generic"), ("consistent", "generic")]


def slip_targets(rng, p, n):
    """Slip velocities in the five branches of Eq. 10, both signs."""
    vs, vd = p.v_s, p.v_d
    lo, hi = np.array([(-0.8, -vd), (-vd, -vs), (-vs, vs), (vs, vd), (vd, 0.8)]).T
    k = rng.integers(0, len(lo), n)
    return lo[k] + (hi[k] - lo[k]) * rng.uniform(size=n)


def make_states(rng, p, n, variant):
    """States, flags and anchors: swing/support, penetrating or not, every force branch."""
    L = p.l - p.r
    th = rng.uniform(-0.45, 0.45, (n, 2))
    near = rng.uniform(size=n) < 0.35                      # double-support-like: both feet low
    th[near, 1] = -th[near, 0] + rng.uniform(-0.01, 0.01, near.sum())
    x_o = rng.uniform(-1.0, 1.0, n)
    lowest = p.r + L * np.max(np.cos(th), axis=1)
    y_o = lowest + rng.uniform(-0.012, 0.006, n)           # lowest foot from 12 mm deep to 6 mm up
    xd_o = rng.uniform(-1.0, 1.0, n)
    yd_o = rng.uniform(-0.4, 0.4, n)                       # foot leaving faster than k_n/d_n: clamp
    thd = np.empty((n, 2))
    for i in range(2):
        vt = slip_targets(rng, p, n)
        thd[:, i] = (vt - xd_o) / (L * np.cos(th[:, i]) + p.r)
    X = np.column_stack([x_o, y_o, th[:, 0], th[:, 1], xd_o, yd_o, thd[:, 0], thd[:, 1]])
    flags = np.array([(0, 0), (0, 1), (1, 0), (1, 1), (1, 1), (1, 1)])[rng.integers(0, 6, n)]
    if variant == "consistent":
        s = x_o[:, None] + L * np.sin(th) + p.r * th
        anchors = s - rng.uniform(-0.01, 0.01, (n, 2))     # slip since touch-down, both signs
    else:
        anchors = rng.uniform(-1, 1, (n, 2))               # must be ignored by the paper variant
    return X, flags, anchors


@pytest.fixture(scope="module", params=CASES, ids=["-".join(c) for c in CASES])
def case(request, ref):
    variant, pname = request.param
    p = PARAMS[pname]
    rng = np.random.default_rng(1000 + CASES.index(request.param))
    X, flags, anchors = make_states(rng, p, N_STATES, variant)
    refs = [ref.rhs(X[j], p, flags[j], anchors[j], variant) for j in range(len(X))]
    return dict(variant=variant, p=p, pname=pname, X=X, flags=flags, anchors=anchors, refs=refs)


def test_states_cover_every_branch(case):
    """The random states really exercise what the comparisons claim to cover."""
    p = case["p"]
    cnt = dict(swing_pen=0, sup_above=0, both=0, clamp=0, xi_pos=0, xi_neg=0, branch=[0] * 5)
    edges = [-p.v_d, -p.v_s, p.v_s, p.v_d]
    for (_xdot, feet, _M, _f), fl in zip(case["refs"], case["flags"]):
        cnt["both"] += feet[0]["active"] and feet[1]["active"]
        for i, ft in enumerate(feet):
            cnt["swing_pen"] += fl[i] == 0 and ft["y_D"] < 0
            cnt["sup_above"] += fl[i] == 1 and ft["y_D"] >= 0
            if ft["active"]:
                cnt["branch"][int(np.searchsorted(edges, ft["v_x"]))] += 1
                cnt["clamp"] += ft["F_n"] == 0.0
                cnt["xi_pos" if ft["xi"] > 0 else "xi_neg"] += 1
    assert min(cnt["branch"]) >= 8, cnt
    for k in ("swing_pen", "sup_above", "both", "clamp", "xi_pos", "xi_neg"):
        assert cnt[k] >= 5, (k, cnt)


def test_rhs_matches_reference(case):
    X = case["X"]
    got = pdw.rhs(X, case["p"], flags=case["flags"], anchors=case["anchors"], variant=case["variant"])
    bad = [j for j, (xdot, *_) in enumerate(case["refs"]) if not close(got[j], xdot)]
    assert not bad, (len(bad), got[bad[0]], case["refs"][bad[0]][0])
    # one state at a time gives the same
    j = 7
    one = pdw.rhs(X[j], case["p"], flags=tuple(case["flags"][j]), anchors=tuple(case["anchors"][j]),
                  variant=case["variant"])
    assert one.shape == (8,) and np.array_equal(one, got[j])


def test_contact_forces_match_reference(case):
    X = case["X"]
    cs = pdw.contact_forces(X, case["p"], flags=case["flags"], anchors=case["anchors"],
                            variant=case["variant"])
    for field in KIN + ("F_n", "F_t", "mu"):
        got = getattr(cs, field)
        assert got.shape == (len(X), 2)
        want = np.array([[ft[field] for ft in refs[1]] for refs in case["refs"]])
        for j in range(len(X)):
            assert close(got[j], want[j]), (field, j, got[j], want[j])
    # gating: exactly zero where the foot is not a penetrating support foot
    active = np.array([[ft["active"] for ft in refs[1]] for refs in case["refs"]])
    assert np.all(cs.F_n[~active] == 0) and np.all(cs.F_t[~active] == 0) and np.all(cs.mu[~active] == 0)
    assert np.all(cs.F_n >= 0)


def test_mass_matrix_matches_reference(case):
    X, p = case["X"], case["p"]
    got = pdw.mass_matrix(X[:, :4], p)
    assert got.shape == (len(X), 4, 4)
    for j in range(len(X)):
        assert close(got[j], case["refs"][j][2]), j
    assert np.array_equal(pdw.mass_matrix(X[3], p), got[3])          # full state accepted
    assert np.array_equal(pdw.mass_matrix(X[3, :4], p), got[3])


def test_energies_match_reference(case, ref):
    X, p = case["X"], case["p"]
    e = pdw.energies(X, p)
    for j in range(len(X)):
        want = ref.energies(X[j], p)
        got = np.array([e["T"][j], e["V_gravity"][j], e["V_hip"][j]])
        assert close(got, want), (j, got, want)
        assert close(e["E"][j], want.sum(), scale=np.abs(want).max())


def test_cdm_terms_match_reference(case, ref):
    """M, the appendix C and Q_f - G of the central difference stage (private _core.cdm_terms)."""
    X, p = case["X"], case["p"]
    k = kernel_index(case["variant"])
    pv = parameter_vector(p)
    nc = len(pdw.core._layout.CONTACT)
    rng = np.random.default_rng(5)
    for j in range(0, len(X), 7):
        F = rng.uniform(-200, 200, 4)             # F_n1, F_n2, F_t1, F_t2
        contact = np.zeros(2 * nc)
        for i in range(2):
            contact[i * nc + pdw.core._layout.CONTACT.index("F_n")] = F[i]
            contact[i * nc + pdw.core._layout.CONTACT.index("F_t")] = F[2 + i]
        M, C, QmG = np.empty(16), np.empty(16), np.empty(4)
        _core.cdm_terms(k, np.ascontiguousarray(X[j]), pv, contact, M, C, QmG)
        a = ref._args(X[j], p)
        assert close(M.reshape(4, 4), np.array(ref.M(*a), float))
        assert close(C.reshape(4, 4), np.array(ref.C(*a), float))
        want = (np.array(ref.Qf(*a, *F), float) - np.array(ref.G(*a), float)).ravel()
        assert close(QmG, want), (QmG, want)


def test_paper_variant_ignores_anchors(ref):
    p = PARAMS["paper"]
    X, flags, anchors = make_states(np.random.default_rng(3), p, 50, "paper")
    a = pdw.rhs(X, p, flags=flags, anchors=anchors, variant="paper")
    b = pdw.rhs(X, p, flags=flags, anchors=(0.0, 0.0), variant="paper")
    assert np.array_equal(a, b)
    c = pdw.rhs(X, p, flags=flags, anchors=anchors, variant="consistent")
    assert not np.allclose(a, c)                     # and the variants differ


# --- the Jacobian ------------------------------------------------------------------------------
class ReferenceJacobian:
    """SymPy's own derivative of the full f(x) = Q_f(F(x)) - C qd - G (forces substituted as
    functions of the state, switched on by the symbols a1, a2 > 0), lambdified; qdd' = M^-1 (df/dx - dM/dx qdd)."""

    def __init__(self, mech, variant):
        gates = [R("a1"), R("a2")]
        sub = {}
        for i in range(2):
            kin = dm.contact_kinematics(i, variant)
            laws = dm.contact_laws(variant)
            at = dict(zip(LAWVARS, (-kin["y_D"], -kin["v_y"], kin["v_x"], kin["xi"])))
            # Python's conditional expression keeps an inactive foot's law unevaluated (its
            # depth is negative there); no CSE, which would hoist it out of the condition
            sub[FS[i]] = sp.Piecewise((laws["F_n"].xreplace(at), gates[i] > 0), (0, True))
            sub[FS[2 + i]] = sp.Piecewise((laws["F_t"].xreplace(at), gates[i] > 0), (0, True))
        f = dm.generalized_forces().xreplace(sub) - mech.Cqd - mech.G
        J = f.jacobian(XS)
        dM = [mech.M.diff(x) for x in XS]
        args = XS + PS + [SG, CG] + ANCH + gates
        self.J = sp.lambdify(args, _lists(J), modules="math")
        self.dM = sp.lambdify(args, _lists(dM), modules="math")

    def __call__(self, x, p, active, anchors, M, qdd):
        a = Reference._args(x, p) + list(anchors) + [float(b) for b in active]
        Jf = np.array(self.J(*a), float)
        dM = np.array(self.dM(*a), float)                 # (8, 4, 4)
        A = Jf - np.einsum("kij,j->ik", dM, qdd)
        out = np.zeros((8, 8))
        out[:4, 4:] = np.eye(4)
        out[4:] = np.linalg.solve(M, A)
        return out


@pytest.fixture(scope="module")
def ref_jac(mech):
    return {v: ReferenceJacobian(mech, v) for v in dm.VARIANTS}


def away_from_switching(p, feet, margin=2e-5):
    """True if no force law is within `margin` of a switching surface at this state."""
    for ft in feet:
        if abs(ft["y_D"]) < 1e-4:
            return False
        if not ft["active"]:
            continue
        v = ft["v_x"]
        if min(abs(v - e) for e in (-p.v_d, -p.v_s, p.v_s, p.v_d)) < margin * p.v_s / 1e-4:
            return False
        if abs(-ft["v_y"] + p.k_n / p.d_n) < 1e-3 or abs(ft["xi"]) < 1e-4:
            return False
    return True


def test_jacobian_matches_symbolic_derivative(case, ref_jac):
    X, p, variant = case["X"], case["p"], case["variant"]
    J = pdw.jacobian(X, p, flags=case["flags"], anchors=case["anchors"], variant=variant)
    assert J.shape == (len(X), 8, 8)
    checked = 0
    for j in range(len(X)):
        xdot, feet, M, f = case["refs"][j]
        if not away_from_switching(p, feet):
            continue
        active = [ft["active"] for ft in feet]
        want = ref_jac[variant](X[j], p, active, case["anchors"][j], M, xdot[4:])
        assert close(J[j], want, rtol=1e-11), (j, np.max(np.abs(J[j] - want)), np.max(np.abs(want)))
        checked += 1
    assert checked >= len(X) // 3


def test_jacobian_matches_finite_differences(case):
    X, p, variant = case["X"], case["p"], case["variant"]
    checked = 0
    for j in range(0, len(X), 3):
        xdot, feet, M, f = case["refs"][j]
        if not away_from_switching(p, feet):
            continue
        fl, an = tuple(case["flags"][j]), tuple(case["anchors"][j])
        J = pdw.jacobian(X[j], p, flags=fl, anchors=an, variant=variant)
        h = 1e-7 * np.maximum(1.0, np.abs(X[j]))
        E = np.diag(h)
        fp = pdw.rhs(X[j] + E, p, flags=fl, anchors=an, variant=variant)
        fm = pdw.rhs(X[j] - E, p, flags=fl, anchors=an, variant=variant)
        Jfd = ((fp - fm) / (2 * h[:, None])).T
        assert np.array_equal(J[:4], np.hstack([np.zeros((4, 4)), np.eye(4)]))
        for k in range(8):       # column by column: each state component's own scale
            assert close(J[:, k], Jfd[:, k], rtol=2e-5), \
                (j, k, J[:, k], Jfd[:, k])
        checked += 1
    assert checked >= len(X) // 10
