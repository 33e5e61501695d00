"""Symbolic model of the flexible planar passive walker on compliant ground.

Everything here follows docs/model.md (the specification); equation numbers
are the paper's. The functions return SymPy expressions built deterministically
(no dict/set iteration order leaks into them), so that `derive.emit` produces the
same bytes on every run.

Stages, in data-flow order:

1. `mechanics` -- T, V, Lagrange's equations: M(q), C(q, qd) qd, G(q) (Eq. 2, A.1-A.4),
   and the Christoffel matrix C printed in the appendix (used by the central
   difference method, whose result depends on C itself).
2. `contact_kinematics` -- contact point, depth, normal rate, slip velocity,
   tangential deformation of one foot (Eqs. 4, 5, 8, 9), per variant (docs/model.md section 6).
3. `contact_laws` -- Hunt-Crossley normal force (Eqs. 3, 6, clamped at 0), the
   friction coefficient of Eq. 10, the tangential spring-damper plus friction
   (Eqs. 7, 11), and their partial derivatives.
4. `generalized_forces` -- Q_f: virtual work of the contact forces at the feet's
   material points plus the hip damper.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import sympy as sp

from . import contact_laws as laws
from . import layout

VARIANTS = ("paper", "consistent")
# Force elements a kernel can omit (their parameters folded to zero before CSE).
FEATURES = ("hip_spring", "hip_damper", "normal_damping", "tangential", "friction")
FEATURE_PARAMS = {
    "hip_spring": ("k_hip",),
    "hip_damper": ("d_hip",),
    "normal_damping": ("d_n",),
    "tangential": ("k_t", "d_t"),
}


def _real(name):
    return sp.Symbol(name, real=True)


# --- symbols ------------------------------------------------------------------------------------
X = tuple(_real(n) for n in layout.STATE)
Q = X[: layout.NQ]
QD = X[layout.NQ:]
P = {n: _real(n) for n in layout.PARAMS + layout.DERIVED + layout.CONTACT_PARAMS}
# contact forces as symbols of the dynamics stage, foot 1 then foot 2
F_N = (_real("F_n1"), _real("F_n2"))
F_T = (_real("F_t1"), _real("F_t2"))
QDD = tuple(_real("qdd%d" % i) for i in range(layout.NQ))
ANCHOR = (_real("s0_1"), _real("s0_2"))
V_IN = (_real("v_in1"), _real("v_in2"))     # approach speed at touch-down (layout.ANCHORS)
Z = tuple(_real(n) for n in layout.BRISTLE)   # LuGre bristle deflections (state after X)
# per-foot scalar contact variables of the force laws
DELTA, DELTAD, VT, XI, FN, VIN, ZB = (_real(n) for n in ("delta", "deltad", "v_t", "xi", "F_n",
                                                          "v_in", "z"))


@dataclass(frozen=True)
class Mechanics:
    """Rigid-body terms of M q'' + C q' + G = Q_f (Eq. 2), as 4x4 / 4x1 SymPy matrices."""

    T: sp.Expr
    V_gravity: sp.Expr
    V_hip: sp.Expr
    M: sp.Matrix
    Cqd: sp.Matrix
    C: sp.Matrix
    G: sp.Matrix


def points():
    """Hip H, leg centres of mass G_i and foot-arc centres A_i (docs/model.md section 2)."""
    l, c, w, r = P["l"], P["c"], P["w"], P["r"]
    xo, yo = Q[0], Q[1]
    H = sp.Matrix([xo, yo])
    Gs, As = [], []
    for th in Q[2:]:
        e = sp.Matrix([sp.sin(th), -sp.cos(th)])
        n = sp.Matrix([sp.cos(th), sp.sin(th)])
        Gs.append(H + c * e + w * n)
        As.append(H + (l - r) * e)
    return H, Gs, As


def _time_derivative(expr):
    return sum(sp.diff(expr, qi) * qdi for qi, qdi in zip(Q, QD))


