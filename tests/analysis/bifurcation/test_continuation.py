"""Continuation of gaits, exact monodromy, bifurcations (pdw.analysis.bifurcation.continuation, docs/continuation.md)."""
import numpy as np
import pytest

import pdw
from pdw import hybrid as H
from pdw import limit_cycle as LC
from pdw.analysis.bifurcation.continuation import continue_gait, follow_cascade
from pdw.core import _hybrid
from pdw.core.errors import InvalidInputError
from pdw.core.model import parameter_vector

COMPASS = H.compass_gait_params()
DEG = np.pi / 180


def _simplest(gamma=0.009, m_l=1e-4):
    """Garcia et al.'s simplest walker: point feet, hip mass 1, leg mass at the foot -> 0,
    g = l = 1."""
    return pdw.Params(l=1.0, c=1.0, w=0.0, r=0.0, J_l=0.0, m_h=1.0, m_l=m_l, k_hip=0.0,
                      d_hip=0.0, gamma=gamma, g=1.0)


def _fd(f, x, h):
    return np.column_stack([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(len(x))])


# --- exact derivatives against finite differences -----------------------------------------------

@pytest.mark.parametrize("params", [COMPASS, pdw.Params.paper_steady()], ids=["compass", "steady"])
def test_emitted_stance_jacobian_and_impact_derivative_match_differences(params):
    p = parameter_vector(params)
    y = H.find_gait(params).state + np.array([0.01, -0.02, 0.05, 0.1])
    _, A = _hybrid.rhs_jac(p, np.ascontiguousarray(y))
    A_fd = _fd(lambda v: _hybrid.rhs(p, np.ascontiguousarray(v)), y, 1e-6)
    np.testing.assert_allclose(A, A_fd, atol=1e-7 * max(1, np.abs(A).max()))
    g = _hybrid.swing_foot_grad(p, np.ascontiguousarray(y))
    g_fd = _fd(lambda v: _hybrid.swing_foot(p, np.ascontiguousarray(v))[:1], y, 1e-6)[0]
    np.testing.assert_allclose(g, g_fd, atol=1e-8)
    ym = H.find_gait(params).details["y_minus"]
    D = _hybrid.impact_jac(p, np.ascontiguousarray(ym))
    D_fd = _fd(lambda v: _hybrid.impact(p, np.ascontiguousarray(v))["y_plus"], ym, 1e-6)
    np.testing.assert_allclose(D, D_fd, atol=1e-7)


@pytest.mark.parametrize("params", [COMPASS, pdw.Params.paper_steady(), _simplest()],
                         ids=["compass", "steady", "simplest"])
def test_exact_step_jacobian_and_multipliers_agree_with_finite_differences(params):
    gait = H.find_gait(params)
    p = parameter_vector(params)
    y = np.ascontiguousarray(gait.state)
    res, DP = _hybrid.step_jac(p, y, H._TIGHT)
    assert res["status"] == "ok"
    DP_fd = _fd(lambda v: H.step_map(v, params, **H._TIGHT), y, 1e-6)
    np.testing.assert_allclose(DP, DP_fd, atol=1e-6 * max(1, np.abs(DP).max()))
    b = continue_gait(params, "gamma", params.gamma * 1.01, model="hybrid", max_points=2)
    np.testing.assert_allclose(np.sort_complex(b.multipliers[0]),
                               np.sort_complex(gait.multipliers), atol=1e-6)
    m_exact, _ = H.floquet(gait.state, params, exact=True)
    np.testing.assert_allclose(np.sort_complex(m_exact), np.sort_complex(gait.multipliers),
                               atol=1e-6)
    _, DP2 = H.step_jacobian(gait.state, params)
    np.testing.assert_array_equal(DP2, DP)


# --- the compass gait's cascade (Goswami, Thuilot & Espiau 1998) ------------------------------------

@pytest.fixture(scope="module")
def cascade():
    return follow_cascade(COMPASS, "gamma", 5.3 * DEG, depth=2, model="hybrid", step=0.05 * DEG)


