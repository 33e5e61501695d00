"""Per-kernel stage expressions, ready for C emission.

A *kernel* is one specialization of the model: a contact variant (docs/model.md
section 6) and the set of force elements present. Absent elements are folded to
zero here, before common-subexpression elimination, so that a kernel never
evaluates a force its scene switched off.

Stage data flow (each one a C function; all arrays caller-allocated)::

    trig         x                          -> trig      sin/cos of the leg angles
    kinematics   x, trig, p, anchors        -> kin       Eqs. 4, 5, 8, 9 per foot
    contact      kin, flags, p              -> contact   Eqs. 3, 6, 7, 10, 11 per foot
    dynamics     x, trig, p, contact        -> M, f      f = Q_f - C qd - G   (Eq. 2)
    (solve)      M, f                       -> qdd       Schur complement, C code
    jacobian     x, trig, p, contact, qdd   -> A         A = df/dx - (dM/dx) qdd
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from . import layout
from . import model as mdl


@dataclass(frozen=True)
class KernelSpec:
    """One generated kernel: a variant, the force elements it contains, and its normal contact
    law (`derive.contact_laws.NORMAL_LAWS`; the paper's Hunt-Crossley by default)."""

    variant: str
    features: tuple = mdl.FEATURES
    normal: str = "hunt_crossley"
    friction: str = "coulomb"

    @property
    def name(self):
        missing = [f for f in mdl.FEATURES if f not in self.features]
        law = "" if self.normal == "hunt_crossley" else "_" + self.normal
        fr = "" if self.friction == "coulomb" else "_" + self.friction
        return self.variant + "".join("_no_" + f for f in missing) + law + fr

    @property
    def nx(self):
        """Size of the continuous state of this kernel's friction law (layout.STATE_LAYOUTS)."""
        return len(layout.STATE_LAYOUTS[self.friction])

    @property
    def mechanics(self):
        """The kernel whose mechanical stages this one shares (same variant and features,
        Hunt-Crossley, smooth Coulomb): only the contact stages (and, under LuGre, the
        kinematics, which carry the bristle state) depend on the contact laws."""
        return KernelSpec(self.variant, self.features)

    @property
    def feature_mask(self):
        return sum(1 << i for i, f in enumerate(mdl.FEATURES) if f in self.features)


TRIG = {}
for _i, _th in enumerate(mdl.Q[2:]):
    TRIG[sp.sin(_th)] = mdl._real("sin_theta%d" % (_i + 1))
    TRIG[sp.cos(_th)] = mdl._real("cos_theta%d" % (_i + 1))
TRIG_NAMES = tuple(s.name for s in TRIG.values())


def _trig(expr):
    out = expr.xreplace(TRIG)
    leftover = [a for a in out.atoms(sp.sin, sp.cos) if a.args[0] in mdl.Q]
    if leftover:
        raise AssertionError("trigonometric terms left after substitution: %s" % leftover)
    return out


def kinematics(spec: KernelSpec):
    """Expressions of `layout.KIN` for both feet (foot-major order)."""
    return [_trig(e) for i in range(2)
            for e in mdl.contact_kinematics(i, spec.variant, spec.friction).values()]


def contact(spec: KernelSpec):
    """Expressions of `layout.CONTACT` for one penetrating support foot."""
    return list(mdl.contact_laws(spec.variant, spec.features, spec.normal, spec.friction).values())


def forcing(spec: KernelSpec) -> sp.Matrix:
    """f = Q_f - C qd - G with the contact forces as symbols (4x1, untrigged)."""
    mech = mdl.mechanics()
    G = mdl.fold_parameters(mech.G, spec.features)
    return mdl.generalized_forces(spec.features) - mech.Cqd - G


def dynamics(spec: KernelSpec):
    """M (row-major 16) then f (4)."""
    M = mdl.mechanics().M
    return [_trig(e) for e in list(M) + list(forcing(spec))]


def cdm_terms(spec: KernelSpec):
    """M (16), the appendix C matrix (16) and Q_f - G (4), for the central difference method."""
    mech = mdl.mechanics()
    QmG = mdl.generalized_forces(spec.features) - mdl.fold_parameters(mech.G, spec.features)
    return [_trig(e) for e in list(mech.M) + list(mech.C) + list(QmG)]


def cdm_pattern():
    """Structural non-zeros of the matrices of `cdm_terms`: bit masks (bit NQ*i + j: entry (i, j),
    row-major) of the entries of M and of C that are not identically zero. The mechanics do not
    depend on the kernel (contact laws, features, variant enter Q_f - G only), so one pattern
    holds for every kernel; the central difference update (pdw/core/csrc/pdw_cdm.c) touches only
    these entries."""
    mech = mdl.mechanics()

    def mask(A):
        return sum(1 << k for k, e in enumerate(A) if sp.expand(e) != 0)

    return mask(mech.M), mask(mech.C)


def contact_partial_symbols():
    """Symbols standing for the contact stage's outputs of foot i: {(i, field): Symbol}."""
    return {(i, f): mdl._real("%s_%d" % (f, i + 1)) for i in range(2) for f in layout.CONTACT}


def dynamics_jacobian(spec: KernelSpec):
    """A = df/dx + sum_i (df/dF_i)(dF_i/dx) - (dM/dx) qdd, a 4x8 matrix, row-major (32).

    dF/dx of each foot is assembled by the chain rule from the contact stage's
    partials (symbols) and the symbolic gradients of delta, delta_dot, xi, v_x. A partial
    that is identically zero in this kernel (its force element absent) is left out of the
    chain, so its gradient is never computed.
    """
    sym = contact_partial_symbols()
    zero = set()
    if "normal_damping" not in spec.features:
        zero.add("dFn_ddeltad")
    if "tangential" not in spec.features:
        zero.add("dFt_dxi")
    if "friction" not in spec.features:
        zero.add("mu")
    sym = {key: (sp.S.Zero if key[1] in zero else s) for key, s in sym.items()}
    f = forcing(spec)
    M = mdl.mechanics().M
    x = mdl.X
    A = f.jacobian(x)
    for i in range(2):
        kin = mdl.contact_kinematics(i, spec.variant)
        grad = lambda e: sp.Matrix([[sp.diff(e, xj) for xj in x]])  # noqa: E731
        dFn = sym[i, "dFn_ddelta"] * grad(-kin["y_D"]) + sym[i, "dFn_ddeltad"] * grad(-kin["v_y"])
        dFt = sym[i, "dFt_dxi"] * grad(kin["xi"]) + sym[i, "dFt_dv"] * grad(kin["v_x"]) \
            + sym[i, "mu"] * dFn
        A += f.diff(mdl.F_N[i]) * dFn + f.diff(mdl.F_T[i]) * dFt
    qdd = sp.Matrix(mdl.QDD)
    for k, xk in enumerate(x):
        A[:, k] -= M.diff(xk) * qdd
    return [_trig(sp.expand(e)) for e in A]


def energies(spec: KernelSpec):
    """T, V_gravity, V_hip (docs/model.md section 3)."""
    mech = mdl.mechanics()
    return [_trig(e) for e in (mech.T, mech.V_gravity, mdl.fold_parameters(mech.V_hip, spec.features))]
