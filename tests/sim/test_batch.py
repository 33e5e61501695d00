"""The ensemble engine (pdw.simulate_batch) against the scalar pdw.simulate, walker by walker."""
import numpy as np
import pytest

import pdw
from pdw.core import _batch, _layout
from pdw.sim.batch import ISA_ENV, simulate_batch

T_END = 1.2      # long enough for touch-downs, lift-offs, gait steps and falls


def _states(n, seed=0):
    """n initial states around the paper's: a mix of walks and falls."""
    rng = np.random.default_rng(seed)
    x = np.tile(np.asarray(pdw.X0_PAPER, float), (n, 1))
    x[:, 6] += rng.uniform(-2.5, 0.5, n)      # thetad1: strongly negative ones fall
    x[:, 7] += rng.uniform(-0.5, 0.5, n)
    return x


def _scalar(x, params, integrator=None, **kw):
    integrator = (integrator or pdw.Integrator()).replace(check_step="off")
    return pdw.simulate(x, t_end=T_END, params=params, record=pdw.Record(every=1, forces=False),
                        limits=pdw.Limits(on_failure="return"), integrator=integrator, **kw)


def _assert_same(b, i, r, rtol=1e-12):
    assert b.status[i] == r.status, i
    assert b.stop_reason[i] == r.stop_reason, i
    assert b.n_steps[i] == r.n_steps
    assert b.t_final[i] == pytest.approx(r.t_final, rel=1e-15, abs=0)
    assert tuple(b.flags_final[i]) == tuple(r.flags[-1])      # the last sample's flags
    assert b.n_touch_down[i] == r.event_counts["touch_down"]
    assert b.n_lift_off[i] == r.event_counts["lift_off"]
    assert b.n_gait_steps[i] == r.n_gait_steps
    scale = np.maximum(np.abs(r.x_final), 1e-300)
    assert np.all(np.abs(b.x_final[i] - r.x_final) <= rtol * scale), (i, b.x_final[i], r.x_final)
    g_b, g_r = b.steps(i), r.gait
    assert len(g_b) == len(g_r)
    for name in ("L", "P", "cycle", "double_support"):
        np.testing.assert_array_equal(g_b[name], g_r[name])
    if r.failure:
        assert b.failure_reason[i] == r.failure["reason"]
        assert b.failure_t[i] == r.failure["t"]
        np.testing.assert_array_equal(b.failure_x[i], r.failure["x"])
        assert b.failure_leg[i] == (r.failure["leg"] or 0)
    else:
        assert b.failure_reason[i] == "none"


@pytest.mark.parametrize("n, lanes, threads", [(1, 8, 1), (11, 4, 1), (13, 8, 2)])
def test_every_walker_is_the_scalar_run(n, lanes, threads):
    """Batch of 1, non-full last blocks (11 = 2*4 + 3, 13 = 8 + 5), threads over ranges."""
    x = _states(n)
    b = simulate_batch(x, t_end=T_END, lanes=lanes, threads=threads, vector=False,
                       integrator=pdw.Integrator(check_step="off"))
    statuses = set()
    for i in range(n):
        r = _scalar(x[i], pdw.Params.paper())
        _assert_same(b, i, r)
        statuses.add(r.status)
    if n > 1:
        assert statuses >= {"walked", "fell"}, statuses     # the mix this test is about


def test_per_walker_params_and_stop_steps():
    x = _states(6, seed=1)
    x[:, 6] = pdw.X0_PAPER[6]                         # all start as the paper's walker...
    params = [pdw.Params.paper(d_hip=d) for d in np.linspace(0.005, 0.03, 6)]   # ...not alike
    b = simulate_batch(x, t_end=T_END, params=params, lanes=4, threads=1, vector=False,
                       integrator=pdw.Integrator(check_step="off"), stop=pdw.Stop(steps=2))
    for i in range(6):
        _assert_same(b, i, _scalar(x[i], params[i], stop=pdw.Stop(steps=2)))
    assert len(set(np.round(b.x_final[:, 6], 9))) > 1      # the parameters did act


