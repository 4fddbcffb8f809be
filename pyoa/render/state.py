"""Resumable running sums of long renders (``pyoa reference``, ``pyoa render --progressive``).

A state file is an ``.npz`` with at least three members: ``key`` (JSON of
every setting that changes the bits of the render), a count (``passes`` or
``samples``: how much of the work is in the sum) and ``sum`` (float64
``(height, width, 3)``); a reference also keeps the sum of squares
(``sumsq``) and the passes a cluster finished out of order (``pending``,
``images``), which join the sums in pass order, so that the sums have the
same bits however the passes were scheduled. It is written atomically after every completed
piece of work, so an interrupted run leaves the last complete one, and it
is only ever resumed by a run with the same key: a state of other settings
is never mixed into an image.

A state is read defensively, since it is only a file: only a regular file is
read (a path that is a device, a FIFO or a directory, or a symlink to one,
is refused: reading ``/dev/zero`` never ends, a FIFO blocks); the key is
read and compared first, so that a state of another run is named as such
(``--size``, ``--spp``...) whatever its size; no more bytes are read in
all than a state of this run can hold; and every array's ``.npy`` header is
checked against the shape and type this run expects, and against the bytes
its member holds, before its data is read, so a forged header cannot make
it allocate.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import stat
import zipfile
from pathlib import Path

import numpy as np

from ..util.atomic import atomic_path

#: Most bytes of a state's key (JSON of a few settings).
KEY_BYTES = 1 << 20
#: Bytes of a member besides its array's data: its .npy header and zip headers.
MEMBER_BYTES = 1 << 10
#: Bytes zipfile reads besides the members: the end of the archive, which it
#: searches for in the last 64 KiB, and the central directory.
ZIP_BYTES = 1 << 17
#: How each kind of file that is not a regular file is named in a refusal.
_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"))


def state_path(out) -> Path:
    """Where a long render to ``out`` (a reference, a progressive render)
    keeps its running sums while it works: ``OUT.state.npz``."""
    return Path(str(out) + ".state.npz")


class BadState(Exception):
    """A state file that cannot be resumed (the message says why)."""


class NotRegularFile(ValueError):
    """A path pyoa reads (a state, a study's files) that is not a regular
    file: it is neither read nor replaced."""


#: What a refusal of a path that is not a regular file suggests by default.
NOT_REGULAR_FIX = "remove or rename it, or give another --out"


def scene_digest(scene) -> str:
    """SHA-256 of what a scene renders: its file's bytes and its world-space
    triangles (which include every mesh file it reads)."""
    h = hashlib.sha256(Path(scene.path).read_bytes())
    h.update(np.ascontiguousarray(scene.triangles).tobytes())
    return h.hexdigest()


def not_regular(path, mode: int, what: str, fix: str = NOT_REGULAR_FIX) -> NotRegularFile:
    """The refusal of ``path`` (``what`` says whose file it is), a file of
    ``mode`` (its target's, for a symlink) that is not a regular file: one
    line naming what it is, and ``fix``."""
    path = Path(path)
    kind = next((name for test, name in _KINDS if test(mode)), None)
    if path.is_symlink():  # a symlink refused as such (O_NOFOLLOW) may name a regular file, or nothing
        kind = f"a symlink to {os.path.realpath(path)!r}" + (f", {kind}" if kind else "")
    return NotRegularFile(f"{str(path)!r} ({what}) is {kind or 'a file of another kind'}, not a regular file; "
                          f"{fix}")


def check_state_file(state, what: str, fix: str = NOT_REGULAR_FIX) -> None:
    """Refuse (:class:`NotRegularFile`, a ValueError naming the path and what
    it is) a state path that exists and is not a regular file once symlinks
    are followed: a device (reading ``/dev/zero`` never ends), a FIFO
    (reading blocks), a directory. Such a path is neither read nor replaced. ``what`` says whose state it
    is, e.g. ``"where pyoa reference keeps its running sum"``; ``fix`` what
    the refusal suggests. Every file pyoa reads that a user could replace
    is checked so, this or :func:`open_regular` (the same rule, made on the
    open file where pyoa reads it itself): states, images (what OpenImageIO
    opens, :func:`pyoa.render.image.image_info`), variance files, scene and
    mesh files (and the files a mesh names), a study's files."""
    try:
        mode = os.stat(state).st_mode
    except FileNotFoundError:  # absent, or a dangling symlink: the first write makes the file
        return
    if not stat.S_ISREG(mode):
        raise not_regular(state, mode, what, fix)


class _Capped:
    """A regular file read through zipfile, which refuses to read more than
    ``cap`` bytes in all (seeks are free): however a state's headers lie, no
    more is read than a state of this run can hold. No read asks for more
    than the file holds past its position either (a buffered read allocates
    what it is asked for)."""

    def __init__(self, fh, cap: int):
        self._fh, self._cap, self._read = fh, cap, 0
        self._size = os.fstat(fh.fileno()).st_size

    def read(self, n: int = -1) -> bytes:
        left = self._cap - self._read
        most = min(left + 1, max(self._size - self._fh.tell(), 0))
        data = self._fh.read(most if n is None or n < 0 else min(n, most))
        self._read += len(data)
        if self._read > self._cap:
            raise BadState(f"it holds more than the {self._cap} bytes a state of this run can have")
        return data

    def seek(self, offset: int, whence: int = 0) -> int:
        return self._fh.seek(offset, whence)

    def tell(self) -> int:
        return self._fh.tell()

    def seekable(self) -> bool:
        return True


def open_regular(path, what: str, fix: str = NOT_REGULAR_FIX):
    """``path`` opened for reading (binary), refused (:class:`NotRegularFile`,
    see :func:`not_regular`) unless it is a regular file: the check is made on
    the open file, so the file read is the file checked (a symlink to
    ``/dev/zero`` would be read for ever, a FIFO blocks). An open that fails
    raises its OSError."""
    # O_NONBLOCK: the open of a FIFO would wait for a writer
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise not_regular(path, mode, what, fix)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def _open_regular(state: Path):
    """A state file opened as :func:`open_regular`; one that cannot be opened is a BadState."""
    try:
        return open_regular(state, "a state file")
    except NotRegularFile:
        raise
    except OSError as exc:
        raise BadState(_first_line(exc)) from None


def _member(zf: zipfile.ZipFile, name: str, check) -> np.ndarray:
    """The array of member ``NAME.npy``; ``check(shape, dtype)`` sees its
    header (and raises BadState) before any array is made from it, and the
    header may not claim more data than the member holds: nothing larger
    than the member is ever allocated."""
    info = zf.getinfo(f"{name}.npy")  # its file_size is checked by the caller
    # Read no more than the member says it holds: zf.read() would inflate a
    # compressed member whole, whatever its header claims (a small forged
    # file can inflate to gigabytes), before its CRC check fails.
    with zf.open(info) as member:
        raw = member.read(info.file_size + 1)
    if len(raw) != info.file_size:
        raise BadState(f"its member {name}.npy holds {'more' if len(raw) > info.file_size else 'fewer'} bytes than "
                       f"its zip header says ({info.file_size})")
    fp = io.BytesIO(raw)
    version = np.lib.format.read_magic(fp)
    if version not in ((1, 0), (2, 0)):
        raise BadState(f"its {name} is a .npy array of version {version}, not 1.0 or 2.0")
    header = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
    shape, _, dtype = header(fp)
    check(shape, dtype)
    claimed = math.prod(shape) * dtype.itemsize
    if claimed > len(raw) - fp.tell():
        raise BadState(f"its member {name}.npy is cut short: its header claims {dtype} {shape} ({claimed} bytes), "
                       f"it holds {len(raw) - fp.tell()} bytes")
    return np.lib.format.read_array(io.BytesIO(raw), allow_pickle=False)


def _want(name: str, dtype, shape, verb: str = "is"):
    """A header check: exactly ``dtype`` and ``shape``."""

    def check(got_shape, got_dtype):
        if got_shape != tuple(shape) or got_dtype != dtype:
            raise BadState(f"its {name} {verb} {got_dtype} {got_shape}, not {np.dtype(dtype)} {tuple(shape)}")

    return check


def _read_key(zf: zipfile.ZipFile):
    """The key saved in an open state (anything JSON holds; None if it is no JSON)."""
    info = zf.getinfo("key.npy")
    if max(info.file_size, info.compress_size) > KEY_BYTES:
        raise BadState(f"its key is over {KEY_BYTES} bytes")

    def check(shape, dtype):
        if shape != () or dtype.kind != "U":
            raise BadState("its key is not a JSON object")

    text = str(_member(zf, "key", check)[()])
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return None


def _first_line(exc: Exception) -> str:
    first = (str(exc).strip().splitlines() or [""])[0]
    return f"unreadable ({type(exc).__name__}: {first})" if first else f"unreadable ({type(exc).__name__})"


#: What a state's read raises when the file is no state (caught as BadState).
_UNREADABLE = (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile)


def saved_key(state: Path) -> dict | None:
    """The key a state file was written with, or None if there is none to read.
    ValueError if it is not a regular file (:func:`check_state_file`)."""
    try:
        with _open_regular(state) as fh, zipfile.ZipFile(_Capped(fh, KEY_BYTES + MEMBER_BYTES + ZIP_BYTES)) as zf:
            key = _read_key(zf)
    except NotRegularFile:
        raise
    except (BadState, *_UNREADABLE):
        return None
    return key if isinstance(key, dict) else None


def describe_size(saved: dict, key: dict) -> str | None:
    """How a saved key's image size differs from this run's, as the user sets
    it (``--size``, or the scene's film without it); None if it does not."""
    was, now = (saved.get("width"), saved.get("height")), (key.get("width"), key.get("height"))
    if was == now:
        return None
    return (f"--size: it holds {was[0]} x {was[1]} pixels and this run asks for {now[0]} x {now[1]} (--size, or "
            f"the scene's film without it); give --size {was[0]} {was[1]} to continue it")


def read_state(state: Path, key: dict, count: str, most: int, describe) -> tuple[np.ndarray | None, int]:
    """``(sum, done)`` saved in ``state`` for ``key``: ``done`` the saved
    ``count`` (``0 <= done <= most``), ``sum`` None when ``done == 0``.

    Raises BadState when it cannot be resumed: unreadable, another run's
    (``describe(saved, key)`` says how it differs) or holding a count, a
    shape or values that no such run can have; ValueError when it is not a
    regular file (:func:`check_state_file`)."""
    arrays, done, _ = read_state_arrays(state, key, count, most, describe)
    return (arrays["sum"] if done else None), done


def read_state_arrays(state: Path, key: dict, count: str, most: int, describe, arrays: tuple[str, ...] = ("sum",),
                      pending: bool = False) -> tuple[dict, int, dict]:
    """:func:`read_state` of a state with several float64 sums (``arrays``,
    each ``(height, width, 3)``) and, with ``pending``, pieces of work
    finished out of order and not yet in the sums: members ``pending`` (their
    indices, increasing, each in ``(done, most)``) and ``images`` (float32
    ``(len(pending), height, width, 3)``).

    Returns ``(sums, done, pending)``: ``sums`` maps each name in ``arrays``
    to its array, ``pending`` each saved index to its image."""
    shape = (key["height"], key["width"], 3)
    size = 8 * int(np.prod(shape)) + MEMBER_BYTES
    limit = {"key.npy": KEY_BYTES, f"{count}.npy": MEMBER_BYTES, **{f"{a}.npy": size for a in arrays}}
    if pending:
        limit["pending.npy"] = 8 * most + MEMBER_BYTES
        limit["images.npy"] = 4 * int(np.prod(shape)) * most + MEMBER_BYTES
    with _open_regular(state) as fh:
        try:
            with zipfile.ZipFile(_Capped(fh, sum(limit.values()) + ZIP_BYTES)) as zf:
                # the key first: a state of another run is named as such, whatever its arrays
                saved = _read_key(zf)
                if not isinstance(saved, dict):
                    raise BadState("its key is not a JSON object")
                if saved != key:
                    raise BadState(describe(saved, key))
                for info in zf.infolist():  # refuse a member larger than it can be before reading any
                    size = max(info.file_size, info.compress_size)
                    if size > limit.get(info.filename, 0):
                        raise BadState(f"unexpected member {info.filename!r} of {size} bytes")

                def counter(got_shape, got_dtype):
                    if got_shape != () or got_dtype.kind not in "iu":
                        raise BadState(f"its {count} count is {got_dtype} {got_shape}, not an integer")

                done = _member(zf, count, counter)
                if not 0 <= int(done) <= most:
                    raise BadState(f"it counts {done.tolist()!r} {count} done, not 0 to {most}")
                done = int(done)
                sums = {a: _member(zf, a, _want(a, np.float64, shape)) for a in arrays}
                if pending:
                    def indices(got_shape, got_dtype):
                        if len(got_shape) != 1 or got_dtype.kind not in "iu":
                            raise BadState(f"its pending {count} are {got_dtype} {got_shape}, not a list of indices")

                    index = _member(zf, "pending", indices)
                    images = _member(zf, "images", _want("pending images", np.float32, (len(index), *shape), "are"))
        except _UNREADABLE as exc:  # truncated, empty, key-less
            raise BadState(_first_line(exc)) from None
    for a, total in sums.items():
        if not np.isfinite(total).all():
            raise BadState(f"its {a} holds NaN or inf")
    waiting = {}
    if pending:
        if index.size and (int(index.min()) <= done or int(index.max()) >= most or np.any(np.diff(index) <= 0)):
            raise BadState(f"its pending {count} {index.tolist()!r} are not increasing indices in ({done}, {most})")
        if not np.isfinite(images).all():
            raise BadState("its pending images hold NaN or inf")
        waiting = {int(k): images[i] for i, k in enumerate(index)}
    return sums, done, waiting


def write_state(state: Path, total: np.ndarray, count: str, done: int, key: dict, **more: np.ndarray) -> None:
    """Save ``total`` (float64), the count ``done``, ``key`` and any ``more``
    arrays (other sums, pending work: :func:`read_state_arrays`), atomically."""
    with atomic_path(state) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, sum=total, key=json.dumps(key), **{count: done}, **more)