@functools.lru_cache(maxsize=None)
def mechanics() -> Mechanics:
    """Lagrange's equations from T and V of docs/model.md section 3 (computed once, cached: treat
    the returned matrices as read-only)."""
    m_h, m_l, J_l, g, k_hip = P["m_h"], P["m_l"], P["J_l"], P["g"], P["k_hip"]
    sg, cg = P["sin_gamma"], P["cos_gamma"]
    H, Gs, _ = points()
    Hd = H.applyfunc(_time_derivative)
    T = sp.Rational(1, 2) * m_h * (Hd.T * Hd)[0]
    Vg = m_h * g * (H[1] * cg - H[0] * sg)
    for Gi, thd in zip(Gs, QD[2:]):
        Gd = Gi.applyfunc(_time_derivative)
        T += sp.Rational(1, 2) * m_l * (Gd.T * Gd)[0] + sp.Rational(1, 2) * J_l * thd ** 2
        Vg += m_l * g * (Gi[1] * cg - Gi[0] * sg)
    Vh = sp.Rational(1, 2) * k_hip * (Q[2] - Q[3]) ** 2
    T = sp.expand(T)
    n = layout.NQ
    M = sp.Matrix(n, n, lambda i, j: sp.simplify(sp.diff(T, QD[i], QD[j])))
    # C qd = d/dt(dT/dqd) - M qdd - dT/dq
    Cqd = sp.Matrix(n, 1, lambda i, _: sp.simplify(
        sum(sp.diff(M[i, j], Q[k]) * QD[k] * QD[j] for j in range(n) for k in range(n))
        - sp.diff(T, Q[i])))
    # Christoffel symbols of the first kind: C_ij = sum_k Gamma_ijk qd_k
    C = sp.Matrix(n, n, lambda i, j: sp.simplify(sum(
        sp.Rational(1, 2) * (sp.diff(M[i, j], Q[k]) + sp.diff(M[i, k], Q[j]) - sp.diff(M[j, k], Q[i]))
        * QD[k] for k in range(n))))
    G = sp.Matrix(n, 1, lambda i, _: sp.simplify(sp.diff(Vg + Vh, Q[i])))
    return Mechanics(T=T, V_gravity=sp.expand(Vg), V_hip=Vh, M=M, Cqd=Cqd, C=C, G=G)


def contact_kinematics(foot: int, variant: str, friction: str = "coulomb") -> dict:
    """Contact quantities of foot ``foot`` (0 or 1) for ``variant`` (docs/model.md sections 2, 6).

    Returns a dict keyed by `layout.KIN` field names (all functions of x and,
    for the ``consistent`` xi, of the anchor symbol s0_i). Under ``friction="lugre"`` the
    field ``z`` is the foot's bristle state; 0 otherwise.
    """
    if variant not in VARIANTS:
        raise ValueError("variant must be one of %s, got %r" % (VARIANTS, variant))
    l, r = P["l"], P["r"]
    xo, yo, xdo, ydo = Q[0], Q[1], QD[0], QD[1]
    th, thd = Q[2 + foot], QD[2 + foot]
    out = {
        "x_D": xo + (l - r) * sp.sin(th),                               # Eq. 4
        "y_D": yo - r - (l - r) * sp.cos(th),                           # Eq. 4
        "v_x": xdo + ((l - r) * sp.cos(th) + r) * thd,                  # Eq. 9
        "s": xo + (l - r) * sp.sin(th) + r * th,
    }
    v_y = ydo + (l - r) * sp.sin(th) * thd                              # d/dt of Eq. 4
    if variant == "paper":
        out["v_y"] = v_y + r * thd                                      # Eq. 5 as printed
        out["xi"] = (l - r) * sp.sin(th)                                # Eq. 8
    else:
        out["v_y"] = v_y
        out["xi"] = out["s"] - ANCHOR[foot]                             # slip since touch-down
    out["v_in"] = V_IN[foot]                                            # captured at touch-down
    out["z"] = Z[foot] if friction == "lugre" else sp.S.Zero
    return {k: out[k] for k in layout.KIN}


def material_velocity(foot: int) -> sp.Matrix:
    """Velocity (v_x, v_y) of foot ``foot``'s material point at D_i (consistent rate), 2x1."""
    kin = contact_kinematics(foot, "consistent")
    return sp.Matrix([kin["v_x"], kin["v_y"]])


def cubic_step(x, x0, h0, x1, h1):
    """step(x; x0, h0, x1, h1) = h0 + (h1 - h0) D^2 (3 - 2 D), D = (x - x0)/(x1 - x0) (Eq. 10)."""
    d = (x - x0) / (x1 - x0)
    return h0 + (h1 - h0) * d ** 2 * (3 - 2 * d)