def test_compass_gait_first_period_doubling_near_4_37_degrees(cascade):
    pds = cascade[0].of_kind("period_doubling")
    assert len(pds) == 1
    pd = pds[0]
    assert abs(pd.value / DEG - 4.37) < 0.05           # literature: 4.37 deg by 0.01 deg steps
    assert pd.tolerance < 1e-6
    # independently, with the finite-difference multipliers of pdw.hybrid.find_gait:
    below = H.find_gait(COMPASS.replace(gamma=pd.value - 0.005 * DEG))
    above = H.find_gait(COMPASS.replace(gamma=pd.value + 0.005 * DEG))
    assert np.all(np.abs(below.multipliers) < 1.0)
    assert np.min(np.real(above.multipliers)) < -1.0
    # stable before, unstable after, on the branch itself
    v = cascade[0].values
    assert cascade[0].stable[v < pd.value].all() and not cascade[0].stable[v > pd.value].any()


def test_switching_gives_a_true_period_two_gait_and_the_second_doubling(cascade):
    b2 = cascade[1]
    assert b2.period_n == 2
    z = b2.z[0]
    params = COMPASS.replace(gamma=b2.values[0])
    y1 = H.step_map(H._y_of(z), params, **H._TIGHT)
    y2 = H.step_map(y1, params, **H._TIGHT)
    assert np.max(np.abs(y2[[0, 2, 3]] - z)) < 1e-8           # period two ...
    assert np.max(np.abs(y1[[0, 2, 3]] - z)) > 1e-3           # ... not one
    first = cascade[0].of_kind("period_doubling")[0].value
    assert b2.values.min() > first - 1e-6                   # supercritical: after the first
    pd2 = b2.of_kind("period_doubling")
    assert len(pd2) == 1 and 4.8 < pd2[0].value / DEG < 5.0
    # the third (period 4 -> 8) is closer still: the cascade accumulates
    pd3 = cascade[2].of_kind("period_doubling")[0].value
    assert (pd2[0].value - first) / (pd3 - pd2[0].value) > 3.0


def test_simplest_walker_loses_stability_by_period_doubling_near_0_015():
    b = continue_gait(_simplest(), "gamma", 0.02, model="hybrid")
    pds = b.of_kind("period_doubling")
    assert len(pds) == 1 and abs(pds[0].value - 0.015) < 5e-4    # Garcia et al.: 0.015
    assert b.stable[b.values < pds[0].value].all()


def test_fold_where_the_long_and_short_step_families_meet():
    """With a hip damper the walker needs a slope: continuing the slope downwards the gait
    turns back at a minimum slope onto a second (unstable) family."""
    params = COMPASS.replace(d_hip=0.2)
    b = continue_gait(params, "gamma", 0.2 * DEG, model="hybrid", max_points=60)
    folds = b.of_kind("fold")
    assert len(folds) == 1
    f = folds[0]
    assert f.value <= b.values.min() + 1e-9                      # the turning point
    assert np.min(np.abs(f.multipliers - 1.0)) < 1e-3           # a multiplier at +1
    # both families exist just above the fold: two distinct gaits at one slope
    g = f.value + 0.05 * DEG
    i1 = int(np.argmin(np.where(np.arange(len(b)) <= f.index, np.abs(b.values - g), np.inf)))
    i2 = int(np.argmin(np.where(np.arange(len(b)) > f.index, np.abs(b.values - g), np.inf)))
    pg = params.replace(gamma=g)
    g1 = H.find_gait(pg, guess=b.state[i1])
    g2 = H.find_gait(pg, guess=b.state[i2])
    assert np.max(np.abs(g1.state - g2.state)) > 1e-2
    assert g1.stable != g2.stable


def test_end_of_the_family_when_the_trailing_foot_stays_down():
    b = continue_gait(COMPASS, "gamma", 30 * DEG, model="hybrid", detect=("end",))
    ends = b.of_kind("end")
    assert len(ends) == 1 and "v_old_up" in ends[0].reason
    assert abs(ends[0].gait.details["z"][0]) > 0 and ends[0].tolerance < 1e-6
    # just below the end the impact throws the trailing foot up, just above it does not
    for dv, up in ((-1e-4, True), (1e-4, False)):
        pg = COMPASS.replace(gamma=ends[0].value + dv)
        gait = H.find_gait(pg, guess=ends[0].gait.state, settle_steps=0)
        assert (gait.details["v_old"][1] > 0) == up


