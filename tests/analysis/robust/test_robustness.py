"""Robustness measures (issue 22 items 3, 5): the hybrid model on a floor offset and on a
pdw.Ground, max_step, gait_sensitivity, first_passage, markov_chain. Each measure is checked
against a number computed here independently (docs/robustness.md)."""
import math

import numpy as np
import pytest

import pdw
from pdw import hybrid as H
from pdw.analysis.robust import first_passage as FP
from pdw.analysis.robust import robustness as R
from pdw.core import _hybrid
from pdw.core.model import parameter_vector

P = pdw.Params.paper_steady()


@pytest.fixture(scope="module")
def gait():
    return H.find_gait(P)


# --- the hybrid model on a floor offset and on a Ground ----------------------------------------

def test_floor_offset_moves_the_strike_to_the_offset_floor(gait):
    for dh in (-0.004, 0.003):
        res = H.step(gait.state, P, dh=dh)
        assert res["status"] == "ok"
        # the swing foot's height at the strike is the offset floor (event located to 1e-13 s)
        assert H.swing_foot(res["y_minus"], P)["y_sw"] == pytest.approx(dh, abs=1e-12)
        # after relabelling, the new swing (old stance) foot is -dh above the new stance level
        y = res["y_plus"]
        assert (P.l - P.r) * (math.cos(y[1]) - math.cos(y[0])) == pytest.approx(dh, abs=1e-12)
        assert res["h_touch"] == pytest.approx(dh)
    # a lower floor: a longer, later step
    lo, hi = H.step(gait.state, P, dh=-0.003), H.step(gait.state, P)
    assert lo["t_strike"] > hi["t_strike"] and lo["step_length"] > hi["step_length"]


def test_flat_ground_and_zero_offset_are_the_flat_code_path(gait):
    a = H.simulate_hybrid(P, gait.state, 6, dt_out=0.01)
    for g in (pdw.Ground.flat(), pdw.Ground.flat(offset=0.3), None):
        b = H.simulate_hybrid(P, gait.state, 6, dt_out=0.01, ground=g, dh=0.0)
        assert np.array_equal(a.t, b.t) and np.array_equal(a.y, b.y)


def test_step_ground_equals_the_floor_offset_at_that_step(gait):
    """A step-down edge between the stance foot and the landing point: the step over it is the
    step with dh = -H (the same event function up to h_st), the next ones flat again."""
    H_ = 0.004
    x_st = -P.r * gait.state[0]                     # stance contact point (s0 = 0)
    edge = x_st + 0.5 * gait.step_length
    ground = pdw.Ground.step(edge, -H_, width=0.01)
    tr = H.simulate_hybrid(P, gait.state, 3, dt_out=0.0, ground=ground)
    r0 = H.step(gait.state, P, dh=-H_)
    s0 = tr.steps[0]
    assert s0["status"] == "ok"
    assert s0["t_strike"] == pytest.approx(r0["t_strike"], abs=1e-9)
    assert np.allclose(s0["y_plus"], r0["y_plus"], atol=1e-8)
    assert s0["h_touch"] == pytest.approx(-H_, abs=1e-12)
    r1 = H.step(r0["y_plus"], P)
    assert tr.steps[1]["t_strike"] == pytest.approx(r1["t_strike"], abs=1e-8)
    # the hip of the recorded trajectory steps down with the ground
    assert tr.x[-1, 1] == pytest.approx(P.r + (P.l - P.r) * math.cos(tr.y[-1, 0]) - H_,
                                        abs=1e-9)


def test_a_riser_hit_is_a_trip_and_leaving_the_ground_is_reported(gait):
    x_st = -P.r * gait.state[0]
    # a 3 cm step up right where the foot lands: the foot meets its riser
    land = x_st + gait.step_length
    res = H.step(gait.state, P, ground=pdw.Ground.step(land - 0.002, 0.03, width=0.004))
    assert res["status"] == "tripped"
    res = H.step(gait.state, P, ground=pdw.Ground.step(5.0, -0.01, extent=(-1.0, 0.2)))
    assert res["status"] == "off_ground"


