"""simulate_batch with a Ground per walker (issue 22 item 7): each walker bitwise its scalar run."""
import numpy as np
import pytest

import pdw
from pdw import Ground
from pdw.sim.batch import simulate_batch

P = pdw.Params.paper_steady()
T_END = 2.0


def _grounds():
    """Flat, steps down and up, a random ground per seed, a patch, a sine, one that runs out."""
    return [Ground(), Ground.step(0.7, -0.004), Ground.random(0.002, 0.1, seed=1, extent=(-1, 5)),
            None, Ground.random(0.002, 0.1, seed=2, extent=(-1, 5)),
            Ground.flat(patches=[dict(s_a=0.3, s_b=0.6, k_n=3e4, mu_s=0.3)]),
            Ground.step(0.5, 0.003), Ground.sine(0.002, 0.8, extent=(-1, 5)),
            Ground.flat(extent=(-1.0, 1.2))]


def _assert_same(b, i, r):
    assert b.status[i] == r.status, (i, b.status[i], r.status)
    assert b.n_steps[i] == r.n_steps
    assert b.t_final[i] == r.t_final
    assert b.n_touch_down[i] == r.event_counts["touch_down"]
    assert b.n_gait_steps[i] == r.n_gait_steps
    np.testing.assert_array_equal(b.x_final[i], r.x_final)
    for name in ("L", "P", "cycle"):
        np.testing.assert_array_equal(b.steps(i)[name], r.gait[name])
    if r.failure:
        assert b.failure_reason[i] == r.failure["reason"]
        np.testing.assert_array_equal(b.failure_x[i], r.failure["x"])


@pytest.mark.parametrize("method, lanes, threads", [("cdm", 4, 1), ("cdm", 8, 2), ("rodas4", 3, 1),
                                                    ("rk4", 4, 2)])
def test_each_walker_on_its_ground_is_its_scalar_run(method, lanes, threads):
    gs = _grounds()
    x = np.tile(np.asarray(pdw.X0_PAPER, float), (len(gs), 1))
    b = simulate_batch(x, t_end=T_END, params=P, method=method, lanes=lanes, threads=threads,
                       ground=gs, integrator=pdw.Integrator(check_step="off"))
    statuses = set()
    for i, g in enumerate(gs):
        r = pdw.simulate(x[i], t_end=T_END, params=P, method=method, ground=g,
                         integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=0),
                         limits=pdw.Limits(on_failure="return"))
        _assert_same(b, i, r)
        statuses.add(r.status)
    assert "off_ground" in statuses and "walked" in statuses
    # the grounds matter: the same walkers on flat ground end elsewhere
    flat = simulate_batch(x, t_end=T_END, params=P, method=method,
                          integrator=pdw.Integrator(check_step="off"))
    assert np.abs(flat.x_final[1] - b.x_final[1]).max() > 1e-6
    assert np.array_equal(flat.x_final[0], b.x_final[0])


def test_one_ground_for_all_and_chunks():
    x = np.tile(np.asarray(pdw.X0_PAPER, float), (5, 1))
    x[:, 6] += np.linspace(-0.2, 0.2, 5)
    g = Ground.step(0.7, -0.004)
    a = simulate_batch(x, t_end=T_END, params=P, ground=g,
                       integrator=pdw.Integrator(check_step="off"))
    c = simulate_batch(x, t_end=T_END, params=P, ground=[g] * 5, chunk_size=2, record=[3],
                       integrator=pdw.Integrator(check_step="off"))
    np.testing.assert_array_equal(a.x_final, c.x_final)
    assert c.recorded[3].ground == g
    np.testing.assert_array_equal(c.recorded[3].x_final, c.x_final[3])


def test_bad_ground_rows_are_named():
    x = np.tile(np.asarray(pdw.X0_PAPER, float), (2, 1))
    with pytest.raises(pdw.InvalidInputError, match="N = 2"):
        simulate_batch(x, t_end=0.1, ground=[Ground()])
    with pytest.raises(pdw.InvalidInputError, match=r"ground\[1\].*ground.sigma"):
        simulate_batch(x, t_end=0.1, ground=[None, {"kind": "random", "sigma": -1}])
    with pytest.raises(pdw.InvalidInputError, match="vector"):
        simulate_batch(x, t_end=0.1, ground=Ground.step(0.5, 0.01), vector=True)
