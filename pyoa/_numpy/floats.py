"""Float32 rules of docs/spec.md section 7 over NumPy arrays (mirrors :mod:`pyoa.reference.floats`).

NumPy evaluates float32 array arithmetic one correctly rounded operation at a
time and never fuses a multiply and an add, which is what the spec asks.
"""

from __future__ import annotations

import numpy as np

F32 = np.float32
U32 = np.uint32


def cell_floor(c, n) -> np.ndarray:
    """The smallest float32 ``>= c / n`` for integer arrays ``0 <= c <= n <= 2**24``.

    ``f = c / n`` correctly rounded is the float32 nearest to ``c/n``, so it
    is either that smallest float32 or the one just below it: one step up
    when ``f < c/n``. The test ``f * n < c`` is exact in float64 (a float32
    times an integer below ``2**25`` has at most 49 significant bits); the
    kernels take the sign of the exactly rounded ``fma(f, n, -c)`` instead.
    """
    c, n = np.asarray(c, dtype=U32), np.asarray(n, dtype=U32)
    f = c.astype(F32) / n.astype(F32)
    below = f.astype(np.float64) * n < c
    return (f.view(U32) + below.astype(U32)).view(F32)


def cell_clamp(x, c, n) -> np.ndarray:
    """Clamp float32 values ``x`` into their cells ``[c/n, (c+1)/n)``
    (:func:`pyoa.reference.floats.cell_clamp`); values inside keep their bits."""
    lo = cell_floor(c, n)
    hi = (cell_floor(np.asarray(c, dtype=U32) + U32(1), n).view(U32) - U32(1)).view(F32)
    return np.minimum(np.maximum(x, lo), hi)


#: Unit roundoff of float32.
_U = 2.0**-24


def sample_value(stratum, sub, jitter, M: int, s: int) -> np.ndarray:
    """``(stratum + (sub + jitter) / M) / s`` in float32, clamped into its
    cell (:func:`pyoa.reference.floats.sample_value`).

    ``sub`` is an integer array (the fine cell is ``stratum * M + sub`` of
    ``N = s * M``) or the float ``(M-1)/2`` of ``centered``: an integer for
    odd ``M``, else a half-integer whose values are clamped into their coarse
    stratum ``stratum`` of ``s``.

    Notes
    -----
    The clamp moves a few values in a million, so only the values that can
    have crossed an edge are examined. Four correctly rounded operations give
    ``x = t (1 + e)`` with ``|e| <= (1 + u)**4 - 1 < 4.0001 u`` (``u = 2**-24``)
    for the exact ``t < 1`` of the same float32 inputs, so ``|x - t| <
    4.0001 u``; and ``t N = c + jitter``, so ``t`` lies ``min(jitter, 1 -
    jitter) / N`` from its cell's nearer edge. A value can leave its cell only
    if ``min(jitter, 1 - jitter) < 4.0001 u N``: outside that band (with a
    margin, ``5 u N``) the value is inside and keeps its bits. For the others
    ``floor(float64(x) * N)`` (exact) decides, and :func:`cell_clamp` moves
    those outside. The kernels clamp every value instead (no branch); the
    conformance tests check that the two agree bit for bit.
    """
    stratum = np.asarray(stratum, dtype=U32)  # no copy when it is uint32 already
    sub = np.asarray(sub)
    x = (stratum.astype(F32) + (sub.astype(F32) + jitter) / F32(M)) / F32(s)
    shape = np.shape(x)
    x = np.atleast_1d(np.asarray(x, dtype=F32))
    whole = np.issubdtype(sub.dtype, np.integer) or float(sub).is_integer()
    n = s * M if whole else s
    band = 5 * _U * n
    jit = np.broadcast_to(np.asarray(jitter, dtype=F32), x.shape)
    # Scan in the jitter's memory order (the operands' layouts differ: the
    # table path's gathers put pixels fastest, the hashes do not): a copy
    # into another order would cost more than the whole clamp. Only the few
    # candidates are then gathered from, and scattered into, x's own layout.
    order = np.argsort(jit.strides, kind="stable")[::-1]
    jit = jit.transpose(order)
    if whole and band < 0.5:
        flat = np.flatnonzero((jit < F32(band)) | (jit > F32(1 - band)))
    else:  # every value is a candidate (N near 2**24, or the coarse cells of a half-integer sub)
        flat = np.arange(x.size)
    if flat.size:
        idx = np.unravel_index(flat, jit.shape)
        xv = x.transpose(order)  # a view: writes through it land in x
        st = np.broadcast_to(stratum, x.shape).transpose(order)[idx]
        c = st * U32(M) + np.broadcast_to(sub, x.shape).transpose(order)[idx].astype(U32) if whole else st
        xi = xv[idx]
        # float64 -> uint32 truncates, which is floor for x >= 0
        out = (xi.astype(np.float64) * n).astype(U32) != c
        if out.any():
            xv[tuple(k[out] for k in idx)] = cell_clamp(xi[out], c[out], U32(n))
    return x.reshape(shape)


def jitter_value(r, amount: np.float32) -> np.ndarray:
    """``0.5 + J * (r - 0.5)`` in float32."""
    return F32(0.5) + F32(amount) * (r - F32(0.5))
