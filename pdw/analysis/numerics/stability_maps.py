"""The stability maps: where each explicit method stops walking, how friction chatters, and the
energy balance of a run (docs/stability.md; `benchmarks/stability_maps.py` draws the maps).

This is an analysis built on one simulation: it runs `pdw.simulate` many times and judges each
run against a tight rodas4 reference (`reference`, `judge`, `largest_step`), measures the
friction chatter of a stuck stance foot (`chatter`, `chatter_onset`) and checks the work-energy
balance of a recorded run (`energy_balance`). The runtime step-size check that every
`pdw.simulate` call runs is `pdw.sim.stepsize`, one layer below.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ...core.errors import InvalidInputError
from ...core.model import contact_forces, energies, rhs
from ...core.params import Params
from ...sim.options import Integrator, Limits, Record
from ...sim.simulation import simulate
from ...sim.stepsize import FIXED_STEP, _set_hip_height, step_limit, typical_start  # noqa: F401

# --------------------------------------------------------------------------------------------
# the criteria of the stability maps
# --------------------------------------------------------------------------------------------

#: Touch-down times must agree with the reference to max(TD_TOL_ABS, TD_TOL_REL x cycle).
TD_TOL_ABS = 2e-3
TD_TOL_REL = 0.01
#: A run may gain at most this much more mechanical energy [J] than the reference (about 7 %
#: of the walker's peak kinetic energy, 1.4 J): see `energy_gain`.
ENERGY_TOL = 0.1


def _sim(*, rtol=1e-6, atol=1e-8, h_max=None, method="cdm", dt=None, record_every=1,
         record_forces=True, **kw):
    """`simulate` with a divergence returned and no step-size check."""
    return simulate(integrator=Integrator(method=method, dt=dt, rtol=rtol, atol=atol, h_max=h_max,
                                          check_step="off"),
                    record=Record(every=record_every, forces=record_forces),
                    limits=Limits(on_failure="return"), **kw)


def reference(params: Params, variant: str = "paper", t_end: float = 3.5, rtol: float = 1e-9,
              h_max: float = 2e-3, x0=None):
    """The reference run of a map cell: rodas4 at ``rtol`` (atol = rtol/100), events to 1e-9 s,
    every step recorded (``h_max`` keeps the record dense), from `typical_start`."""
    x0 = typical_start(params, variant) if x0 is None else x0
    return _sim(x0=x0, t_end=t_end, params=params, variant=variant, method="rodas4", rtol=rtol,
                atol=rtol * 1e-2, h_max=h_max, record_every=1, record_forces=False)


def ground_energy(result) -> np.ndarray:
    """Elastic energy stored in the ground by the normal springs, sum of k_n delta^(m+1)/(m+1)
    over the support feet that penetrate, at each recorded sample [J]."""
    P = result.params
    if len(result.t) == 0:
        return np.zeros(0)
    y = contact_forces(result.x, P, flags=(1, 1), variant=result.variant).y_D
    d = np.clip(-y, 0.0, None) * (result.flags > 0)
    return (P.k_n * d ** 2.5 / 2.5).sum(axis=1)


def mechanical_energy(result) -> np.ndarray:
    """T + V_gravity + V_hip + `ground_energy` at each recorded sample [J]."""
    if len(result.t) == 0:
        return np.zeros(0)
    return energies(result.x, result.params)["E"] + ground_energy(result)


def energy_gain(result) -> float:
    """The largest rise of `mechanical_energy` above its running minimum [J].

    Gravity's work is inside E (V_gravity), so an exact solution gains energy only where the
    model's non-dissipative contact terms put it in: the paper variant's normal "damping" on
    the printed rate (which is not the penetration rate) and its tangential spring on the
    printed xi. The reference's gain (~0.09 J on the typical gait) is the allowance; a numerical
    instability pumps in far more (tens of J before the state runs away)."""
    E = mechanical_energy(result)
    if len(E) == 0:
        return 0.0
    return float(np.max(E - np.minimum.accumulate(E)))


@dataclass
class Verdict:
    """How a run compares with its reference (`judge`).

    walks : reached t_end, the same sequence of touch-downs (count and legs) as the
        reference, and no more energy gain than the reference's plus `ENERGY_TOL`.
    correct : walks, and every touch-down within ``tol`` of the reference's.
    """

    walks: bool
    correct: bool
    status: str
    t_final: float
    n_touch_downs: int
    td_error: float
    tol: float
    energy_gain: float
    reason: str


def touch_downs(result):
    return [(e.t, e.leg) for e in result.events if e.kind == "touch_down"]


def judge(result, ref, ref_gain: float | None = None) -> Verdict:
    """`Verdict` of ``result`` against the reference run ``ref`` (same parameters, start and
    t_end). "Walks correctly" in docs/stability.md is ``Verdict.correct``."""
    tr = touch_downs(ref)
    tm = touch_downs(result)
    cyc = np.diff([t for t, _ in tr])
    tol = max(TD_TOL_ABS, TD_TOL_REL * float(np.mean(cyc))) if len(cyc) else TD_TOL_ABS
    gain = energy_gain(result)
    g_ref = energy_gain(ref) if ref_gain is None else ref_gain
    n = min(len(tr), len(tm))
    err = float(np.max(np.abs(np.array([t for t, _ in tm[:n]]) - [t for t, _ in tr[:n]]))) if n else math.inf
    reason = ""
    if result.status != "walked":
        reason = "%s at t = %.4g s (%s)" % (result.status, result.failure["t"], result.failure["reason"])
    elif [leg for _, leg in tm] != [leg for _, leg in tr]:
        reason = "%d touch-downs (reference %d)" % (len(tm), len(tr))
    elif not gain <= g_ref + ENERGY_TOL:
        reason = "energy gain %.3g J (reference %.3g J)" % (gain, g_ref)
    walks = reason == ""
    if walks and not err <= tol:
        reason = "touch-down %.3g s off (tolerance %.3g s)" % (err, tol)
    return Verdict(walks, walks and err <= tol, result.status, result.t_final, len(tm), err, tol,
                   gain, reason)


def run_fixed(params: Params, method: str, dt: float, variant: str = "paper", t_end: float = 3.5,
              x0=None, sample: float = 2e-4):
    """A map run: ``method`` at step ``dt`` from `typical_start`, a sample every ~``sample`` s."""
    x0 = typical_start(params, variant) if x0 is None else x0
    return _sim(x0=x0, t_end=t_end, dt=dt, params=params, variant=variant, method=method,
                record_every=max(1, int(round(sample / dt))), record_forces=False)


def largest_step(params: Params, method: str, ref, variant: str = "paper", start: float = 1e-5,
                 lo: float = 1e-7, hi: float = 0.1, refine: int = 4, x0=None):
    """Largest steps at which ``method`` walks, and walks correctly (`judge`), on the typical gait.

    Half-decade scan from ``start`` upward until the run no longer walks (downward first if it
    does not walk at ``start``), then ``refine`` bisections in log(dt) between the last step
    that passed and the first that failed, separately for "walks" and "correct" (resolution
    10^(0.5/2^refine): 7.5 % for refine = 4). The result is the largest step *below which every
    tried step passed*: a failure followed by passes at larger steps (it happens near the edge of
    a marginal gait) does not move it up. Returns a dict: ``walk`` / ``correct`` =
    (largest passing dt, smallest failing dt) -- ``None`` for the first when even ``lo``
    fails, ``None`` for the second when even ``hi`` passes -- and ``runs``: [(dt, Verdict)].
    """
    x0 = typical_start(params, variant) if x0 is None else x0
    g_ref = energy_gain(ref)
    cache = {}

    def verdict(dt):
        if dt not in cache:
            r = run_fixed(params, method, dt, variant, ref.t_end, x0)
            cache[dt] = judge(r, ref, g_ref)
        return cache[dt]

    grid = [start * 10 ** (k / 2) for k in range(-20, 21)]
    grid = [d for d in grid if lo * (1 - 1e-9) <= d <= hi * (1 + 1e-9)]
    i0 = min(range(len(grid)), key=lambda i: abs(math.log(grid[i] / start)))

    def edge(key):
        ok = lambda d: getattr(verdict(d), key)
        i = i0
        if ok(grid[i]):
            while i + 1 < len(grid) and ok(grid[i + 1]):
                i += 1
            if i + 1 == len(grid):
                return grid[i], None
            a, b = grid[i], grid[i + 1]
        else:
            while i > 0 and not ok(grid[i - 1]):
                i -= 1
            if i == 0:
                return None, grid[0]
            a, b = grid[i - 1], grid[i]
        return _bisect_log(ok, a, b, refine)

    walk = edge("walks")
    correct = edge("correct")
    return {"walk": walk, "correct": correct, "runs": sorted(cache.items())}


# --------------------------------------------------------------------------------------------
# chatter
# --------------------------------------------------------------------------------------------

#: Window of the first single stance (leg 2 stuck in the reference) where chatter is measured.
CHATTER_WINDOW = (0.05, 0.10)


@functools.lru_cache(maxsize=64)
def _stuck_start(params: Params, variant: str, t0: float):
    """The rodas4 reference's state at t0 (leg 2 stuck in single stance), flags."""
    r = _sim(x0=typical_start(params, variant), t_end=t0, params=params, variant=variant,
             method="rodas4", rtol=1e-10, atol=1e-12, record_every=0)
    fl = tuple(int(f) for f in r.flags[-1]) if len(r.flags) else (0, 1)
    return r.x_final.copy(), fl


