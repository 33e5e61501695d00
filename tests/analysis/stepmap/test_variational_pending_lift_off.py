"""The exact monodromy with Eq. 18a's two lift-off conditions (pdw.analysis.stepmap.variational): a
support foot that leaves the ground while its normal rate is still <= 0 stays support until
the rate turns positive (as the compiled step map does)."""
import numpy as np
import pytest

import pdw
from pdw.analysis.bifurcation.continuation import continue_gait
from pdw.analysis.stepmap import poincare
from pdw.analysis.stepmap import variational as V


@pytest.fixture(scope="module")
def fold_point():
    """paper_steady with d_hip = 0.014 at its d_n fold (2.54e6): there the old stance foot
    leaves the ground 1.4 ms before its normal rate turns positive."""
    P = pdw.Params.paper_steady(d_hip=0.014)
    b = continue_gait(P, "d_n", 1e8, log=True, max_points=30)
    f = b.of_kind("fold")[0]
    return f.z, P.replace(d_n=f.value)


def test_step_and_lift_off_time_match_the_compiled_map(fold_point):
    """Before, the variational step switched the flag where the foot's height passed 0
    (0.0128 s), lifted the other foot off too and found no touch-down by t_max."""
    z, P = fold_point
    s = poincare.step(z, P)
    r = V.step_jacobian(z, P)
    assert r["T"] == pytest.approx(s["period"], abs=1e-9)
    assert np.max(np.abs(r["z"] - s["z"])) < 1e-9
    lift = [t for t, kind, leg in r["events"] if kind == "lift_off"]
    assert len(lift) == 1 and lift[0] == pytest.approx(s["double_support"], abs=1e-9)


def test_exact_jacobian_matches_central_differences(fold_point):
    z, P = fold_point
    M = V.step_jacobian(z, P)["M"]
    h = 1e-5
    J = np.column_stack([(poincare.step(z + e, P)["z"] - poincare.step(z - e, P)["z"]) / (2 * h)
                         for e in np.eye(6) * h])
    assert np.max(np.abs(M - J)) < 1e-4 * max(1.0, np.abs(J).max())
    m = np.sort(np.abs(np.linalg.eigvals(M)))
    assert abs(m[-1] - 1.0) < 1e-4                     # the fold's multiplier at +1
