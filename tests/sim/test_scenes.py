"""Scenes (pdw.Scene, `pdw run`), the online gait analysis, stop conditions, recording options."""
import json
import math
import pathlib
import subprocess
import sys
import tracemalloc

import numpy as np
import pytest

import pdw
import pdw.examples
from pdw import METHODS
from pdw.core import _layout
from pdw.present import cli
from pdw.sim.gait import FIELDS
from pdw.sim.scene import Forces, Integrator, Limits, Record, Scene, Stop
from pdw.studies.study import parse_study

ROOT = pathlib.Path(__file__).resolve().parents[2]
STEADY = pdw.Params.paper_steady()
ALL_BUT_LAST_DS = [f for f in FIELDS if f not in ("double_support", "ds_fraction")]


def _assert_steps_equal(a, b, fields=FIELDS):
    assert len(a) == len(b)
    for f in fields:
        np.testing.assert_array_equal(a[f], b[f], err_msg=f)


def _agree(table, n, k, tol):
    """The periodic criterion on steps n-k .. n-1 (what the compiled loop checks)."""
    if n < k:
        return False
    for f in _layout.PERIODIC_FIELDS:
        w = table[f][n - k:n]
        if not (w.max() - w.min() <= tol * abs(w[-1])):
            return False
    return True


@pytest.fixture(scope="module")
def full_10s():
    """paper_steady from the paper's x0, 10 s, everything recorded (events included)."""
    return pdw.simulate(t_end=10.0, params=STEADY, record=pdw.Record(every=1, forces=True))


# ------------------------------------------------------------------ online gait analysis

def test_descriptors_only_gives_the_steps_of_a_full_run(full_10s):
    d = pdw.simulate(t_end=10.0, params=STEADY,
                     record=pdw.Record(every=0, forces=False, events=False))
    assert d.walked and d.events == [] and len(d.t) == 0 and d.Fn.shape == (0, 2)
    assert np.array_equal(d.x_final, full_10s.x_final)          # recording changes nothing
    ref = pdw.steps(full_10s)
    assert len(ref) >= 15
    _assert_steps_equal(d.gait, ref)                            # bit for bit
    _assert_steps_equal(pdw.steps(d), ref)                      # steps() of such a run: online
    _assert_steps_equal(full_10s.gait, ref)                     # and of a full run: the same
    assert d.n_gait_steps == len(ref)
    kinds = [e.kind for e in full_10s.events]
    assert d.event_counts == {"touch_down": kinds.count("touch_down"),
                              "lift_off": kinds.count("lift_off")}


def test_online_steps_of_the_paper_run_match_pdw_steps_for_every_variant():
    for variant in _layout.VARIANTS:
        r = pdw.simulate(variant=variant, record=pdw.Record(every=0))
        _assert_steps_equal(r.gait, pdw.steps(r))
        assert len(r.gait) >= 3


def test_ring_keeps_the_last_steps_of_a_long_run():
    full = pdw.simulate(t_end=25.0, params=STEADY, record=pdw.Record(every=0))
    d = pdw.simulate(t_end=25.0, params=STEADY, record=pdw.Record(every=0, events=False))
    ref = pdw.steps(full)
    assert len(ref) > _layout.STEP_RING and d.n_gait_steps == len(ref)
    assert len(d.gait) == _layout.STEP_RING
    last = pdw.sim.gait.Steps({f: ref[f][-_layout.STEP_RING:] for f in FIELDS})
    _assert_steps_equal(d.gait, last)


def test_descriptors_only_memory_does_not_grow_with_the_run():
    def peak(t_end):
        pdw.simulate(t_end=t_end, params=STEADY, record=pdw.Record(every=0, events=False))
        tracemalloc.start()
        r = pdw.simulate(t_end=t_end, params=STEADY, record=pdw.Record(every=0, events=False))
        _, p = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        assert r.walked
        return p, r
    short, _ = peak(0.1)                         # 10^3 steps
    long_, r = peak(30.0)                        # 3 x 10^5 steps, ~50 gait steps
    assert r.n_gait_steps > _layout.STEP_RING
    assert long_ <= short + 256, (short, long_)      # the same, up to Python object noise


# ------------------------------------------------------------------ stop conditions

