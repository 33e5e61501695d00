"""`pdw continue SPEC.toml`: the spec is checked whole before the first point (every table,
every key's type and range, named in the error, exit code 2), its name is a plain file name
(nothing is written outside --out), and figures follow the command line's one rule for a
missing optional dependency (--no-figures, exit code 4 before the work)."""
import json
import pathlib
import sys

import pytest

from pdw.present import cli, cli_continue

# the compass gait on rigid ground: a few points, a fraction of a second
BASE = {"name": "cc", "title": "t", "model": "hybrid", "preset": "compass", "parameter": "gamma",
        "start": 0.0524, "stop": 0.056,
        "continuation": {"step": 0.002, "max_points": 3},
        "plot": {"y": "z0", "x_scale": 57.3, "x_label": "slope [deg]"}}


def _toml(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"%s"' % value.replace("\\", "\\\\").replace('"', '\\"')
    if isinstance(value, float) and value != value:
        return "nan"
    if isinstance(value, float) and value in (float("inf"), float("-inf")):
        return "inf" if value > 0 else "-inf"
    if isinstance(value, list):
        return "[%s]" % ", ".join(_toml(v) for v in value)
    if isinstance(value, dict):
        return "{%s}" % ", ".join("%s = %s" % (k, _toml(v)) for k, v in value.items())
    return repr(value)


def _write(tmp_path, spec, name="spec.toml"):
    top = ["%s = %s" % (k, _toml(v)) for k, v in spec.items() if not isinstance(v, dict)]
    tables = ["[%s]\n%s" % (k, "\n".join("%s = %s" % (kk, _toml(vv)) for kk, vv in v.items()))
              for k, v in spec.items() if isinstance(v, dict)]
    path = tmp_path / name
    path.write_text("\n".join(top) + "\n" + "\n".join(tables) + "\n")
    return path


def _with(key, value):
    spec = json.loads(json.dumps(BASE))
    d = spec
    for k in key[:-1]:
        d = d.setdefault(k, {})
    d[key[-1]] = value
    return spec


def _files(folder):
    return sorted(str(p.relative_to(folder)) for p in pathlib.Path(folder).rglob("*")
                  if p.is_file())


def test_the_base_spec_runs(tmp_path, capsys):
    rc = cli.main(["continue", str(_write(tmp_path, BASE)), "--out", str(tmp_path / "o"),
                   "--no-progress", "--no-figures"])
    assert rc == 0, capsys.readouterr().err
    assert _files(tmp_path / "o") == ["cc.csv", "cc.json"]


# --- issue 26 item 2: the name is a plain file name -----------------------------------------

@pytest.mark.parametrize("name", ["../..", "../escape", "/tmp/pdw-continue-escape", "", ".hidden",
                                  "a/b", "..", "x" * 101])
def test_a_spec_name_cannot_leave_the_output_folder(tmp_path, capsys, name):
    box = tmp_path / "box"
    out = box / "a" / "b"
    spec = _write(tmp_path, _with(("name",), name))
    rc = cli.main(["continue", str(spec), "--out", str(out), "--no-progress", "--no-figures"])
    err = capsys.readouterr().err
    assert rc == 2 and "plain file name" in err and "Traceback" not in err
    assert not box.exists() or _files(box) == []            # nothing written anywhere in it
    assert not any(p.name.startswith(".") for p in tmp_path.rglob("*"))
    assert not pathlib.Path("/tmp/pdw-continue-escape.csv").exists()


def test_run_spec_in_python_checks_the_name_too(tmp_path, monkeypatch):
    """The API under the command (`cli_continue.run_spec` of a spec dict) applies the same
    rule before computing."""
    calls = []
    monkeypatch.setattr(cli_continue, "continue_gait", lambda *a, **k: calls.append(1))
    spec = _with(("name",), "../escape")
    with pytest.raises(cli_continue.InvalidInputError, match="plain file name"):
        cli_continue.run_spec(spec, out=tmp_path / "o")
    assert calls == [] and list(tmp_path.iterdir()) == []


# --- issue 26 item 11: the whole spec, before the first point ---------------------------------

BAD = [
    (("name",), 3, "name"),
    (("title",), 1.5, "title"),
    (("model",), "rigid", "model"),
    (("preset",), "atlas", "preset"),
    (("variant",), "soft", "variant"),
    (("parameter",), "gama", "parameter"),
    (("parameter",), 1, "parameter"),
    (("stop",), "x", "stop"),
    (("stop",), float("nan"), "stop"),
    (("stop",), 0.0524, "stop"),                            # = start
    (("start",), [1], "start"),
    (("params",), 2.5, "[params]"),
    (("params", "m_h"), "x", "m_h"),
    (("params", "m_h"), -1.0, "m_h"),
    (("params", "zz"), 1.0, "zz"),
    (("couple",), 0, "[couple]"),
    (("couple",), [1], "[couple]"),
    (("couple", "m_h"), "x", "m_h"),
    (("couple", "m_h"), 1e300, "m_h"),
    (("couple", "gamma"), 1.0, "gamma"),                    # the parameter itself
    (("continuation",), 2.5, "[continuation]"),
    (("continuation", "step"), "x", "step"),
    (("continuation", "step"), -0.1, "step"),
    (("continuation", "method"), "newton", "method"),
    (("continuation", "max_points"), [1], "max_points"),
    (("continuation", "max_points"), float("inf"), "max_points"),
    (("continuation", "max_points"), 2.9, "max_points"),
    (("continuation", "max_points"), 1, "max_points"),
    (("continuation", "step_min"), "x", "step_min"),
    (("continuation", "step_max"), "x", "step_max"),
    (("continuation", "step_max"), 2.0, "step_max"),
    (("continuation", "tol"), "x", "tol"),
    (("continuation", "tol"), {"a": 1}, "tol"),
    (("continuation", "locate_tol"), 0.0, "locate_tol"),
    (("continuation", "log"), 1, "log"),
    (("continuation", "detect"), 0, "detect"),
    (("continuation", "detect"), ["folds"], "detect"),
    (("continuation", "max_newton"), "x", "max_newton"),
    (("continuation", "max_newton"), 2.5, "max_newton"),
    (("continuation", "fd_step"), -1.0, "fd_step"),
    (("continuation", "options"), 2.5, "options"),
    (("continuation", "options"), [1], "options"),
    (("continuation", "options"), {"rtol": 2.0}, "rtol"),
    (("continuation", "options"), {"zz": 1.0}, "zz"),
    (("continuation", "cascade"), [1], "cascade"),
    (("continuation", "cascade"), float("inf"), "cascade"),
    (("continuation", "period"), {"a": 1}, "period"),
    (("continuation", "period"), 2, "period"),              # hybrid: needs a switched start
    (("continuation", "workers"), 0, "workers"),
    (("continuation", "zz"), 1, "zz"),
    (("plot",), "x", "[plot]"),
    (("plot",), 1, "[plot]"),
    (("plot", "y"), "nonsense", "y"),
    (("plot", "x_scale"), [1], "x_scale"),
    (("plot", "x_scale"), 0.0, "x_scale"),
    (("plot", "x_label"), 3, "x_label"),
    (("plot", "zz"), 1, "zz"),
    (("contact",), {"normal": "flores"}, "[contact]"),     # hybrid: rigid ground
    (("zz",), 1, "zz"),
]


@pytest.mark.parametrize("key, value, word", BAD, ids=["%s=%r" % (".".join(k), v)
                                                       for k, v, _ in BAD])
def test_a_malformed_spec_is_refused_before_the_first_point(tmp_path, capsys, monkeypatch,
                                                             key, value, word):
    calls = []
    monkeypatch.setattr(cli_continue, "continue_gait", lambda *a, **k: calls.append(1))
    monkeypatch.setattr(cli_continue, "follow_cascade", lambda *a, **k: calls.append(1))
    out = tmp_path / "o"
    rc = cli.main(["continue", str(_write(tmp_path, _with(key, value))), "--out", str(out),
                   "--no-progress"])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert err.startswith("pdw: ") and word in err and "Traceback" not in err, err
    assert "spec.toml" in err                                # the file is named
    assert calls == [] and not out.exists()                  # no point computed, nothing written


def test_the_continuous_models_options_and_contact_are_checked(tmp_path):
    from pdw.present import continue_spec
    spec = dict(BASE, model="continuous", preset="paper_steady", parameter="d_hip", start=0.01,
                stop=0.02, continuation={"options": {"dt": 0.0}}, plot={})
    with pytest.raises(cli_continue.InvalidInputError, match="options dt"):
        continue_spec.check_spec(spec, "s.toml")
    spec["continuation"] = {"options": {"rtol": 1e-9}}
    spec["contact"] = {"normal": "flores", "e": 7.0}
    with pytest.raises(cli_continue.InvalidInputError, match=r"\[contact\].*e"):
        continue_spec.check_spec(spec, "s.toml")
    spec["contact"] = {"normal": "flores", "e": 0.2}
    checked = continue_spec.check_spec(spec, "s.toml")
    assert checked["contact"]["normal"] == "flores" and checked["plot"]["y"] == "step_length"
    spec["continuation"] = {"log": True}
    spec["start"], spec["stop"] = 0.01, 0.0
    with pytest.raises(cli_continue.InvalidInputError, match="log"):
        continue_spec.check_spec(spec, "s.toml")


def test_a_ground_table_is_refused_with_the_reason(tmp_path):
    """issue 22 item 1: a continuation spec reads no [ground] (a gait needs the same ground
    under every step); it says so and points to the slope, not "unknown key"."""
    from pdw.present import continue_spec
    spec = dict(BASE, ground={"kind": "plane", "slope": 0.01})
    with pytest.raises(cli_continue.InvalidInputError,
                       match=r"spec\.toml: \[ground\]: .*same ground under every step.*gamma"):
        continue_spec.check_spec(spec, "spec.toml")


@pytest.mark.parametrize("name", ["compass_cascade", "d_hip", "fig11_k_n", "rigid_limit",
                                  "simplest_walker"])
def test_every_shipped_spec_passes_the_check(name):
    import pdw
    spec = cli_continue.load_spec(pdw.examples.continuation_path(name))
    assert spec["name"] == name and spec["plot"]["y"] in ("step_length", "z0")


# --- issue 26 item 9: matplotlib missing ------------------------------------------------------

def _no_matplotlib(monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)       # import matplotlib -> ImportError
    for mod in [m for m in sys.modules if m.startswith("matplotlib.")]:
        monkeypatch.delitem(sys.modules, mod)


def test_without_matplotlib_continue_refuses_before_the_work(tmp_path, capsys, monkeypatch):
    _no_matplotlib(monkeypatch)
    calls = []
    monkeypatch.setattr(cli_continue, "continue_gait", lambda *a, **k: calls.append(1))
    out = tmp_path / "o"
    rc = cli.main(["continue", str(_write(tmp_path, BASE)), "--out", str(out), "--no-progress"])
    err = capsys.readouterr().err
    assert rc == 4 and calls == [] and not out.exists()
    assert err.strip().splitlines() == [
        "pdw: error: matplotlib is not installed (needed for the diagram): pip install "
        "'pdw[plot]', or run with --no-figures; nothing was computed"]


def test_continue_no_figures_runs_without_matplotlib(tmp_path, capsys, monkeypatch):
    _no_matplotlib(monkeypatch)
    out = tmp_path / "o"
    rc = cli.main(["continue", str(_write(tmp_path, BASE)), "--out", str(out), "--no-progress",
                   "--no-figures"])
    text = capsys.readouterr().out
    assert rc == 0 and _files(out) == ["cc.csv", "cc.json"]
    assert "wrote %s" % (out / "cc.csv") in text and ".png" not in text
    rows = (out / "cc.csv").read_text().strip().splitlines()
    assert rows[0].startswith("branch,") and len(rows) == 1 + 3       # max_points = 3
