"""Property-based tests (hypothesis) over physically meaningful parameters and states, extremes
included: every run either returns a valid result or raises a clear pdw error -- never a crash,
a hang, or a NaN in a result marked walked (docs/stability.md).

Bounded: short runs (t_end <= 0.3 s), a step-count budget for the explicit adaptive method, a
wall-clock watchdog per run; about 20 s in all.

Then (issue 16) hypothesis fuzzing of the compiled entry points (shapes, dtypes, strides,
values), of `Params`, `simulate`, scenes, studies, grounds and robustness specs (malformed
input), and of long random runs: every case either succeeds (with an honest result) or raises
the documented error -- never a crash, a raw Python error, or a status that lies. A small budget
runs in ``make test``; the ``slow`` twins (``make study``) run about 1.7 10^5 cases in all
(counts in docs/stability.md). ``PDW_FUZZ_EXAMPLES`` overrides the small budget per test.
"""
import json
import math
import os
import threading
import time
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import pdw
from pdw.core import _batch, _core, _hybrid
from pdw.core.errors import (
    InvalidInputError,
    PdwError,
    SimulationError,
    StepSizeWarning,
)
from pdw.core.model import parameter_vector
from pdw.sim import stepsize as SL
from pdw.studies.study import parse_study

#: PDW_FUZZ_SCALE=20 (say) runs 20 times the examples, with fresh random draws: a bug hunt.
SCALE = float(os.environ.get("PDW_FUZZ_SCALE", "1"))
SETTINGS = dict(deadline=None, derandomize=SCALE == 1, suppress_health_check=[HealthCheck.too_slow])


def n(k):
    return max(1, int(k * SCALE))

WATCHDOG_S = 20.0          # a run that takes longer has hung (the longest take ~0.3 s)


def log_uniform(lo, hi):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0 ** e)


@st.composite
def params(draw):
    """The paper's walker on any ground: k_n 1e3-1e9, d_n 0 or 1e2-1e8, slope 0-0.2 rad,
    friction 0-2, point or arc feet, friction steepness v_s 1e-6-1e-2, tangential and hip
    elements from absent to ten times the paper's."""
    mu_s = draw(st.sampled_from([0.0, 2.0]) | st.floats(0.0, 2.0))
    v_s = draw(log_uniform(1e-6, 1e-2))
    return pdw.Params(
        k_n=draw(log_uniform(1e3, 1e9)),
        d_n=draw(st.just(0.0) | log_uniform(1e2, 1e8)),
        gamma=draw(st.sampled_from([0.0, 0.2]) | st.floats(0.0, 0.2)),
        mu_s=mu_s, mu_d=mu_s * draw(st.floats(0.5, 1.0)),
        r=draw(st.sampled_from([0.0, 0.2]) | st.floats(0.0, 0.45)),
        v_s=v_s, v_d=10 * v_s,
        k_t=draw(st.just(0.0) | log_uniform(1.0, 1e3)),
        d_t=draw(st.just(0.0) | log_uniform(10.0, 1e4)),
        k_hip=draw(st.floats(0.0, 10.0)),
        d_hip=draw(st.floats(0.0, 0.2)),
    )


@st.composite
def states(draw):
    """Around the typical gait's start: hip 0.3-0.7 m up (feet from 0.2 m deep to 0.2 m in the
    air), legs +-0.6 rad, velocities up to 5 m/s or rad/s; any support flags."""
    x = np.array(pdw.X0_PAPER)
    x[1] = draw(st.floats(0.3, 0.7))
    x[2] = draw(st.floats(-0.6, 0.6))
    x[3] = draw(st.floats(-0.6, 0.6))
    x[4:] = [draw(st.floats(-5.0, 5.0)) for _ in range(4)]
    flags = draw(st.sampled_from([(0, 1), (1, 0), (1, 1), (0, 0)]))
    return x, flags


def bounded(fn, timeout=WATCHDOG_S):
    """Run fn() in a thread (the compiled loops release the GIL); fail if it does not return
    within ``timeout`` seconds -- a hang."""
    out = {}

    def target():
        try:
            out["value"] = fn()
        except BaseException as e:      # noqa: BLE001 -- re-raised below
            out["error"] = e

    th = threading.Thread(target=target, daemon=True)
    th.start()
    th.join(timeout)
    assert not th.is_alive(), "hang: the run did not return within %g s" % timeout
    if "error" in out:
        raise out["error"]
    return out["value"]


def check_result(r, t_end):
    assert r.status in ("walked", "fell", "diverged")
    for a in (r.t, r.x, r.Fn, r.Ft, r.x_final):
        assert np.isfinite(a).all(), "non-finite values in a %s result" % r.status
    # fixed-step methods take round(t_end/dt) steps: t_final is within dt/2 of t_end
    slack = 0.5 * r.dt if r.method in SL.FIXED_STEP else 1e-12
    assert all(0.0 <= e.t <= r.t_final + 1e-12 and math.isfinite(e.x_D) for e in r.events)
    assert r.t_final <= t_end + slack + 1e-12
    if r.status == "walked":
        assert r.failure is None
        assert r.t_final >= t_end - slack - 1e-12
    else:
        f = r.failure
        assert 0.0 <= f["t"] <= r.t_final + 1e-12
        assert f["x"].shape == (8,) and np.isfinite(f["x"]).all()
        assert isinstance(f["reason"], str) and f["reason"] and f["reason"] != "none"


