"""Numerical stability of the time loops: where the step size stops being safe, and why.

The explicit methods (cdm, verlet, rk4, dopri5) are stable only for steps below a limit set by
the stiffest forces of the model (docs/stability.md has the measured maps). This module holds

* the **linear stability of one step** of each method applied to the linearized model
  x' = J x (`step_matrix`, `linear_limit`): the largest h for which the one-step map does not
  grow faster than the exact solution;
* the **step-size check** of `pdw.simulate` (`step_limit`, `check_step`): the smallest linear
  limit at four representative states of the typical gait (`stance_states`: three in single
  stance, one at the landing) for the given parameters, *without* the friction law's slope
  (friction saturates, so its instability is a bounded chatter, not a divergence; see below),
  times a per-variant, per-method factor calibrated on the stability maps (`CALIBRATION`);
* the **criteria of the stability maps** (`typical_start`, `reference`, `judge`,
  `largest_step`, `chatter`), and the **energy balance** of a run (`energy_balance`).

Other contact laws (`pdw.Contact`): the default law's estimate at the run's parameters times a
per-law, per-method factor fitted on measured limits (`pdw.sim.stepsize_laws`).

Why this module is long: the step maps, the representative states and the check built on them
share their constants and caches; the presets' limits and the per-law factors are apart.
"""
from __future__ import annotations

import functools
import math
import types
import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from ..core import _core, _layout
from ..core.errors import InvalidInputError, StepSizeError, StepSizeWarning
from ..core.integrators import METHODS
from ..core.model import check_variant, jacobian, kernel_index, parameter_vector
from ..core.params import X0_PAPER, Params
from .stepsize_laws import LAW_CALIBRATION, LUGRE_SIGMA1, law_factor, law_message, law_of, law_params  # noqa: F401
from .stepsize_presets import PRESET_DT_MAX, preset_limits

NQ = _core.NQ
NX = _core.NX
FIXED_STEP = ("cdm", "verlet", "rk4")
ADAPTIVE = ("dopri5", "rodas4")
CHECK_MODES = ("warn", "error", "off")
#: The parameters whose force elements can set a step limit, and the forces in words.
FORCES = {
    "d_n": "the normal contact damping d_n delta^p delta' (Hunt-Crossley; explicit in every "
           "fixed-step method)",
    "k_n": "the normal contact stiffness k_n delta^m",
    "d_t": "the tangential damper d_t |xi|^p v (Eqs. 7, 11)",
    "k_t": "the tangential spring k_t |xi|^m (Eqs. 7, 11)",
    "d_hip": "the hip damper d_hip",
    "v_s": "the friction law's slope near v = 0 (|dmu/dv| ~ 0.75/v_s)",
}
_NO_FRICTION = tuple(f for f in _layout.FEATURES if f != "friction")

#: Calibration of `step_limit`, per variant and method: the largest step at which the typical
#: gait walks (measured, docs/stability.md) divided by the linear limit at the representative
#: states, at its smallest over the stability maps' cells (benchmarks/stability_maps.py prints
#: it), rounded down.
CALIBRATION = {"paper": {"cdm": 0.1, "verlet": 0.17, "rk4": 0.22},
               "consistent": {"cdm": 0.11, "verlet": 0.12, "rk4": 0.12}}
#: When a stuck stance foot needs at least FRICTION_LOAD of its static friction mu_s F_n to
#: hold the tangential spring-damper (paper variant, k_t >~ 600 at the paper's values), an
#: explicit method's friction chatter changes the gait: the walking edge falls to a few times
#: the chatter limit (k_t = 850 in docs/stability.md: 6-10 x). `step_limit` is then at most
#: CHATTER_CALIBRATION x `StepLimit.dt_chatter`.
FRICTION_LOAD = 0.8
CHATTER_CALIBRATION = 5.0


# --------------------------------------------------------------------------------------------
# linear stability of one step
# --------------------------------------------------------------------------------------------

@functools.lru_cache(maxsize=None)
def _rk(name):
    T = _core.rk_tableau(name)
    return np.array(T["A"]), np.array(T["b"])


@functools.lru_cache(maxsize=1)
def _blocks():
    """[E Z Z], [Z E Z], [Z Z E] (NQ x 3 NQ; E the identity, Z zeros), read-only: the block
    rows of the second-order step maps, built once (the step-size check builds ~60 maps)."""
    Z, E = np.zeros((NQ, NQ)), np.eye(NQ)
    out = (np.hstack([E, Z, Z]), np.hstack([Z, E, Z]), np.hstack([Z, Z, E]))
    for b in out:
        b.flags.writeable = False
    return out