def test_hybrid_refuses_a_tilted_plane():
    with pytest.raises(pdw.InvalidInputError, match="gamma"):
        H.step(H.find_gait(P).state, P, ground=pdw.Ground.plane(0.01))


# --- exact sensitivities, the gait sensitivity norm --------------------------------------------

def test_step_sensitivities_to_the_floor_offset_match_central_differences(gait):
    p = parameter_vector(P)
    opts = dict(H._TIGHT)
    res, DP, Ym, ydh, Tg, Tdh = _hybrid.step_sens(p, gait.state, opts)
    e = 1e-6
    a = H.step(gait.state, P, dh=e, **opts)
    b = H.step(gait.state, P, dh=-e, **opts)
    assert Tdh == pytest.approx((a["t_strike"] - b["t_strike"]) / (2 * e), rel=1e-6)
    assert np.allclose(ydh, (a["y_minus"] - b["y_minus"]) / (2 * e), rtol=1e-5, atol=1e-6)
    _, DP0 = H.step_jacobian(gait.state, P)
    assert np.array_equal(DP, DP0)


def test_h2_norm_of_a_scalar_system_is_the_geometric_sum():
    a, b, c, d = 0.6, 2.0, 0.5, 0.3
    expect = math.sqrt(d * d + (c * b) ** 2 / (1 - a * a))
    assert R.h2_norm([[a]], [[b]], [[c]], [[d]]) == pytest.approx(expect, rel=1e-12)
    with pytest.raises(pdw.InvalidInputError, match="not stable"):
        R.h2_norm([[1.01]], [[b]], [[c]], [[d]])


def test_gait_sensitivity_equals_the_summed_response_of_a_direct_simulation(gait):
    names = ("step_time", "step_length", "thetad_st")
    G = pdw.gait_sensitivity(P, indicators=names, gait=gait)
    assert G.check["rel_diff"] < 1e-6                       # exact vs central differences
    resp = R.disturbance_response(P, e=1e-6, n_steps=150, indicators=names, gait=gait)
    assert G.norm == pytest.approx(math.sqrt((resp ** 2).sum()), rel=1e-3)
    for i, n in enumerate(names):
        assert G.per_indicator[n] == pytest.approx(math.sqrt((resp[:, i] ** 2).sum()), rel=1e-3)
    # step 0's response is D, step k's is C A^(k-1) B
    assert resp[0] == pytest.approx(G.D[:, 0], rel=1e-3)
    assert resp[3] == pytest.approx((G.C @ np.linalg.matrix_power(G.A, 2) @ G.B)[:, 0],
                                    rel=2e-3)


def test_gait_sensitivity_by_differences_is_the_cross_checks_system(gait):
    G = pdw.gait_sensitivity(P, gait=gait, indicators=("step_time", "speed"))
    F = pdw.gait_sensitivity(P, gait=gait, indicators=("step_time", "speed"), method="fd")
    assert G.method == "exact" and F.method == "fd" and F.check == {}
    assert F.norm == pytest.approx(G.check["fd_norm"], rel=1e-12)
    assert F.A.shape == G.A.shape and F.B.shape == G.B.shape


def test_gait_sensitivity_bad_input():
    with pytest.raises(pdw.InvalidInputError, match="method"):
        pdw.gait_sensitivity(P, method="newton")
    with pytest.raises(pdw.InvalidInputError, match="indicators"):
        pdw.gait_sensitivity(P, indicators=("hip_height",))
    with pytest.raises(pdw.InvalidInputError, match="model"):
        pdw.gait_sensitivity(P, model="rigid")


# --- max_step -----------------------------------------------------------------------------------

