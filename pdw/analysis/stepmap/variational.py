"""The exact monodromy of the continuous walker's step map: variational equations with saltation
matrices (issue #24 item 2; a Python/SciPy version over the compiled rhs and Jacobian).

One step of the touch-down map (`pdw.analysis.stepmap.poincare.step`) from section point z:

    x0 = E(z)          (`section.embed`: leg 2's contact point at the origin, flags (1, 1))
    x' = f(x; flags)   between support-flag switches (lift-off, Eq. 18a: a support foot's height
                       g_i = y_o - r - (l - r) cos(theta_i) > 0 AND its normal rate v_i (the
                       paper's Eq. 5) > 0: where g_i passes 0 first, the foot stays support,
                       without penetration force, until v_i passes 0 (or g_i returns below 0);
                       touch-down: a swing foot's height through 0 downwards while ahead of
                       the other foot), and
    z' = R x(T)        at leg 1's touch-down (`section_coordinates(x, leg=1)`: relabelled).

Its Jacobian is M = R S_T Phi(T) E with Phi' = A(x(t)) Phi (A = df/dx, `pdw.ode_function`'s
``jac``), and at every flag switch at time t_k the saltation matrix

    S_k = I + (f+ - f-) grad g^T / (grad g . f-)

(f- and f+ the vector fields before and after, the identity where the force law is continuous
at zero penetration, as Hunt-Crossley is), and at the section event the projection
S_T = I - f grad g1^T / (grad g1 . f) (the derivative of the touch-down time). x is integrated
by SciPy's Radau (rtol 1e-10) with the event functions (flag switches, the swing foot's
arming, Eq. 11's gates), then (x, Phi) from each interval's start to its end by LSODA
(``phi_rtol``). f jumps where a support foot's penetration reaches 0 (the tangential
spring-damper of Eqs. 7, 11 does not vanish with it): f- and f+ are the one-sided limits
(f 1e-9 s before and after the event), not f on the surface.

Scope: the paper variant (the consistent variant's tangential anchors are not differentiated)
and the default laws (`pdw.ode_function` has no contact argument). Slower than the finite
differences (one Python integration of 72 equations), so not the continuation's default: it
is the cross-check of `tests/analysis/stepmap/test_continuation_variational.py` and of a user's doubts near a kink.
"""
from __future__ import annotations

import math

import numpy as np

from ...core.errors import InvalidInputError
from ...core.ode import ode_function
from ...core.params import Params
from . import section as _section

N = 8


def _foot(x, leg, p):
    """(height g, grad g (8,), horizontal position) of leg's contact point (leg 0 or 1)."""
    th = x[2 + leg]
    g = x[1] - p.r - (p.l - p.r) * math.cos(th)
    grad = np.zeros(N)
    grad[1] = 1.0
    grad[2 + leg] = (p.l - p.r) * math.sin(th)
    return g, grad, x[0] + (p.l - p.r) * math.sin(th)


def _rate(x, leg, p):
    """(v, grad v (8,)): leg's normal rate in the paper variant (docs/model.md section 6),
    v = ydot_o + (l - r) sin(theta) thetadot + r thetadot, which Eq. 18's flag rules read."""
    th, w = x[2 + leg], x[6 + leg]
    v = x[5] + (p.l - p.r) * math.sin(th) * w + p.r * w
    grad = np.zeros(N)
    grad[5] = 1.0
    grad[2 + leg] = (p.l - p.r) * math.cos(th) * w
    grad[6 + leg] = (p.l - p.r) * math.sin(th) + p.r
    return v, grad


def _event(fn, direction):
    """A terminal event function of solve_ivp with its crossing direction."""
    fn.terminal = True
    fn.direction = direction
    return fn


def _embed_jac(z, p):
    E = np.zeros((N, 6))
    th2 = z[1]
    E[0, 1] = -(p.l - p.r) * math.cos(th2)
    E[1, 1] = -(p.l - p.r) * math.sin(th2)
    for i, j in ((2, 0), (3, 1), (4, 2), (5, 3), (6, 4), (7, 5)):
        E[i, j] = 1.0
    return E


