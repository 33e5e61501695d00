"""Limit cycles of the continuous model (pdw.limit_cycle, pdw.cell_mapping): the Poincaré map,
Newton shooting, Floquet multipliers, period-n, cell mapping, the rigid-ground limit."""
import math

import numpy as np
import pytest

import pdw
from pdw import cell_mapping as CM
from pdw import hybrid as H
from pdw import limit_cycle as LC
from pdw.analysis.gait_types import GaitNotFoundError

P = pdw.Params.paper_steady()


@pytest.fixture(scope="module")
def gait():
    return LC.find_gait(P)


@pytest.fixture(scope="module")
def long_run():
    """20 s from the paper's x0 with rodas4 at the Newton tolerances, every step recorded."""
    return pdw.simulate(t_end=20, params=P, method="rodas4", integrator=pdw.Integrator(**LC.TIGHT),
                        record=pdw.Record(every=1, forces=False))


def test_section_embedding_round_trip():
    z = np.array([-0.36, 0.38, 0.86, -0.19, -1.8, -1.67])
    x = LC.embed(z, P)
    lr = P.l - P.r
    assert x[0] + lr * math.sin(x[3]) == pytest.approx(0, abs=1e-15)          # x_D2 = 0
    assert x[1] - P.r - lr * math.cos(x[3]) == pytest.approx(0, abs=1e-15)    # y_D2 = 0
    np.testing.assert_array_equal(LC.section_coordinates(x, 2), z)
    # relabelling: a touch-down of leg 1 swaps the legs
    xs = x[[0, 1, 3, 2, 4, 5, 7, 6]]
    np.testing.assert_array_equal(LC.section_coordinates(xs, 1), z)
    with pytest.raises(pdw.InvalidInputError):
        LC.embed([1, 2, 3], P)


def test_gait_is_a_fixed_point_and_stable(gait):
    g = gait
    assert g.model == "continuous" and g.details["residual"] < 1e-9
    z = g.details["z"]
    np.testing.assert_allclose(LC.step_map(z, P, **LC.TIGHT), z, atol=2e-9)
    assert g.period == pytest.approx(0.580028, abs=2e-6)
    assert g.step_length == pytest.approx(0.368967, abs=2e-6)
    assert g.double_support == pytest.approx(0.016307, abs=2e-6)
    m = np.abs(g.multipliers)
    assert len(m) == 6 and g.stable
    # a complex dominant pair of modulus ~0.50, the rest small
    assert m[0] == pytest.approx(0.5009, abs=2e-3) and m[1] == pytest.approx(m[0], rel=1e-9)
    assert abs(g.multipliers[0].imag) > 0.1 and m[2] < 0.05
    # independent of the finite-difference step (10x larger) in the resolved multipliers
    np.testing.assert_allclose(np.abs(g.details["multipliers_check"][:3]), m[:3], atol=2e-3)
    # the state is a valid simulate() start with flags (1, 1) on the section
    assert g.state[0] + (P.l - P.r) * math.sin(g.state[3]) == pytest.approx(0, abs=1e-14)


def test_fixed_point_equals_long_simulation(gait, long_run):
    """The Newton fixed point is where a long simulation (no restarts) converges."""
    r = long_run
    assert r.status == "walked"
    td = [e for e in r.events if e.kind == "touch_down"][-1]
    i = int(np.argmin(np.abs(r.t - td.t)))
    z_sim = LC.section_coordinates(r.x[i], td.leg)
    np.testing.assert_allclose(z_sim, gait.details["z"], atol=1e-7)
    st = pdw.steps(r).steady(4)
    assert st["L"] == pytest.approx(gait.step_length, abs=1e-7)
    assert st["cycle"] == pytest.approx(gait.period, abs=1e-7)
    assert st["double_support"] == pytest.approx(gait.double_support, abs=1e-7)
    assert st["P"] == pytest.approx(gait.details["swing_period"], abs=1e-7)


def test_every_default_guess_converges_to_the_same_gait(gait):
    guesses = LC.default_guesses(P)
    assert len(guesses) >= 3
    z0 = gait.details["z"]
    for name, z in guesses[1:]:
        g = LC.find_gait(P, guess=z, max_iter=10)
        np.testing.assert_allclose(g.details["z"], z0, atol=1e-7, err_msg=name)


def test_period_two_search_finds_the_period_one_gait(gait):
    g2 = LC.find_gait(P, guess=gait.details["z"], period=2)
    np.testing.assert_allclose(g2.details["z"], gait.details["z"], atol=1e-7)
    assert g2.period == pytest.approx(2 * gait.period, abs=1e-7)
    # multipliers of P^2 are the squares of P's (dominant pair)
    np.testing.assert_allclose(np.abs(g2.multipliers[:2]), np.abs(gait.multipliers[:2]) ** 2,
                               atol=3e-3)
    d = LC.detect_period(P, z0=gait.details["z"], n_transient=2, n_max=3, tol=1e-5)
    assert d["kind"] == "period" and d["n"] == 1


