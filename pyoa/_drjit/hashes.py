"""Integer hashes of docs/spec.md sections 2 and 3 in Dr.Jit operations
(mirrors :mod:`pyoa._numpy.hashes` and ``kernels/include/pyoa/hashes.h``).

Dr.Jit's ``UInt32`` arithmetic wraps modulo ``2**32`` as the spec requires.
Constants above ``2**31`` are wrapped in the argument's own type first, so
that they are never read as signed literals.
"""

from __future__ import annotations

import drjit as dr

from ..reference.floats import UNIT_SCALE
from ..reference.hashes import BLOCK_KEY, BLOCK_ORDER_KEY, PIXEL_KEY, walk_mask


def mix32(x):
    """Wellons' lowbias32 (:func:`pyoa.reference.mix32`)."""
    U = type(x)
    x = x ^ (x >> 16)
    x = x * U(0x7FEB352D)
    x = x ^ (x >> 15)
    x = x * U(0x846CA68B)
    return x ^ (x >> 16)


def hash_pair(a, b, key: int):
    """``mix32(b ^ mix32(a ^ key))``, never 0 (:func:`pyoa.reference.hashes.hash_pair`)."""
    U = type(a) if dr.is_array_v(a) else type(b)
    a, b = U(a), U(b)
    h = mix32(b ^ mix32(a ^ U(key)))
    return dr.select(h == 0, U(key), h)


def pixel_seed(seed, pixel):
    """The point-set seed of one pixel (docs/spec.md section 3)."""
    return hash_pair(seed, pixel, PIXEL_KEY)


def block_seed(p, block):
    """The seed of block ``block`` (block 0 keeps ``p``; section 6)."""
    U = type(p) if dr.is_array_v(p) else type(block)
    p, block = U(p), U(block)
    return dr.select(block == 0, p, hash_pair(p, block, BLOCK_KEY))


def block_order_seed(P, block, N: int):
    """The seed of block ``block``'s sample order (:func:`pyoa.reference.hashes.block_order_seed`):
    0 for block 0 (``permute`` with seed 0 is the identity), else
    ``hash_pair(P, N, BLOCK_ORDER_KEY)``."""
    U = type(P) if dr.is_array_v(P) else type(block)
    P, block = U(P), U(block)
    return dr.select(block == 0, U(0), hash_pair(P, N, BLOCK_ORDER_KEY))


