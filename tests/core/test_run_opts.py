"""The compiled loops' options, one record (issue 25): pdw_run_opts declared once for Cython,
filled by one filler for both entry points (`_core.run`, `_batch.run_range`), from the option
objects (`pdw.sim.options.c_options`)."""
import re

import numpy as np
import pytest

import pdw
from pdw.core import _batch, _core
from pdw.core.model import kernel_index, parameter_vector
from pdw.sim.batch import _outputs
from pdw.sim.options import Limits, Stop, c_options

X = np.array(pdw.X0_PAPER)
P = parameter_vector(pdw.Params.paper())
K = kernel_index("paper", None)
BASE = dict(dt=1e-4, n_steps=20000, fall_hip_height=0.4, fall_depth=0.2, max_speed=1e3)


def _struct_fields(text, name):
    """The field names of C struct `name` in text (a header or a Cython declaration)."""
    body = re.search(r"typedef struct %s \{(.*?)\} %s;" % (name, name), text, re.S)
    if body is None:    # Cython: "ctypedef struct name:" then indented declarations
        block = text.split("ctypedef struct %s:" % name, 1)[1]
        lines = []
        for line in block.splitlines()[1:]:
            if line.strip() and not line.startswith(" " * 8):
                break
            lines.append(line.split("#")[0])
        decls = ";".join(lines)
    else:
        decls = re.sub(r"/\*.*?\*/", "", body.group(1), flags=re.S)
    names = []
    for decl in decls.split(";"):
        words = decl.replace("\n", " ").split()
        if len(words) >= 2:     # "double rtol, atol" -> rtol, atol
            names += [w.strip() for w in " ".join(words[1:]).split(",") if w.strip()]
    return names


def test_cython_declaration_matches_the_c_struct(repo_root):
    """_opts.pxi declares every field of pdw_sim.h's pdw_run_opts, in order: a new option is
    its field in both (and nothing else in Cython)."""
    c = _struct_fields((repo_root / "pdw/core/csrc/pdw_sim.h").read_text(), "pdw_run_opts")
    pyx = _struct_fields((repo_root / "pdw/core/_opts.pxi").read_text(), "pdw_run_opts")
    assert c == pyx and len(c) >= 17
    assert list(_core.OPT_FIELDS) == c


def _batch_run(opts, n=2):
    out = _outputs(n)
    _batch.run_range(K, np.tile(X, (n, 1)), P[None].copy(), np.tile(np.array([0, 1], np.intc),
                     (n, 1)), np.full(n, 0.4), np.full(n, 0.2), opts, out, 0, n, 2, False)
    return out


def test_an_option_given_only_in_the_record_reaches_both_loops():
    """stop_touch_down set from the option object alone stops the scalar and the ensemble run
    at the same state (the one filler), earlier than a run without it."""
    opts = c_options(Stop(touch_down=1), Limits(), **BASE)
    one = _core.run(K, 0, X, P, 0, 1, opts)
    plain = _core.run(K, 0, X, P, 0, 1, BASE)
    assert one["n_steps"] < plain["n_steps"]
    out = _batch_run({k: v for k, v in opts.items()
                      if k not in ("fall_hip_height", "fall_depth")})
    assert np.array_equal(out["x_final"][0], one["x_final"])
    assert out["n_steps"][0] == one["n_steps"]


@pytest.mark.parametrize("change, words", [
    (dict(stop_on_moon=1), "no field"),
    (dict(dt=0.0), "dt must be"),
    (dict(n_steps=-3), "n_steps"),
    (dict(stop_touch_down=3), "stop_touch_down"),
    (dict(periodic_k=1), "periodic_k"),
    (dict(max_speed=0.0), "max_speed"),
    (dict(n_steps=2 ** 64), "n_steps"),
    (dict(stop_steps=1.5), "stop_steps"),
])
def test_both_entry_points_refuse_a_bad_record_alike(change, words):
    """One filler: the same bad field gets the same error from _core.run and run_range."""
    bad = dict(BASE, **change)
    errors = []
    for call in (lambda: _core.run(K, 0, X, P, 0, 1, bad), lambda: _batch_run(bad)):
        with pytest.raises(ValueError, match=words) as e:
            call()
        errors.append(str(e.value))
    assert errors[0] == errors[1]


def test_derived_fields_and_the_ensemble_records_nothing():
    """t_end 0 is n_steps dt (a field left out is 0); the ensemble refuses a record field."""
    a = _core.run(K, 0, X, P, 0, 1, dict(BASE, n_steps=500))
    b = _core.run(K, 0, X, P, 0, 1, dict(BASE, n_steps=500, t_end=0.05))
    assert a["t_final"] == b["t_final"] and np.array_equal(a["x_final"], b["x_final"])
    with pytest.raises(ValueError, match="records no samples"):
        _batch_run(dict(BASE, record_events=1))


def test_resume_statuses_and_record_limits_are_generated():
    """PDW_STATUS_RECORDS_FULL / POLL, the record buffer sizes and the poll interval come from
    derive/layout.py (RESUME, RECORD_CHUNK, ...): the compiled module's values are the layout's,
    and the resume statuses are apart from every status a Result can see."""
    from pdw.core import _layout
    assert (_core.POLL_EVERY, _core.RECORD_CHUNK, _core.RECORD_EXACT_MAX) == (
        _layout.POLL_EVERY, _layout.RECORD_CHUNK, _layout.RECORD_EXACT_MAX)
    assert _layout.RESUME == ("records_full", "poll")
    assert len(_layout.RESUME_TEXT) == len(_layout.RESUME)
    assert _layout.RESUME_BASE >= len(_layout.STATUS)


def test_an_adaptive_run_resumes_through_records_full_and_polls():
    """A tiny first record buffer (RECORDS_FULL again and again) and a poll every 2 iterations
    give the samples of one unbroken run."""
    opts = dict(BASE, n_steps=3000, record_every=1, rtol=1e-6, atol=1e-8, event_tol=1e-9,
                t_end=0.3)
    m = pdw.METHODS.index("rodas4")
    a = _core.run(K, m, X, P, 0, 1, opts, poll_every=0)
    b = _core.run(K, m, X, P, 0, 1, opts, poll_every=2, max_records=3)
    assert len(a["t"]) > 3 * 8 and np.array_equal(a["x"], b["x"])