def run_checked(**kw):
    """simulate under the watchdog: a Result (checked) or a pdw error (checked); nothing else."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", StepSizeWarning)
            r = bounded(lambda: pdw.simulate(**kw))
    except SimulationError as e:
        assert math.isfinite(e.t) and e.x is not None and np.isfinite(e.x).all() and e.reason
        assert e.result is not None
        check_result(e.result, kw["t_end"])
        return e.result
    except InvalidInputError as e:
        assert str(e)
        return None
    check_result(r, kw["t_end"])
    return r


@settings(max_examples=n(60), **SETTINGS)
@given(P=params(), s=states(), method=st.sampled_from(["cdm", "verlet", "rk4"]),
       dt=log_uniform(1e-5, 1e-2), variant=st.sampled_from(["paper", "consistent"]),
       on_failure=st.sampled_from(["raise", "return"]))
def test_fixed_step_runs_return_a_valid_result_or_a_pdw_error(P, s, method, dt, variant, on_failure):
    x0, flags = s
    run_checked(x0=x0, flags0=flags, params=P, method=method, dt=dt, t_end=0.3, variant=variant,
                record=pdw.Record(every=1), limits=pdw.Limits(on_failure=on_failure))


@settings(max_examples=n(40), **SETTINGS)
@given(P=params(), s=states(), rtol=log_uniform(1e-7, 1e-3),
       variant=st.sampled_from(["paper", "consistent"]))
def test_rodas4_runs_return_a_valid_result_or_a_pdw_error(P, s, rtol, variant):
    x0, flags = s
    run_checked(x0=x0, flags0=flags, params=P, method="rodas4",
                integrator=pdw.Integrator(rtol=rtol, atol=rtol * 1e-2), dt=1e-4, t_end=0.3,
                variant=variant, record=pdw.Record(every=3), limits=pdw.Limits(on_failure="return"))


@pytest.mark.parametrize("method", ["rodas4", "dopri5"])
def test_adaptive_runs_end_at_t_end(method):
    r = pdw.simulate(method=method, t_end=0.25, dt=0.1, record=pdw.Record(every=0))
    assert r.t_final == pytest.approx(0.25)      # ended at 0.2 s = round(t_end/dt)*dt before the fix


@settings(max_examples=n(15), **SETTINGS)
@given(P=params(), s=states())
def test_dopri5_runs_return_a_valid_result_or_a_pdw_error(P, s):
    """dopri5 is explicit: its steps are bounded by ~3/|lambda| of the stuck friction (1e-9 s on
    the stiffest ground); t_end is cut to about 2e5 such steps."""
    x0, flags = s
    h = SL.step_limit(P, "dopri5").dt_max
    t_end = float(min(0.3, max(2e5 * h, 1e-3)))
    t_end = round(t_end / 1e-5) * 1e-5     # a multiple of dt (test_adaptive_runs_end_at_t_end)
    run_checked(x0=x0, flags0=flags, params=P, method="dopri5",
                integrator=pdw.Integrator(rtol=1e-5, atol=1e-7), dt=1e-5, t_end=t_end,
                record=pdw.Record(every=0), limits=pdw.Limits(on_failure="return"))


@settings(max_examples=n(40), **SETTINGS)
@given(P=params(), method=st.sampled_from(list(pdw.METHODS)),
       variant=st.sampled_from(["paper", "consistent"]))
def test_step_limit_is_defined_everywhere(P, method, variant):
    lim = bounded(lambda: SL.step_limit(P, method, variant), timeout=10.0)
    assert lim.dt_max > 0 and not math.isnan(lim.dt_max)
    if method in SL.FIXED_STEP:
        assert math.isfinite(lim.dt_max) and lim.force in SL.FORCES
        assert str(lim.dt_max)[:3] in lim.message(1.0) or "%.2g" % lim.dt_max in lim.message(1.0)
    X, flags = SL.stance_states(P, variant)
    assert np.isfinite(X).all()


@settings(max_examples=n(40), **SETTINGS)
@given(P=params(), s=states(), variant=st.sampled_from(["paper", "consistent"]))
def test_model_functions_are_finite(P, s, variant):
    """rhs, jacobian, contact forces and energies at any state and parameters: finite."""
    x, flags = s
    for f in (pdw.rhs, pdw.jacobian):
        assert np.isfinite(f(x, P, flags=flags, variant=variant)).all()
    cs = pdw.contact_forces(x, P, flags=flags, variant=variant)
    assert all(np.isfinite(getattr(cs, k)).all() for k in ("F_n", "F_t", "mu", "v_x", "y_D"))
    assert (cs.F_n >= 0).all()
    assert np.isfinite(pdw.energies(x, P)["E"])


@settings(max_examples=n(30), **SETTINGS)
@given(field=st.sampled_from(["dt", "t_end", "max_speed", "rtol", "atol", "h_max", "event_tol",
                              "fall_depth"]),
       value=st.sampled_from([0.0, -1.0, math.nan, math.inf, -math.inf, "x", None]))
def test_bad_numbers_raise_invalid_input_naming_the_field(field, value):
    if value is None and field in ("h_max", "fall_depth", "dt", "t_end"):
        return                          # None is their default (no limit, l/4, 1e-4, 3.5)
    section = {"max_speed": "limits", "fall_depth": "limits"}.get(field, "integrator")
    kw = {field: value} if field in ("dt", "t_end") else {section: {field: value}}  # the table
    with pytest.raises(InvalidInputError, match=field) as ei:
        pdw.simulate(**{"t_end": 0.01, **kw})
    assert isinstance(ei.value, PdwError)


# --- malformed input at every entry point (issue 16) ---------------------------------------

SMALL = int(os.environ.get("PDW_FUZZ_EXAMPLES", "25"))
#: the slow twins' examples per test (their sum is the study's count: 1.71e5)
LARGE = {"compiled": 40000, "hybrid": 15000, "params": 20000, "simulate": 5000,
         "scene": 10000, "study": 9900, "long": 100,
         # the entry points merged after issue 16's first pass
         "batch": 5000, "batch_compiled": 20000, "ode": 20000, "contact": 3000, "load": 5000,
         "buffer": 3000,
         # issue 26 (round three): counts into the compiled layer, NaN states at every public
         # entry point, silent coercions, the file formats (BatchResult, the sweep CSV)
         "counts": 4000, "nan_states": 4000, "coerce": 3000, "batch_file": 2000, "csv": 2000,
         # the spec formats of round three's terrain and robustness work
         "ground": 10000, "robustness": 10000}
_HC = [HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much]
P = parameter_vector(pdw.Params.paper())
X0 = np.array(pdw.X0_PAPER)


#: ``PDW_FUZZ_COUNT_FILE``: a JSON file where the cases run so far (per target, with the seconds
#: and the CPU seconds since its first case) are written every 50 cases, so that a budget cut by a deadline still
#: has exact counts (docs/stability.md section 11).
_COUNT_FILE = os.environ.get("PDW_FUZZ_COUNT_FILE")
_COUNTS = {}


def _count(kind):
    n, t0, c0 = _COUNTS.get(kind, (0, time.monotonic(), time.process_time()))
    _COUNTS[kind] = (n + 1, t0, c0)
    if _COUNT_FILE and (n + 1) % 50 == 0:
        try:
            with open(_COUNT_FILE) as f:
                known = json.load(f)
        except (OSError, ValueError):
            known = {}
        known.update({k: {"cases": c, "seconds": round(time.monotonic() - t, 1),
                          "cpu_seconds": round(time.process_time() - cpu, 1)}
                      for k, (c, t, cpu) in _COUNTS.items()})
        with open(_COUNT_FILE + ".tmp", "w") as f:
            json.dump(known, f, indent=1)
        os.replace(_COUNT_FILE + ".tmp", _COUNT_FILE)


def _twin(kind, fn, strategy=None, small=None):
    """A small-budget test and its slow twin with LARGE[kind] examples: fn(data) draws its case
    from hypothesis' data, or fn(case) gets one case of ``strategy``."""
    def case(data):
        _count(kind)
        fn(data if strategy is None else data.draw(strategy))

    def fast(data):
        case(data)

    def slow(data):
        case(data)
    fast = settings(max_examples=small or SMALL, deadline=None,
                    suppress_health_check=_HC)(given(st.data())(fast))
    slow = settings(max_examples=LARGE[kind], deadline=None,
                    suppress_health_check=_HC)(given(st.data())(slow))
    return fast, pytest.mark.slow(slow)


