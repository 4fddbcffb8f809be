"""Argument checks shared by the modules of :mod:`pyoa.analysis`.

Every bad value is a :class:`ValueError` here (the analysis functions have
always refused bad input that way), including those :func:`pyoa.samplers._int`
would report as a :class:`TypeError`.

* :func:`_int`: an integer argument within bounds;
* :func:`_unit_values`, :func:`_points`: real, finite values in ``[0, 1)``
  (or ``[0, 1]``), and point sets of shape ``(..., N, d)``;
* :func:`_dim`: a dimension, ``1 <= d <= 2**20``.
"""

from __future__ import annotations

import numpy as np

from ..samplers import _int as _checked_int


def _int(name: str, value, lo: int | None = None, hi: int | None = None) -> int:
    """:func:`pyoa.samplers._int`, but every bad value is a ValueError here."""
    try:
        return _checked_int(name, value, lo, hi)
    except TypeError as exc:
        raise ValueError(str(exc)) from None


def _points(points, what: str = "points", closed: bool = False) -> np.ndarray:
    """``points`` as a real array of shape (..., N, d) with every value in [0, 1)
    (or [0, 1] when ``closed``); float32 stays float32, the rest becomes float64."""
    x = _unit_values(points, what, closed)
    if x.ndim < 2:
        raise ValueError(f"{what} must have shape (N, d) (or (..., N, d)), got shape {x.shape}")
    if x.shape[-2] == 0 or x.shape[-1] == 0:
        raise ValueError(f"{what} must hold at least one point of at least one dimension, got shape {x.shape}")
    return x


def _unit_values(values, what: str, closed: bool = False) -> np.ndarray:
    """``values`` (any shape) as a real array with every value finite and in
    [0, 1) (or [0, 1] when ``closed``); float32 stays float32, the rest
    becomes float64."""
    try:
        x = np.asarray(values)
    except ValueError:  # ragged nested sequences
        raise ValueError(f"{what} must be a real array (a regular, not ragged, nested sequence)") from None
    # "m" (timedelta64) counts as an integer subtype to NumPy
    if x.dtype.kind not in "iuf":
        raise ValueError(f"{what} must be a real array, got dtype {x.dtype}")
    if x.dtype not in (np.float32, np.float64):
        x = x.astype(np.float64)
    if x.size == 0:
        return x
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{what} must be finite (found NaN or infinity)")
    lo, hi = float(x.min()), float(x.max())
    if lo < 0 or hi > 1 or (hi == 1 and not closed):
        bad = lo if lo < 0 else hi
        raise ValueError(f"{what} must lie in [0, 1{']' if closed else ')'}, found {bad!r}")
    return x


def _dim(d) -> int:
    return _int("d", d, 1, 2**20)
