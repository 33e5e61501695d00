"""The option objects of a run (pdw/sim/options.py): validation, one name per option, the
Scene holding the same objects, outcomes, and simulate_batch's progress and repr."""
import dataclasses
import io

import numpy as np
import pytest

import pdw
from pdw.sim.options import Integrator, Limits, Outcome, Record, Stop

X2 = np.array([pdw.X0_PAPER, pdw.X0_PAPER])


# --- validation: the field and its allowed range ------------------------------------------------

@pytest.mark.parametrize("make, key, text", [
    (lambda: Record(every=-1), "record.every", "[0,"),
    (lambda: Record(every=1.5), "record.every", "an integer"),
    (lambda: Record(forces=1), "record.forces", "true or false"),
    (lambda: Record(every=2, dense_output=True), "record.every", "must be 1"),
    (lambda: Record(every=0, energies=True), "record.energies", "every > 0"),
    (lambda: Record(t_eval=[0.1, float("nan")]), "record.t_eval", "finite"),
    (lambda: Integrator(method="euler"), "integrator.method", "'rodas4'"),
    (lambda: Integrator(rtol=0.0), "integrator.rtol", "> 0"),
    (lambda: Integrator(max_steps=0), "integrator.max_steps", "[1,"),
    (lambda: Integrator(check_step="loud"), "integrator.check_step", "'warn'"),
    (lambda: Stop(periodic_steps=1), "stop.periodic_steps", "[2, 32]"),
    (lambda: Stop(touch_down=3), "stop.touch_down", "0, 1, 2"),
    (lambda: Stop(t_end=-1.0), "stop.t_end", "> 0"),
    (lambda: Limits(on_failure="ignore"), "limits.on_failure", "'return'"),
    (lambda: Limits(max_speed=float("inf")), "limits.max_speed", "finite"),
])
def test_a_bad_option_names_its_field_and_range(make, key, text):
    with pytest.raises(pdw.InvalidInputError) as e:
        make()
    assert repr(key) in str(e.value) and text in str(e.value)


def test_stop_of_before_points_to_limits():
    with pytest.raises(pdw.InvalidInputError, match=r"pdw\.Limits\(max_speed=\.\.\.\)"):
        Stop(max_speed=10.0)


def test_numpy_numbers_are_numbers_and_objects_are_frozen():
    r = Record(every=np.int64(3), forces=np.bool_(False))
    assert r.every == 3 and type(r.every) is int and r.forces is False
    assert Integrator(rtol=np.float32(1e-5)).rtol == pytest.approx(1e-5)
    with pytest.raises(AttributeError):
        r.every = 2                                   # type: ignore[misc]
    assert r.replace(every=5).every == 5 and r.every == 3


# --- one name per option ------------------------------------------------------------------------

def test_a_value_given_twice_must_agree():
    with pytest.raises(pdw.InvalidInputError, match="give it once"):
        pdw.simulate(dt=1e-4, integrator=Integrator(dt=2e-4), t_end=0.01)
    with pytest.raises(pdw.InvalidInputError, match="give it once"):
        pdw.simulate(t_end=0.01, stop=Stop(t_end=0.02))
    with pytest.raises(pdw.InvalidInputError, match="give it once"):
        pdw.simulate(t_end=0.01, method="rk4", integrator=Integrator(method="cdm"))
    with pytest.warns(DeprecationWarning, match=r"simulate\(record_every=\.\.\.\) is deprecated"):
        with pytest.raises(pdw.InvalidInputError, match="record_every"):
            pdw.simulate(t_end=0.01, record=Record(), record_every=2)
    # given once, either way, the same run
    a = pdw.simulate(pdw.X0_PAPER, 0.05, 2e-4, method="rk4")
    b = pdw.simulate(integrator=Integrator(method="rk4", dt=2e-4), stop=Stop(t_end=0.05))
    assert np.array_equal(a.x, b.x) and a.integrator == b.integrator and a.stop == b.stop


def test_unknown_keyword_is_an_error_naming_it():
    with pytest.raises(pdw.InvalidInputError, match="'record_evry'"):
        pdw.simulate(t_end=0.01, record_evry=2)


