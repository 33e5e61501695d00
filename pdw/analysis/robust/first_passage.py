"""Mean first-passage time (MFPT) on rough ground by Monte Carlo (docs/robustness.md).

A walker on rough ground is *metastable* (Byl & Tedrake, "Metastable walking machines", IJRR
28(8), 2009): it walks many steps and then falls, and after a short transient its chance of
falling at a step is nearly constant, so the number of steps to the fall is close to
geometric. `first_passage` walks ``walkers`` walkers, each on its own random disturbance from
its own seed, for at most ``max_steps`` steps, and estimates the MFPT (the expected number of
steps up to and including the failing one) by ``mfpt_estimate``: the constant-hazard maximum-
likelihood estimate with censoring (walkers still walking at ``max_steps`` count their steps
as exposure, not as failures) and an exact Poisson (Garwood) confidence interval.

Walkers are cut into chunks of consecutive walkers, each chunk one task on ``executor`` (a
``concurrent.futures`` executor, Dask's ``client.get_executor()``; None: threads here), and
each walker's outcome depends only on its index and the seed, never on its chunk. With
``path`` the finished chunks are appended to a CSV file as they finish; a killed study run
again with the same ``path`` and arguments reads them back and runs only the walkers missing.
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field

import numpy as np

from ...core import _hybrid, checks, interrupt  # type: ignore[attr-defined]  # compiled, no stub
from ...core.errors import InvalidInputError
from . import robustness as _rb

_COLUMNS = ("walker", "steps", "failed", "status")
#: statuses a file of finished walkers may hold (the hybrid step's, pdw.simulate's)
_STATUSES = frozenset(_hybrid.STATUS) | {"walked", "periodic", "fell", "diverged", "off_ground",
                                         "no_steps", "interrupted"}


@dataclass
class FirstPassage:
    """Outcome of `first_passage` (or ``mfpt_estimate`` alone).

    Attributes
    ----------
    mfpt : float
        Mean first-passage time [steps] (inf when no walker failed).
    ci : (float, float)
        Its confidence interval at ``confidence`` [steps].
    confidence : float
    walkers, failures, censored : int
        Walkers run, those that failed, those still walking at ``max_steps``.
    exposure : int
        Steps walked by all walkers (the failing steps included).
    steps : ndarray of int (N,)
        Each walker's steps (up to and including its failing step; ``max_steps`` if censored).
    failed : ndarray of bool (N,)
    status : ndarray of str (N,)
        The failing step's status ("ok" when censored).
    max_steps : int
    km_mean : float
        Kaplan-Meier restricted mean of min(steps, max_steps) (no constant-hazard assumption;
        equals the MFPT when nobody is censored, a lower bound otherwise).
    meta : dict
        What was run (model, disturbance, seed, ...).
    """

    mfpt: float
    ci: tuple
    confidence: float
    walkers: int
    failures: int
    censored: int
    exposure: int
    steps: np.ndarray
    failed: np.ndarray
    status: np.ndarray
    max_steps: int
    km_mean: float
    meta: dict = field(default_factory=dict)

    @property
    def rel_halfwidth(self) -> float:
        """Half the confidence interval's width relative to the MFPT."""
        return 0.5 * (self.ci[1] - self.ci[0]) / self.mfpt if self.failures else math.inf

    def __repr__(self) -> str:
        return ("FirstPassage(mfpt=%.5g steps, ci=(%.5g, %.5g) at %g, %d walkers, %d failed, "
                "%d censored at %d)" % (self.mfpt, self.ci[0], self.ci[1], self.confidence,
                                        self.walkers, self.failures, self.censored,
                                        self.max_steps))


def mfpt_estimate(steps, failed, *, max_steps=None, confidence=0.95, status=None,
                  meta=None) -> FirstPassage:
    """The MFPT [steps] and its confidence interval from walkers' first-passage data.

    ``steps`` (N,): each walker's steps up to and including the failing one, or the steps it
    walked when censored (``failed`` False). With a constant chance p of failing per step the
    maximum-likelihood estimate under censoring is p = F / E (F failures, E = sum of steps, the
    exposure), so MFPT = E / F; the interval is the exact Poisson (Garwood) interval of F at
    exposure E: E / (chi2(1 - a/2; 2F + 2) / 2) ... E / (chi2(a/2; 2F) / 2), a = 1 -
    confidence (accurate for p << 1, the metastable regime).
    """
    from scipy.stats import chi2

    steps = np.asarray(steps, dtype=np.int64)
    failed = np.asarray(failed, dtype=bool)
    if steps.shape != failed.shape or steps.ndim != 1:
        raise InvalidInputError("steps and failed must be 1-D of one length, got %s and %s"
                                % (steps.shape, failed.shape))
    if len(steps) and steps.min() < 0:
        raise InvalidInputError("steps must be >= 0")
    confidence = checks.number("confidence", confidence, lo=0.0, hi=1.0, lo_open=True,
                               hi_open=True)
    F, E = int(failed.sum()), int(steps.sum())
    a = 1.0 - confidence
    if F == 0:
        mfpt = math.inf
        ci = (E / (chi2.ppf(1 - a / 2, 2) / 2) if E else 0.0, math.inf)
    else:
        mfpt = E / F
        ci = (E / (chi2.ppf(1 - a / 2, 2 * F + 2) / 2), E / (chi2.ppf(a / 2, 2 * F) / 2))
    K = int(steps.max()) if max_steps is None and len(steps) else int(max_steps or 0)
    return FirstPassage(mfpt=float(mfpt), ci=(float(ci[0]), float(ci[1])),
                        confidence=confidence, walkers=len(steps), failures=F,
                        censored=int(len(steps) - F), exposure=E, steps=steps, failed=failed,
                        status=(np.asarray(status) if status is not None
                                else np.where(failed, "fell", "ok")),
                        max_steps=K, km_mean=_km_mean(steps, failed), meta=dict(meta or {}))


