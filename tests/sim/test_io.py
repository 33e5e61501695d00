"""Issue 26, items 3 and 10; issue 25 "save and load of one format in one module".

What pdw writes, pdw reads (`pdw.sim.files` owns the format, writer and reader side by side):

* every Result pdw can return round-trips through ``Result.save`` / `pdw.load`, bit for bit,
  NaN and inf data included (a diverged run's non-finite energies, a fell run's inf force were
  written and then refused), every status, every contact law (LuGre's 10-entry state), dense
  output, features, t_eval, ``.npz`` and ``.nc``;
* a damaged, truncated or foreign file is a `pdw.InvalidInputError` naming the file (a damaged
  ``.npz`` raised a raw ``zlib.error``), never unpickled, and NaN where a run's description
  must be finite (times, parameters) is still refused;
* `BatchResult` saves and loads (with its recorded walkers); `pdw.load` returns the type the
  file's format tag names, through a registry another kind (a continuation Branch) joins.
"""
import dataclasses
import json
import struct
import warnings
import zipfile

import numpy as np
import pytest

import pdw
from pdw.sim import files, io

X0 = np.array(pdw.X0_PAPER, dtype=float)


def _quiet(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pdw.simulate(**kw)


def _same(a, b):
    """Bitwise the same array (NaN where NaN, the same inf)."""
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype.kind == b.dtype.kind and \
        np.array_equal(a, b, equal_nan=a.dtype.kind == "f")


def _assert_round_trip(r, r2):
    assert type(r2) is type(r)
    for name in ("t", "x", "flags", "Fn", "Ft", "x_final"):
        assert _same(getattr(r, name), getattr(r2, name)), name
    assert r2.events == r.events
    for name in ("status", "stop_reason", "t_final", "dt", "t_end", "method", "variant",
                 "n_steps", "n_gait_steps", "event_counts", "events_recorded", "features",
                 "params", "stats"):
        assert getattr(r2, name) == getattr(r, name), name
    assert (r2.contact or pdw.Contact()) == (r.contact or pdw.Contact())
    assert r2.state_names == r.state_names
    assert (r.energies is None) == (r2.energies is None)
    for k in (r.energies or {}):
        assert _same(r.energies[k], r2.energies[k]), k
    assert (r.gait is None) == (r2.gait is None)
    if r.gait is not None:
        for k, v in r.gait.table.items():
            assert _same(v, r2.gait.table[k]), k
    assert (r.failure is None) == (r2.failure is None)
    if r.failure:
        assert _same(r.failure["x"], r2.failure["x"])
        assert r2.failure["t"] == r.failure["t"] and r2.failure["reason"] == r.failure["reason"]
    assert (r.sol is None) == (r2.sol is None)
    if r.sol is not None:
        tq = np.linspace(r.sol.t[0], r.sol.t[-1], 37)
        assert _same(r.sol(tq), r2.sol(tq))


def _fell_with_inf():
    x = X0.copy()
    x[1] = -1e308
    return _quiet(x0=x, t_end=0.01, record=pdw.Record(energies=True),
                  limits=pdw.Limits(on_failure="return"))


def _diverged_nonfinite_energies():
    x = X0.copy()
    x[5] = 1e200
    return _quiet(x0=x, t_end=0.01, record=pdw.Record(energies=True),
                  limits=pdw.Limits(on_failure="return", max_speed=1e308))


def _standing():
    """Standing still on level ground: no step in 8 s (status "no_steps", test_ensemble)."""
    p = pdw.Params.paper(gamma=0.0)
    a = 0.2
    x = [0.0, p.r + (p.l - p.r) * np.cos(a), -a, a, 0, 0, 0, 0]
    return pdw.simulate(x, t_end=8.0, params=p, flags0=(1, 1),
                        integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=200),
                        limits=pdw.Limits(on_failure="return"))


