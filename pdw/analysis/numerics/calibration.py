"""Drop tests of the normal contact laws, and their calibration to the paper's ground.

`drop_test` drops a point mass onto one compiled normal law (the very contact stage a
simulation runs, `pdw.core._core.contact_batch`) and measures its effective coefficient of
restitution. `calibrate` gives each law parameters matched to the paper's Hunt-Crossley ground
on physical grounds (docs/contact_laws.md):

1. the same static sink under the walker's weight W = (m_h + 2 m_l) g cos(gamma): the
   stiffness k makes F_n(delta_s) = W at the Hunt-Crossley sink delta_s = (W/k_n)^(2/3);
2. the same effective coefficient of restitution of a foot landing at the typical touch-down
   speed, measured by the drop test (not assumed): the damping (d, or e) is solved for by
   bisection on the measured restitution.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ...core import _core, _layout
from ...core.contact import Contact
from ...core.errors import InvalidInputError
from ...core.model import kernel_index, parameter_vector
from ...core.params import Params

_KIN = {n: i for i, n in enumerate(_layout.KIN)}
_CON = {n: i for i, n in enumerate(_layout.CONTACT)}


@dataclass(frozen=True)
class Drop:
    """Outcome of a drop test: e = v_out / v_in; the largest depth [m] and force [N]; the
    contact duration [s] (force > 0)."""

    e: float
    v_in: float
    v_out: float
    max_depth: float
    peak_force: float
    duration: float


class _Law:
    """The compiled normal force of one law as a function of (delta, delta_dot, v_in)."""

    def __init__(self, contact: Contact, params: Params, variant: str = "paper"):
        params = contact.parameters(params)
        self.k = kernel_index(variant, None, contact.normal)
        self.p = contact.vector(parameter_vector(params))
        nk = len(_layout.KIN)
        self.kin = np.zeros((1, 2 * nk))
        self.flags = np.array([[1, 0]], dtype=np.intc)
        self.out = np.zeros((1, 2 * len(_layout.CONTACT)))

    def __call__(self, delta, deltad, v_in):
        self.kin[0, _KIN["y_D"]] = -delta
        self.kin[0, _KIN["v_y"]] = -deltad
        self.kin[0, _KIN["v_in"]] = v_in
        _core.contact_batch(self.k, self.kin, self.flags, self.p, self.out)
        return self.out[0, _CON["F_n"]]


def drop_test(contact, params: Params | None = None, v_in: float = 0.3, mass: float | None = None,
              gravity: bool = False, n_per_contact: int = 4000) -> Drop:
    """Drop a point mass onto a normal law and measure its coefficient of restitution.

    The mass meets the ground (depth 0) at ``v_in`` [m/s], downward; it is integrated with the
    classical Runge-Kutta method (``n_per_contact`` steps per Hertz contact time) until it
    leaves the ground (depth back to 0) or, the ground being unable to pull, the force drops
    to 0 while it rises (it then leaves at that speed). e = v_out / v_in.

    Parameters
    ----------
    contact : pdw.Contact, dict or str
    params : Params, optional
        The walker's parameters (k_n, d_n unless the contact sets them); default paper.
    v_in : float
        Impact speed [m/s], > 0.
    mass : float, optional
        Dropped mass [kg]; default the walker's m_h + 2 m_l.
    gravity : bool
        Include the weight m g cos(gamma) during contact (False: the impact alone, the
        laws' textbook setting).

    Returns
    -------
    Drop
    """
    contact = Contact.coerce(contact)
    params = Params.paper() if params is None else params
    if not (v_in > 0 and math.isfinite(v_in)):
        raise InvalidInputError("v_in must be finite and > 0 [m/s], got %r" % (v_in,))
    m = params.m_h + 2 * params.m_l if mass is None else float(mass)
    if not (m > 0 and math.isfinite(m)):
        raise InvalidInputError("mass must be finite and > 0 [kg], got %r" % (mass,))
    law = _Law(contact, params)
    g = params.g * math.cos(params.gamma) if gravity else 0.0
    k = contact.parameters(params).k_n
    # Hertz contact time 2.87 (m^2 / (k^2 v))^(1/5) (k in N/m^1.5); a linear spring: pi sqrt(m/k)
    tc = math.pi * math.sqrt(m / k) if contact.normal == "kelvin_voigt" \
        else 2.87 * (m * m / (k * k * v_in)) ** 0.2
    h = tc / n_per_contact

    def acc(d, dd):
        return (-law(d, dd, v_in) + m * g) / m if d > 0 else g

    d, dd, t = 0.0, v_in, 0.0
    max_d = peak = t_force = 0.0
    for _ in range(50 * n_per_contact):
        k1v, k1a = dd, acc(d, dd)
        k2v, k2a = dd + 0.5 * h * k1a, acc(d + 0.5 * h * k1v, dd + 0.5 * h * k1a)
        k3v, k3a = dd + 0.5 * h * k2a, acc(d + 0.5 * h * k2v, dd + 0.5 * h * k2a)
        k4v, k4a = dd + h * k3a, acc(d + h * k3v, dd + h * k3a)
        d_new = d + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        dd_new = dd + h / 6 * (k1a + 2 * k2a + 2 * k3a + k4a)
        t += h
        f = law(d_new, dd_new, v_in) if d_new > 0 else 0.0
        if f > 0:
            t_force = t
        peak = max(peak, f)
        max_d = max(max_d, d_new)
        if d_new <= 0.0 and dd_new < 0:          # left the ground: speed at depth 0
            frac = d / (d - d_new)                  # linear interpolation within the step
            v_out = -(dd + frac * (dd_new - dd))
            return Drop(v_out / v_in, v_in, v_out, max_d, peak, t_force)
        if f <= 0.0 and dd_new < 0 and g == 0.0 and d_new > 0:
            # rising with no force and no gravity: it leaves at this speed
            return Drop(-dd_new / v_in, v_in, -dd_new, max_d, peak, t_force)
        d, dd = d_new, dd_new
    if g > 0:     # settled under its weight: fully inelastic
        return Drop(0.0, v_in, 0.0, max_d, peak, t_force)
    raise RuntimeError("drop test did not end within 50 contact times (law %s)" % contact.normal)


@dataclass(frozen=True)
class Landing:
    """The typical touch-down of the default walker: the landing foot's approach speed -v_y
    [m/s] and its effective mass 1/(J M^-1 J^T) [kg] along the ground normal (J = dv_y/dq'),
    medians over the touch-downs of a run."""

    speed: float
    mass: float
    n: int


def typical_landing(params: Params | None = None, variant: Literal["paper", "consistent"] = "paper", t_end: float = 6.0,
                    skip: int = 3) -> Landing:
    """Measure the touch-downs of the default (Hunt-Crossley) walker from the paper's start:
    a cdm run at dt = 1e-4 s, the state one step before each touch-down after the first
    ``skip`` (the start-up transient)."""
    from ...core.model import contact_forces, mass_matrix
    from ...sim.simulation import simulate
    params = Params.paper_steady() if params is None else params
    r = simulate(params=params, variant=variant, t_end=t_end, dt=1e-4, method="cdm")
    speeds, masses = [], []
    td = [e for e in r.events if e.kind == "touch_down"][skip:]
    for ev in td:
        i = int(np.searchsorted(r.t, ev.t)) - 1
        x, j = r.x[i], ev.leg - 1
        cs = contact_forces(x, params, flags=(1, 1), variant=variant)
        speeds.append(-cs.v_y[j])
        th = _layout.STATE.index("theta%d" % (j + 1))
        J = np.zeros(_layout.NQ)        # dv_y/dq' of foot j (Eq. 5 of the variant)
        J[_layout.STATE.index("y_o")] = 1.0
        J[th] = (params.l - params.r) * math.sin(x[th]) + (params.r if variant == "paper" else 0.0)
        M = mass_matrix(x[:_layout.NQ], params)
        masses.append(1.0 / float(J @ np.linalg.solve(M, J)))
    if not speeds:
        raise RuntimeError("no touch-down after the first %d in %g s" % (skip, t_end))
    return Landing(float(np.median(speeds)), float(np.median(masses)), len(speeds))


@dataclass(frozen=True)
class Calibration:
    """Each law's `Contact` matched to the default ground: ``contacts[law]``; the target
    restitution ``e_target`` (the Hunt-Crossley drop at the typical landing), each law's
    measured ``e_drop`` and static sink ``sink`` [m]; ``reachable[law]`` is False when no
    parameter of the law reaches e_target (it then gets its most dissipative setting)."""

    landing: Landing
    weight: float
    sink: dict
    e_target: float
    e_drop: dict
    contacts: dict
    reachable: dict


def _bisect(fun, lo, hi, target, log=False, n=40):
    """x in [lo, hi] with fun(x) = target, fun monotone; None when target is outside."""
    flo, fhi = fun(lo), fun(hi)
    if (flo - target) * (fhi - target) > 0:
        return None
    for _ in range(n):
        mid = math.sqrt(lo * hi) if log else 0.5 * (lo + hi)
        fm = fun(mid)
        if (fm - target) * (flo - target) > 0:
            lo, flo = mid, fm
        else:
            hi = mid
    return math.sqrt(lo * hi) if log else 0.5 * (lo + hi)


def calibrate(params: Params | None = None, variant: Literal["paper", "consistent"] = "paper",
              landing: Landing | None = None) -> Calibration:
    """Parameters of every normal law matched to ``params``' Hunt-Crossley ground.

    Static sink: the laws with delta^1.5 stiffness keep k = k_n (at rest their damping is 0,
    so the sink under the weight W is (W/k_n)^(2/3) for each); Kelvin-Voigt gets
    k = W / delta_s. Restitution: the Hunt-Crossley drop test at the typical landing
    (`typical_landing`: speed and effective mass; no gravity, the impact alone) gives e_target;
    Kelvin-Voigt's d and the e of Lankarani-Nikravesh and Flores are solved for so that their
    own drop test (same speed and mass) gives e_target. Hertz has no damping (e = 1).
    """
    params = Params.paper_steady() if params is None else params
    landing = typical_landing(params, variant) if landing is None else landing
    W = params.weight
    sink = (W / params.k_n) ** (2.0 / 3.0)
    v, m = landing.speed, landing.mass

    def e_of(contact):
        return drop_test(contact, params, v_in=v, mass=m).e

    hc = Contact()
    e_target = e_of(hc)
    contacts = {"hunt_crossley": hc, "hertz": Contact("hertz")}
    reachable = {"hunt_crossley": True, "hertz": e_target >= 1.0 - 1e-9}
    k_kv = W / sink
    d_kv = _bisect(lambda d: e_of(Contact("kelvin_voigt", k=k_kv, d=d)), 1e-2, 1e5, e_target,
                   log=True)
    reachable["kelvin_voigt"] = d_kv is not None
    contacts["kelvin_voigt"] = Contact("kelvin_voigt", k=k_kv, d=1e5 if d_kv is None else d_kv)
    for law in ("lankarani_nikravesh", "flores"):
        e = _bisect(lambda x, law=law: e_of(Contact(law, e=x)), 0.01, 1.0, e_target)
        reachable[law] = e is not None
        contacts[law] = Contact(law, e=0.01 if e is None else e)
    e_drop = {law: e_of(c) for law, c in contacts.items()}
    sinks = {law: sink for law in contacts}
    return Calibration(landing, W, sinks, e_target, e_drop, contacts, reachable)


@dataclass(frozen=True)
class LugreCalibration:
    """LuGre matched to the paper's friction law (`calibrate_lugre`): the `Contact`, the
    tangential effective mass of a foot at mid-stance [kg], the weight [N], the bristle
    mode's natural frequency sqrt(sigma0 W / m_t) [rad/s] and the presliding displacement
    mu_s / sigma0 [m]."""

    contact: Contact
    mass: float
    weight: float
    omega: float
    presliding: float


def calibrate_lugre(params: Params | None = None, sigma0: float = 1e5,
                    normal: str = "hunt_crossley", **normal_parameters) -> LugreCalibration:
    """LuGre friction matched to the paper's smooth Coulomb law (Eq. 10) on physical grounds.

    * Stribeck curve: mu_s = `Params.mu_s`, mu_c = `Params.mu_d`, and v_s such that g(v) is
      half-way from mu_s to mu_c where Eq. 10's cubic step is, at (v_s + v_d)/2
      (`pdw.core.contact.lugre_stribeck`).
    * sigma0 [1/m]: the bristle stiffness per unit normal force; default 1e5 (Canudas de Wit et
      al. 1995), a presliding displacement mu_s / sigma0 of 5 um: stiff against the foot's
      travel, as the paper's law, which lets the stuck foot creep at most v_s.
    * sigma1 [s/m]: critically damped bristles for the foot that carries the weight W:
      sigma1 = 2 sqrt(sigma0 m_t / W), m_t = 1/(J M^-1 J^T) with J = dv_x/dq' of a foot at
      mid-stance (both legs vertical).
    * sigma2 = 0: Eq. 10 has no viscous term (mu = mu_d for every |v| > v_d).

    ``normal`` and ``normal_parameters`` (k, d, e, ...) give the normal law, as `Contact`.
    """
    from ...core.contact import lugre_stribeck
    from ...core.model import mass_matrix
    params = Params.paper_steady() if params is None else params
    W = params.weight
    q = np.zeros(_layout.NQ)
    q[_layout.STATE.index("y_o")] = params.l
    J = np.zeros(_layout.NQ)                 # v_x = xd_o + ((l - r) cos(theta) + r) thetad
    J[_layout.STATE.index("x_o")] = 1.0
    J[_layout.STATE.index("theta1")] = params.l
    m_t = 1.0 / float(J @ np.linalg.solve(mass_matrix(q, params), J))
    sigma1 = 2.0 * math.sqrt(sigma0 * m_t / W)
    st = lugre_stribeck(params)
    c = Contact(normal, friction="lugre", sigma0=sigma0, sigma1=sigma1, sigma2=0.0, **st,
                **normal_parameters)
    return LugreCalibration(c, m_t, W, math.sqrt(sigma0 * W / m_t), st["mu_s"] / sigma0)
