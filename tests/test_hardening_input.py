"""Issue 16, findings 8 and 9: malformed input never becomes other valid input, and every
error is a `pdw.InvalidInputError` naming the field (and the allowed range).
"""
import math
import subprocess
import sys

import numpy as np
import pytest

import pdw
from pdw.analysis.rigid import hybrid
from pdw.studies.study import parse_study

X0 = np.array(pdw.X0_PAPER)


# --- finding 8: nothing malformed is coerced ------------------------------------------------

@pytest.mark.parametrize("flags", ["01", "11", (1,), (0.9, 1.9), (0, 1, 1), [[0, 1, 1]], None,
                                   (0, 2), (True, 2.0)])
def test_model_functions_refuse_malformed_flags(flags):
    """rhs(x, flags='01') computed flags (1, 1); flags=(1,) broadcast; (0.9, 1.9) became (0, 1)."""
    with pytest.raises(pdw.InvalidInputError, match="flags"):
        pdw.rhs(X0, flags=flags)
    with pytest.raises(pdw.InvalidInputError, match="flags"):
        pdw.jacobian(X0, flags=flags)


@pytest.mark.parametrize("flags0", ["01", (1,), (0.9, 1.9), (0, 1, 0), (0, 5)])
def test_simulate_refuses_malformed_flags0(flags0):
    with pytest.raises(pdw.InvalidInputError, match="flags0"):
        pdw.simulate(t_end=0.01, flags0=flags0)


def test_flags_accepted_forms_agree():
    """The accepted spellings of the same flags give the same numbers."""
    want = pdw.rhs(X0, flags=(0, 1))
    for f in ([0, 1], np.array([0, 1]), np.array([0, 1], dtype=np.intc), (np.int64(0), 1)):
        assert np.array_equal(pdw.rhs(X0, flags=f), want)


@pytest.mark.parametrize("x0,what", [
    (np.tile(X0[:4], (2, 1)), "shape"),                 # (2, 4): 8 numbers, not a state
    (X0.reshape(2, 4), "shape"),
    (X0 + 0j, "real"),                                   # complex
    ([str(v) for v in X0], "real"),                      # strings
    (X0[:7], "shape"),
])
def test_simulate_refuses_states_that_are_not_states(x0, what):
    with pytest.raises(pdw.InvalidInputError, match=what):
        pdw.simulate(x0=x0, t_end=0.01)


def test_model_functions_refuse_complex_and_misshapen_states():
    with pytest.raises(pdw.InvalidInputError, match="real"):
        pdw.rhs(X0 + 1j)
    with pytest.raises(pdw.InvalidInputError, match="shape"):
        pdw.rhs(X0.reshape(2, 4))
    with pytest.raises(pdw.InvalidInputError, match="anchors"):
        pdw.rhs(X0, anchors=(0.0,))


@pytest.mark.parametrize("value", [math.nan, math.inf, "0.2", True])
def test_fall_hip_height_must_be_a_finite_number(value):
    """fall_hip_height = nan switched fall detection off."""
    with pytest.raises(pdw.InvalidInputError, match="fall_hip_height"):
        pdw.simulate(t_end=0.01, fall_hip_height=value)


_STUDY = """
name = "s"
[[axes]]
name = "k_n"
values = [1e5]
[run]
%(run)s
[scene]
%(scene)s
[scene.stop]
t_end = 1.0
[scene.integrator]
%(integrator)s
"""


