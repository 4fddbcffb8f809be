"""The integer hashes of docs/spec.md sections 2 and 3 over an array namespace
(:mod:`pyoa._arrays`): the operations of :mod:`pyoa.reference.hashes`, in its
order, on uint32 arrays, and ``kernels/include/pyoa/hashes.h``'s.

Arguments broadcast; seeds and indices are uint32 arrays or Python ints.
"""

from __future__ import annotations

from ..reference.floats import UNIT_SCALE
from ..reference.hashes import JITTER_KEY, PIXEL_KEY, STRATUM_KEY, SUBSTRATUM_KEY, walk_mask


def mix32(xp, x):
    """Wellons' lowbias32 (:func:`pyoa.reference.mix32`)."""
    (x,) = xp.as_uint32(x)
    x = x ^ (x >> 16)  # a new array: the steps below update it in place
    x *= 0x7FEB352D
    x ^= x >> 15
    x *= 0x846CA68B
    x ^= x >> 16
    return x


def hash_pair(xp, a, b, key: int):
    """``mix32(b ^ mix32(a ^ key))``, never 0 (:func:`pyoa.reference.hashes.hash_pair`)."""
    a, b = xp.as_uint32(a, b)
    h = mix32(xp, b ^ mix32(xp, a ^ key))
    return xp.select(h == 0, key, h)


def pixel_seed(xp, seed, pixel):
    """The point-set seed of one pixel (docs/spec.md section 3.1, :func:`pyoa.reference.pixel_seed`)."""
    return hash_pair(xp, seed, pixel, PIXEL_KEY)


def derived_seed(xp, p, index, key: int):
    """``hash_pair(p, index, key)`` where ``p != 0``, else 0 (the unscrambled canonical array keeps 0)."""
    p, index = xp.as_uint32(p, index)
    return xp.select(p == 0, 0, hash_pair(xp, p, index, key))


def dimension_seeds(xp, p, col):
    """The seeds ``(P1, P2, P3)`` of column ``col`` of the array with seed ``p``
    (docs/spec.md section 3.3, :func:`pyoa.reference.dimension_seeds`)."""
    p, col = xp.as_uint32(p, col)
    q = p * (col + 1)
    return q * STRATUM_KEY, q * SUBSTRATUM_KEY, q * JITTER_KEY


def permute_round(xp, i, p, w: int):
    """One pass of Kensler's bijection on ``[0, w]``, ``w + 1`` a power of two
    (:func:`pyoa.reference.hashes.permute_round`: the body of the cycle walk)."""
    i, p = xp.as_uint32(i, p)
    i = i ^ p  # a new array: the steps below update it in place
    i *= 0xE170893D
    i ^= p >> 16
    i ^= (i & w) >> 4
    i ^= p >> 8
    i *= 0x0929EB3F
    i ^= p >> 23
    i ^= (i & w) >> 1
    i *= 1 | (p >> 27)
    i *= 0x6935FA69
    i ^= (i & w) >> 11
    i *= 0x74DCB303
    i ^= (i & w) >> 2
    i *= 0x9E501CC3
    i ^= (i & w) >> 2
    i *= 0xC860A3DF
    i &= w
    i ^= i >> 5
    return i


def permute(xp, i, l: int, p):
    """Element ``i`` of the ``p``-th permutation of ``0..l-1`` (:func:`pyoa.reference.permute`;
    ``l`` a Python int, ``1 <= l <= 2**31``; ``p == 0`` is the identity)."""
    return permutes(xp, (i, l, p))[0]


def permutes(xp, *walks):
    """Several :func:`permute` at once: ``permutes(xp, (i1, l1, p1), (i2, l2,
    p2))`` is ``[permute(xp, i1, l1, p1), permute(xp, i2, l2, p2)]``, bit for bit.

    The cycle walks (a round until the lane lands below ``l``) are one
    ``xp.while_loops`` call: NumPy runs them one after another on the lanes
    still walking, Dr.Jit in one loop. Dr.Jit's LLVM backend runs a kernel
    one packet of lanes at a time, so a walk's loop is bound by the latency
    of a round's chain of dependent multiplications and repeats until the
    packet's slowest lane is done; walks in one loop overlap their chains
    and share that wait. With an OA value's two walks (stratum and
    sub-stratum) in one loop, Bose ``cmj`` s = 11 ran at 260 against 230 M
    values/s with two loops (7.9 M values a call, median of 15 alternating
    calls, Intel Xeon 6/207, 2 threads). A power-of-two ``l`` needs no walk
    (one round lands below it), ``l == 1`` no round.
    """
    ins = [(*xp.as_uint32(i, p), l, walk_mask(l)) for i, l, p in walks]
    first = [permute_round(xp, i, p, w) if l > 1 else None for i, p, l, w in ins]
    loops = [((x, p), lambda x, p, l=l: x >= l, lambda x, p, w=w: (permute_round(xp, x, p, w), p))
             for x, (i, p, l, w) in zip(first, ins) if l > 1 and w + 1 != l]
    walked = iter(xp.while_loops(loops, "pyoa_permute"))
    out = []
    for x, (i, p, l, w) in zip(first, ins):
        if l == 1:
            out.append(xp.zeros(i, p))
            continue
        if w + 1 != l:
            x = next(walked)[0]
        out.append(xp.select(p == 0, i, (x + p % l) % l))
    return out


def randfloat(xp, i, p):
    """A float32 in ``[0, 1)`` hashed from ``(i, p)``; 0.5 where ``p == 0``
    (:func:`pyoa.reference.randfloat`).

    ``p`` keeps its own shape: in NumPy's table path one seed per (pixel,
    dimension) serves every sample, so the terms of ``p`` cost little per value.
    """
    i, p = xp.as_uint32(i, p)
    i = i ^ p  # a new array: the steps below update it in place
    i ^= i >> 17
    i ^= i >> 10
    i *= 0xB36534E5
    i ^= i >> 12
    i ^= i >> 21
    i *= 0x93FC4795
    i ^= 0xDF6E307F
    i ^= i >> 17
    i *= 1 | (p >> 18)
    # uint32 -> float32 rounds to nearest even, then one float32 multiply
    r = xp.f32(i) * UNIT_SCALE
    zero = p == 0
    return xp.select(zero, 0.5, r) if xp.may_any(zero) else r
