"""The exact monodromy of the continuous walker's step map: variational equations with saltation
matrices (issue #24 item 2; a Python/SciPy version over the compiled rhs and Jacobian).

Why this module is long (about 640 lines): Eq. 18's flag rules, the saltations and the event
loop that both engines share belong together (split, each part would read the others' state).

One step of the touch-down map (`pdw.analysis.stepmap.poincare.step`) from section point z:

    x0 = E(z)          (`section.embed`: leg 2's contact point at the origin, flags (1, 1))
    x' = f(x; flags)   between support-flag switches (lift-off, Eq. 18a: a support foot's height
                       g_i = y_o - r - (l - r) cos(theta_i) > 0 AND its normal rate v_i (the
                       paper's Eq. 5) > 0: where g_i passes 0 first, the foot stays support,
                       without penetration force, until v_i passes 0 (or g_i returns below 0);
                       touch-down, Eq. 18b: an armed swing foot's height g_i < 0 AND v_i < 0
                       (armed: above the ground while ahead of the other foot, as the
                       compiled loop's pdw_update_flags: armed when its contact point passes
                       the other one's forwards, or at a lift-off ahead of it; disarmed when
                       it passes back behind it, events of both engines); where g_i
                       passes 0 downwards with v_i >= 0 (the paper's v_i is not dg_i/dt) the
                       foot stays swing, without forces, until v_i passes 0 (or g_i returns
                       above 0)), and
    z' = R x(T)        at leg 1's touch-down (`section_coordinates(x, leg=1)`: relabelled).

Its Jacobian is M = R S_T Phi(T) E with Phi' = A(x(t)) Phi (A = df/dx, `pdw.ode_function`'s
``jac``), and at every flag switch at time t_k the saltation matrix

    S_k = I + (f+ - f-) grad g^T / (grad g . f-)

(f- and f+ the vector fields before and after, the identity where the force law is continuous
at zero penetration, as Hunt-Crossley is), and at the section event the projection
S_T = I - f grad g1^T / (grad g1 . f) (the derivative of the touch-down time; grad v1
for v1 instead where the touch-down is v1's crossing). x is integrated
by SciPy's Radau (rtol 1e-10) with the event functions (flag switches, the swing foot's
arming, Eq. 11's gates), then (x, Phi) from each interval's start to its end by LSODA
(``phi_rtol``). f jumps where a support foot's penetration reaches 0 (the tangential
spring-damper of Eqs. 7, 11 does not vanish with it): f- and f+ are the one-sided limits
(f 1e-9 s before and after the event), not f on the surface.

Every contact law with Coulomb friction (`pdw.Contact`: hunt_crossley, hertz, kelvin_voigt,
lankarani_nikravesh, flores; ``contact=``), through `pdw.ode_function`'s compiled f and
symbolic Jacobian of that law's kernel. The saltation matrices are built from the one-sided
limits of f, so a law's own jump needs no special code: Hunt-Crossley, Hertz,
Lankarani-Nikravesh and Flores give zero normal force at zero penetration (their force is
continuous at touch-down; the jump of f there is the tangential spring-damper's alone),
Kelvin-Voigt's force jumps by d * delta_dot at touch-down (d [N s/m] times the landing rate).
lankarani_nikravesh and flores damp with the approach speeds v_in (captured at each foot's
touch-down, held until the next; docs/contact_laws.md): the state is augmented with
(v_in1, v_in2) (v_in' = 0), the touch-down resets v_in_i = -v_i (the foot's normal rate), its
saltation carries that reset, df/dv_in is a central difference of the compiled f (a smooth
function of v_in; relative error ~1e-9), and the section's seventh coordinate v_in1 (the
trailing foot's approach speed, `pdw.analysis.stepmap.section`) is differentiated with the
rest. LuGre friction is refused: its kernel's Jacobian is itself a central difference (not
exact) and its bristle states reset at touch-down; use finite differences there.

Scope: the paper variant (the consistent variant's tangential anchors are not differentiated).

Two engines integrate each interval between events (``engine=``); the flag logic and the
saltation matrices above are this module's, shared by both:

* ``"compiled"`` (default; pdw/core/csrc/pdw_cvar.c, `pdw.core._core.cvar_interval`): x by
  RODAS4 (rtol, atol) and Phi by RODAS4 on the linear non-autonomous Phi' = A(x(t)) Phi along
  x's step (its f_t term dA/dt = dA[f] a central difference of the symbolic Jacobian along f;
  A at the inner stage times from its cubic Hermite interpolant between the step's ends, A and
  dA/dt there: 3 Jacobians a step), Phi's error estimate controlling the steps too
  (`PHI_TOL`); the events located in C to rounding (Newton on re-steps).
* ``"python"``: SciPy's Radau (rtol 1e-10) with the event functions, then LSODA for (x, Phi)
  (``phi_rtol``): the reference.

They agree to 2e-8 on paper_steady's multipliers (2e-9 at rtol 1e-12, phi_rtol 1e-10), to
~1e-7 for the other laws, to 2e-5 for Kelvin-Voigt's calibrated gait, whose rises' saltations
move by 1e-3 with a 1e-11 s shift of the event (the Python version itself moves by 2.5e-5
between rtol 1e-10 and 1e-11). Cost (benchmarks/bench_monodromy.py, CPU): compiled 0.16-0.5 x
the finite differences (13-15 maps through the ensemble engine), Python 6-26 x. ``dparam``
adds a parameter mu to the state (the compiled engine only): its column of A is a central
difference of f between two models (relative step 1e-6 in the continuation), and dz'/dmu comes
from the same integration; a branch point of `continue_gait` (P(z), M, dP/dmu and the map's
descriptors, `step_summary`) then costs one variational step, 0.6-0.7 x the differences' for
the default law and 0.2-0.3 x for the laws the ensemble engine does not run (docs/continuation.md).
Not the continuation's default (its documented branches are the differences'); it is the
cross-check of `GaitMap.crosscheck` and of a user's doubts near a kink.
"""
from __future__ import annotations