def slip(result, leg: int = 2, window=None):
    """Slip velocity v_x of ``leg``'s foot at the recorded samples (inside ``window``, if given)
    during which it is the only support leg."""
    i = leg - 1
    m = (result.flags[:, i] == 1) & (result.flags[:, 1 - i] == 0)
    if window is not None:
        m &= (result.t >= window[0]) & (result.t <= window[1])
    if not m.any():
        return np.zeros(0)
    return contact_forces(result.x[m], result.params, flags=(1, 1), variant=result.variant).v_x[:, i]


@dataclass
class Chatter:
    """Friction behaviour of a stuck stance foot in a run (`chatter`).

    slip_fraction: fraction of steps with |v_x| > v_s (the friction law on its sliding
        branch while the foot should stick);
    reversal_rate: fraction of consecutive steps in which v_x changes sign;
    slides: slip_fraction > 1/2 (the stuck foot slides spuriously);
    chatters: slides and reversal_rate >= 1/4 (the slip reverses at least every fourth step:
        the friction force flips between its saturated values -- cdm's pattern is ++--);
    v_rms: RMS slip velocity [m/s].
    """

    dt: float
    slip_fraction: float
    reversal_rate: float
    v_rms: float
    slides: bool
    chatters: bool


def chatter(params: Params, method: str, dt: float, variant: str = "paper",
            window=CHATTER_WINDOW) -> Chatter:
    """Classify the stance foot's friction (`Chatter`) in a run of ``method`` at step ``dt``
    through ``window`` of the typical gait's first single stance, started from the rodas4
    reference's state at the window's start (the foot stuck there, |v_x| ~ 0.03 v_s), every
    step recorded."""
    x0, fl = _stuck_start(params, variant, float(window[0]))
    span = float(window[1] - window[0])
    r = _sim(x0=x0, flags0=fl, t_end=span, dt=min(dt, span), params=params, variant=variant,
             method=method, record_every=1, record_forces=False)
    v = slip(r, 2)
    if len(v) < 3:
        return Chatter(dt, math.nan, math.nan, math.nan, False, False)
    frac = float(np.mean(np.abs(v) > params.v_s))
    s = np.sign(v)
    rev = float(np.mean(s[1:] != s[:-1]))
    slides = frac > 0.5
    return Chatter(dt, frac, rev, float(np.sqrt(np.mean(v * v))), slides, slides and rev >= 0.25)


