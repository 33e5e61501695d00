"""Record arrays that outlive one run: ``simulate(..., out=RecordBuffer())``.

A run records t (N,), x (N, nx), flags (N, 2) and the contact forces (N, 4) at every step
(nx = 8, or 10 with LuGre's bristle states: `pdw.core._layout.STATE_LAYOUTS`): for the default
3.5 s at dt = 1e-4, about 3.9 MB. Fresh arrays are fresh pages, faulted in (and zeroed by the
kernel) as the loop first writes them, on every run (benchmarks/bench_io.py measures the cost).
A `RecordBuffer` passed as ``out=`` is allocated once and reused, by runs of any friction law:
the Result's t, x, flags, Fn, Ft are then *views* into it, valid until the next run with the
same buffer (copy what you keep).
"""
from __future__ import annotations

import numpy as np

from ..core import _core, _layout, checks
from ..core.errors import InvalidInputError


class RecordBuffer:
    """Reusable record arrays for `pdw.simulate` (``out=``); grows when a run needs more rows.

    The states are kept in one block of ``capacity * NX_MAX`` floats (``pdw.core._core.NX_MAX``,
    the widest state layout); ``x`` is a C-contiguous view of its first ``capacity * nx``
    entries, shape (capacity, nx), with the width of the last run's friction law (8 before the
    first run). A run of another width views the same block anew: nothing is allocated, and the
    pages a narrower run never touches are never faulted in.

    Parameters
    ----------
    capacity : int
        Rows to allocate now (0: on the first run).
    """

    def __init__(self, capacity: int = 0):
        self._alloc(checks.count("capacity", capacity))

    def _alloc(self, n):
        try:
            self._make(n)
        except MemoryError:
            raise InvalidInputError("RecordBuffer capacity = %d rows needs %.3g GB; allowed: what "
                                    "fits in memory" % (n, n * 8 * (1 + _core.NX_MAX + 2 + 4) / 1e9)
                                    ) from None

    def _make(self, n):
        self.t = np.zeros(n)
        self._states = np.zeros(n * _core.NX_MAX)        # x: a view at the run's width
        self.x = self._states[:n * _core.NX].reshape(n, _core.NX)
        self.flags = np.zeros((n, 2), dtype=np.intc)
        self.contact = np.zeros((n, len(_layout.RECORD_CONTACT)))

    @property
    def capacity(self) -> int:
        """Rows allocated now."""
        return len(self.t)

    def arrays(self, rows: int, nx: int = _core.NX):
        """(t (n,), x (n, nx), flags (n, 2), contact (n, 4)) with n >= ``rows`` (reallocated if
        smaller); ``nx`` is the run's state width (`pdw.Contact.nx`). An ``x`` of another width
        that is this buffer's own view is re-viewed at width nx; arrays put in place of the
        buffer's own must have the shapes above."""
        if rows > self.capacity:
            self._alloc(rows)
        n = self.capacity
        x, states = self.x, self._states
        if (isinstance(x, np.ndarray) and x.ndim == 2 and x.shape != (n, nx)
                and x.base is states and states is not None and n * nx <= states.size):
            self.x = states[:n * nx].reshape(n, nx)     # the same memory, another width
        for name, a, shape, dtype in (("t", self.t, (n,), np.float64),
                                      ("x", self.x, (n, nx), np.float64),
                                      ("flags", self.flags, (n, 2), np.intc),
                                      ("contact", self.contact, (n, len(_layout.RECORD_CONTACT)),
                                       np.float64)):
            if not (isinstance(a, np.ndarray) and a.shape == shape and a.dtype == dtype
                    and a.flags.c_contiguous and a.flags.writeable):
                raise InvalidInputError(
                    "out.%s must be a writeable C-contiguous %s array of shape %s (out.t's "
                    "length), got %s" % (name, np.dtype(dtype).name, shape,
                                         getattr(a, "shape", type(a).__name__)))
        return self.t, self.x, self.flags, self.contact