def test_lanes_and_threads_do_not_change_results():
    """Each lane is independent: the vector path gives the same per-walker answer in any lane."""
    x = _states(20, seed=2)
    ref = simulate_batch(x, t_end=T_END, lanes=1, threads=1, vector=True,
                         integrator=pdw.Integrator(check_step="off"))
    for lanes, threads in ((8, 1), (5, 2), (16, 2)):
        b = simulate_batch(x, t_end=T_END, lanes=lanes, threads=threads, vector=True,
                           integrator=pdw.Integrator(check_step="off"))
        np.testing.assert_array_equal(b.x_final, ref.x_final)
        np.testing.assert_array_equal(b.status, ref.status)
        np.testing.assert_array_equal(b.n_touch_down, ref.n_touch_down)


def test_vector_path_agrees_in_outcome():
    """libmvec's sin/cos differ from libm's in the last bits; flag switches on the step grid
    turn that into step-sized shifts of events, so the states are not 1e-12 close (see
    docs/ensemble.md), but each walker's outcome and event counts are the scalar run's."""
    x = _states(12, seed=3)
    b = simulate_batch(x, t_end=T_END, lanes=8, threads=1, vector=True,
                       integrator=pdw.Integrator(check_step="off"))
    for i in range(12):
        r = _scalar(x[i], pdw.Params.paper())
        assert b.status[i] == r.status
        if r.status == "walked":
            assert b.n_touch_down[i] == r.event_counts["touch_down"]
            np.testing.assert_allclose(b.x_final[i], r.x_final, rtol=0.05, atol=0.05)


def test_bad_row_is_named():
    x = _states(5)
    x[3, 2] = np.nan
    with pytest.raises(pdw.InvalidInputError, match="row 3"):
        simulate_batch(x, t_end=T_END)
    with pytest.raises(pdw.InvalidInputError, match="row 2"):
        simulate_batch(_states(4), t_end=T_END, flags0=[(0, 1), (0, 1), (2, 1), (0, 1)])
    with pytest.raises(pdw.InvalidInputError, match="row 1"):
        simulate_batch(_states(2), t_end=T_END, params=[pdw.Params.paper(), "paper"])
    with pytest.raises(pdw.InvalidInputError, match=r"\(N, 8\)"):
        simulate_batch(np.zeros((3, 7)), t_end=T_END)
    with pytest.raises(pdw.InvalidInputError, match="method"):
        simulate_batch(_states(2), t_end=T_END, method="euler")
    with pytest.raises(pdw.InvalidInputError, match="vector"):
        simulate_batch(_states(2), t_end=T_END, method="dopri5", vector=True)
    with pytest.raises(pdw.InvalidInputError, match="rtol"):
        simulate_batch(_states(2), t_end=T_END, method="rodas4",
                       integrator=pdw.Integrator(rtol=0.0))
    with pytest.raises(pdw.InvalidInputError, match="row 1"):
        simulate_batch(_states(2), t_end=T_END, method="rodas4",
                       params=[pdw.Params.paper(), None])


def test_dataframe():
    pd = pytest.importorskip("pandas")
    x = _states(3)
    b = simulate_batch(x, t_end=T_END, integrator=pdw.Integrator(check_step="off"))
    df = b.to_dataframe()
    assert isinstance(df, pd.DataFrame) and len(df) == 3
    np.testing.assert_array_equal(df["x_thetad1"].to_numpy(), b.x_final[:, 6])
    walked = b.n_gait_steps > 0
    last = np.minimum(b.n_gait_steps, _layout.STEP_RING) - 1
    for i in np.nonzero(walked)[0]:
        assert df["last_L"][i] == b.gait_rows[i, last[i], _layout.STEP.index("L")]


def test_empty_batch():
    b = simulate_batch(np.zeros((0, 8)), t_end=T_END)
    assert len(b) == 0 and b.x_final.shape == (0, 8)


