"""``zfaure`` over an array namespace (:mod:`pyoa._arrays`):
:func:`pyoa.reference.zfaure.zfaure` operation for operation (docs/spec.md
section 5.12), and ``kernels/include/pyoa/zfaure.h``.

Samples ``i``, dimensions ``j``, pixels and seeds are uint32 arrays that
broadcast; ``N``, ``b``, ``k`` and ``width`` are Python ints, assumed valid
(the catalogue checked them), so the loops over the grid's and the index's
digits unroll. The index ``T = z N + i`` is uint64.
"""

from __future__ import annotations

from ..reference.faure import FAURE_KEY
from ..reference.zfaure import ZFAURE_AXIS_KEY, ZFAURE_INDEX_KEY, ZFAURE_ORDER_KEY, ZFAURE_TILE_KEY, total_digits
from .blocks import block_seed
from .faure import digits_value, index_digits
from .hashes import derived_seed, hash_pair, mix32, permute


def axis_permute(xp, d, b: int, h):
    """:func:`pyoa.reference.zfaure.axis_permute`."""
    return permute(xp, permute(xp, d, b, h), b, mix32(xp, h))


def pixel_code(xp, x, y, b: int, k: int, S):
    """:func:`pyoa.reference.zfaure.pixel_code` (uint64) for the sequence seed ``S``."""
    code = xp.u64(xp.zeros(x, y, S))
    t = S
    for level in range(k):  # the most significant digits first
        scale = b ** (k - 1 - level)
        dx, dy = x // scale % b, y // scale % b
        gx = axis_permute(xp, dx, b, hash_pair(xp, t, 0, ZFAURE_AXIS_KEY))
        gy = axis_permute(xp, dy, b, hash_pair(xp, t, 1, ZFAURE_AXIS_KEY))
        swap = (hash_pair(xp, t, 2, ZFAURE_AXIS_KEY) >> 31) != 0
        if level + 1 < k:  # the last level's hash is never used
            t = hash_pair(xp, t, dy * b + dx, ZFAURE_TILE_KEY)
        code = code * (b * b) + xp.u64(xp.select(swap, gx * b + gy, gy * b + gx))
    return code


def chained_scramble(xp, a: list, b: int, h, copies) -> list:
    """:func:`pyoa.reference.zfaure.chained_scramble` in the lanes of ``copies``; the others keep their digits."""
    out = list(a)
    for r in range(len(a) - 1, -1, -1):
        out[r] = permute(xp, a[r], b, xp.select(copies, h, 0))
        if r:  # the last hash is never used
            h = hash_pair(xp, h, a[r], ZFAURE_INDEX_KEY)
    return out


def zfaure(xp, i, j, N: int, b: int, k: int, width: int, pixel, seed):
    """:func:`pyoa.reference.zfaure.zfaure` over arrays."""
    i, j, pixel, seed = xp.as_uint32(i, j, pixel, seed)
    S = hash_pair(xp, seed, b, ZFAURE_ORDER_KEY)  # never 0: every seed scrambles
    T = pixel_code(xp, pixel % width, pixel // width, b, k, S) * N + xp.u64(i)
    a = index_digits(xp, T, b, total_digits(b, k, N))
    col, block = j % b, j // b
    P = block_seed(xp, S, block)
    copies = block != 0
    if xp.may_any(copies):
        a = chained_scramble(xp, a, b, hash_pair(xp, P, b, ZFAURE_INDEX_KEY), copies)
    return digits_value(xp, a, b, col, derived_seed(xp, P, col, FAURE_KEY))