def step_matrix(method: str, J, h: float) -> np.ndarray:
    """The one-step map of ``method`` with step ``h`` applied to the linear system x' = J x.

    J is (8, 8) in the layout `pdw.STATE` (x = [q, qd]); its lower blocks A = dqdd/dq and
    B = dqdd/dqd are what the second-order schemes see.

    * rk4, dopri5: the stability function R(hJ) of the tableau (8 x 8).
    * verlet: the map of [q_n, v_n, a_n] (12 x 12); a_n is carried between steps
      (a_{n+1} = A q_{n+1} + B (v_{n+1/2} + h/2 a_n), pdw_verlet.c).
    * cdm: the map of [U_n, U_{n-1}, U_{n-2}] (12 x 12): U_{n+1} = 2 U_n - U_{n-1} +
      h^2 (A U_n + B (U_n - U_{n-2}) / 2h) -- docs/model.md section 7, whose force evaluation uses
      Eq. 17's velocity (U_n - U_{n-2}) / 2h, lagging half a step behind. (The C q' term,
      implicit in the scheme, is small and treated like the rest.)
    """
    J = np.asarray(J, dtype=float)
    if method in ("rk4", "dopri5"):
        A, b = _rk(method)
        eye = np.eye(NX)
        K: list[np.ndarray] = []
        for i in range(len(b)):
            X = eye + h * sum(A[i, j] * K[j] for j in range(i)) if i else eye
            K.append(J @ X)
        return eye + h * sum(b[i] * K[i] for i in range(len(b)))
    Aq, Bv = J[NQ:, :NQ], J[NQ:, NQ:]
    B0, B1, B2 = _blocks()
    if method == "verlet":
        vh = B1 + 0.5 * h * B2
        q1 = B0 + h * vh
        a1 = Aq @ q1 + Bv @ (vh + 0.5 * h * B2)
        v1 = vh + 0.5 * h * a1
        return np.vstack([q1, v1, a1])
    if method == "cdm":
        Un, Um1, Um2 = B0, B1, B2
        U1 = 2 * Un - Um1 + h * h * (Aq @ Un) + 0.5 * h * (Bv @ (Un - Um2))
        return np.vstack([U1, Un, Um1])
    raise InvalidInputError("no explicit step map for method %r; allowed: cdm, verlet, rk4, dopri5"
                            % (method,))


def _cdm_maps(Js, hs):
    """`step_matrix`("cdm", J, h) of each J of Js (n, 8, 8) and h of hs (n,), bit for bit
    (tests/sim/test_stance_search.py), without its matrix products: with [U_n, U_n-1, U_n-2]
    the block rows [E Z Z], [Z E Z], [Z Z E], A U_n = [A Z Z] and B (U_n - U_n-2) = [B Z -B]
    exactly, so the first block row is [2E + h^2 A + h/2 B, -E, -h/2 B] summed in the same
    order. (n, 12, 12)."""
    n = len(Js)
    h2 = (hs * hs)[:, None, None]
    hb = (0.5 * hs)[:, None, None]
    Aq, Bv = Js[:, NQ:, :NQ], Js[:, NQ:, NQ:]
    M = np.zeros((n, 3 * NQ, 3 * NQ))
    M[:, :NQ, :NQ] = (2.0 * np.eye(NQ) + h2 * Aq) + hb * Bv
    M[:, :NQ, NQ:2 * NQ] = 0.0 - np.eye(NQ)    # 2 Z - E: +0 off the diagonal
    M[:, :NQ, 2 * NQ:] = 0.0 + hb * -Bv        # Z + h/2 B (-E): +0 where B is 0
    M[:, NQ:, :2 * NQ] = np.eye(2 * NQ)
    return M


def _growth(method, J, h):
    return float(np.max(np.abs(np.linalg.eigvals(step_matrix(method, J, h)))))


def linear_limit(method: str, J, h_lo: float = 1e-10, h_hi: float = 1.0, rel: float = 1e-3) -> float:
    """Largest step h in [h_lo, h_hi] below which ``method`` is stable on x' = J x (frozen J).

    Stable means: the spectral radius rho of the one-step map (`step_matrix`) grows no faster
    than the exact solution, ln rho <= 1.5 h max(0, max Re lambda(J)) + rel (the walker has
    physically unstable, slow modes -- it is an inverted pendulum -- which the exact solution
    grows too). Search: from h = 1/max|lambda(J)|, half-decade steps down until stable and up
    until unstable, then 12 bisections in log h (0.03 % resolution). Returns h_lo if unstable
    there, h_hi if stable everywhere up to it. rodas4 (L-stable) has no limit: inf.
    """
    return linear_limits(method, [J], h_lo, h_hi, rel)[0]


