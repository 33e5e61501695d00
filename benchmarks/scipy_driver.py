"""Drive scipy's ``solve_ivp`` (LSODA, Radau, DOP853, ...) with pdw's compiled model.

The walker is a hybrid system: its right-hand side f depends on a discrete state (support
flags, the arming of the scuffing guard, the tangential anchors; docs/model.md sections 5-6) that
changes only at flag switches. pdw's adaptive loops locate each switch inside a step and
restart there (pdw/core/csrc/pdw_ode.c); this module does the same with scipy:

* f and its Jacobian are pdw's compiled kernels (``pdw.core._core.rhs_batch`` and
  ``pdw.core._core.jacobian_batch``, the very code that ``pdw.simulate`` calls), wrapped thinly on
  preallocated (1, 8) arrays -- the same compiled right-hand side as pdw's integrators;
* every switch rule of pdw/core/csrc/pdw_discrete.c that can fire from the current discrete state
  is a *terminal* scipy event, with a continuous function that is positive exactly where the
  rule's conjunction holds (and rises through 0 when it starts to hold):

      support leg i             lift-off     min(y_Di, v_yi)
      swing leg i, not armed    arming       min(x_Di - x_Dj, y_Di)
      swing leg i, armed        disarming    x_Dj - x_Di        (x_Di <= x_Dj)
                                touch-down   min(-y_Di, -v_yi)

  (the contact kinematics x_D, y_D, v_y of the variant are the compiled kernel's own, read
  from the work array of ``rhs_batch``);
* when an event stops the integration at t_e, the state is taken just after the switch,
  x(t_e + delta) on the step's dense output (delta = 1e-10 s: pdw's loops likewise end the step
  on the right end of a bracket of width event_tol, default 1e-9 s), `update_flags` -- a line
  by line mirror of ``pdw_update_flags`` -- is applied until nothing changes (as pdw's
  ``settle_flags``), and ``solve_ivp`` restarts from there with the events of the new
  discrete state.

`simulate_scipy` returns the final state, the touch-down / lift-off events (in
``pdw.Event`` form) and the work counters. tests/test_scipy_driver.py checks the events
against ``pdw.simulate(method="rodas4")``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

import pdw
from pdw.core import _core, _layout
from pdw.core.model import kernel_index, parameter_vector

_K0 = _layout.WORK["kin"][0]
_NK = len(_layout.KIN)
_X_D, _Y_D, _V_Y, _S = (_layout.KIN.index(n) for n in ("x_D", "y_D", "v_y", "s"))
#: state is taken this long after a located switch [s] (pdw: event_tol = 1e-9 s bracket)
DELTA = 1e-10


class Model:
    """pdw's compiled f, Jacobian and contact kinematics for one discrete state, on
    preallocated arrays (no allocation in the calls but the returned copies)."""

    def __init__(self, params=None, variant="paper"):
        self.k = kernel_index(variant)
        self.p = parameter_vector(params)
        self.x = np.zeros((1, _core.NX))
        self.xdot = np.zeros((1, _core.NX))
        self.J = np.zeros((1, _core.NX * _core.NX))
        self.work = np.zeros((1, _core.NWORK))
        self.kwork = np.zeros((1, _core.NWORK))
        self.kx = np.zeros((1, _core.NX))
        self.kdot = np.zeros((1, _core.NX))
        self.flags = np.zeros((1, 2), dtype=np.intc)
        self.anchors = np.zeros((1, 2))
        self.nfev = self.njev = self.nkin = 0
        self._kin_key = None

    def set_discrete(self, flags, anchors):
        self.flags[0] = flags
        self.anchors[0] = anchors
        self._kin_key = None

    def fun(self, t, y):
        self.x[0] = y
        _core.rhs_batch(self.k, self.x, self.p, self.flags, self.anchors, self.xdot, self.work)
        self.nfev += 1
        return self.xdot[0].copy()

    def jac(self, t, y):
        self.x[0] = y
        _core.jacobian_batch(self.k, self.x, self.p, self.flags, self.anchors, self.J, self.work)
        self.njev += 1
        return self.J[0].reshape(_core.NX, _core.NX).copy()

    def kinematics(self, y):
        """(2, 6) contact kinematics `pdw.core._layout.KIN` of both feet at y (cached per y)."""
        key = y.tobytes()
        if key != self._kin_key:
            self.kx[0] = y
            _core.rhs_batch(self.k, self.kx, self.p, self.flags, self.anchors, self.kdot, self.kwork)
            self.nkin += 1
            self._kin_key = key
            self._kin = self.kwork[0, _K0:_K0 + 2 * _NK].reshape(2, _NK).copy()
        return self._kin


@dataclass
class Discrete:
    """pdw_discrete (pdw/core/csrc/pdw_sim.h): flags, arming and anchors of legs 1, 2 (index 0, 1)."""

    flags: list
    armed: list = field(default_factory=lambda: [0, 0])
    anchors: list = field(default_factory=lambda: [0.0, 0.0])

    def key(self):
        return (tuple(self.flags), tuple(self.armed), tuple(self.anchors))


def update_flags(kin, d: Discrete, t, events):
    """One pass of pdw_update_flags (pdw/core/csrc/pdw_discrete.c), rule by rule, on the contact
    kinematics ``kin`` (2, 6) of the state; appends pdw.Event tuples to ``events``.
    ``kin`` must be recomputed by the caller after a touch-down (new anchor: xi only)."""
    for i in range(2):
        ki, kj = kin[i], kin[1 - i]
        y, vy = ki[_Y_D], ki[_V_Y]
        if d.flags[i]:
            if y > 0.0 and vy > 0.0:                                    # Eq. 18a: lift-off
                d.flags[i] = 0
                d.armed[i] = 0
                events.append(pdw.Event(t, i + 1, "lift_off", ki[_X_D], y))
            continue
        # scuffing guard: armed once above ground while downhill of the other foot
        if ki[_X_D] <= kj[_X_D]:
            d.armed[i] = 0
        elif y > 0.0:
            d.armed[i] = 1
        if d.armed[i] and y < 0.0 and vy < 0.0:                         # Eq. 18b: touch-down
            d.flags[i] = 1
            d.armed[i] = 0
            d.anchors[i] = ki[_S]
            events.append(pdw.Event(t, i + 1, "touch_down", ki[_X_D], y))


def settle_flags(model: Model, y, d: Discrete, t, events):
    """pdw's settle_flags: apply update_flags until nothing changes (at most 3 passes)."""
    for _ in range(3):
        before = d.key()
        model.set_discrete(d.flags, d.anchors)
        update_flags(model.kinematics(y), d, t, events)
        if d.key() == before:
            break
    model.set_discrete(d.flags, d.anchors)


