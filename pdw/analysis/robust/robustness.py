"""Robustness measures of a gait on ground that is not uniform (issue 22, docs/robustness.md).

* `max_step`: the largest single step height (down or up, perpendicular to the mean slope; the
  ground stays at the new level) that the period-one gait survives and returns from;
* `gait_sensitivity`: the gait sensitivity norm of Hobbelen & Wisse (IEEE T-RO 23(6), 2007):
  the H2 norm of the linearized step map from a floor-height disturbance to gait indicators;
* `pdw.analysis.robust.first_passage`: the mean first-passage time on rough ground (Monte Carlo) and
  `pdw.analysis.robust.markov`: its Markov-chain estimate (Byl & Tedrake, IJRR 28(8), 2009).

The hybrid model (`pdw.hybrid`, docs/hybrid.md) meets a floor-height disturbance through the
step map's floor offset ``dh`` (the ground under the swing foot relative to the stance foot's
level): a step down of height H is ``dh = -H`` at one step and 0 after it, since the walker's
dynamics depend only on the relative levels. Its step map has an exact Jacobian
(`pdw.hybrid.step_jacobian`) and exact sensitivities to ``dh`` (``pdw.core._hybrid.step_sens``),
which `gait_sensitivity` uses.

The continuous (compliant) model needs a `pdw.Ground` with the step (terrain's branch) and is
run by `pdw.simulate_batch` (see ``_continuous``).
"""
from __future__ import annotations

import math

import numpy as np

from ...core import _hybrid, checks, interrupt  # type: ignore[attr-defined]  # compiled, no stub
from ...core.errors import InvalidInputError
from ...core.model import parameter_vector
from ...core.params import Params
from ..gait_types import Gait
from ..rigid import hybrid as _hy
from .robustness_core import GaitSensitivity, MaxStep, h2_norm, returned

__all__ = ["max_step", "gait_sensitivity", "disturbance_response", "step_lengths", "MaxStep",
           "GaitSensitivity", "h2_norm", "returned", "INDICATORS", "MODELS", "DIRECTIONS"]

#: Gait indicators of `gait_sensitivity` (per step): step_time [s] (touch-down to touch-down),
#: step_length [m] (footprint spacing), speed [m/s] (their ratio), and the post-impact state
#: theta_st [rad], thetad_st, thetad_sw [rad/s] (the hybrid model's section coordinates).
INDICATORS = ("step_time", "step_length", "speed", "theta_st", "thetad_st", "thetad_sw")
MODELS = ("hybrid", "continuous")
DIRECTIONS = ("down", "up")


# --- helpers ----------------------------------------------------------------------------------

def _params(params):
    if params is None:
        return Params.paper_steady()
    if not isinstance(params, Params):
        raise InvalidInputError("params must be a pdw.Params, got %s" % type(params).__name__)
    return params


def _hybrid_gait(params, gait, options):
    if gait is not None:
        if not isinstance(gait, Gait) or gait.model != "hybrid":
            raise InvalidInputError("gait must be a hybrid pdw.Gait (pdw.hybrid.find_gait), "
                                    "got %r" % (gait,))
        return gait
    return _hy.find_gait(params, **options)


def step_lengths(params, y0, Y) -> np.ndarray:
    """Footprint spacings [m] (K,) of hybrid steps from ``y0`` through the post-impact states
    ``Y`` (K, 4): step k ends at Y[k]; its pre-impact angles are Y[k, 1] (stance) and Y[k, 0]
    (swing), its start's stance angle Y[k-1, 0] (y0[0] for k = 0). docs/hybrid.md:
    L = (l - r)(sin theta_sw- - sin theta_st-) + r (theta_st0 - theta_st-)."""
    lr, r = params.l - params.r, params.r
    Y = np.asarray(Y, dtype=float).reshape(-1, 4)
    th0 = np.concatenate([[y0[0]], Y[:-1, 0]])
    st_m, sw_m = Y[:, 1], Y[:, 0]
    return lr * (np.sin(sw_m) - np.sin(st_m)) + r * (th0 - st_m)


