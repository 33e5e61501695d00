"""The lane scheduler shared by the lane loops (pdw_lanes_run in pdw/core/csrc/pdw_batch.c)
and the serial loop that small blocks take (pdw_batch_serial): bitwise the scalar runs, and
which loop did the work."""
import functools

import numpy as np
import pytest

import pdw
from pdw.core import _batch, interrupt
from pdw.sim.batch import ISA_ENV, simulate_batch

T_END = 1.2      # touch-downs, lift-offs, gait steps and falls

LANE_ISAS = [n for n in ("base", "avx2", "avx512") if _batch.isa_supported(n)]
KW = {"cdm": {}, "rodas4": dict(rtol=1e-6, atol=1e-8)}


def _states(n, seed):
    """n initial states around the paper's: a mix of walks and falls."""
    rng = np.random.default_rng(seed)
    x = np.tile(np.asarray(pdw.X0_PAPER, float), (n, 1))
    x[:, 6] += rng.uniform(-2.5, 0.5, n)
    x[:, 7] += rng.uniform(-0.5, 0.5, n)
    return x


def _assert_bitwise(b, i, x, method):
    """Walker i of batch b is bit for bit the scalar run from x."""
    r = pdw.simulate(x, t_end=T_END, method=method, record=pdw.Record(every=1, forces=False),
                     limits=pdw.Limits(on_failure="return"),
                     integrator=pdw.Integrator(check_step="off", **KW[method]))
    assert b.status[i] == r.status, i
    assert b.n_steps[i] == r.n_steps, i
    assert b.t_final[i] == r.t_final, i
    assert b.n_touch_down[i] == r.event_counts["touch_down"], i
    assert b.n_lift_off[i] == r.event_counts["lift_off"], i
    assert b.n_gait_steps[i] == r.n_gait_steps, i
    assert np.array_equal(b.x_final[i], r.x_final), (i, b.x_final[i] - r.x_final)


@pytest.mark.parametrize("isa", LANE_ISAS)
@pytest.mark.parametrize("method", ["cdm", "rodas4"])
@pytest.mark.parametrize("n, lanes", [(1, 8), (2, 8), (5, 1), (5, 2)])
def test_small_blocks_run_the_scalar_loop_bitwise(isa, method, n, lanes, monkeypatch):
    """A block that would hold at most 2 walkers (PDW_BATCH_SERIAL) runs each walker through
    its method's own loop, one after the other: bit for bit `simulate`, and no lane-step
    (the structure-of-arrays lanes would compute 8 lanes for them)."""
    monkeypatch.setenv(ISA_ENV, isa)
    x = _states(n, seed=5)
    _batch.lane_steps(reset=True)
    b = simulate_batch(x, t_end=T_END, method=method, lanes=lanes, threads=1,
                       integrator=pdw.Integrator(check_step="off", **KW[method]))
    assert _batch.lane_steps(reset=True) == 0
    assert {"walked", "fell"} <= set(b.status) or n < 5
    for i in range(n):
        _assert_bitwise(b, i, x[i], method)


@pytest.mark.parametrize("method", ["cdm", "rodas4"])
def test_three_walkers_take_the_lanes(method):
    """One walker more than PDW_BATCH_SERIAL: the lanes again, still bitwise."""
    x = _states(3, seed=5)
    _batch.lane_steps(reset=True)
    b = simulate_batch(x, t_end=T_END, method=method, lanes=8, threads=1,
                       integrator=pdw.Integrator(check_step="off", **KW[method]))
    assert _batch.lane_steps(reset=True) > 0
    for i in range(3):
        _assert_bitwise(b, i, x[i], method)


@pytest.mark.parametrize("method", ["cdm", "rodas4"])
@pytest.mark.parametrize("n", [1, 2])
def test_vector_batch_of_one_or_two_runs_the_scalar_loop(method, n):
    """vector=True permits the vector trig, it does not require it: a batch of at most
    SERIAL_WALKERS walkers runs the scalar loop with libm's sin/cos, so each walker is bit for
    bit its `simulate` run (the lanes' libmvec trig differs in the last bits) and no lane
    took a step."""
    assert _batch.SERIAL_WALKERS == 2
    x = _states(n, seed=5)
    _batch.lane_steps(reset=True)
    b = simulate_batch(x, t_end=T_END, method=method, lanes=8, threads=1, vector=True,
                       integrator=pdw.Integrator(check_step="off", **KW[method]))
    assert _batch.lane_steps(reset=True) == 0
    for i in range(n):
        _assert_bitwise(b, i, x[i], method)


def test_vector_trig_of_three_walkers_and_of_chunks_stays_in_the_lanes():
    """One walker more than SERIAL_WALKERS: vector=True runs the lanes; and in a chunked batch
    whose last chunk holds a single walker, that walker too runs the lanes, as unchunked (a
    walker's vector numbers do not depend on the chunk it is in)."""
    x = _states(3, seed=5)
    _batch.lane_steps(reset=True)
    simulate_batch(x, t_end=T_END, lanes=8, threads=1, vector=True,
                   integrator=pdw.Integrator(check_step="off"))
    assert _batch.lane_steps(reset=True) > 0
    x = _states(9, seed=6)
    _batch.lane_steps(reset=True)
    whole = simulate_batch(x, t_end=T_END, lanes=8, threads=1, vector=True,
                           integrator=pdw.Integrator(check_step="off"))
    in_lanes = _batch.lane_steps(reset=True)
    chunked = simulate_batch(x, t_end=T_END, lanes=8, threads=1, vector=True, chunk_size=8,
                             integrator=pdw.Integrator(check_step="off"))
    # the lanes commit a walker's ordinary steps wherever it runs: as many with the last
    # walker alone in its chunk (none if that chunk had taken the scalar loop)
    assert _batch.lane_steps(reset=True) == in_lanes > 0
    np.testing.assert_array_equal(chunked.x_final, whole.x_final)