def chatter_onset(params: Params, method: str, variant: str = "paper", key: str = "slides",
                  start: float | None = None, hi: float = 3e-3, refine: int = 4):
    """Smallest step at which the stuck foot slides (``key="slides"``) or chatters
    (``key="chatters"``): half-decade steps up from ``start`` (default: a third of
    `StepLimit.dt_chatter`) until it happens (down first if it already does), then ``refine``
    bisections in log(dt). Returns (largest dt without, smallest dt with); the first is None if
    it happens even at the smallest step tried (start / 1000), the second None if not up to
    ``hi``."""
    if start is None:
        start = step_limit(params, method if method != "rodas4" else "rk4", variant).dt_chatter / 3
    ok = lambda d: not getattr(chatter(params, method, d, variant), key)
    step = math.sqrt(10.0)
    if ok(start):
        a = start
        while True:
            b = a * step
            if b > hi:
                return a, None
            if not ok(b):
                break
            a = b
    else:
        b = start
        while True:
            a = b / step
            if a < start / 1000:
                return None, b
            if ok(a):
                break
            b = a
    return _bisect_log(ok, a, b, refine)


def edge_on_grid(ok, grid, refine: int = 4):
    """(largest step that passes, smallest that fails) of ``ok`` along an ascending ``grid``
    of steps [s], narrowed by ``refine`` bisections in log(dt): the grid is scanned up to its
    first failure b, a being the step before it. Every step passes: (grid[-1], None); the
    first fails: (None, grid[0]). The benchmarks' edge finder (contact laws, step limits)."""
    a = None
    for dt in grid:
        if not ok(dt):
            return (None, dt) if a is None else _bisect_log(ok, a, dt, refine)
        a = dt
    return a, None


