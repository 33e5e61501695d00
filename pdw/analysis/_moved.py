"""The import paths of before the subpackages, kept for one release as aliases.

``pdw.analysis`` was 24 flat modules; 23 of them now live in subpackages
(`docs/architecture.md`). Each old path in `MOVED` still imports, as the *same* module object
as its new path (``limit_cycle`` of ``pdw.analysis`` is ``stepmap.limit_cycle``), with a
`DeprecationWarning` naming the new path. No file stays at an old path: a meta-path finder
(`AliasFinder`, installed by ``pdw/analysis/__init__.py``) answers the old names and hands back
the module of the new name from `sys.modules`. `tests/analysis/test_moved_paths.py` pins the table.
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import os
import sys
import types
import warnings

from ..core.errors import PdwDeprecationWarning

#: old dotted path -> new dotted path of every module that moved into a subpackage
MOVED = {f"pdw.analysis.{old}": f"pdw.analysis.{package}.{old}" for old, package in (
    # the one-step (touch-down Poincare) map of the continuous walker and its gaits
    ("section", "stepmap"), ("poincare", "stepmap"), ("step_maps", "stepmap"),
    ("limit_cycle", "stepmap"), ("variational", "stepmap"), ("gait_maps", "stepmap"),
    # the rigid-ground (hybrid impact-momentum) walker
    ("hybrid", "rigid"), ("chaos", "rigid"),
    # numerical continuation and bifurcations
    ("continuation_engine", "bifurcation"), ("continuation", "bifurcation"),
    ("branch", "bifurcation"), ("codim2", "bifurcation"), ("extension", "bifurcation"),
    ("testfunctions", "bifurcation"),
    # basins of attraction
    ("basin", "basins"), ("cell_mapping", "basins"),
    # robustness on ground that is not uniform
    ("robustness", "robust"), ("robustness_continuous", "robust"),
    ("robustness_core", "robust"), ("first_passage", "robust"), ("markov", "robust"),
    # the numerics of the compliant contact
    ("stability_maps", "numerics"), ("calibration", "numerics"),
)}


#: the files whose frames a warning skips: this module and the package's ``__getattr__``
_OURS = (os.path.abspath(__file__), os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                 "__init__.py"))


def _ours(filename: str) -> bool:
    """Is the frame's file the import machinery or this mechanism?"""
    return (filename.startswith("<frozen importlib") or os.path.abspath(filename) in _OURS
            or os.path.basename(os.path.dirname(filename)) == "importlib")


def _bootstrap(filename: str) -> bool:
    """A frame of importlib's bootstrap, which `warnings.warn` skips on its own."""
    return "importlib" in filename and "_bootstrap" in filename


def _caller_stacklevel() -> int:
    """The stacklevel of the first frame outside the import machinery and this mechanism, so
    that the warning points at the line that imported the old path."""
    frame: types.FrameType | None = sys._getframe(1)
    level = 1
    while frame is not None and _ours(frame.f_code.co_filename):
        frame = frame.f_back
        # `warnings.warn` does not count the frames of importlib._bootstrap (it skips them)
        if frame is not None and not _bootstrap(frame.f_code.co_filename):
            level += 1
    return level


class AliasFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds the old paths of `MOVED`; loads each as the module of its new path."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname not in MOVED:
            return None
        return importlib.machinery.ModuleSpec(fullname, self)

    def create_module(self, spec):
        new = MOVED[spec.name]
        warnings.warn(f"{spec.name} moved to {new}; import it from there (the old path goes "
                      "in the next release)", PdwDeprecationWarning, stacklevel=_caller_stacklevel())
        module = importlib.import_module(new)
        spec.loader_state = module.__spec__       # the import system overwrites __spec__
        return module

    def exec_module(self, module: types.ModuleType) -> None:
        # the module ran under its new name already; give it back its own spec
        if module.__spec__ is not None:
            module.__spec__ = module.__spec__.loader_state


def install() -> None:
    """Put the finder first on `sys.meta_path` (once)."""
    if not any(isinstance(f, AliasFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, AliasFinder())


def attribute(name: str) -> types.ModuleType:
    """``pdw.analysis.<old>`` as an attribute (module ``__getattr__``): imports the alias."""
    full = f"pdw.analysis.{name}"
    if full not in MOVED:
        raise AttributeError(f"module 'pdw.analysis' has no attribute {name!r}")
    return importlib.import_module(full)
