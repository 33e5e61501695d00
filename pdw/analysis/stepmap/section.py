"""The touch-down Poincaré section of the continuous walker, for every contact law
(`pdw.analysis.stepmap.limit_cycle`; docs/studies.md, "Limit cycles"; docs/contact_laws.md).

The section is the touch-down of the swing foot with the legs relabelled: leg 2 has just
touched down (the *leading* leg, its contact point put at the origin), leg 1 trails. Its
mechanical coordinates are those of `SECTION`,

    (theta1, theta2, xd_o, yd_o, thetad1, thetad2)      [rad, rad, m/s, m/s, rad/s, rad/s]

(x_o and y_o follow from theta2: x_D2 = y_D2 = 0). A contact law with *memory* of a foot's
past adds, for the trailing foot, what the continuous run carries across the section and the
mechanical state cannot give back (`section_names`):

``z1_um`` (``contact.friction == "lugre"``) [um]
    The trailing foot's LuGre bristle deflection, 1e6 x the state entry ``z1`` [m] (micrometres,
    so that one fd_step and one Newton tolerance fit every coordinate: the deflection is bounded
    by mu_s / sigma0, 5 um for the calibrated law). The leading foot's bristle is 0: the loop
    resets it at the touch-down (pdw/core/csrc/pdw_discrete.c, before the event's sample is
    recorded), so the recorded sample at the event already holds 0.
``v_in1`` (``contact.normal`` in lankarani_nikravesh, flores) [m/s]
    The trailing foot's approach speed, captured by the loop at its own touch-down one step
    earlier (-v_y of the foot then), which scales its damping until it lifts off. The leading
    foot's approach speed is not a coordinate: it is -v_y of the section state itself (what
    the loop captures at the touch-down, `leading_speed`).

The extras follow the mechanical six in that order (both with LuGre on a Flores ground: 8
coordinates). With the default laws (Coulomb friction on a Hunt-Crossley, Hertz or
Kelvin-Voigt ground) the section is `SECTION` and every function here computes what it did
before the extras existed.

What stays approximate: the ``consistent`` variant's tangential anchor of the trailing foot
(its rolling coordinate at its own touch-down) is not a coordinate; `simulate` re-anchors it at
the section (micrometres of slip, limit_cycle's module docstring).
"""
from __future__ import annotations

import math

import numpy as np

from ...core import _layout
from ...core.contact import LAW_PARAMETERS, Contact
from ...core.errors import InvalidInputError
from ...core.model import contact_forces
from ...core.params import X0_DISTURBED, X0_PAPER, Params
from ...sim.options import Integrator, Limits, Record
from ...sim.simulation import simulate
from ..gait_types import Gait

#: The step maps' runs return a divergence as a status (they judge it themselves).
RETURN = Limits(on_failure="return")

#: Mechanical section coordinates (legs relabelled: leg 2 has just touched down, leg 1 trails).
SECTION = ("theta1", "theta2", "xd_o", "yd_o", "thetad1", "thetad2")
#: Units of every section coordinate a contact law may have.
UNITS = {"theta1": "rad", "theta2": "rad", "xd_o": "m/s", "yd_o": "m/s", "thetad1": "rad/s",
         "thetad2": "rad/s", "z1_um": "um", "v_in1": "m/s"}
#: The bristle coordinate is the state's z1 [m] times this (micrometres).
BRISTLE_SCALE = 1e6
#: Tolerances of cheap uses of the step map (settling walks, cell mapping): errors ~1e-6.
LOOSE = dict(rtol=1e-7, atol=1e-9, event_tol=1e-10)


def _params(params):
    params = Params.paper_steady() if params is None else params
    if not isinstance(params, Params):
        raise InvalidInputError("params must be a pdw.Params, got %s" % type(params).__name__)
    return params


def uses_approach_speeds(contact) -> bool:
    """Does the normal law damp with the approach speed captured at touch-down?"""
    return "e" in LAW_PARAMETERS[Contact.coerce(contact).normal]