def locate(p, i, j, B: int, N: int):
    """The block rule (docs/spec.md section 6, :func:`pyoa.reference.hashes.locate`):
    ``(P, row, col)`` of dimension ``j`` of sample ``i`` in an array of ``N``
    rows and ``B`` columns with seed ``p``. Block ``j // B`` has seed
    ``P = block_seed(p, block)`` and reads row :func:`block_row` of ``i``
    (row ``i`` for block 0).

    ``B`` and ``N`` are Python ints fixed at trace time, like the cells' ``s``
    and :func:`permute`'s ``l``: Dr.Jit compiles an integer division by a
    literal to an exact multiply-and-shift (the float32 one is not exact,
    :mod:`.floats`; the tests compare against NumPy bit for bit)."""
    U = next((type(x) for x in (i, j, p) if dr.is_array_v(x)), None)
    i, j = U(i), U(j)
    P, row = locate_block(p, i, j // B, N)
    return P, row, j % B


def locate_block(p, i, block, N: int):
    """``(P, row)`` of sample ``i`` in block ``block`` (:func:`locate` without
    the column): the block's array seed and the row it reads. A caller that
    draws a block's dimensions one by one keeps these per lane and calls this
    once per block (:mod:`pyoa.mitsuba`)."""
    P = block_seed(p, block)
    return P, block_row(i, N, block_order_seed(P, block, N))


def block_row(i, N: int, r):
    """``permute(permute(i, N, r), N, mix32(r))`` (:func:`pyoa.reference.hashes.block_row`):
    the row of sample ``i`` in a block whose order seed is ``r``; ``i`` where ``r == 0``.

    The two permutations run inside a loop of at most one iteration whose
    lanes are active only where ``r != 0``: inside Mitsuba the dimension is
    an opaque value, the same in every lane of a draw, so in block 0 (most
    draws of a short path) Dr.Jit's loop finds no active lane and skips both
    permutations instead of computing and discarding them."""
    U = type(i) if dr.is_array_v(i) else type(r)
    i, r = U(i), U(r)
    if N == 1:
        return U(0)
    return dr.while_loop(state=(i, r, r != 0), cond=lambda x, r, todo: todo,
                         body=lambda x, r, todo: (permute(permute(x, N, r), N, mix32(r)), r, todo & False),
                         label="pyoa_block_row")[0]


def derived_seed(p, index, key: int):
    """``hash_pair(p, index, key)`` where ``p != 0``, else 0."""
    U = type(p)
    return dr.select(p == 0, U(0), hash_pair(p, index, key))


def _permute_round(i, p, w: int):
    """One pass of Kensler's bijection on ``[0, w]`` (the body of the cycle walk)."""
    U = type(i)
    W = U(w)
    i = i ^ p
    i = i * U(0xE170893D)
    i = i ^ (p >> 16)
    i = i ^ ((i & W) >> 4)
    i = i ^ (p >> 8)
    i = i * U(0x0929EB3F)
    i = i ^ (p >> 23)
    i = i ^ ((i & W) >> 1)
    i = i * (U(1) | (p >> 27))
    i = i * U(0x6935FA69)
    i = i ^ ((i & W) >> 11)
    i = i * U(0x74DCB303)
    i = i ^ ((i & W) >> 2)
    i = i * U(0x9E501CC3)
    i = i ^ ((i & W) >> 2)
    i = i * U(0xC860A3DF)
    i = i & W
    return i ^ (i >> 5)


def permute(i, l: int, p):
    """Element ``i`` of the ``p``-th permutation of ``0..l-1`` (:func:`pyoa.reference.permute`).

    ``l`` is a Python int (``1 <= l <= 2**31``): it is fixed when the code is
    traced. The cycle walk is a ``dr.while_loop`` (symbolic inside a traced
    kernel), left out when ``l`` is a power of two (one round always lands
    below ``l`` then).
    """
    return permutes((i, l, p))[0]


def permutes(*walks):
    """Several :func:`permute` at once: ``permutes((i1, l1, p1), (i2, l2, p2))``
    is ``[permute(i1, l1, p1), permute(i2, l2, p2)]``, bit for bit.

    Their cycle walks run in one ``dr.while_loop``, each lane of each walk
    stepping until it lands below its ``l``. A round is a chain of dependent
    multiplications, and Dr.Jit's LLVM backend runs a kernel one packet of
    lanes at a time, so a walk's loop is bound by that chain's latency and
    repeats until the packet's slowest lane is done; walks in one loop
    overlap their chains and share the wait for the slowest lane. With an OA
    value's two walks (stratum and sub-stratum) in one loop, Bose ``cmj``
    s = 11 ran at 260 against 230 M values/s with two loops (7.9 M values a
    call, median of 15 alternating calls, Intel Xeon 6/207, 2 threads).
    """
    U = next((type(x) for w in walks for x in (w[0], w[2]) if dr.is_array_v(x)), None)
    ins = [(U(i), l, U(p), walk_mask(l)) for i, l, p in walks]
    xs = [U(0) if l == 1 else _permute_round(i, p, w) for i, l, p, w in ins]
    loop = [k for k, (_, l, _, w) in enumerate(ins) if l > 1 and w + 1 != l]  # power-of-two l: one round lands
    if loop:
        def cond(*xw):
            out = xw[0] >= ins[loop[0]][1]
            for x, k in zip(xw[1:], loop[1:]):
                out |= x >= ins[k][1]
            return out

        def body(*xw):
            return tuple(dr.select(x >= ins[k][1], _permute_round(x, ins[k][2], ins[k][3]), x) for x, k in zip(xw, loop))

        walked = dr.while_loop(state=tuple(xs[k] for k in loop), cond=cond, body=body, label="pyoa_permute")
        for x, k in zip(walked, loop):
            xs[k] = x
    out = []
    for x, (i, l, p, _) in zip(xs, ins):
        L = U(l)
        out.append(U(0) if l == 1 else dr.select(p == 0, i, (x + p % L) % L))
    return out


def randfloat(i, p):
    """A float32 in ``[0, 1)`` hashed from ``(i, p)`` (:func:`pyoa.reference.randfloat`); 0.5 where ``p == 0``."""
    U = type(i) if dr.is_array_v(i) else type(p)
    F = dr.float32_array_t(U)
    i, p = U(i), U(p)
    i = i ^ p
    i = i ^ (i >> 17)
    i = i ^ (i >> 10)
    i = i * U(0xB36534E5)
    i = i ^ (i >> 12)
    i = i ^ (i >> 21)
    i = i * U(0x93FC4795)
    i = i ^ U(0xDF6E307F)
    i = i ^ (i >> 17)
    i = i * (U(1) | (p >> 18))
    # uint32 -> float32 rounds to nearest even, then one float32 multiply
    return dr.select(p == 0, F(0.5), F(i) * F(UNIT_SCALE))