def test_basin_points_are_scalar_walks():
    """A 3 x 2 basin slice: each point's class follows from its scalar simulate run."""
    from pdw.analysis.basins import basin as B
    from pdw.analysis.basins import cell_mapping as cmap
    from pdw.analysis.stepmap import limit_cycle as lc
    b = B.basin(phi=(0.6, 0.9, 3), thetad2=(-3.5, -1.0, 2), t_end=6.0, threads=1)
    p = pdw.Params.paper_steady()
    rest = cmap.rest_of(b.reference, p)
    seen = set()
    for j, th in enumerate(b.thetad2):
        for i, ph in enumerate(b.phi):
            x = lc.embed(cmap.cell_state(ph, th, rest, p), p)
            r = pdw.simulate(x, t_end=6.0, params=p, flags0=(1, 1), record=pdw.Record(every=0),
                             stop=pdw.Stop(periodic=True, periodic_steps=4),
                             limits=pdw.Limits(on_failure="return"))
            assert b.n_steps[j, i] == r.n_gait_steps
            expect = {"fell": B.FELL, "diverged": B.FELL, "walked": B.UNDECIDED}.get(r.status)
            if r.status == "periodic":
                same = (abs(r.gait["L"][-1] - b.gait_L) <= 0.02 * b.gait_L
                        and abs(r.gait["P"][-1] - b.gait_P) <= 0.02 * b.gait_P)
                expect = B.GAIT if same else B.OTHER
            assert b.outcome[j, i] == expect, (ph, th, r.status)
            seen.add(int(b.outcome[j, i]))
    assert B.GAIT in seen and B.FELL in seen


def test_threads_and_lanes_are_checked():
    with pytest.raises(pdw.InvalidInputError, match="threads"):
        simulate_batch(_states(2), t_end=T_END, threads=0)
    with pytest.raises(pdw.InvalidInputError, match="lanes"):
        simulate_batch(_states(2), t_end=T_END, lanes=65)


# ---- the other methods: per-lane rounds through the scalar integrators' C ----------------

def _assert_bitwise(b, i, r):
    """_assert_same, and the final state bit for bit."""
    _assert_same(b, i, r, rtol=0.0)
    assert np.array_equal(b.x_final[i], r.x_final), (i, b.x_final[i] - r.x_final)


@pytest.mark.parametrize("n, lanes, threads", [(1, 8, 1), (11, 4, 1), (13, 8, 2)])
def test_rodas4_lanes_are_the_scalar_runs_bitwise(n, lanes, threads):
    """Each lane has its own step size, rejections and located events; resumed one accepted
    step at a time it is bit for bit `simulate(method="rodas4")`: batch of 1, non-full last
    blocks, threads, a mix of falls and walks."""
    x = _states(n, seed=4)
    b = simulate_batch(x, t_end=T_END, dt=1e-4, method="rodas4", lanes=lanes, threads=threads,
                       integrator=pdw.Integrator(rtol=1e-6, atol=1e-8))
    statuses = set()
    for i in range(n):
        r = _scalar(x[i], pdw.Params.paper(), method="rodas4",
                    integrator=pdw.Integrator(rtol=1e-6, atol=1e-8))
        _assert_bitwise(b, i, r)
        statuses.add(r.status)
    if n > 1:
        assert statuses >= {"walked", "fell"}, statuses
        # the lanes did take different step sequences (adaptive, not lockstep in time)
        assert len(set(b.n_steps[b.status == "walked"])) > 1


def test_rodas4_per_walker_params_tolerances_and_stop_conditions():
    x = _states(5, seed=5)
    x[:, 6] = pdw.X0_PAPER[6]
    params = [pdw.Params.paper(d_hip=d) for d in np.linspace(0.005, 0.03, 5)]
    kw = dict(integrator=pdw.Integrator(rtol=1e-5, atol=1e-7, h_max=2e-3, event_tol=1e-8),
              stop=pdw.Stop(steps=1))
    b = simulate_batch(x, t_end=T_END, params=params, method="rodas4", lanes=2, threads=1, **kw)
    for i in range(5):
        _assert_bitwise(b, i, _scalar(x[i], params[i], method="rodas4", **kw))
    assert set(b.stop_reason) == {"steps"}
    assert len(set(np.round(b.x_final[:, 6], 9))) > 1


def test_rodas4_step_budget_is_per_walker():
    x = _states(3, seed=6)
    b = simulate_batch(x, t_end=T_END, method="rodas4", lanes=2, threads=1,
                       integrator=pdw.Integrator(max_steps=50))
    for i in range(3):
        r = _scalar(x[i], pdw.Params.paper(), method="rodas4",
                    integrator=pdw.Integrator(max_steps=50))
        _assert_bitwise(b, i, r)
    assert "diverged" in set(b.status)