def test_natural_and_arclength_agree_and_stop_at_the_bound():
    a = continue_gait(COMPASS, "gamma", 3.5 * DEG, model="hybrid", method="natural")
    b = continue_gait(COMPASS, "gamma", 3.5 * DEG, model="hybrid")
    assert a.values[-1] == pytest.approx(3.5 * DEG, abs=1e-12)
    assert b.values[-1] == pytest.approx(3.5 * DEG, abs=1e-12)
    np.testing.assert_allclose(a.z[-1], b.z[-1], atol=1e-8)
    assert "reached stop" in a.stop_reason


def test_continuation_to_the_edge_of_a_parameter_range():
    """k_hip -> 0 (its lower bound): one-sided parameter differences at the edge, and the
    last point exactly at 0, equal to find_gait's gait there."""
    params = pdw.Params.paper_steady()
    b = continue_gait(params, "k_hip", 0.0, model="hybrid")
    assert b.values[-1] == 0.0 and "reached stop" in b.stop_reason
    g = H.find_gait(params.replace(k_hip=0.0), guess=b.state[-1], settle_steps=0)
    np.testing.assert_allclose(g.state, b.state[-1], atol=1e-9)


def test_bad_input_names_the_field():
    with pytest.raises(InvalidInputError, match="parameter"):
        continue_gait(COMPASS, "slope", 0.1, model="hybrid")
    with pytest.raises(InvalidInputError, match="model"):
        continue_gait(COMPASS, "gamma", 0.1, model="rigid")
    with pytest.raises(InvalidInputError, match="stop"):
        continue_gait(COMPASS, "gamma", COMPASS.gamma, model="hybrid")
    with pytest.raises(InvalidInputError, match="k_n > 0"):
        continue_gait(COMPASS, "k_n", -1.0, model="hybrid", log=True)