def _walk_dh(params, y0, dh, options, threads=1, keep=False):
    """Rows of ``dh`` (N, K): one hybrid walker each from ``y0`` (4,) or (N, 4); returns
    (n_done (N,), status (N,) of str, y_last (N, 4), t_sum (N,), Y (N, K, 4) or None, T
    (N, K) or None), with per-step states and durations when ``keep``."""
    p = parameter_vector(params)
    dh = np.ascontiguousarray(np.atleast_2d(np.asarray(dh, dtype=float)))
    n, K = dh.shape
    Y0 = np.ascontiguousarray(np.broadcast_to(np.asarray(y0, dtype=float), (n, 4)))
    opts = _hy._options(options)
    n_done = np.zeros(n, dtype=np.int_)
    status = np.zeros(n, dtype=np.intc)
    y_last = np.empty((n, 4))
    t_sum = np.empty(n)
    Y = np.full((n, K, 4), np.nan) if keep else None
    T = np.full((n, K), np.nan) if keep else None

    def rows(ix):
        lo, hi = ix
        if keep:
            for i in range(lo, hi):      # one row at a time, keeping its states
                yy, tt = _walk_one(p, Y0[i], dh[i], opts)
                n_done[i], status[i] = len(tt), yy[1]
                Y[i, :len(tt)], T[i, :len(tt)] = yy[0], tt
                y_last[i] = yy[0][-1] if len(tt) else Y0[i]
                t_sum[i] = tt.sum()
        else:
            _hybrid.walk_dh_batch(p, Y0[lo:hi], dh[lo:hi], opts, n_done[lo:hi], status[lo:hi],
                                  y_last[lo:hi], t_sum[lo:hi])

    threads = max(1, min(int(threads), n))
    cuts = np.linspace(0, n, threads + 1).astype(int)
    interrupt.thread_map(rows, list(zip(cuts[:-1], cuts[1:])), threads)
    names = np.array([_hybrid.STATUS[s] for s in status])
    return n_done, names, y_last, t_sum, Y, T


def _walk_one(p, y0, dh, opts):
    """One walker, keeping every post-impact state: ((Y (k, 4), status), T (k,))."""
    K = len(dh)
    Y = np.empty((K, 4))
    T = np.empty(K)
    y = np.ascontiguousarray(y0, dtype=float)
    st = 0
    for k in range(K):
        res, _, _ = _hybrid.step(p, y, {**opts, "dh": float(dh[k])})
        if res["status"] == "ok" and res["old_foot_down"]:
            res["status"] = "fell"
        if res["status"] != "ok":
            st = _hybrid.STATUS.index(res["status"])
            return (Y[:k], st), T[:k]
        y = res["y_plus"]
        Y[k], T[k] = y, res["t_strike"]
    return (Y, st), T


# --- max_step ---------------------------------------------------------------------------------

def _hybrid_trials(params, gait, heights, direction, budget, return_tol, threads, options):
    sign = -1.0 if direction == "down" else 1.0
    H = np.asarray(heights, dtype=float)
    dh = np.zeros((len(H), budget + 1))
    dh[:, 0] = sign * H
    n_done, status, _, _, Y, T = _walk_dh(params, gait.state, dh, options, threads, keep=True)
    out = []
    for i, h in enumerate(H):
        surv = n_done[i] == budget + 1
        ret, k = False, -1
        if surv:
            L = step_lengths(params, gait.state, Y[i])
            ret, k = returned(L, T[i], gait.step_length, gait.period, return_tol)
        out.append(dict(height=float(h), survived=bool(surv), returned=bool(ret),
                        steps_to_return=int(k), status=str(status[i])))
    return out