def linear_limits(method: str, Js, h_lo: float = 1e-10, h_hi: float = 1.0,
                  rel: float = 1e-3, enough=None) -> list:
    """`linear_limit` of each Jacobian of ``Js`` (each (8, 8)), bit for bit, with the searches
    run side by side: each round takes the eigenvalues of every pending step map in one
    stacked call (LAPACK's geev per matrix, as alone), a quarter of the calls for the
    check's four states (issue 23: the first call of a process).

    ``enough``: a predicate of a step; a search stops as soon as a step it has found stable,
    and that its limit therefore is at least, satisfies it, and gives that step (a lower bound
    of its limit, not the limit)."""
    if method == "rodas4":
        return [math.inf] * len(Js)
    Js = np.array(Js, dtype=float).reshape(-1, NX, NX)
    evs = np.linalg.eigvals(Js)                 # one stacked call, geev per matrix as alone
    searches = [_search(max(0.0, float(np.max(ev.real))), float(np.max(np.abs(ev))),
                        h_lo, h_hi, rel, enough) for ev in evs]
    out: list = [None] * len(Js)
    pending = {i: next(g) for i, g in enumerate(searches)}
    while pending:
        idx = list(pending)
        if method == "cdm":
            maps = _cdm_maps(Js[idx], np.array([pending[i] for i in idx]))
        else:
            maps = np.stack([step_matrix(method, Js[i], pending[i]) for i in idx])
        rhos = np.max(np.abs(np.linalg.eigvals(maps)), axis=1)
        for i, rho in zip(idx, rhos):
            try:
                pending[i] = searches[i].send(float(rho))
            except StopIteration as done:
                out[i] = done.value
                del pending[i]
    return out


class _Enough(Exception):
    """A cut-short search found a stable step that is enough (`linear_limits`' ``enough``)."""


def _search(lp: float, scale: float, h_lo: float, h_hi: float, rel: float, enough=None):
    """`linear_limit`'s search for one Jacobian (largest Re lambda lp, largest |lambda| scale),
    as a generator: it yields a step h, is sent the spectral radius of the step map there,
    and returns the limit -- or, with ``enough``, the first stable step a that satisfies it
    (every later step the search keeps, and the limit it returns, is >= a)."""
    def unstable(rho, h):
        return rho > 0 and not (math.log(rho) <= 1.5 * h * lp + rel)

    def stable(h):
        if enough is not None and enough(h):
            raise _Enough(h)
        return h

    try:
        return (yield from _bracket(unstable, stable, scale, h_lo, h_hi))
    except _Enough as e:
        return float(e.args[0])


def _bracket(unstable, stable, scale, h_lo, h_hi):
    """The search of `_search`: half-decade steps from 1/scale, then 12 bisections in log h;
    ``stable(a)`` is called on every step found stable."""
    h = min(max(1.0 / scale if scale > 0 else h_hi, h_lo), h_hi)
    step = math.sqrt(10.0)
    if unstable((yield h), h):
        b = h
        while True:
            if b <= h_lo:
                return float(h_lo)
            a = max(b / step, h_lo)
            if not unstable((yield a), a):
                stable(a)
                break
            b = a
    else:
        a = stable(h)
        while True:
            if a >= h_hi:
                return float(h_hi)
            b = min(a * step, h_hi)
            if unstable((yield b), b):
                break
            a = stable(b)
    for _ in range(12):
        m = math.sqrt(a * b)
        if unstable((yield m), m):
            b = m
        else:
            a = stable(m)
    return float(a)


def sensitivity(params: Params, method: str, variant: str = "paper", factor: float = 2.0) -> dict:
    """Which force sets the linear step limit of `step_limit` (friction excluded): for each
    parameter of `FORCES` (but v_s) that is nonzero, the exponent a of limit ~ parameter^a,
    from the limit with that parameter multiplied by ``factor``. A limit set by a damper's
    real eigenvalue -c/m goes as c^-1, one set by a lightly damped contact oscillation as
    k^-1/2; 0 means the element plays no part."""
    h0 = _linear(params, method, variant)[0]
    out = {}
    for name in ("k_n", "d_n", "k_t", "d_t", "d_hip"):
        v = getattr(params, name)
        if v == 0:
            out[name] = 0.0
            continue
        h1 = _linear(params.replace(**{name: v * factor}), method, variant)[0]
        out[name] = math.log(h1 / h0) / math.log(factor)
    return out


def limiting_force(sens: dict) -> str:
    """The parameter with the most negative exponent in a `sensitivity` dict."""
    return min(sens, key=lambda k: sens[k])


# --------------------------------------------------------------------------------------------
# representative states
# --------------------------------------------------------------------------------------------

_KIN0, _NKIN = _layout.WORK["kin"]
_CON0, _NCON = _layout.WORK["contact"]
_KI = {n: i for i, n in enumerate(_layout.KIN)}
_FN, _FT = _layout.CONTACT.index("F_n"), _layout.CONTACT.index("F_t")