@pytest.mark.parametrize("k, tol", [(3, 1e-3), (4, 2e-3), (5, 5e-4)])
def test_stop_when_periodic_stops_as_soon_as_the_last_k_steps_agree(k, tol, full_10s):
    r = pdw.simulate(t_end=10.0, params=STEADY, record=pdw.Record(every=0),
                     stop=pdw.Stop(periodic=True, periodic_steps=k, periodic_tol=tol))
    assert r.status == "periodic" and r.stop_reason == "periodic" and r.walked
    assert r.t_final < 10.0
    ref = pdw.steps(full_10s)
    n = r.n_gait_steps
    # stopped at the touch-down that completes step n, the first n at which the criterion holds
    assert r.t_final == pytest.approx(ref["t_touch_down"][n - 1], abs=1e-12)
    assert _agree(ref.table, n, k, tol)
    assert not any(_agree(ref.table, m, k, tol) for m in range(k, n))
    # the right descriptors: those of the full run, up to that step (whose double support is
    # not known yet when the run stops)
    head = pdw.sim.gait.Steps({f: ref[f][:n] for f in FIELDS})
    _assert_steps_equal(r.gait, head, ALL_BUT_LAST_DS)
    _assert_steps_equal(pdw.sim.gait.Steps({f: r.gait[f][:-1] for f in FIELDS}),
                        pdw.sim.gait.Steps({f: head[f][:-1] for f in FIELDS}))
    assert math.isnan(r.gait["double_support"][-1])
    # and the events it kept are the full run's up to the stop
    assert r.events == [e for e in full_10s.events if e.t <= r.t_final]


def test_a_gait_that_does_not_converge_is_not_stopped():
    """The paper's d_hip = 0.018 gait decays and falls (docs/model.md section 8): no periodic stop."""
    r = pdw.simulate(t_end=8.0, record=pdw.Record(every=0),
                     stop=pdw.Stop(periodic=True, periodic_steps=4, periodic_tol=1e-4))
    assert r.status == "fell" and r.stop_reason == "fell"


@pytest.mark.parametrize("method, kw", [
    ("cdm", dict(dt=1e-4)), ("verlet", dict(dt=2e-6)), ("rk4", dict(dt=2e-6)),
    ("dopri5", dict(dt=1e-5)), ("rodas4", dict(rtol=1e-6, atol=1e-8)),
])      # the fields of pdw.Integrator
def test_every_method_stops_after_n_steps(method, kw):
    assert method in METHODS
    r = pdw.simulate(t_end=3.0, params=STEADY, method=method, integrator=pdw.Integrator(**kw),
                     record=pdw.Record(every=1), stop=pdw.Stop(steps=2))
    assert r.status == "walked" and r.stop_reason == "steps" and r.n_gait_steps == 2
    td = [e for e in r.events if e.kind == "touch_down"]
    assert r.t_final == td[-1].t and r.t_final < 1.6         # the 3rd touch-down ends step 2
    assert r.t[-1] == r.t_final and np.array_equal(r.x[-1], r.x_final)   # final sample stored
    _assert_steps_equal(r.gait, pdw.steps(r))


@pytest.mark.parametrize("method", ["cdm", "rodas4"])
def test_every_method_stops_when_periodic(method):
    r = pdw.simulate(t_end=12.0, params=STEADY, method=method, record=pdw.Record(every=0),
                     stop=pdw.Stop(periodic=True, periodic_steps=3, periodic_tol=2e-3))
    assert r.status == "periodic" and r.t_final < 12.0
    assert _agree(r.gait.table, len(r.gait), 3, 2e-3)


def test_stop_conditions_need_valid_settings():
    with pytest.raises(pdw.InvalidInputError, match="periodic_steps"):
        pdw.simulate(t_end=0.1, stop=pdw.Stop(periodic=True, periodic_steps=1))
    with pytest.raises(pdw.InvalidInputError, match="periodic_steps"):
        pdw.simulate(t_end=0.1,
                     stop=pdw.Stop(periodic=True, periodic_steps=_layout.STEP_RING + 1))
    with pytest.raises(pdw.InvalidInputError, match=r"stop\.steps"):
        pdw.simulate(t_end=0.1, stop=pdw.Stop(steps=-1))
    with pytest.raises(pdw.InvalidInputError, match="periodic_tol"):
        pdw.simulate(t_end=0.1, stop=pdw.Stop(periodic=True, periodic_steps=3, periodic_tol=0.0))


# ------------------------------------------------------------------ recording options