# --- strategies ---------------------------------------------------------------------------------

ANY_FLOAT = st.floats(allow_nan=True, allow_infinity=True)
NICE_FLOAT = st.floats(-1e3, 1e3)
DTYPES = st.sampled_from([np.float64, np.float64, np.float64, np.float32, np.int64, np.intc])


@st.composite
def arrays(draw, shape_hint, dtype=None):
    """An array whose shape is shape_hint mostly, else a random 1-2 d shape; any dtype; C
    order or a strided view."""
    if draw(st.booleans()):
        shape = shape_hint
    else:
        shape = tuple(draw(st.integers(0, 70)) for _ in range(draw(st.integers(1, 2))))
    dt = draw(DTYPES) if dtype is None else dtype
    if not draw(st.integers(0, 5)):
        dt = draw(DTYPES)                       # the wrong dtype now and then
    strided = draw(st.integers(0, 7)) == 0
    full = shape[:-1] + (shape[-1] * (2 if strided else 1),)
    n = int(np.prod(full))
    vals = draw(st.lists(NICE_FLOAT | ANY_FLOAT, min_size=min(n, 4), max_size=min(n, 4)))
    a = np.resize(np.array(vals or [0.0], dtype=float), n).reshape(full) if n else np.zeros(full)
    with np.errstate(invalid="ignore", over="ignore"):
        a = a.astype(dt) if dt != np.float64 else a
    return a[..., ::2] if strided else a


# --- the compiled entry points ------------------------------------------------------------

def _compiled(data):
    n = data.draw(st.integers(0, 4))
    which = data.draw(st.sampled_from(["rhs", "jac", "energies", "cdm", "precompute", "run"]))
    k = data.draw(st.integers(-1, len(_core.kernel_table())))
    x = data.draw(arrays((n, _core.NX)))
    p = data.draw(arrays((_core.NP,)))
    flags = data.draw(arrays((n, 2), np.intc))
    anchors = data.draw(arrays((n, 2)))
    work = data.draw(arrays((n, _core.NWORK)))
    try:
        if which == "rhs":
            _core.rhs_batch(k, x, p, flags, anchors, data.draw(arrays((n, _core.NX))), work)
        elif which == "jac":
            _core.jacobian_batch(k, x, p, flags, anchors, data.draw(arrays((n, 64))), work)
        elif which == "energies":
            _core.energies_batch(k, x, p, data.draw(arrays((n, 3))))
        elif which == "cdm":
            _core.cdm_terms(k, data.draw(arrays((_core.NX,))), p, data.draw(arrays((14,))),
                            data.draw(arrays((16,))), data.draw(arrays((16,))),
                            data.draw(arrays((4,))))
        elif which == "precompute":
            _core.precompute(data.draw(arrays((19,))), data.draw(arrays((_core.NP,))))
        else:
            _core.run(max(k, 0), data.draw(st.integers(-1, 5)), data.draw(arrays((_core.NX,))),
                      P, data.draw(st.integers(-1, 2)), 1,
                      dict(dt=data.draw(st.sampled_from([1e-4, 0.0])),
                           n_steps=data.draw(st.integers(-2, 50)),
                           record_every=data.draw(st.integers(-1, 3)), record_events=1,
                           fall_hip_height=0.25, fall_depth=0.125, max_speed=1e3, rtol=1e-6,
                           atol=1e-8, event_tol=1e-9, t_end=0.005))
    except (ValueError, IndexError, TypeError, BufferError):
        pass                                      # a refusal; a crash would end the test run


def _hybrid_entry(data):
    n = data.draw(st.integers(0, 4))
    which = data.draw(st.sampled_from(["rhs", "energies", "full", "batch", "solve", "impact"]))
    y = data.draw(arrays((_hybrid.NY,)))
    try:
        if which == "rhs":
            _hybrid.rhs(data.draw(arrays((_core.NP,))), y)
        elif which == "energies":
            _hybrid.energies(data.draw(arrays((_core.NP,))), y)
        elif which == "full":
            _hybrid.full_state_batch(P, data.draw(arrays((n, 4))), data.draw(arrays((n, 8))))
        elif which == "batch":
            _hybrid.step_batch(P, data.draw(arrays((n, 4))), {"max_steps": 50},
                               data.draw(arrays((n, 4))), data.draw(arrays((n,), np.intc)))
        elif which == "solve":
            m = data.draw(st.integers(0, 10))
            _hybrid.solve(data.draw(arrays((m, m))), data.draw(arrays((m,))))
        else:
            _hybrid.impact(P, y)
    except (ValueError, TypeError, ArithmeticError, BufferError):
        pass


test_fuzz_compiled_entry_points, test_fuzz_compiled_entry_points_study = _twin("compiled", _compiled)
test_fuzz_hybrid_entry_points, test_fuzz_hybrid_entry_points_study = _twin("hybrid", _hybrid_entry)


# --- Params, simulate, scenes, studies ------------------------------------------------------

JUNK = (ANY_FLOAT | st.integers(-10 ** 30, 10 ** 30) | st.text(max_size=4) | st.none()
        | st.booleans() | st.complex_numbers(max_magnitude=10) | st.lists(NICE_FLOAT, max_size=3))
FIELDS = pdw.Params.__dataclass_fields__


def _params(kw):
    try:
        p = pdw.Params(**kw)
    except pdw.InvalidInputError as e:
        assert any("Params." + f in str(e) for f in kw) or "Params." in str(e), e
        return
    for f in FIELDS:
        v = getattr(p, f)
        assert type(v) is float and math.isfinite(v)


test_fuzz_params, test_fuzz_params_study = _twin("params", _params, st.dictionaries(
    st.sampled_from(sorted(FIELDS)), NICE_FLOAT | JUNK, max_size=4))