@pytest.mark.parametrize("method, dt", [("verlet", 4e-6), ("rk4", 4e-6), ("dopri5", 1e-4)])
def test_other_methods_are_the_scalar_runs_bitwise(method, dt):
    """The same per-lane rounds serve every method (explicit ones at a step they are stable
    at, past a lift-off and a touch-down)."""
    x = _states(3, seed=7)
    b = simulate_batch(x, t_end=0.4, dt=dt, method=method, lanes=2, threads=1,
                       integrator=pdw.Integrator(check_step="off"))
    assert np.all(b.n_touch_down >= 1) and np.all(b.n_lift_off >= 1)
    for i in range(3):
        r = pdw.simulate(x[i], t_end=0.4, dt=dt, method=method,
                         integrator=pdw.Integrator(check_step="off"),
                         record=pdw.Record(every=1, forces=False),
                         limits=pdw.Limits(on_failure="return"))
        _assert_bitwise(b, i, r)


# ---- the cdm lane loops: structure of arrays per instruction set, dispatched at run time ----

ISAS = [n for n in _batch.ISAS if _batch.isa_supported(n)]


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("variant, n, lanes", [("paper", 13, 8), ("consistent", 7, 3),
                                               ("paper", 70, 64)])
def test_every_lane_loop_is_bitwise_the_scalar_run(isa, variant, n, lanes, monkeypatch):
    """PDW_BATCH_ISA forces each loop this CPU runs (so the narrower ones are tested on a wide
    machine): the structure-of-arrays step (masks, the generated batched stages) is the scalar
    step bit for bit, events, falls and failures going through the scalar code."""
    monkeypatch.setenv(ISA_ENV, isa)
    x = _states(n, seed=8)
    b = simulate_batch(x, t_end=T_END, lanes=lanes, threads=1, variant=variant,
                       integrator=pdw.Integrator(check_step="off"))
    statuses = set()
    for i in range(n):
        r = _scalar(x[i], pdw.Params.paper(), variant=variant)
        _assert_bitwise(b, i, r)
        statuses.add(r.status)
    assert statuses >= {"walked", "fell"}, statuses


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("variant, n, lanes, threads", [("paper", 13, 8, 1), ("consistent", 7, 3, 1),
                                                        ("paper", 70, 64, 1), ("paper", 21, 4, 2)])
def test_every_rodas4_lane_loop_is_bitwise_the_scalar_run(isa, variant, n, lanes, threads,
                                                          monkeypatch):
    """rodas4's structure-of-arrays lanes (pdw_batch_ros.inc), per instruction set: each lane
    attempts its own step size in lockstep with the others (Jacobian, pivoted factors, six
    stages, error norm, the checks as masks), and rejects, accepts and adapts its step as the
    scalar driver; located events, failures, first and last steps go through the scalar rodas4.
    Every walker is bit for bit `simulate(method="rodas4")`, and the lanes did the work."""
    monkeypatch.setenv(ISA_ENV, isa)
    x = _states(n, seed=9)
    kw = dict(integrator=pdw.Integrator(rtol=1e-6, atol=1e-8), variant=variant)
    _batch.lane_steps(reset=True)
    b = simulate_batch(x, t_end=T_END, method="rodas4", lanes=lanes, threads=threads, **kw)
    in_lanes = _batch.lane_steps(reset=True)
    statuses = set()
    for i in range(n):
        r = _scalar(x[i], pdw.Params.paper(), method="rodas4", **kw)
        _assert_bitwise(b, i, r)
        statuses.add(r.status)
    assert statuses >= {"walked", "fell"}, statuses
    if isa == "scalar":
        assert in_lanes == 0
    else:
        # all but the rare steps (switches of flags or arming, falls, each walker's first and
        # last) were the lanes'
        assert in_lanes >= 0.9 * b.n_steps.sum(), (in_lanes, b.n_steps.sum())


