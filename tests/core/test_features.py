"""Force elements switched off through `features` are really absent (parameters folded to 0)."""
import numpy as np

import pdw

X = np.array(pdw.X0_PAPER)


def test_without_friction_mu_is_zero_and_ft_is_the_spring_damper_only():
    c_all = pdw.contact_forces(X, flags=(0, 1))
    c_nf = pdw.contact_forces(X, flags=(0, 1), features=("hip_spring", "hip_damper",
                                                          "normal_damping", "tangential"))
    assert c_all.mu[1] == -0.4 and c_nf.mu[1] == 0.0
    # paper variant, xi = (l-r) sin(theta2) > 0: the tangential spring-damper is gated off
    assert c_nf.F_t[1] == 0.0
    np.testing.assert_array_equal(c_nf.F_n, c_all.F_n)


def test_without_hip_spring_equals_k_hip_zero():
    p = pdw.Params.paper()
    feats = ("hip_damper", "normal_damping", "tangential", "friction")
    np.testing.assert_array_equal(pdw.rhs(X, p, features=feats), pdw.rhs(X, p.replace(k_hip=0.0)))
    assert not np.array_equal(pdw.rhs(X, p, features=feats), pdw.rhs(X, p))


def test_params_without_names_unknown_features():
    import pytest
    with pytest.raises(ValueError, match="friction"):
        pdw.Params.paper().without(("hip_spring", "fricton"))