def friction_coefficient(v):
    """Smooth odd friction coefficient mu(v) of Eq. 10 (docs/model.md section 4); opposes slip."""
    vs, vd, ms, md = P["v_s"], P["v_d"], P["mu_s"], P["mu_d"]
    return sp.Piecewise(
        (md, v <= -vd),
        (cubic_step(v, -vd, md, -vs, ms), v <= -vs),
        (cubic_step(v, -vs, ms, vs, -ms), v <= vs),
        (cubic_step(v, vs, -ms, vd, -md), v <= vd),
        (-md, True),
    )


def contact_laws(variant: str, features=FEATURES, normal: str = "hunt_crossley",
                 friction: str = "coulomb") -> dict:
    """Force laws of one penetrating support foot, in the scalar variables delta, deltad, v_t, xi
    (and v_in, the approach speed at touch-down, for the laws that use it).

    Parameters
    ----------
    variant : {"paper", "consistent"}
        Selects the tangential deformation's gate (docs/model.md section 6).
    features : iterable of str
        Force elements present; those absent are folded to zero.
    normal : str
        Normal law, one of `derive.contact_laws.NORMAL_LAWS` (default: the paper's
        Hunt-Crossley, Eqs. 3, 6).
    friction : {"coulomb", "lugre"}
        Friction law: Eq. 10's mu(v_t), or LuGre (`derive.contact_laws.lugre`) in v_t and the
        foot's bristle state z.

    Returns
    -------
    dict keyed by `layout.CONTACT` field names.
    """
    dn, kt, dt = _fold(P["d_n"], "normal_damping", features), \
        _fold(P["k_t"], "tangential", features), _fold(P["d_t"], "tangential", features)
    Pn = dict(P, d_n=dn)
    if normal in ("lankarani_nikravesh", "flores") and "normal_damping" not in features:
        Pn["e_n"] = sp.S.One                # no damping: perfectly elastic
    Fn = laws.normal_force(normal, DELTA, DELTAD, VIN, Pn)   # the ground cannot pull
    zdot = rate = sp.S.Zero
    if "friction" not in features:
        mu = sp.S.Zero
    elif friction == "lugre":
        mu, zdot, rate = laws.lugre(VT, ZB, P)
    else:
        mu = friction_coefficient(VT)
    # Eq. 7 with m = p = 1.5: -sign(xi) k_t |xi|^1.5 - d_t |xi|^1.5 v_t. Its xi-derivative is
    # written out so that it stays finite at xi = 0 (where the anchored variant starts).
    ax = sp.Abs(XI)
    spring_damper = -kt * XI * sp.sqrt(ax) - dt * ax * sp.sqrt(ax) * VT
    d_sd_dxi = -sp.Rational(3, 2) * sp.sqrt(ax) * (kt + dt * sp.sign(XI) * VT)
    if variant == "paper":                          # Eq. 11's gate
        spring_damper = sp.Piecewise((spring_damper, XI <= 0), (0, True))
        d_sd_dxi = sp.Piecewise((d_sd_dxi, XI <= 0), (0, True))
    Ft = spring_damper + mu * FN
    out = {
        "F_n": Fn,
        "F_t": Ft.subs(FN, Fn),
        "mu": mu,
        "zdot": zdot,
        "z_rate": rate,
        "dFn_ddelta": sp.diff(Fn, DELTA),
        "dFn_ddeltad": sp.diff(Fn, DELTAD),
        "dFt_dxi": d_sd_dxi,
        "dFt_dv": sp.diff(Ft, VT).subs(FN, Fn),
    }
    return {k: out[k] for k in layout.CONTACT}


def _fold(sym, feature, features):
    return sym if feature in features else sp.S.Zero


def generalized_forces(features=FEATURES) -> sp.Matrix:
    """Q_f: virtual work of F_t (+X) and F_n (+Y) at the feet's material points, plus the hip damper."""
    Qf = sp.zeros(layout.NQ, 1)
    for i in range(2):
        v = material_velocity(i)
        Jx = sp.Matrix([[sp.diff(v[0], qd) for qd in QD]])
        Jy = sp.Matrix([[sp.diff(v[1], qd) for qd in QD]])
        Qf += Jx.T * F_T[i] + Jy.T * F_N[i]
    d_hip = _fold(P["d_hip"], "hip_damper", features)
    Qf[2] += -d_hip * (QD[2] - QD[3])
    Qf[3] += -d_hip * (QD[3] - QD[2])
    return Qf


def fold_parameters(expr, features):
    """Substitute zero for the parameters of every absent feature."""
    subs = {P[name]: 0 for f, names in FEATURE_PARAMS.items() if f not in features for name in names}
    return expr.subs(subs) if subs else expr