@pytest.mark.parametrize("method, isa, n, lanes", [("cdm", "scalar", 4, 2),
                                                   ("cdm", "best", 1, 8),
                                                   ("cdm", "best", 12, 4),
                                                   ("rodas4", "scalar", 4, 2),
                                                   ("rodas4", "best", 1, 8),
                                                   ("rodas4", "best", 12, 4),
                                                   ("verlet", "best", 4, 2)])
def test_a_cancelled_token_stops_every_lane_loop(method, isa, n, lanes, monkeypatch):
    """Every loop polls through the one scheduler: with the thread's token cancelled before
    the call, the first poll stops the range and the batch raises KeyboardInterrupt with the
    walkers as they were (each started one has run at most a few thousand steps). Without a
    poll each of these runs would finish (20 s of walking) and return."""
    monkeypatch.setenv(ISA_ENV, _batch.best_isa() if isa == "best" else isa)
    x = np.tile(np.asarray(pdw.X0_PAPER, float), (n, 1))
    token = interrupt.Token()
    token.set()
    with pytest.raises(KeyboardInterrupt) as e:
        interrupt.call_with_token(token, functools.partial(
            simulate_batch, x, t_end=20.0, method=method, lanes=lanes, threads=1,
            integrator=pdw.Integrator(check_step="off", **KW.get(method, {}))))
    res = e.value.result
    assert np.all(res.t_final < 2.0), res.t_final
    assert np.all(np.isfinite(res.x_final))


@pytest.mark.parametrize("isa", LANE_ISAS)
def test_per_walker_friction_constants_follow_each_walker(isa, monkeypatch):
    """The cdm lanes compute the friction law's parameter-only terms (2/(v_d - v_s), ...)
    once per walker (contact_consts): with a different law per walker and more walkers than
    lanes (refills), each walker is still bit for bit its scalar run; constants left over
    from a lane's previous walker would change its numbers."""
    monkeypatch.setenv(ISA_ENV, isa)
    n = 9
    x = _states(n, seed=6)
    params = [pdw.Params.paper(v_s=1e-4 * (1 + 0.5 * i), v_d=1e-3 * (1 + 0.7 * i),
                               mu_s=0.5 + 0.05 * i) for i in range(n)]
    _batch.lane_steps(reset=True)
    b = simulate_batch(x, t_end=T_END, params=params, lanes=4, threads=1,
                       integrator=pdw.Integrator(check_step="off"))
    assert _batch.lane_steps(reset=True) > 0
    for i in range(n):
        r = pdw.simulate(x[i], t_end=T_END, params=params[i],
                         record=pdw.Record(every=1, forces=False),
                         limits=pdw.Limits(on_failure="return"),
                         integrator=pdw.Integrator(check_step="off"))
        assert b.status[i] == r.status, i
        assert b.n_steps[i] == r.n_steps, i
        assert np.array_equal(b.x_final[i], r.x_final), (i, b.x_final[i] - r.x_final)
    assert len(set(np.round(b.x_final[:, 6], 9))) > 1


@pytest.mark.parametrize("method", ["cdm", "rodas4"])
def test_vector_results_do_not_depend_on_lanes_or_threads(method):
    """The default lanes (16 for cdm, 8 otherwise), a thread's lanes capped at its share of
    the walkers, and one thread per 8 walkers are speed only: with vector=True (libmvec per
    8-lane chunk) every walker's result is the same bits whatever the lanes and threads, and
    the lanes do the work."""
    x = _states(21, seed=7)
    it = pdw.Integrator(check_step="off", **KW[method])
    _batch.lane_steps(reset=True)
    ref = simulate_batch(x, t_end=T_END, method=method, threads=1, vector=True, integrator=it)
    assert _batch.lane_steps(reset=True) > 0
    assert {"walked", "fell"} <= set(ref.status)
    for lanes, threads in ((None, 2), (3, 1), (8, 2), (64, 2)):
        b = simulate_batch(x, t_end=T_END, method=method, lanes=lanes, threads=threads,
                           vector=True, integrator=it)
        np.testing.assert_array_equal(b.x_final, ref.x_final)
        np.testing.assert_array_equal(b.status, ref.status)
        np.testing.assert_array_equal(b.n_touch_down, ref.n_touch_down)


def test_lane_width_computes_no_needless_chunk():
    """A thread's lanes (`lane_width`): never more than asked or than its walkers, one block
    for a share that fits, and 8 lanes where 16 would leave a generation half empty."""
    from pdw.sim.batch import LANES, lane_width
    assert LANES == 16
    for walkers in range(1, 200):
        for lanes in (1, 3, 8, 16, 64):
            w = lane_width(walkers, lanes)
            assert 1 <= w <= min(walkers, lanes), (walkers, lanes, w)
    assert [lane_width(m, 16) for m in (5, 12, 16, 24, 40, 64, 1000)] == [5, 12, 16, 8, 8, 16, 16]
    assert lane_width(24, 3) == 3
