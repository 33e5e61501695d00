"""Ctrl-C for every long loop, in the main thread and in worker threads.

The compiled loops release the GIL and return to Python (or call back into it) every few
milliseconds to *poll* (docs/stability.md section 11): in the main thread the poll runs Python's
signal handlers, so Ctrl-C raises `KeyboardInterrupt` there within a second. Signals reach
only the main thread, so a loop in a worker thread polls a *cancel token* instead: `thread_map`
gives each of its tasks one, and sets it when the main thread is interrupted (or any task
fails); every loop of those tasks then stops at its next poll with `KeyboardInterrupt`, the
pending tasks are cancelled, and the main thread re-raises once the workers have stopped.
"""
from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor

_local = threading.local()


class Token:
    """A cancel flag, set when the pool that owns it is interrupted; a token made inside a
    task of another pool is cancelled with its parent."""

    def __init__(self, parent: "Token | None" = None):
        self._event = threading.Event()
        self.parent = parent

    def set(self):
        self._event.set()

    def is_set(self) -> bool:
        t: Token | None = self
        while t is not None:
            if t._event.is_set():
                return True
            t = t.parent
        return False


def current() -> Token | None:
    """The cancel token of the calling thread (None outside `thread_map` tasks)."""
    return getattr(_local, "token", None)


def cancelled() -> bool:
    """Has the calling thread's task been cancelled (its pool interrupted)?"""
    t = current()
    return t is not None and t.is_set()


def check():
    """Raise KeyboardInterrupt if the calling thread's task was cancelled."""
    if cancelled():
        raise KeyboardInterrupt("cancelled: the pool of this task was interrupted")


def call_with_token(token: Token, fn, *args):
    """``fn(*args)`` in the calling thread with ``token`` as its cancel token: for tasks that a
    thread pool of someone else's runs (`pdw.sweep.run_study`'s executor); setting the token
    stops the compiled loops of ``fn`` at their next poll."""
    before = current()
    _local.token = token
    try:
        return fn(*args)
    finally:
        _local.token = before


def thread_map(fn, items, workers: int, bar=None) -> list:
    """``[fn(x) for x in items]`` on ``workers`` threads, in order, stoppable by Ctrl-C.

    On KeyboardInterrupt in the calling thread (or an exception of a task) the pending tasks
    are cancelled, the running ones stop at their next poll, and the exception is re-raised
    once they have. With ``workers <= 1`` the tasks run in the calling thread. ``bar`` (a
    `pdw.Progress`, optional) advances by one as each task finishes.
    """
    items = list(items)
    lock = threading.Lock()

    def counted(x):
        out = fn(x)
        if bar is not None:
            with lock:
                bar.update()
        return out

    if workers <= 1 or len(items) <= 1:
        return [counted(x) for x in items]
    token = Token(current())

    def task(x):
        _local.token = token
        try:
            return counted(x)
        finally:
            _local.token = None

    ex = ThreadPoolExecutor(min(workers, len(items)))
    futures = []
    try:
        futures = [ex.submit(task, x) for x in items]
        return [f.result() for f in futures]
    except BaseException:
        token.set()
        for f in futures:
            f.cancel()
        raise
    finally:
        ex.shutdown(wait=True, cancel_futures=True)
