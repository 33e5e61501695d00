"""pdw.Params: presets (docs/model.md sections 1 and 8) and validation (the error names the field and
its allowed range)."""
import dataclasses
import math
import re

import numpy as np
import pytest

import pdw
from pdw import Params

# docs/model.md section 1, typed in from the table
MODEL_MD_TABLE = dict(
    l=0.5, c=0.1, w=-0.0025, r=0.2, J_l=0.0398, m_h=2.0, m_l=1.0, k_hip=0.95, d_hip=0.018,
    gamma=0.02, g=9.8, k_n=1e5, d_n=1e6, k_t=90.0, d_t=900.0, v_s=1e-4, v_d=1e-3, mu_s=0.5, mu_d=0.4,
)


# --- presets --------------------------------------------------------------------------------
def test_paper_preset_is_model_md_table():
    p = Params.paper()
    assert p.as_dict() == MODEL_MD_TABLE
    assert Params() == p                              # the defaults are the paper's
    assert Params.preset("paper") == p


def test_paper_steady_preset_differs_only_in_d_hip():
    s = Params.paper_steady()
    assert s.d_hip == 0.010
    assert {**MODEL_MD_TABLE, "d_hip": 0.010} == s.as_dict()
    assert Params.preset("paper_steady") == s
    assert Params.paper_steady(k_hip=1.0).k_hip == 1.0 and Params.paper_steady(k_hip=1.0).d_hip == 0.010


def test_unknown_preset_is_refused():
    with pytest.raises(ValueError, match="paper_steady"):
        Params.preset("steady")


def test_as_array_follows_the_kernel_layout():
    p = Params.paper(k_t=12.5)
    arr = p.as_array()
    assert arr.dtype == float and arr.shape == (len(pdw.core._layout.PARAMS),)
    for i, name in enumerate(pdw.core._layout.PARAMS):
        assert arr[i] == getattr(p, name)


def test_weight():
    p = Params.paper()
    assert p.weight == pytest.approx(4.0 * 9.8 * math.cos(0.02), rel=1e-15)


def test_params_are_frozen_and_replace_validates():
    p = Params.paper()
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.l = 1.0
    q = p.replace(k_n=2e5)
    assert q.k_n == 2e5 and p.k_n == 1e5
    with pytest.raises(ValueError, match="k_n"):
        p.replace(k_n=-1.0)
    with pytest.raises(ValueError, match="k_nn"):
        p.replace(k_nn=1.0)


def test_integers_and_numpy_scalars_become_floats():
    p = Params.paper(m_h=3, k_n=np.float32(2e5))
    assert type(p.m_h) is float and p.m_h == 3.0
    assert type(p.k_n) is float and p.k_n == 2e5


# --- validation ---------------------------------------------------------------------------------
def _range_in(msg):
    """The message states the allowed range: "allowed: > 0.0", ">= -0.785 and <= 0.785", ..."""
    return re.search(r"allowed: *[<>]=? *-?[0-9]", msg) is not None


BAD = [
    # (field, value): every mass and length that must be positive, and other out-of-range values
    ("l", 0.0), ("l", -0.5),
    ("m_l", 0.0), ("m_l", -1.0),
    ("m_h", -2.0),
    ("c", -0.1),
    ("r", -0.01),
    ("J_l", -0.01),
    ("g", -9.8),
    ("k_n", 0.0), ("k_n", -1.0),
    ("d_n", -1.0), ("k_t", -1.0), ("d_t", -1.0),
    ("k_hip", -0.1), ("d_hip", -0.1),
    ("v_s", 0.0), ("v_s", -1e-4), ("v_d", 0.0),
    ("mu_s", -0.1), ("mu_d", -0.1),
    ("gamma", 1.0), ("gamma", -1.0),
]


@pytest.mark.parametrize("field,value", BAD, ids=["%s=%g" % fv for fv in BAD])
def test_out_of_range_is_refused_naming_field_and_range(field, value):
    with pytest.raises(ValueError) as exc:
        Params.paper(**{field: value})
    msg = str(exc.value)
    assert re.search(r"\b%s\b" % re.escape(field), msg), msg
    assert _range_in(msg), msg


# BUG (reported): the Params docstring says "a non-positive mass ... raises ValueError"; m_h = 0
# is accepted (with J_l = 0 as well, M is then singular: see test_model_physics).
@pytest.mark.parametrize("field", ["m_h", "m_l"])
def test_zero_mass_is_refused(field):
    with pytest.raises(ValueError, match=r"\b%s\b" % field):
        Params.paper(**{field: 0.0})


@pytest.mark.parametrize("field", sorted(MODEL_MD_TABLE))
@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf")], ids=["nan", "inf", "-inf"])
def test_non_finite_is_refused(field, bad):
    with pytest.raises(ValueError) as exc:
        Params.paper(**{field: bad})
    msg = str(exc.value)
    assert re.search(r"\b%s\b" % re.escape(field), msg) and "finite" in msg, msg


@pytest.mark.parametrize("value", ["abc", None, [1.0]])
def test_non_number_is_refused(value):
    with pytest.raises(ValueError, match=r"\bk_t\b"):
        Params.paper(k_t=value)


@pytest.mark.parametrize("r,l", [(0.5, 0.5), (0.6, 0.5), (0.3, 0.25)])
def test_foot_radius_must_be_below_leg_length(r, l):
    with pytest.raises(ValueError) as exc:
        Params.paper(r=r, l=l)
    msg = str(exc.value)
    assert re.search(r"\br\b", msg) and re.search(r"\bl\b", msg) and "r < l" in msg, msg


@pytest.mark.parametrize("v_s,v_d", [(1e-3, 1e-3), (2e-3, 1e-3)])
def test_stiction_velocity_must_be_below_dynamic_velocity(v_s, v_d):
    with pytest.raises(ValueError) as exc:
        Params.paper(v_s=v_s, v_d=v_d)
    msg = str(exc.value)
    assert re.search(r"\bv_s\b", msg) and re.search(r"\bv_d\b", msg) and "v_s < v_d" in msg, msg


def test_allowed_edge_values():
    assert Params.paper(r=0.0).r == 0.0                     # point feet
    assert Params.paper(w=0.0).w == 0.0 and Params.paper(w=0.05).w == 0.05
    assert Params.paper(w=-0.05).w == -0.05                 # w is a signed offset
    for f in ("k_hip", "d_hip", "d_n", "k_t", "d_t", "mu_s", "mu_d"):
        assert getattr(Params.paper(**{f: 0.0}), f) == 0.0   # force elements may be switched off
    assert Params.paper(gamma=0.0).gamma == 0.0 and Params.paper(gamma=-0.05).gamma == -0.05
    assert Params.paper(r=0.499).r == 0.499                 # just below l


def test_error_message_states_the_allowed_range_values():
    with pytest.raises(ValueError) as exc:
        Params.paper(l=-1.0)
    assert re.search(r"> ?0", str(exc.value)), str(exc.value)
    with pytest.raises(ValueError) as exc:
        Params.paper(gamma=2.0)
    msg = str(exc.value)
    assert "0.785" in msg or "pi" in msg, msg              # |gamma| <= pi/4


@pytest.mark.parametrize("field,value", [("k_n", -1.0), ("l", math.nan), ("m_h", "2"),
                                         ("g", None), ("mu_s", 1j), ("v_s", True)])
def test_params_errors_are_invalid_input_naming_the_field(field, value):
    with pytest.raises(pdw.InvalidInputError, match=r"Params\.%s" % field):
        pdw.Params(**{field: value})