def _scan_ok(params, gait, height, direction, budget=100, tol=1e-3):
    """Independent: walk with plain step() calls; success = no failure in budget + 1 steps and
    the last 5 steps' length and time within tol of the gait's."""
    y = gait.state
    Ls, Ts = [], []
    for k in range(budget + 1):
        dh = (-height if direction == "down" else height) if k == 0 else 0.0
        r = H.step(y, params, dh=dh)
        if r["status"] != "ok" or r["old_foot_down"]:
            return False
        Ls.append(r["step_length"])
        Ts.append(r["t_strike"])
        y = r["y_plus"]
    L, T = np.array(Ls[-5:]), np.array(Ts[-5:])
    return bool((abs(L / gait.step_length - 1) <= tol).all()
                and (abs(T / gait.period - 1) <= tol).all())


@pytest.mark.parametrize("direction", ["down", "up"])
def test_max_step_hybrid_matches_a_brute_force_scan(gait, direction):
    m = pdw.max_step(P, direction=direction, gait=gait, h_tol=2e-5)
    grid = np.arange(1, 41) * 0.00025              # 0.25 mm to 10 mm
    first_fail = next(h for h in grid if not _scan_ok(P, gait, h, direction))
    last_ok = first_fail - 0.00025
    assert last_ok - 2e-5 <= m.height <= first_fail
    assert m.bracket[0] == m.height and m.bracket[1] - m.bracket[0] <= 2e-5
    assert m.steps_to_return > 0 and m.monotone
    # the result's own height does succeed, its bracket's upper end fails
    assert _scan_ok(P, gait, m.height, direction)
    assert not _scan_ok(P, gait, m.bracket[1], direction)


def test_max_step_bad_input():
    with pytest.raises(pdw.InvalidInputError, match="direction"):
        pdw.max_step(P, direction="sideways")
    with pytest.raises(pdw.InvalidInputError, match="budget"):
        pdw.max_step(P, budget=3)
    with pytest.raises(pdw.InvalidInputError, match="dh"):
        pdw.max_step(P, dh=0.01)
    # the hybrid model would ignore them: refused, not silently dropped
    with pytest.raises(pdw.InvalidInputError, match="ground"):
        pdw.max_step(P, ground=pdw.Ground.step(0.2, -0.004))
    with pytest.raises(pdw.InvalidInputError, match="executor"):
        from concurrent.futures import ThreadPoolExecutor
        with ThreadPoolExecutor(1) as ex:
            pdw.max_step(P, executor=ex)


# --- first passage ------------------------------------------------------------------------------

def test_mfpt_estimate_covers_a_known_geometric_failure_process():
    """Walkers failing with probability p = 0.01 each step (MFPT 100), censored at 150 steps:
    the interval covers 100 in about 95 % of 300 repetitions and the estimate is unbiased."""
    rng = np.random.default_rng(7)
    hits, est = 0, []
    for _ in range(300):
        t = rng.geometric(0.01, size=400)
        failed = t <= 150
        fp = FP.mfpt_estimate(np.minimum(t, 150), failed, max_steps=150)
        hits += fp.ci[0] <= 100 <= fp.ci[1]
        est.append(fp.mfpt)
    assert 0.92 <= hits / 300 <= 0.98
    assert np.mean(est) == pytest.approx(100, rel=0.02)
    # no censoring: the estimate is the sample mean, and Kaplan-Meier agrees
    t = rng.geometric(0.05, size=500)
    fp = FP.mfpt_estimate(t, np.ones(500, bool))
    assert fp.mfpt == pytest.approx(t.mean()) and fp.km_mean == pytest.approx(t.mean())


