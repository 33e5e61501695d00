"""Issue 16 on the entry points merged after it: the ensemble engine (`pdw.core._batch`,
`simulate_batch`), the ODE object (`ode_function`), the contact laws (`pdw.Contact`), reusable
record buffers (`RecordBuffer`, ``simulate(out=...)``) and result files (`pdw.load`).

Each case was found by attacking the entry point (wrong sizes, dtypes, NaN, strings, tampered
files). The calls that could touch memory out of bounds run in a subprocess, so a crash fails
the test instead of killing the run.
"""
import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import pdw
from pdw.sim.batch import simulate_batch
from pdw.sim.buffers import RecordBuffer

_PRELUDE = """
import numpy as np
import pdw
from pdw.core import _core, _batch
from pdw.core.model import parameter_vector
from pdw.sim.batch import _outputs
from pdw.sim.buffers import RecordBuffer
NX, NP = _core.NX, _core.NP
P = parameter_vector(pdw.Params.paper())
X = np.tile(np.array(pdw.X0_PAPER), (2, 1))
F = np.tile(np.array([0, 1], dtype=np.intc), (2, 1))
H, D = np.full(2, 0.5), np.full(2, 0.1)
O = dict(dt=1e-4, n_steps=50, record_every=1, record_events=1, fall_hip_height=0.2,
         fall_depth=0.1, max_speed=1e3)
def rr(x=X, p=P[None], f=F, dt=1e-4, n=50, stop=0, pk=0, out=None):
    return _batch.run_range(0, x, p, f, H, D, dict(dt=dt, n_steps=n, max_speed=1e3,
                                                   stop_steps=stop, periodic_k=pk,
                                                   periodic_tol=1e-3),
                            _outputs(len(x)) if out is None else out, 0, len(x), 4, False)
def tampered(**arrays):
    b = RecordBuffer(100)
    for k, v in arrays.items():
        setattr(b, k, v)
    return b
def bufs(n=100, nx=NX, nc=4):
    return (np.zeros(n), np.zeros((n, nx)), np.zeros((n, 2), np.intc), np.zeros((n, nc)))
"""

# (call, a word its ValueError must contain): each used to write out of bounds (a heap
# corruption: "double free or corruption"), run on garbage or run with a meaningless value
CRASH_CASES = [
    ("pdw.simulate(t_end=0.005, out=tampered(contact=np.zeros((100, 1))))", "out.contact"),
    ("pdw.simulate(t_end=0.005, out=tampered(x=np.zeros((1, NX))))", "out.x"),
    ("pdw.simulate(t_end=0.05, out=tampered(t=np.zeros(5000)))", "out.x"),
    ("pdw.simulate(t_end=0.005, out=tampered(flags=np.zeros((100, 2))))", "out.flags"),
    ("_core.run(0, 0, X[0], P, 0, 1, O, buffers=bufs(nc=1))",
     "contact"),
    ("_core.run(0, 0, X[0], P, 0, 1, O, "
     "buffers=bufs()[:1] + (np.zeros((3, NX)),) + bufs()[2:])", "x"),
    ("rr(f=np.array([[7, 1], [0, 1]], np.intc))", "flags0"),
    ("rr(dt=float('nan'))", "dt"),
    ("rr(n=-5)", "n_steps"),
    ("rr(pk=99)", "periodic_k"),
    ("rr(out={k: v for k, v in _outputs(2).items() if k != 'fail_x'})", "fail_x"),
    ("rr(out=dict(_outputs(2), fail_x=np.zeros((1, NX))))", "fail_x"),
    ("_core.OdeFunction(0, P[:3].copy(), 0, 1, 0.0, 0.0)", "p"),
    ("_core.OdeFunction(0, P, 7, 1, 0.0, 0.0)", "flags"),
    ("pdw.ode_function().set_discrete(0, 1, float('nan'), 0.0)", "anchors"),
]


