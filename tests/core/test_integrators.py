"""The integrators beyond the paper's (pdw/core/csrc/pdw_{verlet,rk4,dopri5,rodas4}.c,
docs/integrators.md): tableaus, orders, stiffness, event location, agreement, bookkeeping."""
import math

import numpy as np
import pytest

import pdw
from pdw import METHODS, X0_PAPER, simulate
from pdw.core import _core
from pdw.core.integrators import INTEGRATORS
from pdw.core.model import kernel_index, parameter_vector

ADAPTIVE = [n for n in METHODS if INTEGRATORS[n].adaptive]


# ------------------------------------------------------------------ registry and tableaus

def test_registry_matches_c_table():
    assert set(METHODS) == set(INTEGRATORS)
    for name, order, adaptive in _core.method_table():
        assert (INTEGRATORS[name].order, INTEGRATORS[name].adaptive) == (order, adaptive)
    assert INTEGRATORS["rodas4"].stiff and INTEGRATORS["rodas4"].uses_jacobian


def _trees(order):
    """Rooted trees with `order` nodes as sorted tuples of subtrees (Butcher)."""
    if order == 1:
        return [()]
    out = set()

    def partitions(n, maxpart):
        if n == 0:
            yield []
            return
        for k in range(min(n, maxpart), 0, -1):
            for rest in partitions(n - k, k):
                yield [k] + rest

    for parts in partitions(order - 1, order - 1):
        def combos(i, parts=parts):
            if i == len(parts):
                yield []
                return
            for t in _trees(parts[i]):
                for rest in combos(i + 1):
                    yield [t] + rest
        for children in combos(0):
            out.add(tuple(sorted(children)))
    return sorted(out)


def _size(t):
    return 1 + sum(_size(c) for c in t)


def _density(t):
    return _size(t) * math.prod(_density(c) for c in t)


def _weights(t, A):
    """Internal weights Phi_i(t): prod over children of (A Phi(child))."""
    v = np.ones(A.shape[0])
    for c in t:
        v = v * (A @ _weights(c, A))
    return v


def _order_of(b, A, pmax):
    """Highest p <= pmax for which every tree of order <= p satisfies b.Phi(t) = 1/gamma(t)."""
    for p in range(1, pmax + 1):
        for t in _trees(p):
            if abs(b @ _weights(t, A) - 1.0 / _density(t)) > 1e-12:
                return p - 1
    return pmax


@pytest.mark.parametrize("name", ["rk4", "dopri5"])
def test_rk_tableau_order_conditions(name):
    T = _core.rk_tableau(name)
    A, b, c, e = T["A"], T["b"], T["c"], T["e"]
    assert np.allclose(A.sum(axis=1), c, atol=1e-15, rtol=0)       # row sums
    assert np.allclose(np.triu(A), 0.0)                             # explicit
    assert abs(b.sum() - 1.0) < 1e-15
    assert len(_trees(4)) == 4 and len(_trees(5)) == 9              # 1, 1, 2, 4, 9 trees
    assert _order_of(b, A, T["order"] + 1) == T["order"]
    if T["embedded_order"]:
        bhat = b - e
        assert abs(e.sum()) < 1e-15
        assert _order_of(bhat, A, T["order"]) == T["embedded_order"]
    if T["fsal"]:
        assert np.allclose(A[-1], b) and c[-1] == 1.0


def test_rosenbrock_tableau_order_conditions():
    """RODAS4 in the transformed form -> the (alpha, gamma) form of Hairer & Wanner II, Sec.
    IV.7, and their order conditions (Table 7.1) up to order 4; the embedded one: order 3."""
    R = _core.ros_tableau("rodas4")
    g, s = R["gamma"], R["stages"]
    Gam = np.linalg.inv(np.eye(s) / g - R["C"])             # C = diag(1/gamma) - Gamma^-1
    assert np.allclose(np.diag(Gam), g)
    alpha = R["a"] @ Gam
    beta = alpha + Gam
    Bp = beta - np.diag(np.diag(beta))
    al, bp = alpha.sum(axis=1), Bp.sum(axis=1)

    def residuals(b):
        return np.array([
            b.sum() - 1, b @ bp - (0.5 - g),
            b @ al**2 - 1/3, b @ (Bp @ bp) - (1/6 - g + g*g),
            b @ al**3 - 1/4, b @ (al * (alpha @ bp)) - (1/8 - g/3),
            b @ (Bp @ al**2) - (1/12 - g/3), b @ (Bp @ (Bp @ bp)) - (1/24 - g/2 + 1.5*g*g - g**3)])

    r = residuals(R["m"] @ Gam)
    assert np.abs(r).max() < 1e-12
    rhat = residuals((R["m"] - R["e"]) @ Gam)
    assert np.abs(rhat[:4]).max() < 1e-12 and np.abs(rhat[4:]).max() > 1e-3


