"""The hybrid (impact-momentum) walker of docs/model.md section 9, from the same Lagrangian.

Rigid ground; the stance foot rolls without slip: the velocity of its material contact point is
zero (v_x = v_y = 0, the *consistent* normal rate of docs/model.md section 6). For the stance leg i
the constraint J_i(q) qd = 0, with J_i the 2x4 Jacobian of `model.material_velocity(i)`, is
holonomic (for the arc foot as for the point foot r = 0)::

    v_x = d/dt [x_o + (l - r) sin(theta_i) + r theta_i] = 0
    v_y = d/dt [y_o - (l - r) cos(theta_i)]             = 0

so on the ground (contact point at y_D = 0) the hip follows from the stance angle::

    x_o = s0 - (l - r) sin(theta_st) - r theta_st,     y_o = r + (l - r) cos(theta_st)

where s0 is the stance foot's rolling coordinate (constant during the stance; it shifts the
walker along the slope and drops out of the equations of motion). The stance phase is a 2-DOF
system in phi = (theta_st, theta_sw): q = Phi(phi), qd = B(phi) phid with B = dPhi/dphi (4x2,
J_st B = 0). Internally the stance leg is leg 1 of the full model and the swing leg leg 2;
the legs are identical, so a relabelling at heel strike serves both legs.

Reduced equations, two ways (`reduced_dynamics`):

* ``projection``: M (B phidd + Bdot phid) + C qd + G = Q_hip + J^T lambda, premultiplied by
  B^T (B^T J^T = 0): M_r = B^T M B, f_r = B^T (Q_hip - M Bdot phid - C qd - G);
* ``lagrangian``: T_r(phi, phid) = T(Phi, B phid), V_r = V(Phi), Lagrange's equations with the
  generalised hip-damper force B^T Q_hip.

Both give M_r phidd = f_r; the emitted C uses the projection (tests check they agree).

Emitted into generated/pdw_hybrid.{h,c} (`write`), called once from `derive.emit.write_all`.
Reduced state y = [theta_st, theta_sw, thetad_st, thetad_sw] (`STATE`); the parameter vector is
the full model's p (``pdw_precompute``).
"""
from __future__ import annotations

import pathlib

import sympy as sp

from . import layout
from . import model as mdl
from .printer import c_block

STATE = ("theta_st", "theta_sw", "thetad_st", "thetad_sw")
Y = tuple(mdl._real(n) for n in STATE)
PHI, PHID = Y[:2], Y[2:]
PHIDD = (mdl._real("thetadd_st"), mdl._real("thetadd_sw"))
# swing-foot quantities for heel-strike detection and footprints (rolling coordinate s0 = 0)
FOOT = ("y_sw", "vy_sw", "x_sw", "x_st")
ENERGY = layout.ENERGY


def _lr():
    return mdl.P["l"] - mdl.P["r"], mdl.P["r"]


def embedding():
    """Phi(phi) (4x1) and B = dPhi/dphi (4x2): the full q of the stance phase, s0 = 0."""
    lr, r = _lr()
    th = PHI[0]
    Phi = sp.Matrix([-lr * sp.sin(th) - r * th, r + lr * sp.cos(th), PHI[0], PHI[1]])
    return Phi, Phi.jacobian(sp.Matrix(PHI))


def _subs():
    """Substitution of the full state by the reduced one (q = Phi, qd = B phid)."""
    Phi, B = embedding()
    qd = B * sp.Matrix(PHID)
    return {**dict(zip(mdl.Q, Phi)), **dict(zip(mdl.QD, qd))}


def hip_force() -> sp.Matrix:
    """Generalised force of the hip damper in q (4x1); the contact forces are constraint forces."""
    Qf = mdl.generalized_forces(())      # no contact forces (F symbols set to 0 below), no damper
    Qd = mdl.generalized_forces(("hip_damper",)) - Qf
    return Qd