def test_recording_options_do_what_they_say():
    base = dict(t_end=1.0, params=STEADY)
    full = pdw.simulate(record=pdw.Record(every=1, forces=True, energies=True), **base)
    assert len(full.t) == 10001 and full.Fn.shape == (10001, 2)
    e = pdw.energies(full.x, full.params)
    for name in ("T", "V_gravity", "V_hip", "E"):
        np.testing.assert_allclose(full.energies[name], e[name], rtol=1e-12, atol=1e-12)
    every = pdw.simulate(record=pdw.Record(every=7, forces=False), **base)
    assert np.array_equal(every.t, full.t[::7]) and np.array_equal(every.x, full.x[::7])
    assert every.Fn.shape == (0, 2) and every.energies is None
    ev = pdw.simulate(record=pdw.Record(every=0, forces=False), **base)
    assert len(ev.t) == 0 and ev.events == full.events
    with pytest.raises(pdw.InvalidInputError, match=r"record\.energies"):
        pdw.simulate(record=pdw.Record(every=0, energies=True), **base)


def test_switched_off_forces_use_the_specialized_kernel_and_equal_zeroed_parameters():
    feats = ("normal_damping", "tangential", "friction")          # no hip spring or damper
    a = pdw.simulate(t_end=0.6, params=STEADY, features=feats, record=pdw.Record(every=50))
    b = pdw.simulate(t_end=0.6, params=STEADY.replace(k_hip=0.0, d_hip=0.0),
                     record=pdw.Record(every=50))
    assert a.params == STEADY.replace(k_hip=0.0, d_hip=0.0)
    assert a.features == feats and a.status == b.status
    np.testing.assert_allclose(a.x, b.x, rtol=1e-9, atol=1e-9)
    assert [(e.leg, e.kind) for e in a.events] == [(e.leg, e.kind) for e in b.events]
    with pytest.raises(pdw.InvalidInputError, match="hip_sprung"):
        pdw.simulate(t_end=0.1, features=("hip_sprung",))


# ------------------------------------------------------------------ scenes

def test_scene_runs_like_simulate_with_its_settings():
    sc = Scene(preset="paper_steady", params={"k_hip": 0.9}, record=Record.events_only(),
               stop={"t_end": 2.0})
    a = pdw.run(sc)
    b = pdw.simulate(sc)
    c = pdw.simulate(t_end=2.0, params=pdw.Params.paper_steady(k_hip=0.9),
                     record=pdw.Record(every=0, forces=False))
    assert a.scene is sc and b.scene == sc
    assert np.array_equal(a.x_final, c.x_final) and a.events == c.events == b.events
    with pytest.raises(pdw.InvalidInputError, match="dt"):
        pdw.simulate(sc, dt=1e-3)


def test_scene_forces_pick_the_kernel():
    sc = Scene(forces=Forces.only("normal_damping", "friction"), stop={"t_end": 0.3},
               record={"every": 0})
    assert sc.features == ("normal_damping", "friction")
    r = sc.run()
    assert r.features == sc.features and r.params.k_hip == 0 and r.params.k_t == 0


def test_scene_descriptors_only_periodic_in_one_object(full_10s):
    sc = Scene(preset="paper_steady", record=Record.descriptors_only(),
               stop=Stop(t_end=10.0, periodic=True, periodic_steps=3, periodic_tol=1e-3))
    r = sc.run()
    assert r.status == "periodic" and r.events == [] and len(r.t) == 0
    ref = pdw.steps(full_10s)
    _assert_steps_equal(r.gait, pdw.sim.gait.Steps({f: ref[f][:len(r.gait)] for f in FIELDS}),
                        ALL_BUT_LAST_DS)


def _odd_scene():
    return Scene(name='odd "name" \\ with\ttab\nnewline, unicode \u03b3 and \x7f',
                 preset="paper_steady", params={"k_hip": 0.9, "d_n": 2.5e6, "gamma": 1e-300},
                 variant="consistent", x0=(0, 0.5, 0.1, -0.1, 1e-17, -0.0, 3, float(2)),
                 flags0=[1, 1],
                 integrator=Integrator(method="rodas4", dt=3e-5, rtol=1e-9, atol=1e-12,
                                       h_max=0.01, event_tol=1e-11),
                 forces=Forces.only("normal_damping", "friction"),
                 record=Record.full(every=10),
                 stop=Stop(t_end=12.25, steps=7, periodic=True, periodic_steps=5,
                           periodic_tol=1e-5, touch_down=2),
                 limits=Limits(fall_hip_height=0.2, fall_depth=0.05, max_speed=50,
                               on_failure="return"),
                 approach_speeds0=(0.0, 0.25))


