"""The step-size check's compiled parts (issue 23, the first call of a process): the
representative states in one compiled call (`_core.stance_search`), the first depth grid
without numpy.geomspace's glue and the cdm step maps without matrix products give, bit for
bit, what the Python they replace gives."""
import numpy as np
import pytest

import pdw
from pdw.core import _core, _layout
from pdw.core.model import kernel_index, parameter_vector
from pdw.sim import stepsize as S

P0 = pdw.Params.paper()
PARAMS = [P0, pdw.Params.paper_steady(), P0.replace(k_n=1.1 * P0.k_n), P0.replace(k_n=1e3),
          P0.replace(k_n=1e8), P0.replace(d_n=0.0), P0.replace(d_n=1e4), P0.replace(k_t=0.0),
          P0.replace(l=0.6, r=0.1), P0.replace(k_n=3e4, d_n=1e2, m_h=12.0)]


def python_stance_states(params, variant):
    """The representative states as `_stance_states` computed them before: the generator
    searches of `_stance_state` side by side, each grid through `_contact`."""
    cases = [(x, (0, 1), 1, 1.0) for x in S.STANCE_STATES] + \
        [(S.DOUBLE_SUPPORT_STATE, S.LANDING_FLAGS, 0, S.DOUBLE_SUPPORT_LOAD)]
    return np.array(S._side_by_side(
        [S._stance_state(x, params, fl, foot, load * params.weight) for x, fl, foot, load in cases],
        [fl for _, fl, _, _ in cases], params, variant))


@pytest.mark.parametrize("variant", ["paper", "consistent"])
@pytest.mark.parametrize("params", PARAMS)
def test_compiled_stance_states_are_the_python_search_bit_for_bit(params, variant):
    X, flags = S._stance_states(params, variant)
    assert flags == ((0, 1),) * 3 + (S.LANDING_FLAGS,)
    np.testing.assert_array_equal(X, python_stance_states(params, variant), strict=True)
    # and the states do what they are for: the support feet carry the load
    c = S._contact(X, params, np.array(flags, dtype=np.intc), variant)
    load = c.F_n.sum(axis=1) / params.weight
    np.testing.assert_allclose(load, [1, 1, 1, S.DOUBLE_SUPPORT_LOAD], rtol=1e-4)


@pytest.mark.parametrize("l", [0.5, 0.8, 1.0, 1e-3, 7.3, 123.456])
def test_depth_grid_is_numpy_geomspace_bit_for_bit(l):
    d = S._depths.__wrapped__(l)
    np.testing.assert_array_equal(d, np.geomspace(1e-9, 0.25 * l, 97), strict=True)


def test_cdm_maps_are_step_matrix_bit_for_bit_signed_zeros_included():
    rng = np.random.default_rng(3)
    X, flags = S.stance_states(P0, "paper")
    Js = S._state_jacobians(X, P0, flags, "paper")        # structural zeros of the model
    for _ in range(200):
        J = rng.normal(size=(8, 8)) * 10 ** rng.uniform(-3, 6)
        J[rng.random((8, 8)) < 0.4] = 0.0
        J[rng.random((8, 8)) < 0.2] = -0.0
        Js.append(J)
    hs = 10 ** rng.uniform(-8, 0, len(Js))
    M = S._cdm_maps(np.array(Js), hs)
    for J, h, m in zip(Js, hs, M):
        ref = S.step_matrix("cdm", J, h)
        np.testing.assert_array_equal(m, ref, strict=True)
        np.testing.assert_array_equal(np.signbit(m), np.signbit(ref))


def test_stance_search_checks_its_arrays():
    X = np.array(S.STANCE_STATES, dtype=float)
    args = dict(p=parameter_vector(P0), flags=np.array([(0, 1)] * 3, dtype=np.intc),
                foot=np.ones(3, dtype=np.intc), force=np.full(3, P0.weight),
                depths=S._depths(P0.l))
    layout = (P0.l - P0.r, _layout.KIN.index("y_D"), _layout.KIN.index("v_x"),
              _layout.CONTACT.index("F_n"), len(_layout.KIN), len(_layout.CONTACT))
    k = kernel_index("paper", None)

    def call(**kw):
        a = {**args, **kw}
        _core.stance_search(k, X.copy(), a["p"], a["flags"], a["foot"], a["force"], a["depths"],
                            *layout)

    call()
    with pytest.raises(ValueError, match="foot"):
        call(foot=np.ones(2, dtype=np.intc))
    with pytest.raises(ValueError, match="depths"):
        call(depths=np.geomspace(1e-9, 0.1, 50))
    with pytest.raises(ValueError, match="flags"):
        call(flags=np.array([(0, 2)] * 3, dtype=np.intc))
    with pytest.raises(ValueError, match="layout"):
        _core.stance_search(k, X.copy(), args["p"], args["flags"], args["foot"], args["force"],
                            args["depths"], *layout[:4], len(_layout.KIN) + 1, len(_layout.CONTACT))
    with pytest.raises(ValueError, match="foot must hold 0 or 1"):
        call(foot=np.array([1, 1, 2], dtype=np.intc))