def _km_mean(steps, failed) -> float:
    """Kaplan-Meier restricted mean of the first-passage time (up to the largest time seen)."""
    if len(steps) == 0:
        return math.nan
    S, mean, last = 1.0, 0.0, 0
    n_at_risk = len(steps)
    for t in np.unique(steps):
        mean += S * (t - last)
        last = t
        d = int(np.sum((steps == t) & failed))
        S *= 1.0 - d / n_at_risk
        n_at_risk -= int(np.sum(steps == t))
    return float(mean)


# --- the hybrid walker with random step heights --------------------------------------------

def dh_sequence(seed, walker, sigma, n) -> np.ndarray:
    """Walker ``walker``'s floor offsets (n,): i.i.d. N(0, sigma^2) [m] from the generator
    ``numpy.random.default_rng([seed, walker])`` (the same numbers on every machine)."""
    return np.random.default_rng([int(seed), int(walker)]).normal(0.0, sigma, n)


def _hybrid_chunk(params, y0, sigma, seed, lo, hi, max_steps, options):
    """Walkers lo..hi-1 of the hybrid model with random step heights: (steps, failed, status).
    Module level, plain data: process pools and Dask take it."""
    dh = np.stack([dh_sequence(seed, i, sigma, max_steps) for i in range(lo, hi)])
    n_done, status, _, _, _, _ = _rb._walk_dh(params, y0, dh, options, threads=1)
    failed = n_done < max_steps
    steps = np.where(failed, n_done + 1, max_steps)
    return steps.astype(np.int64), failed, np.where(failed, status, "ok")


