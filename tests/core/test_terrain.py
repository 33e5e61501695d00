"""Contact on a shaped ground (docs/terrain.md): the exactness checks of issue 22 item 4, patches,
the off-ground status."""
import math

import numpy as np
import pytest

import pdw
from pdw import Ground

P = pdw.Params.paper_steady()
TIGHT = dict(method="rodas4", integrator=pdw.Integrator(rtol=1e-11, atol=1e-13, event_tol=1e-12),
             record=pdw.Record(every=0))


def _plane_frame(x, d):
    """The state x of the walker on slope gamma + d (its own frame) in the frame of slope gamma,
    where it walks on Ground.plane(d): the plane's tangent t = (cos d, -sin d), normal
    n = (sin d, cos d), leg angles theta - d."""
    t = np.array([math.cos(d), -math.sin(d)])
    n = np.array([math.sin(d), math.cos(d)])
    H, Hd = x[0] * t + x[1] * n, x[4] * t + x[5] * n
    return np.array([H[0], H[1], x[2] - d, x[3] - d, Hd[0], Hd[1], x[6], x[7]])


@pytest.mark.parametrize("method", ["cdm", "rodas4"])
def test_flat_ground_is_todays_model_bitwise(method):
    kw = dict(t_end=1.5, params=P, method=method)
    a = pdw.simulate(**kw)
    for g in (Ground(), Ground.flat(), {"kind": "flat"}, None):
        b = pdw.simulate(ground=g, **kw)
        assert np.array_equal(a.x, b.x) and np.array_equal(a.Fn, b.Fn)
        assert [e.t for e in a.events] == [e.t for e in b.events]


def test_shaped_kernel_on_a_level_plane_is_the_flat_model():
    """The shaped-ground kernel itself (a plane of slope 0) reproduces the flat kernel: cdm to
    rounding, rodas4 (whose Jacobian is then a central difference) to its tolerance."""
    kw = dict(t_end=1.5, params=P, record=pdw.Record(every=0))
    a = pdw.simulate(**kw)
    b = pdw.simulate(ground=Ground.plane(0.0), **kw)
    assert np.abs(a.x_final - b.x_final).max() < 1e-12
    a = pdw.simulate(params=P, t_end=2.5, **TIGHT)
    b = pdw.simulate(params=P, t_end=2.5, ground=Ground.plane(0.0), **TIGHT)
    assert np.abs(a.x_final - b.x_final).max() < 1e-8


@pytest.mark.parametrize("variant", ["paper", "consistent"])
@pytest.mark.parametrize("d", [0.01, -0.008])
def test_tilted_plane_is_the_walker_on_the_steeper_slope(variant, d):
    """Ground.plane(slope=d) on slope gamma = the walker on slope gamma + d, seen in a frame
    rotated by d: the same periods and event times, step lengths along the plane (x_D along the
    slope / cos d), the same state (rotated) at the end."""
    kw = dict(t_end=2.5, variant=variant, **TIGHT)
    ref = pdw.simulate(pdw.X0_PAPER, params=P.replace(gamma=P.gamma + d), **kw)
    g = pdw.simulate(_plane_frame(np.array(pdw.X0_PAPER), d), params=P, ground=Ground.plane(d), **kw)
    assert ref.status == g.status == "walked" and ref.n_gait_steps == g.n_gait_steps >= 3
    assert np.abs(ref.gait["P"] - g.gait["P"]).max() < 1e-8
    assert np.abs(ref.gait["L"] - g.gait["L"] / math.cos(d)).max() < 1e-8
    assert np.abs(np.array([e.t for e in ref.events]) - [e.t for e in g.events]).max() < 1e-8
    assert np.abs(_plane_frame(ref.x_final, d) - g.x_final).max() < 1e-8
    # and it is not the walker on slope gamma
    flat = pdw.simulate(pdw.X0_PAPER, params=P, **kw)
    assert np.abs(flat.gait["P"][:2] - g.gait["P"][:2]).max() > 1e-4


@pytest.mark.parametrize("c", [0.03, -0.02])
def test_a_height_offset_changes_nothing_but_the_height(c):
    kw = dict(t_end=2.5, params=P, **TIGHT)
    a = pdw.simulate(ground=Ground.plane(0.0), **kw)
    x0 = np.array(pdw.X0_PAPER)
    x0[1] += c
    b = pdw.simulate(x0, ground=Ground.flat(offset=c), **kw)
    shifted = b.x_final.copy()
    shifted[1] -= c
    assert np.abs(shifted - a.x_final).max() < 1e-8
    assert np.abs(a.gait["P"] - b.gait["P"]).max() < 1e-10
    assert np.abs(a.gait["L"] - b.gait["L"]).max() < 1e-10


