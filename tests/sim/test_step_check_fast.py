"""The step-size check cut short (issue 23, the first call of a process): `stepsize._safe`
answers "no warning" from a lower bound of the limit, exactly as the whole search would."""
import math
import warnings

import numpy as np
import pytest

import pdw
from pdw.sim import stepsize as S

P0 = pdw.Params.paper()
CASES = [(P0.replace(k_n=1.3 * P0.k_n), "cdm", "paper"),
         (P0.replace(d_n=0.5 * P0.d_n, k_t=900.0), "cdm", "paper"),   # friction load: chatter
         (P0.replace(k_n=0.7 * P0.k_n), "rk4", "consistent"),
         (P0.replace(d_hip=3.0), "verlet", "paper")]


@pytest.mark.parametrize("params, method, variant", CASES)
def test_cut_short_check_agrees_with_the_whole_search(params, method, variant):
    full = S._dt_max_computed(params, method, variant)
    # far below, just below, at, just above and far above the limit
    for dt in (full / 10, np.nextafter(full, 0), full, np.nextafter(full, 1), 3 * full):
        S._BOUNDS.clear()
        assert S._safe(params, method, variant, dt, 1.0) == (not dt > full), dt
    S._BOUNDS.clear()
    assert S._safe(params, method, variant, full / 10, 1.0)
    assert S._BOUNDS[(params, method, variant)] <= full     # a lower bound, kept


def test_linear_limits_side_by_side_are_linear_limit_bit_for_bit():
    X, flags = S.stance_states(P0.replace(k_n=2 * P0.k_n), "paper")
    Js = [S.state_jacobian(x, P0.replace(k_n=2 * P0.k_n), f, "paper") for x, f in zip(X, flags)]
    for method in ("cdm", "verlet", "rk4", "dopri5"):
        assert S.linear_limits(method, Js) == [S.linear_limit(method, J) for J in Js]
    cut = S.linear_limits("cdm", Js, enough=lambda h: h > 1e-6)
    assert all(1e-6 < c <= h for c, h in zip(cut, S.linear_limits("cdm", Js)))


def test_simulate_still_warns_above_the_limit_with_new_parameters():
    P = P0.replace(k_n=1.7 * P0.k_n)
    dt = 2 * S._dt_max_computed(P, "cdm", "paper")
    with pytest.warns(pdw.StepSizeWarning):
        pdw.simulate(params=P, t_end=10 * dt, dt=dt, record=pdw.Record(every=0),
                     limits=pdw.Limits(on_failure="return"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", pdw.StepSizeWarning)
        pdw.simulate(params=P, t_end=0.01, record=pdw.Record(every=0))
    assert math.isfinite(dt)


@pytest.mark.parametrize("variant", ["paper", "consistent"])
def test_state_jacobians_together_are_state_jacobian_bit_for_bit(variant):
    P = P0.replace(k_t=700.0)
    X, flags = S.stance_states(P, variant)
    for features in (S._NO_FRICTION, None):
        together = S._state_jacobians(X, P, flags, variant, features)
        alone = [S.state_jacobian(x, P, f, variant, features) for x, f in zip(X, flags)]
        assert all(np.array_equal(a, b) for a, b in zip(together, alone))
