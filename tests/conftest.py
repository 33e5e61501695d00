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