import math

import numpy as np

from ...core import _core  # type: ignore[attr-defined]  # compiled
from ...core.contact import Contact
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


#: event functions with a crossing direction d are shifted by -d x this (their units: m, m/s,
#: rad): an interval that starts exactly on a surface (g = 0.0 at the last event's state) then
#: does not report that start as the next crossing (brentq returns the bracket's end where g
#: is exactly 0: a Kelvin-Voigt foot re-entering the ground and bouncing out 1 ms later
#: reported the bounce at t0)
EVENT_SHIFT = 1e-14


def _event(fn, direction):
    """A terminal event function of solve_ivp with its crossing direction."""
    def ev(t, x):
        return fn(t, x) - direction * EVENT_SHIFT
    ev.terminal = True
    ev.direction = direction
    return ev


def _embed_jac(z, p):
    E = np.zeros((N, 6))
    th2 = z[1]
    E[0, 1] = -(p.l - p.r) * math.cos(th2)
    E[1, 1] = -(p.l - p.r) * math.sin(th2)
    for i, j in ((2, 0), (3, 1), (4, 2), (5, 3), (6, 4), (7, 5)):
        E[i, j] = 1.0
    return E


class _Field:
    """f and df/dy of the state y = (x, v_in1, v_in2) (the approach speeds only where the law
    uses them, ``na`` = 2; else y = x): v_in' = 0, f reads v_in as held speeds."""

    def __init__(self, f, na, params, pm=None):
        self.f, self.na, self.n, self.params = f, na, N + na + (pm is not None), params
        self.pm = pm        # (f at mu + dmu/2, f at mu - dmu/2, dmu): y carries mu last
        self.flags = [1, 1]
        # constant parameters after x and v_in: mu (``pm``) or variational_ground's heights
        self.n_par = int(pm is not None)

    def height_grad(self, leg):
        """d(leg's height event)/d(the parameters) (n_par,): none here (a subclass's hook)."""
        return np.zeros(self.n_par)

    def _set(self, y):
        if self.na:
            self.f.set_discrete(self.flags[0], self.flags[1], 0.0, 0.0,
                                (float(y[N]), float(y[N + 1])))

    def __call__(self, t, y):
        if len(y) == N:
            return self.f(t, y)
        self._set(y)        # v_in and the constant parameters: zero rates
        return np.concatenate([self.f(t, np.ascontiguousarray(y[:N])), np.zeros(len(y) - N)])

    def jac(self, t, y):
        if not self.na:
            return self.f.jac(t, y)
        self._set(y)
        A = np.zeros((self.n, self.n))
        x = np.ascontiguousarray(y[:N])
        A[:N, :N] = self.f.jac(t, x)
        for j in range(self.na):        # df/dv_in: a central difference (module docstring)
            h = 1e-6 * max(1.0, abs(y[N + j]))
            yp, ym = y.copy(), y.copy()
            yp[N + j] += h
            ym[N + j] -= h
            self._set(yp)
            fp = self.f(t, x)
            self._set(ym)
            A[:N, N + j] = (fp - self.f(t, x)) / (2 * h)
        self._set(y)
        return A

    def set_flags(self, f1, f2):
        self.flags[0], self.flags[1] = f1, f2      # in place: the caller holds the list
        self.f.set_discrete(f1, f2, 0.0, 0.0)