@pytest.mark.parametrize("table,line,field", [
    ("scene", 'x0 = ["0", "0.5", "0", "0", "0", "0", "0", "0"]', "x0"),
    ("scene", "x0 = [0, 0.5, 0, 0]", "x0"),
    ("scene", "flags0 = [5, 7]", "flags0"),
    ("scene", "flags0 = [0.5, 1]", "flags0"),
    ("integrator", "dt = 2.0", "dt"),
    ("integrator", "rtol = nan", "rtol"),
    ("integrator", "atol = -1.0", "atol"),
    ("run", "period_tol = inf", "period_tol"),
    ("run", "steady = 0", "steady"),
])
def test_study_values_are_checked_as_simulate_checks(table, line, field):
    """Such [run] values loaded, and the sweep exited 0 with every row "error"."""
    parts = {"run": "", "scene": "", "integrator": "", table: line}
    with pytest.raises(pdw.InvalidInputError, match=field):
        parse_study(_STUDY % parts)


# --- finding 9: the error's type and field ------------------------------------------------------

@pytest.mark.parametrize("field,value", [("k_n", -1.0), ("l", math.nan), ("m_h", "2"),
                                         ("g", None), ("mu_s", 1j), ("v_s", True)])
def test_params_errors_are_invalid_input_naming_the_field(field, value):
    with pytest.raises(pdw.InvalidInputError, match=r"Params\.%s" % field):
        pdw.Params(**{field: value})


def test_model_function_errors_are_invalid_input():
    with pytest.raises(pdw.InvalidInputError, match="variant"):
        pdw.rhs(X0, variant="papr")
    with pytest.raises(pdw.InvalidInputError, match="params"):
        pdw.rhs(X0, params={"k_n": 1e5})
    with pytest.raises(pdw.InvalidInputError, match="feature"):
        pdw.rhs(X0, features=("hip_sprung",))


@pytest.mark.parametrize("value", [math.nan, None, 2 ** 70, 1.5, -1, "1", True])
def test_record_every_errors_name_the_field(value):
    with pytest.raises(pdw.InvalidInputError, match="record_every"):
        pdw.simulate(t_end=0.01, record_every=value)


def test_deeply_nested_toml_is_an_input_error_not_a_recursion_error(tmp_path):
    text = "a = " + "[" * 50000 + "]" * 50000 + "\n"
    with pytest.raises(pdw.InvalidInputError, match="nested"):
        pdw.Scene.from_toml(text)
    with pytest.raises(pdw.InvalidInputError, match="nested"):
        parse_study(text)
    f = tmp_path / "deep.toml"
    f.write_text(text)
    out = subprocess.run([sys.executable, "-m", "pdw", "run", str(f)], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode != 0
    assert "Traceback" not in out.stderr and "RecursionError" not in out.stderr
    assert "nested" in out.stderr + out.stdout


def test_a_huge_study_is_refused_before_any_allocation():
    with pytest.raises(pdw.InvalidInputError, match="num"):
        parse_study('name = "s"\n[[axes]]\nname = "k_n"\nstart = 1e4\nstop = 1e6\nnum = 10000000000000\n')
    two = ('name = "s"\n[[axes]]\nname = "k_n"\nstart = 1e4\nstop = 1e6\nnum = 100000\n'
           '[[axes]]\nname = "d_n"\nstart = 1e5\nstop = 1e6\nnum = 100000\n')
    with pytest.raises(pdw.InvalidInputError, match="points"):
        parse_study(two)


@pytest.mark.parametrize("opt,value", [("rtol", -1.0), ("atol", 0.0), ("min_step_angle", math.nan),
                                       ("fall_angle", 10.0), ("max_steps", 0), ("dt_out", -1e-3),
                                       ("h_max", math.inf), ("event_tol", "1e-9")])
def test_hybrid_options_are_range_checked(opt, value):
    """rtol = -1 was accepted; min_step_angle = nan reported a good step as "fell"."""
    y = np.array([0.2, -0.2, -1.0, -0.4])
    with pytest.raises(pdw.InvalidInputError, match=opt):
        hybrid.step(y, **{opt: value})


def test_hybrid_state_is_not_reshaped():
    with pytest.raises(pdw.InvalidInputError, match="shape"):
        hybrid.step(np.array([[0.2, -0.2], [-1.0, -0.4]]))
