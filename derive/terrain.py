"""Contact on a shaped ground (docs/model.md section 11, docs/terrain.md).

The ground is h(s) above the mean slope plane, s along the slope (pdw/core/ground.py). For foot i
with arc centre A_i = H + (l - r) e_i, the ground is sampled once, at s_A = x_A (the point of the
surface straight below A in the slope frame): h, h' (and for the consistent variant the arc length
sigma and the surface angle alpha = atan h'). The surface is replaced by its tangent line there
(**the tangent-line approximation**; exact for planes, error O(r^2 h'' h') for curved ground,
measured in docs/terrain.md against the exact closest point):

    N = sqrt(1 + h'^2),   n = (-h', 1)/N (outward normal),   t = (1, h')/N (tangent, downhill)
    gap      g  = n . (A - (s_A, h)) - r = (y_A - h)/N - r          (depth delta = -g)
    contact  C  = A - r n                                            (the foot's nearest point)
    velocity v_C = v_A + r thetad t        (the material point at C; k x (-r n) = r t)
    slip     v_t = t . v_C,   normal rate v_n = n . v_C (= n . v_A; the `paper` variant adds
             r thetad as its printed Eq. 5 does)
    xi       paper: (l - r) t . e_i (the contact point measured from the hip's projection on the
             local surface, Eq. 8 in the surface frame);
             consistent: S - S0, S = sigma(s_A) + t . (A - P) + r (theta - alpha), P = (s_A, h):
             the rolling coordinate in surface coordinates (dS/dt = v_t - alpha_dot delta; exact
             on a plane, where S is the rotated frame's x_o + (l - r) sin theta' + r theta').

The kinematics stage writes these into the flat model's `layout.KIN` fields in the surface frame
(y_D := g, v_x := v_t, v_y := v_n, x_D := s of C, s := S, xi), so every contact law's force stage
runs unchanged. The forces F_n (along n) and F_t (along t) act at C; their generalized force is
the flat dynamics stage's (forces along X, Y at D) applied to F_x = t_x F_t + n_x F_n,
F_y = t_y F_t + n_y F_n, plus the moment of moving their point from D to C:
r (y - n) x F = r (h'/N F_y - (1 - 1/N) F_x) = r ((1 - 1/N) F_t + h'/N F_n) on theta_i
(`ground_forces`).
"""
from __future__ import annotations

import sympy as sp

from . import layout
from . import model as mdl

# the ground sampled under foot i (layout.GROUND), and one foot's contact forces
GND = tuple({f: mdl._real("gnd_%s_%d" % (f, i + 1)) for f in layout.GROUND} for i in range(2))
# outputs of `ground_forces` per foot
GROUND_FORCE = ("F_x", "F_y", "M_theta")


def sample_points():
    """s_A = x_A of each foot (the arc centre's distance along the slope) [m], foot-major."""
    l, r = mdl.P["l"], mdl.P["r"]
    return [mdl.Q[0] + (l - r) * sp.sin(th) for th in mdl.Q[2:]]


def ground_kinematics(foot: int, variant: str) -> dict:
    """The `layout.KIN` fields of foot ``foot`` on the ground sampled in `GND` (module docstring);
    ``z`` (LuGre) is set by the caller."""
    if variant not in mdl.VARIANTS:
        raise ValueError("variant must be one of %s, got %r" % (mdl.VARIANTS, variant))
    l, r = mdl.P["l"], mdl.P["r"]
    xo, yo, xdo, ydo = mdl.Q[0], mdl.Q[1], mdl.QD[0], mdl.QD[1]
    th, thd = mdl.Q[2 + foot], mdl.QD[2 + foot]
    g = GND[foot]
    h, dh = g["h"], g["dh"]
    N = 1 / g["inv_n"]              # sqrt(1 + h'^2), its inverse sampled once with the ground
    xa, ya = xo + (l - r) * sp.sin(th), yo - (l - r) * sp.cos(th)
    xad, yad = xdo + (l - r) * sp.cos(th) * thd, ydo + (l - r) * sp.sin(th) * thd
    vn = (-dh * xad + yad) / N
    out = {
        "x_D": xa + r * dh / N,
        "y_D": (ya - h) / N - r,
        "v_x": (xad + dh * yad) / N + r * thd,
        "v_y": vn + r * thd if variant == "paper" else vn,
        # the rolling coordinate; the paper variant's forces do not use it (its xi is Eq. 8's),
        # so it keeps the flat model's x_A + r theta there and needs no sigma, alpha
        "s": (g["sigma"] + dh * (ya - h) / N + r * (th - g["alpha"]) if variant == "consistent"
              else xa + r * th),
    }
    if variant == "paper":
        out["xi"] = (l - r) * (sp.sin(th) - dh * sp.cos(th)) / N
    else:
        out["xi"] = out["s"] - mdl.ANCHOR[foot]
    out["v_in"] = mdl.V_IN[foot]
    out["z"] = sp.S.Zero
    return {k: out[k] for k in layout.KIN}


