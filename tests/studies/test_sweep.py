"""Parameter studies (pdw.sweep, `pdw sweep`): study files, CSV + provenance, executors
(threads, processes, Dask), resumption after a kill.

Safe sweeps (issue 16, findings 1, 4 and 5): a resumed sweep recomputes every row computed
under other settings and every "error" row; one sweep per output folder (a lock), atomic
writes, process workers that die with their SIGKILLed parent; the study name cannot escape the
output folder.
"""
import concurrent.futures as cf
import csv
import json
import os
import pathlib
import signal
import stat
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import pdw
import pdw.examples
import pdw.present.cli
from pdw.present.study_plots import plot_study
from pdw.studies import sweep as S
from pdw.studies.study import parse_study

ROOT = pathlib.Path(__file__).resolve().parents[2]
STUDY_FILES = [pdw.examples.study_path(n) for n in pdw.examples.studies()]

TINY = """
name = "tiny"
title = "tiny k_n study"
[scene]
preset = "paper_steady"
variant = "paper"
integrator = { method = "rodas4" }
stop = { t_end = 6.0 }
[[axes]]
name = "k_n"
values = [0.8e5, 1.0e5, 1.2e5]
[[axes]]
name = "k_hip"
values = [0.95, 1.0]
[run]
steady = 3
period_tol = 1e-3
fallback = false
[paper]
at = { k_hip = 0.95 }
L = [0.3967, 0.3976]
P = [0.622, 0.620]
v = [0.6375, 0.641]
"""


@pytest.fixture
def tiny():
    return S.parse_study(TINY)


def _csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def test_study_files_parse():
    assert len(STUDY_FILES) >= 9
    names = {f.stem for f in STUDY_FILES}
    assert {"fig11_k_n", "fig12_d_n", "fig13_k_t", "fig14_d_t", "table5_m_h", "table5_m_l",
            "table5_J_l", "table5_w", "table5_r"} <= names
    for f in STUDY_FILES:
        st = S.load_study(f)
        assert st.name == f.stem and st.preset == "paper_steady"
        assert 1 <= len(st.axes) <= 2 and len(st.points()) >= 9
        if st.name.startswith("fig1"):
            assert st.axis_names[1] == "k_hip"
            assert st.axes[1][1].tolist() == [0.9, 0.95, 1.0]
            assert set(st.paper) >= {"L", "P", "v", "at"}


@pytest.mark.parametrize("text, match", [
    ("bogus = 1\n[[axes]]\nname='k_n'\nvalues=[1e5]", "unknown key 'bogus'"),
    ("[[axes]]\nname='k_x'\nvalues=[1e5]", "Params field"),
    ("[[axes]]\nname='k_n'\nstart=1\nstop=2", "missing num"),
    ("[[axes]]\nname='k_n'\nvalues=[-1.0]", "k_n"),
    ("[scene]\nvariant='other'\n[[axes]]\nname='k_n'\nvalues=[1e5]", "scene.*variant"),
    ("[run]\nmode='guess'\n[[axes]]\nname='k_n'\nvalues=[1e5]", "mode"),
    ("[scene.stop]\nt_end='long'\n[[axes]]\nname='k_n'\nvalues=[1e5]", "stop.t_end"),
    ("[scene.integrator]\nmthod='cdm'\n[[axes]]\nname='k_n'\nvalues=[1e5]", "integrator.mthod"),
    ("[scene.params]\nk_n=2e5\n[[axes]]\nname='k_n'\nvalues=[1e5]", "swept and also fixed"),
    # the earlier format: the key's new place is named
    ("variant='consistent'\n[[axes]]\nname='k_n'\nvalues=[1e5]", "scene.variant"),
    ("[run]\nt_end=6.0\n[[axes]]\nname='k_n'\nvalues=[1e5]", "scene.stop.t_end"),
    ("title='no axes'", "one or two"),
])
def test_bad_study_files_name_the_key(text, match):
    with pytest.raises(pdw.InvalidInputError, match=match):
        S.parse_study(text)


def test_points_order_and_tasks(tiny):
    pts = tiny.points()
    assert [k for k, _ in pts] == list(range(6))
    assert [v["k_n"] for _, v in pts[:3]] == [0.8e5, 1.0e5, 1.2e5]      # first axis fastest
    assert [v["k_hip"] for _, v in pts] == [0.95] * 3 + [1.0] * 3
    t = tiny.task(*pts[4])
    assert t["params"]["k_n"] == 1.0e5 and t["params"]["k_hip"] == 1.0
    assert t["params"]["d_hip"] == 0.010                                 # the preset


@pytest.fixture(scope="module")
def tiny_serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("serial")
    return S.run_study(S.parse_study(TINY), out, backend="serial", progress=False,
                       figures=plot_study)


