"""Specialized generated kernels (derive/emit.py KERNELS) against the general kernel.

A kernel specialized for a set of force elements had the absent elements folded to zero
before CSE; it must equal the general kernel of its variant run with the same parameters
zeroed (`Params.without`), at random states, for the right-hand side, the Jacobian, the
contact forces and the energies.
"""
import zlib

import numpy as np
import pytest

import pdw
from pdw.core import _core, _layout
from pdw.core.model import kernel_index, parameter_vector

SPECIALIZED = [(name, variant, feats) for name, variant, feats in _layout.KERNELS
               if tuple(feats) != _layout.FEATURES]


def _random_states(rng, n):
    """States around the walker's stance with penetrating feet, every friction branch and
    both signs of the tangential deformation; random flags and anchors."""
    x = np.empty((n, 8))
    x[:, 0] = rng.uniform(-0.5, 0.5, n)
    x[:, 1] = rng.uniform(0.47, 0.505, n)           # feet up to ~3 cm deep, or above ground
    x[:, 2:4] = rng.uniform(-0.45, 0.45, (n, 2))
    x[:, 4:6] = rng.uniform(-1.0, 1.0, (n, 2))
    x[:, 6:8] = rng.uniform(-3.0, 3.0, (n, 2))
    # slip velocities in the stiction and transition bands of the friction law for some rows
    slow = rng.random(n) < 0.5
    lr = 0.3 * np.cos(x[:, 2]) + 0.2
    x[slow, 4] = -lr[slow] * x[slow, 6] + rng.uniform(-2e-3, 2e-3, slow.sum())
    flags = rng.integers(0, 2, (n, 2)).astype(np.intc)
    anchors = rng.uniform(-0.05, 0.05, (n, 2))
    return x, flags, anchors


def _close(a, b):
    scale = max(1.0, float(np.max(np.abs(b))))
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12 * scale)


def test_the_kernel_table_has_the_specializations():
    names = [k[0] for k in _layout.KERNELS]
    for v in _layout.VARIANTS:
        assert v in names                                        # the general kernel
        assert v + "_no_hip_spring_no_hip_damper" in names
        assert v + "_no_tangential" in names
        assert v + "_no_hip_spring_no_hip_damper_no_tangential" in names
    assert [n for n, _, _ in _core.kernel_table()] == names


@pytest.mark.parametrize("name, variant, feats", SPECIALIZED, ids=[k[0] for k in SPECIALIZED])
def test_kernel_index_picks_the_specialized_kernel(name, variant, feats):
    k = kernel_index(variant, feats)
    assert _core.kernel_table()[k][0] == name
    assert k != kernel_index(variant)
    # feature order does not matter
    assert kernel_index(variant, tuple(reversed(feats))) == k


def test_a_combination_without_a_kernel_falls_back_to_the_general_one():
    feats = tuple(f for f in _layout.FEATURES if f != "friction")
    for v in _layout.VARIANTS:
        assert kernel_index(v, feats) == kernel_index(v)


@pytest.mark.parametrize("name, variant, feats", SPECIALIZED, ids=[k[0] for k in SPECIALIZED])
def test_specialized_kernel_equals_general_kernel_with_forces_zeroed(name, variant, feats):
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    X, F, A = _random_states(rng, 400)
    ks, kg = kernel_index(variant, feats), kernel_index(variant)
    params = pdw.Params.paper()
    p = parameter_vector(params.without(feats))
    out = {}
    for k in (ks, kg):
        xdot, work = np.empty_like(X), np.empty((len(X), _core.NWORK))
        _core.rhs_batch(k, X, p, F, A, xdot, work)
        J, wj = np.empty((len(X), 64)), np.empty((len(X), _core.NWORK))
        _core.jacobian_batch(k, X, p, F, A, J, wj)
        e = np.empty((len(X), len(_layout.ENERGY)))
        _core.energies_batch(k, X, p, e)
        out[k] = dict(xdot=xdot, work=work, J=J, partials=wj, e=e)
    s, g = out[ks], out[kg]
    c0, nc = _layout.WORK["contact"]
    contact = lambda w: w[:, c0:c0 + nc].reshape(-1, 2, len(_layout.CONTACT))  # noqa: E731
    n_contact = (contact(g["work"])[:, :, 0] > 0).sum()
    assert n_contact > 100, "the random states must exercise the contact forces"
    for row in range(len(X)):
        _close(s["xdot"][row], g["xdot"][row])
        _close(s["J"][row], g["J"][row])
        _close(contact(s["work"])[row, :, :3], contact(g["work"])[row, :, :3])   # F_n, F_t, mu
        _close(contact(s["partials"])[row], contact(g["partials"])[row])
        _close(s["e"][row], g["e"][row])


@pytest.mark.parametrize("name, variant, feats", SPECIALIZED, ids=[k[0] for k in SPECIALIZED])
def test_public_model_functions_use_the_specialized_kernel(name, variant, feats):
    """pdw.rhs / jacobian / contact_forces with `features` equal the general kernel with the
    parameters zeroed by hand."""
    rng = np.random.default_rng(7)
    X, F, A = _random_states(rng, 50)
    params = pdw.Params.paper_steady()
    zeroed = params.without(feats)
    for x, f, a in zip(X, F, A):
        _close(pdw.rhs(x, params, f, a, variant, features=feats),
               pdw.rhs(x, zeroed, f, a, variant))
        _close(pdw.jacobian(x, params, f, a, variant, features=feats),
               pdw.jacobian(x, zeroed, f, a, variant))
        cs = pdw.contact_forces(x, params, f, a, variant, features=feats)
        cg = pdw.contact_forces(x, zeroed, f, a, variant)
        for field in ("F_n", "F_t", "mu"):
            _close(getattr(cs, field), getattr(cg, field))


def test_specialized_kernels_do_less_work():
    """The folded force elements are gone from the generated stages (SymPy op counts)."""
    for v in _layout.VARIANTS:
        full = _layout.OPS[v]
        assert _layout.OPS[v + "_no_hip_spring_no_hip_damper"]["dynamics"] < full["dynamics"]
        assert _layout.OPS[v + "_no_tangential"]["contact"] < full["contact"]
        minimal = _layout.OPS[v + "_no_hip_spring_no_hip_damper_no_tangential"]
        assert minimal["dynamics_jacobian"] < full["dynamics_jacobian"]
        assert minimal["contact_partials"] < full["contact_partials"]