SIM_ARGS = {
    "t_end": st.sampled_from([0.02, 0.05]) | JUNK,
    "dt": st.sampled_from([1e-4, 1e-3, 1e-5]) | JUNK,
    "method": st.sampled_from(pdw.METHODS) | JUNK,
    "flags0": st.sampled_from([(0, 1), (1, 1), (1, 0), (0, 0)]) | JUNK,
    "record.every": st.integers(0, 5) | JUNK,
    "limits.fall_hip_height": st.floats(0.0, 0.4) | JUNK,
    "limits.max_speed": st.sampled_from([1e3, 10.0]) | JUNK,
    "integrator.rtol": st.sampled_from([1e-6, 1e-3]) | JUNK,
    "x0": st.lists(st.floats(-0.5, 0.5), min_size=8, max_size=8).map(
        lambda v: (X0 + 0.2 * np.array(v)).tolist()) | JUNK,
}


def _tables(kw):
    """Drawn arguments as the keywords of an entry point: a key ``section.field`` goes into the
    option table ``section`` (a dict, read and checked by the entry point)."""
    out: dict = {}
    for key, value in kw.items():
        if "." in key:
            section, name = key.split(".")
            out.setdefault(section, {})[name] = value
        else:
            out[key] = value
    return out


def _simulate(kw):
    kw = _tables({**kw, "integrator.check_step": "off", "limits.on_failure": "return"})
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = pdw.simulate(**kw)
    except pdw.InvalidInputError:
        return
    assert r.status in ("walked", "periodic", "fell", "diverged", "no_steps")
    assert np.isfinite(r.x).all() and np.isfinite(r.x_final).all()
    if r.status == "walked":
        # a fixed-step run ends at round(t_end/dt) dt (documented), an adaptive one at t_end
        fixed = not pdw.core.integrators.INTEGRATORS[r.method].adaptive
        end = round(r.t_end / r.dt) * r.dt if fixed else r.t_end
        assert r.failure is None and abs(r.t_final - end) < 1e-9 * max(1.0, r.t_end)
    else:
        assert r.status == "no_steps" or r.failure is not None


test_fuzz_simulate, test_fuzz_simulate_study = _twin(
    "simulate", _simulate, st.fixed_dictionaries({}, optional=SIM_ARGS))

TOML_VALUE = (st.integers(-5, 10 ** 7) | st.floats(allow_nan=False, allow_infinity=False)
              | st.text("abc/._-", max_size=6).map(lambda s: '"%s"' % s)
              | st.sampled_from(["nan", "inf", "true", "[]", "[1, 2]", '["0"]', "{}", '"../x"',
                                 '"paper"', '"rodas4"', "[0, 1]", "[5, 7]", "1e400"]))


def _toml(lines):
    return "\n".join("%s = %s" % (k, v) for k, v in lines)


def _scene(lines):
    text = "[walker]\n" + _toml(lines["walker"]) + "\n[run]\n" + _toml(lines["run"]) + "\n"
    try:
        s = pdw.Scene.from_toml(text)
    except pdw.InvalidInputError:
        return
    assert isinstance(s, pdw.Scene)


SCENE_KEYS = st.sampled_from(["t_end", "dt", "method", "variant", "flags0", "record_every", "x0",
                              "k_n", "l", "preset", "foo", "rtol", "stop_steps"])
test_fuzz_scene, test_fuzz_scene_study = _twin("scene", _scene, st.fixed_dictionaries({
    "walker": st.lists(st.tuples(SCENE_KEYS, TOML_VALUE), max_size=3, unique_by=lambda t: t[0]),
    "run": st.lists(st.tuples(SCENE_KEYS, TOML_VALUE), max_size=3, unique_by=lambda t: t[0]),
}))

STUDY_TOP = st.sampled_from(["name", "title", "bogus"])
STUDY_SCENE = st.sampled_from(["preset", "variant", "x0", "flags0", "bogus"])
STUDY_RUN = st.sampled_from(["steady", "period_tol", "mode", "fallback", "t_end", "bogus"])
STUDY_STOP = st.sampled_from(["t_end"])
STUDY_LIMITS = st.sampled_from(["max_speed", "on_failure"])
STUDY_INTEGRATOR = st.sampled_from(["method", "dt", "rtol", "atol"])
AXIS_KEY = st.sampled_from(["values", "start", "stop", "num", "log"])


def _study(parts):
    text = (_toml(parts["top"]) + "\n[[axes]]\nname = \"k_n\"\n" + _toml(parts["axis"])
            + "\n[run]\n" + _toml(parts["run"]) + "\n[scene]\n" + _toml(parts["scene"])
            + "\n[scene.stop]\n" + _toml(parts["stop"])
            + "\n[scene.limits]\n" + _toml(parts["limits"])
            + "\n[scene.integrator]\n" + _toml(parts["integrator"]) + "\n")
    try:
        s = parse_study(text)
    except pdw.InvalidInputError:
        return
    assert "/" not in s.name and not s.name.startswith(".")
    assert 1 <= len(s.points()) <= 10 ** 6
    sc = s.scene
    assert 0 < sc.integrator.dt <= sc.stop.t_end and math.isfinite(sc.integrator.rtol)
    assert tuple(sc.flags0) in ((0, 1), (1, 1), (1, 0), (0, 0))
    assert np.isfinite(sc.x0).all() and len(sc.x0) == 8
    assert s.run["steady"] >= 1 and math.isfinite(s.run["period_tol"])


def _pairs(keys):
    return st.lists(st.tuples(keys, TOML_VALUE), max_size=3, unique_by=lambda t: t[0])


test_fuzz_study, test_fuzz_study_study = _twin("study", _study, st.fixed_dictionaries({
    "top": _pairs(STUDY_TOP), "run": _pairs(STUDY_RUN), "scene": _pairs(STUDY_SCENE),
    "stop": _pairs(STUDY_STOP), "limits": _pairs(STUDY_LIMITS),
    "integrator": _pairs(STUDY_INTEGRATOR),
    "axis": st.lists(st.tuples(AXIS_KEY, TOML_VALUE), min_size=1, max_size=3,
                     unique_by=lambda t: t[0]),
}))


# --- long random runs ---------------------------------------------------------------------

def _long(case):
    """Long runs (20 s, about 30 steps) of random walkers near the paper's: the status is honest (walked means stepping, with
    finite energies; a fall or a divergence says when)."""
    k_n, gamma, method = case
    p = pdw.Params.paper_steady(k_n=k_n, gamma=gamma)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = pdw.simulate(t_end=20.0, params=p, method=method,
                         integrator=pdw.Integrator(check_step="off"),
                         record=pdw.Record(every=50, energies=True),
                         limits=pdw.Limits(on_failure="return"), dt=1e-4)
    if r.status == "walked":
        assert r.n_gait_steps >= 3
        assert all(np.isfinite(v).all() for v in r.energies.values())
        assert np.abs(r.x[:, 2:4]).max() < 2 * np.pi
    else:
        assert r.status in ("fell", "diverged", "no_steps", "periodic")