def _contact(x, params: Params, flags, variant: str, anchors=(0.0, 0.0)):
    """`pdw.core.model.contact_forces` for the check's own inputs (valid by construction: a
    float state or (N, 8) states, default features and contact law; flags (2,) or (N, 2)):
    the same compiled evaluation, bit for bit, without the per-call argument checks, which
    cost ~20 us of the ~25 us of each of the check's ~30 calls (issue 23, the first call of
    a process). Returns y_D, v_x, s, F_n, F_t: (2,) for one state, (N, 2) for N."""
    X = np.array(x, dtype=float, ndmin=2)
    n = len(X)
    f = np.empty((n, 2), dtype=np.intc)
    f[:] = flags
    a = np.empty((n, 2))
    a[:] = anchors
    work = np.empty((n, _core.NWORK))
    _core.rhs_batch(kernel_index(variant, None), X, parameter_vector(params), f, a,
                    np.empty_like(X), work)
    kin = work[:, _KIN0:_KIN0 + _NKIN].reshape(n, 2, len(_layout.KIN))
    con = work[:, _CON0:_CON0 + _NCON].reshape(n, 2, len(_layout.CONTACT))
    out = dict(y_D=kin[:, :, _KI["y_D"]], v_x=kin[:, :, _KI["v_x"]], s=kin[:, :, _KI["s"]],
               F_n=con[:, :, _FN], F_t=con[:, :, _FT])
    if np.ndim(x) == 1:
        out = {k: v[0] for k, v in out.items()}
    return types.SimpleNamespace(**out)


def _set_hip_height(x, params, variant, flags=(0, 1), force=None):
    """x with y_o such that the support feet carry ``force`` (default: the weight,
    (m_h + 2 m_l) g cos(gamma)) in total; the normal force grows with the depth. Three batched
    grids (geometric in the lowest foot's depth, 1e-9 m to l/4), then linear interpolation:
    relative accuracy ~1e-6 in the depth."""
    return _side_by_side([_hip_height(x, params, flags, force)], [flags], params, variant)[0]


def _side_by_side(searches, flags, params, variant):
    """Run generator searches in lockstep: each yields states (m, 8) to evaluate under its
    support flags and is sent their contact state (`_contact`: y_D, v_x, F_n, ... (m, 2));
    one compiled call per round for all of them (rows are evaluated independently, so each
    search gets what it would alone, bit for bit). Returns their results."""
    out: list = [None] * len(searches)
    pending = {i: next(g) for i, g in enumerate(searches)}
    while pending:
        idx = list(pending)
        X = np.concatenate([pending[i] for i in idx])
        F = np.concatenate([np.tile(np.asarray(flags[i], dtype=np.intc), (len(pending[i]), 1))
                            for i in idx])
        c = _contact(X, params, F, variant)
        o = 0
        for i in idx:
            m = len(pending[i])
            part = types.SimpleNamespace(**{k: v[o:o + m] for k, v in vars(c).items()})
            o += m
            try:
                pending[i] = searches[i].send(part)
            except StopIteration as done:
                out[i] = done.value
                del pending[i]
    return out


def _hip_height(x, params, flags, force=None):
    """`_set_hip_height` as a search of `_side_by_side`."""
    x = np.array(x, dtype=float)
    W = params.weight if force is None else float(force)
    y0 = x[1] - float(np.min((yield x[None, :]).y_D[0][np.array(flags) > 0]))

    def grid(depths):
        X = np.repeat(x[None, :], len(depths), axis=0)
        X[:, 1] = y0 - depths
        return X

    d = _depths(params.l)
    for _ in range(3):
        e = (yield grid(d)).F_n.sum(axis=1) - W
        k = int(np.argmax(e > 0))
        if e[k] <= 0:                       # not even l/4 deep carries the weight
            x[1] = y0 - d[-1]
            return x
        if k == 0:
            x[1] = y0 - d[0]
            return x
        lo, hi = d[k - 1], d[k]
        d = np.linspace(lo, hi, 97)
    e = (yield grid(d)).F_n.sum(axis=1) - W
    k = int(np.argmax(e > 0))
    a, b, ea, eb = d[k - 1], d[k], e[k - 1], e[k]
    x[1] = y0 - (a - ea * (b - a) / (eb - ea))
    return x


def _stance_state(x0, params, flags, foot, force):
    """One state of `_stance_states` as a search of `_side_by_side`: the Python reference of
    `_core.stance_search`, which `_stance_states` calls (tests/sim/test_stance_search.py)."""
    x = np.array(x0, dtype=float)
    x[4] -= float((yield x[None, :]).v_x[0][foot])
    if foot == 1:       # single stance: the stance foot neither sinks nor rises
        x[5] = -(params.l - params.r) * math.sin(x[3]) * x[7]
    return (yield from _hip_height(x, params, flags, force))


