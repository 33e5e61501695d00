"""Docs that run: every fenced code block of README.md and docs/*.md is executed here.

What a block's info string (its language) means:

* ``python``: executed; the blocks of one page share one namespace, in order (a page reads
  like a notebook). A statement whose line ends in ``# -> EXPECTED`` is checked: its printed
  output (for a ``print(...)`` call) or the ``str`` of its value must match EXPECTED -- the same
  words in the same order, and the same numbers to the precision written (``# -> walked 12``,
  ``# -> [0, 39.7]``). Other comments are prose.
* ``sh`` / ``bash`` / ``shell`` / ``console``: run as one bash script (``set -e``) from the
  repository root (commands write to the ignored ``out/``), with the test's Python first on PATH
  (``pdw`` is its console script, ``python`` the test's interpreter); every command must succeed.
  Python blocks run in a scratch folder (the files they write do not land in the checkout).
* ``toml``: parsed; a table with ``[[axes]]`` must be a valid study (`pdw.sweep.parse_study`),
  any other a valid scene (`pdw.Scene.from_toml`).
* any other info string (``text``, ``c``, none, ...) is not code and is not run.

A runnable block that must not run in the test suite is marked explicitly by an HTML comment
on the line just before it, with the reason: ``<!-- docs-test: skip (runs the whole test
suite) -->``. A skip without a reason fails. Pages added later are picked up automatically.
"""
from __future__ import annotations

import ast
import contextlib
import io
import os
import pathlib
import re
import subprocess
import sys

import pytest

import pdw

ROOT = pathlib.Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))
RUN = {"python": "python", "py": "python", "sh": "sh", "bash": "sh", "shell": "sh",
       "console": "sh", "toml": "toml"}
FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*([^\s`{]*)")
SKIP = re.compile(r"<!--\s*docs-test:\s*skip\s*(?:\((?P<reason>[^)]*)\))?\s*-->")
CLAIM = re.compile(r"#\s*->\s*(?P<expected>.*?)\s*$")
TOKEN = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[A-Za-z_][A-Za-z_0-9]*")


def blocks(path: pathlib.Path) -> list:
    """The fenced blocks of a Markdown page: dicts with lang, line (1-based), code, skip."""
    out, lines, i = [], path.read_text().splitlines(), 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, fence, lang = m.group(1), m.group(2), m.group(3).lower()
        start, body = i, []
        i += 1
        while i < len(lines) and not lines[i].strip().startswith(fence[0] * len(fence)):
            body.append(lines[i][len(indent):] if lines[i].startswith(indent) else lines[i])
            i += 1
        i += 1
        prev = next((lines[k] for k in range(start - 1, -1, -1) if lines[k].strip()), "")
        sk = SKIP.search(prev)
        out.append({"lang": lang, "line": start + 1, "code": "\n".join(body),
                    "skip": None if sk is None else (sk.group("reason") or "").strip()})
    return out


# --- checking a claimed output ----------------------------------------------------------------

def _tokens(text: str) -> list:
    return TOKEN.findall(text)


def _is_number(tok: str) -> bool:
    return bool(re.fullmatch(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", tok))


def _close(actual: float, expected: str) -> bool:
    """``actual`` equals the number written as ``expected`` to the precision written."""
    mant, _, exp = expected.lower().partition("e")
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    half_ulp = 0.5 * 10.0 ** (-decimals) * (10.0 ** int(exp) if exp else 1.0)
    return abs(actual - float(expected)) <= half_ulp * (1 + 1e-9)


def check_claim(actual: str, expected: str, where: str):
    """The numbers of ``expected`` match those of ``actual`` one for one (to the precision
    written), and its words appear in ``actual`` in the same order."""
    a, e = _tokens(actual), _tokens(expected)
    an, en = [t for t in a if _is_number(t)], [t for t in e if _is_number(t)]
    assert len(an) == len(en), "%s: claimed %r, got %r (numbers differ in count)" % (
        where, expected, actual)
    for x, y in zip(an, en):
        assert _close(float(x), y), "%s: claimed %r, got %r (%s vs %s)" % (
            where, expected, actual, x, y)
    words = iter([t for t in a if not _is_number(t)])
    for w in (t for t in e if not _is_number(t)):
        assert any(w == x for x in words), "%s: claimed %r, got %r (word %r)" % (
            where, expected, actual, w)


# --- running blocks ---------------------------------------------------------------------------

def run_python(code: str, ns: dict, where: str):
    tree = ast.parse(code)
    lines = code.splitlines()
    for node in tree.body:
        last = lines[node.end_lineno - 1]
        claim = CLAIM.search(last) if "#" in last else None
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            if isinstance(node, ast.Expr):
                value = eval(compile(ast.Expression(node.value), where, "eval"), ns)
            else:
                exec(compile(ast.Module([node], []), where, "exec"), ns)
                value = None
        printed = buf.getvalue()
        sys.stdout.write(printed)
        if claim:
            is_print = isinstance(node, ast.Expr) and isinstance(node.value, ast.Call) and \
                getattr(node.value.func, "id", "") == "print"
            actual = printed if is_print or value is None else str(value)
            check_claim(actual, claim.group("expected"), "%s line %d" % (where, node.end_lineno))


def run_sh(code: str, cwd: pathlib.Path, where: str):
    """Run the block as one bash script (``set -e``: every command must succeed) from the
    repository root, as the docs say (outputs go to the ignored out/); ``cwd`` holds the
    interpreter shim."""
    env = dict(os.environ)
    shim = cwd / "_bin"                      # `python` and `pdw` are the test's interpreter's
    shim.mkdir(exist_ok=True)
    (shim / "python").unlink(missing_ok=True)
    (shim / "python").symlink_to(sys.executable)
    env["PATH"] = os.pathsep.join([str(shim), str(pathlib.Path(sys.executable).parent),
                                   env.get("PATH", "")])
    p = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", code], cwd=ROOT, env=env,
                       capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, "%s: the block exited %d:\n%s%s" % (
        where, p.returncode, p.stdout[-3000:], p.stderr[-3000:])


def run_toml(code: str, where: str):
    from pdw.core import _toml
    from pdw.studies.study import parse_study
    data = _toml.loads(code)
    if "axes" in data:
        parse_study(code, name=where)
    else:
        pdw.Scene.from_toml(code, source=where)


def _page_id(path):
    return str(path.relative_to(ROOT))


@pytest.mark.parametrize("page", PAGES, ids=_page_id)
def test_page_code_blocks_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    ns = {"__name__": "__main__"}              # a page is a script: its main guard runs
    for b in blocks(page):
        kind = RUN.get(b["lang"])
        where = "%s:%d" % (_page_id(page), b["line"])
        if kind is None:
            continue
        if b["skip"] is not None:
            assert b["skip"], \
                "%s: a skipped block must say why: <!-- docs-test: skip (reason) -->" % where
            continue
        if kind == "python":
            run_python(b["code"], ns, where)
        elif kind == "sh":
            run_sh(b["code"], tmp_path, where)
        else:
            run_toml(b["code"], where)
    if not any(RUN.get(b["lang"]) for b in blocks(page)):
        pytest.skip("no runnable block on this page")


# --- the checker itself can fail -----------------------------------------------------------------

@pytest.mark.parametrize("actual, expected, ok", [
    ("walked 12\n", "walked 12", True),
    ("walked 13\n", "walked 12", False),
    ("fell 12\n", "walked 12", False),
    ("array([ 0.        , 39.71234])", "[0, 39.7]", True),
    ("array([ 0.        , 39.81234])", "[0, 39.7]", False),
    ("0.36851", "0.3685", True),
    ("0.36861", "0.3685", False),
    ("1.04e-05", "1e-5", True),
    ("1 2 3", "1 2", False),
])
def test_claim_checker(actual, expected, ok):
    if ok:
        check_claim(actual, expected, "t")
    else:
        with pytest.raises(AssertionError):
            check_claim(actual, expected, "t")


def test_block_parser_and_skip_marker(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("text\n\n```python\nx = 1\n```\n\n<!-- docs-test: skip (too slow) -->\n"
                    "```sh\nmake study\n```\n\n```\nplain\n```\n")
    bs = blocks(page)
    assert [(b["lang"], b["skip"]) for b in bs] == [("python", None), ("sh", "too slow"),
                                                    ("", None)]
    assert bs[0]["code"] == "x = 1" and bs[0]["line"] == 3


#: References that must not come back (issue 26 item 17): the specification is docs/model.md,
#: the product never points at the development workspace, and the compiled modules and the
#: layouts live in pdw.core.
STALE = re.compile(r"MODEL\.md|\.\./shared|/work/shared|(?<![\w.])shared/|pdw\._layout\b|"
                   r"pdw\._core\b|pdw\._hybrid\b|pdw\._batch\b")
TEXT_SUFFIXES = {".py", ".pyx", ".pxi", ".pyi", ".c", ".h", ".inc", ".md", ".toml", ".txt",
                 ".rst", ".cfg", ".in"}


def _product_files():
    yield ROOT / "README.md"
    for top in ("pdw", "docs", "benchmarks", "derive", "generated"):
        for p in sorted((ROOT / top).rglob("*")):
            if p.is_file() and p.suffix in TEXT_SUFFIXES and "__pycache__" not in p.parts:
                yield p


def test_no_stale_references_in_the_product():
    hits = []
    for p in _product_files():
        for n, line in enumerate(p.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
            if STALE.search(line):
                hits.append("%s:%d: %s" % (p.relative_to(ROOT), n, line.strip()))
    assert hits == [], "\n".join(hits)


def test_the_stale_reference_pattern_catches_what_it_should():
    for bad in ("see MODEL.md section 6", "../shared/paper.pdf", "/work/shared/tools",
                "`pdw._layout.FEATURES`", "pdw._core", "in shared/notes"):
        assert STALE.search(bad), bad
    for good in ("docs/model.md section 6", "pdw.core._layout.FEATURES", "pdw.core._core",
                 "a shared library", "shared memory"):
        assert not STALE.search(good), good


def test_work_precision_doc_does_not_send_users_to_private_batches():
    """docs/work_precision.md told users to call _core.rhs_batch; the public face is pdw.rhs."""
    import pathlib
    text = (pathlib.Path(__file__).resolve().parent.parent / "docs" / "work_precision.md").read_text()
    assert "_core.rhs_batch" not in text and "pdw.rhs" in text
