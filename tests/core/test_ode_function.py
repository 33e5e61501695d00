"""pdw.ode_function: the compiled model object for external solvers."""

import numpy as np
import pytest

import pdw

scipy_integrate = pytest.importorskip("scipy.integrate")

X0 = np.array(pdw.X0_PAPER)


def test_matches_rhs_and_jacobian_at_random_states():
    rng = np.random.default_rng(3)
    X = X0 + 0.05 * rng.standard_normal((20, 8))
    for variant in pdw.VARIANTS:
        for flags, anchors in (((0, 1), (0.0, 0.01)), ((1, 1), (-0.02, 0.03)), ((0, 0), (0, 0))):
            f = pdw.ode_function(variant=variant, flags=flags, anchors=anchors)
            for x in X:
                np.testing.assert_array_equal(
                    f(0.3, x), pdw.rhs(x.tolist(), flags=flags, anchors=anchors, variant=variant))
                np.testing.assert_array_equal(
                    f.jac(0.3, x), pdw.jacobian(x, flags=flags, anchors=anchors, variant=variant))
            np.testing.assert_array_equal(
                f.batch(X), pdw.rhs(X, flags=flags, anchors=anchors, variant=variant))


def test_features_and_params_are_applied():
    p = pdw.Params.paper().replace(k_hip=2.0)
    f = pdw.ode_function(p, features=("hip_spring", "normal_damping", "tangential", "friction"))
    np.testing.assert_array_equal(f(0, X0), pdw.rhs(X0.tolist(), p, features=(
        "hip_spring", "normal_damping", "tangential", "friction")))
    assert not np.array_equal(f(0, X0), pdw.rhs(X0))


def test_returns_a_fresh_array_each_call():
    f = pdw.ode_function()
    a = f(0, X0)
    b = f(0, X0 + 0.01)
    assert not np.shares_memory(a, b) and not np.array_equal(a, b)


def test_kept_results_are_not_overwritten_by_later_calls():
    """f and jac compute into an internal buffer and return a copy: what a caller keeps stays."""
    f = pdw.ode_function()
    a, ja = f(0, X0), f.jac(0, X0)
    a0, ja0 = a.copy(), ja.copy()
    b, jb = f(0, X0 + 0.01), f.jac(0, X0 + 0.01)
    np.testing.assert_array_equal(a, a0)
    np.testing.assert_array_equal(ja, ja0)
    assert not np.array_equal(a, b) and not np.array_equal(ja, jb)
    assert not np.shares_memory(ja, jb)


def test_every_input_layout_gives_the_fast_paths_values():
    """The raw-buffer path (C-contiguous float64 (8,)) and the converting path agree."""
    import array
    f = pdw.ode_function(flags=(1, 1), anchors=(0.01, -0.02))
    want, want_j = f(0, X0), f.jac(0, X0)
    strided = np.zeros((8, 3))
    strided[:, 1] = X0
    for x in (X0.tolist(), strided[:, 1], array.array("d", X0), memoryview(X0), X0.reshape(1, 8)[0], X0.astype(">f8")):
        np.testing.assert_array_equal(f(0, x), want)
        np.testing.assert_array_equal(f.general(0, x), want)
        np.testing.assert_array_equal(f.jac(0, x), want_j)
    np.testing.assert_array_equal(f(0, np.stack([X0, X0])), np.stack([want, want]))
    x32 = X0.astype(np.float32)
    np.testing.assert_array_equal(f(0, x32), f(0, x32.astype(np.float64)))


@pytest.mark.parametrize("x", [np.zeros(7), np.zeros(9), [0.0] * 7, np.zeros((2, 4)).ravel()[:5]])
def test_a_state_of_the_wrong_shape_is_refused_naming_x(x):
    f = pdw.ode_function()
    for call in (f, f.jac, f.general):
        with pytest.raises(pdw.InvalidInputError, match=r"x must .*shape \(8,\)"):
            call(0.0, x)


