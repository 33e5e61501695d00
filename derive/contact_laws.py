"""The family of normal contact laws, written once (issue 12, docs/contact_laws.md).

Each law gives the normal force of one penetrating support foot from its depth delta > 0
[m], its penetration rate delta_dot = -v_y [m/s] (docs/model.md section 4) and, for the laws whose
damping comes from a coefficient of restitution, the approach speed v_in [m/s] captured at the
foot's touch-down (a per-foot discrete value, like the consistent variant's anchor s0_i). The
ground cannot pull: every law with damping is clamped at 0.

=====================  =========================================================  ==============
law                    F_n (delta > 0)                                            parameters
=====================  =========================================================  ==============
hunt_crossley          k_n delta^1.5 + d_n delta^1.5 delta_dot   (Eqs. 3, 6)      k_n, d_n
hertz                  k_n delta^1.5                                              k_n
kelvin_voigt           k_n delta + d_n delta_dot                                  k_n, d_n
lankarani_nikravesh    k_n delta^1.5 (1 + 3 (1 - e^2)/4 delta_dot / v0)           k_n, e_n
flores                 k_n delta^1.5 (1 + 8 (1 - e)/(5 e) delta_dot / v0)         k_n, e_n
=====================  =========================================================  ==============

with v0 = max(v_in, v_in_min) (a foot that starts in contact has no approach speed; v_in_min
keeps the damping finite). Units: k_n in N/m^1.5 (N/m for kelvin_voigt), d_n in N s/m^2.5
(N s/m for kelvin_voigt), e_n dimensionless in (0, 1]. Lankarani & Nikravesh (1990) derived
their hysteresis factor for e close to 1; Flores et al. (2011) for the whole range.

Friction laws (`FRICTION_LAWS`): ``coulomb``, the paper's smooth law mu(v) F_n (Eq. 10, in
derive/model.py), and ``lugre`` (Canudas de Wit, Olsson, Astrom & Lischinsky 1995), per unit
normal force, with a bristle deflection z [m] per foot added to the continuous state:

    g(v)  = mu_c + (mu_s - mu_c) exp(-(v/v_s)^2)             Stribeck curve [-]
    dz/dt = v - sigma0 |v| z / g(v)                           bristle dynamics [m/s]
    F_f   = -(sigma0 z + sigma1 dz/dt + sigma2 v) F_n         friction force, +X [N]

(v the slip velocity v_x of Eq. 9; the minus sign: friction opposes slip, as Eq. 10's mu(v)).
sigma0 [1/m], sigma1 [s/m], sigma2 [s/m] are per unit normal force. At constant sliding v the
bristle settles at z_ss = g(v) sign(v) / sigma0, where F_f = -(g(v) sign(v) + sigma2 v) F_n.

The Hunt-Crossley expression is built exactly as it always was (`hunt_crossley`), so that the
default kernel's generated code, and its results, do not move.
"""
from __future__ import annotations

import sympy as sp

NORMAL_LAWS = ("hunt_crossley", "hertz", "kelvin_voigt", "lankarani_nikravesh", "flores")
FRICTION_LAWS = ("coulomb", "lugre")

#: the exponent of the nonlinear laws (the paper's m = p = 1.5)
EXPONENT = sp.Rational(3, 2)


def _clamped(f):
    return sp.Piecewise((f, f > 0), (0, True))


def hunt_crossley(delta, deltad, kn, dn):
    """The paper's Hunt-Crossley force (Eqs. 3, 6; m = p = 1.5, q = 1), clamped at 0."""
    d15 = delta * sp.sqrt(delta)            # delta^m = delta^p, m = p = 1.5 (delta > 0 here)
    return _clamped(kn * d15 + dn * d15 * deltad)


def hertz(delta, kn):
    """Hertz: k_n delta^1.5, no damping (elastic, e = 1)."""
    return kn * delta * sp.sqrt(delta)


def kelvin_voigt(delta, deltad, kn, dn):
    """Kelvin-Voigt: linear spring k_n [N/m] and dashpot d_n [N s/m], clamped at 0."""
    return _clamped(kn * delta + dn * deltad)


def lankarani_nikravesh_factor(e):
    """Hysteresis factor chi of Lankarani & Nikravesh (1990): 3 (1 - e^2)/4."""
    return sp.Rational(3, 4) * (1 - e ** 2)


def flores_factor(e):
    """Hysteresis factor chi of Flores et al. (2011): 8 (1 - e)/(5 e)."""
    return sp.Rational(8, 5) * (1 - e) / e


def hysteresis(delta, deltad, kn, chi, v0):
    """k_n delta^1.5 (1 + chi delta_dot / v0), clamped at 0."""
    return _clamped(kn * delta * sp.sqrt(delta) * (1 + chi * deltad / v0))


def normal_force(law, delta, deltad, v_in, P):
    """Normal force of ``law`` (one of `NORMAL_LAWS`) for one penetrating foot.

    Parameters
    ----------
    law : str
    delta, deltad, v_in : sympy.Symbol
        Depth [m], penetration rate [m/s], approach speed captured at touch-down [m/s].
    P : dict
        Parameter symbols by name (k_n, d_n, e_n, v_in_min).
    """
    kn, dn = P["k_n"], P["d_n"]
    if law == "hunt_crossley":
        return hunt_crossley(delta, deltad, kn, dn)
    if law == "hertz":
        return hertz(delta, kn)
    if law == "kelvin_voigt":
        return kelvin_voigt(delta, deltad, kn, dn)
    v0 = sp.Max(v_in, P["v_in_min"])
    if law == "lankarani_nikravesh":
        return hysteresis(delta, deltad, kn, lankarani_nikravesh_factor(P["e_n"]), v0)
    if law == "flores":
        return hysteresis(delta, deltad, kn, flores_factor(P["e_n"]), v0)
    raise ValueError("normal law must be one of %s, got %r" % (NORMAL_LAWS, law))


def uses_approach_speed(law):
    """Does the law's damping depend on the approach speed at touch-down?"""
    return law in ("lankarani_nikravesh", "flores")


def stribeck(v, P):
    """LuGre's Stribeck curve g(v) = mu_c + (mu_s - mu_c) exp(-(v/v_s)^2) [-]."""
    mu_s, mu_c, v_s = P["lg_mu_s"], P["lg_mu_c"], P["lg_v_s"]
    return mu_c + (mu_s - mu_c) * sp.exp(-(v / v_s) ** 2)


def lugre(v, z, P):
    """LuGre friction per unit normal force and bristle dynamics of one sliding foot.

    Parameters
    ----------
    v, z : sympy.Symbol
        Slip velocity [m/s] and bristle deflection [m].
    P : dict
        Parameter symbols by name (sigma0, sigma1, sigma2, lg_mu_s, lg_mu_c, lg_v_s).

    Returns
    -------
    (mu, zdot, rate) : friction force per unit normal force (+X, opposes slip) [-], dz/dt [m/s]
    and the relaxation rate sigma0 |v| / g(v) [1/s], so that dz/dt = v - rate z.
    """
    rate = P["sigma0"] * sp.Abs(v) / stribeck(v, P)
    zdot = v - rate * z
    mu = -(P["sigma0"] * z + P["sigma1"] * zdot + P["sigma2"] * v)
    return mu, zdot, rate