def _run(code):
    return subprocess.run([sys.executable, "-c", textwrap.dedent(_PRELUDE + code)],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("call,word", CRASH_CASES, ids=[c[1] + ":" + c[0][:40] for c in CRASH_CASES])
def test_compiled_boundary_of_the_new_entry_points_refuses_before_touching_memory(call, word):
    out = _run("""
try:
    %s
except ValueError as e:
    print("VALUEERROR", e)
else:
    print("RETURNED")
""" % call)
    assert out.returncode == 0, (call, out.returncode, out.stderr[-2000:])
    line = out.stdout.strip().splitlines()[-1]
    assert line.startswith("VALUEERROR"), (call, line)
    assert word in line, line


# --- simulate_batch: strict input, as simulate -------------------------------------------------

X2 = np.tile(np.array(pdw.X0_PAPER), (2, 1))
BATCH_CASES = [
    (dict(flags0=(0.9, 1.9)), "flags0"),                 # was silently (0, 1)
    (dict(flags0="01"), "flags0"),
    (dict(flags0=[(0, 1), (2, 1)]), "flags0 row 1"),
    (dict(fall_hip_height=float("nan")), "fall_hip_height"),   # was fall detection off
    (dict(fall_hip_height="0.3"), "fall_hip_height"),    # was float("0.3")
    (dict(fall_hip_height=[0.3, 0.3]), "fall_hip_height"),     # was a raw TypeError
    (dict(x0=X2.astype(complex)), "x0"),                 # was the real part
    (dict(x0=[["1"] * 8]), "x0"),                        # was float("1")
    (dict(x0=np.ones((1, 8), bool)), "x0"),
    (dict(vector="no"), "vector"),                       # was bool("no") = True
    (dict(t_end=1e30), "t_end / dt"),                    # was a raw OverflowError
    (dict(t_end=1.7e304), "t_end / dt"),                 # t_end/dt = inf (found by the fuzzer)
]


@pytest.mark.parametrize("kw,field", BATCH_CASES, ids=[c[1] + ":" + repr(c[0])[:30] for c in BATCH_CASES])
def test_simulate_batch_refuses_malformed_input_naming_the_field(kw, field):
    kw = {"t_end": 0.01, **kw}
    x0 = kw.pop("x0", X2)
    with pytest.raises(pdw.InvalidInputError, match=field.replace("(", r"\(")):
        simulate_batch(x0, **kw)


def test_simulate_refuses_a_t_end_whose_step_count_overflows():
    """t_end = 1.8e304 with dt = 1e-4: t_end/dt is inf, and round(inf) was a raw OverflowError
    (found by the fuzzer)."""
    with pytest.raises(pdw.InvalidInputError, match="t_end/dt"):
        pdw.simulate(t_end=1.797693134862316e+304)


def test_simulate_batch_still_takes_well_formed_input():
    b = simulate_batch(X2.tolist(), t_end=0.01, flags0=np.array([[0, 1], [0, 1]]),
                       fall_hip_height=0.3, vector=np.bool_(False))
    r = pdw.simulate(t_end=0.01, record_every=0, fall_hip_height=0.3)
    assert np.array_equal(b.x_final[0], r.x_final) and list(b.status) == ["walked"] * 2


# --- ode_function / OdeFunction ----------------------------------------------------------------

@pytest.mark.parametrize("x", [np.array(pdw.X0_PAPER, complex), ["1"] * 8, np.ones((2, 4)),
                               np.ones((1, 1, 8)), np.ones(8, bool)],
                         ids=["complex", "strings", "2x4", "1x1x8", "bool"])
def test_ode_function_refuses_states_it_used_to_coerce(x):
    """f(t, x) used to take the real part, parse strings and ravel any 8-element array."""
    f = pdw.ode_function()
    with pytest.raises(pdw.InvalidInputError, match="x must"):
        f(0.0, x)
    with pytest.raises(pdw.InvalidInputError, match="x must"):
        f.jac(0.0, x)


def test_ode_function_fast_and_converting_paths_agree():
    f = pdw.ode_function()
    x = np.array(pdw.X0_PAPER)
    assert np.array_equal(f(0.0, x), f(0.0, list(x)))
    assert np.array_equal(f(0.0, np.vstack([x, x]))[1], f(0.0, x))
    assert np.array_equal(f.jac(0.0, list(x)), f.jac(0.0, x))


@pytest.mark.parametrize("kw,field", [(dict(flags=np.array([0.0, 1.0])), "flags"),
                                      (dict(flags=(0.9, 1)), "flags"),
                                      (dict(anchors=("0", "1")), "anchors"),
                                      (dict(anchors=(0.0, float("inf"))), "anchors")])
def test_ode_function_discrete_state_is_strict(kw, field):
    with pytest.raises(pdw.InvalidInputError, match=field):
        pdw.ode_function(**kw)


# --- Contact, RecordBuffer ---------------------------------------------------------------------

@pytest.mark.parametrize("kw", [dict(k="1e5"), dict(k=True), dict(d=1j),
                                dict(normal="flores", e="0.5")])
def test_contact_parameters_must_be_real_numbers(kw):
    """Contact(k="1e5") was float("1e5"), Contact(k=True) a stiffness of 1."""
    with pytest.raises(pdw.InvalidInputError, match="contact." + [k for k in kw if k != "normal"][0]):
        pdw.Contact(**kw)


@pytest.mark.parametrize("cap", [-1, "x", 1.5, float("nan"), 2 ** 41, None])
def test_record_buffer_capacity_is_checked(cap):
    with pytest.raises(pdw.InvalidInputError, match="capacity"):
        RecordBuffer(cap)


def test_a_well_formed_record_buffer_still_gives_the_same_run():
    b = RecordBuffer(10)
    r1 = pdw.simulate(t_end=0.01, out=b)
    r2 = pdw.simulate(t_end=0.01)
    assert np.array_equal(r1.x, r2.x) and b.capacity >= len(r2.t)


# --- dense output -------------------------------------------------------------------------------

@pytest.mark.parametrize("kw,field", [(dict(t_eval=np.array([0.01 + 1j])), "t_eval"),
                                      (dict(t_eval=[0.0, float("nan")]), "t_eval"),
                                      (dict(dense_output="yes"), "dense_output")])
def test_dense_output_arguments_are_strict(kw, field):
    """A complex t_eval was its real part; dense_output="yes" was True."""
    with pytest.raises(pdw.InvalidInputError, match=field):
        pdw.simulate(t_end=0.02, method="rodas4", **kw)


@pytest.mark.parametrize("tq", ["0.01", 0.01 + 1j, np.full((2, 2), 0.01), float("nan"), 5.0])
def test_dense_interpolant_refuses_bad_times(tq):
    """sol("0.01") was parsed; complex and 2-D times gave raw TypeError / ValueError."""
    sol = pdw.simulate(t_end=0.02, method="rodas4", dense_output=True).sol
    with pytest.raises(pdw.InvalidInputError, match="t"):
        sol(tq)
    assert sol(0.01).shape == (8,) and sol([0.005, 0.01]).shape == (2, 8)


# --- pdw.load ----------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    path = tmp_path_factory.mktemp("load") / "good.npz"
    pdw.simulate(t_end=0.02, record_energies=True).save(path)
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files}
    return path, arrays, json.loads(str(arrays.pop("meta")))