def test_a_patch_everywhere_is_the_changed_parameter():
    """Per-foot patched parameters = the parameter changed (same shaped kernel, same arithmetic)."""
    kw = dict(t_end=2.0, record=pdw.Record(every=0))
    a = pdw.simulate(params=P.replace(k_n=2e5, mu_s=0.6), ground=Ground.plane(0.0), **kw)
    b = pdw.simulate(params=P, ground=Ground.plane(0.0).with_patches(
        [dict(s_a=-10.0, s_b=40.0, k_n=2e5, mu_s=0.6)]), **kw)
    assert np.array_equal(a.x_final, b.x_final)
    c = pdw.simulate(params=P, ground=Ground.plane(0.0), **kw)
    assert not np.array_equal(a.x_final, c.x_final)
    far = pdw.simulate(params=P, ground=Ground.plane(0.0).with_patches(
        [dict(s_a=20.0, s_b=21.0, k_n=2e5)]), **kw)       # a patch the feet never reach
    assert np.array_equal(far.x_final, c.x_final)


def _contact_s(x):
    l, r = P.l, P.r
    return np.stack([x[:, 0] + (l - r) * np.sin(x[:, 2]), x[:, 0] + (l - r) * np.sin(x[:, 3])], 1)


@pytest.mark.parametrize("method", ["rodas4", "dopri5"])
def test_adaptive_methods_never_step_over_a_patch_edge(method):
    """Every blend-zone boundary that a support foot's contact point crosses is the end of an
    accepted step (located to event_tol), never crossed inside one."""
    g = Ground.flat(offset=0.0, blend=0.004).with_patches(
        [dict(s_a=0.05, s_b=0.09, k_n=3e4, d_n=3e5), dict(s_a=0.47, s_b=0.5, k_n=4e5)])
    zones = g.table().zones
    r = pdw.simulate(params=P, ground=g, t_end=2.0, method=method,
                     integrator=pdw.Integrator(rtol=1e-5, atol=1e-7, h_max=0.05),
                     record=pdw.Record(every=1))
    s = _contact_s(r.x)
    crossed = hit = 0
    for i in range(2):
        for z in zones:
            sup = (r.flags[:-1, i] == 1) & (r.flags[1:, i] == 1)
            over = sup & (np.minimum(s[:-1, i], s[1:, i]) < z - 1e-7) & (np.maximum(s[:-1, i], s[1:, i]) > z + 1e-7)
            crossed += int(over.sum())
            hit += int((np.abs(s[:, i] - z) < 1e-7).any())
    assert crossed == 0
    assert hit >= 4        # the feet did roll over the patches' edges


def test_off_ground_is_a_status():
    g = Ground.flat(extent=(-1.0, 1.5)).with_patches([dict(s_a=0.2, s_b=0.3, k_n=1e5)])
    r = pdw.simulate(params=P, ground=g, t_end=3.0, record=pdw.Record(every=0),
                     limits=pdw.Limits(on_failure="return"))
    assert r.status == "off_ground"
    assert "defined extent" in r.failure["reason"]
    assert r.failure["x"][0] + P.l > 1.5 - 1e-3


def test_bad_ground_argument():
    with pytest.raises(pdw.InvalidInputError, match="ground"):
        pdw.simulate(ground="bumpy", t_end=0.01)
    with pytest.raises(pdw.InvalidInputError, match="ground.sigma"):
        pdw.simulate(ground={"kind": "random", "sigma": -1.0}, t_end=0.01)


def test_result_carries_its_ground():
    g = Ground.step(1.0, -0.004)
    r = pdw.simulate(params=P, ground=g, t_end=0.2)
    assert r.ground == g


@pytest.mark.parametrize("variant", ["paper", "consistent"])
@pytest.mark.parametrize("ground", [Ground.sine(0.01, 0.7), Ground.random(0.003, 0.1, seed=4, extent=(-1, 3)),
                                    Ground.step(0.35, -0.01, width=0.05)], ids=lambda g: g.kind)
def test_derived_jacobian_is_the_derivative_of_the_rhs(variant, ground):
    """The shaped-ground Jacobian (derive/terrain.py ground_jacobian) against central differences
    of the shaped-ground right-hand side, feet in contact on the slope of the ground."""
    from pdw.core import _core
    from pdw.core.model import kernel_index, parameter_vector
    k = kernel_index(variant, None)
    p = parameter_vector(P)
    cg = _core.CGround(ground.table())
    x = np.array(pdw.X0_PAPER) + np.array([0.3, -0.003, 0.01, -0.02, 0.05, 0.01, 0.1, 0.2])
    anchors = np.array([0.1, 0.25, 0.0, 0.0])
    f = _core.ground_stage(k, cg, x, p, 1, 1, anchors)
    J = _core.ground_stage(k, cg, x, p, 1, 1, anchors, True)
    fd = np.zeros_like(J)
    for j in range(8):
        e = np.zeros(8)
        e[j] = h = 1e-7 * max(1.0, abs(x[j]))
        fd[:, j] = (_core.ground_stage(k, cg, x + e, p, 1, 1, anchors)
                    - _core.ground_stage(k, cg, x - e, p, 1, 1, anchors)) / (2 * h)
    assert np.abs(f[4:]).max() > 1.0            # forces act
    assert np.abs(J - fd).max() < 1e-8 * np.abs(J).max()