def test_first_passage_hybrid_is_chunk_independent_and_resumes(gait, tmp_path):
    kw = dict(sigma=0.002, walkers=24, max_steps=60, gait=gait, seed=3)
    a = pdw.first_passage(P, **kw)
    b = pdw.first_passage(P, chunk_size=5, threads=1, **kw)
    assert np.array_equal(a.steps, b.steps) and np.array_equal(a.failed, b.failed)
    assert a.failures > 0 and a.censored > 0            # both kinds of walkers in the test
    # walker i's own walk, by hand: its dh sequence through plain step() calls
    i = 4
    dh = FP.dh_sequence(3, i, 0.002, 60)
    y, n = gait.state, 0
    for k in range(60):
        r = H.step(y, P, dh=dh[k])
        n += 1
        if r["status"] != "ok" or r["old_foot_down"]:
            break
        y = r["y_plus"]
    assert a.steps[i] == n
    # a killed study: the file holds 10 walkers and half a line; the rerun runs the rest
    path = tmp_path / "fp.csv"
    pdw.first_passage(P, path=path, chunk_size=24, **kw)
    lines = path.read_text().splitlines()
    path.write_text("\n".join(lines[:12]) + "\n" + lines[12][:3])
    c = pdw.first_passage(P, path=path, chunk_size=5, **kw)
    assert np.array_equal(c.steps, a.steps) and c.meta["resumed"] == 10
    with pytest.raises(pdw.InvalidInputError, match="another first-passage study"):
        pdw.first_passage(P, path=path, **{**kw, "sigma": 0.003})


def test_first_passage_bad_input(gait):
    with pytest.raises(pdw.InvalidInputError, match="sigma"):
        pdw.first_passage(P, sigma=-0.001, gait=gait)
    with pytest.raises(pdw.InvalidInputError, match="walkers"):
        pdw.first_passage(P, sigma=0.001, walkers=0, gait=gait)


# --- the Markov chain ---------------------------------------------------------------------------

def test_markov_chain_mfpt_matches_monte_carlo_on_the_same_chain(gait):
    mc = pdw.markov_chain(P, sigma=0.002, n_dh=7, resolution=0.02, gait=gait)
    assert mc.complete and mc.n_cells > 10
    # rows of Q plus the failure probability sum to 1
    assert np.allclose(np.asarray(mc.Q.sum(axis=1)).ravel() + mc.fail, 1.0)
    steps, failed = mc.sample(3000, 5000, seed=1)
    fp = FP.mfpt_estimate(steps, failed, confidence=0.999)
    assert fp.censored == 0
    # the chain's exact MFPT vs the sample mean of its own first-passage times
    se = steps.std() / math.sqrt(len(steps))
    assert abs(steps.mean() - mc.mfpt) < 4 * se
    assert mc.lambda2 < 1 and mc.mfpt_eig > 1


# --- the spec and the command line ---------------------------------------------------------------

def test_robustness_spec_validation_names_the_key():
    from pdw.studies.robustness_spec import parse_spec

    ok = 'name = "x"\nmeasure = "max_step"\n'
    parse_spec(ok)
    bad = {
        ok + 'colour = "red"\n': "colour",
        'name = "x"\nmeasure = "max_speed"\n': "measure",
        ok + '[options]\ndirection = "down"\nbudgett = 3\n': "options.budgett",
        ok + '[params]\nk_hipp = 1.0\n': "params.k_hipp",
        ok + '[params]\nk_hip = "stiff"\n': "params.k_hip",
        ok + '[sweep]\nparameter = "k_hip"\nvalues = [0.5, "x"]\n': r"sweep.values\[1\]",
        ok + '[sweep]\nparameter = "k_hip"\nstart = 0.5\nstop = 1.0\n': "sweep.num",
        ok + '[sweep]\nparameter = "m_h"\nvalues = [1.0, -2.0]\n': "sweep.values",
        'name = "x"\nmeasure = "first_passage"\nmodel = "continuous"\n[ground]\n'
        'kind = "random"\nsigma = -0.01\n': "sigma",
        ok + '[ground]\nkind = "random"\nsigma = 0.01\n': "only measure",
        'name = "x"\nmeasure = "first_passage"\n': "options.sigma",
        'name = "x"\nmeasure = "first_passage"\nmodel = "continuous"\n': "ground",
        'name = "x"\nmeasure = "markov_chain"\nmodel = "continuous"\n': "markov_chain",
    }
    for text, match in bad.items():
        with pytest.raises(pdw.InvalidInputError, match=match):
            parse_spec(text)