def _write(path, arrays, meta):
    np.savez(path, meta=np.array(json.dumps(meta)), **arrays)
    return path


TAMPER = [
    ("x wrong columns", lambda a, m: a.update(x=a["x"][:, :3]), "'x'"),
    ("x fewer rows", lambda a, m: a.update(x=a["x"][:5]), "'x'"),
    # NaN in x is a run's data (a diverged run's state: it round-trips, tests/test_io.py);
    # NaN in t is not
    ("t NaN", lambda a, m: a["t"].__setitem__(3, np.nan), "'t' must be finite"),
    ("x strings", lambda a, m: a.update(x=np.array(["a"] * 8)), "'x'"),
    ("flags 7", lambda a, m: a["flags"].__setitem__((1, 0), 7), "'flags'"),
    ("flags float", lambda a, m: a.update(flags=a["flags"] + 0.5), "'flags'"),
    ("no t", lambda a, m: a.pop("t"), "'t'"),
    ("event kind 9", lambda a, m: a.update(events=np.array([[0.1, 1, 9, 0, 0]])), "'events'"),
    ("event leg 5", lambda a, m: a.update(events=np.array([[0.1, 5, 0, 0, 0]])), "'events'"),
    ("x_final short", lambda a, m: a.update(x_final=np.zeros(3)), "'x_final'"),
    ("energy short", lambda a, m: a.update(energy_T=np.zeros(2)), "'energy_T'"),
    ("no settings", lambda a, m: m.pop("settings"), "settings"),
    ("unknown parameter", lambda a, m: m["settings"]["params"].update(zz=1), "settings.params"),
    ("bad parameter", lambda a, m: m["settings"]["params"].update(k_n=-5.0), "k_n"),
    ("unknown status", lambda a, m: m.update(status="bogus"), "status"),
    ("dt a string", lambda a, m: m["settings"].update(dt="x"), "settings.dt"),
    ("unknown method", lambda a, m: m["settings"].update(method="zzz"), "settings.method"),
    ("unknown feature", lambda a, m: m["settings"].update(features=["zzz"]), "settings.features"),
    ("t_final a string", lambda a, m: m.update(t_final="soon"), "t_final"),
    ("failure without a state", lambda a, m: m.update(failure={"x": [1.0]}), "failure"),
]