def test_an_old_keyword_with_a_bad_value_names_the_keyword_written():
    with pytest.warns(DeprecationWarning, match=r"simulate\(stop_steps=\.\.\.\) is deprecated"):
        with pytest.raises(pdw.InvalidInputError, match=r"'stop_steps' \(now 'stop.steps'\)"):
            pdw.simulate(t_end=0.01, stop_steps=-1)


def test_dicts_are_read_as_tables():
    r = pdw.simulate(t_end=0.02, record={"every": 0}, limits={"on_failure": "return"})
    assert len(r.t) == 0 and r.record == Record(every=0) and r.limits.on_failure == "return"
    with pytest.raises(pdw.InvalidInputError, match="must be a pdw.Record"):
        pdw.simulate(t_end=0.02, record=3)


def test_ground_slot_refuses_what_this_build_cannot_run():
    with pytest.raises(pdw.InvalidInputError, match="ground"):
        pdw.simulate(t_end=0.01, ground="bumpy")


# --- the Scene holds the same objects -------------------------------------------------------------

def _full_scene():
    return pdw.Scene(
        preset="paper_steady",
        integrator=Integrator(method="rodas4", dt=1e-4, rtol=1e-7, max_steps=10 ** 6,
                              check_step="off"),
        record=Record(every=1, forces=False, t_eval=(0.1, 0.2, 0.3), dense_output=True),
        stop=Stop(t_end=1.5, touch_down=1), limits=Limits(max_speed=500.0, on_failure="return"),
        approach_speeds0=(0.0, 0.1))


def test_scene_expresses_every_simulate_option_and_round_trips():
    sc = _full_scene()
    back = pdw.Scene.from_toml(sc.to_toml())
    assert back == sc
    for key in ("t_eval", "dense_output", "max_steps", "check_step", "touch_down",
                "approach_speeds0", "[limits]"):
        assert key in sc.to_toml(), key
    r_scene = pdw.run(back)
    r = pdw.simulate(sc.x0, params=pdw.Params.paper_steady(), integrator=sc.integrator,
                     record=sc.record, stop=sc.stop, limits=sc.limits,
                     approach_speeds0=(0.0, 0.1))
    assert np.array_equal(r_scene.t, r.t) and np.array_equal(r_scene.x, r.x)
    assert r.stop_reason == "touch_down" and r.sol is not None and len(r.t) <= 3


def test_scene_file_of_before_reads_its_stop_limits_into_limits():
    text = '[stop]\nt_end = 2.0\nmax_speed = 50.0\non_failure = "return"\n'
    with pytest.warns(DeprecationWarning, match=r"moved to \[limits\]"):
        sc = pdw.Scene.from_toml(text)
    assert sc.limits == Limits(max_speed=50.0, on_failure="return") and sc.stop.t_end == 2.0
    with pytest.warns(DeprecationWarning):
        assert sc.replace(stop={"fall_depth": 0.1}).limits.fall_depth == 0.1
    with pytest.warns(DeprecationWarning), pytest.raises(pdw.InvalidInputError, match="only"):
        pdw.Scene.from_toml(text + "[limits]\nmax_speed = 40.0\n")


def test_scene_always_says_its_method_dt_and_t_end():
    sc = pdw.Scene(integrator={"rtol": 1e-7})
    assert (sc.integrator.method, sc.integrator.dt, sc.stop.t_end) == ("cdm", 1e-4, 3.5)


# --- the outcome ------------------------------------------------------------------------------------

@pytest.mark.parametrize("opts, outcome", [
    (dict(t_end=0.2), Outcome.T_END),
    (dict(t_end=3.0, stop=Stop(steps=2)), Outcome.STEPS),
    (dict(t_end=3.0, stop=Stop(touch_down=1)), Outcome.TOUCH_DOWN),
    (dict(t_end=20.0, params=pdw.Params.paper_steady(), record=Record.descriptors_only(),
          stop=Stop(periodic=True)), Outcome.PERIODIC),
    (dict(t_end=2.0, x0=np.array(pdw.X0_PAPER) * [1, 1, 1, 1, 1, 1, 0, 0]), Outcome.FELL),
])
def test_status_and_stop_reason_derive_from_one_outcome(opts, outcome):
    r = pdw.simulate(**opts)
    assert r.outcome is outcome
    assert (r.status, r.stop_reason) == (outcome.status, outcome.stop_reason)


