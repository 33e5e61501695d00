"""One progress mechanism for every long job: sweeps, cell mapping, basins, continuation and
the figures of ``pdw walk``.

`Progress` draws with tqdm, the ecosystem's bar, when tqdm is installed, and with a small
built-in bar otherwise (pdw does not depend on tqdm). Both are quiet when the stream is not a
terminal (a log file, CI, a notebook's captured stderr) and when ``enabled=False``.

Library functions take ``progress=False|True|Progress`` and turn it into a bar with
`progress_bar`: ``False`` (the library's default) draws nothing, ``True`` draws on stderr when
it is a terminal (the CLI's default), a `Progress` of the caller's (its own stream or label,
or one bar shared by several jobs) gets the job's units added to its total.
"""
from __future__ import annotations

import sys
import time
from typing import Any

from .errors import InvalidInputError


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

    def __init__(self, total: int = 0, done: int = 0, label: str = "pdw", stream=None,
                 enabled: bool = True):
        self.total, self.done, self.label = int(total), int(done), label
        self.stream = sys.stderr if stream is None else stream
        tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self._wanted = bool(enabled) and tty
        self._bar: Any = None            # the tqdm bar while one is drawn
        self._tqdm: Any = None           # tqdm's class, when installed and drawing
        self._finished = False
        self._t0 = time.perf_counter()
        self._last = 0.0
        if self._wanted:
            try:
                from tqdm import tqdm
            except ImportError:
                tqdm = None
            self._tqdm = tqdm
        self.update(0)

    @property
    def enabled(self) -> bool:
        """Whether the bar draws (asked for, on a terminal, and with work to count)."""
        return self._wanted and self.total > 0

    def add(self, total: int, label: str | None = None) -> Progress:
        """Add ``total`` units of work (a job joining the bar); returns the bar."""
        self.total += int(total)
        if label is not None and self.done == 0:
            self.label = label
        if self._bar is not None:
            self._bar.total = self.total
            self._bar.refresh()
        return self

    def update(self, n: int = 1) -> None:
        """Count ``n`` more units done (and draw, at most every 0.1 s without tqdm)."""
        self.done += n
        if not self.enabled:
            return
        if self._tqdm is not None:
            if self._bar is None:
                if n == 0 and self.done >= self.total and self._finished:
                    return
                self._bar = self._tqdm(total=self.total, initial=self.done, desc=self.label,
                                       file=self.stream, dynamic_ncols=True)
            else:
                self._bar.update(n)
            if self.done >= self.total:     # done: a later job added to the bar starts a new one
                self._bar.close()
                self._bar, self._finished = None, True
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

    def track(self, items):
        """Yield from ``items``, counting one unit as each is done with (when the next is
        asked for): ``[f(z) for z in bar.track(Z)]``, ``list(bar.track(pool.map(f, Z)))``."""
        for item in items:
            yield item
            self.update()

    def close(self) -> None:
        """End the bar (a job that stops before its total: a branch that ends early)."""
        if self._bar is not None:
            self._bar.close()
        elif self.enabled and 0 < self.done < self.total and self._tqdm is None:
            self.stream.write("\n")
            self.stream.flush()


def progress_bar(progress, total: int, label: str, done: int = 0) -> Progress:
    """The bar of a job of ``total`` units from a ``progress=`` argument.

    Parameters
    ----------
    progress : bool or Progress
        False (or None): no bar. True: a bar on stderr, drawn only when stderr is a terminal.
        A `Progress`: that bar, with ``total`` added to its total (several jobs, one bar).
    total : int
        Units of work of the job (grid points, cells, continuation points, figures).
    label : str
        Text before the bar.
    done : int
        Units of the job already done (a resumed study).

    Returns
    -------
    Progress
    """
    if isinstance(progress, Progress):
        bar = progress.add(total, label)
        bar.update(int(done))
        return bar
    if progress is None or progress is False or progress is True:
        return Progress(total, done, label=label, enabled=bool(progress))
    raise InvalidInputError("progress must be False, True or a pdw.Progress, got %r"
                            % (progress,))