@pytest.mark.parametrize("name,change,field", TAMPER, ids=[t[0] for t in TAMPER])
def test_load_refuses_a_tampered_file_naming_the_field(saved, tmp_path, name, change, field):
    """Each of these used to load into a Result that lied (or raised KeyError/IndexError)."""
    path, arrays, meta = saved
    a = {k: v.copy() for k, v in arrays.items()}
    m = json.loads(json.dumps(meta))
    change(a, m)
    with pytest.raises(pdw.InvalidInputError, match=field):
        pdw.load(_write(tmp_path / "bad.npz", a, m))


@pytest.mark.parametrize("content", ["truncated", "empty", "random", "missing", "bad json",
                                     "pickled"])
def test_load_refuses_an_unreadable_file(saved, tmp_path, content):
    """BadZipFile, EOFError, FileNotFoundError, JSONDecodeError and numpy's pickle refusal
    become one InvalidInputError naming the file."""
    path, arrays, meta = saved
    bad = tmp_path / "bad.npz"
    raw = path.read_bytes()
    if content == "truncated":
        bad.write_bytes(raw[:len(raw) // 2])
    elif content == "empty":
        bad.write_bytes(b"")
    elif content == "random":
        bad.write_bytes(np.random.default_rng(0).bytes(1000))
    elif content == "bad json":
        np.savez(bad, meta=np.array("{not json"), **arrays)
    elif content == "pickled":
        np.savez(bad, meta=np.array(json.dumps(meta)), **dict(arrays, x=np.array([object()] * 8)))
    with pytest.raises(pdw.InvalidInputError, match="bad.npz"):
        pdw.load(bad)


def test_load_of_an_untouched_file_gives_the_run_back(saved):
    path, arrays, meta = saved
    r = pdw.load(path)
    assert np.array_equal(r.x, arrays["x"]) and r.status == meta["status"]
    assert r.params == pdw.Params(**meta["settings"]["params"])