def reduced_dynamics(method: str = "projection"):
    """(M_r 2x2, f_r 2x1) of the stance phase, M_r phidd = f_r, in the symbols `Y` and `model.P`."""
    mech = mdl.mechanics()
    sub = _subs()
    Phi, B = embedding()
    Qh = hip_force()
    if method == "projection":
        M = mech.M.xreplace(sub)
        Bdot_phid = sp.Matrix(4, 1, lambda i, _: sum(
            sp.diff(B[i, j], PHI[k]) * PHID[k] * PHID[j] for j in range(2) for k in range(2)))
        rest = M * Bdot_phid + mech.Cqd.xreplace(sub) + mech.G.xreplace(sub) - Qh.xreplace(sub)
        Mr = (B.T * M * B).applyfunc(sp.simplify)
        fr = (-(B.T * rest)).applyfunc(sp.simplify)
        return Mr, fr
    if method == "lagrangian":
        T = mech.T.xreplace(sub)
        V = (mech.V_gravity + mech.V_hip).xreplace(sub)
        Qr = B.T * Qh.xreplace(sub)
        Mr = sp.Matrix(2, 2, lambda i, j: sp.simplify(sp.diff(T, PHID[i], PHID[j])))
        fr = sp.Matrix(2, 1, lambda i, _: sp.simplify(
            Qr[i] - sum(sp.diff(T, PHID[i], PHI[k]) * PHID[k] for k in range(2))
            + sp.diff(T, PHI[i]) - sp.diff(V, PHI[i])))
        return Mr, fr
    raise ValueError("method must be 'projection' or 'lagrangian', got %r" % method)


def ground_force():
    """Ground reaction (F_x, F_y) on the stance foot's material point during the stance, 2x1.

    The first two rows of the full equations read M q'' + C q' + G = J^T lambda with J's columns
    for (x_o, y_o) the identity, so lambda is those rows of the left side, evaluated with
    q'' = B phidd + Bdot phid; phidd appears as the symbols `PHIDD`.
    """
    mech = mdl.mechanics()
    sub = _subs()
    _, B = embedding()
    Bdot_phid = sp.Matrix(4, 1, lambda i, _: sum(
        sp.diff(B[i, j], PHI[k]) * PHID[k] * PHID[j] for j in range(2) for k in range(2)))
    qdd = B * sp.Matrix(PHIDD) + Bdot_phid
    lhs = mech.M.xreplace(sub) * qdd + mech.Cqd.xreplace(sub) + mech.G.xreplace(sub)
    return sp.Matrix([sp.simplify(lhs[0]), sp.simplify(lhs[1])])


def swing_foot():
    """`FOOT`: swing foot height y_D and normal rate (consistent), its contact point x_D and the
    stance foot's contact point x_D (stance rolling coordinate s0 = 0)."""
    sub = _subs()
    sw = mdl.contact_kinematics(1, "consistent")
    st = mdl.contact_kinematics(0, "consistent")
    out = {"y_sw": sw["y_D"], "vy_sw": sw["v_y"], "x_sw": sw["x_D"], "x_st": st["x_D"]}
    return [sp.simplify(out[k].xreplace(sub)) for k in FOOT]


def energies():
    """T, V_gravity, V_hip of the stance phase (V_gravity with s0 = 0)."""
    mech = mdl.mechanics()
    sub = _subs()
    return [sp.simplify(e.xreplace(sub)) for e in (mech.T, mech.V_gravity, mech.V_hip)]


def full_state():
    """The full model's x = [q, qd] (8) of the stance phase, stance leg = leg 1, s0 = 0."""
    Phi, B = embedding()
    return list(Phi) + list(B * sp.Matrix(PHID))


def impact_terms():
    """M(q) (16, row-major) and the material-point Jacobians J_1, J_2 (2x4 each, foot-major,
    row-major) in the full coordinates: the data of the impact's KKT system."""
    M = mdl.mechanics().M
    J = []
    for foot in range(2):
        v = mdl.material_velocity(foot)
        J += list(v.jacobian(sp.Matrix(mdl.QD)))
    return list(M) + J


# --- variational equations and saltation (continuation, exact monodromy) ----------------------

def stance_jacobian_terms():
    """The pieces of d(ydot)/dy (4x4) of the stance phase, without inverting M_r symbolically.

    ydot = [phid, phidd] with M_r(phi) phidd = f_r(y), so for each y_k
    d phidd / d y_k = M_r^{-1} (d f_r / d y_k - (d M_r / d y_k) phidd), and M_r depends on phi
    only. Returns [dM_r/dtheta_st (4, row-major), dM_r/dtheta_sw (4), df_r/dy (2x4 row-major)].
    """
    Mr, fr = reduced_dynamics("projection")
    out = []
    for k in range(2):
        out += [sp.simplify(sp.diff(e, PHI[k])) for e in Mr]
    for i in range(2):
        out += [sp.simplify(sp.diff(fr[i], Y[k])) for k in range(4)]
    return out


