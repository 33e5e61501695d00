"""Many touch-down step maps through the ensemble engine (pdw.analysis.stepmap.step_maps): the same
numbers as the scalar `step`, walker by walker, so find_gait, Floquet, continuation and cell
mapping do not move when they use it; and the stop condition it rests on (stop_touch_down)."""
import numpy as np
import pytest

import pdw
from pdw import cell_mapping as CM
from pdw import limit_cycle as LC
from pdw.analysis.stepmap import step_maps
from pdw.analysis.stepmap.gait_maps import ContinuousProblem
from pdw.core import _batch

P = pdw.Params.paper_steady()


@pytest.fixture(scope="module")
def gait():
    return LC.find_gait(P)


def _fd_points(z, h=1e-5):
    E = np.eye(len(z)) * h
    return [z] + [z + e for e in E] + [z - e for e in E]


@pytest.mark.parametrize("variant", ["paper", "consistent"])
def test_engine_images_are_the_scalar_steps_bitwise(gait, variant):
    """The 13 points of a finite-difference Jacobian, per-point parameters, tight and loose
    tolerances: z' of one `simulate_batch(stop_touch_down=1)` call is `step`'s z' bit for bit,
    and the lanes did the work."""
    z = gait.details["z"]
    pts = _fd_points(z)
    plist = [P.replace(k_hip=P.k_hip * (1 + 0.01 * i)) for i in range(len(pts))]
    for opts in (LC.TIGHT, LC.LOOSE):
        full = {**LC._step_defaults(), **opts, "t_hint": 0.6}
        _batch.lane_steps(reset=True)
        imgs = step_maps.images(pts, plist, variant, "rodas4", full, threads=2)
        assert _batch.lane_steps(reset=True) > 0
        for q, p, im in zip(pts, plist, imgs):
            s = LC.step(q, p, variant, "rodas4", t_hint=0.6, **opts)
            assert s["status"] == "ok"
            assert im is not None and np.array_equal(im, s["z"]), (im, s["z"])


def test_points_the_engine_leaves_go_to_step(gait):
    """A fall, no touch-down (too slow a start), and no touch-down inside the first window
    (t_hint far too short) come back as None; `compose_points` then runs `step` for them, so
    its answers (and statuses) are the scalar ones."""
    z = gait.details["z"]
    falls = z.copy()
    falls[2] += 1.0                             # the hip thrown forward: a fall
    slow = z.copy()
    slow[2] -= 1.0                              # the hip thrown back: no touch-down by t_max
    pts = [z, falls, slow, z + 1e-5]
    full = {**LC._step_defaults(), **LC.TIGHT}
    imgs = step_maps.images(pts, P, "paper", "rodas4", full)
    assert imgs[0] is not None and imgs[3] is not None and imgs[1] is None and imgs[2] is None
    outs = LC.compose_points(pts, 1, P, "paper", "rodas4", dict(LC.TIGHT), workers=2)
    for q, (val, steps) in zip(pts, outs):
        s = LC.step(q, P, "paper", "rodas4")
        assert steps[-1]["status"] == s["status"]
        if s["status"] == "ok":
            assert np.array_equal(val, s["z"])
        else:
            assert val is None
    assert [outs[1][1][-1]["status"], outs[2][1][-1]["status"]] == ["fell", "no_touch_down"]
    # the first window too short: every point is the scalar step's second window
    short = {**full, "t_hint": 0.05}
    assert step_maps.images([z], P, "paper", "rodas4", short) == [None]


def test_jacobian_floquet_and_find_gait_do_not_move(gait, monkeypatch):
    """The Jacobian through the engine is the thread pool's, bit for bit."""
    z = gait.details["z"]
    J1, P1, s1 = LC.jacobian(z, P, **LC.TIGHT)
    monkeypatch.setattr(step_maps, "batchable", lambda *a, **k: False)
    J0, P0, s0 = LC.jacobian(z, P, **LC.TIGHT)
    assert np.array_equal(J1, J0) and np.array_equal(P1, P0)
    assert s1[0]["period"] == s0[0]["period"]


