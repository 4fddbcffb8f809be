"""Atomic file writes: a failed write never leaves a half-written file over a good one.

Errors name the user's path, never the hidden temporary file beside it: an
:class:`OSError` raised while the temporary file is created, written or
renamed is re-raised as the same kind of error (``PermissionError``,
``FileNotFoundError``...) reading ``cannot write 'PATH': REASON``.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def new_file_mode() -> int:
    """The mode a plain :func:`open` gives a new file: ``0o666`` less the
    umask (so a group-shared directory, umask 002, gets group-writable
    files). Every file pyoa creates gets it."""
    return 0o666 & ~_umask()


def _renamed(exc: OSError, path: Path, tmp: str | None = None) -> OSError:
    """``exc`` as the same OSError subclass, saying it could not write ``path``.

    Only ``errno`` is kept: with ``strerror`` or ``filename`` set, ``str()``
    of an OSError would print the temporary file's name again.
    """
    reason = exc.strerror or str(exc)
    if tmp:  # a writer's own message may quote the temporary name
        reason = reason.replace(tmp, str(path))
    message = f"cannot write {str(path)!r}: {reason}"
    try:
        err = type(exc)(message)
    except TypeError:  # a subclass with a constructor of its own
        err = OSError(message)
    err.errno = exc.errno
    return err


def _about_temp(exc: OSError, tmp: str, path: Path) -> bool:
    """Whether ``exc`` (raised inside the ``with`` block) is about writing the
    temporary file: it names it, or no file at all (a full disk while
    writing), or it is the rename onto ``path``. An error about another file,
    say an input the writer reads, is left as it is."""
    names = [os.fspath(f) if isinstance(f, os.PathLike) else f for f in (exc.filename, exc.filename2)]
    return names[0] in (None, tmp) and names[1] in (None, tmp, os.fspath(path))


def _check_target(path: Path) -> None:
    """Refuse, before anything is created, a target that can never be written."""
    if not path.parent.is_dir():
        what = "is not a directory" if path.parent.exists() else "does not exist"
        raise FileNotFoundError(f"directory {str(path.parent)!r} {what} (for {str(path)!r})")
    if path.is_dir():
        raise IsADirectoryError(f"cannot write {str(path)!r}: it is a directory; name a file in it")


def _temp_file(path: Path) -> str:
    """Create the hidden temporary file beside ``path``; returns its name."""
    try:
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=path.suffix)
    except OSError as exc:
        raise _renamed(exc, path) from None
    os.close(fd)
    return tmp


def check_writable(path: str | os.PathLike) -> Path:
    """Check that :func:`atomic_path` can write ``path``, without touching it.

    For callers that do long work before writing: the check creates and
    removes a temporary file beside ``path`` (the only reliable test: a
    permission check says nothing about read-only file systems, ``/proc``
    or root), so a write that would fail at the end fails before the work.

    Raises
    ------
    FileNotFoundError
        Its directory does not exist (or is not a directory).
    IsADirectoryError
        ``path`` is a directory.
    OSError
        Any other reason a file cannot be created there, naming ``path``.
    """
    path = Path(path)
    _check_target(path)
    os.unlink(_temp_file(path))
    return path


def _file_id(path) -> tuple[int, int] | None:
    """(device, inode) of the file at ``path``, symlinks followed; None if there is none."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):  # absent, a dangling symlink, an unreadable name
        return None
    return st.st_dev, st.st_ino


def check_not_inputs(outputs, inputs) -> None:
    """Refuse (ValueError, one line) an output that is one of a command's
    inputs, before any work: writing it would replace what the command reads
    (a render written over its own reference). ``outputs`` and ``inputs`` are
    ``(option, path)`` pairs; a path that does not exist is none of them.
    Files are compared by device and inode, so every spelling of one file is
    caught: ``./ref.exr``, ``sub/../ref.exr``, a symlink to it, a hard link."""
    seen = {}
    for option, path in inputs:
        fid = _file_id(path)
        if fid is not None:
            seen.setdefault(fid, (option, path))
    for option, path in outputs:
        hit = seen.get(_file_id(path)) if path is not None else None
        if hit is not None:
            raise ValueError(f"{option} {str(path)!r} is the same file as {hit[0]} {str(hit[1])!r} (one device and "
                             f"inode), which this command reads: writing it would replace it; give another {option}")


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path beside ``path``; on success it replaces ``path``.

    The temporary file lives in the same directory (so :func:`os.replace` is
    an atomic rename on POSIX) and keeps the suffix, for writers that choose a
    format by extension. On any exception it is removed and ``path`` is untouched.

    Raises
    ------
    FileNotFoundError
        The directory of ``path`` does not exist (raised before the body runs).
    IsADirectoryError
        ``path`` is a directory (raised before the body runs).
    OSError
        Creating, writing (an OSError of the body that names the temporary
        file or no file) or renaming the temporary file failed: the same
        OSError subclass, with a message naming ``path``.
    """
    path = Path(path)
    _check_target(path)
    tmp = _temp_file(path)
    try:
        try:
            yield Path(tmp)
            # mkstemp makes the file 0600; give it the mode a plain open() would
            # (or keep the mode of the file it replaces).
            os.chmod(tmp, path.stat().st_mode & 0o7777 if path.exists() else new_file_mode())
            os.replace(tmp, path)
        except OSError as exc:
            if not _about_temp(exc, tmp, path):
                raise
            raise _renamed(exc, path, tmp) from None
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise
