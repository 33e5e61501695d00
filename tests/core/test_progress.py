"""pdw.core.progress: one bar for long jobs, quiet off a terminal."""
import io
import sys

import pytest

import pdw
from pdw.core import progress


class Tty(io.StringIO):
    def isatty(self):
        return True


def test_quiet_when_not_a_terminal_or_disabled():
    for stream, enabled in ((io.StringIO(), True), (Tty(), False)):
        bar = progress.Progress(5, stream=stream, enabled=enabled)
        for _ in range(5):
            bar.update()
        assert stream.getvalue() == ""


@pytest.mark.parametrize("use_tqdm", [False, True])
def test_draws_on_a_terminal_up_to_the_total(use_tqdm, monkeypatch):
    if use_tqdm:
        pytest.importorskip("tqdm")
    else:
        monkeypatch.setitem(sys.modules, "tqdm", None)      # import fails: the built-in bar
    s = Tty()
    bar = progress.Progress(4, done=1, label="cells", stream=s)
    for _ in range(3):
        bar.update()
    out = s.getvalue()
    assert "cells" in out and "4/4" in out


# --- the mechanism: progress_bar, a shared bar, track ------------------------------------------

def test_progress_argument_is_checked_and_a_given_bar_is_shared():
    with pytest.raises(pdw.InvalidInputError, match="progress"):
        progress.progress_bar("yes", 3, "job")
    s = Tty()
    bar = pdw.Progress(label="two jobs", stream=s)
    for total in (2, 3):
        job = progress.progress_bar(bar, total, "job")
        assert job is bar
        assert list(job.track(range(total))) == list(range(total))
    assert (bar.done, bar.total) == (5, 5)
    assert "5/5" in s.getvalue()


def test_track_counts_a_unit_only_once_it_is_done():
    bar = pdw.Progress(3, enabled=False)
    seen = []
    for _item in bar.track("abc"):
        seen.append(bar.done)       # while the k-th item is worked on, k units are done
    assert seen == [0, 1, 2] and bar.done == 3


def test_the_library_is_quiet_by_default(capsys):
    cm = pdw.cell_mapping.cell_map(pdw.Params.paper_steady(), phi=(0.70, 0.80, 2),
                                   thetad2=(-2.6, -0.8, 1), workers=1)
    assert cm.image.size == 2
    assert capsys.readouterr().err == ""


# --- every long job advances the bar to its total, and writes nothing off a terminal -----------

def _bars():
    return pdw.Progress(stream=Tty()), pdw.Progress(stream=io.StringIO())


@pytest.mark.parametrize("workers", [1, 2])
def test_cell_map_and_point_mapping_count_every_cell(workers):
    tty, quiet = _bars()
    cm = pdw.cell_mapping.cell_map(pdw.Params.paper_steady(), phi=(0.70, 0.80, 3),
                                   thetad2=(-2.6, -0.8, 2), workers=workers, progress=tty)
    assert (tty.done, tty.total) == (6, 6) and "6/6" in tty.stream.getvalue()
    ok, steps = pdw.cell_mapping.point_mapping_basin(cm, cm.image_point[0], n_steps=1,
                                                     workers=workers, progress=quiet)
    assert len(ok) == 6 and (quiet.done, quiet.total) == (6, 6)
    assert quiet.stream.getvalue() == ""


def test_continuation_counts_its_points():
    from pdw.analysis.bifurcation.continuation import continue_gait
    tty, quiet = _bars()
    params = pdw.hybrid.compass_gait_params()
    b = continue_gait(params, "gamma", params.gamma * 1.05, model="hybrid", max_points=4,
                      progress=tty)
    assert tty.done == len(b) and tty.total == 4
    assert "continuation gamma" in tty.stream.getvalue() and "%d/4" % len(b) in tty.stream.getvalue()
    continue_gait(params, "gamma", params.gamma * 1.05, model="hybrid", max_points=3,
                  progress=quiet)
    assert quiet.done > 0 and quiet.stream.getvalue() == ""


def test_basin_counts_its_grid_points():
    from pdw.analysis.basins import basin
    tty, quiet = _bars()
    b = basin.basin(pdw.Params.paper_steady(), phi=(0.74, 0.76, 2), thetad2=(-2.0, -1.8, 2),
                    t_end=6.0, chunk_size=3, progress=tty)
    assert b.walkers == 4 and (tty.done, tty.total) == (4, 4) and "4/4" in tty.stream.getvalue()
    basin.basin(pdw.Params.paper_steady(), phi=(0.74, 0.76, 2), thetad2=(-2.0, -1.8, 1),
                t_end=6.0, progress=quiet)
    assert (quiet.done, quiet.total) == (2, 2) and quiet.stream.getvalue() == ""
