"""Example scenes and study files shipped with pdw (package data).

``pdw run --example NAME`` runs a scene, ``pdw sweep --example NAME`` a study,
``pdw continue --example NAME`` a continuation (``continuations/*.toml``, docs/continuation.md),
``pdw robustness --example NAME`` a robustness measure (``robustness/*.toml``, docs/robustness.md);
``--list-examples`` lists them. In Python: `scene_path`, `study_path`, `scenes`, `studies`.

Scenes (``*.toml`` here) are `pdw.Scene` files (docs/scenes.md); studies (``studies/*.toml``)
are parameter studies (docs/studies.md) whose ``[scene]`` table is a `pdw.Scene`.
"""
from __future__ import annotations

import pathlib

from ..core.errors import InvalidInputError

HERE = pathlib.Path(__file__).resolve().parent


def _names(folder: pathlib.Path) -> list:
    return sorted(p.stem for p in folder.glob("*.toml"))


def scenes() -> list:
    """Names of the example scenes."""
    return _names(HERE)


def studies() -> list:
    """Names of the example studies (the paper's Table 5 and Figs. 11-14)."""
    return _names(HERE / "studies")


def _path(folder, names, kind, name) -> pathlib.Path:
    stem = name[:-5] if name.endswith(".toml") else name
    if stem not in names:
        raise InvalidInputError("no example %s %r; available: %s" % (kind, name, ", ".join(names)))
    return folder / (stem + ".toml")


def continuations() -> list:
    """Names of the example continuations (docs/continuation.md)."""
    return _names(HERE / "continuations")


def continuation_path(name: str) -> pathlib.Path:
    """Path of the example continuation ``name`` (e.g. ``"compass_cascade"``)."""
    return _path(HERE / "continuations", continuations(), "continuation", name)


def robustness_specs() -> list:
    """Names of the example robustness specs (docs/robustness.md)."""
    return _names(HERE / "robustness")


def robustness_path(name: str) -> pathlib.Path:
    """Path of the example robustness spec ``name`` (e.g. ``"max_step_k_hip"``)."""
    return _path(HERE / "robustness", robustness_specs(), "robustness spec", name)


def scene_path(name: str) -> pathlib.Path:
    """Path of the example scene ``name`` (e.g. ``"typical_gait"``)."""
    return _path(HERE, scenes(), "scene", name)


def study_path(name: str) -> pathlib.Path:
    """Path of the example study ``name`` (e.g. ``"fig11_k_n"``)."""
    return _path(HERE / "studies", studies(), "study", name)


def describe(path: pathlib.Path) -> str:
    """An example file's description: the first sentence of its leading comment (the comment
    lines before the first key, joined; a sentence ends at ". " before a capital letter or at
    the end of the comment), whole: never cut inside a parenthesis."""
    words: list[str] = []
    for line in path.read_text().splitlines():
        if not line.startswith("#"):
            if words or line.strip():
                break
            continue
        words += line.lstrip("#").split()
    text = " ".join(words)
    depth = 0
    for i, ch in enumerate(text):
        depth += {"(": 1, ")": -1}.get(ch, 0)
        if (ch == "." and depth == 0 and i + 2 < len(text) and text[i + 1] == " "
                and text[i + 2].isupper()):
            return text[:i + 1]
    return text
