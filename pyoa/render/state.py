"""Resumable running sums of long renders (``pyoa reference``, ``pyoa render --progressive``).

A state file is an ``.npz`` with three members: ``key`` (JSON of every
setting that changes the bits of the render), a count (``passes`` or
``samples``: how much of the work is in the sum) and ``sum`` (float64
``(height, width, 3)``). It is written atomically after every completed
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
    shape = (key["height"], key["width"], 3)
    limit = {"key.npy": 1 << 20, f"{count}.npy": 1 << 10, "sum.npy": 8 * int(np.prod(shape)) + (1 << 10)}
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
            total = st["sum"]
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:  # truncated, empty, key-less
        raise BadState(_first_line(exc)) from None
    if total.shape != shape or total.dtype != np.float64:
        raise BadState(f"its sum is {total.dtype} {total.shape}, not float64 {shape}")
    if not np.isfinite(total).all():
        raise BadState("its sum holds NaN or inf")
    return (total if done else None), done


def write_state(state: Path, total: np.ndarray, count: str, done: int, key: dict) -> None:
    """Save ``total`` (float64), the count ``done`` and ``key``, atomically."""
    with atomic_path(state) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, sum=total, key=json.dumps(key), **{count: done})