def _event(fn, leg, kind):
    fn.terminal = True
    fn.direction = 1.0
    fn.leg = leg
    fn.kind = kind
    return fn


def switch_events(model: Model, d: Discrete):
    """The terminal events of every rule that can fire from discrete state d."""
    ev = []
    for i in range(2):
        j = 1 - i
        if d.flags[i]:
            ev.append(_event(lambda t, y, i=i: min(model.kinematics(y)[i, _Y_D],
                                                    model.kinematics(y)[i, _V_Y]), i, "lift_off"))
        elif not d.armed[i]:
            ev.append(_event(lambda t, y, i=i, j=j: min(
                model.kinematics(y)[i, _X_D] - model.kinematics(y)[j, _X_D],
                model.kinematics(y)[i, _Y_D]), i, "arm"))
        else:
            ev.append(_event(lambda t, y, i=i, j=j: model.kinematics(y)[j, _X_D]
                             - model.kinematics(y)[i, _X_D], i, "disarm"))
            ev.append(_event(lambda t, y, i=i: min(-model.kinematics(y)[i, _Y_D],
                                                    -model.kinematics(y)[i, _V_Y]), i, "touch_down"))
    return ev


@dataclass
class ScipyResult:
    t_final: float
    x_final: np.ndarray
    events: list                  # pdw.Event (legs 1, 2), like pdw.Result.events
    x_out: dict                   # requested output times -> state
    stats: dict                   # rhs, jacobians, steps, segments, kinematics, lu (if any)
    wall_time: float
    status: str