def typical_start(params: Params | None = None, variant: str = "paper") -> np.ndarray:
    """The typical gait's initial state (`pdw.X0_PAPER`, stance leg 2, flags (0, 1)) with the
    hip height y_o set so that the stance foot carries the walker's weight under ``params``
    and ``variant`` (for the paper's values y_o changes by 0.1 mm). On softer or stiffer
    ground the paper's y_o would start the walker sunk or floating; this keeps the gait's
    start comparable across the maps."""
    params = Params.paper() if params is None else params
    return _set_hip_height(X0_PAPER, params, variant)


#: Early, mid and late single stance of the typical gait (`pdw.X0_PAPER` and the rodas4 run
#: from it with `Params.paper_steady()` at t = 0.15 s and 0.30 s; leg 2 in stance, flags (0, 1)).
STANCE_STATES = (
    (0.0, 0.4969, -0.0582, 0.0582, 0.5092, 0.0186, 3.3338, -1.0093),
    (0.0788, 0.4961, 0.3947, -0.0996, 0.5690, -0.0314, 2.1244, -1.1414),
    (0.1777, 0.4847, 0.4661, -0.3000, 0.7759, -0.1382, -1.3415, -1.5946),
)
#: The landing 8 ms after the first touch-down of that run (t = 0.350 s): foot 1 is 3.0 mm deep
#: and still sinking at 0.65 m/s, the feet carry 3.7 weights. In `stance_states` it is taken
#: with foot 1 alone in support (flags (1, 0)): the trailing foot lifts off within a few ms,
#: too soon for its tangential damper's fast mode to grow (the maps show no effect of d_t there).
DOUBLE_SUPPORT_STATE = (0.21897, 0.4765, 0.37161, -0.38544, 0.85002, -0.099734, -1.7726, -1.7783)
DOUBLE_SUPPORT_LOAD = 3.7
LANDING_FLAGS = (1, 0)


def stance_states(params: Params | None = None, variant: str = "paper") -> tuple:
    """The representative states of `step_limit` (`_stance_states`; computed once per
    ``params`` and ``variant``): ``(X, flags)``, X (4, 8) a fresh copy."""
    params = Params.paper() if params is None else params
    X, flags = _stance_states(params, variant)
    return X.copy(), list(flags)


@functools.lru_cache(maxsize=256)
def _stance_states(params: Params, variant: str) -> tuple:
    """The representative states of `step_limit`: ``(X, flags)``, X of shape (4, 8): the three
    `STANCE_STATES` (flags (0, 1)) and the landing, `DOUBLE_SUPPORT_STATE` with flags
    `LANDING_FLAGS`; each with the support foot stuck (x_o' set so that its slip velocity is 0
    -- at `pdw.X0_PAPER` it still slides at 5 mm/s), in single stance not sinking either (y_o'
    set so that the consistent normal rate y_o' + (l - r) sin(theta2) theta2' is 0; the paper
    variant's printed rate keeps its r theta2'), and y_o set so that it carries the weight
    (the landing: `DOUBLE_SUPPORT_LOAD` times it) under ``params`` and ``variant``. Late in
    stance the paper variant's tangential spring-damper acts (xi_2 < 0), early on it does not;
    the landing holds the impact (d_n delta^p delta' at its largest)."""
    params = Params.paper() if params is None else params
    cases = [(x, (0, 1), 1, 1.0) for x in STANCE_STATES] + \
        [(DOUBLE_SUPPORT_STATE, LANDING_FLAGS, 0, DOUBLE_SUPPORT_LOAD)]
    flags = [fl for _, fl, _, _ in cases]
    X = np.array([x for x, _, _, _ in cases], dtype=float)
    # `_stance_state` of each case in one compiled call, bit for bit (tests/sim/
    # test_stance_search.py): a fifth of the check's first call in a fresh process (issue 23)
    _core.stance_search(kernel_index(variant, None), X, parameter_vector(params),
                        np.array(flags, dtype=np.intc),
                        np.array([foot for _, _, foot, _ in cases], dtype=np.intc),
                        np.array([load * params.weight for _, _, _, load in cases]),
                        _depths(params.l), params.l - params.r, _KI["y_D"], _KI["v_x"], _FN,
                        len(_layout.KIN), len(_layout.CONTACT))
    X.flags.writeable = False
    return X, tuple(flags)


@functools.lru_cache(maxsize=64)
def _depths(l: float) -> np.ndarray:
    """The first grid of `_hip_height`: 97 depths, geometric from 1e-9 m to l/4: numpy.geomspace's
    arithmetic (log10, linspace, power, the end points set), bit for bit (tests/sim/
    test_stance_search.py), in a fifth of its numpy calls (its first call in a process costs
    0.15 ms, half the compiled search)."""
    lo, hi = 1e-9, 0.25 * l
    ls, le = np.log10(np.array([lo, hi]))
    y = np.arange(97, dtype=float)
    y *= (le - ls) / 96
    y += ls
    y[-1] = le
    d = np.power(10.0, y)
    d[0], d[-1] = lo, hi
    d.flags.writeable = False
    return d