def section_names(contact=None) -> tuple:
    """Names of the section coordinates under ``contact`` (`pdw.Contact`, dict, law name or
    None for the default): `SECTION`, then ``"z1_um"`` with LuGre friction, then ``"v_in1"``
    with the lankarani_nikravesh and flores normal laws (module docstring; units in `UNITS`)."""
    c = Contact.coerce(contact)
    extra: tuple[str, ...] = ("z1_um",) if c.friction == "lugre" else ()
    if uses_approach_speeds(c):
        extra += ("v_in1",)
    return SECTION + extra


def section_units(contact=None) -> tuple:
    """Units of `section_names` (contact)."""
    return tuple(UNITS[n] for n in section_names(contact))


def check_z(z, name="z", contact=None) -> np.ndarray:
    """z as a float array of the section's size under ``contact``, finite; else
    `InvalidInputError` naming the coordinates."""
    names = section_names(contact)
    a = np.array(z, dtype=float).reshape(-1)
    if a.shape != (len(names),):
        raise InvalidInputError("%s must have %d components %s, got shape %s"
                                % (name, len(names), names, np.shape(z)))
    if not np.isfinite(a).all():
        raise InvalidInputError("%s must be finite, got %r" % (name, a))
    return a


def embed(z, params=None, contact=None) -> np.ndarray:
    """The full state of section point z under ``contact``, to be simulated with flags (1, 1):
    leg 2's contact point at the origin (x_D2 = y_D2 = 0), ``pdw.STATE`` (8 entries), and with
    LuGre the bristle states (z1 = z1_um / 1e6 [m], z2 = 0: leg 2 has just touched down).
    The approach speeds are not state: `start` gives them."""
    p = _params(params)
    a = check_z(z, contact=contact)
    th1, th2, xd, yd, w1, w2 = a[:6]
    x = np.array([-(p.l - p.r) * math.sin(th2), p.r + (p.l - p.r) * math.cos(th2),
                  th1, th2, xd, yd, w1, w2])
    c = Contact.coerce(contact)
    if c.friction == "lugre":
        x = np.concatenate([x, [a[6] / BRISTLE_SCALE, 0.0]])
    return x


def leading_speed(x, params, variant="paper") -> float:
    """The approach speed [m/s] of leg 2 at a touch-down state x: max(-v_y2, 0), what the loop
    captures (the foot that has just landed)."""
    return max(-float(contact_forces(np.asarray(x)[:8], params, flags=(1, 1),
                                     variant=variant).v_y[1]), 0.0)


def start(z, params=None, contact=None, variant="paper"):
    """(x0, approach_speeds0) of a `simulate` run from section point z (flags (1, 1)):
    `embed`, and for the laws that use them the approach speeds (v_in1 of z, `leading_speed`),
    else None. A negative v_in1 (a Newton or finite-difference iterate) starts as 0: the laws
    take max(v_in, v_in_min), so the map is flat there."""
    p = _params(params)
    x0 = embed(z, p, contact)
    if not uses_approach_speeds(contact):
        return x0, None
    return x0, (max(float(np.asarray(z, dtype=float)[-1]), 0.0), leading_speed(x0, p, variant))


def section_coordinates(x, leg=2, contact=None, approach_speeds=None) -> np.ndarray:
    """z of a full state x recorded at the touch-down of ``leg`` (1 or 2): relabels the legs
    when leg 1 touched down, drops x_o and y_o; with LuGre (x of 10 entries) appends the other
    (trailing) foot's bristle [um]; with lankarani_nikravesh or flores appends the trailing
    foot's approach speed from ``approach_speeds`` = (v_in1, v_in2) [m/s], the speeds the loop
    holds at that touch-down in the run's leg labels (`held_speeds`)."""
    x = np.asarray(x, dtype=float)
    if leg == 2:
        z = x[[2, 3, 4, 5, 6, 7]].copy()
    elif leg == 1:
        z = x[[3, 2, 4, 5, 7, 6]].copy()
    else:
        raise InvalidInputError("leg must be 1 or 2, got %r" % (leg,))
    if contact is None:
        return z
    c = Contact.coerce(contact)
    other = 2 - leg                 # index of the trailing foot in the run's labels (0 or 1)
    if c.friction == "lugre":
        if x.shape[-1] != c.nx:
            raise InvalidInputError("x must be a LuGre state of %d entries (%s), got %d"
                                    % (c.nx, ", ".join(c.state_names), x.shape[-1]))
        z = np.append(z, x[8 + other] * BRISTLE_SCALE)
    if uses_approach_speeds(c):
        if approach_speeds is None:
            raise InvalidInputError("the %s law's section carries the trailing foot's approach "
                                    "speed: pass approach_speeds=(v_in1, v_in2) [m/s]" % c.normal)
        z = np.append(z, float(approach_speeds[other]))
    return z


