"""Issue 16, findings 1, 4 and 5: safe sweeps.

* 1: a resumed sweep recomputes every row whose settings (hashed: parameters, variant, method,
  [run], model) differ from the study's, and every "error" row.
* 4: one sweep per output folder (an exclusive lock, a clear refusal for the second); writes are
  atomic; the workers of a process pool die with their (SIGKILLed) parent.
* 5: the study name is a plain file name: it cannot escape the output folder.
"""
import csv
import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import time

import pytest

import pdw
from pdw.studies import sweep as S
from pdw.studies.study import parse_study

BASE = """
name = "safe"
[scene]
preset = "%(preset)s"
params = { k_hip = %(k_hip)r }
[scene.integrator]
method = "%(method)s"
[scene.stop]
t_end = %(t_end)r
[[axes]]
name = "k_n"
values = [0.9e5, 1.1e5]
[run]
steady = 2
fallback = false
"""
DEFAULT = dict(preset="paper_steady", method="rodas4", k_hip=0.95, t_end=1.5)


def _study(**kw):
    return parse_study(BASE % {**DEFAULT, **kw})


def _rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def _run(study, out):
    return S.run_study(study, out, backend="serial", progress=False, figures=False)


# --- finding 1 -------------------------------------------------------------------------------

@pytest.mark.parametrize("change", [dict(preset="paper"), dict(method="dopri5"),
                                    dict(k_hip=0.97), dict(t_end=1.6)])
def test_resume_recomputes_rows_computed_under_other_settings(tmp_path, change):
    first = _run(_study(), tmp_path)
    assert first.computed == [0, 1]
    again = _run(_study(), tmp_path)                 # same settings: resumed
    assert again.computed == [] and again.resumed == [0, 1]
    changed = _run(_study(**change), tmp_path)       # other settings: every row computed again
    assert changed.computed == [0, 1] and changed.resumed == []
    rows = _rows(tmp_path / "safe.csv")
    want = [_study(**change).task(k, v)["settings"] for k, v in _study(**change).points()]
    assert [r["settings"] for r in rows] == want
    assert want != [_study().task(k, v)["settings"] for k, v in _study().points()]


def test_error_rows_are_recomputed(tmp_path):
    _run(_study(), tmp_path)
    path = tmp_path / "safe.csv"
    rows = _rows(path)
    rows[1]["status"] = "error"
    rows[1]["error"] = "a broken [run] of an earlier attempt"
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]), lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
    res = _run(_study(), tmp_path)
    assert res.computed == [1] and res.resumed == [0]
    assert _rows(path)[1]["status"] != "error"


# --- finding 4 -------------------------------------------------------------------------------

def test_a_second_sweep_on_a_locked_folder_is_refused_clearly(tmp_path):
    with S._FolderLock(tmp_path):
        with pytest.raises(pdw.PdwError, match="in use by another sweep.*%d" % os.getpid()):
            _run(_study(), tmp_path)
    assert not (tmp_path / "safe.csv").exists()
    assert _run(_study(), tmp_path).computed == [0, 1]        # free again


def test_two_concurrent_sweep_commands_never_corrupt_the_csv(tmp_path):
    """Two `pdw sweep` processes on one folder: one runs, the other is refused with a clear
    message (or runs after it, resuming); the CSV ends whole, every row once."""
    f = tmp_path / "safe.toml"
    f.write_text(BASE % {**DEFAULT, "t_end": 4.0})
    cmd = [sys.executable, "-m", "pdw", "sweep", str(f), "--out", str(tmp_path / "out"),
           "--backend", "serial", "--no-figures", "--no-progress"]
    procs = [subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for _ in range(2)]
    outs = [p.communicate(timeout=300) for p in procs]
    codes = [p.returncode for p in procs]
    assert 0 in codes, outs
    for code, (_, err) in zip(codes, outs):
        if code != 0:
            assert "in use by another sweep" in err and "Traceback" not in err, err
    rows = _rows(tmp_path / "out" / "safe.csv")
    assert [r["index"] for r in rows] == ["0", "1"]
    assert all(r["status"] and r["settings"] for r in rows)
    assert not list((tmp_path / "out").glob("*.tmp"))


def _children(pid):
    out = []
    for d in pathlib.Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                stat = (d / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(d.name))
    return out


def _alive(pid):
    try:
        state = pathlib.Path("/proc/%d/stat" % pid).read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_process_workers_die_with_a_sigkilled_parent(tmp_path):
    f = tmp_path / "slow.toml"
    f.write_text(textwrap.dedent("""
        name = "slow"
        [scene.stop]
        t_end = 200.0
        [[axes]]
        name = "k_n"
        values = [0.9e5, 1.0e5, 1.1e5, 1.2e5]
        [run]
        fallback = false
        """))
    parent = subprocess.Popen([sys.executable, "-m", "pdw", "sweep", str(f), "--out",
                               str(tmp_path / "out"), "--backend", "process", "--workers", "2",
                               "--no-figures", "--no-progress"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        workers = []
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and len(workers) < 2:
            time.sleep(0.2)
            workers = [c for c in _children(parent.pid) if _alive(c)]
        assert len(workers) >= 2, "no workers started"
        time.sleep(0.5)
        parent.send_signal(signal.SIGKILL)
        parent.wait(timeout=30)
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and any(_alive(w) for w in workers):
            time.sleep(0.1)
        assert not any(_alive(w) for w in workers), "workers outlived their parent"
    finally:
        if parent.poll() is None:
            parent.kill()


# --- finding 5 -------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["../../x", "/tmp/pdw-escape", "a/b", "..", ".hidden", "",
                                  "x" * 101, "a\x00b"])
def test_a_study_name_is_a_plain_file_name(name, tmp_path):
    text = (BASE % DEFAULT).replace('name = "safe"', 'name = %s' % _toml_str(name))
    with pytest.raises(pdw.InvalidInputError, match="plain file name"):
        parse_study(text)
    study = _study()
    study.name = name                         # a Study built in Python is checked when run
    with pytest.raises(pdw.InvalidInputError, match="plain file name"):
        _run(study, tmp_path / "out")
    assert not pathlib.Path("/tmp/pdw-escape.csv").exists()


def _toml_str(s):
    return '"%s"' % s.replace("\\", "\\\\").replace('"', '\\"').replace("\x00", "\\u0000")
