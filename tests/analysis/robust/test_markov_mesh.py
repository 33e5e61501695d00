"""The Markov chain's cell representative (`pdw.markov_chain(representative=...)`) and its
step-height bins (docs/robustness.md, "Why the chain and Monte Carlo differ";
benchmarks/markov_vs_mc.py measures the full decomposition)."""
import math

import numpy as np
import pytest
from scipy.stats import norm

import pdw
from pdw import hybrid as H
from pdw.analysis.robust import markov as M

P = pdw.Params.paper_steady()


@pytest.fixture(scope="module")
def gait():
    return H.find_gait(P)


def test_centre_representatives_are_the_cell_centres(gait):
    res = 0.02
    first = pdw.markov_chain(P, sigma=0.002, n_dh=7, resolution=res, gait=gait)
    centre = pdw.markov_chain(P, sigma=0.002, n_dh=7, resolution=res, gait=gait,
                              representative="centre")
    assert centre.meta["representative"] == "centre" and first.meta["representative"] == "first"
    w = math.sqrt(P.g / P.l)
    scale = np.array([1.0, 1.0, 1.0 / w, 1.0 / w])
    u = centre.states[1:] * scale / res           # the start cell keeps the gait's state
    assert np.allclose(u - np.floor(u), 0.5, atol=1e-9)
    uf = first.states[1:] * scale / res
    assert not np.allclose(uf - np.floor(uf), 0.5, atol=1e-3)   # "first": reached states
    for mc in (first, centre):
        assert np.allclose(np.asarray(mc.Q.sum(axis=1)).ravel() + mc.fail, 1.0)
    # the representative changes the answer: the mesh is not converged at this resolution
    assert abs(centre.mfpt / first.mfpt - 1) > 0.05


def test_representative_bad_input_names_the_field(gait):
    with pytest.raises(pdw.InvalidInputError, match="representative"):
        pdw.markov_chain(P, sigma=0.002, n_dh=3, resolution=0.05, gait=gait,
                         representative="center")


def test_dh_nodes_keep_each_bins_probability_and_mean():
    for n in (11, 21, 41):
        dh, w = M.dh_nodes(0.002, n)
        assert w.sum() == pytest.approx(1.0, abs=1e-14)
        assert np.all(np.diff(dh) > 0)
        e = np.linspace(-5, 5, n + 1)
        assert w[1:-1] == pytest.approx(np.diff(norm.cdf(e[1:-1])), rel=1e-12)
        assert dh @ w == pytest.approx(0.0, abs=1e-15)        # symmetric: the mean is 0
        # the variance is N(0, sigma^2)'s less the within-bin variance (at most width^2 / 12)
        width = 0.002 * 10 / n
        assert 0.002 ** 2 - width ** 2 / 12 - 1e-12 <= dh ** 2 @ w <= 0.002 ** 2
