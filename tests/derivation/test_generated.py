"""generated/ and pdw/core/_layout.py against derive/.

Fast: every generated file carries `derive.emit.input_hash()` (SHA-256 of derive/*.py and the
SymPy version); a change to derive/ without `make derive` changes the hash. Slower (a few
seconds): regeneration is deterministic across processes with different hash seeds, and gives
the committed bytes (`make test` also runs `python -m derive --check`).
"""
import os
import pathlib
import re
import subprocess
import sys

import pytest

sp = pytest.importorskip("sympy")

import pdw  # noqa: E402
from derive import emit, layout  # noqa: E402
from pdw.core import _core, _layout  # noqa: E402

GENERATED = ("generated/pdw_model.h", "generated/pdw_model.c", "generated/pdw_hybrid.h",
             "generated/pdw_hybrid.c", "generated/pdw_batch_gen.h", "generated/pdw_terrain_gen.h",
             "pdw/core/_layout.py")


@pytest.fixture(scope="module")
def current_hash():
    return emit.input_hash()


def test_layout_module_hash_matches_derive(current_hash):
    assert re.fullmatch(r"[0-9a-f]{64}", current_hash)
    assert _layout.INPUT_HASH == current_hash, "pdw/core/_layout.py is stale: run `make derive`"
    assert pdw.INPUT_HASH == current_hash
    assert _layout.SYMPY_VERSION == sp.__version__


@pytest.mark.parametrize("name", [n for n in GENERATED if n.startswith("generated/")])
def test_generated_c_hash_matches_derive(repo_root, current_hash, name):
    text = (repo_root / name).read_text()
    found = re.findall(r"input hash: ([0-9a-f]{64})", text)
    assert found == [current_hash], "%s is stale: run `make derive`" % name
    assert "SymPy %s" % sp.__version__ in text
    if name.endswith(".h"):
        assert re.search(r'#define PDW_(HYBRID_|BATCH_|TERRAIN_)?INPUT_HASH "%s"' % current_hash, text)


def test_input_hash_covers_every_derive_source(tmp_path, monkeypatch, current_hash):
    """Editing any derive/*.py changes the hash (checked on a copy of derive/)."""
    src = pathlib.Path(emit.__file__).resolve().parent
    files = sorted(src.glob("*.py"))
    assert {f.name for f in files} >= {"model.py", "stages.py", "emit.py", "layout.py", "printer.py"}
    for f in files:
        (tmp_path / f.name).write_bytes(f.read_bytes())
    monkeypatch.setattr(emit, "DERIVE_DIR", tmp_path)
    assert emit.input_hash() == current_hash                     # same bytes, same hash
    for f in files:
        original = (tmp_path / f.name).read_bytes()
        (tmp_path / f.name).write_bytes(original + b"\n")
        assert emit.input_hash() != current_hash, f.name
        (tmp_path / f.name).write_bytes(original)


def test_python_layout_matches_derive_layout():
    assert _layout.STATE == layout.STATE == pdw.STATE
    assert _layout.PARAMS == layout.PARAMS == tuple(pdw.Params.__dataclass_fields__)
    assert _layout.KIN == layout.KIN and _layout.CONTACT == layout.CONTACT
    assert _layout.ENERGY == layout.ENERGY and _layout.NQ == layout.NQ


def test_compiled_extension_matches_layout():
    """The built extension was compiled from the generated files that _layout describes."""
    assert _core.NX == len(_layout.STATE) and _core.NQ == _layout.NQ
    assert _core.NWORK == _layout.NWORK
    assert _core.NP == len(_layout.PARAMS) + len(_layout.DERIVED) + len(_layout.CONTACT_PARAMS)
    table = _core.kernel_table()
    assert [name for name, _, _ in table] == [k[0] for k in _layout.KERNELS]
    assert [_layout.VARIANTS[v] for _, v, _ in table] == [k[1] for k in _layout.KERNELS]


def _regenerate(root, seed):
    env = dict(os.environ, PYTHONHASHSEED=str(seed))
    return subprocess.Popen([sys.executable, "-m", "derive", "--root", str(root)], env=env,
                            cwd=str(pathlib.Path(emit.__file__).resolve().parent.parent),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory):
    """generated/ written twice: by `derive.emit.write_all` in this process, and meanwhile by
    `python -m derive --root` in a child process with another hash seed (set/dict order)."""
    roots = [tmp_path_factory.mktemp("regen%d" % i) for i in range(2)]
    child = _regenerate(roots[1], 12345)
    written = emit.write_all(pathlib.Path(roots[0]))
    out, err = child.communicate(timeout=300)
    assert child.returncode == 0, err.decode()
    assert sorted(str(p.relative_to(roots[0])) for p in written) == sorted(GENERATED)
    return roots


def test_regeneration_is_deterministic(regenerated):
    a, b = regenerated
    for name in GENERATED:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name


def test_committed_files_are_the_regenerated_ones(regenerated, repo_root):
    for name in GENERATED:
        assert (regenerated[0] / name).read_bytes() == (repo_root / name).read_bytes(), \
            "%s differs from derive/: run `make derive`" % name
