"""The package's shape: the public API of before the layers, readable reprs, module sizes."""
import pathlib
import re
import subprocess
import sys
import warnings

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
    "limit_cycle", "cell_mapping", "find_gait", "sweep", "StepSizeWarning", "StepSizeError", "PdwDeprecationWarning",
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
    fell = pdw.simulate(t_end=6.0, record=pdw.Record(every=0),
                        limits=pdw.Limits(on_failure="return"))
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


# --- every option named once (issue 25): the spellings of before, pinned -----------------------

#: simulate's parameters as they were before the option objects (31; the first 17 positional).
SIMULATE_BEFORE = ("x0", "t_end", "dt", "params", "variant", "method", "flags0", "record_every",
                   "record_forces", "on_failure", "fall_hip_height", "fall_depth", "max_speed",
                   "rtol", "atol", "h_max", "event_tol", "features", "record_events",
                   "record_energies", "stop_steps", "periodic_steps", "periodic_tol",
                   "check_step", "t_eval", "dense_output", "out", "max_steps", "contact",
                   "approach_speeds0", "stop_touch_down")
#: simulate_batch's parameters before (the first 22 positional).
BATCH_BEFORE = ("x0", "t_end", "dt", "params", "variant", "method", "flags0", "threads", "lanes",
                "vector", "stop_steps", "periodic_steps", "periodic_tol", "fall_hip_height",
                "fall_depth", "max_speed", "check_step", "rtol", "atol", "h_max", "event_tol",
                "max_steps", "executor", "chunk_size", "record", "record_every",
                "stop_touch_down")
#: One value of each old keyword, off its default, on a short run where it matters.
LEGACY_VALUES = {
    "rtol": 1e-7, "atol": 1e-9, "h_max": 2e-3, "event_tol": 1e-8, "max_steps": 10 ** 6,
    "check_step": "off", "record_every": 2, "record_forces": False, "record_events": False,
    "record_energies": True, "t_eval": (0.01, 0.02), "dense_output": True, "out": "buffer",
    "stop_steps": 1, "periodic_steps": 3, "periodic_tol": 1e-2, "stop_touch_down": 1,
    "fall_hip_height": 0.3, "fall_depth": 0.1, "max_speed": 500.0, "on_failure": "return",
}
#: Where each old keyword lives now (the table pdw.sim.options.LEGACY must equal).
LEGACY_PLACES = {
    "rtol": ("integrator", "rtol"), "atol": ("integrator", "atol"),
    "h_max": ("integrator", "h_max"), "event_tol": ("integrator", "event_tol"),
    "max_steps": ("integrator", "max_steps"), "check_step": ("integrator", "check_step"),
    "record_every": ("record", "every"), "record_forces": ("record", "forces"),
    "record_events": ("record", "events"), "record_energies": ("record", "energies"),
    "t_eval": ("record", "t_eval"), "dense_output": ("record", "dense_output"),
    "out": ("record", "out"), "stop_steps": ("stop", "steps"),
    "periodic_steps": ("stop", "periodic_steps"), "periodic_tol": ("stop", "periodic_tol"),
    "stop_touch_down": ("stop", "touch_down"), "fall_hip_height": ("limits", "fall_hip_height"),
    "fall_depth": ("limits", "fall_depth"), "max_speed": ("limits", "max_speed"),
    "on_failure": ("limits", "on_failure"),
}


def test_every_old_keyword_of_simulate_is_still_accepted():
    """Each parameter of before is a parameter now or a line of the one mapping table."""
    import inspect

    from pdw.sim.options import LEGACY, POSITIONAL
    now = inspect.signature(pdw.simulate).parameters
    assert all(n in now or n in LEGACY for n in SIMULATE_BEFORE)
    assert all(n in inspect.signature(pdw.simulate_batch).parameters or n in LEGACY
               for n in BATCH_BEFORE)
    assert POSITIONAL["simulate"] == SIMULATE_BEFORE[3:17]
    assert POSITIONAL["simulate_batch"] == BATCH_BEFORE[3:22]
    assert set(LEGACY_VALUES) == set(LEGACY) and LEGACY == LEGACY_PLACES


def test_only_x0_t_end_dt_are_positional():
    import inspect
    for fn in (pdw.simulate, pdw.simulate_batch, pdw.simulate_many):
        kinds = [(p.name, p.kind) for p in inspect.signature(fn).parameters.values()]
        pos = [n for n, k in kinds if k == inspect.Parameter.POSITIONAL_OR_KEYWORD]
        assert pos == ["x0", "t_end", "dt"], fn