def step_jacobian(z, params: Params | None = None, *, variant: str = "paper",
                  rtol: float = 1e-10, atol: float = 1e-12, phi_rtol: float = 1e-10,
                  t_max: float = 2.5,
                  max_events: int = 12) -> dict:
    """One step of the touch-down map and its exact Jacobian (module docstring).

    Parameters
    ----------
    z : array_like (6,)
        Section point (`pdw.analysis.stepmap.section.SECTION`).
    params : Params
        Default `Params.paper_steady()`.
    variant : {"paper"}
        Only the paper variant.
    rtol, atol : float
        Radau tolerances of the trajectory x.
    phi_rtol : float
        LSODA's relative tolerance of (x, Phi) (absolute: 1e-2 of it).

    Returns
    -------
    dict
        ``z`` (z' (6,)), ``M`` (6, 6) dP/dz, ``T`` (the step time [s]), ``events`` (list of
        (t, kind, leg) of the flag switches and gates), ``saltations`` (their S_k), ``x`` (the
        state at the touch-down, legs not relabelled), ``dx_dz`` (8, 6) and ``Phi`` (8, 8).
    """
    from scipy.integrate import solve_ivp
    if variant != "paper":
        raise InvalidInputError("variational step_jacobian: only variant='paper', got %r"
                                % (variant,))
    p = _section._params(params)
    z = _section.check_z(z)
    x0 = _section.embed(z, p)
    flags = [1, 1]
    x, Phi = x0.copy(), np.eye(N)
    t0, events, salts = 0.0, [], []
    f = ode_function(p, variant, flags=(1, 1))

    def aug_rhs(t, yy):
        xx = yy[:N]
        return np.concatenate([f(t, xx), (f.jac(t, xx) @ yy[N:].reshape(N, N)).ravel()])

    armed = [False, True]       # a swing foot touches down only ahead of the other one
    gate_dir = [0.0, 0.0]       # after a gate crossing only the opposite one (not t0 again)
    # a support foot above the ground whose normal rate is not yet > 0: Eq. 18a lifts it off
    # only when v > 0 too, so until then it stays support (flag 1) with no penetration force
    pending = [False, False]

    for _ in range(max_events):
        evs = []
        for leg in (0, 1):
            if flags[leg] and pending[leg]:     # Eq. 18a's second condition, v through 0
                evs.append(_event(lambda t, xx, leg=leg: _rate(xx, leg, p)[0], 1.0))
            elif flags[leg] or armed[leg]:
                evs.append(_event(lambda t, xx, leg=leg: _foot(xx, leg, p)[0],
                                  1.0 if flags[leg] else -1.0))
            else:                   # arming: the swing foot passes the other foot
                evs.append(_event(lambda t, xx, leg=leg: _foot(xx, leg, p)[2]
                                  - _foot(xx, 1 - leg, p)[2], 1.0))
        for leg in (0, 1):          # Eq. 11's gate: the tangential damper acts while xi <= 0
            evs.append(_event(lambda t, xx, leg=leg, on=flags[leg]: xx[2 + leg] if on else 1.0,
                              gate_dir[leg]))
        for leg in (0, 1):          # a pending foot back into the ground: contact again
            evs.append(_event(lambda t, xx, leg=leg, on=pending[leg]:
                              _foot(xx, leg, p)[0] if on else 1.0, -1.0))
        x_start = x.copy()
        sol = solve_ivp(f, (t0, t_max), x, method="Radau", rtol=rtol, atol=atol, jac=f.jac,
                        events=evs, dense_output=True)
        if sol.status == -1:
            raise InvalidInputError("variational step_jacobian: integration failed: %s"
                                    % sol.message)
        hits = [(te[0], k) for k, te in enumerate(sol.t_events) if len(te) and te[0] > t0]
        if not hits:
            raise InvalidInputError("variational step_jacobian: no touch-down by t_max = %g s"
                                    % t_max)
        t_ev, k_ev = min(hits)
        x = sol.y_events[k_ev][0].copy()
        leg = k_ev % 2
        # the variational equations along this interval's dense trajectory
        ph = solve_ivp(aug_rhs, (t0, t_ev), np.concatenate([x_start, Phi.ravel()]),
                       method="LSODA", rtol=phi_rtol, atol=phi_rtol * 1e-2)
        if ph.status != 0:
            raise InvalidInputError("variational step_jacobian: variational equations "
                                    "failed: %s" % ph.message)
        Phi = ph.y[N:, -1].reshape(N, N)
        if k_ev >= 4 or (k_ev < 2 and flags[leg] and pending[leg]):
            # a pending foot's normal rate through 0 (the lift-off, Eq. 18a: the flag-gated
            # forces stop) or its height back through 0 (the penetration force returns)
            fx = f(t_ev, x)
            tau = 1e-9
            f_minus = f(t_ev, x - tau * fx)
            if k_ev < 2:
                _, grad = _rate(x, leg, p)
                flags[leg] = 0
                armed[leg] = False
                f.set_discrete(flags[0], flags[1], 0.0, 0.0)
                events.append((t_ev, "lift_off", leg + 1))
            else:
                _, grad, _ = _foot(x, leg, p)
            pending[leg] = False
            f_plus = f(t_ev, x + tau * fx)
            S = np.eye(N) + np.outer(f_plus - f_minus, grad) / (grad @ f_minus)
            Phi = S @ Phi
            salts.append(S)
            t0 = t_ev
            continue
        if k_ev >= 2:               # a gate of the force law: f jumps, the flags stay
            grad = np.zeros(N)
            grad[2 + leg] = 1.0
            fx = f(t_ev, x)
            tau = 1e-9
            f_minus, f_plus = f(t_ev, x - tau * fx), f(t_ev, x + tau * fx)
            S = np.eye(N) + np.outer(f_plus - f_minus, grad) / (grad @ f_minus)
            Phi = S @ Phi
            events.append((t_ev, "gate", leg + 1))
            gate_dir[leg] = 1.0 if x[6 + leg] < 0 else -1.0
            salts.append(S)
            t0 = t_ev
            continue
        if not flags[leg] and not armed[leg]:       # armed: no flag switch, no saltation
            armed[leg] = True
            t0 = t_ev
            continue
        g, grad, xd = _foot(x, leg, p)
        # one-sided limits: the contact force jumps where the penetration reaches 0 (Eq. 11's
        # tangential spring-damper does not vanish with it), so f at the surface itself is
        # neither side's
        tau = 1e-9
        fx = f(t_ev, x)
        f_minus = f(t_ev, x - tau * fx)
        if not flags[leg] and leg == 0:
            # leg 1's touch-down ahead of leg 2: the section
            S = np.eye(N) - np.outer(f_minus, grad) / (grad @ f_minus)
            R = np.zeros((6, N))
            for i, j in enumerate((3, 2, 4, 5, 7, 6)):
                R[i, j] = 1.0
            M = R @ S @ Phi @ _embed_jac(z, p)
            return {"z": R @ x, "M": M, "T": t_ev, "events": events, "saltations": salts,
                    "x": x, "dx_dz": S @ Phi @ _embed_jac(z, p), "Phi": Phi}
        if flags[leg] and _rate(x, leg, p)[0] <= 0.0:
            # above the ground but not yet rising (Eq. 18a): the penetration force ends, the
            # flag stays 1 until v > 0
            pending[leg] = True
            f_plus = f(t_ev, x + tau * fx)
            S = np.eye(N) + np.outer(f_plus - f_minus, grad) / (grad @ f_minus)
            Phi = S @ Phi
            salts.append(S)
            t0 = t_ev
            continue
        flags[leg] = 0 if flags[leg] else 1
        armed[leg] = False
        f.set_discrete(flags[0], flags[1], 0.0, 0.0)
        f_plus = f(t_ev, x + tau * fx)
        S = np.eye(N) + np.outer(f_plus - f_minus, grad) / (grad @ f_minus)
        Phi = S @ Phi
        events.append((t_ev, "touch_down" if flags[leg] else "lift_off", leg + 1))
        salts.append(S)
        t0 = t_ev
    raise InvalidInputError("variational step_jacobian: more than %d flag switches in one step"
                            % max_events)
