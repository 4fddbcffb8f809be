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
"""

from __future__ import annotations

import hashlib
import json
import zipfile
from pathlib import Path

import numpy as np

from ..atomic import atomic_path


def state_path(out) -> Path:
    """Where a long render to ``out`` (a reference, a progressive render)
    keeps its running sums while it works: ``OUT.state.npz``."""
    return Path(str(out) + ".state.npz")


class BadState(Exception):
    """A state file that cannot be resumed (the message says why)."""


def scene_digest(scene) -> str:
    """SHA-256 of what a scene renders: its file's bytes and its world-space
    triangles (which include every mesh file it reads)."""
    h = hashlib.sha256(Path(scene.path).read_bytes())
    h.update(np.ascontiguousarray(scene.triangles).tobytes())
    return h.hexdigest()


def _first_line(exc: Exception) -> str:
    first = (str(exc).strip().splitlines() or [""])[0]
    return f"unreadable ({type(exc).__name__}: {first})" if first else f"unreadable ({type(exc).__name__})"


def saved_key(state: Path) -> dict | None:
    """The key a state file was written with, or None if there is none to read."""
    try:
        with zipfile.ZipFile(state) as zf:
            info = zf.getinfo("key.npy")
            if info.file_size > 1 << 20:
                return None
        with np.load(state, allow_pickle=False) as st:
            key = json.loads(str(st["key"][()]))
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None
    return key if isinstance(key, dict) else None


def read_state(state: Path, key: dict, count: str, most: int, describe) -> tuple[np.ndarray | None, int]:
    """``(sum, done)`` saved in ``state`` for ``key``: ``done`` the saved
    ``count`` (``0 <= done <= most``), ``sum`` None when ``done == 0``.

    Raises BadState when it cannot be resumed: unreadable, another run's
    (``describe(saved, key)`` says how it differs) or holding a count, a
    shape or values that no such run can have."""
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
    size = 8 * int(np.prod(shape)) + (1 << 10)
    limit = {"key.npy": 1 << 20, f"{count}.npy": 1 << 10, **{f"{a}.npy": size for a in arrays}}
    if pending:
        limit["pending.npy"] = 8 * most + (1 << 10)
        limit["images.npy"] = 4 * int(np.prod(shape)) * most + (1 << 10)
    try:
        with zipfile.ZipFile(state) as zf:
            for info in zf.infolist():  # refuse a member larger than it can be before reading any
                if info.file_size > limit.get(info.filename, 0):
                    raise BadState(f"unexpected member {info.filename!r} of {info.file_size} bytes")
        with np.load(state, allow_pickle=False) as st:
            try:
                saved = json.loads(str(st["key"][()]))
            except ValueError:
                saved = None
            if not isinstance(saved, dict):
                raise BadState("its key is not a JSON object")
            if saved != key:
                raise BadState(describe(saved, key))
            done = st[count]
            if done.shape != () or done.dtype.kind not in "iu" or not 0 <= int(done) <= most:
                raise BadState(f"it counts {done.tolist()!r} {count} done, not 0 to {most}")
            done = int(done)
            sums = {a: st[a] for a in arrays}
            if pending:
                index, images = st["pending"], st["images"]
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:  # truncated, empty, key-less
        raise BadState(_first_line(exc)) from None
    for a, total in sums.items():
        if total.shape != shape or total.dtype != np.float64:
            raise BadState(f"its {a} is {total.dtype} {total.shape}, not float64 {shape}")
        if not np.isfinite(total).all():
            raise BadState(f"its {a} holds NaN or inf")
    waiting = {}
    if pending:
        if index.ndim != 1 or index.dtype.kind not in "iu" or (index.size and (
                int(index.min()) <= done or int(index.max()) >= most or np.any(np.diff(index) <= 0))):
            raise BadState(f"its pending {count} {index.tolist()!r} are not increasing indices in ({done}, {most})")
        if images.shape != (len(index), *shape) or images.dtype != np.float32:
            raise BadState(f"its pending images are {images.dtype} {images.shape}, not float32 "
                           f"{(len(index), *shape)}")
        if not np.isfinite(images).all():
            raise BadState("its pending images hold NaN or inf")
        waiting = {int(k): images[i] for i, k in enumerate(index)}
    return sums, done, waiting


def write_state(state: Path, total: np.ndarray, count: str, done: int, key: dict, **more: np.ndarray) -> None:
    """Save ``total`` (float64), the count ``done``, ``key`` and any ``more``
    arrays (other sums, pending work: :func:`read_state_arrays`), atomically."""
    with atomic_path(state) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, sum=total, key=json.dumps(key), **{count: done}, **more)