def test_cdm_lanes_do_the_work():
    """The bitwise tests above could pass through the scalar fallback alone: the lane loop
    of the widest instruction set commits all but the event steps."""
    x = _states(13, seed=8)
    _batch.lane_steps(reset=True)
    b = simulate_batch(x, t_end=T_END, lanes=8, threads=1,
                       integrator=pdw.Integrator(check_step="off"))
    in_lanes = _batch.lane_steps(reset=True)
    assert 0.99 * b.n_steps.sum() <= in_lanes < b.n_steps.sum()


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("method", ["cdm", "rodas4"])
def test_vector_trig_is_lane_independent_per_isa(isa, method, monkeypatch):
    monkeypatch.setenv(ISA_ENV, isa)
    x = _states(11, seed=9)
    kw = dict(t_end=0.6, method=method, vector=True, integrator=pdw.Integrator(check_step="off"))
    ref = simulate_batch(x, lanes=1, threads=1, **kw)
    for lanes, threads in ((3, 1), (8, 1), (16, 1), (4, 2)):
        b = simulate_batch(x, lanes=lanes, threads=threads, **kw)
        np.testing.assert_array_equal(b.x_final, ref.x_final)
        np.testing.assert_array_equal(b.n_steps, ref.n_steps)


def test_rodas4_vector_trig_agrees_in_outcome():
    """rodas4's lanes with libmvec's sin/cos: not bitwise (the adaptive step sequence carries
    the last bits on), but every walker's outcome and event counts are the scalar run's and a
    walk's final state agrees to the tolerance's order. (Whether the states differ from the
    scalar ones at all depends on the build: `make sanitize`'s instrumented build leaves the
    loop unvectorized, calls libm's sin/cos in it and gets libm's bits.)"""
    x = _states(16, seed=4)
    kw = dict(integrator=pdw.Integrator(rtol=1e-6, atol=1e-8))
    b = simulate_batch(x, t_end=T_END, method="rodas4", lanes=8, threads=1, vector=True, **kw)
    for i in range(16):
        r = _scalar(x[i], pdw.Params.paper(), method="rodas4", **kw)
        assert b.status[i] == r.status
        assert b.n_touch_down[i] == r.event_counts["touch_down"]
        assert b.n_lift_off[i] == r.event_counts["lift_off"]
        if r.status == "walked":
            np.testing.assert_allclose(b.x_final[i], r.x_final, rtol=1e-3, atol=1e-4)


def test_isa_choice_is_checked(monkeypatch):
    monkeypatch.setenv(ISA_ENV, "sse9")
    with pytest.raises(pdw.InvalidInputError, match=ISA_ENV):
        simulate_batch(_states(2), t_end=0.1)
    missing = [n for n in _batch.ISAS if not _batch.isa_supported(n)]
    if missing:
        monkeypatch.setenv(ISA_ENV, missing[0])
        with pytest.raises(pdw.InvalidInputError, match="does not run"):
            simulate_batch(_states(2), t_end=0.1)


@pytest.mark.parametrize("method, isa", [("rodas4", None), ("cdm", ISAS[-1])])
def test_lane_loops_stop_on_a_cancel_token(method, isa, monkeypatch):
    """The per-method rounds and the SoA loop poll like the first loop: a cancelled token stops
    them within a second; finished walkers keep their rows, the others are "interrupted" at a
    finite state."""
    import threading
    import time

    from pdw.core import interrupt
    if isa:
        monkeypatch.setenv(ISA_ENV, isa)
    token, out = interrupt.Token(), {}

    def worker():
        interrupt._local.token = token
        t0 = time.monotonic()
        try:
            simulate_batch(np.tile(pdw.X0_PAPER, (3000, 1)), t_end=3.5, method=method, threads=1,
                           integrator=pdw.Integrator(check_step="off"))
            out["r"] = ("finished", time.monotonic() - t0, None)
        except KeyboardInterrupt as e:
            out["r"] = ("interrupted", time.monotonic() - t0, e.result)

    t = threading.Thread(target=worker)
    t.start()
    time.sleep(1.0)
    token.set()
    t.join(30)
    what, seconds, res = out["r"]
    assert what == "interrupted" and seconds < 3.0, out["r"]
    stopped = res.status == "interrupted"
    assert stopped.any() and np.isfinite(res.x_final).all()
    assert set(res.status[~stopped]) <= {"walked", "periodic", "fell", "diverged", "no_steps"}
