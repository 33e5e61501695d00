"""Limit cycles of the continuous (compliant-ground) walker: Poincaré map, Newton shooting,
Floquet multipliers, period-n detection (issue 7; docs/studies.md, "Limit cycles").

Poincaré section
----------------
The section is the **touch-down of the swing foot**: the instant its support flag turns on
(docs/model.md section 5, Eq. 18b), with both flags then 1 (the old stance foot is still on the
ground: double support begins). The state is taken just after the flag change, i.e. the
recorded sample at the event time; with ``rodas4``/``dopri5`` the event is located to
``event_tol`` (default here 1e-12 s), so the new stance foot's height is 0 to ~1e-12 m.

Coordinates (translation-invariant, legs relabelled): the leg that has just touched down (the
*leading* leg) is called leg 2 and the other (the *trailing*, old stance leg, about to lift off)
leg 1, as at the paper's initial condition (leg 2 support). On the section the new stance
foot's contact point is put at the origin, x_D2 = 0 and y_D2 = 0, which fixes the hip position
from theta2:

    x_o = -(l - r) sin(theta2),   y_o = r + (l - r) cos(theta2)

so the mechanical section is 6-dimensional, with coordinates (`SECTION`)

    z = (theta1, theta2, xd_o, yd_o, thetad1, thetad2)
      = (trailing angle, leading angle, hip velocity along / normal to the slope,
         trailing leg's rate, leading (swing) leg's rate)        [rad, rad, m/s, m/s, rad/s, rad/s]

A contact law with memory adds the trailing foot's share of it (`section_names(contact)`,
``pdw.analysis.stepmap.section``): with LuGre friction its bristle deflection ``z1_um`` [um] (the leading
foot's is 0: reset at its touch-down), with the lankarani_nikravesh and flores normal laws its
approach speed ``v_in1`` [m/s] captured at its own touch-down (the leading foot's is -v_y of the
section state). The map then is the continuous run's, on and off a fixed point, for period-n
gaits too; with the default laws (Coulomb friction, Hunt-Crossley / Hertz / Kelvin-Voigt) there
is no extra coordinate and z has 6 entries.

`embed(z, params, contact)` is the full state (flags (1, 1)); `section_coordinates(x, leg,
contact, approach_speeds)` goes back (relabelling when leg 1 touched down). The discarded
coordinates are x_o (translation along the slope: the map is invariant under it) and y_o
(y_D2 = 0 on the section).

The step map
------------
`step(z)`: ``pdw.simulate(embed(z), flags0=(1, 1), record_every=1, approach_speeds0=...)``
until past the trailing leg's next touch-down; the sample recorded at that event's time
(adaptive methods end an accepted step exactly there and record it after the flag update) is
relabelled and mapped to z'. The new trailing foot is the old leading one: its bristle is the
run's, its approach speed the one it got at the start (or at a later touch-down of its own).
Nothing in the compiled code is changed: the loop records every accepted step (a few thousand
samples) and Python picks the one at the event. The simulation runs to
``1.3 * t_hint + 0.05`` s (``t_hint``: the previous period, default 0.75 s) and, if the touch-down
has not happened by then, again to ``t_max``. (`pdw.analysis.stepmap.poincare` holds `step`; many maps
at once, through the ensemble engine with ``stop_touch_down=1``: `pdw.analysis.stepmap.step_maps`.)

*Restarting the discrete state.* At the section both legs are support, so nobody is armed
(docs/model.md section 5) and the restart's discrete state equals the running one, except for the
`consistent` variant's tangential anchors: `simulate` anchors a support leg at its initial
state, which is right for the new stance leg (it has just touched down) but resets the
trailing leg's accumulated slip since its own touch-down (micrometres; it lifts off ~16-50 ms
later). The `paper` variant (default) has no anchors, and its map is exact.

*Fixed-step methods* (``cdm``, ``verlet``, ``rk4``) switch flags at step boundaries; the section
state is then interpolated linearly between the last sample above ground and the first below
(y_D = 0), but the map stays quantised by dt (its event times jump by dt), so Newton with
finite differences is meaningless below ~dt-sized changes: use ``rodas4``.

Newton shooting and Floquet multipliers
---------------------------------------
`find_gait` solves P^n(z) = z (n = ``period``, default 1) by Newton's method with a damped step
(halved until the residual decreases). The Jacobian DP is taken by **central differences** with
an absolute step ``fd_step`` (default 1e-5 in every coordinate: rad, m/s, rad/s, um), each column
from two step-map evaluations (2 len(z) per Jacobian; for period 1 with an adaptive method and
the default laws as walkers of one `pdw.simulate_batch` call, rodas4 in the ensemble engine's
vectorized lanes, bitwise the scalar maps: `pdw.analysis.stepmap.step_maps`; otherwise in parallel
threads: the compiled loop releases the GIL). With the default tolerances (rtol 1e-10, atol 1e-12, event_tol 1e-12) one map
evaluation is reproducible to ~1e-10, so the Jacobian is good to ~1e-5 and Newton converges to a
residual max|P(z) - z| < ``tol`` = 1e-9 (the floor is ~3e-10). The Floquet multipliers are the
eigenvalues of the len(z) x len(z) Jacobian of P^n at the fixed point (6 x 6 for the default
laws, 7 x 7 with LuGre or Flores; the full 8x8 map would add the neutral translation and the
section's constraint); multipliers far below the Jacobian's noise
(~1e-4 in modulus) are not resolved. ``details["multipliers_check"]`` repeats them with
10 x ``fd_step``.

Starting guesses (``default_guesses``): the paper's initial condition and its disturbed start
(Fig. 9), and the hybrid model's gait (pre-impact state, `pdw.hybrid`), each first walked for
``settle_time`` seconds in one simulation (a stable gait attracts them); Newton starts from the
last touch-down of that walk.

Period-n detection: `detect_period` iterates the map and reports the smallest n with
max|z_{k+n} - z_k| < tol over the last iterates (or that the walker fell, or no period up to
``n_max``).
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ...core.errors import InvalidInputError
from ...core.params import X0_PAPER, Params
from ..gait_types import Gait, GaitNotFoundError
from .poincare import (  # noqa: F401  (the one-step map, re-exported)
    LOOSE_LUGRE,
    STEP_STATUS,
    TIGHT,
    _foot_height,
    _params,
    _z,
    orbit,
    step,
    step_map,
)
from .section import (  # noqa: F401
    LOOSE,
    SECTION,
    UNITS,
    _guess_z,
    default_guesses,
    embed,
    extend,
    hybrid_guess,
    section_coordinates,
    section_names,
    section_units,
    settle,
)
from .step_maps import (  # noqa: F401  (many maps at once, re-exported)
    _compose,
    _step_defaults,
    _workers,
    compose_points,
    map_batch,
    map_images,
)


def jacobian(z, params=None, variant="paper", method="rodas4", *, fd_step=1e-5, period=1,
             workers=None, **options):
    """(J, P^n(z), steps at z): central-difference Jacobian of P^n at z (n = len(z) square,
    ``section_names``), step ``fd_step`` (absolute, every coordinate in its unit of ``UNITS``); the
    2 n + 1 evaluations run in ``workers`` threads, the 2 n perturbed ones through the ensemble
    engine where it takes them (`compose_points`: the same numbers). J is NaN where a perturbed
    step failed."""
    z = _z(z, contact=options.get("contact"))
    n = len(z)
    E = np.eye(n) * fd_step
    pts = [z] + [z + e for e in E] + [z - e for e in E]
    outs = compose_points(pts, period, params, variant, method, options, workers)
    val = [o[0] if o[0] is not None else np.full(n, np.nan) for o in outs]
    J = np.column_stack([(val[1 + k] - val[1 + n + k]) / (2 * fd_step) for k in range(n)])
    return J, val[0], outs[0][1]


def floquet(z, params=None, variant="paper", method="rodas4", *, fd_step=1e-5, period=1,
            workers=None, **options):
    """(multipliers sorted by decreasing modulus, Jacobian) of P^n at z (a fixed point)."""
    opts = {**TIGHT, **options}
    J, _, _ = jacobian(z, params, variant, method, fd_step=fd_step, period=period,
                       workers=workers, **opts)
    mult = np.linalg.eigvals(J)
    return mult[np.argsort(-np.abs(mult))], J


# --- Newton shooting ----------------------------------------------------------------------------

def _newton(z, period, params, variant, method, opts, tol, max_iter, fd_step, workers):
    z = np.array(z, dtype=float)
    res = None
    for it in range(max_iter):
        J, Pz, steps = jacobian(z, params, variant, method, fd_step=fd_step, period=period,
                                workers=workers, **opts)
        if not np.isfinite(Pz).all():
            return None, dict(reason="step failed at iterate %d (%s)"
                              % (it, steps[-1]["status"]), iterations=it)
        res = Pz - z
        rn = float(np.max(np.abs(res)))
        if rn < tol:
            return z, dict(reason="converged", iterations=it, residual=rn, jacobian=J,
                           steps=steps)
        A = J - np.eye(len(z))
        if not np.isfinite(A).all():
            return None, dict(reason="Jacobian not finite at iterate %d" % it, iterations=it)
        try:
            dz = np.linalg.solve(A, -res)
        except np.linalg.LinAlgError:
            return None, dict(reason="singular Newton matrix", iterations=it)
        lam = 1.0
        for _ in range(8):
            zt = z + lam * dz
            Pt, _ = _compose(zt, period, params, variant, method, opts)
            if Pt is not None and np.max(np.abs(Pt - zt)) < rn:
                break
            lam *= 0.5
        z = z + lam * dz
    return None, dict(reason="no convergence in %d iterations (residual %.3g)"
                      % (max_iter, np.nan if res is None else np.max(np.abs(res))),
                      iterations=max_iter)


def find_gait(params: Params | None = None, variant: str = "paper",
              guess: ArrayLike | Gait | None = None, method: str = "rodas4", *, period: int = 1,
              tol: float = 1e-9, max_iter: int = 20, fd_step: float = 1e-5,
              settle_time: float = 8.0, workers: int | None = None, **options: Any) -> Gait:
    """The period-``period`` gait of the continuous (compliant-ground) walker by Newton shooting
    on the touch-down Poincaré map (module docstring).

    Parameters
    ----------
    params : Params
        Default `Params.paper_steady()`.
    variant : {"paper", "consistent"}
        Contact reading (docs/model.md section 6).
    guess : array_like, or a `Gait` (hybrid or continuous), optional
        A section point (``len(section_names(contact))`` entries, or the 6 mechanical ones: the
        law's extras then get ``extend``'s defaults), a full state at a touch-down (8 entries, or
        LuGre's 10), or a gait. Default: ``default_guesses`` in turn. A guess is used as it is
        (no settling walk).
    method : str
        Integrator of the step map; ``rodas4`` (default) locates the touch-down to ``event_tol``.
    period : int
        Solve P^period(z) = z (2 for a period-two gait, ...).
    tol : float
        Newton converges when max|P^n(z) - z| < tol (every coordinate in its unit of ``UNITS``:
        rad, m/s, rad/s, um for the bristle).
    max_iter : int
        Newton iterations per guess.
    fd_step : float
        Absolute step of the central-difference Jacobian (in each coordinate's unit).
    settle_time : float
        Length of the settling walk of the default guesses [s].
    workers : int
        Threads for the Jacobian's 2 len(z) + 1 map evaluations (default: all cores).
    options
        Step-map options: rtol, atol, event_tol (default ``TIGHT``), t_max, dt, and
        ``contact`` (`pdw.Contact`: the normal and friction laws). The section follows the law
        (``section_names``, ``pdw.analysis.stepmap.section``): with LuGre friction it carries the trailing
        foot's bristle ``z1_um`` [um], with lankarani_nikravesh or flores the trailing foot's
        approach speed ``v_in1`` [m/s], so the map is the continuous run's for every law.

    Returns
    -------
    Gait
        ``model="continuous"``; ``state``: the full state at the section (flags (1, 1), leg 2
        just touched down, its contact point at the origin); ``period``: touch-down to
        touch-down [s] (for period n > 1: the whole n-step cycle); ``step_length``: footprint
        spacing (n > 1: the mean); ``double_support`` [s] (n > 1: the mean); ``multipliers``: the
        len(z) eigenvalues of DP^n (6 for the default laws). ``details``: ``z``,
        ``section_names``, ``section_units``, ``jacobian``, ``fd_step``, ``residual``,
        ``newton_iterations``, ``swing_period``, ``travel``, ``orbit`` (n section points),
        ``steps``, ``multipliers_check`` (with 10 x fd_step), the guess used.

    Raises
    ------
    GaitNotFoundError
        No guess converged (``attempts`` says why for each).
    """
    p = _params(params)
    period = int(period)
    if period < 1:
        raise InvalidInputError("period must be >= 1, got %r" % (period,))
    opts = {**TIGHT, **options}
    contact = opts.get("contact")
    if guess is not None:
        guesses = [("given", _guess_z(guess, p, contact, variant))]
    else:
        guesses = default_guesses(p, variant, method, settle_time,
                                  **({} if contact is None else dict(contact=contact)))
    attempts = []
    for name, z0 in guesses:
        z, info = _newton(z0, period, p, variant, method, opts, tol, max_iter, fd_step, workers)
        attempts.append({"guess": name, "z0": z0, **{k: v for k, v in info.items()
                                                      if k not in ("jacobian", "steps")}})
        if z is not None:
            return _gait(p, variant, method, z, period, info, fd_step, opts, workers, name)
    raise GaitNotFoundError("no period-%d gait of the continuous model found from %d guess(es); "
                            "last: %s" % (period, len(guesses),
                                          attempts[-1]["reason"] if attempts else "no guess"),
                            attempts)


def _gait(p, variant, method, z, period, info, fd_step, opts, workers, guess_name):
    J = info["jacobian"]
    mult = np.linalg.eigvals(J)
    mult = mult[np.argsort(-np.abs(mult))]
    J10, _, _ = jacobian(z, p, variant, method, fd_step=10 * fd_step, period=period,
                         workers=workers, **opts)
    m10 = np.linalg.eigvals(J10)
    m10 = m10[np.argsort(-np.abs(m10))]
    steps = info["steps"]
    orbit_z = [z] + [s["z"] for s in steps[:-1]]
    T = float(sum(s["period"] for s in steps))
    contact = opts.get("contact")
    names = section_names(contact)
    details = {
        "section": "touch-down of the swing foot (flags (1, 1)); legs relabelled so that leg 2 "
                   "has just touched down; z = %s; x_D2 = y_D2 = 0" % (names,),
        "section_names": names, "section_units": section_units(contact),
        "z": z, "variant": variant, "method": method, "options": dict(opts), "fd_step": fd_step,
        "jacobian": J, "multipliers_check": m10, "residual": info["residual"],
        "newton_iterations": info["iterations"], "guess": guess_name, "period_n": period,
        "orbit": np.array(orbit_z), "steps": [{k: v for k, v in s.items() if k != "result"}
                                              for s in steps],
        "swing_period": float(np.mean([s["swing_period"] for s in steps])),
        "travel": float(np.mean([s["travel"] for s in steps])),
        "cycle": float(np.mean([s["period"] for s in steps])),
    }
    return Gait(state=embed(z, p, contact), period=T,
                step_length=float(np.mean([s["step_length"] for s in steps])),
                double_support=float(np.mean([s["double_support"] for s in steps])),
                multipliers=mult, model="continuous", params=p, details=details)


# --- period-n detection -------------------------------------------------------------------------

def detect_period(params=None, z0=None, variant="paper", method="rodas4", *, n_transient=30,
                  n_max=8, tol=1e-6, **options) -> dict:
    """Iterate the map ``n_transient + 2 n_max`` times from z0 (default: the paper's initial
    condition settled for 4 s) and classify the orbit.

    Returns a dict: ``kind`` ("period", "fell" (or another failed step: ``status``), or
    "aperiodic": no period up to n_max within tol), ``n`` (the period, or None), ``Z`` (the
    iterates), ``distance`` (max|z_{k+n} - z_k| over the last n_max iterates for n = 1..n_max).
    Step-map ``options`` default to `LOOSE`; with LuGre friction to `LOOSE_LUGRE` (at `LOOSE`
    the bristle coordinate z1_um jitters by ~3e-6 um from step to step, above ``tol``).
    """
    p = _params(params)
    contact = options.get("contact")
    loose = LOOSE_LUGRE if "z1_um" in section_names(contact) else LOOSE
    opts = {**loose, **options}
    if z0 is None:
        z0 = settle(X0_PAPER, p, variant, method, flags0=(0, 1), t_end=4.0,
                    **({} if contact is None else dict(contact=contact)))
        if z0 is None:
            return dict(kind="fell", status="fell", n=None,
                        Z=np.empty((0, len(section_names(contact)))), distance={})
    N = n_transient + 2 * n_max
    Z, info = orbit(z0, N, p, variant, method, **opts)
    if len(Z) < N + 1:
        return dict(kind="fell" if info[-1]["status"] == "fell" else "failed",
                    status=info[-1]["status"], n=None, Z=Z, distance={})
    tail = Z[-(n_max + 1):]
    dist = {}
    for n in range(1, n_max + 1):
        dist[n] = float(np.max(np.abs(Z[-n_max:] - Z[-n_max - n:len(Z) - n])))
    for n in range(1, n_max + 1):
        if dist[n] < tol:
            return dict(kind="period", status="ok", n=n, Z=Z, distance=dist, tail=tail)
    return dict(kind="aperiodic", status="ok", n=None, Z=Z, distance=dist, tail=tail)
