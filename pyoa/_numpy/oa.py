"""Orthogonal-array samplers over NumPy arrays (mirrors :mod:`pyoa.reference.oa`
and, piece by piece, ``kernels/include/pyoa/oa.h``).

Each function takes broadcastable arrays of sample indices ``i``, dimensions
``j`` (any ``j >= 0``; blocks per docs/spec.md section 6) and array seeds ``p`` and
returns float32 values; see the reference for the mathematics. The pieces
(block rule, cell, offset) are public to this package because the NumPy
backend's table path (:mod:`.backend`) reuses them.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .. import gf
from ..reference import oa as G  # the constructions' geometries (N, B, s, M)
from ..reference.hashes import BLOCK_ORDER_KEY, JITTER_KEY, STRATUM_KEY, SUBSTRATUM_KEY
from .floats import F32, jitter_value, sample_value
from .hashes import U32, block_seed, hash_pair, mix32, permute, randfloat


def locate(p, i, j, B: int, N: int):
    """The block rule (docs/spec.md section 6, :func:`pyoa.reference.hashes.locate`)
    over arrays: ``(P, row, col)`` of dimension ``j`` of sample ``i`` in an
    array of ``N`` rows and ``B`` columns with seed ``p``. Block 0 reads row
    ``i`` (its order seed is 0, and ``permute`` with seed 0 is the identity);
    block ``b >= 1`` reads row :func:`block_row` of ``i``."""
    i, j = np.asarray(i, dtype=U32), np.asarray(j, dtype=U32)
    block, col = j // U32(B), j % U32(B)
    P = block_seed(p, block)
    return P, block_row(i, N, block_order_seed(P, block, N)), col


def block_row(i, N: int, r) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.hashes.block_row`: ``permute(permute(i,
    N, r), N, mix32(r))``, the identity where ``r == 0``."""
    return permute(permute(i, N, r), N, mix32(r))


def block_order_seed(P, block, N: int) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.hashes.block_order_seed` (0 for block 0)."""
    P, block = np.broadcast_arrays(np.asarray(P, dtype=U32), np.asarray(block, dtype=U32))
    return np.where(block == 0, U32(0), hash_pair(P, N, BLOCK_ORDER_KEY))


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


def oa_value(i, j, p, offset: str, jitter: float, geometry, cell) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.oa.oa_value`: the frame every
    construction shares. The block rule (:func:`locate`) gives the copy's seed,
    the row and the column; ``cell(row, col)`` gives ``(A_ij, u, cell_key)``;
    then stratum, offset and jitter (docs/spec.md section 5.2)."""
    N, B, s, M = geometry
    P, row, col = locate(p, i, j, B, N)
    aij, u, cell_key = cell(row, col)
    q = P * (col + U32(1))  # times the three keys: the column's seeds (section 3.3)
    stratum = permute(aij, s, q * U32(STRATUM_KEY))
    sub = offset_sub(offset, u, M, cell_key, aij, q * U32(SUBSTRATUM_KEY))
    return sample_value(stratum, sub, jitter_value(randfloat(row, q * U32(JITTER_KEY)), F32(jitter)), M, s)


def bose(i, j, s: int, p, offset: str = "cmj", jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.bose` (parameters assumed valid)."""
    def cell(row, col):
        aij, aik = bose_cell(row, col, s)
        return aij, aik, aik * U32(s) + aij + U32(1)

    return oa_value(i, j, p, offset, jitter, G.bose_geometry(s), cell)


def _row_key(cell, *shape):
    """A construction's cell with the 'j' offset's key ``row + 1``."""
    return lambda row, col: (*cell(row, col, *shape), row + U32(1))


def cmjnd(i, j, s: int, t: int, p, offset: str = "cmj", jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.cmjnd` (parameters assumed valid)."""
    return oa_value(i, j, p, offset, jitter, G.cmjnd_geometry(s, t), _row_key(cmjnd_cell, s))


def bush(i, j, s: int, t: int, p, offset: str = "cmj", jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.bush` (parameters assumed valid)."""
    return oa_value(i, j, p, offset, jitter, G.bush_geometry(s, t), _row_key(bush_cell, s, t))


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


def addelman_kempthorne(i, j, q: int, p, offset: str = "cmj", jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.addelman_kempthorne` (parameters assumed valid)."""
    return oa_value(i, j, p, offset, jitter, G.addelman_kempthorne_geometry(q), _row_key(addelman_kempthorne_cell, q))


def bose_bush(i, j, s: int, p, offset: str = "cmj", jitter: float = 1.0) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.bose_bush` (parameters assumed valid)."""
    return oa_value(i, j, p, offset, jitter, G.bose_bush_geometry(s), _row_key(bose_bush_cell, s))