# --------------------------------------------------------------------------------------------
# the step-size check of simulate
# --------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class StepLimit:
    """The estimated largest safe fixed step of ``method`` for given parameters.

    dt_max : float
        Steps above this are expected to make the typical gait fall or diverge spuriously
        (inf for rodas4; for dopri5, its explicit stability bound, set by friction: the
        adaptive controller keeps it below that by itself).
    force : str
        The parameter of the force element that sets it (a key of `FORCES`): the one with the
        most negative exponent in ``sensitivity``.
    dt_linear : float
        The smallest linear limit at the representative states (before calibration).
    calibration : float
        dt_max / dt_linear (measured on the maps, `CALIBRATION`).
    dt_chatter : float
        Linear limit including the friction law's slope, in single stance: above it the stuck
        foot slides spuriously or chatters (bounded; not warned about).
    eigenvalue : complex
        The stiffest eigenvalue of df/dx (friction excluded) at that state [1/s].
    sensitivity : dict
        Exponent a of dt_linear ~ parameter^a for k_n, d_n, k_t, d_t, d_hip (`sensitivity`).
    friction_load : float
        The largest share of the static friction mu_s F_n that a stuck stance foot needs to hold
        the tangential spring-damper at the stance states; from `FRICTION_LOAD` on, dt_max is
        capped by the chatter limit and ``force`` is "v_s".
    law, law_factor : str, float
        The contact law (`pdw.sim.stepsize_laws`) and its factor on the default law's estimate.
    """

    method: str
    variant: str
    dt_max: float
    force: str
    dt_linear: float
    calibration: float
    dt_chatter: float
    eigenvalue: complex
    sensitivity: dict = field(default_factory=dict, compare=False)
    friction_load: float = 0.0
    law: str = "hunt_crossley"
    law_factor: float = 1.0

    @property
    def why(self) -> str:
        return FORCES.get(self.force, self.force)

    def message(self, dt: float) -> str:
        if self.law != "hunt_crossley":
            return law_message(self, dt)
        if self.force == "v_s" and self.method in FIXED_STEP:
            return ("dt = %.3g s exceeds the estimated limit %.2g s of method %r for these "
                    "parameters (variant %r): the stuck stance foot needs %.0f %% of its static "
                    "friction to hold the tangential spring, so the friction chatter of an "
                    "explicit method (above ~%.2g s, %s) changes the gait; limit = %.0f x that "
                    "(docs/stability.md). Use dt <= %.2g, or method='rodas4' (L-stable, no step "
                    "limit); check_step='off' disables this check."
                    % (dt, self.dt_max, self.method, self.variant, 100 * self.friction_load,
                       self.dt_chatter, FORCES["v_s"], CHATTER_CALIBRATION, self.dt_max))
        return ("dt = %.3g s exceeds the estimated stability limit %.2g s of method %r for these "
                "parameters (variant %r): the limit is set by %s (limit ~ %s^%.2g; stiffest "
                "non-friction eigenvalue %.3g /s in stance; linear limit %.2g s x calibration "
                "%.2g, docs/stability.md). Above it the typical gait falls or diverges "
                "spuriously. Use dt <= %.2g, or method='rodas4' (L-stable, no step limit); "
                "check_step='off' disables this check."
                % (dt, self.dt_max, self.method, self.variant, self.why, self.force,
                   self.sensitivity.get(self.force, float("nan")), abs(self.eigenvalue),
                   self.dt_linear, self.calibration, self.dt_max))


def _stiffest(J):
    ev = np.linalg.eigvals(J)
    return complex(ev[np.argmax(np.abs(ev))])


def state_jacobian(x, params: Params, flags, variant: str = "paper", features=_NO_FRICTION):
    """df/dx at a representative state, its support feet anchored where they are (the
    consistent variant's xi = 0: a foot that has not slipped since touch-down)."""
    s = _contact(x, params, flags, variant).s
    anchors = tuple(float(s[i]) if flags[i] else 0.0 for i in range(2))
    return jacobian(x, params, flags=flags, anchors=anchors, variant=variant, features=features)


def _state_jacobians(X, params: Params, flags, variant: str, features=_NO_FRICTION) -> list:
    """[`state_jacobian` of each state of X (n, 8) with its flags], bit for bit, in two
    compiled calls (rows are evaluated independently) without the per-call argument checks."""
    X = np.array(X, dtype=float, ndmin=2)
    F = np.array(flags, dtype=np.intc).reshape(len(X), 2)
    anchors = np.where(F > 0, _contact(X, params, F, variant).s, 0.0)
    J = np.empty((len(X), NX * NX))
    folded = params if features is None else params.without(features)
    _core.jacobian_batch(kernel_index(variant, features), X, parameter_vector(folded), F,
                         anchors, J, np.empty((len(X), _core.NWORK)))
    return list(J.reshape(len(X), NX, NX))