def first_passage(params=None, *, sigma=None, ground=None, walkers=400, max_steps=1000,
                  model="hybrid", seed=0, chunk_size=None, executor=None, threads=2,
                  path=None, confidence=0.95, gait=None, progress=None,
                  **options) -> FirstPassage:
    """Mean first-passage time [steps] on rough ground by Monte Carlo, with a confidence interval.

    Parameters
    ----------
    params : Params
        Default `Params.paper_steady()`.
    sigma : float
        Hybrid model: the standard deviation [m] of i.i.d. Gaussian step heights (the ground
        under each landing foot relative to the stance foot's level, drawn anew every step;
        Byl & Tedrake's stochastic terrain). Walker i draws them from ``[seed, i]``
        (``dh_sequence``).
    ground : pdw.Ground, optional
        Continuous model: a ``Ground.random(sigma=..., ...)``; walker i walks its own ground,
        the same but of seed ``seed + i`` (``pdw.analysis.robust.robustness_continuous.chunk``).
    walkers, max_steps : int
        Walkers, and the steps after which a walker still walking is censored.
    model : {"hybrid", "continuous"}
    seed : int
    chunk_size : int, optional
        Walkers per task (default: walkers / (4 threads), at least 1).
    executor : concurrent.futures.Executor, optional
        Runs the chunks (``submit``); None: ``threads`` threads here.
    path : str or Path, optional
        A CSV file of finished walkers: appended as chunks finish; read back (and only the
        missing walkers run) when it exists. Its first line records what a walker's outcome
        depends on (not ``walkers``: a study extended by more walkers runs only the new ones);
        a file of another study is refused.
    confidence : float
        Of the interval (``mfpt_estimate``).
    gait : Gait, optional
        The start (default: the model's period-one gait).
    progress : pdw.Progress, optional
        Advanced by the walkers of each finished chunk.
    options
        Hybrid step-map options.

    Returns
    -------
    FirstPassage
    """
    params = _rb._params(params)
    model = checks.choice("model", model, _rb.MODELS)
    walkers = checks.count("walkers", walkers, lo=1, hi=10 ** 9)
    max_steps = checks.count("max_steps", max_steps, lo=1, hi=10 ** 8)
    seed = checks.count("seed", seed, lo=0, hi=2 ** 63 - 1)
    threads = checks.count("threads", threads, lo=1, hi=1024)
    if model == "continuous":
        from ...core.ground import Ground
        from . import robustness_continuous as _rc

        if sigma is not None:
            raise InvalidInputError("first_passage(model='continuous') takes ground = "
                                    "pdw.Ground.random(sigma=...), not sigma")
        if not isinstance(ground, Ground) or ground.kind != "random":
            raise InvalidInputError("first_passage(model='continuous') needs ground = "
                                    "pdw.Ground.random(sigma=..., ...), got %r" % (ground,))
        gait = _rc.continuous_gait(params, gait)
        chunk = _rc.chunk
        kw = dict(params=params, gait=gait, ground=ground, seed=seed, max_steps=max_steps,
                  options=dict(options))
        dist = dict(ground=ground.to_dict())
    else:
        if ground is not None:
            raise InvalidInputError("first_passage(model='hybrid') takes sigma (random step "
                                    "heights), not ground")
        if sigma is None:
            raise InvalidInputError("first_passage(model='hybrid') needs sigma [m] >= 0")
        sigma = checks.number("sigma", sigma, lo=0.0)
        gait = _rb._hybrid_gait(params, gait, options)
        chunk = _hybrid_chunk
        kw = dict(params=params, y0=np.array(gait.state), sigma=sigma, seed=seed,
                  max_steps=max_steps, options=dict(options))
        dist = dict(sigma=sigma)
    size = (max(1, -(-walkers // (4 * threads))) if chunk_size is None
            else checks.count("chunk_size", chunk_size, lo=1, hi=10 ** 9))
    meta = dict(model=model, **dist, seed=seed, max_steps=max_steps,
                params=params.as_dict(), options={k: float(v) for k, v in options.items()},
                gait=[float(v) for v in np.ravel(gait.state)])
    done = _read(path, meta) if path is not None else {}
    meta["walkers"] = walkers
    todo = [(lo, min(walkers, lo + size)) for lo in range(0, walkers, size)
            if not all(i in done for i in range(lo, min(walkers, lo + size)))]

    def finish(lohi, out):
        steps, failed, status = out
        rows = {lohi[0] + j: (int(steps[j]), bool(failed[j]), str(status[j]))
                for j in range(len(steps))}
        done.update(rows)
        if path is not None:
            _append(path, rows)
        if progress is not None:
            progress.update(len(steps))

    if executor is None:
        def task(lohi):
            out = chunk(lo=lohi[0], hi=lohi[1], **kw)
            return lohi, out
        for lohi, out in interrupt.thread_map(task, todo, threads):
            finish(lohi, out)
    else:
        futs = [(lohi, executor.submit(chunk, lo=lohi[0], hi=lohi[1], **kw))
                for lohi in todo]
        for lohi, f in futs:
            finish(lohi, f.result())
    rows = [done[i] for i in range(walkers)]
    return mfpt_estimate([r[0] for r in rows], [r[1] for r in rows], max_steps=max_steps,
                         confidence=confidence, status=[r[2] for r in rows],
                         meta={**meta, "resumed": len(rows) - sum(b - a for a, b in todo)})


# --- the file of finished walkers -----------------------------------------------------------

def _header(meta) -> str:
    return "# pdw first_passage " + json.dumps(meta, sort_keys=True)


def _read(path, meta) -> dict:
    """Rows {walker: (steps, failed, status)} of a file of finished walkers (empty if none)."""
    path = os.fspath(path)
    if not os.path.exists(path):
        with open(path, "w") as f:
            f.write(_header(meta) + "\n" + ",".join(_COLUMNS) + "\n")
        return {}
    with open(path) as f:
        lines = f.read().splitlines()
    if not lines or lines[0] != _header(meta):
        raise InvalidInputError("path %r holds another first-passage study (its first line "
                                "differs from %r); use a new file" % (path, _header(meta)[:80]))
    if len(lines) < 2 or lines[1] != ",".join(_COLUMNS):
        raise InvalidInputError("path %r: line 2 must be the header %r"
                                % (path, ",".join(_COLUMNS)))
    out = {}
    for n, line in enumerate(lines[2:], start=3):
        parts = line.split(",")
        if len(parts) != len(_COLUMNS) or parts[3] not in _STATUSES:
            continue            # a line cut by a kill: that walker runs again
        try:
            out[int(parts[0])] = (int(parts[1]), parts[2] == "1", parts[3])
        except ValueError:
            raise InvalidInputError("path %r line %d: %r is not walker,steps,failed,status"
                                    % (path, n, line)) from None
    return out


def _append(path, rows) -> None:
    text = "".join("%d,%d,%d,%s\n" % (i, s, int(f), st) for i, (s, f, st) in sorted(rows.items()))
    with open(os.fspath(path), "a") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())