def swing_foot_gradient():
    """d y_sw / d y (4): the gradient of the heel-strike event function (swing foot height)."""
    y_sw = swing_foot()[0]
    return [sp.simplify(sp.diff(y_sw, s)) for s in Y]


def impact_jacobian_terms():
    """Derivatives of the impact's KKT data along the stance embedding q = Phi(phi), qd = B phid.

    Returns [dM/dtheta_st (16), dM/dtheta_sw (16), dJ_2/dtheta_st (8), dJ_2/dtheta_sw (8),
    d qd / d y (4x4 row-major)], M the full mass matrix, J_2 the swing foot's material-point
    Jacobian (2x4, row-major), qd = B(phi) phid the full velocities: with them the impact map's
    derivative follows from differentiating K s = b (`pdw_hybrid_impact_jac`).
    """
    Phi, B = embedding()
    qsub = dict(zip(mdl.Q, Phi))
    M = mdl.mechanics().M.xreplace(qsub)
    J2 = mdl.material_velocity(1).jacobian(sp.Matrix(mdl.QD)).xreplace(qsub)
    out = []
    for k in range(2):
        out += [sp.simplify(sp.diff(e, PHI[k])) for e in M]
    for k in range(2):
        out += [sp.simplify(sp.diff(e, PHI[k])) for e in J2]
    qd = B * sp.Matrix(PHID)
    out += [sp.simplify(sp.diff(qd[i], Y[k])) for i in range(4) for k in range(4)]
    return out


# --- emission --------------------------------------------------------------------------------

def _names():
    names = {}
    for s in Y:
        names[s] = "y[PDW_HY_%s]" % s.name.upper()
    for i, s in enumerate(PHIDD):
        names[s] = "ydd[%d]" % i
    for n, s in mdl.P.items():
        names[s] = "p[PDW_P_%s]" % n.upper()
    for s in mdl.Q:
        names[s] = "q[PDW_X_%s]" % s.name.upper()
    return names


def _enum(prefix, names):
    body = ",\n".join("    PDW_%s_%s = %d" % (prefix, n.upper(), i) for i, n in enumerate(names))
    return "enum {\n%s,\n    PDW_N%s = %d\n};" % (body, prefix, len(names))


def _function(signature, body):
    return "%s\n{\n%s\n}\n" % (signature, body)


PROTOS = """\
/* stance dynamics: M_r (2x2 row-major) and f_r (2) of M_r phidd = f_r */
void pdw_hybrid_stance(const double *y, const double *p, double *Mr, double *fr);
/* ydot = [phid, phidd]; returns 0, or -1 if M_r is singular */
int pdw_hybrid_rhs(const double *y, const double *p, double *ydot);
/* ground reaction (F_x, F_y) on the stance foot for accelerations ydd (2) */
void pdw_hybrid_ground_force(const double *y, const double *ydd, const double *p, double *F);
/* swing-foot quantities PDW_HYFOOT_* (stance rolling coordinate s0 = 0) */
void pdw_hybrid_swing_foot(const double *y, const double *p, double *foot);
/* T, V_gravity, V_hip (PDW_ENERGY_*) of the stance phase, s0 = 0 */
void pdw_hybrid_energies(const double *y, const double *p, double *e);
/* full-model state x (PDW_NX) with the stance leg as leg 1, s0 = 0 */
void pdw_hybrid_full_state(const double *y, const double *p, double *x);
/* M(q) (16) then J_1, J_2 (8 each: 2x4 row-major) of the feet's material-point velocities */
void pdw_hybrid_impact_terms(const double *q, const double *p, double *MJ);
/* dM_r/dtheta_st (4), dM_r/dtheta_sw (4), df_r/dy (8: 2x4 row-major) of the stance phase */
void pdw_hybrid_stance_jac_terms(const double *y, const double *p, double *dMf);
/* gradient d y_sw / d y (4) of the swing foot's height (the heel-strike event function) */
void pdw_hybrid_swing_foot_grad(const double *y, const double *p, double *g);
/* dM/dphi (2 x 16), dJ_2/dphi (2 x 8), d qd / d y (16: 4x4 row-major) along q = Phi(phi) */
void pdw_hybrid_impact_jac_terms(const double *y, const double *p, double *dK);"""