def test_continuation_evaluation_does_not_move(gait, monkeypatch):
    prob = ContinuousProblem(P, "k_hip")
    z = gait.details["z"]
    e1 = prob.evaluate(z, P.k_hip)
    monkeypatch.setattr(step_maps, "batchable", lambda *a, **k: False)
    e0 = ContinuousProblem(P, "k_hip").evaluate(z, P.k_hip)
    assert e1.ok and e0.ok
    assert np.array_equal(e1.M, e0.M) and np.array_equal(e1.P_lam, e0.P_lam)
    assert np.array_equal(e1.Pz, e0.Pz)


def test_cell_map_images_are_map_batch(monkeypatch):
    """A small cell map (walks and falls): the engine's images and statuses are `map_batch`'s."""
    cm1 = CM.cell_map(P, phi=(0.55, 0.95, 4), thetad2=(-4.0, 0.0, 3))
    monkeypatch.setattr(step_maps, "batchable", lambda *a, **k: False)
    cm0 = CM.cell_map(P, phi=(0.55, 0.95, 4), thetad2=(-4.0, 0.0, 3))
    np.testing.assert_array_equal(cm1.image_point, cm0.image_point)
    assert list(cm1.status) == list(cm0.status)
    assert "ok" in set(cm1.status) and len(set(cm1.status)) > 1
    np.testing.assert_array_equal(cm1.image, cm0.image)


def test_batchable_is_what_the_engine_takes_bitwise():
    assert step_maps.batchable("rodas4") and step_maps.batchable("dopri5")
    assert not step_maps.batchable("cdm")                    # the section is interpolated
    assert not step_maps.batchable("rodas4", period=2)
    assert not step_maps.batchable("rodas4", options={"contact": {"friction": "lugre"}})
    assert not step_maps.batchable("rodas4", options={"contact": "hertz"})
    assert not step_maps.batchable("rodas4", options={"record": True})


@pytest.mark.parametrize("method", ["rodas4", "cdm"])
def test_stop_touch_down_ends_at_the_event(method):
    """simulate(stop=Stop(touch_down=k)) stops at leg k's first touch-down with the event's state:
    the sample a full recorded run has at that event; the batch says the same."""
    x0 = pdw.X0_PAPER
    full = pdw.simulate(x0, t_end=1.0, method=method, record=pdw.Record(events=True))
    td = next(e for e in full.events if e.kind == "touch_down" and e.leg == 1)
    r = pdw.simulate(x0, t_end=1.0, method=method, stop=pdw.Stop(touch_down=1))
    assert r.stop_reason == "touch_down" and r.status == "walked"
    i = int(np.argmin(np.abs(full.t - td.t)))
    assert r.t_final == pytest.approx(td.t, abs=0) or method == "cdm"
    np.testing.assert_array_equal(r.x_final, full.x[i])
    b = pdw.simulate_batch(np.array([x0]), t_end=1.0, method=method, stop=pdw.Stop(touch_down=1))
    assert b.stop_reason[0] == "touch_down"
    np.testing.assert_array_equal(b.x_final[0], r.x_final)


@pytest.mark.parametrize("bad", [3, -1, 1.5, "1", True])
def test_stop_touch_down_is_checked(bad):
    """Checked by the option object, and by each entry point given the table as a dict."""
    with pytest.raises(pdw.InvalidInputError, match=r"stop\.touch_down"):
        pdw.Stop(touch_down=bad)
    with pytest.raises(pdw.InvalidInputError, match=r"stop\.touch_down"):
        pdw.simulate(pdw.X0_PAPER, t_end=0.1, stop={"touch_down": bad})
    with pytest.raises(pdw.InvalidInputError, match=r"stop\.touch_down"):
        pdw.simulate_batch(np.array([pdw.X0_PAPER]), t_end=0.1, stop={"touch_down": bad})