def _limits(params: Params, method: str, variant: str, features=_NO_FRICTION):
    """Linear limits of ``method`` at each of `stance_states`."""
    X, flags = stance_states(params, variant)
    return linear_limits(method, _state_jacobians(X, params, flags, variant, features))


@functools.lru_cache(maxsize=1024)
def _linear(params: Params, method: str, variant: str):
    """(linear limit without friction, index of the state that sets it) over `stance_states`."""
    hs = _limits(params, method, variant)
    k = int(np.argmin(hs))
    return hs[k], k


@functools.lru_cache(maxsize=1024)
def _friction_load(params: Params, variant: str) -> float:
    """Largest |F_t without friction| / (mu_s F_n) of the stuck foot at the single-stance states."""
    X, flags = _stance_states(params, variant)
    n = len(STANCE_STATES)
    F = np.array(flags[:n], dtype=np.intc)
    # two compiled calls for the n states (rows are evaluated independently: bit for bit
    # what one call per state gives)
    anchors = np.where(F > 0, _contact(X[:n], params, F, variant).s, 0.0)
    cs = _contact(X[:n], params.replace(mu_s=0.0, mu_d=0.0), F, variant, anchors)
    load = 0.0
    for j, fl in enumerate(flags[:n]):
        i = fl.index(1)
        need, cap = abs(float(cs.F_t[j, i])), params.mu_s * float(cs.F_n[j, i])
        load = max(load, need / cap if cap > 0 else (math.inf if need > 0 else 0.0))
    return load


@functools.lru_cache(maxsize=1024)
def _chatter_limit(params: Params, method: str, variant: str) -> float:
    return min(_limits(params, method, variant, features=None)[:len(STANCE_STATES)])


def _dt_max_computed(params, method, variant):
    dt = CALIBRATION[variant][method] * _linear(params, method, variant)[0]
    if _friction_load(params, variant) >= FRICTION_LOAD:
        dt = min(dt, CHATTER_CALIBRATION * _chatter_limit(params, method, variant))
    return dt


def _preset_table():
    """`PRESET_DT_MAX` computed anew (for a change of the model or of the calibration)."""
    return {(preset, variant): {m: _dt_max_computed(getattr(Params, preset)(), m, variant)
                                for m in FIXED_STEP}
            for preset, variant in PRESET_DT_MAX}


_BOUNDS: dict = {}


def _safe(params: Params, method: str, variant: str, dt: float, f: float) -> bool:
    """Is ``dt`` at most ``f`` x `_dt_max` (no warning), proven without the whole search? The
    searches of `_dt_max_computed` run cut short (`linear_limits`' ``enough``): each stops at
    the first stable step whose calibrated value already covers dt, a lower bound of its limit
    (a search's limit is never below a step it found stable, and rounding is monotone, so the
    answer is exactly `check_step`'s). The bound is kept per (params, method, variant); a dt
    it does not cover goes the whole way (`_dt_max`). The first call of a process with new
    parameters pays this instead of the whole search (issue 23)."""
    key = (params, method, variant)
    bound = _BOUNDS.get(key)
    if bound is None:
        c = CALIBRATION[variant][method]
        X, flags = stance_states(params, variant)
        hs = linear_limits(method, _state_jacobians(X, params, flags, variant),
                           enough=lambda h: not dt > f * (c * h))
        bound = c * min(hs)
        if _friction_load(params, variant) >= FRICTION_LOAD:
            n = len(STANCE_STATES)
            hc = linear_limits(method, _state_jacobians(X[:n], params, flags[:n], variant, None),
                               enough=lambda h: not dt > f * (CHATTER_CALIBRATION * h))
            bound = min(bound, CHATTER_CALIBRATION * min(hc))
        if len(_BOUNDS) >= 1024:
            _BOUNDS.clear()
        _BOUNDS[key] = bound
    return not dt > f * bound


def _dt_max(params, method, variant):
    known = preset_limits(params, variant)
    if known is not None and method in known:
        return known[method]
    return _dt_max_computed(params, method, variant)


@functools.lru_cache(maxsize=256)
def _step_limit(params: Params, method: str, variant: str) -> StepLimit:
    if method == "rodas4":
        return StepLimit(method, variant, math.inf, "none", math.inf, 1.0, math.inf, 0j)
    X, flags = stance_states(params, variant)
    dt_chatter = _chatter_limit(params, method, variant)
    Jf = [state_jacobian(x, params, fl, variant, None) for x, fl in zip(X, flags)]
    if method == "dopri5":
        # adaptive: the controller keeps the step below its explicit bound by itself
        return StepLimit(method, variant, dt_chatter, "v_s", dt_chatter, 1.0, dt_chatter,
                         max((_stiffest(J) for J in Jf[:len(STANCE_STATES)]), key=abs))
    h, k = _linear(params, method, variant)
    sens = sensitivity(params, method, variant)
    J = state_jacobian(X[k], params, flags[k], variant)
    c = CALIBRATION[variant][method]
    load = _friction_load(params, variant)
    dt_max = _dt_max(params, method, variant)
    force = "v_s" if dt_max < c * h else limiting_force(sens)
    return StepLimit(method, variant, dt_max, force, h, c, dt_chatter, _stiffest(J), sens, load)