RUNS = {
    "walked": lambda: pdw.simulate(t_end=0.4, record=pdw.Record(energies=True)),
    "periodic": lambda: pdw.simulate(t_end=12.0, params=pdw.Params.paper_steady(),
                                     record=pdw.Record(every=50),
                                     stop=pdw.Stop(periodic=True, periodic_steps=4, periodic_tol=1e-3)),
    "fell_inf_force": _fell_with_inf,
    "diverged_nonfinite_energies": _diverged_nonfinite_energies,
    "diverged_rodas4": lambda: _quiet(x0=np.r_[X0[:6], 1e160, X0[7]], t_end=0.01,
                                      method="rodas4",
                                      limits=pdw.Limits(on_failure="return", max_speed=1e308)),
    "no_steps": lambda: _standing(),
    "hertz": lambda: pdw.simulate(t_end=0.3, contact=pdw.Contact("hertz"),
                                  limits=pdw.Limits(on_failure="return")),
    "kelvin_voigt": lambda: pdw.simulate(t_end=0.3, contact=pdw.Contact("kelvin_voigt")),
    "flores_rodas4": lambda: pdw.simulate(t_end=0.3, method="rodas4",
                                          contact=pdw.Contact("flores", e=0.3)),
    "lankarani": lambda: pdw.simulate(t_end=0.3, contact=pdw.Contact("lankarani_nikravesh",
                                                                     e=0.9)),
    "lugre": lambda: _quiet(t_end=0.3, method="rodas4", contact=pdw.Contact(friction="lugre")),
    "lugre_dense": lambda: _quiet(t_end=0.2, method="rodas4", record=pdw.Record(dense_output=True),
                                  contact=pdw.Contact(friction="lugre", sigma1=10.0)),
    "dense_cdm": lambda: pdw.simulate(t_end=0.2, record=pdw.Record(dense_output=True)),
    "dense_rodas4_t_eval": lambda: pdw.simulate(t_end=0.3, method="rodas4",
                                                record=pdw.Record(dense_output=True, t_eval=np.linspace(0, 0.3, 31))),
    "t_eval": lambda: pdw.simulate(t_end=0.3, record=pdw.Record(t_eval=[0.0, 0.1, 0.25])),
    "features": lambda: pdw.simulate(t_end=0.3, features=("hip_spring", "friction")),
    "consistent_no_events": lambda: pdw.simulate(t_end=0.3, variant="consistent",
                                                 record=pdw.Record(events=False, every=0)),
    "steps_stop": lambda: pdw.simulate(t_end=3.0, record=pdw.Record(every=10),
                                       stop=pdw.Stop(steps=2)),
}


@pytest.mark.parametrize("suffix", [".npz", ".nc"])
@pytest.mark.parametrize("name", list(RUNS))
def test_every_result_round_trips(name, suffix, tmp_path):
    r = RUNS[name]()
    r2 = pdw.load(r.save(tmp_path / ("r" + suffix)))
    _assert_round_trip(r, r2)
    assert r2.provenance["format"] == "pdw-result-1"


def test_the_statuses_of_the_issue_hold_non_finite_data():
    """The runs of the issue do hold NaN/inf data (else the round trips above prove nothing)."""
    r = _fell_with_inf()
    assert r.status == "fell" and not np.isfinite(r.Fn).all()
    r = _diverged_nonfinite_energies()
    assert r.status == "diverged" and not np.isfinite(r.energies["E"]).all()
    statuses = {RUNS[n]().status for n in ("walked", "periodic", "no_steps")}
    assert statuses == {"walked", "periodic", "no_steps"}


def test_an_interrupted_result_round_trips(tmp_path):
    """Ctrl-C's partial Result (status "interrupted"), as `pdw.simulate` hands it on."""
    r = dataclasses.replace(pdw.simulate(t_end=0.2), status="interrupted",
                            stop_reason="interrupted")
    _assert_round_trip(r, pdw.load(r.save(tmp_path / "i.npz")))


# --- damaged and tampered files ---------------------------------------------------------------

@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    p = tmp_path_factory.mktemp("io") / "r.npz"
    r = pdw.simulate(t_end=0.7)
    assert len(r.events) >= 2
    r.save(p)
    return p


def _rewrite(src, dst, change):
    with np.load(src, allow_pickle=False) as z:
        a = {k: z[k] for k in z.files}
    change(a)
    np.savez(dst, **a)
    return dst


