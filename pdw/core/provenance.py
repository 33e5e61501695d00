"""Where a result came from: pdw's version, the derivation's INPUT_HASH and pdw's own source
revision.

`source_revision` describes the git checkout pdw is imported from, and only that: when pdw
is installed (site-packages, a wheel) it is None, even if the user's working directory or the
virtual environment sits inside some other git repository.
"""
from __future__ import annotations

import functools
import pathlib
import platform
import subprocess
import sys

import numpy as np

_PACKAGE = pathlib.Path(__file__).resolve().parent.parent        # .../pdw


def _git(root, *args):
    try:
        out = subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True,
                             timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() if out.returncode == 0 else None


@functools.lru_cache(maxsize=None)
def source_revision(package_dir: str | None = None) -> str | None:
    """``git describe --always --dirty --tags`` of pdw's own source checkout, or None.

    It is reported only when the package directory (default: the imported ``pdw``) is the
    ``pdw/`` of a git work tree that tracks this very file's package (``pdw/__init__.py``);
    an installed copy inside some other repository gets None, never that repository's commit.
    """
    pkg = pathlib.Path(package_dir).resolve() if package_dir else _PACKAGE
    root = pkg.parent
    top = _git(root, "rev-parse", "--show-toplevel")
    if top is None or pathlib.Path(top).resolve() != root:
        return None
    if _git(root, "ls-files", "--error-unmatch", str(pkg.relative_to(root) / "__init__.py")) is None:
        return None
    return _git(root, "describe", "--always", "--dirty", "--tags") or None


def provenance() -> dict:
    """pdw_version, input_hash, source_revision, python, numpy, platform (JSON-able)."""
    from . import __version__, _layout
    return {"pdw_version": __version__, "input_hash": _layout.INPUT_HASH,
            "source_revision": source_revision(), "python": sys.version.split()[0],
            "numpy": np.__version__, "platform": platform.platform()}
