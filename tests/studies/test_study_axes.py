"""The axes of a parameter study (docs/studies.md): ``values``, a linear ``start``/``stop``/``num``
range, and ``log = true``, a geometric one (equal ratios, not equal differences)."""

import numpy as np
import pytest

import pdw
from pdw.studies.study import parse_study


def _axis(body):
    return parse_study("[[axes]]\nname = 'k_n'\n" + body).axes[0]


def test_log_axis_is_geometric():
    name, v = _axis("start = 1e4\nstop = 1e6\nnum = 5\nlog = true\n")
    assert name == "k_n"
    np.testing.assert_allclose(v, [1e4, 10 ** 4.5, 1e5, 10 ** 5.5, 1e6], rtol=1e-12)
    ratios = v[1:] / v[:-1]
    np.testing.assert_allclose(ratios, ratios[0], rtol=1e-12)


def test_linear_axis_is_arithmetic():
    _, v = _axis("start = 1e4\nstop = 1e6\nnum = 5\n")
    np.testing.assert_allclose(v, [1e4, 2.575e5, 5.05e5, 7.525e5, 1e6], rtol=1e-12)
    _, w = _axis("start = 1e4\nstop = 1e6\nnum = 5\nlog = false\n")
    np.testing.assert_array_equal(v, w)


def test_values_axis_is_taken_as_given():
    _, v = _axis("values = [3e5, 1e5, 2e5]\n")
    np.testing.assert_array_equal(v, [3e5, 1e5, 2e5])


@pytest.mark.parametrize("bounds", ["start = 0.0\nstop = 1e5", "start = -1.0\nstop = 1e5"])
def test_log_axis_needs_positive_bounds(bounds):
    with pytest.raises(ValueError, match="log axis needs start, stop > 0"):
        _axis(bounds + "\nnum = 3\nlog = true\n")


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


def test_a_huge_study_is_refused_before_any_allocation():
    with pytest.raises(pdw.InvalidInputError, match="num"):
        parse_study('name = "s"\n[[axes]]\nname = "k_n"\nstart = 1e4\nstop = 1e6\nnum = 10000000000000\n')
    two = ('name = "s"\n[[axes]]\nname = "k_n"\nstart = 1e4\nstop = 1e6\nnum = 100000\n'
           '[[axes]]\nname = "d_n"\nstart = 1e5\nstop = 1e6\nnum = 100000\n')
    with pytest.raises(pdw.InvalidInputError, match="points"):
        parse_study(two)
