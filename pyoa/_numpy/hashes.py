"""Integer hashes of docs/spec.md sections 2 and 3 over NumPy uint32 arrays.

Mirrors :mod:`pyoa.reference.hashes` operation for operation; NumPy's uint32
arithmetic wraps modulo ``2**32`` as the spec requires. Arguments broadcast.
"""

from __future__ import annotations

import numpy as np

from ..hashes import U32, _u32, block_seed, hash_pair, mix32, pixel_seed  # noqa: F401  (this package's hashes)
from ..reference.floats import UNIT_SCALE
from ..reference.hashes import JITTER_KEY, STRATUM_KEY, SUBSTRATUM_KEY

_UNIT_SCALE = np.float32(UNIT_SCALE)


def _permute_round(i: np.ndarray, p: np.ndarray, w: np.uint32) -> np.ndarray:
    """One pass of Kensler's bijection on ``[0, w]`` (the body of the cycle walk)."""
    i = i ^ p
    i *= U32(0xE170893D)
    i ^= p >> U32(16)
    i ^= (i & w) >> U32(4)
    i ^= p >> U32(8)
    i *= U32(0x0929EB3F)
    i ^= p >> U32(23)
    i ^= (i & w) >> U32(1)
    i *= U32(1) | (p >> U32(27))
    i *= U32(0x6935FA69)
    i ^= (i & w) >> U32(11)
    i *= U32(0x74DCB303)
    i ^= (i & w) >> U32(2)
    i *= U32(0x9E501CC3)
    i ^= (i & w) >> U32(2)
    i *= U32(0xC860A3DF)
    i &= w
    i ^= i >> U32(5)
    return i


def permute(i, l: int, p) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.permute` (``l`` a scalar, ``1 <= l <= 2**31``)."""
    i, p = np.broadcast_arrays(_u32(i), _u32(p))
    shape = i.shape
    i, p = i.ravel(), p.ravel()
    w = l - 1
    for k in (1, 2, 4, 8, 16):
        w |= w >> k
    w = U32(w)
    out = i.copy()
    todo = np.flatnonzero(p != 0)  # p == 0 is the identity
    if todo.size:
        pt = p[todo]
        cur = i[todo]
        res = np.empty_like(cur)
        pending = np.arange(todo.size)
        while pending.size:  # cycle walking until every lane is below l
            cur = _permute_round(cur, pt[pending], w)
            ok = cur < l
            res[pending[ok]] = cur[ok]
            pending, cur = pending[~ok], cur[~ok]
        out[todo] = (res + pt % U32(l)) % U32(l)
    return out.reshape(shape)


def randfloat(i, p) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.randfloat`: float32 in ``[0, 1)``."""
    # p keeps its own (often much smaller) shape: one seed per (pixel,
    # dimension) serves every sample, so its terms cost little per value
    # (at least 1-d: uint32 scalars would warn on the wrapping multiplies)
    shape = np.broadcast_shapes(np.shape(i), np.shape(p))
    p = np.atleast_1d(_u32(p))
    i = np.atleast_1d(_u32(i)) ^ p
    i ^= i >> U32(17)
    i ^= i >> U32(10)
    i *= U32(0xB36534E5)
    i ^= i >> U32(12)
    i ^= i >> U32(21)
    i *= U32(0x93FC4795)
    i ^= U32(0xDF6E307F)
    i ^= i >> U32(17)
    i *= U32(1) | (p >> U32(18))
    # uint32 -> float32 rounds to nearest even, then one float32 multiply.
    r = i.astype(np.float32) * _UNIT_SCALE
    zero = p == 0
    return (np.where(zero, np.float32(0.5), r) if np.any(zero) else r).reshape(shape)


def dimension_seeds(p, j):
    """Vectorized :func:`pyoa.reference.dimension_seeds`: (P1, P2, P3)."""
    q = _u32(p) * (_u32(j) + U32(1))
    return q * U32(STRATUM_KEY), q * U32(SUBSTRATUM_KEY), q * U32(JITTER_KEY)
