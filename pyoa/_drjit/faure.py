"""The Owen-scrambled Faure sequence in Dr.Jit operations (mirrors
:func:`pyoa._numpy.faure.faure` and ``kernels/include/pyoa/faure.h``; the mathematics is
in :mod:`pyoa.reference.faure` and docs/spec.md section 5.11).

``b`` (the base) and ``n`` (the digits of the largest index) are Python ints:
the digit loops unroll when the code is traced. The dimension ``j`` is an
array whose block may differ per lane (inside Mitsuba it is the sampler's
dimension counter), so every lane takes the copies' path (all ``K`` index
digits, the index scramble) and block 0's lanes skip the scramble by a
select: their extra digits are zero, which leaves the value unchanged.
"""

from __future__ import annotations

import drjit as dr

from ..reference.faure import (
    FAURE_DIGIT_KEY,
    FAURE_INDEX_KEY,
    FAURE_KEY,
    cell_digits,
    out_digits,
)
from .hashes import block_seed, derived_seed, hash_pair, permute


def _index_scramble(a: list, b: int, s) -> list:
    """:func:`pyoa.reference.faure.index_scramble`; ``s == 0`` leaves a lane's digits as they are."""
    U = type(s)
    out = list(a)
    high = U(0)
    power = 1
    for r in range(len(a) - 1, -1, -1):
        key = dr.select(s == 0, U(0), hash_pair(s, U(power) + high, FAURE_DIGIT_KEY))
        out[r] = permute(a[r], b, key)
        if r:  # the last one is never used (and could pass 2**32)
            high = high * b + a[r]
        power *= b
    return out


def faure(i, j, b: int, n: int, p):
    """:func:`pyoa.reference.faure.faure` over Dr.Jit arrays (``i < b**n``)."""
    U = type(i)
    U64 = dr.uint64_array_t(U)
    F = dr.float32_array_t(U)
    j, p = U(j), U(p)
    col, block = j % b, j // b
    P = block_seed(p, block)
    q = derived_seed(P, col, FAURE_KEY)
    K = out_digits(b)
    n = K  # see the module docstring: block 0's extra digits are zero
    a = []
    rest = U(i)
    for _ in range(n):
        a.append(rest % b)
        rest = rest // b
    a = _index_scramble(a, b, dr.select(block != 0, hash_pair(P, U(b), FAURE_INDEX_KEY), U(0)))
    # Taylor shift: the coefficients of A(x + col) mod b (products < b**2 <= 2**24)
    for k in range(n - 1):
        for r in range(n - 2, k - 1, -1):
            a[r] = (a[r] + col * a[r + 1]) % b
    numer = U64(0)
    prefix = U(0)
    power = 1
    for k in range(K):
        y = a[k]
        key = dr.select(q == 0, U(0), hash_pair(q, U(power) + prefix, FAURE_DIGIT_KEY))
        numer = numer * b + U64(permute(y, b, key))
        if k + 1 < K:  # the last prefix is never used (and could pass 2**32)
            prefix = prefix * b + y
        power *= b
    x24 = (numer << 24) // power
    fine = b ** cell_digits(b)
    cell = numer // (power // fine)
    lo = ((cell << 24) + (fine - 1)) // fine
    return F(dr.maximum(x24, lo)) * F(2.0**-24)