def max_step(params=None, *, direction="down", model="hybrid", h_max=None, h_tol=1e-4,
             trials_per_round=8, max_rounds=20, budget=100, return_tol=1e-3, gait=None,
             threads=2, executor=None, ground=None, **options) -> MaxStep:
    """The largest single step height the period-one gait survives and returns from.

    The walker walks its gait; at one step the ground under the landing foot is ``height``
    lower (``direction="down"``) or higher (``"up"``) than under the stance foot, perpendicular
    to the mean slope, and stays at that level. A height *succeeds* when the walker then walks
    ``budget`` more steps without failing and *returns*: from some step on its step length and
    step time stay within ``return_tol`` (relative) of the gait's to the end, at least 5 steps
    (``returned``). The search is a multisection: each round tries ``trials_per_round`` heights
    evenly inside the bracket (one batch of walkers), the bracket becomes (the largest height
    with every smaller one tried a success, the first failure), until it is shorter than
    ``h_tol`` [m] or after ``max_rounds``.

    Parameters
    ----------
    params : Params
        Default `Params.paper_steady()`.
    direction : {"down", "up"}
    model : {"hybrid", "continuous"}
        ``"hybrid"``: the rigid-ground model (docs/hybrid.md), the step as the step map's floor
        offset at one step. ``"continuous"``: the compliant model on a `pdw.Ground` with the
        step (needs terrain's Ground; see docs/robustness.md).
    h_max : float, optional
        Upper end of the first bracket [m]; default 0.2 l. If it succeeds it is doubled (up
        to 4 times) until a height fails.
    h_tol : float
        Width of the final bracket [m].
    trials_per_round, max_rounds : int
    budget : int
        Steps walked after the step (>= 10).
    return_tol : float
        Relative tolerance of step length and step time for "returned".
    gait : Gait, optional
        The undisturbed gait (default: ``pdw.hybrid.find_gait(params)``).
    threads : int
        Threads sharing each round's walkers (hybrid).
    executor, ground
        Continuous model only (see ``_continuous``).
    options
        Hybrid step-map options (``pdw.hybrid.DEFAULT_OPTIONS``, without ``dh``).

    Returns
    -------
    MaxStep
    """
    params = _params(params)
    direction = checks.choice("direction", direction, DIRECTIONS)
    model = checks.choice("model", model, MODELS)
    h_tol = checks.number("h_tol", h_tol, lo=0.0, lo_open=True)
    n_round = checks.count("trials_per_round", trials_per_round, lo=1, hi=10 ** 4)
    max_rounds = checks.count("max_rounds", max_rounds, lo=1, hi=1000)
    budget = checks.count("budget", budget, lo=10, hi=10 ** 6)
    return_tol = checks.number("return_tol", return_tol, lo=0.0, hi=1.0, lo_open=True)
    threads = checks.count("threads", threads, lo=1, hi=1024)
    h_max = 0.2 * params.l if h_max is None else checks.number("h_max", h_max, lo=0.0,
                                                               lo_open=True)
    if "dh" in options:
        raise InvalidInputError("max_step sets the floor offset dh itself; do not pass it")
    if model == "hybrid" and (executor is not None or ground is not None):
        raise InvalidInputError("max_step(model='hybrid') takes neither executor nor ground "
                                "(its trials run on threads; the step is its floor offset): "
                                "got %s" % ", ".join(n for n, v in (("executor", executor),
                                                                    ("ground", ground))
                                                     if v is not None))
    if model == "continuous":
        from . import robustness_continuous as _rc
        run = _rc.step_trials_fn(params, direction=direction, budget=budget,
                                 return_tol=return_tol, gait=gait, executor=executor,
                                 ground=ground, threads=threads, **options)
        gait = run.gait
    else:
        gait = _hybrid_gait(params, gait, {k: v for k, v in options.items()
                                           if k not in ("dh",)})

        def run(heights):
            return _hybrid_trials(params, gait, heights, direction, budget, return_tol,
                                  threads, options)

    if max(abs(np.asarray(gait.multipliers))) >= 1.0:
        return MaxStep(height=0.0, bracket=(0.0, 0.0), steps_to_return=-1, direction=direction,
                       model=model, return_tol=return_tol, budget=budget, trials=[],
                       monotone=True, gait=gait, stable=False)
    trials = []
    ok = lambda t: t["survived"] and t["returned"]      # noqa: E731
    lo, hi = 0.0, h_max
    first = run([hi])
    for t in first:
        t["round"] = 0
    trials += first
    grow = 0
    while ok(trials[-1]) and grow < 4:
        lo, hi, grow = hi, 2 * hi, grow + 1
        t = run([hi])[0]
        t["round"] = 0
        trials.append(t)
    if ok(trials[-1]):
        return _result(trials, hi, math.inf, direction, model, return_tol, budget, gait)
    for rnd in range(1, max_rounds + 1):
        if hi - lo <= h_tol:
            break
        hs = lo + (hi - lo) * np.arange(1, n_round + 1) / (n_round + 1)
        res = run(hs)
        for t in res:
            t["round"] = rnd
        trials += res
        new_hi = hi
        for t in res:               # in increasing height
            if not ok(t):
                new_hi = t["height"]
                break
            lo = t["height"]
        hi = new_hi
    return _result(trials, lo, hi, direction, model, return_tol, budget, gait)


def _result(trials, lo, hi, direction, model, return_tol, budget, gait):
    at = [t for t in trials if t["height"] == lo]
    k = at[-1]["steps_to_return"] if at else 0
    fails = [t["height"] for t in trials if not (t["survived"] and t["returned"])]
    monotone = not any(t["survived"] and t["returned"] and fails and t["height"] > min(fails)
                       for t in trials)
    return MaxStep(height=float(lo), bracket=(float(lo), float(hi)), steps_to_return=int(k),
                   direction=direction, model=model, return_tol=return_tol, budget=budget,
                   trials=sorted(trials, key=lambda t: t["height"]), monotone=monotone,
                   gait=gait)