def extend(z, params=None, contact=None, variant="paper", names=None) -> np.ndarray:
    """A section point of ``contact`` from another one: the mechanical six, and the extras of
    ``contact`` from z where z has them (``names``: z's coordinates, default `SECTION` or those
    of ``contact``), else at their defaults: the trailing foot's bristle 0 (relaxed), its
    approach speed the leading foot's (`leading_speed`: exact on a period-1 gait). For
    guesses: a gait of another law, of the hybrid model."""
    want = section_names(contact)
    a = np.array(z, dtype=float).reshape(-1)
    if names is None:
        if a.shape == (len(want),):
            return check_z(a, contact=contact)
        names = SECTION
    names = tuple(names)
    if a.shape != (len(names),) or names[:6] != SECTION:
        raise InvalidInputError("z must have %d components %s, got shape %s"
                                % (len(names), names, np.shape(z)))
    out = list(check_z(a[:6], "z", None))
    for n in want[6:]:
        if n in names:
            out.append(a[names.index(n)])
        elif n == "z1_um":
            out.append(0.0)
        else:
            p = _params(params)
            out.append(leading_speed(embed(out[:6], p), p, variant))
    return check_z(out, "z", contact)


def held_speeds(result, t, initial, params, variant="paper"):
    """The approach speeds (v_in1, v_in2) [m/s] the loop of ``result`` holds at time t: each
    foot's -v_y at its last touch-down before t (the recorded sample at that event), or
    ``initial`` (the run's approach speeds at its start) for a foot that has not touched down
    since the start."""
    out = list(initial)
    for e in result.events:
        if e.kind != "touch_down" or not e.t < t:
            continue
        i = int(np.argmin(np.abs(result.t - e.t)))
        x = result.x[i]
        out[e.leg - 1] = -float(contact_forces(x[:8], params, flags=(1, 1),
                                               variant=variant).v_y[e.leg - 1])
    return tuple(out)


def initial_speeds(x0, flags0, params, variant="paper", approach_speeds0=None):
    """The approach speeds a run starts with (the loop's rule, pdw_discrete_init): the given
    ``approach_speeds0``, else max(-v_y, 0) of each foot that starts in support, 0 for a swing
    foot."""
    if approach_speeds0 is not None:
        return tuple(float(v) for v in approach_speeds0)
    vy = contact_forces(np.asarray(x0)[:8], params, flags=(1, 1), variant=variant).v_y
    return tuple(max(-float(vy[i]), 0.0) if flags0[i] else 0.0 for i in range(2))


# --- section points from walks, and guesses -----------------------------------------------------

