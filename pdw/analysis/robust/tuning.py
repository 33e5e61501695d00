"""Parameters tuned for the mean first-passage time with common random numbers (issue 22 item 6;
docs/robustness.md, "Tuning for the MFPT").

A Monte Carlo MFPT drawn from fresh grounds at every evaluation is a noisy objective, on which
a deterministic optimizer chases the noise. With **common random numbers** every evaluation walks
the same walkers on the same grounds (the same seeds: walker i's step heights from ``[seed, i]``
on the hybrid model, its random ground of seed ``seed + i`` on the compliant one), so the
estimate is a deterministic function of the parameters, and `scipy.optimize` works on it as on
any deterministic function: `MfptObjective` is that function, `tune_first_passage` runs
``scipy.optimize.minimize_scalar`` (one parameter, bounded) or ``scipy.optimize.minimize``
(Nelder-Mead with bounds) on it and re-evaluates the optimum on a held-out seed set, since an
optimum found on one set of walkers overfits them.

The gait at each point is the period-one gait continued from the base parameters' (`gait_at`):
through a fixed lattice of anchor points, so the gait, and with it the objective, does not
depend on the order in which the optimizer visits the points.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...core import checks
from ...core.errors import InvalidInputError, PdwError
from ..rigid import hybrid as _hy
from ..stepmap import limit_cycle as _lc
from . import first_passage as _fp
from . import robustness as _rb

__all__ = ["MfptObjective", "TunedMfpt", "tune_first_passage", "STATISTICS"]

#: what the objective maximizes: ``mfpt`` the censored maximum-likelihood MFPT E/F [steps]
#: (`first_passage`'s estimate); ``geometric_mean`` exp(mean log min(T_i, K)) [steps], the
#: walkers' first-passage times T_i censored at K = max_steps; ``censored_mean`` the mean of
#: min(T_i, K) [steps]. For a geometric T each is an increasing function of the MFPT.
STATISTICS = ("mfpt", "geometric_mean", "censored_mean")


def statistic(fp, name) -> float:
    """The statistic ``name`` (`STATISTICS`) of a `FirstPassage` [steps]."""
    if name == "mfpt":
        return float(fp.mfpt)
    t = np.minimum(np.asarray(fp.steps, dtype=float), fp.max_steps)
    if name == "geometric_mean":
        return float(np.exp(np.mean(np.log(np.maximum(t, 1.0)))))
    return float(t.mean())


class MfptObjective:
    """The first-passage statistic as a deterministic function of some parameters (common
    random numbers): ``f(x)`` is minus the statistic at ``params.replace(names = x)``, for
    `scipy.optimize`.

    Parameters
    ----------
    params : Params
        The base parameters (and the base of the gait continuation).
    names : sequence of str
        The Params fields that x sets (x has their length).
    model : {"hybrid", "continuous"}
    sigma : float, optional
        Hybrid model: the step heights' standard deviation [m] (`first_passage`).
    ground : pdw.Ground, optional
        Continuous model: a ``Ground.random(...)``; walker i on its seed ``seed + i``.
    walkers, max_steps, seed : int
        The walkers (the same at every evaluation), their censoring, the seed of the set.
    statistic : str
        One of `STATISTICS`.
    gait_step : float
        The anchor lattice's spacing, relative to each parameter's base value (absolute for a
        base value of 0): the gait continuation's largest step.
    threads : int
    options
        The model's step-map or walk options (`first_passage`).

    Attributes
    ----------
    evaluations : list of (tuple, float)
        Every distinct point evaluated and its statistic [steps], in order.
    """

    def __init__(self, params=None, names=("k_hip",), *, model="hybrid", sigma=None,
                 ground=None, walkers=100, max_steps=300, seed=1, statistic="mfpt",
                 gait_step=0.1, threads=2, **options) -> None:
        self.params = _rb._params(params)
        self.names = tuple(names)
        if not self.names:
            raise InvalidInputError("names must name at least one Params field")
        for n in self.names:
            v = getattr(self.params, n, None)
            if not isinstance(v, (int, float)) or isinstance(v, bool):
                raise InvalidInputError("names: %r is not a numeric pdw.Params field" % (n,))
        self.model = checks.choice("model", model, _rb.MODELS)
        self.statistic = checks.choice("statistic", statistic, STATISTICS)
        self.walkers = checks.count("walkers", walkers, lo=1, hi=10 ** 7)
        self.max_steps = checks.count("max_steps", max_steps, lo=1, hi=10 ** 7)
        self.seed = checks.count("seed", seed, lo=0, hi=2 ** 62)
        self.threads = checks.count("threads", threads, lo=1, hi=1024)
        self.gait_step = checks.number("gait_step", gait_step, lo=0.0, lo_open=True, hi=1.0)
        self.sigma, self.ground, self.options = sigma, ground, dict(options)
        if self.model == "continuous":
            from ...core.ground import Ground

            if sigma is not None or not isinstance(ground, Ground) or ground.kind != "random":
                raise InvalidInputError("MfptObjective(model='continuous') needs ground = "
                                        "pdw.Ground.random(...) and no sigma")
        else:
            if ground is not None or sigma is None:
                raise InvalidInputError("MfptObjective(model='hybrid') needs sigma [m], no "
                                        "ground")
            self.sigma = checks.number("sigma", sigma, lo=0.0)
        self.x0 = np.array([float(getattr(self.params, n)) for n in self.names])
        self._h = np.array([self.gait_step * abs(v) if v != 0 else self.gait_step
                            for v in self.x0])
        self._anchors: dict = {}
        self._memo: dict = {}
        self._grounds: list | None = None
        self.evaluations: list = []

    # --- the gait ---------------------------------------------------------------------------
    def _find(self, x, guess):
        P = self.at(x)
        if self.model == "hybrid":
            if guess is None:
                return _hy.find_gait(P, **self.options)
            return _hy.find_gait(P, guess=guess.state, settle_steps=0, **self.options)
        return _lc.find_gait(P, guess=guess)

    def _anchor(self, j):
        """The gait at lattice point x0 + j h, continued from the lattice neighbour one step
        closer to x0 along the coordinate of the largest |j| (None: no gait)."""
        j = tuple(int(v) for v in j)
        if j not in self._anchors:
            if not any(j):
                g = self._find(self.x0, None)
            else:
                i = int(np.argmax(np.abs(j)))
                prev = list(j)
                prev[i] -= int(np.sign(j[i]))
                g0 = self._anchor(prev)
                try:
                    g = None if g0 is None else self._find(self.x0 + np.array(j) * self._h, g0)
                except PdwError:
                    g = None
            self._anchors[j] = g
        return self._anchors[j]

    def at(self, x):
        """The Params at x."""
        return self.params.replace(**{n: float(v) for n, v in zip(self.names, x)})

    def gait_at(self, x):
        """The period-one gait at x, from the nearest anchor of the lattice x0 + j h (None when
        no gait is found there)."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        g0 = self._anchor(np.rint((x - self.x0) / self._h))
        if g0 is None:
            return None
        try:
            return self._find(x, g0)
        except PdwError:
            return None

    # --- the first passage ------------------------------------------------------------------
    def first_passage(self, x):
        """The `FirstPassage` at x on the objective's walkers (None: no gait at x). Memoized."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if x.shape != (len(self.names),):
            raise InvalidInputError("x must have %d values (%s), got %s"
                                    % (len(self.names), ", ".join(self.names), x.shape))
        key = tuple(float(v) for v in x)
        if key not in self._memo:
            g = self.gait_at(x)
            fp = None if g is None else self._run(self.at(x), g)
            self._memo[key] = fp
            self.evaluations.append((key, 0.0 if fp is None else statistic(fp, self.statistic)))
        return self._memo[key]

    def _run(self, P, g):
        if self.model == "hybrid":
            return _fp.first_passage(P, sigma=self.sigma, walkers=self.walkers,
                                     max_steps=self.max_steps, seed=self.seed, gait=g,
                                     threads=self.threads, **self.options)
        from . import robustness_continuous as _rc

        if self._grounds is None:
            # the walkers' grounds, built once (their tables are cached on them); the step
            # length only sets their extent, from the base gait
            L = self._anchor((0,) * len(self.names)).step_length
            self._grounds = [_rc.walker_ground(self.ground, self.seed, i, self.max_steps, L)
                             for i in range(self.walkers)]
        b = _rc.batch(P, g, self._grounds, self.max_steps, threads=self.threads,
                      **self.options)
        steps, fell, status = _rc.outcomes(b, self.max_steps)
        return _fp.mfpt_estimate(steps, fell, max_steps=self.max_steps, status=status,
                                 meta=dict(model="continuous", seed=self.seed))

    def value(self, x) -> float:
        """The statistic at x [steps] (0 where there is no gait)."""
        fp = self.first_passage(x)
        return 0.0 if fp is None else statistic(fp, self.statistic)

    def __call__(self, x) -> float:
        return -self.value(x)

    def with_seed(self, seed, walkers=None) -> "MfptObjective":
        """The same objective on another set of walkers (``walkers`` of them, default as
        many; the gaits' anchors shared)."""
        out = MfptObjective(self.params, self.names, model=self.model, sigma=self.sigma,
                            ground=self.ground, max_steps=self.max_steps,
                            walkers=self.walkers if walkers is None else walkers,
                            seed=seed, statistic=self.statistic, gait_step=self.gait_step,
                            threads=self.threads, **self.options)
        out._anchors = self._anchors
        return out


@dataclass
class TunedMfpt:
    """Outcome of `tune_first_passage`.

    Attributes
    ----------
    x : ndarray (n,)
        The optimum of the named parameters.
    names : tuple of str
    value : float
        The statistic at x on the tuning walkers [steps] (in-sample).
    first_passage : FirstPassage
        At x on the tuning walkers.
    holdout : FirstPassage or None
        At x on the held-out walkers (out-of-sample), when a holdout seed was given.
    nfev : int
        The calls of the objective (the grid's and the optimizer's).
    evaluations : list of (tuple, float)
        Each call's point and statistic [steps], in order.
    result : scipy.optimize.OptimizeResult
    objective : MfptObjective
    """

    x: np.ndarray
    names: tuple
    value: float
    first_passage: Any
    holdout: Any
    nfev: int
    evaluations: list
    result: Any = field(repr=False)
    objective: Any = field(repr=False)

    def __repr__(self) -> str:
        xs = ", ".join("%s=%.4g" % (n, v) for n, v in zip(self.names, self.x))
        h = "" if self.holdout is None else ", held out %.4g (%.4g, %.4g)" % (
            self.holdout.mfpt, *self.holdout.ci)
        return "TunedMfpt(%s, %s %.4g in-sample%s, %d evaluations)" % (
            xs, self.objective.statistic, self.value, h, self.nfev)


def tune_first_passage(params=None, names=("k_hip",), bounds=((0.5, 1.5),), *, x0=None,
                       xatol=0.02, maxiter=30, holdout_seed=None, objective=None, grid=None,
                       **objective_kw) -> TunedMfpt:
    """Tune parameters to maximize the first-passage statistic with `scipy.optimize` on a
    common-random-numbers objective (`MfptObjective`).

    One parameter: ``scipy.optimize.minimize_scalar(method="bounded")``, ``xatol``. Several:
    ``scipy.optimize.minimize(method="Nelder-Mead")`` with ``bounds``, from ``x0`` (default the
    base values, clipped into the bounds), its first simplex a quarter of each bound's width
    from it, xatol absolute in each parameter, fatol 1 step. ``holdout_seed``: the optimum re-evaluated on as many walkers
    of that seed (a seed set disjoint from the tuning one when the seeds differ by more than
    ``walkers`` on the continuous model). ``grid`` (one parameter): the objective is first
    evaluated at these points (sorted, inside the bounds) and Brent runs on the bracket of the
    best one's neighbours: a rugged objective (the compliant walker's, docs/terrain.md) has
    local maxima that Brent from the whole interval ends in.

    Parameters
    ----------
    params : Params
    names : sequence of str
    bounds : sequence of (float, float)
        One (lo, hi) per name.
    x0 : array_like, optional
    xatol : float
    maxiter : int
        Brent's iterations, or Nelder-Mead's function evaluations.
    holdout_seed : int, optional
    objective : MfptObjective, optional
        Instead of building one from ``params, names, **objective_kw``.
    grid : sequence of float, optional
        One parameter: points scanned first; Brent then on the best point's neighbours.
    objective_kw
        `MfptObjective`'s keywords (model, sigma or ground, walkers, max_steps, seed,
        statistic, threads, ...).

    Returns
    -------
    TunedMfpt
    """
    from scipy.optimize import minimize, minimize_scalar

    f = objective if objective is not None else MfptObjective(params, names, **objective_kw)
    bounds = [tuple(float(v) for v in b) for b in bounds]
    if len(bounds) != len(f.names) or any(not lo < hi for lo, hi in bounds):
        raise InvalidInputError("bounds must be one (lo, hi) with lo < hi per name (%s), got "
                                "%r" % (", ".join(f.names), bounds))
    xatol = checks.number("xatol", xatol, lo=0.0, lo_open=True)
    maxiter = checks.count("maxiter", maxiter, lo=1, hi=10 ** 5)
    calls: list = []

    def g(x):
        v = f(np.atleast_1d(x))
        calls.append((tuple(float(u) for u in np.atleast_1d(x)), -v))
        return v

    if len(f.names) == 1:
        lo, hi = bounds[0]
        if grid is not None:
            pts = np.unique(np.asarray(grid, dtype=float))
            if pts.ndim != 1 or len(pts) < 3 or pts[0] < lo or pts[-1] > hi:
                raise InvalidInputError("grid must hold at least 3 points inside the bounds "
                                        "%r, got %r" % (bounds[0], grid))
            vals = [g([p]) for p in pts]
            i = int(np.argmin(vals))
            lo, hi = float(pts[max(i - 1, 0)]), float(pts[min(i + 1, len(pts) - 1)])
        res = minimize_scalar(lambda v: g([v]), bounds=(lo, hi), method="bounded",
                              options=dict(xatol=xatol, maxiter=maxiter))
        # Brent never evaluates its bracket's ends: the best point seen (a grid point included)
        best = min(calls, key=lambda c: -c[1])
        x = np.array([float(res.x) if -res.fun >= best[1] else best[0][0]])
    else:
        lo, hi = np.array([b[0] for b in bounds]), np.array([b[1] for b in bounds])
        start = np.clip(f.x0 if x0 is None else np.asarray(x0, dtype=float), lo, hi)
        # the first simplex: a quarter of each bound's width from the start (inward), not
        # scipy's 5 % of the start, which on a rugged objective stalls in one cell
        simplex = [start]
        for i, w in enumerate(0.25 * (hi - lo)):
            v = start.copy()
            v[i] = v[i] + w if v[i] + w <= hi[i] else v[i] - w
            simplex.append(v)
        res = minimize(g, start, method="Nelder-Mead", bounds=bounds,
                       options=dict(xatol=xatol, fatol=1.0, maxfev=maxiter,
                                    initial_simplex=np.array(simplex)))
        x = np.asarray(res.x, dtype=float)
    held = None
    if holdout_seed is not None:
        held = f.with_seed(holdout_seed).first_passage(x)
    fp = f.first_passage(x)
    return TunedMfpt(x=x, names=f.names, value=f.value(x), first_passage=fp, holdout=held,
                     nfev=len(calls), evaluations=calls, result=res, objective=f)

