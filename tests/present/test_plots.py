"""Tests of pdw.present.plots: files written, image sizes, GIF frames, the double-support zoom."""
import io
import subprocess
import sys

import numpy as np
import pytest

import pdw

pytest.importorskip("matplotlib")
PIL_Image = pytest.importorskip("PIL.Image")

from pdw.core.progress import Progress  # noqa: E402
from pdw.present import plots  # noqa: E402
from pdw.sim.simulation import simulate  # noqa: E402

T_SHORT = 1.2  # two touch-downs (0.34 s, 0.91 s) and two double supports


@pytest.fixture(scope="module")
def run():
    r = simulate(t_end=T_SHORT)
    assert r.walked
    return r


class _Tty(io.StringIO):
    def isatty(self):
        return True


@pytest.fixture(scope="module")
def bar():
    return Progress(stream=_Tty())


@pytest.fixture(scope="module")
def written(run, tmp_path_factory, bar):
    out = tmp_path_factory.mktemp("plots")
    return out, plots.save_all(run, out, progress=bar)


def test_save_all_advances_its_bar_one_unit_per_file(written, bar):
    _, paths = written
    assert (bar.done, bar.total) == (len(paths), len(paths))
    assert "figures" in bar.stream.getvalue() and "%d/%d" % (len(paths), len(paths)) in bar.stream.getvalue()


def _events_double_supports(result):
    """(t_touch_down, t_lift_off) pairs: a touch-down followed by the other leg's lift-off."""
    ev = sorted(result.events, key=lambda e: e.t)
    pairs = []
    for a, b in zip(ev, ev[1:]):
        if a.kind == "touch_down" and b.kind == "lift_off" and a.leg != b.leg:
            pairs.append((a.t, b.t))
    return pairs


def test_import_does_not_need_matplotlib(tmp_path):
    code = "import sys, pdw, pdw.present.plots; print('matplotlib' in sys.modules)"
    # cwd: a neutral folder, so that the pdw under test is imported (not sources in the cwd)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=tmp_path)
    assert out.stdout.strip() == "False"


def test_save_all_writes_every_file(written):
    out, paths = written
    names = [p.name for p in paths]
    assert names == ["fig4_gait.png", "fig5_stick.png", "fig6_contact.png",
                     "fig7_double_support.png", "walker.gif"]
    for p in paths:
        assert p.parent == out
        assert p.is_file() and p.stat().st_size > 10_000, p


def test_pngs_have_expected_size_and_content(written):
    _, paths = written
    keys = {"fig4_gait.png": "fig_gait", "fig5_stick.png": "fig_stick",
            "fig6_contact.png": "fig_contact", "fig7_double_support.png": "fig_double_support"}
    for p in paths:
        if p.suffix != ".png":
            continue
        with PIL_Image.open(p) as im:
            assert im.format == "PNG"
            w, h = plots.FIGSIZE[keys[p.name]]
            assert im.size == (round(w * plots.DPI), round(h * plots.DPI)), p.name
            a = np.asarray(im.convert("L"), dtype=float)
        # not blank: a good share of non-white pixels and real contrast
        assert (a < 200).mean() > 0.01, p.name
        assert a.std() > 10, p.name


def test_gif_frames_and_size(written):
    _, paths = written
    gif = paths[-1]
    assert gif.stat().st_size < 3_000_000
    with PIL_Image.open(gif) as im:
        assert im.format == "GIF"
        assert im.n_frames > 10
        # real time at 25 fps over the run
        assert im.n_frames == round(T_SHORT * 25) + 1
        im.seek(0)
        f0 = np.asarray(im.convert("RGB"), dtype=float)
        im.seek(im.n_frames - 1)
        f1 = np.asarray(im.convert("RGB"), dtype=float)
    assert np.abs(f0 - f1).mean() > 0.5, "the walker does not move between first and last frame"


def test_animate_duration_sets_frame_count(run, tmp_path):
    p = plots.animate(run, tmp_path / "sub" / "w.gif", fps=10, duration=1.5)
    with PIL_Image.open(p) as im:
        assert im.n_frames == 16


def test_double_support_intervals_match_flags_and_events(run):
    dss = plots.double_support_intervals(run)
    got = [t for d in dss for t in (d.t_start, d.t_end)]
    assert got == pytest.approx([t for ab in _events_double_supports(run) for t in ab])
    assert len(dss) == 2
    both = run.flags.all(axis=1)
    for d in dss:
        assert d.leg_down in (1, 2) and d.leg_up == 3 - d.leg_down
        inside = (run.t >= d.t_start + 1e-9) & (run.t < d.t_end - 1e-9)
        assert inside.any() and both[inside].all()
        before = run.t < d.t_start - 1e-9
        assert not both[before][-5:].any()
    # flags are both 1 nowhere else
    covered = np.zeros_like(both)
    for d in dss:
        covered |= (run.t >= d.t_start - 1e-9) & (run.t <= d.t_end + 1e-9)
    assert not (both & ~covered).any()


