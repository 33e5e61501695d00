"""The command line: `pdw walk`, `pdw run`, `pdw sweep` options, exit codes and messages."""
import io
import json
import os
import subprocess
import sys

import pytest

import pdw
from pdw.present import cli
from pdw.sim.scene import Scene


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
    assert meta["scene"]["stop"]["t_end"] == 1.5 and meta["status"] == "walked"
    assert meta["params"]["d_hip"] == 0.018
    # the scene as run reads back, and `pdw run` of it gives the same steps
    scene = Scene.load(tmp_path / "scene.toml")
    assert scene.stop.t_end == 1.5 and scene.integrator.method == "cdm"
    assert cli.main(["run", str(tmp_path / "scene.toml"), "--out", str(tmp_path / "again")]) == 0
    assert (tmp_path / "again" / "steps.csv").read_text() == (tmp_path / "steps.csv").read_text()


def test_walk_reads_the_scene_schema_and_command_line_wins(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text('name = "soft"\nvariant = "consistent"\npreset = "paper_steady"\n'
                     '[params]\nk_hip = 0.9\n[stop]\nt_end = 1.0\n')
    rc = cli.main(["walk", "--scene", str(scene), "--t-end", "0.5", "--no-figures",
                   "--out", str(tmp_path / "o")])
    assert rc == 0
    meta = json.loads((tmp_path / "o" / "run.json").read_text())
    assert meta["scene"]["variant"] == "consistent" and meta["scene"]["stop"]["t_end"] == 0.5
    assert meta["params"]["k_hip"] == 0.9 and meta["params"]["d_hip"] == 0.010


def test_walk_runs_the_shipped_example_scene(tmp_path, capsys):
    """`pdw walk --scene` and `pdw run` read one schema: the shipped example works in both."""
    path = pdw.examples.scene_path("typical_gait")
    rc = cli.main(["walk", "--scene", str(path), "--t-end", "2.0", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert rc == 0 and "nothing was recorded" in out      # the example records descriptors only


@pytest.mark.parametrize("text, word", [
    ("t_ends = 1.0\n", "t_ends"),
    ('[integrator]\ndt = "small"\n', "integrator.dt"),
    ("figures = false\n", "figures"),
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


def test_a_fall_returns_code_3_and_no_steady_values(tmp_path, capsys):
    rc = cli.main(["walk", "--t-end", "6", "--no-figures", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert rc == 3 and "fell" in out
    assert "before the run fell" in out and "vs the paper" not in out
    assert json.loads((tmp_path / "run.json").read_text())["steady"] is None


def test_version_and_exit_codes_are_documented(capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["--version"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("pdw %s" % pdw.__version__) and pdw.INPUT_HASH[:12] in out
    with pytest.raises(SystemExit):
        cli.main(["--help"])
    out = capsys.readouterr().out
    for code in (0, 2, 3, 4, 141):
        assert "\n  %3d  " % code in out


def test_examples_are_listed_and_run(tmp_path, capsys):
    assert cli.main(["run", "--list-examples"]) == 0
    out = capsys.readouterr().out
    assert "typical_gait" in out and "fig11_k_n" in out
    assert cli.main(["run", "--example", "no_such_thing"]) == 2
    assert "typical_gait" in capsys.readouterr().err            # the error lists what exists
    assert cli.main(["run"]) == 2


def test_pdw_run_with_neither_or_both_is_usage(tmp_path, capsys):
    assert cli.main(["run", "x.toml", "--example", "typical_gait"]) == 2
    assert "one of them" in capsys.readouterr().err


def test_warnings_are_one_line_without_source(tmp_path, capsys):
    rc = cli.main(["walk", "--t-end", "0.3", "--dt", "2e-3", "--no-figures", "--out",
                   str(tmp_path)])
    err = capsys.readouterr().err
    assert rc in (0, 3)
    lines = [x for x in err.splitlines() if "StepSizeWarning" in x]
    assert len(lines) == 1 and lines[0].startswith("pdw: StepSizeWarning: ")
    assert "cli.py" not in err and "warnings.warn" not in err


def test_missing_optional_dependency_names_the_extra(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)       # import matplotlib -> ImportError
    for mod in [m for m in sys.modules if m.startswith("pdw.plots")]:
        monkeypatch.delitem(sys.modules, mod)
    rc = cli.main(["walk", "--t-end", "0.5", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert rc == 0 and (tmp_path / "steps.csv").exists()
    assert err.strip().splitlines() == ["pdw: no figures: matplotlib is not installed: "
                                        "pip install 'pdw[plot]' (or --no-figures)"]


@pytest.mark.parametrize("extra, match", [
    (["--backend", "process", "--scheduler", "tcp://127.0.0.1:1"], "--backend"),
    (["--backend", "thread", "--dask-local"], "--backend"),
    (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "--workers"),
])
def test_sweep_refuses_options_that_would_be_ignored(capsys, extra, match):
    assert cli.main(["sweep", "--example", "fig11_k_n", "--no-progress"] + extra) == 2
    assert match in capsys.readouterr().err


def test_sweep_scheduler_and_dask_local_exclude_each_other(capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["sweep", "--example", "fig11_k_n", "--scheduler", "x", "--dask-local"])
    assert e.value.code == 2


def test_sweep_on_a_local_dask_cluster(tmp_path, capsys):
    pytest.importorskip("distributed")
    f = tmp_path / "tiny.toml"
    f.write_text('name = "tiny"\n[scene]\nstop = { t_end = 4.0 }\n[[axes]]\nname = "k_n"\n'
                 'values = [1.0e5]\n[run]\nfallback = false\nsteady = 2\n')
    rc = cli.main(["sweep", str(f), "--dask-local", "--workers", "1", "--out", str(tmp_path / "o"),
                   "--no-progress", "--no-figures"])
    assert rc == 0
    meta = json.loads((tmp_path / "o" / "tiny.json").read_text())
    assert "ClientExecutor" in meta["executor"] and meta["n_computed"] == 1


def test_closed_pipe_ends_quietly(tmp_path):
    """`pdw walk | head -1`: no BrokenPipeError traceback, exit code 141."""
    env = dict(os.environ, PYTHONUNBUFFERED="0")
    p = subprocess.Popen([sys.executable, "-m", "pdw", "walk", "--t-end", "0.5", "--no-figures",
                          "--out", str(tmp_path)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, env=env, cwd=tmp_path)
    p.stdout.close()                     # the reader is gone before anything was written
    err = p.stderr.read().decode()
    rc = p.wait()
    p.stderr.close()
    assert "Traceback" not in err and "BrokenPipe" not in err
    assert rc == 141


def test_unreadable_files_are_one_line_errors(tmp_path, capsys):
    for argv in (["run", str(tmp_path / "missing.toml")],
                 ["sweep", str(tmp_path / "missing.toml")],
                 ["continue", str(tmp_path / "missing.toml")]):
        assert cli.main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith("pdw: ") and "missing.toml" in err and "Traceback" not in err


@pytest.mark.parametrize("flag", [[], ["--no-progress"]])
def test_walk_draws_a_bar_over_its_figures_on_a_terminal_only(tmp_path, monkeypatch, flag):
    pytest.importorskip("matplotlib")

    class Tty(io.StringIO):
        def isatty(self):
            return True

    err = Tty()
    monkeypatch.setattr(sys, "stderr", err)
    rc = cli.main(["walk", "--t-end", "0.5", "--out", str(tmp_path)] + flag)
    assert rc == 0 and (tmp_path / "walker.gif").exists()
    drawn = "figures" in err.getvalue()
    assert drawn == (flag == []), err.getvalue()
