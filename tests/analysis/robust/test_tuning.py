"""The MFPT tuned with scipy.optimize on a common-random-numbers objective (issue 22 item 6;
docs/robustness.md, "Tuning for the MFPT"): the objective is a deterministic function of the
parameters on its walkers, the optimizer's result beats its bracket's ends on those walkers,
and another seed set gives another value."""
import numpy as np
import pytest

import pdw
from pdw.analysis.robust.tuning import MfptObjective, statistic, tune_first_passage

P = pdw.Params.paper_steady()
KW = dict(model="hybrid", sigma=0.0018, walkers=40, max_steps=200, seed=5, threads=1)


def test_crn_objective_is_deterministic_and_seed_dependent():
    a = MfptObjective(P, ("k_hip",), **KW)
    b = MfptObjective(P, ("k_hip",), **KW)
    b.value([1.3])                       # another order of visits: other anchors first
    va, vb = a.value([0.9]), b.value([0.9])
    assert va == vb                      # bitwise: the same walkers on the same ground
    assert np.array_equal(a.first_passage([0.9]).steps, b.first_passage([0.9]).steps)
    # it is pdw.first_passage at that point on those seeds
    fp = pdw.first_passage(a.at([0.9]), gait=a.gait_at([0.9]), **{k: v for k, v in KW.items()
                                                                   if k != "model"})
    assert fp.mfpt == va
    # another seed set: other walkers, another value (the same parameters)
    other = a.with_seed(6)
    assert other.value([0.9]) != va
    assert not np.array_equal(other.first_passage([0.9]).steps, a.first_passage([0.9]).steps)
    # the statistics are of the same walkers
    t = np.minimum(fp.steps, fp.max_steps)
    assert statistic(fp, "censored_mean") == pytest.approx(t.mean())
    assert statistic(fp, "geometric_mean") == pytest.approx(np.exp(np.log(t).mean()))


def test_tuned_k_hip_beats_its_bracket_ends_on_the_same_walkers():
    f = MfptObjective(P, ("k_hip",), **KW)
    t = tune_first_passage(objective=f, bounds=[(0.5, 1.5)], xatol=0.05, holdout_seed=1000)
    ends = f.value([0.5]), f.value([1.5])
    assert 0.5 < t.x[0] < 1.5
    assert t.value > max(ends)
    assert t.value == max(v for _, v in t.evaluations)      # the best point it saw
    assert t.nfev == len(t.evaluations) == t.result.nfev
    # the held-out walkers are other walkers, at the same k_hip
    assert t.holdout is not None and t.holdout.mfpt != t.value
    assert t.holdout.walkers == KW["walkers"]


def test_grid_then_brent_in_the_best_cell():
    f = MfptObjective(P, ("k_hip",), **KW)
    grid = [0.5, 0.75, 1.0, 1.25, 1.5]
    t = tune_first_passage(objective=f, bounds=[(0.5, 1.5)], grid=grid, xatol=0.02)
    vals = [f.value([k]) for k in grid]
    i = int(np.argmax(vals))
    assert grid[max(i - 1, 0)] <= t.x[0] <= grid[min(i + 1, 4)]
    assert t.value >= max(vals) and t.nfev > len(grid)
    with pytest.raises(pdw.InvalidInputError, match="grid"):
        tune_first_passage(objective=f, bounds=[(0.5, 1.5)], grid=[0.4, 0.9, 1.2])


def test_nelder_mead_over_two_parameters_stays_in_bounds():
    f = MfptObjective(P, ("k_hip", "d_hip"), **KW)
    t = tune_first_passage(objective=f, bounds=[(0.6, 1.4), (0.0, 0.02)], xatol=0.02,
                           maxiter=8)
    assert all(0.6 <= x[0] <= 1.4 and 0.0 <= x[1] <= 0.02 for x, _ in t.evaluations)
    assert t.value >= f.value([0.95, 0.010])                 # the start


def test_continuous_objective_is_first_passage_on_the_same_grounds():
    g = pdw.Ground.random(0.002, 0.1)
    kw = dict(ground=g, walkers=3, max_steps=12, seed=4, threads=1)
    f = MfptObjective(P, ("k_hip",), model="continuous", **kw)
    fp = f.first_passage([0.95])
    ref = pdw.first_passage(P, model="continuous", gait=f.gait_at([0.95]), **kw)
    assert np.array_equal(fp.steps, ref.steps) and np.array_equal(fp.failed, ref.failed)


def test_bad_input_names_the_field():
    with pytest.raises(pdw.InvalidInputError, match="statistic"):
        MfptObjective(P, statistic="median", **KW)
    with pytest.raises(pdw.InvalidInputError, match="names"):
        MfptObjective(P, ("k_hipp",), **KW)
    with pytest.raises(pdw.InvalidInputError, match="sigma"):
        MfptObjective(P, model="hybrid", ground=pdw.Ground.random(0.001))
    with pytest.raises(pdw.InvalidInputError, match="bounds"):
        tune_first_passage(P, ("k_hip",), [(1.5, 0.5)], **KW)
    with pytest.raises(pdw.InvalidInputError, match="x must have"):
        MfptObjective(P, **KW).value([0.9, 0.01])
