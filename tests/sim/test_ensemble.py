"""Ensembles around the batch engine (pdw.sim.ensemble): the scalar fallback, chunks over
executors, recorded subsets, simulate's end-of-run checks, the chunked/resumable basin."""
import math
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest

import pdw
from pdw.sim import ensemble as E
from pdw.sim.batch import simulate_batch

T_END = 1.2
FIELDS = ("status", "stop_reason", "x_final", "t_final", "n_steps", "flags_final",
          "failure_reason", "failure_t", "failure_x", "failure_leg", "n_touch_down",
          "n_lift_off", "n_gait_steps", "gait_rows")


def _states(n, seed=0):
    rng = np.random.default_rng(seed)
    x = np.tile(np.asarray(pdw.X0_PAPER, float), (n, 1))
    x[:, 6] += rng.uniform(-2.5, 0.5, n)
    x[:, 7] += rng.uniform(-0.5, 0.5, n)
    return x


def _assert_identical(a, b):
    assert len(a) == len(b)
    for f in FIELDS:
        u, v = getattr(a, f), getattr(b, f)
        if u.dtype == object:
            assert list(u) == list(v), f
        else:
            np.testing.assert_array_equal(u, v, err_msg=f)     # NaN == NaN here: bitwise


def test_scalar_path_is_the_batch_bitwise():
    """scalar_batch (pdw.simulate per walker) and the compiled lanes: the same BatchResult."""
    x = _states(13)
    params = [pdw.Params.paper(d_hip=d) for d in np.linspace(0.005, 0.03, 13)]
    b = simulate_batch(x, t_end=T_END, params=params, threads=1,
                       integrator=pdw.Integrator(check_step="off"))
    s = E.scalar_batch(x, t_end=T_END, params=params, threads=2,
                       integrator=pdw.Integrator(check_step="off"))
    assert s.engine == "scalar" and b.engine == "batch"
    assert {"walked", "fell"} <= set(b.status)
    _assert_identical(b, s)


def test_fallback_for_a_method_the_engine_refuses(monkeypatch):
    """simulate_many: the batch engine where it runs the method, pdw.simulate otherwise."""
    x = _states(5, seed=4)
    assert E.supports("cdm")
    m = E.simulate_many(x, t_end=T_END, threads=1, integrator=pdw.Integrator(check_step="off"))
    assert m.engine == "batch"
    # a method the engine refuses (rodas4 today; if it learns rodas4, force the refusal)
    E.supports.cache_clear()
    real = E.supports.__wrapped__
    monkeypatch.setattr(E, "supports", lambda method, variant="paper": False
                        if method in ("rodas4", "cdm") else real(method, variant))
    r = E.simulate_many(x, t_end=T_END, method="rodas4", threads=2,
                        integrator=pdw.Integrator(rtol=1e-6, atol=1e-8, check_step="off"))
    assert r.engine == "scalar"
    for i in range(len(x)):
        s = pdw.simulate(x[i], t_end=T_END, method="rodas4",
                         integrator=pdw.Integrator(rtol=1e-6, atol=1e-8, check_step="off"),
                         record=pdw.Record(every=1), limits=pdw.Limits(on_failure="return"))
        assert r.status[i] == s.status and r.n_steps[i] == s.n_steps
        np.testing.assert_array_equal(r.x_final[i], s.x_final)
        assert tuple(r.flags_final[i]) == tuple(s.flags[-1])
    c = E.simulate_many(x, t_end=T_END, threads=1, integrator=pdw.Integrator(check_step="off"))   # cdm, forced scalar
    assert c.engine == "scalar"
    _assert_identical(c, m)


def test_non_default_contact_law_takes_the_scalar_path():
    x = _states(2, seed=5)
    law = pdw.Contact(normal="kelvin_voigt")
    r = E.simulate_many(x, t_end=0.3, threads=1, contact=law,
                        integrator=pdw.Integrator(check_step="off"))
    assert r.engine == "scalar"
    s = pdw.simulate(x[1], t_end=0.3, contact=law, integrator=pdw.Integrator(check_step="off"),
                     record=pdw.Record(every=0), limits=pdw.Limits(on_failure="return"))
    np.testing.assert_array_equal(r.x_final[1], s.x_final)


