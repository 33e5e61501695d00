"""One progress mechanism for every long job (sweeps now; cell mapping, basins, continuation
and the figures of ``pdw walk`` are to be wired to it).

`Progress` draws with tqdm, the ecosystem's bar, when tqdm is installed, and with a small
built-in bar otherwise (pdw does not depend on tqdm). Both are quiet when the stream is not a
terminal (a log file, CI, a notebook's captured stderr) and when ``enabled=False``.
"""
from __future__ import annotations

import sys
import time


class Progress:
    """A progress bar over ``total`` units of work, ``done`` of them already done.

    Parameters
    ----------
    total : int
        Units of work.
    done : int
        Units already done (a resumed study).
    label : str
        Text before the bar.
    stream : file, optional
        Default ``sys.stderr``.
    enabled : bool
        False: draw nothing. Otherwise draw only on a terminal.
    """

    def __init__(self, total, done=0, label="pdw", stream=None, enabled=True):
        self.total, self.done, self.label = int(total), int(done), label
        self.stream = sys.stderr if stream is None else stream
        tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.enabled = bool(enabled) and self.total > 0 and tty
        self._bar = None
        self._t0 = time.perf_counter()
        self._last = 0.0
        if self.enabled:
            try:
                from tqdm import tqdm
            except ImportError:
                tqdm = None
            if tqdm is not None:
                self._bar = tqdm(total=self.total, initial=self.done, desc=label,
                                 file=self.stream, dynamic_ncols=True)
        self.update(0)

    def update(self, n=1):
        self.done += n
        if not self.enabled:
            return
        if self._bar is not None:
            self._bar.update(n)
            if self.done >= self.total:
                self._bar.close()
            return
        now = time.perf_counter()
        if now - self._last < 0.1 and self.done < self.total:
            return
        self._last = now
        frac = self.done / self.total
        self.stream.write("\r%s: [%-30s] %d/%d (%3.0f%%) %.1f s" % (
            self.label, "#" * int(30 * frac), self.done, self.total, 100 * frac,
            now - self._t0))
        if self.done >= self.total:
            self.stream.write("\n")
        self.stream.flush()

    def close(self):
        if self._bar is not None:
            self._bar.close()
