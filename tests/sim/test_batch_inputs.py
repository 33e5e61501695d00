"""Issue 26, item 7: `simulate_batch(record=...)` takes walker indices, nothing coerced.

``record=[1.5]`` used to record walker 1 (``int(1.5)``), ``record="12"`` walkers 1 and 2, and
a bad index was found only after the whole batch had run. Each entry must now be an integer
in [0, N) (`pdw.core.checks.count`), checked before the run, naming the entry.
"""
import numpy as np
import pytest

import pdw

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