def test_run_writes_csv_provenance_and_figure(tiny_serial):
    res = tiny_serial
    rows = _csv(res.paths["csv"])
    assert [int(r["index"]) for r in rows] == list(range(6))
    assert all(r["status"] == "walked" and r["gait"] == "period-1" for r in rows)
    L = np.array([float(r["L"]) for r in rows])
    assert np.all((L > 0.3) & (L < 0.45))
    # k_hip 0.95 -> 1.0 shortens the step at every k_n (the paper's trend)
    assert np.all(L[3:] < L[:3])
    meta = json.loads(res.paths["json"].read_text())
    assert meta["code"]["input_hash"] == pdw.INPUT_HASH
    assert meta["code"]["pdw_version"] == pdw.__version__
    assert "git_describe" in meta["code"]
    assert meta["study"]["sha256"] == res.study.digest() and meta["n_points"] == 6
    assert meta["base_params"]["d_hip"] == 0.010 and meta["status_counts"] == {"walked": 6}
    assert res.paths["png"].exists() and res.paths["png"].stat().st_size > 10000


def _values(rows):
    return [(r["index"], r["L"], r["P"], r["cycle"]) for r in rows]


def test_threads_and_processes_give_the_serial_numbers(tiny_serial, tmp_path):
    for backend in ("thread", "process"):
        res = S.run_study(S.parse_study(TINY), tmp_path / backend, backend=backend, workers=2,
                          progress=False, figures=False)
        assert _values(res.rows) == _values(tiny_serial.rows), backend


class KillAfter(cf.Executor):
    """An executor that computes the first n tasks (in this thread) and then 'dies': every
    later task fails, as if the machine went away."""

    def __init__(self, n):
        self.n, self.count = n, 0

    def submit(self, fn, *args, **kwargs):
        fut = cf.Future()
        if self.count < self.n:
            fut.set_result(fn(*args, **kwargs))
        else:
            fut.set_exception(KeyboardInterrupt("killed"))
        self.count += 1
        return fut


def test_killed_sweep_resumes_without_recomputing(tiny_serial, tmp_path, monkeypatch):
    # point by point (batch=False): the kill and the counting of run_point are per point
    study = S.parse_study(TINY)
    with pytest.raises(KeyboardInterrupt):
        S.run_study(study, tmp_path, executor=KillAfter(4), progress=False, figures=False,
                      batch=False)
    rows = _csv(tmp_path / "tiny.csv")
    assert sorted(int(r["index"]) for r in rows) == [0, 1, 2, 3]
    # a write cut by the kill: a torn last line is dropped on resumption
    with open(tmp_path / "tiny.csv", "a") as f:
        f.write("4,100000.0,1.0,wal")
    calls = []
    real = S.run_point

    def counting(task):
        calls.append(task["index"])
        return real(task)

    monkeypatch.setattr(S, "run_point", counting)
    res = S.run_study(study, tmp_path, backend="thread", workers=2, progress=False,
                      figures=False, batch=False)
    assert sorted(calls) == [4, 5] and res.computed == [4, 5] and res.resumed == [0, 1, 2, 3]
    rows = _csv(tmp_path / "tiny.csv")
    assert [int(r["index"]) for r in rows] == list(range(6))           # each point once
    assert _values(res.rows) == _values(tiny_serial.rows)
    meta = json.loads((tmp_path / "tiny.json").read_text())
    assert meta["n_resumed"] == 4 and meta["n_computed"] == 2
    # all done: a rerun computes nothing
    calls.clear()
    res = S.run_study(study, tmp_path, progress=False, figures=False,
                      batch=False)
    assert calls == [] and res.computed == []


def test_resume_refuses_a_csv_of_another_study(tmp_path):
    study = S.parse_study(TINY)
    other = S.parse_study(TINY.replace("values = [0.8e5, 1.0e5, 1.2e5]",
                                       "values = [0.7e5, 1.0e5, 1.2e5]"))
    with pytest.raises(KeyboardInterrupt):
        S.run_study(study, tmp_path, executor=KillAfter(1), progress=False, figures=False,
                      batch=False)
    with pytest.raises(pdw.PdwError, match="does not match"):
        S.run_study(other, tmp_path, progress=False, figures=False,
                      batch=False)
    res = S.run_study(other, tmp_path, resume=False, backend="serial", progress=False,
                      figures=False)
    assert len(res.computed) == 6