test_fuzz_long_runs, test_fuzz_long_runs_study = _twin(
    "long", _long, st.tuples(st.floats(5e4, 2e5), st.floats(0.015, 0.025),
                             st.sampled_from(["cdm", "rodas4"])), small=max(1, SMALL // 10))


# --- the entry points merged after the first pass: batch, ode, contact, buffers, files --------

def _batch_compiled(data):
    """_batch.run_range with random shapes, dtypes, strides and values of every input and
    output array, and random scalars: a refusal or a completed range, never a crash."""
    from pdw.sim.batch import _outputs
    n = data.draw(st.integers(0, 4))
    out = _outputs(n)
    if data.draw(st.integers(0, 3)) == 0:
        key = data.draw(st.sampled_from(sorted(out)))
        out[key] = data.draw(arrays(out[key].shape if out[key].ndim < 3 else (n, 3),
                                    out[key].dtype.type))
    try:
        _batch.run_range(data.draw(st.integers(-1, len(_core.kernel_table()))),
                         data.draw(arrays((n, _core.NX))), data.draw(arrays((1, _core.NP))),
                         data.draw(arrays((n, 2), np.intc)), data.draw(arrays((n,))),
                         data.draw(arrays((n,))),
                         dict(dt=data.draw(st.sampled_from([1e-4, 0.0]) | ANY_FLOAT),
                              n_steps=data.draw(st.integers(-2, 30)),
                              max_speed=data.draw(st.sampled_from([1e3]) | ANY_FLOAT),
                              stop_steps=data.draw(st.integers(-1, 3)),
                              periodic_k=data.draw(st.integers(-1, 40)),
                              periodic_tol=data.draw(st.sampled_from([1e-3]) | ANY_FLOAT)), out,
                         data.draw(st.integers(-1, n + 1)), data.draw(st.integers(-1, n + 1)),
                         data.draw(st.integers(-1, 70)), data.draw(st.booleans()))
    except (ValueError, IndexError, TypeError, BufferError, KeyError):
        pass


BATCH_ARGS = {
    "t_end": st.sampled_from([0.005, 0.02]) | JUNK,
    "dt": st.sampled_from([1e-4, 1e-3]) | JUNK,
    "flags0": st.sampled_from([(0, 1), (1, 1), [(0, 1), (1, 0)]]) | JUNK,
    "limits.fall_hip_height": st.floats(0.0, 0.4) | JUNK,
    "lanes": st.integers(-1, 70) | JUNK,
    "threads": st.integers(0, 3) | JUNK,
    "vector": st.booleans() | JUNK,
    "stop.steps": st.integers(0, 3) | JUNK,
    "stop.periodic": st.booleans() | JUNK,
    "stop.periodic_steps": st.integers(0, 3) | JUNK,
    "limits.max_speed": st.sampled_from([1e3, 10.0]) | JUNK,
    "params": st.sampled_from([None, pdw.Params.paper(), [pdw.Params.paper()] * 2,
                               [pdw.Params.paper_steady(k_n=2e5), pdw.Params.paper()]]) | JUNK,
}


def _batch_public(case):
    x0, kw = case
    kw = _tables({**kw, "integrator.check_step": "off"})
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            b = pdw.simulate_batch(x0, **kw)
    except pdw.InvalidInputError:
        return
    assert set(b.status) <= {"walked", "periodic", "fell", "diverged"}
    assert np.isfinite(b.x_final).all() and np.isfinite(b.t_final).all()
    walked = b.status == "walked"
    assert (b.failure_reason[walked] == "none").all()


BATCH_X0 = (st.integers(0, 3).flatmap(lambda n: st.lists(
    st.lists(st.floats(-0.3, 0.3), min_size=8, max_size=8), min_size=n, max_size=n)).map(
    lambda v: (X0 + np.array(v).reshape(-1, 8)).tolist()) | JUNK
    | st.sampled_from([[X0.tolist()] * 2]) | arrays((2, 8)))

test_fuzz_batch_entry_point, test_fuzz_batch_entry_point_study = _twin(
    "batch_compiled", _batch_compiled)
test_fuzz_simulate_batch, test_fuzz_simulate_batch_study = _twin(
    "batch", _batch_public, st.tuples(BATCH_X0, st.fixed_dictionaries({}, optional=BATCH_ARGS)))


def _ode(data):
    """ode_function with junk arguments, then f, f.jac, f.batch with random arrays."""
    kw = data.draw(st.fixed_dictionaries({}, optional={
        "flags": st.sampled_from([(0, 1), (1, 1)]) | JUNK,
        "anchors": st.sampled_from([(0.0, 0.0), (0.1, -0.2)]) | JUNK,
        "variant": st.sampled_from(["paper", "consistent"]) | JUNK,
        "features": st.sampled_from([None, ("hip_spring",), ()]) | JUNK}))
    try:
        f = pdw.ode_function(**kw)
    except pdw.InvalidInputError:
        return
    x = data.draw(arrays((_core.NX,)) | JUNK)
    for call in (lambda: f(0.0, x), lambda: f.jac(0.0, x),
                 lambda: f.batch(data.draw(arrays((data.draw(st.integers(0, 3)), _core.NX))))):
        try:
            out = call()
        except (ValueError, TypeError, BufferError):
            continue
        assert isinstance(out, np.ndarray) and out.dtype == np.float64
        assert out.shape in ((_core.NX,), (_core.NX, _core.NX)) or out.shape[1:] == (_core.NX,)


test_fuzz_ode_function, test_fuzz_ode_function_study = _twin("ode", _ode)


def _contact(case):
    kw, run = case
    try:
        c = pdw.Contact(**kw)
    except pdw.InvalidInputError:
        return
    for name in ("k", "d", "e", "v_in_min"):
        v = getattr(c, name)
        assert v is None or (type(v) is float and math.isfinite(v))
    if run:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = pdw.simulate(t_end=0.02, contact=c, integrator=pdw.Integrator(check_step="off"),
                                 record=pdw.Record(every=0), limits=pdw.Limits(on_failure="return"))
        except pdw.InvalidInputError:
            return
        assert r.status in ("walked", "fell", "diverged") and np.isfinite(r.x_final).all()


test_fuzz_contact, test_fuzz_contact_study = _twin("contact", _contact, st.tuples(
    st.fixed_dictionaries({}, optional={
        "normal": st.sampled_from(list(pdw.core.contact.NORMAL_LAWS)) | JUNK,
        "friction": st.sampled_from(list(pdw.core.contact.FRICTION_LAWS)) | JUNK,
        "k": st.floats(1e3, 1e7) | JUNK, "d": st.floats(0, 1e7) | JUNK,
        "e": st.floats(0.05, 1.0) | JUNK, "v_in_min": st.floats(1e-4, 1.0) | JUNK}),
    st.integers(0, 9).map(lambda i: i == 0)))


def _buffer(data):
    """RecordBuffer with a random capacity, then random arrays put in place of its own."""
    from pdw.sim.buffers import RecordBuffer
    try:
        b = RecordBuffer(data.draw(st.integers(0, 300) | JUNK))
    except pdw.InvalidInputError:
        return
    n = b.capacity
    if n > 10 ** 4:       # a valid, huge buffer (allocated lazily): do not fill it here
        return
    for name, shape, dt in (("t", (n,), None), ("x", (n, 8), None), ("flags", (n, 2), np.intc),
                            ("contact", (n, 4), None)):
        if data.draw(st.integers(0, 3)) == 0:
            setattr(b, name, data.draw(arrays(shape, dt)))
    try:
        r = pdw.simulate(t_end=0.005, integrator=pdw.Integrator(check_step="off"),
                         record=pdw.Record(out=b))
    except pdw.InvalidInputError:
        return
    assert np.isfinite(r.x).all() and len(r.t) == len(r.x) == 51


test_fuzz_record_buffer, test_fuzz_record_buffer_study = _twin("buffer", _buffer)

_SAVED = {}


def _saved():
    if not _SAVED:
        import json
        import tempfile
        d = tempfile.mkdtemp(prefix="pdw-fuzz-")
        path = os.path.join(d, "good.npz")
        pdw.simulate(t_end=0.02, record=pdw.Record(energies=True)).save(path)
        with np.load(path) as z:
            arrays_ = {k: z[k] for k in z.files}
        _SAVED.update(dir=d, arrays=arrays_, meta=json.loads(str(arrays_.pop("meta"))))
    return _SAVED


def _tamper(data, a):
    """Damage a saved file's arrays ``a`` in place, 1 to 3 times: an array dropped, replaced by
    a random one of its shape, or one numeric entry poked with any float (an integer array
    becomes float)."""
    for _ in range(data.draw(st.integers(1, 3))):
        key = data.draw(st.sampled_from(sorted(a)))
        action = data.draw(st.sampled_from(["replace", "drop", "poke"]))
        if action == "drop":
            a.pop(key, None)
        elif action == "replace" and key in a:
            a[key] = data.draw(arrays(a[key].shape))
        elif key in a and a[key].size and a[key].dtype.kind in "fiu":
            flat = a[key].astype(float).reshape(-1)
            flat[data.draw(st.integers(0, flat.size - 1))] = data.draw(ANY_FLOAT)
            a[key] = flat.reshape(a[key].shape)


def _load(data):
    """A saved result with random arrays replaced, dropped or mutated and random metadata
    fields replaced by junk: pdw.load gives an InvalidInputError or a Result whose arrays
    are consistent, its times finite (a state, force or energy may be NaN or inf: a run's
    data, which a saved diverged run holds, issue 26.3)."""
    import json
    s = _saved()
    a = {k: v.copy() for k, v in s["arrays"].items()}
    m = json.loads(json.dumps(s["meta"]))
    _tamper(data, a)
    if data.draw(st.booleans()):
        where = m if data.draw(st.booleans()) else m["settings"]
        where[data.draw(st.sampled_from(sorted(where)))] = data.draw(
            JUNK.filter(lambda v: not isinstance(v, complex)))
    path = os.path.join(s["dir"], "case.npz")
    np.savez(path, meta=np.array(json.dumps(m)), **a)
    try:
        r = pdw.load(path)
    except pdw.InvalidInputError:
        return
    assert r.x.shape == (len(r.t), 8) and np.isfinite(r.t).all()
    assert r.flags.shape == (len(r.t), 2) and set(np.unique(r.flags)) <= {0, 1}
    assert r.status in ("walked", "periodic", "fell", "diverged", "no_steps", "interrupted")


test_fuzz_load, test_fuzz_load_study = _twin("load", _load)


# --- issue 26 (round three) -------------------------------------------------------------------

#: a count: small and valid, or beyond every range (negative, past MAX_COUNT, past a C long)
COUNTS = (st.integers(0, 60) | st.integers(-2 ** 70, -1) | st.integers(2 ** 40 + 1, 2 ** 70)
          | st.sampled_from([2 ** 62, 2 ** 63 - 1, 2 ** 63, 2 ** 64, -2 ** 63 - 1]))


def _counts(data):
    """Any count into the compiled layer: a result, or a refusal naming it (ValueError /
    InvalidInputError, MemoryError for an allocation too large); never a crash, a hang (no
    count past MAX_COUNT is run) or a raw OverflowError."""
    p = parameter_vector(pdw.Params.paper_steady())
    y0 = np.array([0.2, -0.2, -1.0, -0.3])
    which = data.draw(st.sampled_from(["walk", "step", "run", "batch", "find_gait"]))
    c1, c2 = data.draw(COUNTS), data.draw(COUNTS)
    try:
        if which == "walk":
            _hybrid.walk(p, y0, 0.0, min(c1, 5) if 0 <= c1 <= 60 else c1, {}, c2)
        elif which == "step":
            _hybrid.step(p, y0, {}, 0.0, 0.0, c1)
        elif which == "run":
            name = data.draw(st.sampled_from(["max_records", "event_capacity", "stop_steps",
                                              "max_steps", "poll_every"]))
            o = dict(dt=1e-4, n_steps=c1 if not 0 <= c1 <= 60 else 20,
                     record_every=data.draw(st.integers(0, 3)), record_events=1,
                     fall_hip_height=0.25, fall_depth=0.125, max_speed=1e3)
            if name in ("stop_steps", "max_steps"):
                _core.run(0, 0, X0, P, 0, 1, o | {name: c2})
            else:
                _core.run(0, 0, X0, P, 0, 1, o, **{name: c2})
        elif which == "batch":
            from pdw.sim.batch import _outputs
            out = _outputs(1)
            _batch.run_range(0, X0[None].copy(), P[None].copy(), np.array([[0, 1]], np.intc),
                             np.array([0.2]), np.array([0.1]),
                             dict(dt=1e-4, n_steps=c1 if not 0 <= c1 <= 60 else 20, max_speed=1e3,
                                  stop_steps=c2 if c2 > 60 or c2 < 0 else 0),
                             out, 0, 1, 1, False)
        else:
            pdw.hybrid.find_gait(pdw.Params.paper_steady(), settle_steps=c1 if c1 > 60 or c1 < 0
                                 else 1, max_iter=c2 if c2 > 60 or c2 < 0 else 1)
    except (ValueError, MemoryError, pdw.hybrid.GaitNotFoundError):
        pass


test_fuzz_counts, test_fuzz_counts_study = _twin("counts", _counts)

_NAN_ENTRIES = {
    "rhs": lambda x: pdw.rhs(x), "jacobian": lambda x: pdw.jacobian(x),
    "contact_forces": lambda x: pdw.contact_forces(x).F_n,
    "energies": lambda x: pdw.energies(x)["E"], "mass_matrix": lambda x: pdw.mass_matrix(x),
    "ode_f": lambda x: pdw.ode_function()(0.0, x), "ode_jac": lambda x: pdw.ode_function().jac(0.0, x),
    "ode_batch": lambda x: pdw.ode_function().batch(np.ascontiguousarray(x[None])),
    "hybrid_rhs": lambda x: pdw.hybrid.stance_rhs(x[:4]),
    "hybrid_step": lambda x: pdw.hybrid.step_map(x[:4]),
    "simulate": lambda x: pdw.simulate(x, t_end=0.001, integrator=pdw.Integrator(check_step="off")),
}


def _nan_states(data):
    """A state with random NaN/inf entries (and random finite ones) into every public entry
    point that takes a state: InvalidInputError, or an answer of NaN in every entry."""
    x = np.array([data.draw(NICE_FLOAT) for _ in range(8)])
    bad = data.draw(st.lists(st.integers(0, 7), min_size=1, max_size=3))
    for i in bad:
        x[i] = data.draw(st.sampled_from([np.nan, np.inf, -np.inf]))
    name = data.draw(st.sampled_from(sorted(_NAN_ENTRIES)))
    if name.startswith("hybrid") and not any(i < 4 for i in bad):
        return
    try:
        out = _NAN_ENTRIES[name](x)
    except pdw.InvalidInputError as e:
        assert "finite" in str(e), (name, str(e))
        return
    assert np.isnan(np.asarray(out, dtype=float)).all(), (name, x, out)


test_fuzz_nan_states, test_fuzz_nan_states_study = _twin("nan_states", _nan_states)

_COERCE_JUNK = (st.booleans() | st.text(max_size=4) | st.floats(allow_nan=True)
                | st.integers(-3, 5) | st.just(np.float64(1.5)) | st.just([1.5]) | st.just("12")
                | st.just(np.ma.masked_array([1.0], mask=[True])[0]))


def _coerce(data):
    """No silent coercion: record indices, LuGre parameters, Kelvin-Voigt's k/d, steady()'s
    last/rtol and masked states take integers/reals of their type or raise InvalidInputError
    (a bool, a string, 1.5 where an index is expected, a masked entry)."""
    which = data.draw(st.sampled_from(["record", "lugre", "kv", "steady", "masked"]))
    v = data.draw(_COERCE_JUNK)
    try:
        if which == "record":
            rec = v if isinstance(v, (list, str)) else [v]
            b = pdw.simulate_batch(np.tile(X0, (3, 1)), t_end=0.002, record=rec)
            assert all(isinstance(i, int) and 0 <= i < 3 for i in b.recorded)
            assert all(type(r) is not bool and float(r) == int(r) for r in np.ravel(rec))
        elif which == "lugre":
            name = data.draw(st.sampled_from(["sigma0", "sigma1", "sigma2", "mu_s", "mu_c", "v_s"]))
            c = pdw.Contact(friction="lugre", **{name: v})
            assert type(getattr(c, name)) is float and not isinstance(v, (bool, str))
        elif which == "kv":
            c = pdw.Contact("kelvin_voigt", **{data.draw(st.sampled_from(["k", "d"])): v})
            assert type(c.k) is float and type(c.d) is float and not isinstance(v, (bool, str))
        elif which == "steady":
            sd = pdw.steps(_short_run()).steady(v)
            assert isinstance(sd["converged"], bool) and not isinstance(v, (bool, str))
        else:
            mask = np.zeros(8, bool)
            mask[data.draw(st.integers(0, 7))] = data.draw(st.booleans())
            x = np.ma.masked_array(X0.copy(), mask=mask)
            r = pdw.rhs(x)
            assert not mask.any() and np.array_equal(r, pdw.rhs(X0))
    except pdw.InvalidInputError:
        pass


_SHORT = {}


def _short_run():
    if not _SHORT:
        _SHORT["r"] = pdw.simulate(t_end=1.2, record=pdw.Record(every=0))
    return _SHORT["r"]


test_fuzz_coerce, test_fuzz_coerce_study = _twin("coerce", _coerce)

_BATCH_SAVED = {}


def _batch_saved():
    if not _BATCH_SAVED:
        import tempfile
        d = tempfile.mkdtemp(prefix="pdw-fuzz-batch-")
        x = np.tile(X0, (3, 1))
        x[1, 1] = -0.3
        path = os.path.join(d, "good.npz")
        pdw.simulate_batch(x, t_end=0.05, record=[0], record_every=20).save(path)
        with np.load(path) as z:
            a = {k: z[k] for k in z.files}
        _BATCH_SAVED.update(dir=d, arrays=a, meta=json.loads(str(a.pop("meta"))))
    return _BATCH_SAVED


def _batch_file(data):
    """A saved BatchResult with arrays replaced, dropped or poked and metadata junk: pdw.load
    gives an InvalidInputError naming the file, or a BatchResult of consistent shapes."""
    s = _batch_saved()
    a = {k: v.copy() for k, v in s["arrays"].items()}
    m = json.loads(json.dumps(s["meta"]))
    _tamper(data, a)
    if data.draw(st.booleans()):
        m[data.draw(st.sampled_from(sorted(m)))] = data.draw(
            JUNK.filter(lambda v: not isinstance(v, complex)))
    path = os.path.join(s["dir"], "case.npz")
    np.savez(path, meta=np.array(json.dumps(m)), **a)
    try:
        b = pdw.load(path)
    except pdw.InvalidInputError as e:
        assert "case.npz" in str(e)
        return
    n = len(b)
    assert b.x_final.shape == (n, 8) and b.status.shape == (n,) and b.gait_rows.shape[0] == n
    assert set(b.status) <= set(pdw.sim.files.STATUSES + pdw.sim.files.STOP_REASONS)


test_fuzz_batch_file, test_fuzz_batch_file_study = _twin("batch_file", _batch_file)

_CSV_SAVED = {}


def _csv_saved():
    if not _CSV_SAVED:
        import tempfile

        from pdw.studies import sweep
        d = tempfile.mkdtemp(prefix="pdw-fuzz-csv-")
        st_ = sweep.parse_study('name = "f"\n[scene]\npreset = "paper_steady"\n'
                                'stop = { t_end = 1.5 }\nrecord = { every = 0 }\n'
                                '[[axes]]\nname = "gamma"\nvalues = [0.036, 0.04, 0.044]\n'
                                '[run]\nsteady = 2\nfallback = false\n')
        sweep.run_study(st_, d, backend="serial")
        _CSV_SAVED.update(dir=d, study=st_, text=open(os.path.join(d, "f.csv")).read())
    return _CSV_SAVED


def _csv(data):
    """A sweep CSV with random cells replaced by junk, lines cut or duplicated: load_sweep gives
    a table or an InvalidInputError naming the file; read_rows (a resume) keeps only rows of
    the column types and never raises anything but PdwError."""
    s = _csv_saved()
    lines = s["text"].splitlines()
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(lines) - 1))
        cells = lines[i].split(",")
        action = data.draw(st.sampled_from(["cell", "cut", "dup", "drop"]))
        if action == "cell":
            j = data.draw(st.integers(0, len(cells) - 1))
            cells[j] = data.draw(st.text(max_size=6).filter(lambda t: "\n" not in t and "\r" not in t
                                                            and "," not in t and '"' not in t))
            lines[i] = ",".join(cells)
        elif action == "cut":
            lines[i] = lines[i][:data.draw(st.integers(0, len(lines[i])))]
        elif action == "dup":
            lines.insert(i, lines[i])
        else:
            lines.pop(i)
            if not lines:
                lines = [""]
    path = os.path.join(s["dir"], "case.csv")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    from pdw.studies import table
    try:
        out = pdw.load_sweep(path, as_frame=False)
        assert out.dtype.names[0] == "index"
    except pdw.InvalidInputError as e:
        assert "case.csv" in str(e)
    try:
        rows = table.read_rows(path, s["study"])
    except pdw.PdwError:
        return
    for r in rows.values():
        assert type(r["index"]) is int and (r["n_steps"] == "" or type(r["n_steps"]) is int)
        assert r["status"] in table.STATUSES


test_fuzz_csv, test_fuzz_csv_study = _twin("csv", _csv)


# --- the spec formats round three added: the [ground] table, the robustness spec ---------------

GROUND_KEYS = st.sampled_from(["kind", "edges", "heights", "width", "s", "h", "order", "slope",
                               "amplitude", "wavelength", "phase", "sigma", "correlation", "seed",
                               "modes", "offset", "extent", "blend", "bogus"])
GROUND_KIND = st.sampled_from(['"flat"', '"steps"', '"profile"', '"plane"', '"sine"',
                               '"random"', '"sum"', '"bogus"', "3"])
GROUND_VALUE = (TOML_VALUE | st.sampled_from(
    ["[0.5, 1.0]", "[0.01, -0.01]", "[1.0, 0.5]", "[0.0, 0.5, 1.0]", "[0.0, 0.001, 0.0]",
     "[-1.0, 40.0]", "[1e300, 1e301]", "1e-300", "0.001", "0.2", "-0.001", "[]", "[[1]]"]))
PATCH_KEYS = st.sampled_from(["s_a", "s_b", "k_n", "d_n", "mu_s", "mu_d", "k_t", "bogus"])


def _ground(case):
    """A [ground] table of random keys and values: a Ground whose heights are finite inside
    its range and whose compiled table builds, or InvalidInputError -- never another error."""
    text = "[ground]\nkind = %s\n%s\n" % (case["kind"], _toml(case["fields"]))
    for patch in case["patches"]:
        text += "[[ground.patches]]\n%s\n" % _toml(patch)
    try:
        d = pdw.core._toml.loads(text)
    except pdw.core._toml.TOMLDecodeError:
        return
    try:
        g = pdw.Ground.from_dict(d["ground"])
        lo, hi = g.s_range
        s = np.linspace(max(lo, -5.0), min(hi, 5.0), 7) if lo <= hi else np.array([])
        assert np.isfinite(np.asarray(g.h(s), dtype=float)).all()
        g.table()
    except pdw.InvalidInputError:
        return


