"""The command line: `pdw walk`, `pdw run`, `pdw sweep` options, exit codes and messages."""
import io
import json
import os
import pathlib
import re
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


def _no_module(monkeypatch, name):
    """Simulate an optional dependency that is not installed: ``import name`` raises."""
    monkeypatch.setitem(sys.modules, name, None)
    for mod in [m for m in sys.modules if m.startswith(name + ".")]:
        monkeypatch.delitem(sys.modules, mod)


# issue 26 item 9: one rule for a missing optional dependency, checked before the work

@pytest.mark.parametrize("module", ["matplotlib", "PIL"])
def test_walk_without_the_plot_extra_refuses_before_the_work(tmp_path, capsys, monkeypatch,
                                                             module):
    if module == "PIL":                 # matplotlib itself imports PIL: have it imported already
        pytest.importorskip("matplotlib.pyplot")
    _no_module(monkeypatch, module)
    ran = []
    monkeypatch.setattr(Scene, "run", lambda self: ran.append(1))
    rc = cli.main(["walk", "--t-end", "0.5", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 4 and ran == [] and not (tmp_path / "o").exists()
    assert err.strip().splitlines() == [
        "pdw: error: %s is not installed (needed for the figures and the GIF): pip install "
        "'pdw[plot]', or run with --no-figures; nothing was computed" % module]


def test_walk_no_figures_needs_no_plot_extra(tmp_path, capsys, monkeypatch):
    _no_module(monkeypatch, "matplotlib")
    rc = cli.main(["walk", "--t-end", "0.5", "--no-figures", "--out", str(tmp_path)])
    assert rc == 0 and (tmp_path / "steps.csv").exists()
    assert capsys.readouterr().err == ""


def test_sweep_without_matplotlib_refuses_before_the_work(tmp_path, capsys, monkeypatch):
    _no_module(monkeypatch, "matplotlib")
    f = tmp_path / "tiny.toml"
    f.write_text('name = "tiny"\n[scene]\nstop = { t_end = 1.0 }\n[[axes]]\nname = "k_n"\n'
                 'values = [1.0e5]\n[run]\nfallback = false\nsteady = 2\n')
    out = tmp_path / "o"
    rc = cli.main(["sweep", str(f), "--out", str(out), "--no-progress", "--backend", "serial"])
    err = capsys.readouterr().err
    assert rc == 4 and not out.exists(), err
    assert "matplotlib is not installed (needed for the figure)" in err and "--no-figures" in err
    rc = cli.main(["sweep", str(f), "--out", str(out), "--no-progress", "--backend", "serial",
                   "--no-figures"])
    assert rc == 0 and sorted(p.name for p in out.iterdir()) == ["tiny.csv", "tiny.json"]


@pytest.mark.parametrize("where", [["--dask-local"], ["--scheduler", "tcp://127.0.0.1:1"]])
def test_sweep_without_dask_exits_4_before_the_work(tmp_path, capsys, monkeypatch, where):
    _no_module(monkeypatch, "distributed")
    out = tmp_path / "o"
    rc = cli.main(["sweep", "--example", "fig11_k_n", "--out", str(out), "--no-progress",
                   "--no-figures"] + where)
    err = capsys.readouterr().err
    assert rc == 4 and not out.exists()
    assert err.strip().splitlines() == [
        "pdw: error: distributed is not installed (needed for --scheduler and --dask-local): "
        "pip install 'pdw[dask]'; nothing was computed"]


def test_invalid_input_is_reported_before_a_missing_dependency(tmp_path, capsys, monkeypatch):
    _no_module(monkeypatch, "matplotlib")
    bad = tmp_path / "bad.toml"
    bad.write_text("t_ends = 1.0\n")
    assert cli.main(["walk", "--scene", str(bad), "--out", str(tmp_path)]) == 2
    assert "t_ends" in capsys.readouterr().err


def test_a_run_that_raises_a_divergence_exits_3(tmp_path, capsys):
    """The exit-code table holds for errors too: a scene whose divergence is an error
    (on_failure = "raise") ends with code 3 ("fell or diverged"), not 2 ("invalid input")."""
    scene = tmp_path / "div.toml"
    scene.write_text('[params]\nk_n = 1e8\n[integrator]\nmethod = "rk4"\ndt = 0.01\n'
                     '[stop]\nt_end = 2.0\n[limits]\non_failure = "raise"\n')
    rc = cli.main(["run", str(scene)])
    err = capsys.readouterr().err
    assert rc == 3 and "diverged at t = " in err and "Traceback" not in err, err


def test_the_readme_exit_code_table_is_the_commands(capsys):
    """The README's exit codes are `cli.EXIT_CODES`, and it says they hold for every command."""
    readme = (pathlib.Path(__file__).resolve().parents[2] / "README.md").read_text()
    text = " ".join(readme.split("Exit codes")[1].split("\n\n")[0].split())
    assert text.startswith(", the same for every command:"), text
    codes = [int(c) for c in re.findall(r"(?<![\w.])(\d{1,3}) (?=[a-z])", text)]
    assert codes == list(cli.EXIT_CODES), text


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


# issue 26 item 12: every example listed, each with its whole first sentence

def test_list_examples_shows_every_example_with_a_whole_sentence(capsys):
    assert cli.main(["run", "--list-examples"]) == 0
    out = capsys.readouterr().out
    for name in (pdw.examples.scenes() + pdw.examples.studies()
                 + pdw.examples.continuations()):
        assert "\n  %s " % name in out, name
    assert "pdw continue --example NAME" in out
    # the entries (a name line plus its indented continuation lines) close their parentheses
    entries = []
    for line in out.splitlines():
        if line.startswith("   "):
            entries[-1] += line
        elif line.startswith("  "):
            entries.append(line)
    assert len(entries) == len(pdw.examples.scenes() + pdw.examples.studies()
                               + pdw.examples.continuations())
    for e in entries:
        text = " ".join(e.split())
        assert text.count("(") == text.count(")"), text
    typical = " ".join(out.split("\n  typical_gait")[1].split("example studies")[0].split())
    assert typical.endswith("agree within 0.1 %."), typical


# issue 26 item 2: names from user input never leave --out; a scene's name is a label only

@pytest.mark.parametrize("name", ["../../escape", "/tmp/pdw-scene-escape", "", ".hidden"])
def test_scene_names_do_not_name_files(tmp_path, capsys, name):
    scene = tmp_path / "in" / "s.toml"
    scene.parent.mkdir()
    scene.write_text('name = "%s"\n[stop]\nt_end = 0.3\n' % name)
    box = tmp_path / "box"
    for argv in (["run", str(scene), "--out", str(box / "run")],
                 ["walk", "--scene", str(scene), "--no-figures", "--out", str(box / "walk")]):
        assert cli.main(argv) in (0, 3)
    written = sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*") if p.is_file())
    assert written == ["box/run/run.json", "box/run/scene.toml", "box/run/steps.csv",
                       "box/run/trajectory.npz", "box/walk/report.txt", "box/walk/run.json",
                       "box/walk/scene.toml", "box/walk/steps.csv", "box/walk/trajectory.npz",
                       "in/s.toml"]
    assert not pathlib.Path("/tmp/pdw-scene-escape").exists()