@pytest.mark.parametrize("scene", [Scene(), _odd_scene(),
                                   Scene(record=Record.descriptors_only(), stop={"t_end": 1e3})],
                         ids=["default", "odd", "descriptors"])
def test_scene_round_trips_through_toml(scene, tmp_path):
    text = scene.to_toml()
    back = Scene.from_toml(text)
    assert back == scene and back.to_toml() == text
    assert Scene.load(scene.save(tmp_path / "s.toml")) == scene
    assert Scene.from_dict(scene.to_dict()) == scene
    assert hash(back) == hash(scene)


def test_scene_values_are_normalised():
    sc = Scene(x0=[0, 0.5, 0, 0, 0, 0, 0, 0], stop={"t_end": 2}, params={"k_hip": 1})
    assert sc.x0 == (0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0) and isinstance(sc.stop.t_end, float)
    assert sc.params == {"k_hip": 1.0} and sc.parameters().k_hip == 1.0


def test_scene_replace_updates_tables():
    sc = Scene(stop={"t_end": 5.0, "periodic": True})
    s2 = sc.replace(stop={"t_end": 7.0}, record=Record.descriptors_only(), variant="consistent")
    assert s2.stop.t_end == 7.0 and s2.stop.periodic and s2.variant == "consistent"
    assert s2.record == Record.descriptors_only() and sc.stop.t_end == 5.0
    with pytest.raises(pdw.InvalidInputError, match="'stop.t_ned'"):
        sc.replace(stop={"t_ned": 1.0})
    with pytest.raises(pdw.InvalidInputError, match="'colour'"):
        sc.replace(colour="red")


@pytest.mark.parametrize("text, key", [
    ("colour = 1\n", "'colour'"),
    ("[record]\nevry = 1\n", "'record.evry'"),
    ("[integrator]\nmethd = 'cdm'\n", "'integrator.methd'"),
    ("[forces]\nfricton = true\n", "'forces.fricton'"),
    ("[stop]\nt_ned = 1.0\n", "'stop.t_ned'"),
    ("[params]\nk_hipp = 1.0\n", "'params.k_hipp'"),
    ("[solver]\ndt = 1e-4\n", "'solver'"),
    ('[integrator]\ndt = "small"\n', "'integrator.dt'"),
    ("[integrator]\nmethod = 4\n", "'integrator.method'"),
    ("[record]\nevery = 1.5\n", "'record.every'"),
    ("[record]\nevents = 1\n", "'record.events'"),
    ("[stop]\nsteps = true\n", "'stop.steps'"),
    ("[stop]\nperiodic = 'yes'\n", "'stop.periodic'"),
    ("[params]\nk_hip = 'stiff'\n", "'params.k_hip'"),
    ("[params]\nm_h = -2.0\n", "'params.m_h'"),
    ("x0 = [0.0, 0.5]\n", "'x0'"),
    ("flags0 = [0, 2]\n", "'flags0'"),
    ("name = 3\n", "'name'"),
    ("record = 3\n", "'record'"),
    ("params = 3\n", "'params'"),
    ('variant = "rigid"\n', "'variant'"),
    ('preset = "flat"\n', "'preset'"),
    ('[integrator]\nmethod = "euler"\n', "'integrator.method'"),
    ("[integrator]\ndt = -1e-4\n", "'integrator.dt'"),
    ("[stop]\nperiodic_steps = 1\n", "'stop.periodic_steps'"),
    ('[limits]\non_failure = "ignore"\n', "'limits.on_failure'"),
    ("[record]\nevery = 0\nenergies = true\n", "'record.energies'"),
    ("[integrator]\ndt = 10.0\n", "'integrator.dt'"),
])
def test_bad_scene_file_is_an_error_naming_the_key(text, key, tmp_path, capsys):
    with pytest.raises(pdw.InvalidInputError, match=key.replace(".", r"\.")):
        Scene.from_toml(text)
    path = tmp_path / "bad.toml"
    path.write_text(text)
    assert cli.main(["run", str(path)]) == 2
    err = capsys.readouterr().err
    assert key in err and str(path) in err


