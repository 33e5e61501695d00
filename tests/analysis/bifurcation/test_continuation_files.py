"""Branches as files, labels, events and plots (issue #24 e, c; docs/continuation.md)."""
import numpy as np
import pytest

import pdw
from pdw import hybrid as H
from pdw.analysis.bifurcation.continuation import continue_gait
from pdw.analysis.bifurcation.testfunctions import BUILTIN, KINDS, LABELS, Event

COMPASS = H.compass_gait_params()
DEG = np.pi / 180


@pytest.fixture(scope="module")
def short():
    """The compass gait from 3 to 4 deg: no bifurcation yet (the first doubling is at 4.39)."""
    return continue_gait(COMPASS, "gamma", 4.0 * DEG, model="hybrid")


def test_branch_file_round_trip_with_provenance(tmp_path, short):
    p = short.save(tmp_path / "b.npz")
    b = pdw.load(p)
    assert isinstance(b, pdw.Branch)
    for k in pdw.Branch.ARRAYS:
        np.testing.assert_array_equal(getattr(b, k), getattr(short, k))
    assert b.stop_reason == short.stop_reason and b.parameter == "gamma"
    assert b.provenance["pdw_version"] == pdw.__version__
    assert b.provenance["input_hash"] == pdw.INPUT_HASH and "written" in b.provenance


def test_a_loaded_branch_is_extended_to_the_same_period_doubling(tmp_path, short):
    """Extended from its last point (4 deg) to 5 deg, the loaded branch finds the doubling that
    one continuation from 3 to 5 deg finds, to the location tolerance."""
    b = pdw.load(short.save(tmp_path / "b.npz"))
    ext = b.extend(5.0 * DEG)
    assert ext.values[0] == pytest.approx(4.0 * DEG, abs=1e-15)
    (pd,) = ext.of_kind("period_doubling")
    direct = continue_gait(COMPASS, "gamma", 5.0 * DEG, model="hybrid")
    (pd0,) = direct.of_kind("period_doubling")
    assert pd.located and abs(pd.value - pd0.value) < 2e-8
    # saved with its bifurcations, the extended branch switches after a round trip
    again = pdw.load(ext.save(tmp_path / "ext.npz"))
    (pd2,) = again.of_kind("period_doubling")
    assert pd2.value == pd.value and pd2.label == pd.label == "PD1" and pd2.located
    g_loaded, g_orig = again.switch(pd2), ext.switch(pd)
    np.testing.assert_allclose(g_loaded.details["z"], g_orig.details["z"], atol=1e-12)


def test_bad_branch_files_are_refused(tmp_path, short):
    with pytest.raises(pdw.InvalidInputError, match="npz"):
        short.save(tmp_path / "b.csv")
    bad = tmp_path / "bad.npz"
    np.savez(bad, meta=np.array('{"format": "pdw-branch-1"}'), values=np.zeros(2))
    with pytest.raises(pdw.InvalidInputError, match="lacks"):
        pdw.load(bad)


def test_kinds_and_labels_derive_from_the_test_functions():
    assert KINDS[:4] == ("fold", "period_doubling", "neimark_sacker", "end")
    assert {t.kind for t in BUILTIN} | {"event"} == set(KINDS)
    assert [LABELS[k] for k in ("fold", "period_doubling", "neimark_sacker", "end",
                                "branch_point", "event")] == ["LP", "PD", "NS", "EP", "BP", "UZ"]


def test_user_event_step_length_located_and_reported():
    """events=[Event("step_length", L)]: located where the branch's step length is L,
    independently: find_gait at the located slope has that step length."""
    b0 = continue_gait(COMPASS, "gamma", 4.0 * DEG, model="hybrid")
    L = 0.5 * (b0.step_length[0] + b0.step_length[-1])
    b = continue_gait(COMPASS, "gamma", 4.0 * DEG, model="hybrid", locate_tol=1e-12,
                      events=[Event("step_length", L)])
    (ev,) = b.of_kind("event")
    assert ev.located and ev.label.startswith("UZ")
    g = H.find_gait(COMPASS.replace(gamma=ev.value))
    assert abs(g.step_length - L) < 1e-9
    assert not b0.of_kind("event")


def test_labels_run_along_the_branch():
    """The d_hip = 0.2 compass gait continued downwards has a fold then (maybe) more: labels
    are numbered in branch order."""
    b = continue_gait(COMPASS.replace(d_hip=0.2), "gamma", 0.2 * DEG, model="hybrid",
                      max_points=60)
    labels = [f.label for f in sorted(b.bifurcations, key=lambda f: f.index)]
    assert labels[0] == "LP1"
    assert [int(x[2:]) for x in labels] == list(range(1, len(labels) + 1))


def test_branch_plot_overlays_in_distinct_colours_with_units_and_labels(short):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    b2 = continue_gait(COMPASS, "gamma", 5.0 * DEG, model="hybrid")
    ax = short.plot(b2, y="step_length", x_scale=180 / np.pi)
    colours = {ln.get_color() for ln in ax.lines if ln.get_marker() in ("None", "")}
    assert colours == {"C0", "C1"}
    assert ax.get_xlabel() == "gamma [deg]" and ax.get_ylabel() == "step length [m]"
    assert "PD1" in [t.get_text() for t in ax.texts]
    # a third branch drawn on the same axes later takes the next colour
    short.plot(ax=ax, y="step_length", x_scale=180 / np.pi)
    assert "C2" in {ln.get_color() for ln in ax.lines}
    ax2 = pdw.plot_branches([short], y="z0")
    assert "theta_st" in ax2.get_ylabel() and "[rad]" in ax2.get_ylabel()
    with pytest.raises(pdw.InvalidInputError, match="y must be"):
        pdw.plot_branches([short], y="nope")
    plt.close("all")