RHS = """\
int pdw_hybrid_rhs(const double *restrict y, const double *restrict p, double *restrict ydot)
{
    double Mr[4], fr[2];
    pdw_hybrid_stance(y, p, Mr, fr);
    const double det = Mr[0]*Mr[3] - Mr[1]*Mr[2];
    ydot[0] = y[PDW_HY_THETAD_ST];
    ydot[1] = y[PDW_HY_THETAD_SW];
    ydot[2] = (Mr[3]*fr[0] - Mr[1]*fr[1]) / det;
    ydot[3] = (Mr[0]*fr[1] - Mr[2]*fr[0]) / det;
    return (det != 0.0 && det == det) ? 0 : -1;
}
"""


def header(h, banner):
    return "\n".join([
        banner,
        "#ifndef PDW_HYBRID_H\n#define PDW_HYBRID_H\n",
        '#include "pdw_model.h"\n',
        '#define PDW_HYBRID_INPUT_HASH "%s"\n' % h,
        "/* reduced state of the stance phase (docs/model.md section 9): stance leg, swing leg */",
        _enum("HY", STATE), "",
        "/* swing-foot quantities (pdw_hybrid_swing_foot) */",
        _enum("HYFOOT", FOOT), "",
        PROTOS,
        "\n#endif /* PDW_HYBRID_H */\n",
    ])


def source(banner):
    names = _names()
    parts = [banner, "#include <math.h>\n#include \"pdw_hybrid.h\"\n"]
    Mr, fr = reduced_dynamics("projection")
    code, _ = c_block(list(Mr) + list(fr), ["Mr[%d]" % i for i in range(4)]
                      + ["fr[%d]" % i for i in range(2)], names)
    parts.append(_function("void pdw_hybrid_stance(const double *restrict y, const double *restrict p,\n"
                           "    double *restrict Mr, double *restrict fr)", code))
    parts.append(RHS)
    code, _ = c_block(list(ground_force()), ["F[0]", "F[1]"], names)
    parts.append(_function("void pdw_hybrid_ground_force(const double *restrict y, "
                           "const double *restrict ydd,\n    const double *restrict p, "
                           "double *restrict F)", code))
    code, _ = c_block(swing_foot(), ["foot[PDW_HYFOOT_%s]" % f.upper() for f in FOOT], names)
    parts.append(_function("void pdw_hybrid_swing_foot(const double *restrict y, "
                           "const double *restrict p,\n    double *restrict foot)", code))
    code, _ = c_block(energies(), ["e[PDW_ENERGY_%s]" % f.upper() for f in ENERGY], names)
    parts.append(_function("void pdw_hybrid_energies(const double *restrict y, "
                           "const double *restrict p, double *restrict e)", code))
    code, _ = c_block(full_state(), ["x[%d]" % i for i in range(len(layout.STATE))], names)
    parts.append(_function("void pdw_hybrid_full_state(const double *restrict y, "
                           "const double *restrict p, double *restrict x)", code))
    code, _ = c_block(impact_terms(), ["MJ[%d]" % i for i in range(32)], names)
    parts.append(_function("void pdw_hybrid_impact_terms(const double *restrict q, "
                           "const double *restrict p, double *restrict MJ)",
                           "    (void)q; (void)p;\n" + code))
    code, _ = c_block(stance_jacobian_terms(), ["dMf[%d]" % i for i in range(16)], names)
    parts.append(_function("void pdw_hybrid_stance_jac_terms(const double *restrict y, "
                           "const double *restrict p,\n    double *restrict dMf)",
                           "    (void)y; (void)p;\n" + code))
    code, _ = c_block(swing_foot_gradient(), ["g[%d]" % i for i in range(4)], names)
    parts.append(_function("void pdw_hybrid_swing_foot_grad(const double *restrict y, "
                           "const double *restrict p,\n    double *restrict g)",
                           "    (void)y; (void)p;\n" + code))
    code, _ = c_block(impact_jacobian_terms(), ["dK[%d]" % i for i in range(64)], names)
    parts.append(_function("void pdw_hybrid_impact_jac_terms(const double *restrict y, "
                           "const double *restrict p,\n    double *restrict dK)",
                           "    (void)y; (void)p;\n" + code))
    return "\n".join(parts)


def write(root: pathlib.Path, h: str, banner: str):
    """Write generated/pdw_hybrid.{h,c} below ``root``; returns their paths."""
    files = {root / "generated" / "pdw_hybrid.h": header(h, banner),
             root / "generated" / "pdw_hybrid.c": source(banner)}
    for path, text in files.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return list(files)