def ground_forces(foot: int):
    """(F_x, F_y, M_theta) of foot ``foot``: its surface-frame forces F_n, F_t as slope-frame
    components at D, and the moment r (y - n) x F of moving them from D to C.

    Written linear in F_n and F_t with coefficients of the ground alone, c = 1/N and s = h'/N
    (t = (c, s), n = (-s, c)): F_x = c F_t - s F_n, F_y = s F_t + c F_n, and the moment
    r (s F_y - (1 - c) F_x) = r ((1 - c) F_t + s F_n) by s^2 + c^2 = 1. The forces come last in
    the time loops' chain (ground -> kinematics -> contact -> forces): in this form each output
    is one product and one sum after them. Equal to the (h' F_t + F_n)/N form to rounding."""
    r = mdl.P["r"]
    c, s = GND[foot]["inv_n"], GND[foot]["s_n"]      # s = h' c, sampled with the ground
    fn, ft = mdl.F_N[foot], mdl.F_T[foot]
    return [c * ft - s * fn, s * ft + c * fn, r * ((1 - c) * ft + s * fn)]


def _ground_slopes(g):
    """d/ds of each sampled ground value (the chain rule through s_A): h' , h'', sigma' = N,
    alpha' = h''/N^2, (1/N)' = -h' h''/N^3, (h'/N)' = h''/N^3; h'' itself does not enter the
    kinematics."""
    dh, ddh, inv_n = g["dh"], g["ddh"], g["inv_n"]
    return {"h": dh, "dh": ddh, "sigma": 1 / inv_n, "alpha": ddh * inv_n ** 2,
            "ddh": sp.S.Zero, "inv_n": -dh * ddh * inv_n ** 3, "s_n": ddh * inv_n ** 3}


def _total_gradient(e, g, slope, dsA):
    """d e/dx with the ground values g sampled at s_A(x): partials in x plus the chain rule."""
    return sp.Matrix([[sp.diff(e, xj) + sum(sp.diff(e, g[k]) * slope[k] for k in layout.GROUND)
                       * dsA[j] for j, xj in enumerate(mdl.X)]])


def ground_jacobian(variant: str):
    """The ground's part of A = df/dx (4x8, row-major 32), to add to the mechanics kernel's
    dynamics_jacobian evaluated with the slope-frame forces (F_N := F_y, F_T := F_x) and every
    contact partial set to 0 (which gives df/dx at fixed forces minus (dM/dx) qdd): for each
    foot, the forces' total gradient -- through the contact partials (symbols), the surface-frame
    kinematics and the ground sampled at s_A(x) (h, h', h'', chain rule) -- times the columns of
    f for F_x and F_y, plus the moment's gradient on theta_i. The patches' dependence on s is
    left out (the Jacobian is exact off the blend zones)."""
    from . import stages  # the contact partial symbols (stages imports this module's callers)
    sym = stages.contact_partial_symbols()
    f = stages.forcing(stages.KernelSpec(variant))
    x = mdl.X
    A = sp.zeros(layout.NQ, len(x))
    sA = sample_points()
    for i in range(2):
        g = GND[i]
        slope = _ground_slopes(g)
        dsA = [sp.diff(sA[i], xj) for xj in x]
        kin = ground_kinematics(i, variant)
        grad = [_total_gradient(e, g, slope, dsA) for e in
                (-kin["y_D"], -kin["v_y"], kin["xi"], kin["v_x"])]
        dFn = sym[i, "dFn_ddelta"] * grad[0] + sym[i, "dFn_ddeltad"] * grad[1]
        dFt = sym[i, "dFt_dxi"] * grad[2] + sym[i, "dFt_dv"] * grad[3] + sym[i, "mu"] * dFn
        ddh_dx = sp.Matrix([[slope["dh"] * dsA[j] for j in range(len(x))]])
        dinv_dx = sp.Matrix([[slope["inv_n"] * dsA[j] for j in range(len(x))]])
        ds_dx = sp.Matrix([[slope["s_n"] * dsA[j] for j in range(len(x))]])
        fn, ft, dh, inv_n, s_n = mdl.F_N[i], mdl.F_T[i], g["dh"], g["inv_n"], g["s_n"]
        fx, fy, mom = (sp.diff(e, fn) * dFn + sp.diff(e, ft) * dFt + sp.diff(e, dh) * ddh_dx
                       + sp.diff(e, inv_n) * dinv_dx + sp.diff(e, s_n) * ds_dx
                       for e in ground_forces(i))
        # the flat forcing's columns for the forces along X (F_T) and Y (F_N) at D
        A += f.diff(mdl.F_T[i]) * fx + f.diff(mdl.F_N[i]) * fy
        A[2 + i, :] += mom
    return [stages._trig(e) for e in A]
