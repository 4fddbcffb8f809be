"""pbrt-v4's ZSobol sampler over NumPy arrays (mirrors :mod:`pyoa.reference.zsobol`,
which holds the mathematics and references, and ``kernels/include/pyoa/zsobol.h``).

Sample indices ``i``, dimensions ``j`` (or pairs ``b``) and pixels broadcast
as integer arrays (uint32 or int64 with uint32 values); ``log2n``,
``log2res``, ``width`` and ``seed`` are Python ints, assumed valid (the
reference and the catalogue check them). The Morton index, the digit keys
and ``mix64`` are uint64 arrays, whose multiplications wrap modulo ``2**64``
as the reference's ``& MASK64`` does; arrays are at least 1-d so that no
uint64 scalar arithmetic (which warns on wrap-around) takes place.
"""

from __future__ import annotations

import numpy as np

from ..reference.baselines import OWEN_KEY
from ..reference.zsobol import DIGIT_MULT, PERMS, ZSOBOL_KEY, digit_count
from .baselines import owen_scramble, sobol_bits, unit24
from .hashes import U32, hash_pair

U64 = np.uint64
#: :data:`pyoa.reference.zsobol.PERMS` flattened: ``_PERMS[4 p + digit]``.
_PERMS = np.array(PERMS, dtype=U64).ravel()
_M1, _M2 = U64(0x7FB5D329728EA185), U64(0x81DADEF4BC2DD44D)
_LOW32 = U64(0xFFFFFFFF)


def _u64(x) -> np.ndarray:
    return np.atleast_1d(np.asarray(x, dtype=U64))


def mix64(v) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.zsobol.mix64` (pbrt's ``MixBits``), uint64."""
    v = _u64(v).copy()
    v ^= v >> U64(31)
    v *= _M1
    v ^= v >> U64(27)
    v *= _M2
    v ^= v >> U64(33)
    return v


def _spread(v: np.ndarray) -> np.ndarray:
    """Bit ``t`` of a value below ``2**32`` to bit ``2t`` (uint64)."""
    v = v & _LOW32
    v = (v | (v << U64(16))) & U64(0x0000FFFF0000FFFF)
    v = (v | (v << U64(8))) & U64(0x00FF00FF00FF00FF)
    v = (v | (v << U64(4))) & U64(0x0F0F0F0F0F0F0F0F)
    v = (v | (v << U64(2))) & U64(0x3333333333333333)
    v = (v | (v << U64(1))) & U64(0x5555555555555555)
    return v


def morton2(x, y) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.zsobol.morton2` for coordinates below ``2**32`` (uint64)."""
    return _spread(_u64(x)) | (_spread(_u64(y)) << U64(1))


def morton_index(i, log2n: int, width: int, pixel) -> np.ndarray:
    """``(morton2(pixel mod width, (pixel // width) mod 2**16) << log2n) | i`` (uint64)."""
    pixel = _u64(pixel)
    W = U64(width)
    x, y = pixel % W, (pixel // W) & U64(0xFFFF)
    return (morton2(x, y) << U64(log2n)) | _u64(i)


def permute_digits(m, q, log2n: int, log2res: int, bits: int = 64) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.zsobol.permute_digits` (uint64): the
    permuted index of Morton indices ``m`` with pair keys ``q`` (uint32).

    Only the digits at bit positions below ``bits`` are computed (``bits =
    32``: ``g mod 2**32``, all that the values use); the hashes still read
    the whole of ``m``.
    """
    m, q = np.broadcast_arrays(_u64(m), _u64(q))
    odd = log2n & 1
    key = U64(DIGIT_MULT) * q  # < 2**63: never wraps
    g = np.zeros(m.shape, dtype=U64)
    for d in range(digit_count(log2n, log2res) - 1, odd - 1, -1):
        shift = 2 * d - odd
        if shift >= bits:
            continue
        digit = (m >> U64(shift)) & U64(3)
        higher = m >> U64(shift + 2)  # the unpermuted digits above this one
        perm = (mix64(higher ^ key) >> U64(24)) % U64(24)
        g |= np.take(_PERMS, ((perm << U64(2)) | digit).astype(np.intp)) << U64(shift)
    if odd:
        g |= (m & U64(1)) ^ (mix64((m >> U64(1)) ^ key) & U64(1))
    if bits < 64:
        g &= U64((1 << bits) - 1)
    return g


def sample_index(i, b, log2n: int, log2res: int, width: int, pixel, seed: int) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.zsobol.sample_index`: the whole permuted
    index ``g`` (uint64, at least 1-d, the broadcast shape of ``i``, ``b``
    and ``pixel``)."""
    i, b, pixel = np.broadcast_arrays(np.atleast_1d(i), np.atleast_1d(b), np.atleast_1d(pixel))
    q = hash_pair(U32(seed), np.asarray(b, dtype=U32), ZSOBOL_KEY)
    return permute_digits(morton_index(i, log2n, width, pixel), q, log2n, log2res)


def zsobol(i, j, log2n: int, log2res: int, width: int, pixel, seed: int) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.zsobol.zsobol`: float32 values of the
    broadcast shape of ``i``, ``j`` and ``pixel`` (at least 1-d)."""
    i, j, pixel = np.broadcast_arrays(np.atleast_1d(i), np.atleast_1d(j), np.atleast_1d(pixel))
    j = np.asarray(j, dtype=U32)
    c = j & U32(1)
    q = hash_pair(U32(seed), j >> U32(1), ZSOBOL_KEY)
    g = permute_digits(morton_index(i, log2n, width, pixel), q, log2n, log2res, bits=32).astype(U32)
    return unit24(owen_scramble(sobol_bits(g, c), hash_pair(q, U32(1) + c, OWEN_KEY)))