test_fuzz_ground, test_fuzz_ground_study = _twin("ground", _ground, st.fixed_dictionaries({
    "kind": GROUND_KIND,
    "fields": st.lists(st.tuples(GROUND_KEYS, GROUND_VALUE), max_size=5, unique_by=lambda t: t[0]),
    "patches": st.lists(st.lists(st.tuples(PATCH_KEYS, TOML_VALUE), max_size=4,
                                 unique_by=lambda t: t[0]), max_size=2),
}))

ROB_TOP = st.sampled_from(["title", "measure", "model", "preset", "bogus"])
ROB_MEASURE = st.sampled_from(['"max_step"', '"gait_sensitivity"', '"first_passage"',
                               '"markov_chain"', '"bogus"', "1"])
ROB_OPTIONS = st.sampled_from(["direction", "indicators", "sigma", "walkers", "max_steps",
                               "seed", "tol", "h_max", "bogus"])
ROB_SWEEP = st.sampled_from(["parameter", "values", "bogus"])


def _robustness(case):
    """A robustness spec of random keys and values: parsed whole, or InvalidInputError."""
    from pdw.studies.robustness_spec import parse_spec
    text = ('name = %s\nmeasure = %s\n%s\n[options]\n%s\n[sweep]\n%s\n'
            % (case["name"], case["measure"], _toml(case["top"]), _toml(case["options"]),
               _toml(case["sweep"])))
    try:
        spec = parse_spec(text)
    except pdw.InvalidInputError:
        return
    assert "/" not in spec.name and not spec.name.startswith(".")
    assert spec.measure in ("max_step", "gait_sensitivity", "first_passage", "markov_chain")
    assert len(spec.values) >= 1


test_fuzz_robustness, test_fuzz_robustness_study = _twin("robustness", _robustness,
                                                         st.fixed_dictionaries({
    "name": st.sampled_from(['"r"', '".."', '"a/b"', '""', '".x"', "3"]),
    "measure": ROB_MEASURE,
    "top": _pairs(ROB_TOP), "options": _pairs(ROB_OPTIONS), "sweep": _pairs(ROB_SWEEP),
}))