@pytest.mark.parametrize("which", [0, 1, -1])
def test_double_support_zoom_brackets_a_real_double_support(run, which):
    fig = plots.fig_double_support(run, which=which)
    lo, hi = fig.axes[0].get_xlim()
    pairs = _events_double_supports(run)
    inside = [(a, b) for a, b in pairs if lo < a < b < hi]
    assert len(inside) == 1, (lo, hi, pairs)
    a, b = inside[0]
    expect = pairs[which]
    assert (a, b) == pytest.approx(expect)
    # a zoom, not the whole run, with margins on both sides
    assert hi - lo < 0.2 and a - lo > 1e-3 and hi - b > 1e-3
    sel = (run.t > a + 1e-9) & (run.t < b - 1e-9)
    assert run.flags[sel].all()
    # the duration is annotated in ms
    texts = " ".join(t.get_text() for ax in fig.axes for t in ax.texts)
    assert ("%.1f ms" % ((b - a) * 1e3)) in texts


def test_double_support_zoom_without_double_support_raises():
    r = simulate(t_end=0.2)  # the first touch-down comes at 0.34 s
    assert plots.double_support_intervals(r) == []
    with pytest.raises(ValueError, match="no double support"):
        plots.fig_double_support(r)
    with pytest.raises(ValueError, match="out of range"):
        plots.fig_double_support(simulate(t_end=0.5), which=3)


def test_contact_needs_forces():
    r = simulate(t_end=0.1, record=pdw.Record(forces=False))
    with pytest.raises(ValueError, match="contact forces"):
        plots.fig_contact(r)


def test_friction_sign_change_in_stance(run):
    changes = plots._friction_sign_changes(run)
    assert changes
    n = plots._smooth_window(run.t, 20e-3)
    for tc, leg in changes:
        i = int(np.searchsorted(run.t, tc))
        assert run.flags[i, leg - 1] == 1
        ft = plots._running_mean(run.Ft[:, leg - 1], n)
        assert ft[i - 1] < 0 < ft[i]


def test_figures_name_paper_figures_and_label_axes(run):
    for fn, tag in [(plots.fig_gait, "Fig. 4"), (plots.fig_stick, "Fig. 5"),
                    (plots.fig_contact, "Fig. 6"), (plots.fig_double_support, "Fig. 7")]:
        fig = fn(run)
        assert tag in fig._suptitle.get_text()
        bottom = fig.axes[len(fig.axes) - 1] if fn is not plots.fig_stick else fig.axes[0]
        assert "[" in bottom.get_xlabel()
        for ax in fig.axes:
            assert "[" in ax.get_ylabel(), (fn.__name__, ax.get_title())


def test_stick_is_equal_aspect_and_slope_descends(run):
    fig = plots.fig_stick(run)
    ax = fig.axes[0]
    assert ax.get_aspect() == 1.0
    # the ground line (drawn in the world frame) falls by tan(gamma) per metre
    lines = [ln for ln in ax.get_lines() if len(ln.get_xdata()) == 2 and ln.get_color() == "k"]
    x, y = np.asarray(lines[0].get_xdata()), np.asarray(lines[0].get_ydata())
    assert (y[1] - y[0]) / (x[1] - x[0]) == pytest.approx(-np.tan(run.params.gamma))


def test_walk_figures_draw_the_grounds_shape_and_its_patches():
    """issue 22 item 8: the surface drawn is h(s) of the result's Ground in the world frame
    (a 4 mm step down at s = 0.5 m), and a patch is a band over exactly its interval, labelled
    with the property it sets."""
    import types

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from pdw.present import figure_kit as fk
    ground = pdw.Ground.steps([0.5], [-0.004], width=0.05,
                              patches=[pdw.Patch.make(0.8, 1.2, k_n=2.0e4)])
    gamma = 0.0524
    fig, ax = plt.subplots()
    try:
        gx, gy = fk.draw_ground(ax, types.SimpleNamespace(ground=ground), -0.2, 1.5, 0.05, gamma)
        s = np.linspace(-0.2, 1.5, len(gx))
        wx, wy = fk._to_world(s, ground.h(s), gamma)
        assert np.allclose(gx, wx, atol=1e-12) and np.allclose(gy, wy, atol=1e-12)
        fx, fy = fk._to_world(s, np.zeros_like(s), gamma)
        assert np.max(np.abs(gy - fy)) > 0.0039          # the step is drawn, not a flat line
        bands = [ln for ln in ax.get_lines() if ln.get_color() == fk.PATCH_COLOR]
        assert len(bands) == 1 and bands[0].get_label() == "patch: k_n = 2e+04"
        bs = bands[0].get_xdata() * np.cos(gamma) - bands[0].get_ydata() * np.sin(gamma)
        assert 0.8 <= bs.min() < 0.802 and 1.198 < bs.max() <= 1.2    # along the slope [m]
    finally:
        plt.close(fig)
