"""Orthogonal-array samplers over NumPy arrays (mirrors :mod:`pyoa.reference.oa`
and, piece by piece, ``kernels/oa.cl``).

Each function takes broadcastable arrays of sample indices ``i``, dimensions
``j`` (any ``j >= 0``; blocks per docs/spec.md section 6) and array seeds ``p`` and
returns float32 values; see the reference for the mathematics. The pieces
(column key, cell, offset, value) are public to this package because the
NumPy backend's table path (:mod:`.backend`) reuses them.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .. import gf
from ..reference.hashes import JITTER_KEY, STRATUM_KEY, SUBSTRATUM_KEY
from .floats import F32, jitter_value, sample_value
from .hashes import U32, block_seed, permute, randfloat


def column_key(p, j, dmax: int) -> np.ndarray:
    """``block_seed(p, j // dmax) * (j % dmax + 1)``: times STRATUM_KEY,
    SUBSTRATUM_KEY and JITTER_KEY it gives the dimension seeds."""
    j = np.asarray(j, dtype=U32)
    return block_seed(p, j // U32(dmax)) * (j % U32(dmax) + U32(1))


@lru_cache(maxsize=None)
def field(q: int) -> "Field":
    """The (cached) :class:`Field` of order q: its uint32 tables are built once,
    not per chunk."""
    return Field(q)


class Field:
    """GF(q) arithmetic on uint32 code arrays: mod q for prime q, else the
    lookup tables of :func:`pyoa.gf.tables` (the same tables the kernels read)."""

    def __init__(self, q: int):
        self.q = q
        self.tabled = gf.prime_power(q)[1] > 1
        if self.tabled:
            self._add, self._mul = (t.astype(U32) for t in gf.tables(q))

    def add(self, a, b):
        if self.tabled:
            return self._add[a * U32(self.q) + b]
        return (a + b) % U32(self.q)

    def mul(self, a, b):
        if self.tabled:
            return self._mul[a * U32(self.q) + b]
        return (a * b) % U32(self.q)


def bose_cell(i, col, s: int):
    """``(A_ij, A_ik)`` of Bose column ``col < s+1`` and its partner column, over GF(s)."""
    i, col = np.asarray(i, dtype=U32), np.asarray(col, dtype=U32)
    F = field(s)
    S = U32(s)
    a0, a1 = i // S, i % S
    k = np.where(col % U32(2) == 1, col - U32(1), col + U32(1))
    # Columns 0 and 1 are clipped to multiplier 0 only to keep table indices
    # in range; np.where then discards those lanes.
    m_j = np.where(col >= 2, col - U32(1), U32(0)) % S
    m_k = np.where(col >= 2, k - U32(1), U32(0)) % S
    aij = np.where(col == 0, a0, np.where(col == 1, a1, F.add(a0, F.mul(m_j, a1))))
    aik = np.where(col == 0, a1, np.where(col == 1, a0, F.add(a0, F.mul(m_k, a1))))
    return aij, aik


def bush_cell(i, col, s: int, t: int):
    """``(A_ij, u)`` of Bush column ``col < s+1``: the row polynomial at ``col``
    (or its leading coefficient for ``col == s``) and the sub-stratum index."""
    i, col = np.asarray(i, dtype=U32), np.asarray(col, dtype=U32)
    F = field(s)
    S = U32(s)
    M = U32(s ** (t - 1))
    x = np.minimum(col, S - U32(1))  # column s evaluates nothing; keep indices in range
    acc = np.zeros(np.broadcast(i, col).shape, dtype=U32)
    for l in range(t - 1, -1, -1):  # Horner
        acc = F.add(F.mul(acc, x), (i // S ** U32(l)) % S)
    lead = i // (M)  # c_{t-1}
    last = col == S
    return np.where(last, lead, acc), np.where(last, i % M, i // S)


def cmjnd_cell(i, col, s: int):
    """``(A_ij, v)``: digit ``col`` of ``i`` in base ``s``, and the other digits."""
    i = np.asarray(i, dtype=U32)
    S = U32(s)
    sj = S ** np.asarray(col, dtype=U32)  # s**col <= s**(t-1) < 2**24
    return (i // sj) % S, i % sj + (i // (sj * S)) * sj


def offset_sub(offset: str, u, M: int, cell_key, aij, P2):
    """The sub-stratum (float32) of each offset style; ``cell_key`` seeds ``j``."""
    if offset == "centered":
        return F32((M - 1) / 2)
    seed = {"j": cell_key * P2, "mj": (aij + U32(1)) * P2, "cmj": P2}[offset]
    return permute(u, M, seed)


def oa_value(i, stratum, sub, P3, M: int, s: int, jitter: float) -> np.ndarray:
    """``(stratum + (sub + jitter) / M) / s`` with the jitter of sample ``i``."""
    return sample_value(stratum, sub, jitter_value(randfloat(i, P3), F32(jitter)), M, s)


def bose(i, j, s: int, p, offset: str = "cmj", jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.bose` (parameters assumed valid)."""
    i, j = np.asarray(i, dtype=U32), np.asarray(j, dtype=U32)
    q = column_key(p, j, s + 1)
    aij, aik = bose_cell(i, j % U32(s + 1), s)
    stratum = permute(aij, s, q * U32(STRATUM_KEY))
    sub = offset_sub(offset, aik, s, aik * U32(s) + aij + U32(1), aij, q * U32(SUBSTRATUM_KEY))
    return oa_value(i, stratum, sub, q * U32(JITTER_KEY), s, s, jitter)


def cmjnd(i, j, s: int, t: int, p, offset: str = "cmj", jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.cmjnd` (parameters assumed valid)."""
    i, j = np.asarray(i, dtype=U32), np.asarray(j, dtype=U32)
    q = column_key(p, j, t)
    M = s ** (t - 1)
    aij, v = cmjnd_cell(i, j % U32(t), s)
    stratum = permute(aij, s, q * U32(STRATUM_KEY))
    sub = offset_sub(offset, v, M, i + U32(1), aij, q * U32(SUBSTRATUM_KEY))
    return oa_value(i, stratum, sub, q * U32(JITTER_KEY), M, s, jitter)


def bush(i, j, s: int, t: int, p, offset: str = "cmj", jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.bush` (parameters assumed valid)."""
    i, j = np.asarray(i, dtype=U32), np.asarray(j, dtype=U32)
    q = column_key(p, j, s + 1)
    M = s ** (t - 1)
    aij, u = bush_cell(i, j % U32(s + 1), s, t)
    stratum = permute(aij, s, q * U32(STRATUM_KEY))
    sub = offset_sub(offset, u, M, i + U32(1), aij, q * U32(SUBSTRATUM_KEY))
    return oa_value(i, stratum, sub, q * U32(JITTER_KEY), M, s, jitter)


@lru_cache(maxsize=None)
def _ak_arrays(q: int) -> tuple[np.ndarray, ...]:
    """:func:`pyoa.gf.ak_constants` as uint32 arrays, built once per q."""
    return tuple(np.asarray(v, dtype=U32) for v in gf.ak_constants(q))


def addelman_kempthorne_cell(i, col, q: int):
    """``(A_ij, u)`` of Addelman-Kempthorne column ``col < 2q+1`` (see the reference)."""
    i, col = np.asarray(i, dtype=U32), np.asarray(col, dtype=U32)
    F = field(q)
    Q = U32(q)
    kappa, b, k, c = _ak_arrays(q)
    h, x, y = i // (Q * Q), (i // Q) % Q, i % Q
    x2 = F.mul(x, x)
    hq = h * Q
    # Columns 1..q-1 use multiplier m = col; q..2q-1 use m = col - q (m = 0
    # is column q, since k[0] = c[0] = 0). Out-of-range m are clamped to 0 to
    # keep table indices valid; np.where discards those lanes.
    mA = np.where((col >= 1) & (col < Q), col, U32(0))
    mB = np.where((col >= Q) & (col < 2 * Q), col - Q, U32(0))
    colA = F.add(F.add(x, F.mul(mA, y)), np.where(h == 1, b[mA], U32(0)))
    colB = np.where(
        h == 1,
        F.add(F.add(F.add(y, F.mul(k[mB], x)), F.mul(kappa, x2)), c[mB]),
        F.add(F.add(y, F.mul(mB, x)), x2),
    )
    aij = np.where(col == 0, y, np.where(col < Q, colA, np.where(col < 2 * Q, colB, x)))
    u = hq + np.where((col == 0) | ((col >= Q) & (col < 2 * Q)), x, y)
    return aij, u


def bose_bush_cell(i, col, s: int):
    """``(A_ij, u)`` of Bose-Bush column ``col < 2s+1``, computed in GF(2s)."""
    i, col = np.asarray(i, dtype=U32), np.asarray(col, dtype=U32)
    F = field(2 * s)
    S = U32(s)
    x, k = i // S, i % S
    a = (F.mul(x, np.minimum(col, U32(2 * s - 1))) % S) ^ k
    last = col == U32(2 * s)
    return np.where(last, x % S, a), np.where(last, (x // S) * S + k, x)


def _index2(cell, i, j, s: int, p, offset: str, jitter: float) -> np.ndarray:
    i, j = np.asarray(i, dtype=U32), np.asarray(j, dtype=U32)
    q = column_key(p, j, 2 * s + 1)
    aij, u = cell(i, j % U32(2 * s + 1), s)
    stratum = permute(aij, s, q * U32(STRATUM_KEY))
    sub = offset_sub(offset, u, 2 * s, i + U32(1), aij, q * U32(SUBSTRATUM_KEY))
    return oa_value(i, stratum, sub, q * U32(JITTER_KEY), 2 * s, s, jitter)


def addelman_kempthorne(i, j, q: int, p, offset: str = "cmj", jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.addelman_kempthorne` (parameters assumed valid)."""
    return _index2(addelman_kempthorne_cell, i, j, q, p, offset, jitter)


def bose_bush(i, j, s: int, p, offset: str = "cmj", jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.bose_bush` (parameters assumed valid)."""
    return _index2(bose_bush_cell, i, j, s, p, offset, jitter)
