"""The axes of a parameter study (docs/studies.md): ``values``, a linear ``start``/``stop``/``num``
range, and ``log = true``, a geometric one (equal ratios, not equal differences)."""
import numpy as np
import pytest

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
