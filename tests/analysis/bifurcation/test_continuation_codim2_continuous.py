"""Two-parameter continuation with the directional second differences and the sigma tolerance
(issue #24 a: the continuous model's fold curve in (k_n, d_n)); pdw.analysis.bifurcation.codim2."""
import numpy as np
import pytest

import pdw
from pdw import hybrid as H
from pdw.analysis.bifurcation.codim2 import continue_bifurcation
from pdw.analysis.bifurcation.continuation import continue_gait
from pdw.analysis.stepmap import poincare

DEG = np.pi / 180


def test_directional_second_differences_give_the_same_hybrid_curve():
    """The compass gait's doubling in c: the directional scheme (no extra monodromies) and the
    monodromy scheme put the curve at the same slopes (1e-9 rad at c = 0.6), with fewer maps."""
    b = continue_gait(H.compass_gait_params(), "gamma", 5.3 * DEG, model="hybrid")
    pd = b.of_kind("period_doubling")[0]
    a = continue_bifurcation(pd, "c", 0.7, second="monodromy", at=[0.6])
    d = continue_bifurcation(pd, "c", 0.7, second="directional", at=[0.6])
    ia, id_ = (int(np.argmin(np.abs(c.values[:, 1] - 0.6))) for c in (a, d))
    assert abs(a.values[ia, 0] - d.values[id_, 0]) < 1e-9
    assert d.n_maps < a.n_maps


def test_bad_second_and_sigma_tol_are_refused():
    b = continue_gait(H.compass_gait_params(), "gamma", 5.3 * DEG, model="hybrid")
    pd = b.of_kind("period_doubling")[0]
    with pytest.raises(pdw.InvalidInputError, match="second"):
        continue_bifurcation(pd, "c", 0.7, second="exact")
    with pytest.raises(pdw.InvalidInputError, match="sigma_tol"):
        continue_bifurcation(pd, "c", 0.7, sigma_tol=0.0)


@pytest.mark.slow
def test_continuous_fold_curve_in_k_n_d_n_against_one_parameter_folds_and_walks():
    """paper_steady with d_hip = 0.014 (paper variant) has a fold in d_n at 2.54e6 (k_n = 1e5).
    Followed in k_n to 1.5e5, the curve's d_n there equals the fold that a one-parameter
    continuation in d_n locates at k_n = 1.5e5 (to 1e-3 relative: sigma_tol 3e-6 over the
    finite-difference M), and the step map itself (no continuation, no Jacobian) walks 150
    steps on 2 % below the fold and falls within them 2 % above it, both started on the
    gait found at 0.9 x the fold's d_n."""
    P = pdw.Params.paper_steady(d_hip=0.014)
    b = continue_gait(P, "d_n", 1e8, log=True, max_points=30)
    fold = b.of_kind("fold")[0]
    cv = continue_bifurcation(fold, "k_n", 1.5e5, fd_step=1e-4, max_points=40, at=[1.5e5])
    assert "reached stop" in cv.stop_reason
    assert np.all(np.min(np.abs(cv.multipliers - 1.0), axis=1) < 1e-4)
    d_curve = cv.values[-1, 0]
    Q = P.replace(k_n=1.5e5)
    b2 = continue_gait(Q, "d_n", 1e8, log=True, max_points=30)
    (f2,) = b2.of_kind("fold")
    assert abs(d_curve / f2.value - 1.0) < 1e-3
    stable = b2.values[:f2.index + 1]                   # the branch up to the fold
    z0 = b2.z[int(np.argmin(np.abs(stable - 0.9 * f2.value)))]
    for factor, walks in ((0.98, True), (1.02, False)):
        R = Q.replace(d_n=factor * d_curve)
        z, ok = z0, True
        for _ in range(150):
            out = poincare.step(z, R)
            if out["status"] != "ok":
                ok = False
                break
            z = out["z"]
        assert ok == walks, factor
