"""pyoa.atomic.atomic_path: a failed write never replaces a good file."""

from __future__ import annotations

import os
import stat

import pytest

from pyoa.atomic import atomic_path


def test_success_replaces_and_cleans_up(tmp_path):
    target = tmp_path / "out.npy"
    target.write_text("old")
    with atomic_path(target) as tmp:
        assert tmp != target and tmp.parent == target.parent and tmp.suffix == ".npy"
        tmp.write_text("new")
        assert target.read_text() == "old"  # not visible before the end
    assert target.read_text() == "new"
    assert os.listdir(tmp_path) == ["out.npy"]


def test_failure_keeps_old_file_and_removes_temp(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("old")
    with pytest.raises(ZeroDivisionError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            1 / 0
    assert target.read_text() == "old"
    assert os.listdir(tmp_path) == ["out.csv"]


def test_failure_before_writing_anything(tmp_path):
    target = tmp_path / "new.npy"
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.unlink()  # the writer removed it already
            raise RuntimeError
    assert os.listdir(tmp_path) == []


def test_missing_directory(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        with atomic_path(tmp_path / "no" / "x.npy"):
            pass


def test_new_file_gets_normal_permissions(tmp_path):
    """A file written through atomic_path is as readable as one written directly
    (mode 0o666 minus the umask), not the 0o600 of a mkstemp temporary file."""
    umask = os.umask(0o022)
    os.umask(umask)
    direct = tmp_path / "direct.npy"
    direct.write_bytes(b"x")
    target = tmp_path / "atomic.npy"
    with atomic_path(target) as tmp:
        tmp.write_bytes(b"x")
    want = stat.S_IMODE(direct.stat().st_mode)
    assert want == 0o666 & ~umask
    assert oct(stat.S_IMODE(target.stat().st_mode)) == oct(want)
