"""The figures of studies: the sweep figure marks the points whose walker fell (issue 26 item
14), and the basin gallery example shows a basin (its cells resolve: gait or fall)."""
import ast
import pathlib

import pytest

pytest.importorskip("matplotlib")
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import pdw  # noqa: E402
from pdw.analysis.basins import basin  # noqa: E402
from pdw.present import study_plots  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]

STUDY = """
name = "falls"
[scene.stop]
t_end = 12.0
[[axes]]
name = "gamma"
values = [0.0, 0.015, 0.02, 0.025, 0.06]
[run]
fallback = false
steady = 2
"""


def test_the_sweep_figure_marks_the_points_that_fell(tmp_path, monkeypatch):
    res = pdw.sweep.run_study(pdw.sweep.parse_study(STUDY), tmp_path, backend="serial",
                              progress=False, figures=False)
    fell = sorted(r["gamma"] for r in res.rows if r["status"] == "fell")
    assert fell == [0.0, 0.06] and len(res.rows) == 5          # the study itself
    figs = []
    monkeypatch.setattr(plt, "close", lambda fig: figs.append(fig))
    study_plots.plot_study(res.study, res.rows, tmp_path / "f.png")
    (fig,) = figs
    for ax in fig.axes:                                       # in every panel ...
        marks = [ln for ln in ax.lines if ln.get_marker() == "x"]
        assert len(marks) == 1
        assert sorted(marks[0].get_xdata()) == fell
        assert "fell" in marks[0].get_label()
    legend = fig.axes[0].get_legend()                         # ... and in the legend
    assert legend is not None and any("fell" in t.get_text() for t in legend.get_texts())
    plt.close("all")


def _gallery_basin_call():
    """The keyword arguments of the `basin.basin(...)` call in docs/gallery/plot_basin.py."""
    tree = ast.parse((ROOT / "docs" / "gallery" / "plot_basin.py").read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and getattr(node.func, "attr", "") == "basin":
            return {k.arg: ast.literal_eval(k.value) for k in node.keywords}
    raise AssertionError("no basin.basin(...) call in the gallery example")


def test_the_basin_gallery_shows_a_basin():
    """The gallery's window and t_end, on a coarse 8 x 8 grid: the cells resolve (almost none
    undecided) and the window holds both the basin and its edge (gait and falls)."""
    kw = _gallery_basin_call()
    kw["phi"] = (*kw["phi"][:2], 8)
    kw["thetad2"] = (*kw["thetad2"][:2], 8)
    b = basin.basin(pdw.Params.paper_steady(), **kw)
    undecided = b.fraction(basin.UNDECIDED)
    gait, fell = b.fraction(basin.GAIT), b.fraction(basin.FELL)
    assert undecided <= 0.05, (gait, fell, undecided)
    assert 0.2 <= gait <= 0.8 and fell >= 0.2, (gait, fell, undecided)
