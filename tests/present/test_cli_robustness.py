"""`pdw robustness`: the rules every command follows (issue 26 items 2 and 9) -- the spec's
name is a plain file name, and a missing matplotlib is found before the work (exit 4)."""
import pathlib
import sys

import pytest

from pdw.present import cli, cli_robustness

SPEC = """name = "{name}"
measure = "gait_sensitivity"
model = "hybrid"

[options]
indicators = ["step_time"]
"""


def _write(tmp_path, name="gsn"):
    p = tmp_path / "spec.toml"
    p.write_text(SPEC.format(name=name))
    return p


def _files(folder):
    return sorted(str(p.relative_to(folder)) for p in pathlib.Path(folder).rglob("*"))


@pytest.mark.parametrize("name", ["..", "../escape", ".hidden", "a/b", "/tmp/pdw-rob-escape",
                                  "", "x" * 101])
def test_a_robustness_spec_name_cannot_leave_the_output_folder(tmp_path, capsys, monkeypatch,
                                                               name):
    calls = []
    monkeypatch.setattr(cli_robustness, "run_spec", lambda *a, **k: calls.append(1))
    box = tmp_path / "box"
    rc = cli.main(["robustness", str(_write(tmp_path, name)), "--out", str(box / "o"),
                   "--no-figures"])
    err = capsys.readouterr().err
    assert rc == 2 and "plain file name" in err and "Traceback" not in err
    assert calls == [] and not box.exists()
    assert not pathlib.Path("/tmp/pdw-rob-escape.csv").exists()


def test_without_matplotlib_robustness_refuses_before_the_work(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)       # import matplotlib -> ImportError
    for mod in [m for m in sys.modules if m.startswith("matplotlib.")]:
        monkeypatch.delitem(sys.modules, mod)
    calls = []
    monkeypatch.setattr(cli_robustness, "run_spec", lambda *a, **k: calls.append(1))
    out = tmp_path / "o"
    rc = cli.main(["robustness", str(_write(tmp_path)), "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 4 and calls == [] and not out.exists()
    assert "matplotlib is not installed (needed for the figure)" in err
    assert "--no-figures" in err and "nothing was computed" in err
