"""The Markov-chain estimate of the mean first-passage time (Byl & Tedrake, IJRR 2009).

The hybrid walker on stochastic terrain is a Markov chain: its post-impact state y (4,) and a
random step height dh (i.i.d. N(0, sigma^2), the ground under the landing foot relative to the
stance foot) give the next state y' = P(y, dh) or a failure. `markov_chain` discretizes it as
Byl & Tedrake do ("Metastable walking machines", Sec. 4): a mesh of the states reachable from
the gait, built outward from the gait's state one generation at a time, and the step-height
distribution as ``n_dh`` values: the conditional means of equal-width bins, weighted by the
bins' probabilities (``dh_nodes``). The mesh is a grid of cells of side ``resolution`` in the scaled coordinates
u = (theta_st, theta_sw, thetad_st / w, thetad_sw / w), w = sqrt(g / l); each cell is
represented by the first reachable state that fell in it, and a transition goes to the cell of
the next state. A failing step goes to the absorbing state. With Q the transient block of the
transition matrix,

    m = (I - Q)^-1 1       (the fundamental matrix: m_i = expected steps to failure from i)

and Byl & Tedrake's eigenvalue estimate MFPT ~ 1 / (1 - lambda_2), lambda_2 the largest
eigenvalue of Q (the second largest of the whole chain, whose largest is the absorbing state's
1). Both are reported; `MarkovChain.sample` runs the discretized chain itself by Monte Carlo
(the check that the linear algebra and the sampling agree).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...core import checks
from ...core.errors import InvalidInputError
from . import robustness as _rb


@dataclass
class MarkovChain:
    """Outcome of `markov_chain`.

    Attributes
    ----------
    mfpt : float
        Expected steps to failure [steps] from the gait's cell (fundamental matrix).
    mfpt_eig : float
        1 / (1 - lambda_2) [steps] (Byl & Tedrake's estimate).
    lambda2 : float
        Largest eigenvalue of the transient block Q.
    Q : scipy.sparse.csr_matrix (n, n)
        Transitions between cells; ``fail`` (n,) the probability of failing from each cell.
    states : ndarray (n, 4)
        Each cell's representative post-impact state.
    m : ndarray (n,)
        Expected steps to failure from each cell.
    start : int
        The gait's cell.
    complete : bool
        False when the mesh reached ``max_cells`` before every reachable cell was found (the
        unexplored cells are then treated as failures: mfpt is a lower bound).
    dh, weights : ndarray (n_dh,)
        The step heights [m] and their probabilities.
    sigma, resolution : float
    """

    mfpt: float
    mfpt_eig: float
    lambda2: float
    Q: Any
    fail: np.ndarray
    states: np.ndarray
    m: np.ndarray
    start: int
    complete: bool
    dh: np.ndarray
    weights: np.ndarray
    sigma: float
    resolution: float
    meta: dict = field(default_factory=dict)

    @property
    def n_cells(self) -> int:
        return len(self.states)

    def sample(self, walkers, max_steps, seed=0):
        """Monte Carlo on the discretized chain itself: (steps (walkers,), failed (walkers,)),
        each walker from the gait's cell; for `pdw.analysis.robust.first_passage.mfpt_estimate`."""
        rng = np.random.default_rng(seed)
        Q = self.Q.tocsr()
        n = Q.shape[0]
        # per row: cumulative probabilities over (its columns..., failure)
        indptr, cols, vals = Q.indptr, Q.indices, Q.data
        steps = np.zeros(walkers, dtype=np.int64)
        failed = np.zeros(walkers, dtype=bool)
        state = np.full(walkers, self.start)
        alive = np.arange(walkers)
        cum = [np.cumsum(vals[indptr[i]:indptr[i + 1]]) for i in range(n)]
        for k in range(1, max_steps + 1):
            if len(alive) == 0:
                break
            u = rng.random(len(alive))
            nxt = np.empty(len(alive), dtype=np.int64)
            for j, w in enumerate(alive):
                c = cum[state[w]]
                pos = int(np.searchsorted(c, u[j], side="right"))
                nxt[j] = cols[indptr[state[w]] + pos] if pos < len(c) else -1
            dead = nxt < 0
            steps[alive[dead]] = k
            failed[alive[dead]] = True
            state[alive[~dead]] = nxt[~dead]
            alive = alive[~dead]
        steps[alive] = max_steps
        return steps, failed


def dh_nodes(sigma, n_dh, span=5.0):
    """``n_dh`` step heights [m] and their probabilities: N(0, sigma^2) cut into n_dh bins of
    equal width on [-span sigma, span sigma] (the outer bins reach to infinity), each bin
    represented by its conditional mean and weighted by its probability. Probabilities are
    preserved bin by bin, so the chance of a step height beyond a failure threshold is right to
    within one bin (an equal-probability rule loses the tails where the falls come from; a
    Gauss-Hermite rule puts large weights on few tail nodes)."""
    from scipy.stats import norm

    e = np.linspace(-span, span, n_dh + 1)
    e[0], e[-1] = -np.inf, np.inf
    P = np.diff(norm.cdf(e))
    mean = (norm.pdf(e[:-1]) - norm.pdf(e[1:])) / P        # E[x | bin] of N(0, 1)
    return sigma * mean, P


#: how a cell of the mesh is represented (`markov_chain`'s ``representative``)
REPRESENTATIVES = ("first", "centre")


def markov_chain(params=None, *, sigma, n_dh=41, resolution=0.01, max_cells=20000, gait=None,
                 threads=2, representative="first", **options) -> MarkovChain:
    """Byl & Tedrake's Markov-chain MFPT of the hybrid walker with i.i.d. step heights.

    Parameters
    ----------
    params : Params
        Default `Params.paper_steady()`.
    sigma : float
        Standard deviation of the step heights [m] (> 0).
    n_dh : int
        Step heights of the discretized distribution (``dh_nodes``).
    resolution : float
        Side of the mesh's cells in the scaled state u (module docstring).
    max_cells : int
        Largest mesh.
    gait : Gait, optional
    threads : int
    representative : {"first", "centre"}
        The state a cell's transitions start from: the first reachable state that fell in it
        (Byl & Tedrake's sampled mesh; the default), or the cell's centre. The two differ by
        the mesh's error (docs/robustness.md, "Why the chain and Monte Carlo differ").
    options
        Hybrid step-map options.

    Returns
    -------
    MarkovChain
    """
    import scipy.sparse as sps
    import scipy.sparse.linalg as spl

    params = _rb._params(params)
    sigma = checks.number("sigma", sigma, lo=0.0, lo_open=True)
    n_dh = checks.count("n_dh", n_dh, lo=1, hi=10 ** 4)
    resolution = checks.number("resolution", resolution, lo=0.0, lo_open=True)
    max_cells = checks.count("max_cells", max_cells, lo=1, hi=10 ** 7)
    representative = checks.choice("representative", representative, REPRESENTATIVES)
    gait = _rb._hybrid_gait(params, gait, options)
    dh, w = dh_nodes(sigma, n_dh)
    scale = np.array([1.0, 1.0, 1.0, 1.0]) / np.array(
        [1.0, 1.0, math.sqrt(params.g / params.l), math.sqrt(params.g / params.l)])

    def key(y):
        return tuple(np.floor(np.asarray(y) * scale / resolution).astype(np.int64))

    states = [np.array(gait.state, dtype=float)]
    index = {key(states[0]): 0}
    rows, cols, vals = [], [], []
    fail = [0.0]
    frontier = [0]
    complete = True
    while frontier:
        Y0 = np.repeat(np.array([states[i] for i in frontier]), n_dh, axis=0)
        DH = np.tile(dh, len(frontier))[:, None]
        n_done, _, y_next, _, _, _ = _rb._walk_dh(params, Y0, DH, options, threads)
        new = []
        for a, i in enumerate(frontier):
            for j in range(n_dh):
                r = a * n_dh + j
                if n_done[r] < 1:
                    fail[i] += w[j]
                    continue
                k = key(y_next[r])
                c = index.get(k)
                if c is None:
                    if len(states) >= max_cells:
                        complete = False
                        fail[i] += w[j]          # unexplored: counted as a failure
                        continue
                    c = index[k] = len(states)
                    states.append(np.array(y_next[r]) if representative == "first" else
                                  (np.array(k) + 0.5) * resolution / scale)
                    fail.append(0.0)
                    new.append(c)
                rows.append(i)
                cols.append(c)
                vals.append(w[j])
        frontier = new
    n = len(states)
    Q = sps.csr_matrix((vals, (rows, cols)), shape=(n, n))      # duplicates summed
    fail_arr = np.array(fail)
    A = sps.identity(n, format="csc") - Q.tocsc()
    m = spl.spsolve(A, np.ones(n)) if n > 1 else np.array([1.0 / max(fail_arr[0], 1e-300)])
    m = np.atleast_1d(m)
    if n > 2:
        lam = spl.eigs(Q, k=1, which="LM", return_eigenvectors=False, maxiter=10 ** 5)
        lam2 = float(np.real(lam[0]))
    else:
        lam2 = float(np.max(np.abs(np.linalg.eigvals(Q.toarray()))))
    if not np.isfinite(m).all():
        raise InvalidInputError("markov_chain: the transient block is singular (a closed set "
                                "of cells never fails: sigma too small for this resolution?)")
    return MarkovChain(mfpt=float(m[0]), mfpt_eig=1.0 / (1.0 - lam2) if lam2 < 1 else math.inf,
                       lambda2=lam2, Q=Q, fail=fail_arr, states=np.array(states), m=m, start=0,
                       complete=complete, dh=dh, weights=w, sigma=sigma, resolution=resolution,
                       meta=dict(n_dh=n_dh, max_cells=max_cells, representative=representative,
                                 options=dict(options)))