def test_bad_python_scene_is_an_error_naming_the_key():
    with pytest.raises(pdw.InvalidInputError, match="'record.every'"):
        Scene(record=Record(every=-1))
    with pytest.raises(pdw.InvalidInputError, match="'stop.t_end'"):
        Scene(stop={"t_end": "long"})
    with pytest.raises(pdw.InvalidInputError, match="'forces'"):
        Forces.only("hip", "friction")
    with pytest.raises(pdw.InvalidInputError):
        pdw.run(3)


def test_invalid_toml_is_reported(tmp_path):
    with pytest.raises(pdw.InvalidInputError, match="not valid TOML"):
        Scene.from_toml("[stop\n")
    with pytest.raises(pdw.InvalidInputError, match="cannot read"):
        Scene.load(tmp_path / "missing.toml")


# ------------------------------------------------------------------ the shipped example, CLI

def test_shipped_example_runs_with_pdw_run(tmp_path, capsys):
    example = pdw.examples.scene_path("typical_gait")
    sc = Scene.load(example)
    assert sc == Scene.from_toml(sc.to_toml())
    rc = cli.main(["run", str(example), "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert rc == 0 and "periodic" in out and "L [m]" in out
    meta = json.loads((tmp_path / "run.json").read_text())
    assert meta["status"] == "periodic" and meta["stop_reason"] == "periodic"
    assert Scene.load(tmp_path / "scene.toml") == sc
    rows = (tmp_path / "steps.csv").read_text().strip().splitlines()
    assert rows[0].split(",") == list(FIELDS) and len(rows) == meta["n_gait_steps"] + 1


def test_pdw_run_reports_a_fall_with_code_3(tmp_path, capsys):
    path = Scene(stop={"t_end": 8.0}, record=Record.events_only()).save(tmp_path / "f.toml")
    assert cli.main(["run", str(path)]) == 3
    out = capsys.readouterr().out
    assert "fell" in out and "no steady values: the run fell" in out and "steady (mean" not in out


def test_pdw_walk_still_works(tmp_path, capsys):
    assert cli.main(["walk", "--t-end", "0.5", "--no-figures", "--out", str(tmp_path)]) == 0


def test_docs_list_every_scene_key():
    import dataclasses

    from pdw.sim.scene import SECTION_TYPES
    text = (ROOT / "docs" / "scenes.md").read_text()
    for f in dataclasses.fields(Scene):
        assert "`%s`" % f.name in text or "[%s]" % f.name in text, f.name
    for section, cls in SECTION_TYPES.items():
        for f in dataclasses.fields(cls):
            assert "`%s.%s`" % (section, f.name) in text or "`%s`" % f.name in text, f.name


def test_random_scenes_round_trip():
    from hypothesis import given, settings
    from hypothesis import strategies as st
    finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
    positive = st.floats(min_value=1e-300, max_value=1e300)

    @settings(max_examples=150, deadline=None)
    @given(name=st.text(st.characters(blacklist_categories=("Cs",)), max_size=30),
           x0=st.lists(finite, min_size=8, max_size=8),
           flags=st.lists(st.integers(0, 1), min_size=2, max_size=2),
           k_hip=st.floats(0.0, 10.0), dt=positive, every=st.integers(0, 10**9),
           steps=st.integers(0, 10**6), tol=positive, method=st.sampled_from(METHODS),
           bools=st.lists(st.booleans(), min_size=5, max_size=5),
           h_max=st.none() | positive)
    def check(name, x0, flags, k_hip, dt, every, steps, tol, method, bools, h_max):
        sc = Scene(name=name, x0=x0, flags0=flags, params={"k_hip": k_hip},
                   integrator=Integrator(method=method, dt=dt, h_max=h_max),
                   forces=Forces(*bools), record=Record(every=every),
                   stop=Stop(t_end=max(dt, 1.0), steps=steps, periodic_tol=tol))
        assert Scene.from_toml(sc.to_toml()) == sc

    check()


def test_deeply_nested_toml_is_an_input_error_not_a_recursion_error(tmp_path):
    text = "a = " + "[" * 50000 + "]" * 50000 + "\n"
    with pytest.raises(pdw.InvalidInputError, match="nested"):
        pdw.Scene.from_toml(text)
    with pytest.raises(pdw.InvalidInputError, match="nested"):
        parse_study(text)
    f = tmp_path / "deep.toml"
    f.write_text(text)
    out = subprocess.run([sys.executable, "-m", "pdw", "run", str(f)], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode != 0
    assert "Traceback" not in out.stderr and "RecursionError" not in out.stderr
    assert "nested" in out.stderr + out.stdout
