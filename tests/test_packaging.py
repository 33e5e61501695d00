"""The installed package stands on its own (slow: builds, installs, runs; `make study`).

Builds the sdist and, from it, the wheel (`python -m build`, so the wheel is built from the
sdist: a file missing from the sdist breaks the build); checks what each carries; installs the
wheel into a fresh virtual environment *without SymPy* and runs ``pdw run --example
typical_gait`` and ``pdw walk --no-figures`` there; then installs the test extra minus SymPy
and runs the sdist's own test suite against the installed wheel.

Needs the ``build`` package, network or a package index for the fresh venv's dependencies, and
a few minutes.
"""
import os
import pathlib
import subprocess
import sys
import tarfile
import zipfile

import pytest

from pdw.core import _toml

ROOT = pathlib.Path(__file__).resolve().parent.parent
pytestmark = pytest.mark.slow


def _run(cmd, cwd=None, timeout=900, env=None):
    p = subprocess.run([str(c) for c in cmd], cwd=cwd, capture_output=True, text=True,
                       timeout=timeout, env=env)
    assert p.returncode == 0, "%s exited %d:\n%s\n%s" % (
        " ".join(map(str, cmd)), p.returncode, p.stdout[-4000:], p.stderr[-4000:])
    return p


@pytest.fixture(scope="module")
def dists(tmp_path_factory):
    pytest.importorskip("build")
    out = tmp_path_factory.mktemp("dist")
    _run([sys.executable, "-m", "build", "--no-isolation", "--outdir", out, ROOT])
    sdist, = out.glob("pdw-*.tar.gz")
    wheel, = out.glob("pdw-*.whl")
    return sdist, wheel


@pytest.fixture(scope="module")
def venv(tmp_path_factory, dists):
    """A fresh venv with the wheel installed (its dependencies only: no SymPy)."""
    env_dir = tmp_path_factory.mktemp("venv")
    _run([sys.executable, "-m", "venv", env_dir])
    py = env_dir / "bin" / "python"
    _run([py, "-m", "pip", "install", "--quiet", "--disable-pip-version-check", dists[1]])
    return env_dir


def test_wheel_carries_the_package_and_no_sources(dists):
    names = zipfile.ZipFile(dists[1]).namelist()
    assert "pdw/examples/typical_gait.toml" in names
    assert "pdw/examples/studies/fig11_k_n.toml" in names
    assert any(n.endswith("LICENSE") for n in names)
    assert any(n.startswith("pdw/") and n.endswith(".so") for n in names)
    assert "pdw/py.typed" in names and "pdw/core/_core.pyi" in names      # PEP 561
    bad = [n for n in names if n.endswith((".c", ".h", ".pyx")) or "/tests/" in n]
    assert bad == []
    meta = zipfile.ZipFile(dists[1]).read(
        next(n for n in names if n.endswith("METADATA"))).decode()
    assert "License-Expression: MIT" in meta and "Requires-Python: >=3.10" in meta


def test_wheel_modules_carry_no_debug_symbols(dists, tmp_path):
    zf = zipfile.ZipFile(dists[1])
    for n in zf.namelist():
        if n.endswith(".so"):
            data = zf.read(n)
            assert b".debug_info" not in data and b".symtab" not in data, n


def test_sdist_is_complete(dists):
    names = tarfile.open(dists[0]).getnames()
    root = names[0].split("/")[0]
    for need in ("LICENSE", "README.md", "Makefile", "setup.py", "pyproject.toml",
                 "tests/conftest.py", "derive/__main__.py", "generated/pdw_model.c",
                 "pdw/examples/typical_gait.toml", "docs/model.md"):
        assert "%s/%s" % (root, need) in names, need
    # no build products: compiled modules, Cython's C output (pdw/.../_core.c, _hybrid.c, _batch.c)
    assert not [n for n in names if n.endswith(".so") or os.path.basename(n) in (
        "_core.c", "_hybrid.c", "_batch.c")]