def settle(x0, params=None, variant="paper", method="rodas4", *, flags0=(0, 1), t_end=8.0,
           rtol=LOOSE["rtol"], atol=LOOSE["atol"], event_tol=LOOSE["event_tol"], contact=None,
           approach_speeds0=None):
    """Walk from full state x0 for ``t_end`` s (one simulation, under ``contact``) and return
    the section point (`section_names` (contact)) of the last touch-down with both feet on the
    ground, or None if there was none."""
    p = _params(params)
    res = simulate(x0, t_end, 1e-4, params=p, variant=variant, flags0=flags0,
                   integrator=Integrator(method=method, rtol=rtol, atol=atol, event_tol=event_tol),
                   record=Record(every=1, forces=False), limits=RETURN, contact=contact,
                   approach_speeds0=approach_speeds0)
    speeds = None
    if contact is not None and uses_approach_speeds(contact):
        speeds = initial_speeds(x0, flags0, p, variant, approach_speeds0)
    for e in reversed(res.events):
        if e.kind != "touch_down":
            continue
        i = int(np.argmin(np.abs(res.t - e.t)))
        if abs(res.t[i] - e.t) < 1e-12 + 1e-9 * e.t and res.flags[i].all():
            held = None if speeds is None else held_speeds(res, e.t, speeds, p, variant)
            return section_coordinates(res.x[i], e.leg, contact, held)
    return None


def hybrid_guess(params=None):
    """A section point from the hybrid (rigid-ground) model's gait: its pre-impact state with
    the hip velocity of the rolling stance foot, legs relabelled (None if it has no gait)."""
    from ..rigid import hybrid
    p = _params(params)
    try:
        g = hybrid.find_gait(p)
    except Exception:      # noqa: BLE001 - no hybrid gait: no guess
        return None
    x = hybrid.full_state(g.details["y_minus"], p)        # leg 1 stance (trailing), 2 leading
    return section_coordinates(x, 2)


def default_guesses(params=None, variant="paper", method="rodas4", settle_time=8.0,
                    contact=None):
    """Starting points for Newton (list of (name, z)): the paper's initial condition, its
    disturbed start (Fig. 9) and the hybrid gait, each walked for ``settle_time`` s under
    ``contact`` (the hybrid gait's z with the extras of `extend`)."""
    p = _params(params)
    c = None if contact is None else Contact.coerce(contact)
    law = {} if c is None else dict(contact=c)
    out = []
    for name, x0, f0 in (("paper x0", X0_PAPER, (0, 1)), ("disturbed x0", X0_DISTURBED, (1, 0))):
        z = settle(x0, p, variant, method, flags0=f0, t_end=settle_time, **law)
        if z is not None:
            out.append((name + " settled", z))
    zh = hybrid_guess(p)
    if zh is not None:
        if c is not None:
            zh = extend(zh, p, c, variant)
        x0, v0 = start(zh, p, c, variant)
        z = settle(x0, p, variant, method, flags0=(1, 1), t_end=settle_time,
                   **law, **({} if v0 is None else dict(approach_speeds0=v0)))
        out.append(("hybrid gait settled", z if z is not None else zh))
        if z is not None:
            out.append(("hybrid gait", zh))
    return out


def _guess_z(guess, params, contact=None, variant="paper"):
    """A section point of ``contact`` from a guess (a `Gait`, a section point, a full state);
    the extras a guess lacks at their defaults (`extend`)."""
    if isinstance(guess, Gait):
        names = SECTION
        if guess.model == "continuous":
            z = np.asarray(guess.details["z"], dtype=float)
            names = guess.details.get("section_names", SECTION)
        else:
            from ..rigid import hybrid
            x = hybrid.full_state(guess.details["y_minus"], params)
            z = section_coordinates(x, 2)
        if contact is None and names == SECTION:
            return check_z(z)
        return extend(z, params, contact, variant, names)
    g = np.asarray(guess, dtype=float).reshape(-1)
    if contact is None:
        if g.shape == (len(_layout.STATE),):
            return section_coordinates(g, 2 if g[3] >= g[2] else 1)
        return check_z(g, "guess")
    c = Contact.coerce(contact)
    if g.shape in ((len(_layout.STATE),), (c.nx,)) and g.size != len(section_names(c)):
        leg = 2 if g[3] >= g[2] else 1
        if c.friction == "lugre" and g.size == len(_layout.STATE):
            g = np.concatenate([g, [0.0, 0.0]])
        z = section_coordinates(g, leg, Contact(friction=c.friction))
        return extend(z, params, c, variant) if uses_approach_speeds(c) else z
    try:
        return extend(g, params, c, variant)
    except InvalidInputError:
        return check_z(g, "guess", c)
