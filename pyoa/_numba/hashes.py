"""The integer hashes of docs/spec.md section 2 (:mod:`pyoa.reference.hashes`),
compiled with numba, one value at a time.

Values are uint32 held in int64 (numba's natural integer), so a product of
two uint32 does not fit: :func:`mul32` multiplies modulo 2^32 in two halves
whose products stay below 2^48, never relying on a wrapping int64 overflow
(which LLVM may treat as undefined). The functions are inlined into their
callers, so the split costs one multiplication more, not a call.
"""

from __future__ import annotations

from numba import njit

_JIT = dict(nogil=True, cache=True, inline="always")
MASK32 = 0xFFFFFFFF


@njit(**_JIT)
def mul32(a, b):
    """``a * b mod 2^32`` for ``a, b`` in ``[0, 2^32)``, without overflowing int64."""
    return (a * (b & 0xFFFF) + (((a * (b >> 16)) & 0xFFFF) << 16)) & MASK32


@njit(**_JIT)
def mix32(x):
    """Wellons' lowbias32 (:func:`pyoa.reference.hashes.mix32`) of a uint32."""
    x ^= x >> 16
    x = mul32(x, 0x7FEB352D)
    x ^= x >> 15
    x = mul32(x, 0x846CA68B)
    x ^= x >> 16
    return x


@njit(**_JIT)
def hash_pair(a, b, key):
    """``mix32(b ^ mix32(a ^ key))``, never 0 (:func:`pyoa.reference.hashes.hash_pair`);
    ``a`` and ``b`` are taken modulo 2^32."""
    h = mix32((b & MASK32) ^ mix32((a & MASK32) ^ key))
    return key if h == 0 else h
