"""The command line: `pdw walk` and its scene files."""
import json

import pytest

from pdw.present import cli


def test_walk_writes_report_steps_and_run_info(tmp_path, capsys):
    rc = cli.main(["walk", "--t-end", "1.5", "--no-figures", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert rc == 0
    assert "status: walked" in out and "L [m]" in out
    report = (tmp_path / "report.txt").read_text()
    assert report.strip() == out.split("\nwrote:")[0].strip()
    rows = (tmp_path / "steps.csv").read_text().strip().splitlines()
    assert rows[0].startswith("leg,") and len(rows) == 3      # touch-downs at 0.91, 1.46 s
    assert rows[1].split(",")[0] == "2"
    meta = json.loads((tmp_path / "run.json").read_text())
    assert meta["t_end"] == 1.5 and meta["status"] == "walked" and meta["params"]["d_hip"] == 0.018


def test_scene_file_sets_options_and_command_line_wins(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text('t_end = 1.0\nvariant = "consistent"\npreset = "paper_steady"\n'
                     'figures = false\n[params]\nk_hip = 0.9\n')
    rc = cli.main(["walk", "--scene", str(scene), "--t-end", "0.5", "--out", str(tmp_path / "o")])
    assert rc == 0
    meta = json.loads((tmp_path / "o" / "run.json").read_text())
    assert meta["variant"] == "consistent" and meta["t_end"] == 0.5
    assert meta["params"]["k_hip"] == 0.9 and meta["params"]["d_hip"] == 0.010


@pytest.mark.parametrize("text, word", [
    ("t_ends = 1.0\n", "t_ends"),
    ('dt = "small"\n', "dt"),
    ("figures = 1\n", "figures"),
])
def test_bad_scene_file_names_the_key(tmp_path, capsys, text, word):
    scene = tmp_path / "bad.toml"
    scene.write_text(text)
    rc = cli.main(["walk", "--scene", str(scene), "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert rc == 2 and repr(word) in err


def test_invalid_parameter_is_reported_with_its_field(tmp_path, capsys):
    scene = tmp_path / "p.toml"
    scene.write_text("[params]\nm_h = -2.0\n")
    rc = cli.main(["walk", "--scene", str(scene), "--out", str(tmp_path), "--no-figures"])
    err = capsys.readouterr().err
    assert rc == 2 and "m_h" in err and ">" in err


def test_a_fall_returns_a_nonzero_code(tmp_path, capsys):
    rc = cli.main(["walk", "--t-end", "6", "--no-figures", "--out", str(tmp_path)])
    assert rc == 3 and "fell" in capsys.readouterr().out
