"""Issue 26, item 7: `simulate_batch(record=...)` takes walker indices, nothing coerced.

``record=[1.5]`` used to record walker 1 (``int(1.5)``), ``record="12"`` walkers 1 and 2, and
a bad index was found only after the whole batch had run. Each entry must now be an integer
in [0, N) (`pdw.core.checks.count`), checked before the run, naming the entry.
"""

import numpy as np
import pytest

import pdw
from pdw.sim.batch import simulate_batch

X = np.tile(np.array(pdw.X0_PAPER), (3, 1))


@pytest.mark.parametrize("record,field", [
    ([1.5], r"record\[0\]"), ([0, 2.7], r"record\[1\]"), ([True], r"record\[0\]"),
    (["1"], r"record\[0\]"), ("12", "record"), (1, "record"), ([3], r"record\[0\]"),
    ([-1], r"record\[0\]"), (np.array([[0, 1]]), "record"), ({0: 1}, "record"),
])
def test_record_takes_integer_indices_only(record, field):
    with pytest.raises(pdw.InvalidInputError, match=field):
        pdw.simulate_batch(X, t_end=0.002, record=record)


def test_record_is_checked_before_the_run(monkeypatch):
    """The bad index is found before a single lane runs (not after the batch)."""
    from pdw.core import _batch
    ran = []
    monkeypatch.setattr(_batch, "run_range", lambda *a, **k: ran.append(1))
    with pytest.raises(pdw.InvalidInputError):
        pdw.simulate_batch(X, t_end=0.002, record=[5])
    assert not ran


def test_integral_indices_still_record():
    b = pdw.simulate_batch(X, t_end=0.002, record=[2, np.int64(0), 2.0])
    assert sorted(b.recorded) == [0, 2]
    r = pdw.simulate(X[2], t_end=0.002)
    assert np.array_equal(b.recorded[2].x, r.x)


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
    if "fall_hip_height" in kw:         # the [limits] table, read and checked by simulate_batch
        kw["limits"] = {"fall_hip_height": kw.pop("fall_hip_height")}
    with pytest.raises(pdw.InvalidInputError, match=field.replace("(", r"\(")):
        simulate_batch(x0, **kw)


def test_simulate_batch_still_takes_well_formed_input():
    b = simulate_batch(X2.tolist(), t_end=0.01, flags0=np.array([[0, 1], [0, 1]]),
                       vector=np.bool_(False), limits=pdw.Limits(fall_hip_height=0.3))
    r = pdw.simulate(t_end=0.01, record=pdw.Record(every=0), limits=pdw.Limits(fall_hip_height=0.3))
    assert np.array_equal(b.x_final[0], r.x_final) and list(b.status) == ["walked"] * 2
