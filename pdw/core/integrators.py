"""The compiled integrators, described (docs/integrators.md).

Every loop is C (pdw/core/csrc/, one module per method, registered in pdw/core/csrc/pdw_methods.c, whose
table order is the method id); `pdw.simulate(method=name)` dispatches through that
table. This module describes each method for users and tests; `name`, `order` and `adaptive`
are checked against the C table at import, so the two cannot drift apart.

The common contract (pdw/core/csrc/pdw_sim.h, pdw/core/csrc/pdw_ode.h): a method advances the 8-state ODE
x' = f(x; flags, anchors) of docs/model.md section 3 with the discrete state (support flags, arming,
anchors of docs/model.md sections 5-6) held fixed during a step and updated between steps by
`pdw_update_flags`, which records every touch-down and lift-off as an event. Fixed-step methods
take ``round(t_end/dt)`` steps of ``dt`` and update the flags once per step from the state at
the step's start (the paper's Fig. 3). Adaptive methods integrate to ``t_end`` from a first step
``dt`` under ``rtol``/``atol`` (Hairer's scaled RMS norm) and ``h_max``, locate each flag
switch inside a step to within ``event_tol`` and end the step there. Every method counts its f
evaluations, Jacobians and rejected steps (`Result.stats`).
"""
from __future__ import annotations

from dataclasses import dataclass

from . import _core


@dataclass(frozen=True)
class Integrator:
    """One compiled integrator."""

    name: str
    order: int             #: order of the state on smooth problems
    adaptive: bool         #: error-controlled step size (rtol, atol, h_max, event_tol)
    stiff: bool            #: stable at steps far above the stuck-friction time scale (~1 us)
    uses_jacobian: bool    #: evaluates the symbolic Jacobian df/dx (kernel->jacobian)
    rhs_per_step: int      #: f evaluations per accepted step (steady state, no rejections)
    doc: str               #: the method's contract


INTEGRATORS = {i.name: i for i in (
    Integrator("cdm", 1, False, False, False, 1,
               "The paper's central difference method, docs/model.md section 7 (Eqs. 13-17), as "
               "printed: U_{n+1} from (M/dt^2 + C/2dt) U_{n+1} = ..., velocity (U_{n+1} - "
               "U_{n-1})/2dt, i.e. the centred velocity at t_n used at t_{n+1}: first order. "
               "Explicit: with the foot stuck the friction law's eigenvalue near -1e6 /s makes "
               "steps above ~1.5 us unstable, and at the paper's dt = 1e-4 the friction "
               "chatters (bounded only because mu saturates)."),
    Integrator("verlet", 2, False, False, False, 1,
               "Velocity Verlet with a half-step velocity predictor for the velocity-dependent "
               "forces: v_{n+1/2} = v_n + h/2 a_n, q_{n+1} = q_n + h v_{n+1/2}, "
               "a_{n+1} = qdd(q_{n+1}, v_{n+1/2} + h/2 a_n), v_{n+1} = v_{n+1/2} + h/2 a_{n+1}. "
               "Second order in q and in v (v is the velocity at t_{n+1}), one f per step "
               "(a_{n+1} is reused; recomputed after a flag change). Explicit: needs dt of a "
               "few microseconds in stance to avoid friction chatter."),
    Integrator("rk4", 4, False, False, False, 4,
               "Classical fourth-order Runge-Kutta, fixed step, four f per step; flags updated "
               "once per step like cdm. Explicit (stability bound ~2.8/|lambda|, about 2.5 us "
               "with the foot stuck)."),
    Integrator("dopri5", 5, True, False, False, 6,
               "Dormand-Prince 5(4), FSAL, local extrapolation, Hairer's PI step-size "
               "controller (beta = 0.04), events located to event_tol. Accurate and cheap per "
               "step but explicit: in stance the stuck foot bounds its steps to ~3 us, so a "
               "3.5 s gait costs ~1.5e6 steps. Use for swing-only or flight problems, or to "
               "cross-check."),
    Integrator("rodas4", 4, True, True, True, 6,
               "RODAS4, a stiffly accurate, L-stable Rosenbrock method of order 4 with an "
               "embedded order-3 estimate (Hairer & Wanner, Solving ODEs II): one symbolic "
               "Jacobian, one 8x8 LU and six f per step, I controller, events located to "
               "event_tol. Resolves stick friction at millisecond steps without chatter; the "
               "recommended method (rtol 1e-7, atol 1e-9 gives ~1e-6 in q at 3.5 s)."),
)}


def _check_against_c_table():
    table = _core.method_table()
    names = [n for n, _, _ in table]
    if sorted(names) != sorted(INTEGRATORS):
        raise ImportError("pdw.core.integrators is out of step with the C method table: %s vs %s"
                          % (names, sorted(INTEGRATORS)))
    for name, order, adaptive in table:
        i = INTEGRATORS[name]
        if (i.order, i.adaptive) != (order, adaptive):
            raise ImportError("pdw.core.integrators: %s is (order %d, adaptive %s) in C, (%d, %s) here"
                              % (name, order, adaptive, i.order, i.adaptive))


_check_against_c_table()

#: The method names in the order of the C table (the method id of `pdw.core._core.run`).
METHODS = tuple(name for name, _, _ in _core.method_table())


def get(name: str) -> Integrator:
    """The description of integrator ``name``."""
    try:
        return INTEGRATORS[name]
    except KeyError:
        raise ValueError("unknown integrator %r; allowed: %s" % (name, ", ".join(INTEGRATORS))) from None