# ------------------------------------------------------------------ convergence order

X0_FLIGHT = (0.0, 1.0, -0.3, 0.3, 0.5, 0.0, 2.0, -1.0)   # hip 1 m up: both feet in the air
T_FLIGHT = 0.2


@pytest.fixture(scope="module")
def flight_reference():
    """Swing of both legs with no contact (flags (0, 0), feet above ground): a smooth problem.
    Reference: scipy's DOP853 on pdw.rhs at rtol 1e-13."""
    from scipy.integrate import solve_ivp
    p = pdw.Params.paper()
    sol = solve_ivp(lambda t, x: pdw.rhs(x, p, flags=(0, 0)), (0.0, T_FLIGHT), X0_FLIGHT,
                    method="DOP853", rtol=1e-13, atol=1e-13)
    cs = pdw.contact_forces(sol.y.T, flags=(0, 0))
    assert (cs.y_D > 0.05).all()                           # no contact anywhere
    return sol.y[:, -1]


@pytest.mark.parametrize("name", list(INTEGRATORS))
def test_convergence_order(name, flight_reference):
    """The log-log slope of the error at T against the step matches the declared order.
    Adaptive methods run at a fixed step: rtol = atol = 1 never rejects, h_max caps the step."""
    info = INTEGRATORS[name]
    ns = [10, 20, 40, 80] if info.order >= 4 else [100, 200, 400, 800]
    errs = []
    for n in ns:
        h = T_FLIGHT / n
        tol = dict(rtol=1.0, atol=1.0, h_max=h) if info.adaptive else {}
        r = simulate(x0=X0_FLIGHT, t_end=T_FLIGHT, dt=h, method=name, flags0=(0, 0),
                     integrator=pdw.Integrator(check_step="off", **tol),  # no ground: no contact limit
                     record=pdw.Record(every=0))
        assert not r.events
        errs.append(np.abs(r.x_final - flight_reference).max())
    slope = np.polyfit(np.log(T_FLIGHT / np.array(ns)), np.log(errs), 1)[0]
    assert abs(slope - info.order) < 0.25, (name, errs, slope)


# ------------------------------------------------------------------ stiffness: stick friction