@pytest.mark.parametrize("old", sorted(LEGACY_VALUES))
def test_old_keyword_warns_and_maps_to_its_field(old):
    """simulate(old=v) warns naming the new spelling, runs exactly as the option object with
    that field, and the Result reports the field set (the mapping old -> (object, field))."""
    from pdw.sim.options import OPTION_SECTIONS, new_spelling
    section, name = LEGACY_PLACES[old]
    value = LEGACY_VALUES[old]
    if value == "buffer":
        value = pdw.RecordBuffer()
    method = "rodas4" if section == "integrator" and old != "check_step" else "cdm"
    kw = dict(t_end=0.3, params=pdw.Params.paper(), method=method)
    with pytest.warns(DeprecationWarning, match=r"%s\(%s=\.\.\.\) is deprecated; write %s"
                      % ("simulate", old, re.escape(new_spelling(old).split("(")[0]))):
        r_old = pdw.simulate(**kw, **{old: value})
    fields = {"periodic": True, "periodic_steps": value} if old == "periodic_steps" else \
        {name: value}
    r_new = pdw.simulate(**kw, **{section: OPTION_SECTIONS[section](**fields)})
    got = getattr(getattr(r_old, section), name)
    assert got == (tuple(value) if isinstance(value, tuple) else value)
    if old == "periodic_steps":
        assert r_old.stop.periodic
    for a in ("t", "x", "x_final", "Fn"):
        assert np.array_equal(getattr(r_old, a), getattr(r_new, a)), a
    assert (r_old.status, r_old.stop_reason, r_old.n_steps) == \
        (r_new.status, r_new.stop_reason, r_new.n_steps)


def test_an_unasserted_deprecation_is_an_error_in_the_tests():
    """pyproject.toml's filterwarnings makes a deprecation of pdw that a test does not assert
    an error (here an old keyword, which warns and runs outside the tests), not a third
    party's DeprecationWarning."""
    with pytest.raises(pdw.PdwDeprecationWarning,
                       match=r"simulate\(record_every=\.\.\.\) is deprecated"):
        pdw.simulate(t_end=0.01, record_every=0)
    with warnings.catch_warnings(record=True) as rec:      # a dependency's: a warning, no error
        warnings.warn("numpy.foo is deprecated", DeprecationWarning, stacklevel=1)
    assert [w.category for w in rec] == [DeprecationWarning]
    with pytest.warns(DeprecationWarning, match=r"write record=pdw\.Record\(every=\.\.\.\)"):
        assert len(pdw.simulate(t_end=0.01, record_every=0).t) == 0


def _by_position(rec):
    """The argument named by each warning recorded (all of them "passing NAME by position")."""
    names = [re.match(r"simulate(?:_batch)?: passing (\w+) by position is deprecated",
                      str(w.message)) for w in rec]
    assert all(names), [str(w.message) for w in rec]
    return [m.group(1) for m in names]


def test_old_positional_form_warns_and_works():
    """issue 26 item 13: simulate(x0, 3.5, 1e-4, None, "paper", "rk4") is legal for one release."""
    with pytest.warns(DeprecationWarning) as rec:           # one warning per argument
        r = pdw.simulate(pdw.X0_PAPER, 0.2, 1e-4, None, "paper", "rk4")
    assert _by_position(rec) == ["params", "variant", "method"]
    assert r.method == "rk4" and r.integrator.method == "rk4"
    assert np.array_equal(r.x_final, pdw.simulate(pdw.X0_PAPER, 0.2, 1e-4, method="rk4").x_final)
    with pytest.warns(DeprecationWarning) as rec:
        b = pdw.simulate_batch(np.array([pdw.X0_PAPER]), 2.0, 1e-4, None, "paper", "cdm",
                               (0, 1), 1, 8, False, 1)
    assert _by_position(rec) == ["params", "variant", "method", "flags0", "threads", "lanes",
                                 "vector", "stop_steps"]
    assert b.stop_reason[0] == "steps"
    with pytest.raises(pdw.InvalidInputError, match="at most 17 positional"):
        pdw.simulate(pdw.X0_PAPER, 0.2, 1e-4, *([None] * 15))


# --- the map of the house stays true (issue 25 part 2) ------------------------------------------