# --- gait sensitivity norm ----------------------------------------------------------------------

def _indicator_rows(params, names, res, DP, Ym, ydh, Tg, Tdh, B):
    """Rows C (m, 4) and D (m, 1) of the chosen indicators (hybrid, exact)."""
    lr, r = params.l - params.r, params.r
    st_m, sw_m = res["y_minus"][0], res["y_minus"][1]
    gx = np.array([-lr * math.cos(st_m) - r, lr * math.cos(sw_m), 0.0, 0.0])
    CL = gx @ Ym + np.array([r, 0.0, 0.0, 0.0])
    DL = gx @ ydh
    T0, L0 = res["t_strike"], res["step_length"]
    rows = {"step_time": (Tg, Tdh), "step_length": (CL, DL),
            "speed": ((CL - L0 / T0 * Tg) / T0, (DL - L0 / T0 * Tdh) / T0),
            "theta_st": (DP[0], B[0]), "thetad_st": (DP[2], B[2]), "thetad_sw": (DP[3], B[3])}
    C = np.array([rows[n][0] for n in names])
    D = np.array([[rows[n][1]] for n in names])
    return C, D


def _indicator_values(params, y0, res):
    L, T = res["step_length"], res["t_strike"]
    y = res["y_plus"]
    return {"step_time": T, "step_length": L, "speed": L / T, "theta_st": y[0],
            "thetad_st": y[2], "thetad_sw": y[3]}


def _fd_system(params, y0, names, h, opts):
    """A, B, C, D of the hybrid step map by central differences (step h in y0 and dh)."""
    p = parameter_vector(params)
    cols = []
    for j in range(5):
        out = []
        for s in (1.0, -1.0):
            y = np.array(y0, dtype=float)
            o = dict(opts)
            if j < 4:
                y[j] += s * h
            else:
                o["dh"] = s * h
            res, _, _ = _hybrid.step(p, np.ascontiguousarray(y), o)
            if res["status"] != "ok":
                raise InvalidInputError("gait_sensitivity: a finite-difference step failed (%s)"
                                        % res["status"])
            v = _indicator_values(params, y, res)
            out.append(np.concatenate([res["y_plus"], [v[n] for n in names]]))
        cols.append((out[0] - out[1]) / (2 * h))
    J = np.array(cols).T            # (4 + m, 5)
    return J[:4, :4], J[:4, 4:], J[4:, :4], J[4:, 4:]