#: the one-sided limits f- and f+ are f at the event state moved across the surface, along
#: grad h, to h = -/+ this (h the event function: m, m/s or rad). Moving along f by 1e-9 s
#: instead (the first version) changed M by 0.2 at Kelvin-Voigt's gait, whose f varies by
#: J f tau there (1e-7 s: by 19); 1e-11 s gave 2e-3: the limits must be taken at the point.
LIMIT_OFFSET = 1e-12


def _across(y, grad, h, side):
    """y moved along grad (8,) to the event function's value side x LIMIT_OFFSET (h: its value
    at y)."""
    yy = y.copy()
    yy[:N] += (side * LIMIT_OFFSET - h) * grad / (grad @ grad)
    return yy


def _saltation(F, y, grad_x, h, change, height_leg=None):
    """(S, y+) at a switching surface h = 0 with gradient ``grad_x`` (8,) at y (h: its value
    at y, ~0): ``change()`` applies the discrete change (flags; returns the touch-down leg
    whose approach speed resets, or None). S = D + (f+ - D f-) grad^T / (grad . f-), D the
    reset's Jacobian (the identity but for a reset v_in_i = -v_i(x)); f- and f+ the one-sided
    limits (`LIMIT_OFFSET`: f at the surface itself is neither side's). The side a state is
    on before the event is the sign of -grad . f (the crossing direction). ``height_leg``:
    the surface is that leg's height (its parameter part, `_Field.height_grad`, enters grad).
    """
    n = F.n
    fy = F(0.0, y)
    d = 1.0 if grad_x @ fy[:N] > 0 else -1.0      # crossing upwards (h: - to +) or down
    f_minus = F(0.0, _across(y, grad_x, h, -d))
    grad = np.zeros(n)
    grad[:N] = grad_x
    if height_leg is not None and F.n_par:
        grad[n - F.n_par:] = F.height_grad(height_leg)
    leg = change()
    D = np.eye(n)
    y_plus = y.copy()
    if leg is not None and F.na:
        v, gv = _rate(y, leg, F.params)
        y_plus[N + leg] = -v
        D[N + leg, :] = 0.0
        D[N + leg, :N] = -gv
    f_plus = F(0.0, _across(y_plus, grad_x, h, d))
    S = D + np.outer(f_plus - D @ f_minus, grad) / (grad @ f_minus)
    return S, y_plus


def _specs(flags, pending, armed, gate_dir, sunk):
    """The compiled engine's event list (kind, leg, direction), slot for slot as the lambdas
    of `step_jacobian`'s loop (pdw_cvar.h's PDW_CVAR_EV_* codes)."""
    out = []
    for leg in (0, 1):
        if flags[leg] and pending[leg]:
            out.append((_EV_RATE, leg, 1.0))
        elif not flags[leg] and sunk[leg]:
            out.append((_EV_RATE, leg, -1.0))
        elif flags[leg] or armed[leg]:
            out.append((_EV_HEIGHT, leg, 1.0 if flags[leg] else -1.0))
        else:
            out.append((_EV_AHEAD, leg, 1.0))
    for leg in (0, 1):
        out.append((_EV_THETA if flags[leg] else _EV_NONE, leg, gate_dir[leg]))
    for leg in (0, 1):
        if pending[leg] or sunk[leg]:
            out.append((_EV_HEIGHT, leg, 1.0 if sunk[leg] else -1.0))
        else:
            out.append((_EV_NONE, leg, -1.0))
    for leg in (0, 1):
        out.append((_EV_AHEAD if _disarmable(flags, armed, leg) else _EV_NONE, leg, -1.0))
    return out