def test_outcome_readings():
    assert {o.status for o in Outcome} == {"walked", "periodic", "fell", "diverged", "no_steps",
                                           "interrupted"}
    for o in Outcome:
        assert Outcome.of(o.status, o.stop_reason) is o


# --- simulate_batch: keyword-only, progress, repr (issue 26 items 8, 13) -------------------------

def test_batch_progress_counts_every_walker_and_changes_no_bit():
    x = np.repeat(X2, 12, axis=0)
    plain = pdw.simulate_batch(x, 0.3, threads=1)
    bar = pdw.Progress(stream=io.StringIO())
    with_bar = pdw.simulate_batch(x, 0.3, threads=1, progress=bar, lanes=2)
    assert bar.done == len(x) and bar.total == len(x)
    assert np.array_equal(plain.x_final, with_bar.x_final)
    assert list(plain.status) == list(with_bar.status)
    with pytest.raises(pdw.InvalidInputError, match="progress"):
        pdw.simulate_batch(x, 0.3, progress="yes")


def test_batch_repr_is_a_few_lines():
    b = pdw.simulate_batch(np.repeat(X2, 50, axis=0), 0.2, threads=1, record=[3])
    text = repr(b)
    lines = text.splitlines()
    assert 3 <= len(lines) <= 6 and max(map(len, lines)) <= 160, text
    assert "100 walkers" in text and "100 walked" in text and "x_final 100x8" in text
    assert "recorded: walkers 3" in text and "[" not in text


def test_batch_takes_the_same_objects_as_simulate():
    it, st = Integrator(method="rodas4", rtol=1e-7), Stop(steps=1)
    b = pdw.simulate_batch(X2, 2.0, integrator=it, stop=st, limits=Limits(max_speed=800.0))
    r = pdw.simulate(X2[0], 2.0, integrator=it, stop=st, limits=Limits(max_speed=800.0),
                     record=Record.events_only())
    assert b.stop_reason[0] == r.stop_reason == "steps"
    assert np.array_equal(b.x_final[0], r.x_final)
    m = pdw.simulate_many(X2, 2.0, integrator=it, stop=st)
    assert np.array_equal(m.x_final, b.x_final)


# --- the options reach the compiled loops by their C names (more: tests/test_run_opts.py) ---------

def test_c_options_names_the_fields_of_pdw_run_opts():
    """c_options: each option with a C name (`_f(..., c=NAME)`) under that name, then what the
    run derives; every name is a field of pdw_run_opts."""
    from pdw.core import _core
    from pdw.sim.options import c_options
    objs = (Integrator(h_max=1.0, max_steps=5), Record(), Stop(), Limits())
    names = c_options(*objs)
    named = {f.metadata["c"] for o in objs for f in dataclasses.fields(o) if f.metadata["c"]}
    assert set(names) == named >= {"rtol", "atol", "event_tol", "record_every",
                                   "record_events", "stop_steps", "periodic_tol",
                                   "stop_touch_down", "max_speed"}
    assert set(names) <= set(_core.OPT_FIELDS)
    assert c_options(Stop(touch_down=1)) == {"stop_steps": 0, "periodic_tol": 1e-3,
                                             "stop_touch_down": 1}
    assert c_options(Stop(touch_down=1), dt=1e-4, stop_touch_down=2)["stop_touch_down"] == 2


@pytest.mark.parametrize("fn", [pdw.simulate_batch, pdw.simulate_many])
def test_ensembles_refuse_recording_keywords_instead_of_ignoring_them(fn):
    name = fn.__name__
    with pytest.warns(DeprecationWarning, match=r"%s\(record_forces=\.\.\.\) is deprecated" % name):
        with pytest.raises(pdw.InvalidInputError, match="records no samples"):
            fn(X2, 0.1, record_forces=False)