def test_paper_damping_has_no_gait():
    """docs/model.md section 8: with the paper's d_hip = 0.018 the walker falls; no period-one gait."""
    Pp = pdw.Params.paper()
    d = LC.detect_period(Pp)
    assert d["kind"] == "fell"
    with pytest.raises(GaitNotFoundError):
        LC.find_gait(Pp, max_iter=6)


def test_step_reports_failures_without_raising():
    z = np.array([-0.05, 0.05, 0.1, 0.0, 0.0, 0.0])         # almost standing still: falls back
    s = LC.step(z, P, t_max=1.5)
    assert s["status"] in ("fell", "no_touch_down") and np.isnan(s["z"]).all()
    with pytest.raises(pdw.SimulationError):
        LC.step_map(z, P, t_max=1.5)


def test_fixed_step_map_is_close_but_quantised(gait):
    z = gait.details["z"]
    s = LC.step(z, P, method="cdm", dt=1e-5)
    assert s["status"] == "ok"
    assert abs(s["period"] - gait.period) < 5e-4
    assert np.max(np.abs(s["z"] - z)) < 1e-2


def test_unravel_simple_cell_map():
    # 0 -> 1 -> 2 -> 1 (period-2 group {1, 2}); 3 -> 3 (period 1); 4 -> 0; 5 -> sink; 6 -> 5
    image = [1, 2, 1, 3, 0, CM.SINK, 5]
    group, steps, periodic = CM.unravel(image)
    assert len(periodic) == 2
    assert sorted(periodic[0].tolist()) == [1, 2] and periodic[1].tolist() == [3]
    assert group.tolist() == [0, 0, 0, 1, 0, CM.SINK, CM.SINK]
    assert steps.tolist() == [1, 0, 0, 0, 2, 1, 2]


def test_newton_and_cell_mapping_agree(gait):
    z = gait.details["z"]
    fp = (z[1] - z[0], z[5])
    cm = CM.cell_map(P, phi=(0.70, 0.80, 25), thetad2=(-2.6, -0.8, 20))
    assert len(cm.periodic) >= 1
    da = np.diff(cm.a_edges)[0]
    db = np.diff(cm.b_edges)[0]
    A, B = cm.centers()
    # every periodic cell lies within 1.5 cells of Newton's fixed point ...
    for g in cm.periodic:
        assert np.all(np.abs(A[g] - fp[0]) <= 1.5 * da), (A[g], fp)
        assert np.all(np.abs(B[g] - fp[1]) <= 1.5 * db), (B[g], fp)
    # ... and Newton's cell is in a basin (not the sink)
    assert cm.group[cm.cell_of(*fp)] >= 0
    assert (cm.group >= 0).sum() > 0.3 * len(cm.group)


def test_rigid_limit_two_stiffnesses():
    """As k_n grows (d_n ~ k_n^(4/3): the contact's damping ratio at the static sink fixed), the
    consistent variant's gait approaches the hybrid model's and double support shrinks."""
    gh = H.find_gait(P)
    out = []
    guess = None
    for kn in (1e5, 1e7):
        Pk = P.replace(k_n=kn, d_n=P.d_n * (kn / P.k_n) ** (4 / 3))
        g = LC.find_gait(Pk, variant="consistent", guess=guess)
        guess = g
        out.append(g)
    (g1, g2) = out
    assert abs(g2.period - gh.period) < 0.15 * abs(g1.period - gh.period)
    assert abs(g2.step_length - gh.step_length) < 0.1 * abs(g1.step_length - gh.step_length)
    assert abs(g2.period - gh.period) < 2e-3 and abs(g2.step_length - gh.step_length) < 3e-3
    assert g2.double_support < 0.1 * g1.double_support and g2.double_support < 5e-3
    assert abs(g2.multipliers[0]) == pytest.approx(abs(gh.multipliers[0]), abs=0.02)


@pytest.mark.slow
def test_limit_cycle_studies(repo_root):
    """benchmarks/limit_cycles.py (fixed points, basin.png) and benchmarks/rigid_limit.py
    (fig8.png, rigid_limit.png): a few minutes; `make study`."""
    import sys
    sys.path.insert(0, str(repo_root / "benchmarks"))
    import limit_cycles
    import rigid_limit
    limit_cycles.main()
    rigid_limit.main()
    for name in ("basin", "fig8", "rigid_limit"):
        assert (repo_root / "docs" / "figures" / (name + ".png")).exists()
