"""Chaos, measured: Lyapunov exponents, orbit diagrams, Feigenbaum ratios (docs/continuation.md).

* `lyapunov`: the largest Lyapunov exponent of the hybrid step map (per step), from the exact
  step Jacobian (`pdw.hybrid.step_jacobian`: variational equations with the saltation matrix of
  the heel strike) along an orbit, by the standard renormalised tangent vector:
  lambda = (1/N) sum_k log |DP_k v_k|, v_{k+1} = DP_k v_k / |DP_k v_k|. At a stable fixed
  point it equals log of the largest multiplier's modulus (a closed form the tests use).
* `orbit_diagram`: the section coordinate theta_st after each of the last steps of a walk, at
  many values of one parameter (the compiled walk loop, `pdw.hybrid`, on threads).
* `feigenbaum_ratios`: delta_k = (mu_k - mu_{k-1}) / (mu_{k+1} - mu_k) of located doublings.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from ...core import _hybrid, checks  # type: ignore[attr-defined]  # compiled, no stub
from ...core.errors import InvalidInputError
from ...core.interrupt import thread_map
from ...core.model import parameter_vector
from ...core.params import Params
from ..gait_types import GaitNotFoundError
from . import hybrid as H

_E = np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])


def lyapunov(params: Params, *, n_steps: int = 2000, n_transient: int = 200,
             start=None, options: dict | None = None) -> dict:
    """The largest Lyapunov exponent of the hybrid walker's step map [1/step].

    Parameters
    ----------
    params : Params
        The walker (hybrid model, `pdw.hybrid`).
    n_steps, n_transient : int
        Steps averaged over, after ``n_transient`` steps of transient.
    start : array_like (4,), optional
        Initial state (default: the period-1 gait of `pdw.hybrid.find_gait`, slightly
        perturbed so that an unstable gait is left).
    options : dict
        Step-map options (`pdw.hybrid.DEFAULT_OPTIONS`; default the tight ones).

    Returns
    -------
    dict
        ``exponent`` [1/step], ``per_second`` (divided by the mean step time [1/s]),
        ``running`` (the running estimate after each step, (n_steps,)), ``theta`` (theta_st
        after each averaged step), ``steps`` (steps walked).

    Raises
    ------
    pdw.InvalidInputError
        Bad counts or options, or the walker falls (the message says at which step and why).
    """
    n_steps = checks.count("n_steps", n_steps, lo=1, hi=10 ** 8)
    n_transient = checks.count("n_transient", n_transient, lo=0, hi=10 ** 8)
    opts = {**H._TIGHT, **H._options(options or {})}
    p = parameter_vector(params)
    if start is None:
        y = H.find_gait(params).state + np.array([1e-7, -1e-7, 0.0, 0.0])
    else:
        y = np.array(checks.real_array("start", start, [(4,)]), dtype=float)
    y = np.ascontiguousarray(y)
    v = np.ones(3) / np.sqrt(3.0)
    total, t_total = 0.0, 0.0
    running = np.empty(n_steps)
    theta = np.empty(n_steps)
    for k in range(n_transient + n_steps):
        if k < n_transient:
            res, _, _ = _hybrid.step(p, y, opts)
        else:
            res, DP = _hybrid.step_jac(p, y, opts)
        if res["status"] != "ok":
            raise InvalidInputError("lyapunov: the walker stops at step %d: %s"
                                    % (k, res["status"]))
        y = np.ascontiguousarray(res["y_plus"])
        if k < n_transient:
            continue
        w = (DP[list(H._SECTION)] @ _E) @ v
        nw = float(np.linalg.norm(w))
        total += np.log(nw)
        t_total += res["t_strike"]
        v = w / nw
        j = k - n_transient
        running[j] = total / (j + 1)
        theta[j] = y[0]
    lam = total / n_steps
    return {"exponent": lam, "per_second": total / t_total, "running": running,
            "theta": theta, "steps": n_transient + n_steps}


def orbit_diagram(params: Params, parameter: str, values: Sequence[float], *,
                  n_steps: int = 200, keep: int = 100, workers: int | None = None,
                  options: dict | None = None) -> dict:
    """The orbit (bifurcation) diagram of the hybrid walker over one parameter.

    The values are swept in order (in ``workers`` contiguous chunks, one per thread, in the
    compiled walk loop `pdw.hybrid`): the walk at each value starts from the last state of the
    previous value's walk (the first of a chunk, or after a fall, from the period-1 gait of
    ``params`` there, found from the last good state), walks ``n_steps`` steps and keeps theta_st after each of the last ``keep``
    (NaN where the walker fell).

    Returns
    -------
    dict
        ``values`` (M,), ``theta`` (M, keep) [rad], ``fell`` (M,) bool.
    """
    if parameter not in Params.__dataclass_fields__:
        raise InvalidInputError("parameter must be a Params field, got %r" % (parameter,))
    n_steps = checks.count("n_steps", n_steps, lo=1, hi=10 ** 7)
    keep = checks.count("keep", keep, lo=1, hi=n_steps)
    vals = np.array([checks.number("values[%d]" % i, v) for i, v in enumerate(values)])
    nw = checks.count("workers", workers if workers is not None else 1, lo=1, hi=4096)
    opts = {**H.DEFAULT_OPTIONS, **H._options(options or {})}
    y_ref = np.ascontiguousarray(H.find_gait(params).state + np.array([1e-6, -1e-6, 0, 0]))
    chunks = [c for c in np.array_split(np.arange(len(vals)), nw) if len(c)]

    def gait_start(P, guess):
        try:
            y = H.find_gait(P, guess=guess, settle_steps=0).state
        except GaitNotFoundError:
            y = guess
        return np.ascontiguousarray(y + np.array([1e-6, -1e-6, 0.0, 0.0]))

    def chunk(idx):
        y0, out_th, out_fell, good = None, [], [], y_ref
        for i in idx:
            P = params.replace(**{parameter: float(vals[i])})
            if y0 is None:
                y0 = gait_start(P, good)
            out, _, _, _ = _hybrid.walk(parameter_vector(P), y0, 0.0, n_steps, opts, 0)
            ok = [r["y_plus"] for r in out if r["status"] == "ok"]
            th = np.full(keep, np.nan)
            fell = len(ok) < n_steps
            if not fell:
                th[:] = [y[0] for y in ok[-keep:]]
                y0 = good = np.ascontiguousarray(ok[-1])
            else:
                y0 = None
            out_th.append(th)
            out_fell.append(fell)
        return out_th, out_fell

    res = thread_map(chunk, chunks, nw)
    return {"values": vals, "theta": np.array([t for r in res for t in r[0]]),
            "fell": np.array([f for r in res for f in r[1]])}


def feigenbaum_ratios(values: Sequence[float]) -> np.ndarray:
    """delta_k = (mu_k - mu_{k-1}) / (mu_{k+1} - mu_k) of successive doublings mu_0 < mu_1 <
    ... (at least 3); tends to Feigenbaum's 4.6692 for a cascade of a one-hump map."""
    v = np.asarray(values, dtype=float)
    if v.ndim != 1 or len(v) < 3:
        raise InvalidInputError("values: need at least 3 successive doublings, got %r"
                                % (values,))
    d = np.diff(v)
    return d[:-1] / d[1:]
