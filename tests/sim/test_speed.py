"""What a run costs where it can be counted without a clock (issue 23): the memory of recording,
and the runaway check's answers on the recorded samples (no copies). Timings are benchmarks
(benchmarks/bench_simulate.py); instruction counts are guarded by tests/test_instructions.py."""
import tracemalloc
import warnings

import numpy as np
import pytest

import pdw
from pdw.core import _core, _layout
from pdw.sim import simulation

#: bytes of one recorded sample: t, x (8), flags (2 int32), the four contact forces
SAMPLE = 8 * (1 + _core.NX + 1 + len(_layout.RECORD_CONTACT))


def _peak(**kw):
    pdw.simulate(**kw)                       # warm: the step check's cache, lazy imports
    tracemalloc.start()
    try:
        r = pdw.simulate(**kw)
        held, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return r, held, peak


@pytest.mark.parametrize("t_end", [0.5, 3.5])
def test_full_recording_takes_the_memory_of_its_samples_and_no_copy(t_end):
    """A fixed-step run allocates its samples once, exactly (no doubling past them, no copy
    of the trajectory to check it): the peak is the samples recorded plus a few kB, so it is
    linear in t_end. (It was 1.6x the samples for 3.5 s: the runaway check stacked a copy.)"""
    r, held, peak = _peak(t_end=t_end, record=pdw.Record(every=1))
    samples = len(r.t) * SAMPLE
    assert r.status == "walked" and len(r.t) == round(t_end / 1e-4) + 1
    assert samples <= held and peak <= 1.02 * samples + 64e3, (samples, held, peak)


def test_an_adaptive_run_keeps_the_memory_of_its_samples_only():
    """An adaptive run's records grow geometrically and are trimmed once: what the result
    holds is its samples (RECORD_CHUNK = 65,536 would be 7 MB; rodas4 takes ~1,900 steps)."""
    r, held, _ = _peak(method="rodas4", params=pdw.Params.paper_steady(), record=pdw.Record(every=1))
    samples = len(r.t) * SAMPLE
    assert len(r.t) < _core.RECORD_CHUNK // 8
    assert held <= 1.05 * samples + 64e3, (samples, held)


def test_a_run_that_outgrows_its_records_keeps_every_sample():
    """max_records = 5 forces the doubling path: the samples are those of a run that never
    grew, bit for bit, and the result holds no more rows than it recorded."""
    k = 0
    p = pdw.core.model.parameter_vector(pdw.Params.paper())
    x0 = np.array(pdw.X0_PAPER)
    args = (k, 0, x0, p, 0, 1, dict(dt=1e-4, n_steps=300, record_every=1, record_events=1,
                                    fall_hip_height=0.4, fall_depth=0.2, max_speed=1e3))
    a = _core.run(*args, max_records=5)
    b = _core.run(*args)
    for name in ("t", "x", "flags", "contact"):
        assert np.array_equal(a[name], b[name]), name
        assert a[name].base is None or a[name].base.size <= a[name].size * 16


def test_runaway_is_found_on_the_samples_and_the_final_state():
    """first_runaway scans the rows in C; the failure is the sample before the first runaway
    one, or the last sample when only the final state ran away."""
    x = np.zeros((5, _core.NX))
    assert _core.first_runaway(x, 1.0, 6.0) == -1
    x[3, 2] = -7.0
    assert _core.first_runaway(x, 1.0, 6.0) == 3
    x[1, 1] = 2.0
    assert _core.first_runaway(x, 1.0, 6.0) == 1
    x[:] = np.nan                                     # NaN exceeds nothing (the C loop's job)
    assert _core.first_runaway(x, 1.0, 6.0) == -1
    raw = {"x": np.zeros((4, _core.NX)), "t": np.arange(4.0), "x_final": np.zeros(_core.NX),
           "t_final": 4.0, "event_counts": {"touch_down": 1}}
    raw["x_final"][3] = 7.0
    p = pdw.Params.paper()
    assert simulation._honest(raw, "done", p, np.zeros(_core.NX), None) == "diverged"
    assert raw["failure"]["t"] == 3.0 and "leg turned" in raw["failure"]["reason"]
    raw["x"][2, 1] = 5.0
    assert simulation._honest(raw, "done", p, np.zeros(_core.NX), None) == "diverged"
    assert raw["failure"]["t"] == 1.0 and "hip rose" in raw["failure"]["reason"]


def test_the_presets_shipped_step_limits_are_the_computed_ones():
    """The first fixed-step simulate of a process looks its presets' limits up instead of
    computing them for ~7 ms (issue 23); the table must be what the computation gives, bit
    for bit (a change of the model or the calibration fails here: print
    `stepsize._preset_table()` into `PRESET_DT_MAX`)."""
    from pdw.sim import stepsize
    assert stepsize._preset_table() == stepsize.PRESET_DT_MAX
    for (preset, variant), limits in stepsize.PRESET_DT_MAX.items():
        for method, dt_max in limits.items():
            params = getattr(pdw.Params, preset)()
            assert stepsize._dt_max(params, method, variant) == dt_max
            assert stepsize.step_limit(params, method, variant).dt_max == dt_max


def test_a_preset_warns_above_its_shipped_limit_and_not_below():
    from pdw.sim import stepsize
    dt_max = stepsize.PRESET_DT_MAX["paper", "paper"]["cdm"]
    with pytest.warns(pdw.StepSizeWarning, match="exceeds the estimated"):
        pdw.simulate(t_end=0.01, dt=dt_max * 1.001, limits=pdw.Limits(on_failure="return"),
                     record=pdw.Record(every=0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pdw.simulate(t_end=0.01, dt=dt_max / 1.001, limits=pdw.Limits(on_failure="return"),
                     record=pdw.Record(every=0))


def test_the_caches_of_the_python_set_up_hand_out_nothing_shared_that_can_change():
    """Python around a run (issue 23): the default Params and Contact are shared (immutable),
    the parameter vector is cached per Params but every caller gets its own writeable copy,
    the kernel index is cached but unhashable features still work, checks keep refusing."""
    from pdw.core import checks, model
    assert pdw.Params.paper() is pdw.Params.paper() and pdw.Params.paper() == pdw.Params()
    assert pdw.Params.paper(d_hip=0.01) == pdw.Params.paper_steady()
    with pytest.raises(AttributeError):
        pdw.Params.paper().l = 1.0
    p1 = model.parameter_vector(pdw.Params.paper())
    p1[:] = -1.0
    p2 = model.parameter_vector(pdw.Params.paper())
    assert p2.flags.writeable and not np.array_equal(p1, p2)
    feats = [f for f in _layout.FEATURES if f != "tangential"]
    assert model.kernel_index("paper", feats) == model.kernel_index("paper", tuple(feats))
    assert model.kernel_index("paper", feats) != model.kernel_index("paper")
    for bad in (True, np.bool_(True), "1", 1j, None):
        with pytest.raises(pdw.InvalidInputError):
            checks.number("dt", bad)
    for bad in ((0, 2), (0.0, 1), (0, 1, 0), "01"):
        with pytest.raises(pdw.InvalidInputError):
            checks.flags("flags0", bad)
    assert checks.count("n", 3) == 3 and checks.number("x", 2) == 2.0
    with pytest.raises(pdw.InvalidInputError, match="out of range"):
        checks.count("n", -1)
