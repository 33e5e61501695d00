"""The package's shape: the public API of before the layers, readable reprs, module sizes."""
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import pdw

ROOT = pathlib.Path(__file__).resolve().parents[1]

#: pdw.__all__ as it was before the layers (issue 10): every name must keep importing from pdw.
PUBLIC_BEFORE_LAYERS = [
    "Params", "rhs", "jacobian", "mass_matrix", "contact_forces", "ContactState", "energies",
    "STATE", "VARIANTS", "INPUT_HASH", "simulate", "Result", "Event", "METHODS", "X0_PAPER",
    "X0_DISTURBED", "steps", "Steps", "PdwError", "SimulationError", "DivergedError",
    "SingularSystemError", "FellError", "InvalidInputError", "hybrid", "Gait", "Scene", "run",
    "limit_cycle", "cell_mapping", "find_gait", "sweep", "StepSizeWarning", "StepSizeError",
]


def test_public_names_of_before_the_layers_still_import():
    missing = [n for n in PUBLIC_BEFORE_LAYERS if n not in pdw.__all__ or not hasattr(pdw, n)]
    assert not missing


@pytest.mark.parametrize("name", ["hybrid", "limit_cycle", "cell_mapping", "sweep", "scene"])
def test_public_modules_keep_their_flat_import_path(name):
    code = "import importlib, pdw; m = importlib.import_module('pdw.%s'); print(m.__name__)" % name
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().startswith("pdw.") and out.stdout.strip() != "pdw." + name


def test_no_module_over_500_lines_without_a_stated_reason():
    long = []
    for p in sorted((ROOT / "pdw").rglob("*.py")):
        n = len(p.read_text().splitlines())
        if n > 540 and "Why this module is long" not in p.read_text()[:4000]:
            long.append("%s: %d lines" % (p.relative_to(ROOT), n))
    assert not long


def _repr_ok(text, must):
    lines = text.splitlines()
    assert 1 <= len(lines) <= 6 and max(len(s) for s in lines) <= 160, text
    for m in must:
        assert m in text, (m, text)


def test_result_repr_is_a_few_readable_lines():
    r = pdw.simulate(t_end=1.2)
    _repr_ok(repr(r), ["walked", "cdm", "touch-downs", "last step: leg", "L 0."])
    assert str(len(r.t)) in repr(r) and "array(" not in repr(r)
    fell = pdw.simulate(t_end=6.0, record_every=0, on_failure="return")
    _repr_ok(repr(fell), ["fell", "failure:", "fall_depth"])


def test_steps_and_gait_reprs_are_short():
    st = pdw.simulate(t_end=2.0).gait
    _repr_ok(repr(st), ["%d steps" % len(st), "last: leg"])
    g = pdw.hybrid.find_gait(pdw.Params.paper_steady())
    _repr_ok(repr(g), ["hybrid", "stable", "period", "|multipliers|"])
    assert "%.6g" % g.period in repr(g)
    assert np.isfinite(g.period)


def test_import_pdw_needs_no_fcntl():
    """Issue 26 item 16: `import pdw` (and a study file's parsing) works where fcntl does not
    exist (Windows); the lock imports it where it is taken."""
    code = ("import sys\n"
            "class Block:\n"
            "    def find_spec(self, name, path=None, target=None):\n"
            "        if name == 'fcntl':\n"
            "            raise ImportError('no fcntl here')\n"
            "sys.meta_path.insert(0, Block())\n"
            "sys.modules.pop('fcntl', None)\n"
            "import pdw, pdw.sweep, pdw.present.cli\n"
            "assert 'fcntl' not in sys.modules, 'fcntl was imported'\n"
            "print('ok', pdw.__version__)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=pathlib.Path(__file__).resolve().parent.parent, timeout=120)
    assert out.returncode == 0 and out.stdout.startswith("ok"), out.stderr[-2000:]


def test_gait_not_found_error_is_public():
    """Issue 26 item 12: the error find_gait and continue_gait raise is importable from pdw."""
    from pdw.analysis.gait_types import GaitNotFoundError
    assert pdw.GaitNotFoundError is GaitNotFoundError and "GaitNotFoundError" in pdw.__all__
    assert issubclass(pdw.GaitNotFoundError, pdw.PdwError)