def _bisect_log(ok, a, b, refine):
    """Narrow a bracket ok(a), not ok(b) by ``refine`` bisections in log(dt)."""
    for _ in range(refine):
        m = math.sqrt(a * b)
        if ok(m):
            a = m
        else:
            b = m
    return a, b


# --------------------------------------------------------------------------------------------
# energy balance
# --------------------------------------------------------------------------------------------

def _anchors(result):
    """Anchors s_i^0 at each sample (the consistent variant's xi): s of foot i at the sample
    where it last became support (at the first sample for an initial support leg)."""
    s = contact_forces(result.x, result.params, flags=(0, 0), variant=result.variant).s
    a = np.zeros_like(s)
    cur = np.where(result.flags[0] > 0, s[0], 0.0)
    prev = result.flags[0]
    for k in range(len(result.t)):
        new = (result.flags[k] > 0) & (prev == 0)
        cur = np.where(new, s[k], cur)
        a[k] = cur
        prev = result.flags[k]
    return a


def _groups(flags, anchors):
    """Rows of equal discrete state: [(flags, anchors, mask)]."""
    key = np.column_stack([flags, anchors])
    out = []
    for k in np.unique(key, axis=0):
        out.append(((int(k[0]), int(k[1])), (float(k[2]), float(k[3])), np.all(key == k, axis=1)))
    return out


