"""The flat module paths of pdw.analysis before its subpackages stay importable for one release
(pdw/analysis/_moved.py): the same module object, a DeprecationWarning naming the new path, and
no file left at the old path."""
import importlib
import pathlib
import subprocess
import sys
import warnings

import pytest

import pdw
from pdw.analysis import _moved

ROOT = pathlib.Path(pdw.__file__).resolve().parent

#: the table, written out: a change to MOVED must change this too
EXPECTED = {
    "stepmap": ["section", "poincare", "step_maps", "limit_cycle", "variational", "gait_maps"],
    "rigid": ["hybrid", "chaos"],
    "bifurcation": ["continuation_engine", "continuation", "branch", "codim2", "extension",
                    "testfunctions"],
    "basins": ["basin", "cell_mapping"],
    "robust": ["robustness", "robustness_continuous", "robustness_core", "first_passage",
               "markov"],
    "numerics": ["stability_maps", "calibration"],
}


def test_the_table_is_pinned():
    assert _moved.MOVED == {f"pdw.analysis.{m}": f"pdw.analysis.{pkg}.{m}"
                            for pkg, mods in EXPECTED.items() for m in mods}


def _forget(old):
    """Drop the old name from the module cache and from its package, so it imports afresh."""
    sys.modules.pop(old, None)
    parent, _, leaf = old.rpartition(".")
    sys.modules[parent].__dict__.pop(leaf, None)


@pytest.mark.parametrize("old", sorted(_moved.MOVED))
def test_old_path_imports_as_the_same_module_and_warns(old):
    new = _moved.MOVED[old]
    module = importlib.import_module(new)
    assert (ROOT.parent / (new.replace(".", "/") + ".py")).is_file()
    assert not (ROOT.parent / (old.replace(".", "/") + ".py")).exists(), "a file at the old path"
    _forget(old)
    with pytest.warns(DeprecationWarning, match=rf"{old} moved to {new}\b") as caught:
        assert importlib.import_module(old) is module
    assert caught[0].filename == __file__          # it points at the importing line
    assert module.__name__ == new and module.__spec__.name == new   # its own identity kept
    _forget(old)
    leaf = old.rpartition(".")[2]
    with pytest.warns(DeprecationWarning, match=new):
        exec(f"from pdw.analysis import {leaf} as m; import {old} as m2", ns := {})
    assert ns["m"] is module and ns["m2"] is module
    _forget(old)
    with pytest.warns(DeprecationWarning, match=new):       # attribute access imports it too
        assert getattr(pdw.analysis, leaf) is module


def test_a_name_imported_through_the_old_path_is_the_defining_one():
    _forget("pdw.analysis.limit_cycle")
    with pytest.warns(DeprecationWarning):
        from pdw.analysis.limit_cycle import find_gait
    assert find_gait is pdw.find_gait
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        from pdw.analysis.stepmap.limit_cycle import find_gait as new  # no warning
    assert new is find_gait


def test_unknown_names_still_fail():
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("pdw.analysis.no_such_module")
    with pytest.raises(AttributeError, match="no_such_module"):
        pdw.analysis.no_such_module  # noqa: B018


def test_no_internal_code_imports_an_old_path():
    """Every module of pdw imports in a fresh interpreter with the DeprecationWarning an error."""
    names = []
    for p in sorted(ROOT.rglob("*.py")):
        if "examples" in p.parts or p.name == "__main__.py":
            continue
        rel = p.relative_to(ROOT.parent).with_suffix("")
        names.append(".".join(rel.parts[:-1] if rel.name == "__init__" else rel.parts))
    code = "import importlib\nfor n in %r:\n    importlib.import_module(n)" % names
    run = subprocess.run([sys.executable, "-W", "error::DeprecationWarning", "-c", code],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-2000:]