def test_installed_wheel_runs_without_sympy(venv, tmp_path):
    bindir = venv / "bin"
    p = subprocess.run([bindir / "python", "-c", "import sympy"], capture_output=True)
    assert p.returncode != 0                                    # really without SymPy
    r = _run([bindir / "pdw", "run", "--example", "typical_gait", "--out", tmp_path / "ex"],
             cwd=tmp_path)
    assert "periodic" in r.stdout and "steady (mean of the last 4 steps): L = 0.368" in r.stdout
    r = _run([bindir / "pdw", "walk", "--no-figures", "--out", tmp_path / "walk"], cwd=tmp_path)
    assert "status: walked" in r.stdout and (tmp_path / "walk" / "steps.csv").exists()
    # figures asked for without matplotlib: the data, then one line naming the extra
    r = _run([bindir / "pdw", "walk", "--t-end", "1", "--out", tmp_path / "walk2"], cwd=tmp_path)
    assert r.stderr.strip().splitlines() == [
        "pdw: no figures: matplotlib is not installed: pip install 'pdw[plot]' (or --no-figures)"]
    _run([bindir / "pdw", "--version"], cwd=tmp_path)


def test_sdist_tests_pass_against_the_installed_wheel(venv, dists, tmp_path):
    with tarfile.open(dists[0]) as tf:
        tf.extractall(tmp_path, filter="data") if sys.version_info >= (3, 12) \
            else tf.extractall(tmp_path)
    src, = [p for p in tmp_path.iterdir() if p.is_dir()]
    extras = _toml.loads((src / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    reqs = [r for r in extras["test"] if not r.lower().startswith("sympy")]
    py = venv / "bin" / "python"
    _run([py, "-m", "pip", "install", "--quiet", "--disable-pip-version-check", *reqs])
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    # run from a neutral folder with the `pytest` script (not `python -m pytest`), so that
    # neither pytest nor a test's `python -c` subprocess imports the unpacked, uncompiled sources
    # instead of the installed wheel
    cwd = tmp_path / "elsewhere"
    cwd.mkdir()
    r = _run([venv / "bin" / "pytest", "-q", "-p", "no:cacheprovider", "-c", src / "pyproject.toml",
              "--rootdir", src, src / "tests"], cwd=cwd, timeout=1800, env=env)
    assert " passed" in r.stdout and " failed" not in r.stdout


def _interpreter(version):
    """A python of ``version`` ("3.10"): a pyenv install, or a working ``python3.10`` on PATH."""
    import glob
    import shutil
    cands = sorted(glob.glob(os.path.expanduser("~/.pyenv/versions/%s.*/bin/python" % version)))
    if cands:
        return cands[-1]
    found = shutil.which("python" + version)
    if found and subprocess.run([found, "-c", ""], capture_output=True).returncode == 0:
        return found
    return None


CLAIMED = [c.split(":: ")[-1] for c in _toml.loads((ROOT / "pyproject.toml").read_text())
           ["project"]["classifiers"] if c.startswith("Programming Language :: Python :: 3.")]


@pytest.mark.parametrize("version", CLAIMED)
def test_sdist_installs_and_runs_on_every_claimed_python(version, dists, tmp_path):
    """`requires-python` and the classifiers are true: pip install of the sdist (compiled
    there) and a simulation work on each claimed Python (3.10 reads TOML through tomli)."""
    py = _interpreter(version)
    if py is None:
        pytest.skip("no Python %s on this machine" % version)
    env_dir = tmp_path / "venv"
    _run([py, "-m", "venv", env_dir])
    _run([env_dir / "bin" / "python", "-m", "pip", "install", "--quiet",
          "--disable-pip-version-check", dists[0]])
    r = _run([env_dir / "bin" / "python", "-c", "import sys, pdw; r = pdw.simulate(); "
              "print(sys.version_info[:2], r.status, len(r.events))"], cwd=tmp_path)
    assert r.stdout.split(")")[-1].split() == ["walked", "12"]
    assert r.stdout.startswith("(%s, %s)" % tuple(version.split(".")))
    r = _run([env_dir / "bin" / "pdw", "run", "--example", "typical_gait"], cwd=tmp_path)
    assert "steady (mean of the last 4 steps): L = 0.368" in r.stdout
