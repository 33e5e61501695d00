"""Shared fixtures of the pipeline tests (symbolic, compiled-vs-symbolic, physics, params, generated).

The symbolic derivation (`derive/`) lives at the repository root and is not part of the
installed package: put the root on sys.path so that ``import derive`` works however pytest
is started. It goes at the *end* of sys.path, so that an installed pdw (a wheel, with its
compiled modules) wins over the uncompiled sources of an unpacked sdist.
"""
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.append(str(ROOT))


#: The files of ``make test-quick`` (marker ``quick``): the parameters, one simulation and its
#: gait descriptors, scenes, the ODE object, the command line, the output-file rules and the
#: package's shape -- one fast file per layer that a change most often breaks. Not covered
#: there: the symbolic derivation and the compiled-vs-symbolic checks, integrators'
#: convergence, the ensemble engine, gaits, continuation, sweeps, contact laws, docs.
QUICK_FILES = {"test_params.py", "test_simulation.py", "test_gait.py", "test_scenes.py",
               "test_ode_function.py", "test_cli.py", "test_paths.py", "test_architecture.py"}




def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.path.name in QUICK_FILES:
            item.add_marker(pytest.mark.quick)


@pytest.fixture(scope="session")
def repo_root():
    """The repository root (holds derive/, generated/, pdw/)."""
    return ROOT


@pytest.fixture(scope="session")
def mech():
    """`derive.model.mechanics()`, computed once per session (a few seconds of SymPy)."""
    pytest.importorskip("sympy")
    from derive import model

    return model.mechanics()