def test_rodas4_sticks_without_chatter_at_large_steps():
    """Stance of leg 2 from the paper's start (before the first touch-down at 0.337 s): once the
    foot sticks, its slip speed stays below v_s = 1e-4 m/s with RODAS4 at steps of milliseconds
    (the friction eigenvalue is near -1e6 /s). cdm at the paper's dt = 1e-4 chatters."""
    v_s = pdw.Params.paper().v_s
    r = simulate(t_end=0.33, method="rodas4", integrator=pdw.Integrator(rtol=1e-5, atol=1e-7))
    assert not r.events
    h = np.diff(r.t)
    assert np.median(h) > 1e-3 and r.stats["steps"] < 0.33 / 1e-4 / 10
    vx = pdw.contact_forces(r.x, flags=(0, 1)).v_x[:, 1]
    stuck = np.argmax(np.abs(vx) < v_s)
    assert r.t[stuck] < 0.01
    assert np.abs(vx[stuck:]).max() < v_s
    # the paper's method at its own step: the stuck foot chatters
    c = simulate(t_end=0.33, method="cdm", dt=1e-4)
    vc = pdw.contact_forces(c.x, flags=(0, 1)).v_x[:, 1]
    assert np.abs(vc[len(vc) // 10:]).max() > 10 * v_s


# ------------------------------------------------------------------ event location

@pytest.fixture(scope="module")
def early_events():
    """Events up to 0.4 s (first touch-down of leg 1, lift-off of leg 2), very accurate."""
    r = simulate(t_end=0.4, method="rodas4",
                 integrator=pdw.Integrator(rtol=1e-12, atol=1e-14, event_tol=1e-13),
                 record=pdw.Record(every=0))
    assert [(e.leg, e.kind) for e in r.events] == [(1, "touch_down"), (2, "lift_off")]
    return r.events


@pytest.mark.parametrize("name,rtol", [("rodas4", 1e-10), ("dopri5", 1e-10)])
@pytest.mark.parametrize("event_tol", [1e-4, 1e-6, 1e-9])
def test_events_located_to_event_tol(name, rtol, event_tol, early_events):
    """A located switch ends its step at most event_tol after the crossing (the step is cut at
    the right end of the bisection bracket, where the switch condition holds)."""
    r = simulate(t_end=0.4, method=name,
                 integrator=pdw.Integrator(rtol=rtol, atol=rtol * 1e-2, event_tol=event_tol),
                 record=pdw.Record(every=0))
    ev, ref = r.events, early_events
    assert [(e.leg, e.kind) for e in ev] == [(e.leg, e.kind) for e in ref]
    slack = 2e-9                                          # integration error at this rtol
    td, td_ref = ev[0], ref[0]
    assert -slack <= td.t - td_ref.t <= event_tol + slack
    assert -2.0 * event_tol - 1e-9 < td.y_D < 0.0           # just below ground, |v_y| < 2 m/s
    if event_tol <= 1e-6:                                    # later events: same accuracy
        assert abs(ev[1].t - ref[1].t) <= event_tol + slack + 1e-6 * (event_tol > 1e-7)


# ------------------------------------------------------------------ agreement on the gait

# method, options, bound on the event-time error on the typical gait [s] (measured error x ~3-5,
# docs/integrators.md). The explicit fixed-step methods switch flags at step boundaries and
# need steps below the friction stability limit (~2.5 us), so they are far less accurate.
GAIT_RUNS = [
    ("cdm", dict(dt=1e-5), 1e-2),          # measured 2.0e-3
    ("verlet", dict(dt=1e-6), 1.5e-3),     # measured 3.2e-4
    ("rk4", dict(dt=1e-6), 6e-5),          # measured 1.3e-5
    ("dopri5", dict(dt=1e-5, integrator=pdw.Integrator(rtol=1e-6, atol=1e-8)), 1e-6),  # 2.0e-7
    ("rodas4", dict(integrator=pdw.Integrator(rtol=1e-7, atol=1e-9)), 2.5e-6),        # 4.9e-7
]


@pytest.fixture(scope="module")
def gait_reference():
    return simulate(method="rodas4",
                    integrator=pdw.Integrator(rtol=1e-11, atol=1e-13, event_tol=1e-12),
                    record=pdw.Record(every=0))


@pytest.mark.parametrize("name,kw,bound", GAIT_RUNS)
def test_methods_agree_on_typical_gait(name, kw, bound, gait_reference):
    r = simulate(method=name, record=pdw.Record(every=0), **kw)
    assert r.walked
    ref = [(e.leg, e.kind) for e in gait_reference.events]
    assert [(e.leg, e.kind) for e in r.events] == ref and len(ref) == 12
    dt = np.abs(np.array([e.t for e in r.events]) - [e.t for e in gait_reference.events])
    assert dt.max() < bound, (name, dt.max())


# ------------------------------------------------------------------ bookkeeping

def test_adaptive_records_every_step_and_grows_buffer():
    r = simulate(method="rodas4", integrator=pdw.Integrator(rtol=1e-9, atol=1e-11),
                 record=pdw.Record(every=1))
    n = r.stats["steps"]
    assert n > 4096                                # beyond the first record buffer
    assert len(r.t) == n + 1 and r.t[0] == 0.0 and r.t[-1] == 3.5
    assert (np.diff(r.t) > 0).all()
    assert np.array_equal(r.x[-1], r.x_final)
    r3 = simulate(method="rodas4", integrator=pdw.Integrator(rtol=1e-9, atol=1e-11),
                  record=pdw.Record(every=3))
    assert len(r3.t) == n // 3 + 1 + (n % 3 != 0)
    assert np.array_equal(r3.t[:-1], r.t[:n + 1:3][:len(r3.t) - 1])
    assert r3.Fn.shape == (len(r3.t), 2)


@pytest.mark.parametrize("name", list(INTEGRATORS))
def test_resumption_after_full_event_buffer_is_exact(name):
    """A tiny event buffer forces many returns and resumptions: the result is bit-identical."""
    k, p, x0 = kernel_index("paper"), parameter_vector(None), np.array(X0_PAPER)
    dt = 1e-4 if name in ("cdm", "rodas4") else 2e-6
    t_end = 1.0 if name in ("cdm", "rodas4") else 0.4
    args = (k, METHODS.index(name), x0, p, 0, 1,
            dict(dt=dt, n_steps=int(round(t_end / dt)), record_every=50, record_events=1,
                 fall_hip_height=0.25, fall_depth=0.125, max_speed=1e3, rtol=1e-6, atol=1e-8,
                 event_tol=1e-9))
    a = _core.run(*args, event_capacity=4)
    b = _core.run(*args, event_capacity=256)
    assert len(a["events"]) >= 2
    assert np.array_equal(a["events"], b["events"])
    assert np.array_equal(a["x_final"], b["x_final"]) and np.array_equal(a["x"], b["x"])
    assert a["stats"]["steps"] == b["stats"]["steps"]


@pytest.mark.parametrize("name", list(INTEGRATORS))
def test_work_counters(name):
    r = simulate(t_end=0.05, method=name, dt=1e-5, record=pdw.Record(every=0))
    st = r.stats
    info = INTEGRATORS[name]
    assert st["rhs"] >= info.rhs_per_step * st["steps"]
    assert (st["jacobians"] > 0) == info.uses_jacobian
    if not info.adaptive:
        assert st["steps"] == 5000 and st["rejected"] == 0