def gait_sensitivity(params=None, *, indicators=("step_time",), model="hybrid", gait=None,
                     method="exact", fd_step=1e-6, check=True, **options) -> GaitSensitivity:
    """The gait sensitivity norm (Hobbelen & Wisse 2007) of the period-one gait.

    The disturbance e is a floor-height change [m] at one step (the ground under the landing
    foot is e higher, and stays so); the gait indicators g_i(k) are measured at that step
    (k = 0) and every later one. The norm is sqrt(sum_i sum_k (dg_i(k)/de)^2), from the
    linearized step map x(k+1) = A x(k) + B e(k), g(k) = C x(k) + D e(k) (``h2_norm``).

    Parameters
    ----------
    params : Params
        Default `Params.paper_steady()`.
    indicators : sequence of str
        From ``INDICATORS``; Hobbelen & Wisse's usual choice is step time alone.
    model : {"hybrid", "continuous"}
        ``"hybrid"``: A, B, C, D exact (variational equations of the stance, the saltation of
        the heel strike, the impact map's derivative: ``pdw.core._hybrid.step_sens``), checked
        against central differences. ``"continuous"``: the touch-down map's variational
        equations with the ground heights under the trailing and the landing foot as
        parameters (``pdw.analysis.stepmap.variational_ground``), in the section coordinates
        augmented by the previous step's floor change (docs/robustness.md, "The compliant
        model"); indicators step_time, step_length, speed.
    gait : Gait, optional
    method : {"exact", "fd"}
        ``"exact"`` (default): the linearization above; ``"fd"``: central differences of the
        step map of step ``fd_step`` (the continuous model's cross-checked at fd_step / 2).
    fd_step : float
        Step of the finite differences (state and floor height) [m, rad, m/s, rad/s].
    check : bool
        Compute the finite-difference cross-check of the exact linearization (``.check``: its
        norm and the relative difference; the continuous model warns above
        ``robustness_continuous.REL_CHECK`` = 1e-3).
    options
        Hybrid step-map options (default rtol = atol = 1e-12 here); continuous: options of
        ``pdw.analysis.stepmap.poincare.step`` (the differences' map; ``contact`` and
        ``variant`` also the exact one's: the paper variant, Coulomb friction).

    Returns
    -------
    GaitSensitivity
    """
    params = _params(params)
    model = checks.choice("model", model, MODELS)
    names = tuple(indicators) if not isinstance(indicators, str) else (indicators,)
    if not names:
        raise InvalidInputError("indicators must name at least one of %s" % (INDICATORS,))
    for n in names:
        checks.choice("indicators", n, INDICATORS)
    fd_step = checks.number("fd_step", fd_step, lo=0.0, lo_open=True)
    method = checks.choice("method", method, ("exact", "fd"))
    if model == "continuous":
        from . import robustness_continuous as _rc
        return _rc.gait_sensitivity(params, names, gait=gait, method=method, check=check,
                                    fd_step=fd_step, **options)
    opts = {**_hy._TIGHT, **_hy._options(options)}
    if opts.get("dh", 0.0) != 0.0:
        raise InvalidInputError("gait_sensitivity linearizes about dh = 0; do not pass dh")
    gait = _hybrid_gait(params, gait, {k: v for k, v in options.items()})
    p = parameter_vector(params)
    res, DP, Ym, ydh, Tg, Tdh = _hybrid.step_sens(p, np.ascontiguousarray(gait.state), opts)
    if res["status"] != "ok":
        raise InvalidInputError("gait_sensitivity: the gait's step failed (%s)" % res["status"])
    B = _hybrid.impact_jac(p, np.ascontiguousarray(res["y_minus"])) @ ydh
    C, D = _indicator_rows(params, names, res, DP, Ym, ydh, Tg, Tdh, B)
    A = DP
    if method == "fd":
        A, Bf, C, D = _fd_system(params, gait.state, names, fd_step, opts)
        B, check = Bf[:, 0], False
    if max(abs(np.asarray(gait.multipliers))) >= 1.0:        # unstable: infinite norm
        inf = {n: math.inf for n in names}
        return GaitSensitivity(norm=math.inf, per_indicator=inf, indicators=names, A=A,
                               B=B[:, None], C=C, D=D, method=method, gait=gait)
    norm = h2_norm(A, B[:, None], C, D)
    per = {n: h2_norm(A, B[:, None], C[i:i + 1], D[i:i + 1]) for i, n in enumerate(names)}
    chk = {}
    if check:
        Af, Bf, Cf, Df = _fd_system(params, gait.state, names, fd_step, opts)
        fd = h2_norm(Af, Bf, Cf, Df)
        chk = {"fd_norm": fd, "rel_diff": abs(fd - norm) / max(abs(norm), 1e-300),
               "fd_step": fd_step}
    return GaitSensitivity(norm=norm, per_indicator=per, indicators=names, A=A,
                           B=B[:, None], C=C, D=D, method=method, check=chk, gait=gait)


def disturbance_response(params=None, *, e=1e-5, n_steps=200, indicators=("step_time",),
                         gait=None, **options) -> np.ndarray:
    """The indicators' response (g_i(k) - g_i*) / e (n_steps, m) of the hybrid walker to a
    floor-height change e [m] at step 0, by direct simulation (the nonlinear map; the sum of
    its squares is the gait sensitivity norm squared as e -> 0)."""
    params = _params(params)
    names = tuple(indicators) if not isinstance(indicators, str) else (indicators,)
    opts = {**_hy._TIGHT, **_hy._options(options)}
    gait = _hybrid_gait(params, gait, options)
    p = parameter_vector(params)
    r0, _, _ = _hybrid.step(p, np.ascontiguousarray(gait.state), opts)
    ref = _indicator_values(params, gait.state, r0)
    y = np.ascontiguousarray(gait.state, dtype=float)
    out = np.empty((n_steps, len(names)))
    for k in range(n_steps):
        res, _, _ = _hybrid.step(p, y, {**opts, "dh": float(e) if k == 0 else 0.0})
        if res["status"] != "ok":
            raise InvalidInputError("disturbance_response: step %d failed (%s)"
                                    % (k, res["status"]))
        v = _indicator_values(params, y, res)
        out[k] = [(v[n] - ref[n]) / e for n in names]
        y = res["y_plus"]
    return out
