"""The touch-down Poincaré map of the continuous walker, one step at a time (`step`); the
section, the map's definition and its use are described in `pdw.limit_cycle` (docs/studies.md,
"Limit cycles"). Many steps at once: `pdw.analysis.stepmap.step_maps`.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from ...core.contact import Contact
from ...core.errors import FellError, InvalidInputError, SimulationError
from ...core.integrators import INTEGRATORS, METHODS
from ...sim.options import Integrator, Record
from ...sim.simulation import simulate
from . import section as _section
from .section import RETURN, section_coordinates, section_names

#: Defaults of the step map used by `find_gait` (accurate) ...
TIGHT = dict(rtol=1e-10, atol=1e-12, event_tol=1e-12)
#: ... and for cheap uses (settling walks, cell mapping): errors ~1e-6 (`section.LOOSE`).
#: With LuGre friction, `detect_period`'s: at `LOOSE` its map jitters by ~3e-6 in z1_um [um];
#: here by ~6e-8 (0.3 s a step at `Params.paper_steady()`, 25 x the default law's).
LOOSE_LUGRE = dict(rtol=1e-8, atol=1e-10, event_tol=1e-12)

STEP_STATUS = ("ok", "fell", "diverged", "no_touch_down", "flight", "bad_state")

#: What a step records: every step's state (and the contact forces, or not).
_RECORD = {False: Record(every=1, forces=False), True: Record(every=1, forces=True)}


@functools.lru_cache(maxsize=32)
def _integrator(method, rtol, atol, event_tol):
    """The step's `Integrator` (made once per setting: the maps call `step` many times)."""
    return Integrator(method=method, rtol=rtol, atol=atol, event_tol=event_tol)


def expected_end(t_hint):
    """Where `step` first ends its run [s]: 1.3 x the previous period (``t_hint``, default
    0.75 s) + 0.05 s (then, without a touch-down, again to t_max)."""
    return 1.3 * (0.75 if t_hint is None or not np.isfinite(t_hint) else float(t_hint)) + 0.05


def _params(params):
    return _section._params(params)


def _z(z, name="z", contact=None):
    return _section.check_z(z, name, contact)


def _foot_height(x, leg, p):
    th = x[1 + leg]
    return x[1] - p.r - (p.l - p.r) * math.cos(th)


# --- one step -----------------------------------------------------------------------------------