def _damage_member(src, dst, member="flags.npy"):
    """Flip the first bytes of a compressed member's deflate stream (its block header):
    reading it raises zlib.error ("invalid block type"), which escaped before."""
    data = bytearray(src.read_bytes())
    with zipfile.ZipFile(src) as z:
        info = z.getinfo(member)
    # the local header's own name and extra lengths (numpy's zip64 extra differs from the
    # central directory's)
    name_len, extra_len = struct.unpack("<HH", data[info.header_offset + 26:info.header_offset + 30])
    start = info.header_offset + 30 + name_len + extra_len
    for k in range(start, start + 4):
        data[k] ^= 0xFF
    dst.write_bytes(bytes(data))
    import zlib
    with pytest.raises(zlib.error):             # the damage is the issue's
        with np.load(dst, allow_pickle=False) as z:
            z[member[:-4]]
    return dst


def _write(path, data):
    path.write_bytes(data)
    return path


def _meta(a, **change):
    m = json.loads(str(a["meta"]))
    for k, v in change.items():
        cur = m
        keys = k.split("__")
        for kk in keys[:-1]:
            cur = cur[kk]
        cur[keys[-1]] = v
    a["meta"] = np.array(json.dumps(m))


DAMAGED = {
    "flipped_bytes_zlib": lambda s, d: _damage_member(s, d),
    "truncated": lambda s, d: _write(d, s.read_bytes()[:len(s.read_bytes()) // 2]),
    "empty": lambda s, d: _write(d, b""),
    "random": lambda s, d: _write(d, np.random.default_rng(1).bytes(4000)),
    "no_meta": lambda s, d: _rewrite(s, d, lambda a: a.pop("meta")),
    "meta_not_json": lambda s, d: _rewrite(s, d, lambda a: a.update(meta=np.array("{not json"))),
    "meta_a_number": lambda s, d: _rewrite(s, d, lambda a: a.update(meta=np.array(3.0))),
    "pickled_object": lambda s, d: _rewrite(s, d, lambda a: a.update(
        x=np.array([{"a": 1}], dtype=object))),
    "unknown_format": lambda s, d: _rewrite(s, d, lambda a: _meta(a, format="pdw-unknown-9")),
    "nan_time": lambda s, d: _rewrite(s, d, lambda a: a["t"].__setitem__(1, np.nan)),
    "nan_param": lambda s, d: _rewrite(s, d, lambda a: _meta(a, settings__params__m_h=float("nan"))),
    "x_wrong_width": lambda s, d: _rewrite(s, d, lambda a: a.update(x=a["x"][:, :3])),
    "flags_7": lambda s, d: _rewrite(s, d, lambda a: a["flags"].__setitem__((0, 0), 7)),
    "event_nan_time": lambda s, d: _rewrite(s, d, lambda a: a["events"].__setitem__((0, 0),
                                                                                   np.nan)),
    "bad_status": lambda s, d: _rewrite(s, d, lambda a: _meta(a, status="flew")),
}


@pytest.mark.parametrize("name", list(DAMAGED))
def test_a_damaged_file_is_a_clear_error_naming_it(name, saved, tmp_path):
    bad = DAMAGED[name](saved, tmp_path / ("bad_%s.npz" % name))
    with pytest.raises(pdw.InvalidInputError) as e:
        pdw.load(bad)
    assert str(bad) in str(e.value)


def test_a_missing_file_and_a_foreign_suffix_are_clear_errors(tmp_path):
    with pytest.raises(pdw.InvalidInputError, match="(?i)no such file"):
        pdw.load(tmp_path / "nothing.npz")
    p = tmp_path / "r.txt"
    p.write_text("hello")
    with pytest.raises(pdw.InvalidInputError, match="r.txt"):
        pdw.load(p)


# --- BatchResult, the registry, the old import paths ------------------------------------------

def test_batch_result_round_trips_with_its_recorded_walkers(tmp_path):
    x = np.tile(X0, (4, 1))
    x[2, 1] = -0.3                                 # one that falls at once
    b = pdw.simulate_batch(x, t_end=0.3, record=[0, 2], record_every=10)
    assert set(b.status) >= {"walked", "fell"}
    b2 = pdw.load(b.save(tmp_path / "b.npz"))
    assert type(b2) is type(b) and len(b2) == len(b)
    for f in dataclasses.fields(b):
        if f.name == "recorded":
            continue
        v, v2 = getattr(b, f.name), getattr(b2, f.name)
        if isinstance(v, np.ndarray):
            assert _same(v.astype(str) if v.dtype == object else v,
                         v2.astype(str) if v2.dtype == object else v2), f.name
            assert v2.dtype == v.dtype, f.name
        else:
            assert v2 == v, f.name
    assert sorted(b2.recorded) == [0, 2]
    for i in (0, 2):
        _assert_round_trip(b.recorded[i], b2.recorded[i])
    assert b2.steps(0).table["L"].tolist() == b.steps(0).table["L"].tolist()
    with pytest.raises(pdw.InvalidInputError, match=".npz"):
        b.save(tmp_path / "b.nc")


def test_load_dispatches_on_the_format_tag_and_the_registry_is_open(tmp_path):
    """A kind registered later (as a continuation Branch will be) saves and loads through the
    same `pdw.load`, by its format tag."""
    @dataclasses.dataclass
    class Thing:
        a: np.ndarray
        label: str

    def to_file(t):
        return {"a": t.a}, {"label": t.label}

    def from_file(arrays, meta):
        return Thing(files.array(arrays, "a", (-1,), finite=False), files.field(meta, "label"))

    files.register("test-thing-1", Thing, to_file, from_file)
    try:
        t = Thing(np.array([1.0, np.nan, np.inf]), "x")
        t2 = pdw.load(files.save(t, tmp_path / "t.npz"))
        assert type(t2) is Thing and t2.label == "x" and _same(t2.a, t.a)
        assert "test-thing-1" in files.kinds()
    finally:
        files._KINDS.pop("test-thing-1")
    with pytest.raises(pdw.InvalidInputError, match="test-thing-1"):
        pdw.load(tmp_path / "t.npz")
    with pytest.raises(pdw.InvalidInputError, match="pdw saves"):
        files.save(object(), tmp_path / "o.npz")


def test_one_module_owns_the_format_and_the_old_paths_are_aliases():
    assert io.save is files.save and io.read is files.read and io.metadata is files.metadata
    assert io.result_to_xarray is files.result_to_xarray and io.FORMAT == files.FORMAT
    assert pdw.load is files.load
    from pdw.sim import files as f2
    assert f2.load is pdw.load and f2.STATUSES


@pytest.fixture(scope="module")
def saved_run(tmp_path_factory):
    path = tmp_path_factory.mktemp("load") / "good.npz"
    pdw.simulate(t_end=0.02, record=pdw.Record(energies=True)).save(path)
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files}
    return path, arrays, json.loads(str(arrays.pop("meta")))


def _write_npz(path, arrays, meta):
    np.savez(path, meta=np.array(json.dumps(meta)), **arrays)
    return path


TAMPER = [
    ("x wrong columns", lambda a, m: a.update(x=a["x"][:, :3]), "'x'"),
    ("x fewer rows", lambda a, m: a.update(x=a["x"][:5]), "'x'"),
    # NaN in x is a run's data (a diverged run's state: it round-trips, tests/sim/test_io.py);
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
def test_load_refuses_a_tampered_file_naming_the_field(saved_run, tmp_path, name, change, field):
    """Each of these used to load into a Result that lied (or raised KeyError/IndexError)."""
    path, arrays, meta = saved_run
    a = {k: v.copy() for k, v in arrays.items()}
    m = json.loads(json.dumps(meta))
    change(a, m)
    with pytest.raises(pdw.InvalidInputError, match=field):
        pdw.load(_write_npz(tmp_path / "bad.npz", a, m))


@pytest.mark.parametrize("content", ["truncated", "empty", "random", "missing", "bad json",
                                     "pickled"])
def test_load_refuses_an_unreadable_file(saved_run, tmp_path, content):
    """BadZipFile, EOFError, FileNotFoundError, JSONDecodeError and numpy's pickle refusal
    become one InvalidInputError naming the file."""
    path, arrays, meta = saved_run
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


def test_load_of_an_untouched_file_gives_the_run_back(saved_run):
    path, arrays, meta = saved_run
    r = pdw.load(path)
    assert np.array_equal(r.x, arrays["x"]) and r.status == meta["status"]
    assert r.params == pdw.Params(**meta["settings"]["params"])