def power(x, flags, anchors, params: Params, variant: str = "paper") -> np.ndarray:
    """Power [W] of the contact forces at the feet's material points (F_t v_x + F_n v_y, with
    the consistent normal rate v_y = y_o' + (l - r) sin(theta) theta') and of the hip damper
    (-d_hip (theta1' - theta2')^2), at states x (N, 8) with discrete states flags (N, 2) and
    anchors (N, 2)."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    flags = np.broadcast_to(np.asarray(flags), (len(x), 2))
    anchors = np.broadcast_to(np.asarray(anchors, dtype=float), (len(x), 2))
    P = np.zeros(len(x))
    l_r = params.l - params.r
    for fl, an, m in _groups(flags, anchors):
        xm = x[m]
        cs = contact_forces(xm, params, flags=fl, anchors=an, variant=variant)
        vy = xm[:, 5:6] + l_r * np.sin(xm[:, 2:4]) * xm[:, 6:8]
        P[m] = (cs.F_t * cs.v_x + cs.F_n * vy).sum(axis=1)
    return P - params.d_hip * (x[:, 6] - x[:, 7]) ** 2


def energy_balance(result, quadrature: str = "simpson") -> dict:
    """Work-energy balance of a densely recorded run (every step recorded).

    Over each recorded step [t_k, t_k+1] the discrete state is the one recorded at t_k; the
    work of the contact forces and the hip damper (`power`) is integrated with the trapezoid
    rule, or Simpson's rule with the midpoint state from the cubic Hermite interpolant of
    (x, f(x)) at both ends (``quadrature="simpson"``, the default). Q_f is the virtual work of
    exactly these forces, so d(T + V)/dt = power exactly and the residual
    E(t) - E(0) - W(t) measures the integration (and quadrature) error: work of gravity =
    -(change of V_gravity) = change of T + V_hip - W, dissipated energy = -W.

    Returns a dict of arrays: ``t``; ``E`` = T + V_gravity + V_hip; ``W`` (work of contact forces
    and hip damper since t = 0); ``W_gravity``; ``residual``; and per step (between consecutive
    touch-downs) ``step_residual``, ``step_gravity_work`` and ``step_relative`` (their ratio).
    """
    if quadrature not in ("simpson", "trapezoid"):
        raise InvalidInputError("quadrature must be 'simpson' or 'trapezoid', got %r" % (quadrature,))
    P_ = result.params
    t, x, fl = result.t, result.x, result.flags
    if len(t) < 2:
        raise InvalidInputError("energy_balance needs a recorded run (record_every=1)")
    an = _anchors(result) if result.variant == "consistent" else np.zeros((len(t), 2))
    en = energies(x, P_)
    E = np.asarray(en["E"])                   # (N,): x holds N states
    h = np.diff(t)
    p0 = power(x[:-1], fl[:-1], an[:-1], P_, result.variant)
    p1 = power(x[1:], fl[:-1], an[:-1], P_, result.variant)      # same discrete state
    if quadrature == "trapezoid":
        dW = 0.5 * h * (p0 + p1)
    else:
        f0 = np.empty_like(x[:-1])
        f1 = np.empty_like(x[:-1])
        for fl_k, an_k, m in _groups(fl[:-1], an[:-1]):
            kw = dict(params=P_, flags=fl_k, anchors=an_k, variant=result.variant)
            f0[m] = rhs(x[:-1][m], **kw)
            f1[m] = rhs(x[1:][m], **kw)
        xm = 0.5 * (x[:-1] + x[1:]) + (h[:, None] / 8.0) * (f0 - f1)
        pm = power(xm, fl[:-1], an[:-1], P_, result.variant)
        dW = h / 6.0 * (p0 + 4.0 * pm + p1)
    W = np.concatenate([[0.0], np.cumsum(dW)])
    res = E - E[0] - W
    Vg = np.asarray(en["V_gravity"])
    Wg = -(Vg - Vg[0])
    td = [e.t for e in result.events if e.kind == "touch_down"]
    idx = [min(int(np.searchsorted(t, tt)), len(t) - 1) for tt in td]
    step_res = np.array([res[b] - res[a] for a, b in zip(idx[:-1], idx[1:])])
    step_wg = np.array([Wg[b] - Wg[a] for a, b in zip(idx[:-1], idx[1:])])
    return {"t": t, "E": E, "W": W, "W_gravity": Wg, "residual": res,
            "step_residual": step_res, "step_gravity_work": step_wg,
            "step_relative": step_res / step_wg if len(step_wg) else step_res}
