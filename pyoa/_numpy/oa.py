"""Orthogonal-array samplers over NumPy arrays (mirrors :mod:`pyoa.reference.oa`).

Each function takes broadcastable arrays of sample indices ``i``, dimensions
``j`` (any ``j >= 0``; blocks per SPEC section 6) and array seeds ``p`` and
returns float32 values; see the reference for the mathematics.
"""

from __future__ import annotations

import numpy as np

from .floats import F32, jitter_value, sample_value
from .hashes import U32, block_seed, dimension_seeds, permute, randfloat


def _blocks(j, p, block_dims: int):
    j = np.asarray(j, dtype=U32)
    block, col = j // U32(block_dims), j % U32(block_dims)
    return col, block_seed(p, block)


def bose(i, j, s: int, p, offset: str = "cmj", jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.bose` (parameters assumed valid)."""
    i = np.asarray(i, dtype=U32)
    j, p = _blocks(j, p, s + 1)
    P1, P2, P3 = dimension_seeds(p, j)
    S = U32(s)
    a0, a1 = i // S, i % S
    # Column multiplier of the Bose formula, and of the partner column k.
    k = np.where(j % U32(2) == 1, j - U32(1), j + U32(1))
    aij = np.where(j == 0, a0, np.where(j == 1, a1, (a0 + (j - U32(1)) * a1) % S))
    aik = np.where(j == 0, a1, np.where(j == 1, a0, (a0 + ((k - U32(1)) % S) * a1) % S))

    stratum = permute(aij, s, P1)
    if offset == "centered":
        sub = F32((s - 1) / 2)
    elif offset == "j":
        sub = permute(aik, s, (aik * S + aij + U32(1)) * P2)
    elif offset == "mj":
        sub = permute(aik, s, (aij + U32(1)) * P2)
    else:
        sub = permute(aik, s, P2)
    return sample_value(stratum, sub, jitter_value(randfloat(i, P3), F32(jitter)), s, s)


def cmjnd(i, j, s: int, t: int, p, offset: str = "cmj", jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.cmjnd` (parameters assumed valid)."""
    i = np.asarray(i, dtype=U32)
    j, p = _blocks(j, p, t)
    P1, P2, P3 = dimension_seeds(p, j)
    S = U32(s)
    M = s ** (t - 1)
    sj = S ** j  # s**j <= s**(t-1) < 2**24: no overflow
    aij = (i // sj) % S
    v = i % sj + (i // (sj * S)) * sj

    stratum = permute(aij, s, P1)
    if offset == "centered":
        sub = F32((M - 1) / 2)
    elif offset == "j":
        sub = permute(v, M, (i + U32(1)) * P2)
    elif offset == "mj":
        sub = permute(v, M, (aij + U32(1)) * P2)
    else:
        sub = permute(v, M, P2)
    return sample_value(stratum, sub, jitter_value(randfloat(i, P3), F32(jitter)), M, s)
