"""The instruction-count guard's decisions (benchmarks/instructions.py; the counting itself runs
under valgrind in `make instructions`, which .ci/run calls): it skips in one line without
valgrind or with other versions than the baselines', and fails on growth beyond its margin,
printing the old and new counts."""
import importlib.util
import json
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent


@pytest.fixture
def guard(monkeypatch, tmp_path):
    spec = importlib.util.spec_from_file_location("pdw_instructions",
                                                  ROOT / "benchmarks" / "instructions.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    env = {"compiler": "gcc 12", "libc": "glibc 2.36", "python": "3.11.7", "numpy": "2.4.6",
           "valgrind": "valgrind-3.19.0", "machine": "x86_64", "isa": "avx2"}
    base = {name: 1_000_000 for name in mod.REGIONS}
    monkeypatch.setattr(mod, "BASELINE", tmp_path / "instructions.json")
    monkeypatch.setattr(mod, "environment", lambda: dict(env))
    monkeypatch.setattr(mod.shutil, "which", lambda name: "/usr/bin/" + name)
    mod.BASELINE.write_text(json.dumps({"environment": env, "margin": mod.MARGIN, "counts": base}))
    return mod, env, base


def test_the_committed_baselines_name_every_region_and_their_versions():
    data = json.loads((ROOT / "benchmarks" / "results" / "instructions.json").read_text())
    spec = importlib.util.spec_from_file_location("pdw_instructions",
                                                  ROOT / "benchmarks" / "instructions.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert set(data["counts"]) == set(mod.REGIONS)
    assert all(isinstance(n, int) and n > 10 ** 6 for n in data["counts"].values())
    assert set(data["environment"]) == {"compiler", "libc", "python", "numpy", "valgrind",
                                        "machine", "isa"}


def test_without_valgrind_it_says_so_in_one_line_and_passes(guard, monkeypatch, capsys):
    mod, _, _ = guard
    monkeypatch.setattr(mod.shutil, "which", lambda name: None)
    monkeypatch.setattr(mod, "measure", lambda: pytest.fail("counted without valgrind"))
    assert mod.main([]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert len(out) == 1 and "skipped" in out[0] and "valgrind" in out[0]


def test_other_versions_are_not_compared(guard, monkeypatch, capsys):
    mod, env, _ = guard
    monkeypatch.setattr(mod, "environment", lambda: dict(env, numpy="9.9"))
    monkeypatch.setattr(mod, "measure", lambda: pytest.fail("compared unlike with unlike"))
    assert mod.main([]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert len(out) == 1 and "numpy 2.4.6 -> 9.9" in out[0]


def test_growth_beyond_the_margin_fails_and_prints_old_and_new(guard, monkeypatch, capsys):
    mod, _, base = guard
    grown = dict(base, paper_run_recorded=int(base["paper_run_recorded"] * (1 + mod.MARGIN)) + 1)
    monkeypatch.setattr(mod, "measure", lambda: grown)
    assert mod.main([]) == 1
    out = capsys.readouterr().out
    assert "FAILED" in out and "paper_run_recorded" in out.split("FAILED")[1]
    line = next(s for s in out.splitlines() if s.startswith("paper_run_recorded"))
    assert "1000000" in line and str(grown["paper_run_recorded"]) in line


def test_counts_within_the_margin_or_smaller_pass(guard, monkeypatch):
    mod, _, base = guard
    same = dict(base, paper_run=int(base["paper_run"] * (1 + mod.MARGIN)), find_gait=1)
    monkeypatch.setattr(mod, "measure", lambda: same)
    assert mod.main([]) == 0


def test_update_rewrites_the_baselines(guard, monkeypatch):
    mod, env, base = guard
    new = dict(base, first_call=7_000_000)
    monkeypatch.setattr(mod, "measure", lambda: new)
    monkeypatch.setattr(mod, "environment", lambda: dict(env, numpy="9.9"))
    assert mod.main(["--update"]) == 0
    data = json.loads(mod.BASELINE.read_text())
    assert data["counts"] == new and data["environment"]["numpy"] == "9.9"