def test_dask_local_cluster(tiny_serial, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        res = S.run_study(S.parse_study(TINY), tmp_path, executor=client.get_executor(),
                          progress=False, figures=False)
    assert _values(res.rows) == _values(tiny_serial.rows)
    meta = json.loads((tmp_path / "tiny.json").read_text())
    assert "ClientExecutor" in meta["executor"]


def test_progress_bar_lines(capsys):
    import io
    buf = io.StringIO()
    bar = S.Progress(20, 0, label="x", stream=buf)
    for _ in range(20):
        bar.update()
    # one mechanism for every long job (pdw.core.progress, tests/core/test_progress.py): quiet when
    # the stream is not a terminal
    assert buf.getvalue() == ""


def test_cli_sweep(tmp_path, capsys):
    f = tmp_path / "tiny.toml"
    f.write_text(TINY.replace("values = [0.95, 1.0]", "values = [0.95]"))
    out = tmp_path / "out"
    rc = pdw.present.cli.main(["sweep", str(f), "--out", str(out), "--no-progress", "--no-figures",
                       "--workers", "2"])
    assert rc == 0
    assert "3 points (3 computed, 0 resumed)" in capsys.readouterr().out
    assert (out / "tiny.csv").exists() and (out / "tiny.json").exists()
    assert pdw.present.cli.main(["sweep", str(tmp_path / "missing.toml")]) == 2


def test_run_point_reports_bad_points_as_rows(tiny):
    t = tiny.task(0, {"k_n": 1e5, "k_hip": 0.95})
    t["params"]["r"] = 0.6                     # r >= l: invalid
    row = S.run_point(t)
    assert row["status"] == "error" and "r" in row["error"]


@pytest.mark.slow
def test_all_studies():
    """The paper's Table 5 and Figs. 11-14 (pdw/examples/studies/*.toml): figures in docs/figures/,
    trends in benchmarks/results/studies.txt (a few tens of seconds)."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import _results
    import studies
    studies.main([])
    text = (_results.RESULTS / "studies.txt").read_text()
    assert "fig11_k_n" in text and "table5_r" in text


# --- issue 26 item 12: file modes, the lock file, Ctrl-C ---------------------------------------

@pytest.mark.parametrize("umask", [0o022, 0o027])
def test_sweep_files_get_the_umask_mode_and_the_lock_file_goes(tmp_path, umask):
    """Outputs are written like any new file under the user's umask (0644 under 022: readable
    by collaborators), not mkstemp's private 0600; the lock file is removed at the end."""
    pytest.importorskip("matplotlib")
    old = os.umask(umask)
    try:
        res = S.run_study(S.parse_study(TINY.replace("t_end = 6.0", "t_end = 1.0")), tmp_path,
                          backend="serial", progress=False, figures=plot_study)
    finally:
        os.umask(old)
    modes = {p.name: stat.S_IMODE(p.stat().st_mode) for p in tmp_path.iterdir()}
    assert modes == {"tiny.csv": 0o666 & ~umask, "tiny.json": 0o666 & ~umask,
                     "tiny.png": 0o666 & ~umask}, {k: oct(v) for k, v in modes.items()}
    assert set(res.paths) == {"csv", "json", "png"}


def test_the_lock_file_goes_after_an_error_too(tmp_path):
    with pytest.raises(KeyboardInterrupt):
        S.run_study(S.parse_study(TINY), tmp_path, executor=KillAfter(1), progress=False,
                    figures=False, batch=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tiny.csv"]


_FAST_SLOW = """
name = "fastslow"
[scene.stop]
t_end = 20000.0
[[axes]]
name = "gamma"
values = [0.05, 0.052, 0.054, 0.056, 0.058, 0.06, 0.062, 0.064,
          0.019, 0.0192, 0.0194, 0.0196, 0.0198, 0.02, 0.0202, 0.0204]
[run]
fallback = false
"""


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize("backend", ["thread", "process"])
def test_ctrl_c_ends_a_sweep_at_once_keeping_the_finished_rows(tmp_path, backend):
    """Two batches on two workers: the first (8 walkers that fall within seconds) finishes,
    the second (8 walkers for 20000 s: minutes) runs. Ctrl-C (to the command only, not its
    workers) then stops the running batch: at its next poll (threads) or by ending the pool's
    processes. The command exits with 130 within seconds (it used to wait for the batch), the
    finished rows stay in the CSV, and a rerun resumes from them."""
    f = tmp_path / "fastslow.toml"
    f.write_text(_FAST_SLOW)
    out = tmp_path / "out"
    child = ("import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
             "from pdw.present.cli import main; sys.exit(main(sys.argv[1:]))")
    proc = subprocess.Popen([sys.executable, "-c", child, "sweep", str(f), "--out", str(out),
                             "--workers", "2", "--backend", backend, "--no-figures",
                             "--no-progress"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and len(_csv_rows(out / "fastslow.csv")) < 8:
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.2)
        assert len(_csv_rows(out / "fastslow.csv")) == 8, "the fast batch did not finish"
        time.sleep(1.0)                               # the slow batch is running
        sent = time.monotonic()
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)         # the slow batch alone runs for minutes
        took = time.monotonic() - sent
    finally:
        proc.kill()
    assert proc.returncode == 130 and "interrupted" in err, err[-2000:]
    assert took < 10.0, took                          # a poll is milliseconds; + the exit
    rows = _csv_rows(out / "fastslow.csv")
    assert sorted(int(r["index"]) for r in rows) == list(range(8))
    assert all(r["status"] == "fell" for r in rows)
    assert sorted(S.read_rows(out / "fastslow.csv", S.parse_study(_FAST_SLOW))) == list(range(8))
    assert sorted(p.name for p in out.iterdir()) == ["fastslow.csv"]     # no lock file left


def _csv_rows(path):
    try:
        return _csv(path)
    except FileNotFoundError:
        return []


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