def test_cli_robustness_writes_csv_json_figure_and_exits_2_on_a_bad_spec(tmp_path, capsys):
    import csv
    import json

    from pdw.present.cli import main

    spec = tmp_path / "gsn.toml"
    spec.write_text('name = "gsn"\nmeasure = "gait_sensitivity"\n[options]\n'
                    'indicators = ["step_time"]\n[sweep]\nparameter = "k_hip"\n'
                    'values = [0.75, 0.95]\n')
    assert main(["robustness", str(spec), "--out", str(tmp_path / "o")]) == 0
    rows = list(csv.DictReader(open(tmp_path / "o" / "gsn.csv")))
    assert [float(r["value"]) for r in rows] == [0.75, 0.95]
    G = pdw.gait_sensitivity(P, check=False)
    assert float(rows[1]["norm"]) == pytest.approx(G.norm, rel=1e-7)
    prov = json.loads((tmp_path / "o" / "gsn.json").read_text())
    assert prov["spec"]["toml"] == spec.read_text() and prov["code"]["input_hash"]
    assert (tmp_path / "o" / "gsn.png").stat().st_size > 1000
    spec.write_text('name = "gsn"\nmeasure = "gait_sensitivity"\n[options]\nindicator = 1\n')
    assert main(["robustness", str(spec), "--out", str(tmp_path / "o")]) == 2
    assert "options.indicator" in capsys.readouterr().err


def test_spec_sweep_does_not_walk_from_an_unstable_branch():
    """From k_hip 0.95 to 0.5 in one step the followed hybrid gait is another, unstable one
    (period 0.567 s, |mu| 2.30); the sweep falls back to the stable gait (0.668 s, 0.388)."""
    from pdw.studies.robustness_spec import parse_spec, run_spec

    spec = parse_spec('name = "g"\nmeasure = "gait_sensitivity"\n[options]\ncheck = false\n'
                      '[sweep]\nparameter = "k_hip"\nvalues = [0.95, 0.5]\n')
    rows, _, _ = run_spec(spec)
    jump = H.find_gait(P.replace(k_hip=0.5), guess=H.find_gait(P).state, settle_steps=0)
    assert max(abs(jump.multipliers)) > 2                 # the trap is still there
    stable = H.find_gait(P.replace(k_hip=0.5))
    G = pdw.gait_sensitivity(P.replace(k_hip=0.5), gait=stable, check=False)
    assert rows[1]["norm"] == pytest.approx(G.norm, rel=1e-9) and math.isfinite(G.norm)
    assert rows[1]["gait_mu_max"] == pytest.approx(0.388, abs=1e-3)
    assert rows[1]["gait_period"] == pytest.approx(stable.period, rel=1e-9)


# --- the compliant model --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def cgait():
    return pdw.find_gait(P)


def test_max_step_continuous_bracket_is_checked_by_direct_walks(cgait):
    from pdw.analysis.robust import robustness_continuous as RC

    m = pdw.max_step(P, model="continuous", gait=cgait, budget=30, h_tol=2e-4,
                     trials_per_round=4)
    assert 0.002 < m.height < 0.02 and m.bracket[1] - m.bracket[0] <= 2e-4
    edge = RC.edge_at(cgait)
    for h, ok in ((m.height, True), (m.bracket[1], False)):
        st, L, T = RC.walk(P, cgait, pdw.Ground.step(edge, -h, width=0.01), 31)
        good = st == "walked" and R.returned(L, T, cgait.step_length, cgait.period, 1e-3)[0]
        assert good == ok