def _map_entries():
    """(package, entry) of every line of the map in docs/architecture.md: ("sim", "options"),
    ("core", "_core.pyx"), ("core", "csrc/"), ("", "__init__.py"), ("", "examples/"), and
    for a subpackage ("analysis", "stepmap/") and its modules ("analysis/stepmap", "section")."""
    text = (ROOT / "docs" / "architecture.md").read_text()
    block = text.split("## The picture", 1)[1].split("```")[1]
    entries, package, sub = [], None, None
    for line in block.splitlines():
        head = re.match(r"^ pdw\.(\w+)\s+\d", line)
        if head:
            package, sub = head.group(1), None
            continue
        top = re.match(r"^ pdw/(\S+)", line)
        if top:
            entries.append(("", top.group(1)))
            continue
        entry = re.match(r"^   (\S+)", line)
        if entry and package:
            entries.append((package, entry.group(1)))
            sub = entry.group(1) if entry.group(1).endswith("/") else None
            continue
        inner = re.match(r"^     (\S+)", line)
        if inner and sub and package:
            entries.append((f"{package}/{sub[:-1]}", inner.group(1)))
    return entries


def _modules():
    """(package, entry) of every module under pdw/, as the map names them."""
    out = set()
    for p in (ROOT / "pdw").rglob("*"):
        rel = p.relative_to(ROOT / "pdw")
        if "__pycache__" in rel.parts or p.suffix not in (".py", ".pyx"):
            continue
        if len(rel.parts) == 1:
            out.add(("", rel.name))
        elif rel.parts[0] == "examples":
            out.add(("", "examples/"))
        elif rel.name == "__init__.py":
            if len(rel.parts) == 3:                      # a subpackage: its line ends in "/"
                out.add((rel.parts[0], rel.parts[1] + "/"))
        else:
            out.add(("/".join(rel.parts[:-1]), rel.name if p.suffix == ".pyx" else p.stem))
    return out


def test_every_module_has_a_line_in_the_architecture_map_and_every_line_a_module():
    entries = _map_entries()
    listed = {e for e in entries if not e[1].endswith("/") or e[0] == ""
              or (ROOT / "pdw" / e[0] / e[1] / "__init__.py").is_file()}
    modules = _modules()
    assert not sorted(modules - listed), "modules without a line in docs/architecture.md"
    assert not sorted(listed - modules), "lines of docs/architecture.md naming no module"
    for package, entry in entries:
        if entry.endswith("/"):
            assert (ROOT / "pdw" / package / entry).is_dir(), entry
    assert len(entries) == len(set(entries)), "a module listed twice"


_DOTTED = re.compile(r"(?<![\w/.-])pdw(?:\.[A-Za-z_][A-Za-z0-9_]*)+")


def _resolves(path):
    """Does the dotted path name a module or an attribute of one?"""
    import importlib
    if path.startswith("pdw.__main__"):          # importing it would run the command line
        return path == "pdw.__main__"
    from pdw.analysis._moved import MOVED
    if any(path == old or path.startswith(old + ".") for old in MOVED):
        return False                              # a deprecated alias: cite the new path
    parts = path.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for name in parts[i:]:
            if not hasattr(obj, name):
                return False
            obj = getattr(obj, name)
        return True
    return False


def test_every_dotted_pdw_path_in_docstrings_and_docs_resolves():
    import ast
    texts = []
    for p in sorted((ROOT / "pdw").rglob("*.py")):
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef,
                                 ast.ClassDef)):
                doc = ast.get_docstring(node, clean=False)
                if doc:
                    texts.append((p.relative_to(ROOT), doc))
    texts += [(p.relative_to(ROOT), p.read_text()) for p in sorted((ROOT / "docs").glob("*.md"))]
    texts.append((pathlib.Path("README.md"), (ROOT / "README.md").read_text()))
    stale = sorted({(str(where), m.group(0).rstrip(".")) for where, text in texts
                    for m in _DOTTED.finditer(text) if not _resolves(m.group(0).rstrip("."))})
    assert not stale


def test_the_c_loops_only_read_their_options():
    """pdw_run_opts (pdw_sim.h) is filled before a run and read by the loops: the only writes
    to it in the hand-written C are the ensemble's lane set-up (load_walker, start,
    pdw_batch_start_method in pdw_batch.c)."""
    setup = ("load_walker", "start", "pdw_batch_start_method")
    writes = []
    for p in sorted((ROOT / "pdw" / "core" / "csrc").glob("*")):
        if p.suffix not in (".c", ".h", ".inc"):
            continue
        fn = None
        for n, line in enumerate(p.read_text().splitlines(), 1):
            head = re.match(r"^(?:static |inline |const )*[a-z_]+[ *]+([a-z_0-9]+)\(", line)
            if head:
                fn = head.group(1)
            if re.search(r"(->|\.)opt(\.[a-z_]+)?\s*=[^=]", line) and \
                    not (p.name == "pdw_batch.c" and fn in setup):
                writes.append("%s:%d (%s): %s" % (p.name, n, fn, line.strip()))
    assert not writes
