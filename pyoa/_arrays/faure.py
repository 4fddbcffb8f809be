"""The Owen-scrambled Faure sequence over an array namespace (:mod:`pyoa._arrays`):
:func:`pyoa.reference.faure.faure` operation for operation (docs/spec.md
section 5.11), and ``kernels/include/pyoa/faure.h``.

Sample indices ``i``, dimensions ``j`` and seeds ``p`` are uint32 arrays
that broadcast; the base ``b`` and ``n`` (the digits of the largest index)
are Python ints, assumed valid (the catalogue checked them), so the digit
loops unroll (in Dr.Jit, when the code is traced).

A copy (block >= 1) needs all ``K`` index digits and the index scramble;
block 0 needs only ``n`` digits and no scramble, and its extra digits would
be zero, which leaves its value unchanged. So a namespace that can tell that
no lane is in a copy (``xp.may_any``: NumPy) skips both, and one that
cannot (Dr.Jit, whose dimension may differ per lane: inside Mitsuba it is
the sampler's dimension counter) takes the copies' path in every lane, block
0's lanes leaving the scramble by a select.
"""

from __future__ import annotations

from ..reference.faure import FAURE_DIGIT_KEY, FAURE_INDEX_KEY, FAURE_KEY, cell_digits, out_digits
from .blocks import block_seed
from .hashes import derived_seed, hash_pair, permute


def _index_scramble(xp, a: list, b: int, s) -> list:
    """:func:`pyoa.reference.faure.index_scramble`; ``s == 0`` leaves a lane's digits as they are."""
    out = list(a)
    high = 0
    power = 1
    for r in range(len(a) - 1, -1, -1):
        key = xp.select(s == 0, 0, hash_pair(xp, s, power + high, FAURE_DIGIT_KEY))
        out[r] = permute(xp, a[r], b, key)
        if r:  # the last one is never used (and could pass 2**32)
            high = high * b + a[r]
        power *= b
    return out


def faure(xp, i, j, b: int, n: int, p):
    """:func:`pyoa.reference.faure.faure` over arrays (``i < b**n``)."""
    i, j, p = xp.as_uint32(i, j, p)
    col, block = j % b, j // b
    P = block_seed(xp, p, block)
    copies = block != 0
    scramble = xp.may_any(copies)
    # the copies' scrambled indices have every digit; block 0's extra digits are 0
    a = index_digits(xp, i, b, out_digits(b) if scramble else n)
    if scramble:
        a = _index_scramble(xp, a, b, xp.select(copies, hash_pair(xp, P, b, FAURE_INDEX_KEY), 0))
    return digits_value(xp, a, b, col, derived_seed(xp, P, col, FAURE_KEY))


def index_digits(xp, i, b: int, n: int) -> list:
    """The ``n`` lowest base-``b`` digits of the uint32 or uint64 indices
    ``i`` as uint32 arrays, the least significant first."""
    a = []
    rest = i
    for _ in range(n):
        a.append(xp.u32(rest % b))  # a no-op on uint32 indices
        rest = rest // b
    return a


def digits_value(xp, a: list, b: int, col, q):
    """:func:`pyoa.reference.faure.digits_value`: coordinate ``col`` of the
    index digits ``a`` (uint32 arrays, least significant first, after any
    index scramble), Owen-scrambled with seed ``q``: the Taylor shift, the
    output scramble and the float rule."""
    K = out_digits(b)
    n = len(a)
    a = list(a)
    # Taylor shift: the coefficients of A(x + col) mod b (products < b**2 <= 2**24);
    # step k fixes y_k, and only y_0 .. y_(K-1) are read
    for k in range(min(n - 1, K)):
        for r in range(n - 2, k - 1, -1):
            a[r] = (a[r] + col * a[r + 1]) % b
    numer = 0
    prefix = 0
    power = 1
    for k in range(K):
        y = a[k] if k < n else 0
        key = xp.select(q == 0, 0, hash_pair(xp, q, power + prefix, FAURE_DIGIT_KEY))
        numer = numer * b + xp.u64(permute(xp, y, b, key))
        if k + 1 < K:  # the last prefix is never used (and could pass 2**32)
            prefix = prefix * b + y
        power *= b
    x24 = (numer << 24) // power
    fine = b ** cell_digits(b)
    cell = numer // (power // fine)
    lo = ((cell << 24) + (fine - 1)) // fine
    return xp.f32(xp.maximum(x24, lo)) * 2.0**-24