def _ahead(x, leg, p):
    """Whether leg's contact point is ahead of the other one's (pdw_discrete.c's arming)."""
    return _foot(x, leg, p)[2] > _foot(x, 1 - leg, p)[2]


def _pass(flags, armed, sunk, ahead, t, events):
    """The contact points pass each other at time t, leg ``ahead``'s now in front: it is
    armed if swing, the other one disarmed if an armed swing foot ("disarm" in ``events``)."""
    if not flags[ahead]:
        armed[ahead] = True
    other = 1 - ahead
    if _disarmable(flags, armed, other):
        armed[other] = sunk[other] = False
        events.append((t, "disarm", other + 1))


def _disarmable(flags, armed, leg):
    """Whether leg's swing foot is armed, so that its passing back behind the other foot
    (their contact points level, pdw_discrete.c: x_D,i <= x_D,j) disarms it: the compiled
    loop's rule (pdw_update_flags), an event of both engines (slots 6, 7)."""
    return not flags[leg] and armed[leg]


#: pdw_cvar.h's event kinds
_EV_NONE, _EV_HEIGHT, _EV_RATE, _EV_AHEAD, _EV_THETA = range(5)


#: the compiled engine's tolerance of Phi (relative and absolute; `step_jacobian`'s
#: ``phi_rtol``): its error estimate controls the steps too, else the stiff modes that Phi(0) = I
#: and every saltation excite (and x does not) are not resolved (x's control alone: Phi off by
#: 1e-4 over paper_steady's double support)
PHI_TOL = 1e-8


def _compiled_interval(F, p, specs, t0, y, Phi, h, t_max, rtol, atol, phi_tol):
    """(t_ev, k_ev, next step): y and Phi advanced in place to the first event (pdw_cvar.c)."""
    fp, fm, dmu = F.pm if F.pm is not None else (None, None, 0.0)
    rc, t_ev, k_ev, h = _core.cvar_interval(F.f, p.l, p.r, F.na, specs, t0, y, Phi, h, t_max,
                                            rtol=rtol, atol=atol, phi_rtol=phi_tol,
                                            phi_atol=phi_tol, phi_error=True, a_hermite=True,
                                            f_plus=fp, f_minus=fm, dmu=dmu)
    if rc == 1:
        raise InvalidInputError("variational step_jacobian: no touch-down by t_max = %g s"
                                % t_max)
    if rc != 0:
        raise InvalidInputError("variational step_jacobian: integration failed at t = %.6g s "
                                "(%s)" % (t_ev, "step size below rounding or a non-finite "
                                          "state" if rc == -1 else "step budget spent"))
    return t_ev, k_ev, h


def _python_interval(F, aug_rhs, evs, t0, y, Phi, t_max, rtol, atol, phi_rtol):
    """(t_ev, k_ev, y, Phi) at the first event: Radau for x, then LSODA for (x, Phi)."""
    from scipy.integrate import solve_ivp
    n = F.n
    sol = solve_ivp(F, (t0, t_max), y, method="Radau", rtol=rtol, atol=atol, jac=F.jac,
                    events=evs)
    if sol.status == -1:
        raise InvalidInputError("variational step_jacobian: integration failed: %s"
                                % sol.message)
    hits = [(te[0], k) for k, te in enumerate(sol.t_events) if len(te) and te[0] > t0]
    if not hits:
        raise InvalidInputError("variational step_jacobian: no touch-down by t_max = %g s"
                                % t_max)
    t_ev, k_ev = min(hits)
    y_ev = sol.y_events[k_ev][0].copy()
    # the variational equations along this interval
    ph = solve_ivp(aug_rhs, (t0, t_ev), np.concatenate([y, Phi.ravel()]),
                   method="LSODA", rtol=phi_rtol, atol=phi_rtol * 1e-2)
    if ph.status != 0:
        raise InvalidInputError("variational step_jacobian: variational equations "
                                "failed: %s" % ph.message)
    return t_ev, k_ev, y_ev, ph.y[n:, -1].reshape(n, n).copy()