def test_gait_sensitivity_continuous_matches_a_direct_step_down_response(cgait):
    from pdw.analysis.robust import robustness_continuous as RC

    G = pdw.gait_sensitivity(P, model="continuous", gait=cgait,
                             indicators=("step_time", "step_length"))
    assert G.method == "exact" and G.check["rel_diff"] < 1e-3
    e = 1e-4
    st, L, T = RC.walk(P, cgait, pdw.Ground.step(RC.edge_at(cgait), e, width=0.01), 40,
                       rtol=1e-11, atol=1e-12)
    resp = np.concatenate([(T - cgait.period) / e, (L - cgait.step_length) / e])
    assert G.norm == pytest.approx(math.sqrt((resp ** 2).sum()), rel=0.02)


def test_first_passage_continuous_each_walker_its_own_ground_and_resume(cgait, tmp_path):
    from pdw.analysis.robust import robustness_continuous as RC

    g = pdw.Ground.random(0.0025, 0.1)
    kw = dict(model="continuous", ground=g, walkers=6, max_steps=25, gait=cgait, seed=5)
    a = pdw.first_passage(P, chunk_size=6, threads=1, **kw)
    b = pdw.first_passage(P, chunk_size=2, path=tmp_path / "c.csv", **kw)
    assert np.array_equal(a.steps, b.steps) and a.failures > 0
    # walker 3 by hand: its own ground, seed 5 + 3
    st, L, _ = RC.walk(P, cgait, RC.walker_ground(g, 5, 3, 25, cgait.step_length), 25)
    expect = min(len(L) + 1, 25) if st not in ("walked", "off_ground") else min(len(L), 25)
    assert a.steps[3] == expect
    c = pdw.first_passage(P, path=tmp_path / "c.csv", **kw)
    assert c.meta["resumed"] == 6 and np.array_equal(c.steps, a.steps)
    with pytest.raises(pdw.InvalidInputError, match="Ground.random"):
        pdw.first_passage(P, model="continuous", ground=pdw.Ground.flat(), gait=cgait)


def test_first_passage_continuous_outcomes_censor_at_max_steps():
    """Steps up to and including the failing one; a walker still walking at max_steps is
    censored there, also when it falls in the run's last period and a half."""
    from types import SimpleNamespace

    from pdw.analysis.robust.robustness_continuous import outcomes

    b = SimpleNamespace(n_touch_down=np.array([5, 9, 10, 12, 10, 4]),
                        status=np.array(["fell", "fell", "fell", "diverged", "walked",
                                         "off_ground"]))
    steps, failed, status = outcomes(b, 10)
    assert steps.tolist() == [6, 10, 10, 10, 10, 4]
    assert failed.tolist() == [True, True, False, False, False, False]
    assert status.tolist() == ["fell", "fell", "ok", "ok", "ok", "ok"]


def test_first_passage_runs_on_an_executor_of_processes(gait, cgait):
    """Issue 22 item 5: the chunks are plain-data tasks for any executor (a process pool here,
    Dask's client.get_executor() alike); the walkers are those of the threads run."""
    from concurrent.futures import ProcessPoolExecutor

    hy = dict(sigma=0.002, walkers=12, max_steps=200, seed=3, gait=gait, chunk_size=5)
    co = dict(model="continuous", ground=pdw.Ground.random(0.0025, 0.1), walkers=3,
              max_steps=10, seed=2, gait=cgait, chunk_size=2)
    a, c = pdw.first_passage(P, **hy), pdw.first_passage(P, **co)
    with ProcessPoolExecutor(2) as ex:
        b, d = pdw.first_passage(P, executor=ex, **hy), pdw.first_passage(P, executor=ex, **co)
    assert np.array_equal(a.steps, b.steps) and np.array_equal(a.failed, b.failed)
    assert np.array_equal(c.steps, d.steps) and np.array_equal(c.status, d.status)
    assert a.failures > 0
