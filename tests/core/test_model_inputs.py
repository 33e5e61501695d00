"""Issue 26, item 5: NaN in, an error or NaN out, at every public entry point that takes a state.

`pdw.ode_function(...)(t, x)` used to return finite numbers for a NaN hip height: the contact
clamp turns a NaN depth into "no contact", while `pdw.rhs` refused the same state. Every entry
point that takes a state (rhs, jacobian, contact_forces, energies, mass_matrix,
ode_function's f, jac, batch and converting path, the hybrid model's pointwise functions and
step maps, the continuous model's step maps, simulate, simulate_batch) either raises
`pdw.InvalidInputError` naming the state, or (ode_function, the model object for external
solvers, which checks nothing per call; the continuous model's step, whose status is then
"bad_state") returns NaN in every entry; `poincare.step_map` raises its SimulationError
("bad_state").
"""

import numpy as np
import pytest

import pdw
from pdw.analysis.rigid import hybrid
from pdw.analysis.stepmap import poincare, step_maps

X0 = np.array(pdw.X0_PAPER, dtype=float)
Y0 = np.array([0.2, -0.2, -1.0, -0.3])          # a hybrid (reduced) state
Z0 = np.array([0.2, -0.2, 0.3, -0.1, -1.0, -0.3])  # a point of the touch-down section


def _f():
    return pdw.ode_function()


#: (name, function of a state x of shape (8,), the state it needs: "x", "y" (hybrid) or "z")
ENTRIES = [
    ("rhs", lambda x: pdw.rhs(x), "x"),
    ("rhs_batch", lambda x: pdw.rhs(np.stack([X0, x])), "x"),
    ("rhs_consistent", lambda x: pdw.rhs(x, variant="consistent", flags=(1, 1)), "x"),
    ("jacobian", lambda x: pdw.jacobian(x), "x"),
    ("contact_forces", lambda x: pdw.contact_forces(x).F_n, "x"),
    ("contact_forces_flores", lambda x: pdw.contact_forces(
        x, contact=pdw.Contact("flores", e=0.5)).F_n, "x"),
    ("contact_forces_lugre", lambda x: pdw.contact_forces(
        np.concatenate([x, [0.0, 0.0]]), contact=pdw.Contact(friction="lugre")).F_t, "x"),
    ("energies", lambda x: pdw.energies(x)["E"], "x"),
    ("mass_matrix", lambda x: pdw.mass_matrix(x), "x"),
    ("mass_matrix_q", lambda q: pdw.mass_matrix(q), "q"),
    ("ode_f", lambda x: _f()(0.0, x), "x"),
    ("ode_f_list", lambda x: _f()(0.0, list(x)), "x"),
    ("ode_f_general", lambda x: _f().general(0.0, x), "x"),
    ("ode_f_float32", lambda x: _f()(0.0, x.astype(np.float32)), "x"),
    ("ode_jac", lambda x: _f().jac(0.0, x), "x"),
    ("ode_jac_list", lambda x: _f().jac(0.0, list(x)), "x"),
    ("ode_batch", lambda x: _f().batch(np.ascontiguousarray(x[None])), "x"),
    ("ode_f_rows", lambda x: _f()(0.0, np.stack([x, x])), "x"),
    ("simulate", lambda x: pdw.simulate(x, t_end=0.001), "x"),
    ("simulate_batch", lambda x: pdw.simulate_batch(np.stack([X0, x]), t_end=0.001), "x"),
    ("hybrid.stance_rhs", lambda y: hybrid.stance_rhs(y), "y"),
    ("hybrid.energies", lambda y: hybrid.energies(y)["T"], "y"),
    ("hybrid.swing_foot", lambda y: hybrid.swing_foot(y)["y_sw"], "y"),
    ("hybrid.full_state", lambda y: hybrid.full_state(y), "y"),
    ("hybrid.impact", lambda y: hybrid.impact(y)["y_plus"], "y"),
    ("hybrid.step_map", lambda y: hybrid.step_map(y), "y"),
    ("hybrid.step_jacobian", lambda y: hybrid.step_jacobian(y), "y"),
    ("poincare.step_map", lambda z: poincare.step_map(z, t_max=0.01), "z"),
    ("poincare.step", lambda z: poincare.step(z, t_max=0.01)["z"], "z"),
    ("step_maps.map_images", lambda z: step_maps.map_images(z[None], t_max=0.01)[0], "z"),
]


