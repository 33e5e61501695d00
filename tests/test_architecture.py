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
