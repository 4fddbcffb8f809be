"""The comparison samplers over NumPy arrays (mirrors :mod:`pyoa.reference.baselines`
operation for operation, and ``kernels/include/pyoa/baselines.h``).

Arguments broadcast: sample indices ``i``, dimensions ``j`` and seeds ``p``
are uint32 arrays; parameters assumed valid (the catalogue checked them).
"""

from __future__ import annotations

import numpy as np

from ..tables import sequences
from ..reference.baselines import (
    DIGIT_KEY,
    HALTON_KEY,
    JITX_KEY,
    JITY_KEY,
    OWEN_KEY,
    PAD_KEY,
    RANDOM_KEY,
    SHUFFLE_KEY,
    SOBOL_KEY,
    SUBX_KEY,
    SUBY_KEY,
    _halton_digits,
)
from .floats import F32, jitter_value, sample_value
from .hashes import U32, hash_pair, mix32, permute, randfloat

_UNIT24 = F32(2.0**-24)


def _u32(x) -> np.ndarray:
    return np.asarray(x, dtype=U32)


def unit24(h) -> np.ndarray:
    """``(h >> 8) * 2**-24`` as float32 (exact)."""
    return (h >> U32(8)).astype(F32) * _UNIT24


def derived_seed(p, index, key: int) -> np.ndarray:
    """``hash_pair(p, index, key)`` where ``p != 0``, else 0."""
    p = _u32(p)
    return np.where(p == 0, U32(0), hash_pair(p, index, key))


def reverse_bits(x) -> np.ndarray:
    """Reverse the 32 bits of every element (the classic swap ladder)."""
    x = _u32(x)
    x = ((x >> U32(1)) & U32(0x55555555)) | ((x & U32(0x55555555)) << U32(1))
    x = ((x >> U32(2)) & U32(0x33333333)) | ((x & U32(0x33333333)) << U32(2))
    x = ((x >> U32(4)) & U32(0x0F0F0F0F)) | ((x & U32(0x0F0F0F0F)) << U32(4))
    x = ((x >> U32(8)) & U32(0x00FF00FF)) | ((x & U32(0x00FF00FF)) << U32(8))
    return (x >> U32(16)) | (x << U32(16))


def laine_karras(x, seed) -> np.ndarray:
    x = _u32(x) + _u32(seed)
    x ^= x * U32(0x6C50B47C)
    x ^= x * U32(0xB82F1E52)
    x ^= x * U32(0xC7AFE638)
    x ^= x * U32(0x8D22F6E6)
    return x


def owen_scramble(x, seed) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.baselines.owen_scramble` (seed 0: identity)."""
    x, seed = np.broadcast_arrays(_u32(x), _u32(seed))
    return np.where(seed == 0, x, reverse_bits(laine_karras(reverse_bits(x), seed)))


def sobol_bits(g, dim) -> np.ndarray:
    """XOR of the Sobol direction numbers of dimension ``dim`` over the set bits of ``g``."""
    g, dim = np.broadcast_arrays(_u32(g), _u32(dim))
    V = sequences.sobol_matrices()
    x = np.zeros(g.shape, dtype=U32)
    top = int(g.max()).bit_length() if g.size else 0
    for k in range(top):
        x ^= np.where((g >> U32(k)) & U32(1), V[dim, k], U32(0))
    return x


def random(i, j, p) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.baselines.random`."""
    return unit24(mix32(_u32(i) ^ hash_pair(p, j, RANDOM_KEY)))


def jittered2d(i, j, m: int, dims: int, p, jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.baselines.jittered2d`."""
    i, j = _u32(i), _u32(j)
    M = U32(m)
    J = F32(jitter)
    q = derived_seed(p, j >> U32(1), PAD_KEY)
    k = permute(i, m * m, q * U32(SHUFFLE_KEY))
    even = (j & U32(1)) == 0
    lone = even & (j + U32(1) == U32(dims))
    r = randfloat(k, q * np.where(even, U32(JITX_KEY), U32(JITY_KEY)))
    jit = jitter_value(r, J)
    pair = sample_value(np.where(even, k % M, k // M), F32(0), jit, 1, m)
    alone = sample_value(k, F32(0), jit, 1, m * m)  # a lone last dimension: N strata
    return np.where(lone, alone, pair)


def cmj2d(i, j, m: int, n: int, p, jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.baselines.cmj2d`."""
    i, j = _u32(i), _u32(j)
    J = F32(jitter)
    q = derived_seed(p, j >> U32(1), PAD_KEY)
    k = permute(i, m * n, q * U32(SHUFFLE_KEY))
    sx = permute(k % U32(m), m, q * U32(SUBX_KEY))
    sy = permute(k // U32(m), n, q * U32(SUBY_KEY))
    even = (j & U32(1)) == 0
    jit = jitter_value(randfloat(k, q * np.where(even, U32(JITX_KEY), U32(JITY_KEY))), J)
    x = sample_value(k % U32(m), sy, jit, n, m)
    y = sample_value(k // U32(m), sx, jit, m, n)
    return np.where(even, x, y)


def sobol02(i, j, log2n: int, p) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.baselines.sobol02`."""
    i, j = _u32(i), _u32(j)
    q = derived_seed(p, j >> U32(1), PAD_KEY)
    g = owen_scramble(i, derived_seed(q, 0, OWEN_KEY)) & U32((1 << log2n) - 1)
    x = sobol_bits(g, j & U32(1))
    return unit24(owen_scramble(x, derived_seed(q, U32(1) + (j & U32(1)), OWEN_KEY)))


def halton(i, j, p) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.baselines.halton` (one pass per distinct dimension)."""
    i, j, p = np.broadcast_arrays(_u32(i), _u32(j), _u32(p))
    out = np.empty(i.shape, dtype=F32)
    primes = sequences.primes()
    for dim in np.unique(j):
        sel = j == dim
        ii, pp = i[sel], p[sel]
        b = int(primes[dim])
        q = derived_seed(pp, dim, HALTON_KEY)
        rest = ii.copy()
        prefix = np.zeros_like(ii)
        numer = np.zeros(ii.shape, dtype=np.uint64)
        power = 1
        for _ in range(_halton_digits(b)):
            d = rest % U32(b)
            rest //= U32(b)
            dd = permute(d, b, np.where(q == 0, U32(0), hash_pair(q, U32(power) + prefix, DIGIT_KEY)))
            numer = numer * np.uint64(b) + dd
            prefix += d * U32(power)
            power *= b
        out[sel] = ((numer << np.uint64(24)) // np.uint64(power)).astype(F32) * _UNIT24
    return out


def sobol(i, j, p) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.baselines.sobol`."""
    i, j = _u32(i), _u32(j)
    return unit24(owen_scramble(sobol_bits(i ^ (i >> U32(1)), j), derived_seed(p, j, SOBOL_KEY)))
