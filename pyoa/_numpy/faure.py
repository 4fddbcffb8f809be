"""The Owen-scrambled Faure sequence over NumPy arrays (mirrors
:func:`pyoa.reference.faure.faure` operation for operation, and
``kernels/include/pyoa/faure.h``).

Arguments broadcast: sample indices ``i``, dimensions ``j`` and seeds ``p``
are uint32 arrays; ``b`` and ``n`` are ints, assumed valid (the catalogue
checked them).
"""

from __future__ import annotations

import numpy as np

from ..reference.faure import (
    FAURE_DIGIT_KEY,
    FAURE_INDEX_KEY,
    FAURE_KEY,
    cell_digits,
    out_digits,
)
from .baselines import derived_seed
from .floats import F32
from .hashes import U32, _u32, block_seed, hash_pair, permute

_UNIT24 = F32(2.0**-24)
U64 = np.uint64


def _index_scramble(a: list, b: int, s) -> list:
    """Vectorized :func:`pyoa.reference.faure.index_scramble`; ``s == 0`` leaves a lane's digits as they are."""
    out = list(a)
    high = np.zeros(a[0].shape, U32)
    power = 1
    for r in range(len(a) - 1, -1, -1):
        key = np.where(s == 0, U32(0), hash_pair(s, U32(power) + high, FAURE_DIGIT_KEY))
        out[r] = permute(a[r], b, key)
        if r:  # the last one is never used (and could pass 2**32)
            high = high * U32(b) + a[r]
        power *= b
    return out


def faure(i, j, b: int, n: int, p) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.faure.faure`."""
    i, j, p = np.broadcast_arrays(_u32(i), _u32(j), _u32(p))
    ub = U32(b)
    col, block = j % ub, j // ub
    P = block_seed(p, block)
    q = derived_seed(P, col, FAURE_KEY)
    K = out_digits(b)
    copies = block != 0
    if copies.any():
        n = K  # the copies' scrambled indices have every digit; block 0's extra digits are 0
    a = []
    rest = i.copy()
    for _ in range(n):
        a.append(rest % ub)
        rest = rest // ub
    if copies.any():
        a = _index_scramble(a, b, np.where(copies, hash_pair(P, ub, FAURE_INDEX_KEY), U32(0)))
    # Taylor shift: the coefficients of A(x + col) mod b (products < b**2 <= 2**24)
    for k in range(n - 1):
        for r in range(n - 2, k - 1, -1):
            a[r] = (a[r] + col * a[r + 1]) % ub
    zero = np.zeros(i.shape, U32)
    numer = np.zeros(i.shape, U64)
    prefix = np.zeros(i.shape, U32)
    power = 1
    for k in range(K):
        y = a[k] if k < n else zero
        key = np.where(q == 0, U32(0), hash_pair(q, U32(power) + prefix, FAURE_DIGIT_KEY))
        numer = numer * U64(b) + permute(y, b, key)
        if k + 1 < K:  # the last prefix is never used (and could pass 2**32)
            prefix = prefix * ub + y
        power *= b
    x24 = (numer << U64(24)) // U64(power)
    fine = b ** cell_digits(b)
    cell = numer // U64(power // fine)
    lo = ((cell << U64(24)) + U64(fine - 1)) // U64(fine)
    return np.maximum(x24, lo).astype(F32) * _UNIT24
