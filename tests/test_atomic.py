"""pyoa.util.atomic.atomic_path: a failed write never replaces a good file."""

from __future__ import annotations

import os
import stat

import pytest

from pyoa.util.atomic import atomic_path


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


# ----------------------------------------------------------------------------- errors name the user's path

def test_directory_target_refused_before_anything(tmp_path):
    target = tmp_path / "out.npy"
    target.mkdir()
    ran = []
    with pytest.raises(IsADirectoryError) as info:
        with atomic_path(target):
            ran.append(1)
    assert str(info.value) == f"cannot write {str(target)!r}: it is a directory; name a file in it"
    assert ran == [] and os.listdir(tmp_path) == ["out.npy"] and os.listdir(target) == []


def test_parent_that_is_a_file(tmp_path):
    (tmp_path / "f").write_text("x")
    with pytest.raises(FileNotFoundError, match="is not a directory"):
        with atomic_path(tmp_path / "f" / "x.npy"):
            pass


@pytest.mark.parametrize("target, exc", [("/proc/x.npy", FileNotFoundError), ("/sys/x.npy", PermissionError)])
def test_create_error_names_the_users_path(target, exc):
    """/proc and /sys refuse new files even to root."""
    with pytest.raises(OSError) as info:
        with atomic_path(target):
            pass
    assert isinstance(info.value, exc) and info.value.errno is not None
    assert str(info.value).startswith(f"cannot write {target!r}: ")
    assert ".x.npy." not in str(info.value)  # not the temporary file's name


def test_write_error_names_the_users_path(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("old")
    with pytest.raises(PermissionError) as info:
        with atomic_path(target) as tmp:
            raise PermissionError(13, "Permission denied", str(tmp))
    assert str(info.value) == f"cannot write {str(target)!r}: Permission denied"
    assert info.value.errno == 13
    assert target.read_text() == "old" and os.listdir(tmp_path) == ["out.csv"]


def test_write_error_without_a_file_names_the_users_path(tmp_path):
    target = tmp_path / "out.npy"
    with pytest.raises(OSError, match=r"^cannot write '.*out\.npy': No space left on device$"):
        with atomic_path(target):
            raise OSError(28, "No space left on device")
    assert os.listdir(tmp_path) == []


def test_error_about_another_file_is_left_alone(tmp_path):
    """An input the writer reads is not the output: its error stays its own."""
    with pytest.raises(FileNotFoundError) as info:
        with atomic_path(tmp_path / "out.npy"):
            open(tmp_path / "input.txt")
    assert info.value.filename == str(tmp_path / "input.txt")
    assert os.listdir(tmp_path) == []


def test_rename_error_names_the_users_path(tmp_path, monkeypatch):
    target = tmp_path / "out.npy"

    def fail(src, dst):
        raise OSError(18, "Invalid cross-device link", src, None, dst)

    monkeypatch.setattr(os, "replace", fail)
    with pytest.raises(OSError) as info:
        with atomic_path(target) as tmp:
            tmp.write_text("new")
    assert str(info.value) == f"cannot write {str(target)!r}: Invalid cross-device link"
    assert os.listdir(tmp_path) == []


def test_check_writable(tmp_path):
    from pyoa.util.atomic import check_writable

    target = tmp_path / "out.png"
    assert check_writable(target) == target
    assert os.listdir(tmp_path) == []  # its probe file is gone
    target.write_text("old")
    check_writable(target)
    assert target.read_text() == "old" and os.listdir(tmp_path) == ["out.png"]
    with pytest.raises(IsADirectoryError, match="it is a directory"):
        check_writable(tmp_path)
    with pytest.raises(FileNotFoundError, match="does not exist"):
        check_writable(tmp_path / "no" / "x.png")
    with pytest.raises(FileNotFoundError, match=r"cannot write '/proc/x\.png'"):
        check_writable("/proc/x.png")