def test_scene_ground_table_round_trip_and_run():
    s = pdw.Scene(preset="paper_steady", stop={"t_end": 0.8}, ground={
        "kind": "steps", "edges": [0.5], "heights": [-0.004],
        "patches": [{"s_a": 0.2, "s_b": 0.4, "k_n": 5e4}]})
    assert isinstance(s.ground, Ground)
    back = pdw.Scene.from_toml(s.to_toml())
    assert back == s and back.ground == s.ground
    r = s.run()
    direct = pdw.simulate(params=pdw.Params.paper_steady(), t_end=0.8, ground=s.ground)
    np.testing.assert_array_equal(r.x_final, direct.x_final)
    assert "[ground]" not in pdw.Scene().to_toml()      # unset: flat, nothing written
    with pytest.raises(pdw.InvalidInputError, match="scene key 'ground'.*ground.sigma"):
        pdw.Scene(ground={"kind": "random", "sigma": -1.0})


def test_walk_figures_draw_the_ground(tmp_path):
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    from pdw.present import animation, plots
    g = Ground.steps([0.3], [-0.004], width=0.2).with_patches([dict(s_a=0.1, s_b=0.25, k_n=5e4)])
    r = pdw.simulate(params=P, t_end=0.6, ground=g, record=pdw.Record(every=50))
    fig = plots.fig_stick(r)
    ys = [line.get_ydata() for line in fig.axes[0].lines if len(line.get_ydata()) == 1200]
    assert ys and np.ptp(ys[0]) > 0.004            # the surface drawn is the step's, not a line
    assert any(line.get_color() == "tab:olive" for line in fig.axes[0].lines)     # the patch
    animation.animate(r, tmp_path / "walk.gif", duration=0.4, fps=5)
    assert (tmp_path / "walk.gif").stat().st_size > 0


def test_a_study_scene_with_a_ground_runs_its_points_on_it(tmp_path):
    """Study points on a shaped [scene.ground] run point by point through simulate(ground=)
    (never batched on flat ground): each row is the scalar run on that ground."""
    from pdw.studies import points
    from pdw.studies.study import parse_study
    text = """
name = "ground_study"
[scene]
preset = "paper_steady"
stop = { t_end = 1.5 }
ground = { kind = "steps", edges = [0.5], heights = [-0.004], width = 0.2 }
[[axes]]
name = "k_hip"
values = [0.9, 1.0]
[run]
steady = 1
"""
    study = parse_study(text, name="ground_study")
    assert study.scene.ground == Ground.steps([0.5], [-0.004], width=0.2)
    assert not points.batchable(study)
    for index, values in study.points()[:1]:
        row = points.run_point(study.task(index, values))
        r = pdw.simulate(params=pdw.Params.paper_steady().replace(k_hip=0.9), t_end=1.5,
                         method=study.scene.integrator.method, ground=study.scene.ground,
                         integrator=pdw.Integrator(rtol=study.scene.integrator.rtol, atol=study.scene.integrator.atol),
                         record=pdw.Record(every=study.scene.record.every),
                         limits=pdw.Limits(on_failure="return"))
        assert row["t_final"] == r.t_final and row["status"] == r.status


def test_compiled_ground_refuses_a_tampered_table():
    import dataclasses

    from pdw.core import _core
    t = Ground.sine(0.01, 0.5).table()
    for bad in (dict(lut_inv=float("nan")), dict(s_max=t.s_min), dict(lut=t.lut + len(t.cells)),
                dict(cells=t.cells[:, :5]), dict(arc=t.arc[:-1])):
        with pytest.raises(ValueError, match="ground table"):
            _core.CGround(dataclasses.replace(t, **bad))
    c = t.cells.copy()
    c[3, 4] = np.inf
    with pytest.raises(ValueError, match="finite"):
        _core.CGround(dataclasses.replace(t, cells=c))
    with pytest.raises(TypeError):
        _core.ground_stage(0, None, np.zeros(8), np.zeros(_core.NP), 1, 1, np.zeros(4))


@pytest.mark.parametrize("contact", [{"normal": "flores", "e": 0.5}, {"friction": "lugre"}],
                         ids=["flores", "lugre"])
def test_tilted_plane_with_other_contact_laws(contact):
    """Every contact law runs on the shaped ground unchanged (surface-frame kinematics); LuGre's
    bristle states ride along (its Jacobian: central differences)."""
    d = 0.01
    kw = dict(t_end=2.0, contact=contact,
              **dict(TIGHT, integrator=TIGHT["integrator"].replace(rtol=1e-10, atol=1e-12)))
    ref = pdw.simulate(pdw.X0_PAPER, params=P.replace(gamma=P.gamma + d), **kw)
    g = pdw.simulate(_plane_frame(np.array(pdw.X0_PAPER), d), params=P, ground=Ground.plane(d), **kw)
    assert ref.status == g.status == "walked" and ref.n_gait_steps == g.n_gait_steps >= 2
    assert np.abs(ref.gait["P"] - g.gait["P"]).max() < 1e-8
    assert np.abs(_plane_frame(ref.x_final[:8], d) - g.x_final[:8]).max() < 1e-7
    assert np.abs(ref.x_final[8:] - g.x_final[8:]).max() < 1e-9 if len(ref.x_final) > 8 else True
