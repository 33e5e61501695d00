"""pdw.core.progress: one bar for long jobs, quiet off a terminal."""
import io
import sys

import pytest

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