def step_jacobian(z, params: Params | None = None, *, variant: str = "paper",
                  contact=None, rtol: float = 1e-10, atol: float = 1e-12,
                  phi_rtol: float | None = None, t_max: float = 2.5,
                  max_events: int = 40, engine: str = "compiled", field=None,
                  dparam=None) -> dict:
    """One step of the touch-down map and its exact Jacobian (module docstring).

    Parameters
    ----------
    z : array_like (6,) or (7,)
        Section point (`pdw.analysis.stepmap.section.section_names` of ``contact``: six
        coordinates, seven with the approach-speed laws).
    params : Params
        Default `Params.paper_steady()`.
    variant : {"paper"}
        Only the paper variant.
    contact : pdw.Contact, dict or str, optional
        Contact laws (default the paper's); every normal law with Coulomb friction; LuGre
        friction raises `pdw.InvalidInputError`.
    rtol, atol : float
        Radau tolerances of the trajectory x.
    phi_rtol : float, optional
        The tolerance of Phi: ``engine="python"``, LSODA's relative tolerance of (x, Phi)
        (absolute: 1e-2 of it; default 1e-10); ``"compiled"``, the relative and absolute
        tolerance of Phi's error estimate (default `PHI_TOL`).
    max_events : int
        The most intervals between events in one step (a bouncing support foot, as Hertz's
        at k_n = 1e6, rises and re-enters ~15 times a step).
    engine : {"compiled", "python"}
        ``"compiled"`` (default): x and Phi together by RODAS4 in C (pdw/core/csrc/pdw_cvar.c,
        `rtol`, `atol` on x), the events located there; ``"python"``: SciPy's Radau for x and
        LSODA for (x, Phi), the reference (module docstring).
    field : callable, optional
        ``field(f, na, params)`` -> a `_Field` whose state carries ``n_par`` constant
        parameters after x (and v_in): their columns are appended to ``M``, ``dx_dz`` and
        ``dT`` (`pdw.analysis.stepmap.variational_ground`; the Python engine only).
    dparam : ((Params, contact), (Params, contact), float), optional
        The model at mu + dmu/2 and at mu - dmu/2 of a parameter mu, and dmu (``engine``
        "compiled" only; `param_column`): the state carries mu (mu' = 0), df/dmu is the
        difference of the two models' f over dmu (central, O(dmu^2)), and ``dz_dparam`` is
        dz'/dmu, from the same integration. The two may differ from ``params`` only where
        f reads them (not in l, r: the section and the event functions; the same law).

    Returns
    -------
    dict
        ``z`` (z' (nz,)), ``M`` (nz, nz) dP/dz, ``T`` (the step time [s]), ``dT`` (nz,)
        dT/dz, ``events`` (list of
        (t, kind, leg) of the flag switches and gates), ``saltations`` (their S_k, (n, n) with
        n = 8, or 10 with approach speeds), ``x`` (the state at the touch-down, legs not
        relabelled), ``dx_dz`` (n, nz), ``Phi`` (n, n) and ``flags``; with ``dparam`` also
        ``dz_dparam`` (nz,) (and n counts mu) (the support flags just
        before the touch-down).
    """
    if engine not in ("compiled", "python"):
        raise InvalidInputError("variational step_jacobian: engine must be 'compiled' or "
                                "'python', got %r" % (engine,))
    if variant != "paper":
        raise InvalidInputError("variational step_jacobian: only variant='paper', got %r"
                                % (variant,))
    law = Contact.coerce(contact)
    if law.friction != "coulomb":
        raise InvalidInputError(
            "variational step_jacobian: contact.friction=%r is not supported (LuGre's kernel "
            "has a central-difference Jacobian and bristle states reset at touch-down): use "
            "the finite-difference monodromy (monodromy='differences')" % law.friction)
    p = _section._params(params)
    z = _section.check_z(z, contact=law)
    x0, v_in0 = _section.start(z, p, law, variant)
    na = 0 if v_in0 is None else 2
    nz = len(z)
    f = ode_function(p, variant, flags=(1, 1), contact=law,
                     approach_speeds=v_in0 if na else (0.0, 0.0))
    pm = None
    if dparam is not None:
        if field is not None:
            raise InvalidInputError("variational step_jacobian: give field or dparam, not both")
        if engine != "compiled" or not param_column(p, law, *dparam[:2]):
            raise InvalidInputError("variational step_jacobian: dparam needs engine='compiled' "
                                    "and models that differ only where f reads them (not in "
                                    "l, r or the law)")
        pm = tuple(ode_function(_section._params(P), variant, flags=(1, 1), contact=c)
                   for P, c in dparam[:2]) + (float(dparam[2]),)
    F = _Field(f, na, p, pm) if field is None else field(f, na, p)
    if field is not None and F.n_par and engine != "python":
        raise InvalidInputError("variational step_jacobian: a field with parameters needs "
                                "engine='python'")
    n = F.n
    y = np.concatenate([x0] + ([v_in0] if na else []) + [np.zeros(F.n_par)])
    E = np.zeros((n, nz + F.n_par))
    E[n - F.n_par:, nz:] = np.eye(F.n_par)
    E[:N, :6] = _embed_jac(z, p)
    if na:
        if z[6] > 0.0:
            E[N, 6] = 1.0
        v2, gv2 = _rate(x0, 1, p)
        if -v2 > 0.0:
            E[N + 1, :] = -gv2 @ E[:N, :]
    Phi = np.eye(n)
    t0, salts = 0.0, []
    events: list[tuple] = []
    flags = F.flags

    def aug_rhs(t, yy):
        yv = yy[:n]
        return np.concatenate([F(t, yv), (F.jac(t, yv) @ yy[n:].reshape(n, n)).ravel()])

    armed = [False, True]       # a swing foot touches down only ahead of the other one
    gate_dir = [0.0, 0.0]       # after a gate crossing only the opposite one (not t0 again)
    # a support foot above the ground whose normal rate is not yet > 0: Eq. 18a lifts it off
    # only when v > 0 too, so until then it stays support (flag 1) with no penetration force
    pending = [False, False]
    # an armed swing foot below the ground whose normal rate is not yet < 0: Eq. 18b touches
    # it down only when v < 0 too (the paper's v is not the height's rate), so until then it
    # stays swing, without forces, until v passes 0 (touch-down) or g returns above 0
    sunk = [False, False]
    # the trailing foot may start above the ground, still sinking (v <= 0): a damped law that
    # pulls no force (Kelvin-Voigt's clamp) let it rise before the section; the loop keeps it
    # support until v > 0, so it starts pending
    g1, v1 = _foot(y, 0, p)[0], _rate(y, 0, p)[0]
    if g1 > 0.0:
        if v1 > 0.0:
            raise InvalidInputError("variational step_jacobian: the trailing foot starts above "
                                    "the ground and rising (height %.3g m, rate %.3g m/s): "
                                    "it lifts off at the section itself" % (g1, v1))
        pending[0] = True

    def switch(leg, on):
        def change():
            F.set_flags(*[on if i == leg else flags[i] for i in (0, 1)])
            return leg if on else None
        return change

    h_next = 1e-4             # the compiled engine's first trial step [s]
    for _ in range(max_events):
        evs = []
        for leg in (0, 1):
            if flags[leg] and pending[leg]:     # Eq. 18a's second condition, v through 0
                evs.append(_event(lambda t, xx, leg=leg: _rate(xx, leg, p)[0], 1.0))
            elif not flags[leg] and sunk[leg]:  # Eq. 18b's second condition, v through 0
                evs.append(_event(lambda t, xx, leg=leg: _rate(xx, leg, p)[0], -1.0))
            elif flags[leg] or armed[leg]:
                evs.append(_event(lambda t, xx, leg=leg: _foot(xx, leg, p)[0],
                                  1.0 if flags[leg] else -1.0))
            else:                   # arming: the swing foot passes the other foot
                evs.append(_event(lambda t, xx, leg=leg: _foot(xx, leg, p)[2]
                                  - _foot(xx, 1 - leg, p)[2], 1.0))
        for leg in (0, 1):          # Eq. 11's gate: the tangential damper acts while xi <= 0
            evs.append(_event(lambda t, xx, leg=leg, on=flags[leg]: xx[2 + leg] if on else 1.0,
                              gate_dir[leg]))
        for leg in (0, 1):          # a pending foot back into the ground: contact again;
            # a sunk foot back above it: armed again for its next height crossing
            d_back = 1.0 if sunk[leg] else -1.0
            evs.append(_event(lambda t, xx, leg=leg, on=pending[leg] or sunk[leg], d=d_back:
                              _foot(xx, leg, p)[0] if on else d, d_back))
        for leg in (0, 1):          # an armed swing foot back behind the other one: disarmed
            on = _disarmable(flags, armed, leg)
            evs.append(_event(lambda t, xx, leg=leg, on=on:
                              _foot(xx, leg, p)[2] - _foot(xx, 1 - leg, p)[2] if on else 1.0,
                              -1.0))
        if engine == "compiled":
            t_ev, k_ev, h_next = _compiled_interval(
                F, p, _specs(flags, pending, armed, gate_dir, sunk), t0, y, Phi, h_next, t_max, rtol,
                atol, PHI_TOL if phi_rtol is None else phi_rtol)
        else:
            t_ev, k_ev, y, Phi = _python_interval(F, aug_rhs, evs, t0, y, Phi, t_max, rtol,
                                                  atol, 1e-10 if phi_rtol is None else phi_rtol)
        leg = k_ev % 2
        t0 = t_ev
        if k_ev >= 6 or (k_ev < 2 and not flags[leg] and not armed[leg]):
            # the contact points pass each other: the one now ahead, if swing, is armed (its
            # height crossing then counts from above the ground) and the one now behind, if
            # an armed swing foot, disarmed (the compiled loop's rule, pdw_discrete.c; both
            # at once: each is the other's event). No flag switch, f unchanged, no saltation
            _pass(flags, armed, sunk, 1 - leg if k_ev >= 6 else leg, t_ev, events)
            continue
        if k_ev >= 4 and sunk[leg]:
            # a sunk swing foot back above the ground before its rate turned negative: no
            # flag switch, f unchanged (a swing foot has no forces), no saltation
            sunk[leg] = False
            continue
        if k_ev >= 4 or (k_ev < 2 and flags[leg] and pending[leg]):
            # a pending foot's normal rate through 0 (the lift-off, Eq. 18a: the flag-gated
            # forces stop) or its height back through 0 (the penetration force returns)
            hl = None
            if k_ev < 2:
                h, grad = _rate(y, leg, p)
                change = switch(leg, 0)
                armed[leg] = _ahead(y, leg, p)
                events.append((t_ev, "lift_off", leg + 1))
            else:
                h, grad, _ = _foot(y, leg, p)
                change, hl = (lambda: None), leg
                events.append((t_ev, "reentry", leg + 1))
            pending[leg] = False
            S, y = _saltation(F, y, grad, h, change, hl)
            Phi = S @ Phi
            salts.append(S)
            continue
        if k_ev >= 2:               # a gate of the force law: f jumps, the flags stay
            grad = np.zeros(N)
            grad[2 + leg] = 1.0
            S, y = _saltation(F, y, grad, y[2 + leg], lambda: None)
            Phi = S @ Phi
            events.append((t_ev, "gate", leg + 1))
            gate_dir[leg] = 1.0 if y[6 + leg] < 0 else -1.0
            salts.append(S)
            continue
        if not flags[leg] and sunk[leg]:
            # the sunk foot's normal rate through 0 downwards: the touch-down (Eq. 18b) on
            # the surface v = 0
            sunk[leg] = False
            h, grad = _rate(y, leg, p)
            hl = None
        else:
            h, grad, _ = _foot(y, leg, p)
            hl = leg
            if not flags[leg] and _rate(y, leg, p)[0] >= 0.0:
                # below the ground but not moving down (Eq. 18b wants v < 0): still swing
                sunk[leg] = True
                continue
        if not flags[leg] and leg == 0:
            # leg 1's touch-down ahead of leg 2: the section (the projection S_T; the flags
            # and leg 1's approach speed after it are the next step's)
            f_minus = F(t_ev, _across(y, grad, h, 1.0))   # above the ground: before
            g = np.zeros(n)
            g[:N] = grad
            if hl is not None and F.n_par:
                g[n - F.n_par:] = F.height_grad(hl)
            S = np.eye(n) - np.outer(f_minus, g) / (g @ f_minus)
            R = np.zeros((nz, n))
            for i, j in enumerate((3, 2, 4, 5, 7, 6)):
                R[i, j] = 1.0
            if na:
                R[6, N + 1] = 1.0   # the trailing foot's approach speed: leg 2's held one
            M = R @ S @ Phi @ E
            dT = -(g @ Phi @ E) / (g @ f_minus)
            dx = S @ Phi @ E
            out = {"z": R @ y, "M": M, "T": t_ev, "dT": dT, "events": events,
                   "saltations": salts, "x": y[:N].copy(), "dx_dz": dx, "Phi": Phi,
                   "flags": (flags[0], flags[1])}
            if pm:              # mu's column apart: M, dT, dx_dz stay the state's
                out.update(M=M[:, :nz], dT=dT[:nz], dx_dz=dx[:, :nz], dz_dparam=M[:, nz])
            return out
        if flags[leg] and _rate(y, leg, p)[0] <= 0.0:
            # above the ground but not yet rising (Eq. 18a): the penetration force ends, the
            # flag stays 1 until v > 0
            pending[leg] = True
            events.append((t_ev, "rise", leg + 1))
            S, y = _saltation(F, y, grad, h, lambda: None, hl)
            Phi = S @ Phi
            salts.append(S)
            continue
        on = 0 if flags[leg] else 1
        S, y = _saltation(F, y, grad, h, switch(leg, on), hl)
        # a lifted-off foot already ahead of the other one is armed at once (the compiled
        # loop arms a swing foot above the ground and ahead at its next update)
        armed[leg] = False if on else _ahead(y, leg, p)
        Phi = S @ Phi
        events.append((t_ev, "touch_down" if on else "lift_off", leg + 1))
        salts.append(S)
    raise InvalidInputError("variational step_jacobian: more than %d flag switches in one step"
                            % max_events)