def simulate_scipy(method="LSODA", x0=pdw.X0_PAPER, t_end=3.5, params=None, variant="paper",
                   flags0=(0, 1), rtol=1e-6, atol=1e-8, t_out=(), use_jac=True, max_segments=10000,
                   **options):
    """Integrate the walker with ``scipy.integrate.solve_ivp(method=...)``, the flag switches
    as terminal events (module docstring). ``t_out``: extra times at which the state is
    returned (``x_out``), interpolated on scipy's dense output. ``use_jac``: pass pdw's symbolic
    Jacobian to implicit methods (Radau, BDF, LSODA). Extra ``options`` go to solve_ivp."""
    start = time.perf_counter()
    model = Model(params, variant)
    y = np.array(x0, dtype=float)
    d = Discrete(flags=[int(flags0[0]), int(flags0[1])])
    # pdw_discrete_init: support legs anchored at x0 (anchors enter only xi; kinematics' s does not)
    kin0 = model.kinematics(y)
    d.anchors = [float(kin0[i, _S]) if d.flags[i] else 0.0 for i in range(2)]
    events = []
    t = 0.0
    settle_flags(model, y, d, t, events)
    t_out = sorted(float(s) for s in t_out)
    x_out = {}
    stats = {"rhs": 0, "jacobians": 0, "steps": 0, "segments": 0, "lu": 0}
    jac = model.jac if use_jac and method in ("Radau", "BDF", "LSODA") else None
    status = "walked"
    while t < t_end:
        if stats["segments"] >= max_segments:
            status = "too many segments"
            break
        evs = switch_events(model, d)
        want = [s for s in t_out if t <= s <= t_end and s not in x_out]
        kw = dict(method=method, rtol=rtol, atol=atol, events=evs, dense_output=True, **options)
        if jac is not None:
            kw["jac"] = jac
        sol = solve_ivp(model.fun, (t, t_end), y, **kw)
        stats["segments"] += 1
        stats["steps"] += len(sol.t) - 1
        stats["lu"] += getattr(sol, "nlu", 0)
        if sol.status < 0:
            status = "failed: " + sol.message
            break
        if sol.status == 1:                                 # a switch: stop just after it
            fired = [(te[0], k) for k, te in enumerate(sol.t_events) if len(te)]
            t_e, k = min(fired)
            t_new = min(t_e + DELTA, t_end)
        else:
            t_new = t_end
        for s in want:
            if s <= t_new:
                x_out[s] = sol.sol(s)
        y = sol.sol(t_new) if t_new != sol.t[-1] else sol.y[:, -1].copy()
        t = t_new
        if sol.status == 1:
            before = d.key()
            settle_flags(model, y, d, t, events)
            if d.key() == before:
                # the event fired but the rule does not hold at t_e + delta (a grazing
                # crossing): apply the fired rule itself
                ev = evs[k]
                i = ev.leg
                kin = model.kinematics(y)
                if ev.kind == "lift_off":
                    d.flags[i], d.armed[i] = 0, 0
                    events.append(pdw.Event(t, i + 1, "lift_off", kin[i, _X_D], kin[i, _Y_D]))
                elif ev.kind == "arm":
                    d.armed[i] = 1
                elif ev.kind == "disarm":
                    d.armed[i] = 0
                else:
                    d.flags[i], d.armed[i], d.anchors[i] = 1, 0, float(kin[i, _S])
                    events.append(pdw.Event(t, i + 1, "touch_down", kin[i, _X_D], kin[i, _Y_D]))
                model.set_discrete(d.flags, d.anchors)
    stats["rhs"] = model.nfev
    stats["jacobians"] = model.njev
    stats["kinematics"] = model.nkin
    wall = time.perf_counter() - start
    return ScipyResult(t_final=t, x_final=np.asarray(y, dtype=float), events=events, x_out=x_out,
                       stats=stats, wall_time=wall, status=status)
