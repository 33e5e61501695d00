"""Optional dependencies of the command line: one rule for every command.

A command checks what it needs *before* its work (`require`): figures need matplotlib (and, for
``pdw walk``'s GIF, Pillow) unless ``--no-figures``; ``--scheduler`` / ``--dask-local`` need
Dask. A missing one is `MissingDependency` (an ImportError): ``pdw`` prints one line naming the
extra that installs it and exits with code 4, having computed and written nothing.
"""
from __future__ import annotations

import importlib

#: Optional dependencies (top-level modules) and the extra of pdw that installs them.
EXTRAS = {"matplotlib": "plot", "PIL": "plot", "distributed": "dask", "dask": "dask",
          "scipy": "test", "sympy": "derive"}
#: What to say instead of doing without: the option that drops the need, per module.
ALTERNATIVE = {"matplotlib": "--no-figures", "PIL": "--no-figures"}


class MissingDependency(ImportError):
    """An optional dependency a command needs is not installed (exit code 4)."""


def missing_extra(e: ImportError) -> str | None:
    """One line naming the extra that provides the module ``e`` failed to import, or None."""
    top = (getattr(e, "name", None) or "").split(".")[0]
    if top not in EXTRAS:
        return None
    line = "%s is not installed: pip install 'pdw[%s]'" % (top, EXTRAS[top])
    if top in ALTERNATIVE:
        line += " (or %s)" % ALTERNATIVE[top]
    return line


def require(*modules: str, purpose: str = "") -> None:
    """Import each of ``modules`` (top-level names of `EXTRAS`) or raise `MissingDependency`
    naming the first missing one, what needs it (``purpose``) and the extra; its message is
    the line ``pdw`` prints."""
    for name in modules:
        try:
            importlib.import_module(name)
        except ImportError as e:
            top = (getattr(e, "name", None) or "").split(".")[0]
            name = top if top in EXTRAS else name        # e.g. PIL, missing under matplotlib
            need = " (needed for %s)" % purpose if purpose else ""
            line = "%s is not installed%s: pip install 'pdw[%s]'" % (name, need, EXTRAS[name])
            if name in ALTERNATIVE:
                line += ", or run with %s" % ALTERNATIVE[name]
            raise MissingDependency(line + "; nothing was computed", name=name) from e