def param_column(params, contact, plus, minus) -> bool:
    """Whether `step_jacobian`'s ``dparam`` takes the models ``plus`` and ``minus`` ((Params,
    contact) each) around (``params``, ``contact``): the same leg length and foot radius (the
    section's embedding and the event functions read them) and the same contact law (one
    kernel); the rest of the parameters only f reads."""
    law = Contact.coerce(contact)
    for P, c in (plus, minus):
        q, other = _section._params(P), Contact.coerce(c)
        if (q.l, q.r) != (params.l, params.r) or (other.normal, other.friction) != (
                law.normal, law.friction):
            return False
    return True


def step_summary(res: dict, params: Params | None = None) -> dict:
    """`pdw.analysis.stepmap.poincare.step`'s descriptors of the step that `step_jacobian`
    integrated (``res``), by the map's definitions: ``status`` ("ok"; "flight" where leg 2
    was off the ground at the touch-down; "fell" where the state at the touch-down fails the
    map's fall limits, `pdw.Limits`' defaults: the hip below 0.5 l, a foot deeper than 0.25 l;
    "diverged" with a speed above 1e3; the map checks them at every step of the way, this only
    at the end),
    ``z``, ``period`` [s], ``double_support`` (until
    leg 1's first lift-off [s]), ``swing_period`` [s], ``step_length`` (leg 1's contact point
    at the touch-down [m]) and ``n_events`` (the flag switches, the touch-down included: a
    pending foot's "rise", a "reentry" and Eq. 11's gates switch no flag). The continuation's
    exact evaluation (`gait_maps.ContinuousProblem`) takes them from here instead of a second
    integration of the same step."""
    p = _section._params(params)
    x, T = res["x"], float(res["T"])
    lo = next(t for t, kind, leg in res["events"] if kind == "lift_off" and leg == 1)
    fell = x[1] < 0.5 * p.l or min(_foot(x, 0, p)[0], _foot(x, 1, p)[0]) < -0.25 * p.l
    status = ("diverged" if np.max(np.abs(x[4:N])) > 1e3 else "fell" if fell
              else "ok" if res["flags"][1] == 1 else "flight")
    return {"status": status, "z": res["z"],
            "period": T, "double_support": float(lo), "swing_period": T - float(lo),
            "step_length": float(x[0] + (p.l - p.r) * math.sin(x[2])),
            "n_events": 1 + sum(1 for _, kind, _ in res["events"]
                                if kind in ("lift_off", "touch_down"))}
