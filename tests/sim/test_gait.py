"""Gait descriptors on hand-built event sequences (docs/model.md section 8 definitions)."""
import math

import numpy as np
import pytest

import pdw
from pdw import Event
from pdw.present.report import stance_forces


def _events():
    # leg 2 in stance from the start; leg 1 swings, touches down, then leg 2 lifts off ...
    return [
        Event(0.00, 2, "touch_down", 0.00, -0.001),
        Event(0.05, 1, "lift_off", -0.10, 0.0001),
        Event(0.60, 1, "touch_down", 0.40, -0.0001),
        Event(0.62, 2, "lift_off", 0.15, 0.0002),
        Event(1.20, 2, "touch_down", 0.81, -0.0001),
        Event(1.23, 1, "lift_off", 0.55, 0.0002),
        Event(1.80, 1, "touch_down", 1.20, -0.0001),
    ]


def test_descriptors_follow_the_definitions():
    st = pdw.steps(_events())
    assert len(st) == 3
    np.testing.assert_array_equal(st["leg"], [1, 2, 1])
    # step 1: leg 1 lands at 0.40; leg 2's own last touch-down was at 0.00
    assert st["L"][0] == pytest.approx(0.40)
    assert st["travel"][0] == pytest.approx(0.40 - (-0.10))
    assert st["P"][0] == pytest.approx(0.55)
    assert st["v"][0] == pytest.approx(0.40 / 0.55)
    assert st["cycle"][0] == pytest.approx(0.60)
    assert st["double_support"][0] == pytest.approx(0.02)
    assert st["ds_fraction"][0] == pytest.approx(0.02 / 0.60)
    # step 2: leg 2 lands at 0.81, leg 1's touch-down at 0.40
    assert st["L"][1] == pytest.approx(0.41)
    assert st["travel"][1] == pytest.approx(0.81 - 0.15)
    assert st["P"][1] == pytest.approx(1.20 - 0.62)
    assert st["double_support"][1] == pytest.approx(0.03)
    # last step: the other leg has not lifted off yet -> NaN
    assert math.isnan(st["double_support"][2])
    sd = st.steady(2)
    assert sd["L"] == pytest.approx((0.41 + 0.39) / 2)
    assert sd["spread_L"] == pytest.approx(0.02)


def test_first_partial_step_is_skipped_and_order_does_not_matter():
    ev = _events()
    a = pdw.steps(ev)
    b = pdw.steps(list(reversed(ev)))
    for k in a.table:
        np.testing.assert_array_equal(a.table[k], b.table[k])
    assert pdw.steps(ev[:3]).table["L"].tolist() == pytest.approx([0.40])
    assert len(pdw.steps(ev[:2])) == 0


def test_text_table_lists_every_step():
    txt = pdw.steps(_events()).to_text().splitlines()
    assert len(txt) == 4 and "L [m]" in txt[0]
    assert txt[1].split()[4] == "0.4000"


def test_typical_gait_descriptors_are_close_to_the_paper():
    """paper_steady (docs/model.md section 8): footprint L and P within about 10 % of the paper's."""
    r = pdw.simulate(t_end=12.0, params=pdw.Params.paper_steady(), record=pdw.Record(every=0))
    sd = pdw.steps(r).steady(4)
    assert sd["L"] == pytest.approx(0.397, rel=0.12)
    assert sd["P"] == pytest.approx(0.621, rel=0.12)
    assert sd["travel"] == pytest.approx(0.6, rel=0.1)
    assert 0.01 < sd["double_support"] < 0.03


def test_stance_forces_peak_settle_and_friction_sign_change():
    r = pdw.simulate(t_end=2.1)
    s = stance_forces(r)
    assert len(s) >= 2
    for st in s:
        assert st["Fn_peak"] > 2 * st["weight"]                      # impact peak
        assert st["Fn_settled"] == pytest.approx(st["weight"], rel=0.06)
        assert st["Ft_early"] < 0 < st["Ft_late"]                     # friction - to +
        assert any(d == "-+" for _, d in st["Ft_sign_changes"])


# --- issue 26, item 6: steady() says whether the steps it averages are steady ----------------

def _fell_after_one_step():
    """The paper's start with thetad1 x 0.8 takes one complete step and falls at 1.6 s
    (found by a scan of the start's rates)."""
    x = np.array(pdw.X0_PAPER)
    x[6] *= 0.8
    r = pdw.simulate(x, t_end=3.5, record=pdw.Record(every=0),
                     limits=pdw.Limits(on_failure="return"))
    assert r.status == "fell" and len(pdw.steps(r)) == 1
    return r


def test_steady_of_a_run_that_fell_after_one_step_is_not_converged():
    r = _fell_after_one_step()
    sd = pdw.steps(r).steady()
    assert sd["converged"] is False
    assert sd["last"] == 1 and sd["n_steps"] == 1
    assert np.isnan(sd["spread_L"])


def test_steady_of_a_transient_is_not_converged_and_of_a_converged_gait_is():
    r = pdw.simulate(t_end=3.5, record=pdw.Record(every=0))             # the paper's start: 5 steps, decaying
    sd = pdw.steps(r).steady()
    assert r.status == "walked" and sd["last"] == 4 and sd["converged"] is False
    assert sd["spread_L"] > 1e-3 * sd["L"]
    r = pdw.simulate(t_end=20, params=pdw.Params.paper_steady(), record=pdw.Record(every=0))
    sd = pdw.steps(r).steady()
    assert sd["converged"] is True
    assert sd["spread_L"] <= 1e-3 * sd["L"] and sd["spread_P"] <= 1e-3 * sd["P"]
    # the tolerance decides: tighter than the cdm grid's 2 dt on P, not converged
    assert pdw.steps(r).steady(rtol=1e-4)["converged"] is False


def test_steady_checks_its_arguments():
    st = pdw.steps(pdw.simulate(t_end=1.0, record=pdw.Record(every=0)))
    for bad in (0, 1.5, "4", True):
        with pytest.raises(pdw.InvalidInputError, match="last"):
            st.steady(bad)
    with pytest.raises(pdw.InvalidInputError, match="rtol"):
        st.steady(rtol=0.0)


def test_steps_of_a_batch_points_to_its_per_walker_steps():
    """Issue 26 item 12: pdw.steps(batch_result) says to use b.steps(i), not "not iterable";
    other wrong arguments name what pdw.steps takes."""
    b = pdw.simulate_batch(np.tile(pdw.X0_PAPER, (2, 1)), t_end=0.2)
    with pytest.raises(pdw.InvalidInputError, match=r"b\.steps\(i\)"):
        pdw.steps(b)
    for bad in (5, "events", [1, 2], None):
        with pytest.raises(pdw.InvalidInputError, match="a Result or a sequence of its Events"):
            pdw.steps(bad)
    r = pdw.simulate(t_end=1.5)                  # a one-pass iterator of events still works
    assert pdw.steps(iter(r.events)).table["L"].tolist() == pdw.steps(r).table["L"].tolist()
    assert len(pdw.steps(r)) == 2