def step(z, params=None, variant="paper", method="rodas4", *, t_hint=None, t_max=2.5,
         dt=1e-4, rtol=TIGHT["rtol"], atol=TIGHT["atol"], event_tol=TIGHT["event_tol"],
         record=False, contact=None, ground=None) -> dict:
    """One step of the Poincaré map from section point z (``len(section_names(contact))``
    entries: a z of another size raises `InvalidInputError` naming the coordinates); never raises
    on a failed step.

    Returns a dict: ``status`` (one of `STEP_STATUS`: "ok"; "fell"/"diverged" as `simulate`;
    "no_touch_down" by ``t_max``; "flight": the stance foot was off the ground at the
    touch-down; "bad_state": z is not a valid start), ``z`` (z', NaN unless ok), ``x_touch``
    (the full state at the touch-down, legs not relabelled), ``period`` (touch-down to
    touch-down [s]), ``double_support`` (until the trailing leg's lift-off [s]),
    ``swing_period`` (the trailing leg's lift-off to its touch-down), ``step_length``
    (footprint spacing: leg 1's contact point at touch-down, leg 2's being 0), ``travel``
    (the swing foot's own travel), ``n_events``, ``stats``; with ``record=True`` also
    ``result`` (the `Result`, legs not relabelled, time from the section). ``ground``: a
    `pdw.Ground` (default flat), in the section's frame (the new stance foot at s = 0).
    """
    p = _params(params)
    law = Contact.coerce(contact)
    nz = len(section_names(law))
    if np.size(z) != nz:
        _z(z, contact=law)                  # the wrong size for the law: say so
    out = dict(status="ok", z=np.full(nz, np.nan), x_touch=np.full(law.nx, np.nan),
               period=np.nan, double_support=np.nan, swing_period=np.nan, step_length=np.nan,
               travel=np.nan, n_events=0, stats={})
    try:
        x0, v_in0 = _section.start(z, p, law, variant)
    except InvalidInputError:
        out["status"] = "bad_state"
        return out
    if method not in METHODS:
        raise InvalidInputError("method must be one of %s, got %r" % (", ".join(METHODS), method))
    adaptive = INTEGRATORS[method].adaptive
    t_first = expected_end(t_hint)
    ends = [min(t_first, t_max), t_max] if t_first < t_max else [t_max]
    for t_end in ends:
        t_end = max(t_end, 10 * dt)
        res = simulate(x0, t_end, dt, params=p, variant=variant, flags0=(1, 1),
                       integrator=_integrator(method, rtol, atol, event_tol),
                       record=_RECORD[bool(record)], limits=RETURN, contact=contact,
                       approach_speeds0=v_in0, ground=ground)
        out["stats"] = dict(res.stats)
        lo = next((e for e in res.events if e.leg == 1 and e.kind == "lift_off"), None)
        td = next((e for e in res.events if e.leg == 1 and e.kind == "touch_down"), None)
        if td is not None or res.status != "walked":
            break
    if record:
        out["result"] = res
    if td is None or lo is None:      # (leg 1 touches down only after its lift-off)
        out["status"] = res.status if res.status != "walked" else "no_touch_down"
        return out
    i = int(np.argmin(np.abs(res.t - td.t)))
    x, t = res.x[i].copy(), float(res.t[i])
    if res.flags[i, 1] != 1:
        out["status"] = "flight"
        return out
    if not adaptive and i > 0:
        # fixed step: interpolate to the touch-down foot's height 0 between samples i-1, i
        y0, y1 = _foot_height(res.x[i - 1], 1, p), _foot_height(x, 1, p)
        if y0 >= 0.0 > y1:
            s = y0 / (y0 - y1)
            x = res.x[i - 1] + s * (x - res.x[i - 1])
            t = float(res.t[i - 1] + s * (res.t[i] - res.t[i - 1]))
    speeds = None if v_in0 is None else _section.held_speeds(res, td.t, v_in0, p, variant)
    out.update(status="ok", z=section_coordinates(x, 1, law, speeds), x_touch=x,
               period=t,
               double_support=lo.t, swing_period=t - lo.t,
               step_length=x[0] + (p.l - p.r) * math.sin(x[2]),
               travel=x[0] + (p.l - p.r) * math.sin(x[2]) - lo.x_D,
               n_events=sum(1 for e in res.events if e.t <= td.t))
    return out


def step_map(z, params=None, variant="paper", method="rodas4", **options) -> np.ndarray:
    """P(z): the section point after the next touch-down. Raises `FellError` or
    `SimulationError` when the step fails."""
    s = step(z, params, variant, method, **options)
    if s["status"] == "fell":
        raise FellError("the walker fell during the step from z = %r" % (np.asarray(z),),
                        reason="fell")
    if s["status"] != "ok":
        raise SimulationError("step from z = %r failed: %s" % (np.asarray(z), s["status"]),
                              reason=s["status"])
    return s["z"]


def orbit(z, n, params=None, variant="paper", method="rodas4", **options):
    """n iterates of the map from z: (Z of shape (k+1, len(z)), list of step dicts); stops early
    (k < n) at a failed step."""
    Z, info = [_z(z, contact=options.get("contact"))], []
    t_hint = options.pop("t_hint", None)
    for _ in range(int(n)):
        s = step(Z[-1], params, variant, method, t_hint=t_hint, **options)
        info.append(s)
        if s["status"] != "ok":
            break
        t_hint = s["period"]
        Z.append(s["z"])
    return np.array(Z), info


# --- parallel evaluation ----------------------------------------------------------------------