def step_limit(params: Params | None = None, method: str = "cdm", variant: str = "paper",
               contact=None) -> StepLimit:
    """Estimate the largest fixed step ``method`` can take on the walker with ``params``.

    The smallest linear stability limit (`linear_limit`) of the method on df/dx without the
    friction slope at the representative states (`stance_states`), times the calibration
    factor `CALIBRATION[variant][method]` (the smallest ratio of the measured walking limit to
    this linear limit over the stability maps, docs/stability.md); capped at
    `CHATTER_CALIBRATION` x the chatter limit where the stuck foot needs `FRICTION_LOAD` of its
    static friction. For dopri5: its explicit bound with friction (the step its controller
    keeps below by itself); for rodas4: inf. Cached per
    (params, method, variant); about 10 ms of CPU the first time, warm (the force's exponents
    take five more linear limits).
    With another law (``contact``, `pdw.Contact`; ``params`` the run's, contact.parameters(params)),
    a fixed-step method's dt_max is multiplied by the law's factor (`pdw.sim.stepsize_laws`).
    """
    params = Params.paper() if params is None else params
    if not isinstance(params, Params):
        raise InvalidInputError("params must be a pdw.Params, got %s" % type(params).__name__)
    if method not in METHODS:
        raise InvalidInputError("method must be one of %s, got %r" % (", ".join(METHODS), method))
    try:
        check_variant(variant)
    except ValueError as e:
        raise InvalidInputError(str(e)) from None
    lim = _step_limit(law_params(params, contact), method, variant)
    law = law_of(contact)
    if law == "hunt_crossley" or method not in FIXED_STEP:
        return lim
    f = law_factor(law, method, contact, variant)
    return replace(lim, dt_max=f * lim.dt_max, law=law, law_factor=f)


def step_unknown(dt, method, mode, e):
    """`check_step` could not estimate the limit (a force law so stiff that the linearisation
    is not finite, e.g. v_s <= 1e-150): say so (warning or error), for `pdw.simulate`."""
    msg = ("the stability limit of %s at these parameters could not be estimated (%s): a force "
           "law is too stiff to linearise in double precision; dt = %g is probably far too large "
           "(use an adaptive method, or check_step='off')" % (method, e, dt))
    if mode == "error":
        raise StepSizeError(msg, dt=dt, limit=0.0, force="unknown") from None
    warnings.warn(StepSizeWarning(msg, dt=dt, limit=0.0, force="unknown"), stacklevel=3)


def check_step(dt: float, params: Params, method: str, variant: str, mode: str = "warn",
               contact=None):
    """The check `pdw.simulate` runs before a fixed-step run (``check_step`` argument).
    ``contact``: the run's `pdw.Contact` (None: the default law), as in `step_limit`.

    ``mode``: "warn" (a `pdw.StepSizeWarning` when dt > `step_limit`), "error" (raise
    `pdw.StepSizeError` instead), "off". Adaptive methods are not checked (their dt is only
    the first trial step). Returns the `StepLimit` when dt exceeds it, else None. Costs ~0.4 ms
    of CPU per new (params, method, variant) for a dt below the limit (cut short, `_safe`;
    ~1.4 ms above it, warm; ~0.7 ms more than the presets' first call in a fresh process),
    nothing after (cached), and nothing for the presets (`PRESET_DT_MAX`).
    """
    if mode not in CHECK_MODES:
        raise InvalidInputError("check_step must be one of %s, got %r"
                                % (", ".join(map(repr, CHECK_MODES)), mode))
    if mode == "off" or method not in FIXED_STEP:
        return None
    f = law_factor(law_of(contact), method, contact, variant)
    lp = law_params(params, contact)
    known = preset_limits(lp, variant)
    if (known is None or method not in known) and _safe(lp, method, variant, dt, f):
        return None
    if not dt > f * _dt_max(lp, method, variant):
        return None
    lim = step_limit(params, method, variant, contact)
    msg = lim.message(dt)
    if mode == "error":
        raise StepSizeError(msg, dt=dt, limit=lim.dt_max, force=lim.force)
    warnings.warn(StepSizeWarning(msg, dt=dt, limit=lim.dt_max, force=lim.force), stacklevel=3)
    return lim
