"""Files that pdw names after user input, and how it writes them.

* `file_stem`: the one rule for every name that becomes a file name (a study's ``name``, a
  continuation spec's ``name``; ``pdw sweep``, ``pdw continue``, `pdw.sweep.run_study`): a
  plain file name -- no folder, no "..", no absolute path, no hidden file, no empty name --
  so that every file lands inside the output folder the user chose.
* `write_atomic`, `temp_file`: files written whole (a temporary file in the same folder, then
  a rename) with the mode the user's umask gives a new file (0644 under the usual umask 022),
  not `tempfile.mkstemp`'s private 0600.
* `FolderLock`: one process at a time in an output folder (a sweep). Portable: ``fcntl.flock``
  on POSIX, ``msvcrt.locking`` elsewhere, each imported where the lock is taken (``import pdw``
  needs neither). The lock file is removed when the lock is released.
"""
from __future__ import annotations

import os
import pathlib
import re
import tempfile
import threading

from .errors import InvalidInputError, PdwError

#: A plain file name: letters, digits, "_", "-", "+", "." (not first), at most 100 characters.
NAME_RE = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.+-]{0,99}")

_umask_lock = threading.Lock()


def file_stem(name, where="name") -> str:
    """``name`` if it is a plain file name (`NAME_RE`), else `pdw.InvalidInputError`.

    Parameters
    ----------
    name : str
        The user's name for the files (``<out>/<name>.csv``, ...).
    where : str
        What the error message calls it (e.g. ``"study.toml"`` or ``"spec.toml: name"``).
    """
    if not isinstance(name, str) or not NAME_RE.fullmatch(name) or name in (".", ".."):
        raise InvalidInputError("%s: name must be a plain file name (letters, digits, '_', '-', "
                                "'+', '.'; not starting with '.'; at most 100 characters), got %r"
                                % (where, name))
    return name


def file_mode() -> int:
    """The mode of a new file under the process's umask (``0o666 & ~umask``)."""
    try:                                               # Linux: read it without changing it
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return 0o666 & ~int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    with _umask_lock:                                  # elsewhere: set and restore at once
        mask = os.umask(0o022)
        os.umask(mask)
    return 0o666 & ~mask


def temp_file(path, suffix=".tmp"):
    """A new temporary file next to ``path`` (same folder, so a rename replaces ``path``
    atomically), with `file_mode`; returns (fd, temporary path)."""
    path = pathlib.Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix="." + path.name + ".", suffix=suffix)
    try:
        os.chmod(tmp, file_mode())
    except OSError:                                    # pragma: no cover - a file system
        pass                                           # without modes keeps mkstemp's
    return fd, tmp


def write_atomic(path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file in the same folder (fsync, rename):
    readers see the old file or the new one, never a part. The file gets `file_mode`."""
    fd, tmp = temp_file(path)
    try:
        with os.fdopen(fd, "w", newline="") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _try_lock(f) -> bool:
    try:
        import fcntl
    except ImportError:                                # pragma: no cover - Windows
        import msvcrt
        try:
            f.seek(0)
            msvcrt.locking(f.fileno(), msvcrt.LK_NBLCK, 1)  # type: ignore[attr-defined]
        except OSError:
            return False
        return True
    try:
        fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return False
    return True


def _unlock(f) -> None:
    try:
        import fcntl
    except ImportError:                                # pragma: no cover - Windows
        import msvcrt
        f.seek(0)
        msvcrt.locking(f.fileno(), msvcrt.LK_UNLCK, 1)  # type: ignore[attr-defined]
        return
    fcntl.flock(f, fcntl.LOCK_UN)


class FolderLock:
    """An exclusive lock on ``<folder>/<name>``: one process in a folder at a time.

    Entering takes the lock or raises `pdw.PdwError` naming the process that holds it;
    leaving removes the lock file and releases the lock. A lock file removed by its holder
    while another process waited on it is detected (its inode is no longer the path's) and
    the lock is taken on the new file instead, so two processes never both hold a folder.
    """

    def __init__(self, folder, name=".pdw-sweep.lock", what="sweep"):
        self.path = pathlib.Path(folder) / name
        self.what = what
        self.f = None

    def __enter__(self):
        for _ in range(100):
            f = open(self.path, "a+")
            if not _try_lock(f):
                f.seek(0)
                holder = f.read().strip() or "?"
                f.close()
                raise PdwError("%s is in use by another %s (process %s holds %s): wait for it "
                               "to finish, or write to another folder (--out)"
                               % (self.path.parent, self.what, holder, self.path.name))
            try:
                same = os.path.samestat(os.fstat(f.fileno()), os.stat(self.path))
            except OSError:
                same = False
            if same:
                break
            _unlock(f)                                 # the holder removed this file: retry
            f.close()
        else:                                          # pragma: no cover - a lock storm
            raise PdwError("%s: could not take the lock %s" % (self.path.parent, self.path.name))
        f.seek(0)
        f.truncate()
        f.write("%d\n" % os.getpid())
        f.flush()
        self.f = f
        return self

    def __exit__(self, *exc):
        f, self.f = self.f, None
        if f is None:
            return False
        try:
            os.unlink(self.path)                       # while still holding the lock
        except OSError:
            pass                                       # Windows: an open file stays
        try:
            _unlock(f)
        finally:
            f.close()
        return False