@pytest.mark.parametrize("pool", [ProcessPoolExecutor, ThreadPoolExecutor])
def test_chunks_over_an_executor_are_the_unchunked_batch(pool):
    """Per-walker params and flags are cut with the chunks; order is kept."""
    x = _states(11, seed=6)
    params = [pdw.Params.paper(k_hip=k) for k in np.linspace(0.5, 1.5, 11)]
    f0 = [(0, 1) if i % 3 else (1, 1) for i in range(11)]
    ref = simulate_batch(x, t_end=T_END, params=params, flags0=f0, threads=1,
                         integrator=pdw.Integrator(check_step="off"))
    with pool(2) as ex:
        b = simulate_batch(x, t_end=T_END, params=params, flags0=f0, threads=1,
                           integrator=pdw.Integrator(check_step="off"), executor=ex,
                           chunk_size=4, record=[2, 9], record_every=5)
    _assert_identical(ref, b)
    assert sorted(b.recorded) == [2, 9]
    for i in (2, 9):
        np.testing.assert_array_equal(b.recorded[i].x_final, ref.x_final[i])
    serial = simulate_batch(x, t_end=T_END, params=params, flags0=f0, threads=1, chunk_size=3,
                            integrator=pdw.Integrator(check_step="off"))
    _assert_identical(ref, serial)
    with pytest.raises(pdw.InvalidInputError, match="chunk_size"):
        simulate_batch(x, t_end=T_END, chunk_size=0)
    with pytest.raises(pdw.InvalidInputError, match="record"):
        simulate_batch(x, t_end=T_END, chunk_size=4, record=[11])
    for bad in (0.0, "paper", [pdw.Params.paper()] * 3):
        with pytest.raises(pdw.InvalidInputError, match="params"):
            simulate_batch(x, t_end=T_END, chunk_size=4, params=bad)
        with pytest.raises(pdw.InvalidInputError, match="params"):
            E.scalar_batch(x, t_end=T_END, params=bad)


def test_recorded_subset_is_scalar_simulate():
    x = _states(6, seed=7)
    b = simulate_batch(x, t_end=T_END, threads=1, integrator=pdw.Integrator(check_step="off"),
                       record=[0, 3, 5], record_every=7)
    assert sorted(b.recorded) == [0, 3, 5]
    for i, r in b.recorded.items():
        s = pdw.simulate(x[i], t_end=T_END, integrator=pdw.Integrator(check_step="off"),
                         record=pdw.Record(every=7), limits=pdw.Limits(on_failure="return"))
        np.testing.assert_array_equal(r.t, s.t)
        np.testing.assert_array_equal(r.x, s.x)
        np.testing.assert_array_equal(r.flags, s.flags)
        np.testing.assert_array_equal(r.Fn, s.Fn)
        assert [(e.t, e.leg, e.kind) for e in r.events] == [(e.t, e.leg, e.kind)
                                                            for e in s.events]
        # the same arithmetic as the walker's lane (bitwise path)
        np.testing.assert_array_equal(r.x_final, b.x_final[i])
        assert r.status == b.status[i] and r.n_gait_steps == b.n_gait_steps[i]
        assert np.all(np.diff(r.t) > 0) and r.t[-1] <= b.t_final[i]
    with pytest.raises(pdw.InvalidInputError, match="record"):
        simulate_batch(x, t_end=T_END, record=[6], integrator=pdw.Integrator(check_step="off"))
    with pytest.raises(pdw.InvalidInputError, match="record_every"):
        simulate_batch(x, t_end=T_END, record=[1], record_every=0,
                       integrator=pdw.Integrator(check_step="off"))


def test_end_of_run_checks_as_simulate():
    """A walker standing still on level ground takes no step: simulate says "no_steps", and
    so does the batch (before: "walked")."""
    p = pdw.Params.paper(gamma=0.0)
    x = []
    for a in (0.2, 0.3):
        x.append([0.0, p.r + (p.l - p.r) * math.cos(a), -a, a, 0, 0, 0, 0])
    x = np.vstack([x, _states(1)])
    b = simulate_batch(x, t_end=8.0, params=p, flags0=(1, 1), threads=1,
                       integrator=pdw.Integrator(check_step="off"))
    for i in range(3):
        s = pdw.simulate(x[i], t_end=8.0, params=p, flags0=(1, 1),
                         integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=0),
                         limits=pdw.Limits(on_failure="return"))
        assert b.status[i] == s.status
        assert b.stop_reason[i] == s.stop_reason
    assert list(b.status[:2]) == ["no_steps", "no_steps"]


