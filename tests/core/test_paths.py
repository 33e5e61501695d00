"""pdw.core.paths: the one rule for names that become file names, files written with the
umask's mode, and the portable one-process-per-folder lock (issue 26 items 2, 12, 16)."""
import os
import stat

import pytest

import pdw
from pdw.core import paths


@pytest.mark.parametrize("name", ["../..", "../x", "/tmp/x", "a/b", "a\\b", "", ".", "..",
                                  ".hidden", "x" * 101, "a\x00b", "a b", None, 3, b"x"])
def test_a_name_that_is_not_a_plain_file_name_is_refused(name):
    with pytest.raises(pdw.InvalidInputError, match="spec.toml: name must be a plain file name"):
        paths.file_stem(name, "spec.toml")


@pytest.mark.parametrize("name", ["fig11_k_n", "a.b", "x" * 100, "run-2+3", "_x", "0"])
def test_plain_file_names_pass(name):
    assert paths.file_stem(name) == name


def test_sweep_and_continue_share_the_rule():
    from pdw.present import continue_spec
    from pdw.studies import study
    assert study.NAME_RE is paths.NAME_RE
    spec = {"name": "../x", "parameter": "gamma", "stop": 0.1}
    with pytest.raises(pdw.InvalidInputError, match="plain file name"):
        continue_spec.check_spec(spec, "s.toml")
    with pytest.raises(pdw.InvalidInputError, match="plain file name"):
        study.check_name("../x")


@pytest.mark.parametrize("umask", [0o022, 0o077, 0o002])
def test_write_atomic_gives_the_umask_mode(tmp_path, umask):
    old = os.umask(umask)
    try:
        paths.write_atomic(tmp_path / "f.txt", "hello\n")
        fd, tmp = paths.temp_file(tmp_path / "g.npz")
        os.close(fd)
        mode = paths.file_mode()
    finally:
        os.umask(old)
    assert mode == 0o666 & ~umask
    assert (tmp_path / "f.txt").read_text() == "hello\n"
    assert stat.S_IMODE((tmp_path / "f.txt").stat().st_mode) == 0o666 & ~umask
    assert stat.S_IMODE(os.stat(tmp).st_mode) == 0o666 & ~umask


def test_the_folder_lock_excludes_a_second_holder_and_removes_its_file(tmp_path):
    with paths.FolderLock(tmp_path, ".l.lock", "sweep"):
        assert (tmp_path / ".l.lock").read_text() == "%d\n" % os.getpid()
        with pytest.raises(pdw.PdwError, match="in use by another sweep .process %d"
                           % os.getpid()):
            with paths.FolderLock(tmp_path, ".l.lock", "sweep"):
                pass
    assert list(tmp_path.iterdir()) == []
    with paths.FolderLock(tmp_path, ".l.lock"):          # free again
        pass


def test_a_waiter_on_a_removed_lock_file_takes_the_new_one(tmp_path, monkeypatch):
    """The holder unlinks the lock file while still holding it; a process that opened the old
    file before must not count a lock on it (the unlinked inode) as the folder's lock."""
    lock = paths.FolderLock(tmp_path, ".l.lock")
    real_open = open
    opened = []

    def open_then_remove(path, *a, **k):
        f = real_open(path, *a, **k)
        if not opened:                    # the first open: the holder removes that file now
            opened.append(path)
            os.unlink(path)
        return f

    monkeypatch.setattr("builtins.open", open_then_remove)
    with lock:
        monkeypatch.setattr("builtins.open", real_open)
        inode = os.fstat(lock.f.fileno()).st_ino
        assert (tmp_path / ".l.lock").exists()
        assert os.stat(tmp_path / ".l.lock").st_ino == inode      # the file at the path
    assert len(opened) == 1