def _state(kind):
    return {"x": X0, "q": X0[:4], "y": Y0, "z": Z0}[kind].copy()


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf], ids=["nan", "inf", "-inf"])
@pytest.mark.parametrize("name,fn,kind", ENTRIES, ids=[e[0] for e in ENTRIES])
def test_a_non_finite_state_is_refused_or_gives_nan(name, fn, kind, bad):
    """Every component in turn: NaN/inf in gives InvalidInputError or an all-NaN answer,
    never finite numbers."""
    base = _state(kind)
    for i in range(len(base)):
        x = base.copy()
        x[i] = bad
        try:
            out = fn(x)
        except pdw.InvalidInputError as e:
            assert "finite" in str(e), (name, i, str(e))
            continue
        except pdw.SimulationError as e:    # a step map: "the step from z = [nan ...] failed"
            assert "bad_state" in str(e), (name, i, e)
            continue
        out = np.asarray(out, dtype=float)
        assert np.isnan(out).all(), ("%s returned finite numbers for a state with %r at "
                                     "index %d: %r" % (name, bad, i, out))


def test_the_nan_hip_height_of_the_issue():
    """The case of the issue: y_o = NaN reached the contact clamp as "no contact"."""
    x = X0.copy()
    x[1] = np.nan
    f = pdw.ode_function()
    assert np.isnan(f(0.0, x)).all()
    assert np.isnan(f.jac(0.0, x)).all()
    with pytest.raises(pdw.InvalidInputError, match=r"x\[1\] \(y_o\)"):
        pdw.contact_forces(x)
    with pytest.raises(pdw.InvalidInputError, match=r"x\[1\] \(y_o\)"):
        pdw.rhs(x)


def test_finite_states_are_untouched_by_the_check():
    """The NaN guard changes nothing for finite states: ode_function's f, jac and batch give
    rhs and jacobian bit for bit, and a finite row next to a NaN row of a batch is computed."""
    f = pdw.ode_function()
    rng = np.random.default_rng(3)
    X = X0 + 1e-3 * rng.standard_normal((5, 8))
    for x in X:
        assert np.array_equal(f(0.0, x), pdw.rhs(x))
        assert np.array_equal(f.jac(0.0, x), pdw.jacobian(x))
    B = X.copy()
    B[2, 1] = np.nan
    out = f.batch(B)
    assert np.isnan(out[2]).all()
    rows = [0, 1, 3, 4]
    assert np.array_equal(out[rows], pdw.rhs(X[rows]))


@pytest.mark.parametrize("flags", ["01", "11", (1,), (0.9, 1.9), (0, 1, 1), [[0, 1, 1]], None,
                                   (0, 2), (True, 2.0)])
def test_model_functions_refuse_malformed_flags(flags):
    """rhs(x, flags='01') computed flags (1, 1); flags=(1,) broadcast; (0.9, 1.9) became (0, 1)."""
    with pytest.raises(pdw.InvalidInputError, match="flags"):
        pdw.rhs(X0, flags=flags)
    with pytest.raises(pdw.InvalidInputError, match="flags"):
        pdw.jacobian(X0, flags=flags)


def test_flags_accepted_forms_agree():
    """The accepted spellings of the same flags give the same numbers."""
    want = pdw.rhs(X0, flags=(0, 1))
    for f in ([0, 1], np.array([0, 1]), np.array([0, 1], dtype=np.intc), (np.int64(0), 1)):
        assert np.array_equal(pdw.rhs(X0, flags=f), want)


def test_model_functions_refuse_complex_and_misshapen_states():
    with pytest.raises(pdw.InvalidInputError, match="real"):
        pdw.rhs(X0 + 1j)
    with pytest.raises(pdw.InvalidInputError, match="shape"):
        pdw.rhs(X0.reshape(2, 4))
    with pytest.raises(pdw.InvalidInputError, match="anchors"):
        pdw.rhs(X0, anchors=(0.0,))


def test_model_function_errors_are_invalid_input():
    with pytest.raises(pdw.InvalidInputError, match="variant"):
        pdw.rhs(X0, variant="papr")
    with pytest.raises(pdw.InvalidInputError, match="params"):
        pdw.rhs(X0, params={"k_n": 1e5})
    with pytest.raises(pdw.InvalidInputError, match="feature"):
        pdw.rhs(X0, features=("hip_sprung",))