def test_basin_chunks_checkpoint_and_resume(tmp_path, monkeypatch):
    from pdw.analysis.basins import basin as B
    kw = dict(phi=(0.6, 0.9, 4), thetad2=(-3.5, -1.0, 3), t_end=6.0, threads=1)
    ref = B.basin(**kw, chunk_size=100)
    ck = tmp_path / "b.npz"
    a = B.basin(**kw, chunk_size=5, checkpoint=ck)
    np.testing.assert_array_equal(a.outcome, ref.outcome)
    np.testing.assert_array_equal(a.n_steps, ref.n_steps)
    assert a.cpu_time > 0 and a.wall_time > 0
    # an interrupted run: the last chunk missing from the checkpoint
    with np.load(ck) as c:
        d = {k: c[k] for k in c.files}
    d["outcome"][10:] = -1
    np.savez(ck, **d)
    calls = []
    real = B.simulate_batch
    monkeypatch.setattr(B, "simulate_batch", lambda x0, **o: calls.append(len(x0)) or real(x0, **o))
    r = B.basin(**kw, chunk_size=5, checkpoint=ck)
    assert calls == [1, 2]                      # the reference walker, then only chunk [10, 12)
    assert r.cpu_time > 0 and r.wall_time > 0        # times carried over the resume
    np.testing.assert_array_equal(r.outcome, ref.outcome)
    np.testing.assert_array_equal(r.n_steps, ref.n_steps)
    # other settings: the checkpoint is not reused
    calls.clear()
    B.basin(**kw, chunk_size=5, checkpoint=ck, match_tol=0.03)
    assert sum(calls) == 13
    with ThreadPoolExecutor(2) as ex:
        e = B.basin(**kw, chunk_size=5, executor=ex)
    np.testing.assert_array_equal(e.outcome, ref.outcome)


STUDY = """
name = "bsweep"
[scene]
preset = "paper_steady"
x0 = [0.0, 0.4969, -0.0582, 0.0582, 0.5092, 0.0186, 3.3338, -1.0093]
[scene.integrator]
method = "%s"
[scene.stop]
t_end = 4.0
[scene.limits]
on_failure = "return"
[[axes]]
name = "k_hip"
values = [0.3, 0.9, 1.5]
[[axes]]
name = "d_hip"
values = [0.005, 0.02, 0.2]
[run]
fallback = false
"""


def _rows_equal(rows, ref):
    assert [r["index"] for r in rows] == [r["index"] for r in ref]
    for r, s in zip(rows, ref):
        assert {k: v for k, v in r.items() if k != "wall_s"} == \
            {k: v for k, v in s.items() if k != "wall_s"}, (r, s)


@pytest.mark.parametrize("method,backend", [("cdm", "serial"), ("cdm", "process"),
                                            ("rodas4", "serial")])
def test_sweep_points_as_batches_are_the_scalar_rows(tmp_path, method, backend):
    """A cdm or rodas4 study runs as batches (groups of points with per-walker Params): every
    row is the row `run_point` computes for that point alone; the CSV read back is the same."""
    from pdw.studies.points import batchable
    from pdw.studies.study import parse_study
    from pdw.studies.sweep import read_rows, run_point, run_study
    st = parse_study(STUDY % method)
    assert batchable(st)
    res = run_study(st, tmp_path / backend, backend=backend, workers=2, progress=False)
    assert res.engine == "batch"
    ref = [run_point(st.task(k, v)) for k, v in st.points()]
    statuses = {r["status"] for r in ref}
    assert "walked" in statuses and len(statuses) > 1, statuses       # a mix
    for r, s in zip(res.rows, ref):
        for k, v in s.items():
            if k == "wall_s":
                continue
            w = r[k]
            assert (w == v) or (v == "" and w == "") or (isinstance(v, float) and
                                                        float(w) == v), (k, w, v)
    again = read_rows(res.paths["csv"], st)
    assert sorted(again) == [r["index"] for r in res.rows]


def test_sweep_with_a_method_the_engine_refuses_runs_point_by_point(tmp_path, monkeypatch):
    from pdw.studies import points as sweep_batch
    from pdw.studies.study import parse_study
    from pdw.studies.sweep import run_study
    st = parse_study(STUDY % "cdm")
    E.supports.cache_clear()
    monkeypatch.setattr(sweep_batch.ensemble, "supports", lambda m, v="paper": False)
    res = run_study(st, tmp_path, backend="serial", progress=False)
    assert res.engine == "scalar"
    monkeypatch.undo()
    E.supports.cache_clear()
    b = run_study(st, tmp_path / "b", backend="serial", progress=False)
    assert b.engine == "batch"
    _rows_equal(b.rows, res.rows)
    assert sweep_batch.batchable(parse_study(STUDY % "rodas4")) == E.supports("rodas4")
    off = run_study(st, tmp_path / "off", backend="serial", progress=False, batch=False)
    assert off.engine == "scalar"
    _rows_equal(off.rows, b.rows)


def test_chunks_over_a_dask_executor():
    """The same interface as sweeps: a Dask client's executor takes the chunks."""
    distributed = pytest.importorskip("distributed")
    x = _states(9, seed=8)
    ref = simulate_batch(x, t_end=T_END, threads=1, integrator=pdw.Integrator(check_step="off"))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        b = simulate_batch(x, t_end=T_END, threads=1, executor=client.get_executor(), chunk_size=4,
                           integrator=pdw.Integrator(check_step="off"))
    _assert_identical(ref, b)
