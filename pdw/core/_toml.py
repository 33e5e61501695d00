"""TOML for pdw: one reader, one writer.

Reading is `tomllib` (standard library from Python 3.11) or, on 3.10, `tomli` (the same parser,
a dependency there). Writing is `tomli_w` (the same author's writer): every TOML file pdw writes
(scenes, the scene part of a study) goes through `dumps`.
"""
from __future__ import annotations

import sys

import tomli_w

if sys.version_info >= (3, 11):
    import tomllib
else:                                  # pragma: no cover - exercised on Python 3.10
    import tomli as tomllib

TOMLDecodeError = tomllib.TOMLDecodeError
loads = tomllib.loads


def dumps(data: dict, header: str = "") -> str:
    """TOML text of ``data`` (tables nested as dicts; None values and empty tables left out:
    TOML has no null), after the comment lines of ``header``."""
    def clean(d):
        return {k: clean(v) if isinstance(v, dict) else (list(v) if isinstance(v, tuple) else v)
                for k, v in d.items() if v is not None and v != {}}
    text = tomli_w.dumps(clean(data))
    head = "".join("# %s\n" % line for line in header.splitlines()) if header else ""
    return head + text