def test_rhs_fast_path_agrees_with_its_general_path_for_every_layout():
    strided = np.zeros((8, 2))
    strided[:, 0] = X0
    want = pdw.rhs(X0.tolist())
    for x in (X0, strided[:, 0], np.asfortranarray(X0)):
        np.testing.assert_array_equal(pdw.rhs(x), want)
    x32 = X0.astype(np.float32)
    np.testing.assert_array_equal(pdw.rhs(x32), pdw.rhs(x32.tolist()))
    a = pdw.rhs(X0)
    pdw.rhs(X0 + 0.1)
    np.testing.assert_array_equal(a, want)


@pytest.mark.parametrize("kw, field", [({"flags": (0, 2)}, "flags"), ({"anchors": (0, np.nan)}, "anchors"),
                                       ({"variant": "soft"}, "variant"), ({"params": 3}, "params"),
                                       ({"features": ("wings",)}, "feature")])
def test_bad_input_is_refused_naming_the_field(kw, field):
    with pytest.raises(pdw.InvalidInputError, match=field):
        pdw.ode_function(**kw)


def test_rhs_fast_path_checks_like_the_general_path():
    bad = X0.copy()
    bad[3] = np.nan
    with pytest.raises(ValueError, match="theta2"):
        pdw.rhs(bad)
    with pytest.raises(ValueError, match="flags"):
        pdw.rhs(X0, flags=(0, 3))
    np.testing.assert_array_equal(pdw.rhs(X0, flags=(1, 1)), pdw.rhs(X0.tolist(), flags=[1, 1]))


def test_solve_ivp_reproduces_simulate_rodas4_between_flag_changes():
    """A stretch of the typical gait without a flag change (leg 2 in stance, stuck): Radau
    with the model object and its Jacobian against pdw's own rodas4, both at tight
    tolerances."""
    ref = pdw.simulate(X0, t_end=0.3, method="rodas4", dt=1e-6,
                       integrator=pdw.Integrator(rtol=1e-10, atol=1e-12))
    t_first = min((e.t for e in ref.events), default=np.inf)
    T = 0.2
    assert T < t_first, "the stretch must hold no flag change (first event at %g s)" % t_first
    f = pdw.ode_function(flags=(0, 1))
    sol = scipy_integrate.solve_ivp(f, (0.0, T), X0, method="Radau", jac=f.jac,
                                    rtol=1e-10, atol=1e-12, dense_output=True)
    assert sol.success
    ours = pdw.simulate(X0, t_end=T, method="rodas4", dt=1e-6,
                        integrator=pdw.Integrator(rtol=1e-10, atol=1e-12))
    assert ours.events == []
    err = np.abs(sol.y[:, -1] - ours.x_final)
    scale = np.abs(ours.x_final) + 1e-3
    assert np.max(err / scale) < 1e-6, err
    # and along the way, at pdw's own samples
    mid = sol.sol(ours.t).T
    assert np.max(np.abs(mid - ours.x)) < 1e-6


@pytest.mark.parametrize("x", [np.array(pdw.X0_PAPER, complex), ["1"] * 8, np.ones((2, 4)),
                               np.ones((1, 1, 8)), np.ones(8, bool)],
                         ids=["complex", "strings", "2x4", "1x1x8", "bool"])
def test_ode_function_refuses_states_it_used_to_coerce(x):
    """f(t, x) used to take the real part, parse strings and ravel any 8-element array."""
    f = pdw.ode_function()
    with pytest.raises(pdw.InvalidInputError, match="x must"):
        f(0.0, x)
    with pytest.raises(pdw.InvalidInputError, match="x must"):
        f.jac(0.0, x)


def test_ode_function_fast_and_converting_paths_agree():
    f = pdw.ode_function()
    x = np.array(pdw.X0_PAPER)
    assert np.array_equal(f(0.0, x), f(0.0, list(x)))
    assert np.array_equal(f(0.0, np.vstack([x, x]))[1], f(0.0, x))
    assert np.array_equal(f.jac(0.0, list(x)), f.jac(0.0, x))


@pytest.mark.parametrize("kw,field", [(dict(flags=np.array([0.0, 1.0])), "flags"),
                                      (dict(flags=(0.9, 1)), "flags"),
                                      (dict(anchors=("0", "1")), "anchors"),
                                      (dict(anchors=(0.0, float("inf"))), "anchors")])
def test_ode_function_discrete_state_is_strict(kw, field):
    with pytest.raises(pdw.InvalidInputError, match=field):
        pdw.ode_function(**kw)