def test_branch_csv_json_roundtrip(tmp_path, cascade):
    import csv
    import json
    b = cascade[0]
    b.to_csv(tmp_path / "b.csv")
    with open(tmp_path / "b.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == len(b)
    np.testing.assert_allclose([float(r["value"]) for r in rows], b.values, rtol=1e-15)
    b.to_json(tmp_path / "b.json")
    with open(tmp_path / "b.json", encoding="utf-8") as fh:
        js = json.load(fh)
    assert js["bifurcations"][0]["kind"] == "period_doubling"
    assert js["bifurcations"][0]["value"] == b.bifurcations[0].value


# --- the continuous model -----------------------------------------------------------------------

def test_continuous_branch_points_are_find_gait_fixed_points():
    from concurrent.futures import ThreadPoolExecutor
    params = pdw.Params.paper_steady()
    with ThreadPoolExecutor(2) as ex:
        b = continue_gait(params, "k_hip", 0.97, max_points=3, step=0.01, executor=ex)
    assert len(b) >= 2
    g = LC.find_gait(params.replace(k_hip=b.values[-1]), guess=b.z[-1])
    np.testing.assert_allclose(g.details["z"], b.z[-1], atol=1e-7)
    np.testing.assert_allclose(np.abs(b.multipliers[-1][:2]), np.abs(g.multipliers[:2]),
                               atol=1e-4)


@pytest.mark.slow
def test_continuous_d_hip_branch_ends_in_a_fold():
    params = pdw.Params.paper_steady(d_hip=0.010)
    b = continue_gait(params, "d_hip", 0.03, max_points=40)
    folds = b.of_kind("fold")
    assert len(folds) == 1 and 0.014 < folds[0].value < 0.015
    assert np.min(np.abs(folds[0].multipliers - 1.0)) < 1e-2
    from pdw.analysis.gait_types import GaitNotFoundError
    with pytest.raises(GaitNotFoundError):
        LC.find_gait(params.replace(d_hip=folds[0].value + 5e-4), guess=folds[0].gait)


# --- the engine on maps with known bifurcations -----------------------------------------------

class _Map:
    """A duck-typed problem (pdw.analysis.stepmap.gait_maps) for a smooth map with known bifurcations."""

    model, parameter, period, ADMISSIBLE = "map", "a", 1, {}

    def __init__(self, f, jac, dim):
        self.f, self.jac, self.dim, self.n_maps, self.opts = f, jac, dim, 0, {}

    def value(self, mu):
        return float(mu)

    def coord(self, v):
        return float(v)

    def evaluate(self, z, mu, jac=True):
        from pdw.analysis.stepmap.gait_maps import Evaluation
        self.n_maps += 1
        h = 1e-7
        P_lam = (self.f(z, mu + h) - self.f(z, mu - h)) / (2 * h)
        info = {"period": 1.0, "step_length": 1.0, "double_support": 0.0, "state": z,
                "orbit": np.array([z])}
        return Evaluation(True, "ok", self.f(z, mu), self.jac(z, mu), P_lam, info, {})

    def gait(self, z, mu, ev, mult):
        return pdw.Gait(state=z, period=1.0, step_length=1.0, double_support=0.0,
                        multipliers=mult, model="map")


def test_engine_locates_the_fold_and_period_doubling_of_a_quadratic_map():
    """z' = z + a - z^2: fixed points z = +-sqrt(a), a fold at a = 0, and on z = +sqrt(a) the
    multiplier 1 - 2 sqrt(a) passes -1 at a = 1."""
    from pdw.analysis.bifurcation.continuation import run_continuation
    m = _Map(lambda z, a: z + a - z ** 2, lambda z, a: np.array([[1 - 2 * z[0]]]), 1)
    b = run_continuation(m, [np.sqrt(2.0)], 2.0, -0.5, tol=1e-12, max_points=200)
    kinds = [(f.kind, f.value) for f in b.bifurcations]
    assert [k for k, _ in kinds] == ["period_doubling", "fold"]
    assert abs(kinds[0][1] - 1.0) < 3e-6 and abs(kinds[1][1]) < 3e-6
    assert b.z[-1, 0] < 0                                # continued round the fold


def test_engine_locates_the_neimark_sacker_of_the_delayed_logistic_map():
    """x' = y, y' = a y (1 - x): the fixed point's multipliers have |mu|^2 = a - 1, a complex
    pair crossing the unit circle at a = 2."""
    from pdw.analysis.bifurcation.continuation import run_continuation
    m = _Map(lambda z, a: np.array([z[1], a * z[1] * (1 - z[0])]),
             lambda z, a: np.array([[0.0, 1.0], [-a * z[1], a * (1 - z[0])]]), 2)
    a0 = 1.5
    b = run_continuation(m, [1 - 1 / a0, 1 - 1 / a0], a0, 2.5, tol=1e-12)
    ns = [f for f in b.bifurcations if f.kind == "neimark_sacker"]
    assert len(ns) == 1 and abs(ns[0].value - 2.0) < 1e-5
    assert not any(f.kind == "period_doubling" for f in b.bifurcations)
    assert b.stable[b.values < 2.0].all() and not b.stable[b.values > 2.0].any()


# --- command line and figure ----------------------------------------------------------------------

def test_cli_continue_writes_csv_json_and_diagram(tmp_path, capsys):
    import csv
    import json

    from pdw.present.cli import main
    assert main(["continue", "--example", "simplest_walker", "--out", str(tmp_path)]) == 0
    with open(tmp_path / "simplest_walker.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert {r["period_n"] for r in rows} == {"1", "2", "4"}
    with open(tmp_path / "simplest_walker.json", encoding="utf-8") as fh:
        js = json.load(fh)
    assert js["spec"]["toml"].startswith("#") and js["map_evaluations"] > 0
    pd = js["branches"][0]["bifurcations"][0]
    assert pd["kind"] == "period_doubling" and abs(pd["value"] - 0.015) < 5e-4
    assert (tmp_path / "simplest_walker.png").stat().st_size > 10000
    assert "period_doubling" in capsys.readouterr().out


def test_cli_continue_with_a_contact_section(tmp_path):
    """A continuation spec's [contact] selects the laws (continuous model): the branch's
    points are fixed points of that law's map (7 section coordinates for Flores: its trailing
    approach speed), not of the default law's; a bad law or a rigid model is refused."""
    import json

    from pdw.analysis.stepmap import limit_cycle as LC
    from pdw.present.cli_continue import load_spec, run_spec
    spec_file = tmp_path / "flores.toml"
    spec_file.write_text('name = "flores_k_hip"\nmodel = "continuous"\npreset = "paper_steady"\n'
                         'parameter = "k_hip"\nstop = 1.0\nstart = 0.95\n'
                         '[continuation]\nstep = 0.01\nmax_points = 2\nworkers = 2\n'
                         'detect = []\n[contact]\nnormal = "flores"\ne = 0.18\n')
    spec = load_spec(spec_file)
    (b,), paths = run_spec(spec, out=tmp_path)
    assert len(b) == 2 and b.z.shape == (2, 7)
    flores = pdw.Contact("flores", e=0.18)
    P = pdw.Params.paper_steady()
    for k in range(2):
        Pk = P.replace(k_hip=b.values[k])
        assert np.max(np.abs(LC.step_map(b.z[k], Pk, contact=flores) - b.z[k])) < 1e-8
    with open(paths["json"], encoding="utf-8") as fh:
        assert "flores" in json.load(fh)["spec"]["toml"]
    for bad, match in (('[contact]\nnormal = "rubber"\n', r"\[contact\].*normal"),
                       ('model = "hybrid"\n[contact]\nnormal = "flores"\n', "rigid ground")):
        f = tmp_path / "bad.toml"
        f.write_text('name = "x"\nparameter = "k_hip"\nstop = 1.0\n' + bad)
        with pytest.raises(pdw.InvalidInputError, match=match):
            load_spec(f)


def test_diagram_draws_stable_solid_and_unstable_dashed(cascade):
    import matplotlib
    matplotlib.use("Agg")
    from pdw.present.plots_continuation import plot_branches
    b = cascade[0]
    ax = plot_branches([b], y="step_length")
    styles = {ln.get_linestyle() for ln in ax.lines if ln.get_marker() in ("None", "")}
    assert styles == {"-", "--"}                 # stable before the doubling, unstable after
    pd = b.of_kind("period_doubling")[0]
    marks = [ln for ln in ax.lines if ln.get_marker() == "o"]
    assert len(marks) == 1 and marks[0].get_xdata()[0] == pytest.approx(pd.value)
    import matplotlib.pyplot as plt
    plt.close(ax.figure)


@pytest.mark.slow
def test_rigid_limit_continuation_reproduces_the_newton_table():
    """k_n 1e5 -> 1e9 in log k_n, consistent variant, d_n ~ k_n^(4/3), a point at each k_n of
    the rigid-limit table (docs/studies.md section 3, benchmarks/rigid_limit.py): the same
    period and step length, to the table's 6 digits."""
    table = {1e5: (0.574051, 0.300107), 1e7: (0.564938, 0.338931), 1e9: (0.564193, 0.340188)}
    p0 = pdw.Params.paper_steady()
    b = continue_gait(p0, "k_n", 1e9, variant="consistent", value=1e5, log=True,
                      params_of=lambda k: p0.replace(k_n=k, d_n=1e6 * (k / 1e5) ** (4 / 3)),
                      at=list(table))
    assert not b.bifurcations and "reached stop" in b.stop_reason
    for k, (P, L) in table.items():
        i = int(np.argmin(np.abs(np.log(b.values / k))))
        assert b.values[i] == pytest.approx(k, rel=1e-9)
        assert b.period[i] == pytest.approx(P, abs=2e-6)
        assert b.step_length[i] == pytest.approx(L, abs=2e-6)
