"""Orthogonal-array samplers in Dr.Jit operations (mirrors :mod:`pyoa._numpy.oa`
and ``kernels/oa.cl`` piece by piece; the mathematics is in :mod:`pyoa.reference.oa`
and docs/spec.md sections 4 to 6).

Each sampler takes ``UInt32`` arrays of sample indices ``i``, dimensions ``j``
(any ``j >= 0``; blocks per section 6) and point-set seeds ``p``; its shape
(``s``, ``t``), offset style and jitter amount are Python values fixed when the
code is traced. Values are ``Float32`` arrays of the same backend.
"""

from __future__ import annotations

from functools import cache

import drjit as dr
import numpy as np

from .. import gf
from ..reference.hashes import JITTER_KEY, STRATUM_KEY, SUBSTRATUM_KEY
from .floats import centered_value, jitter_value, sample_value
from .hashes import block_seed, permute, randfloat


def column_key(p, j, dmax: int):
    """``block_seed(p, j // dmax) * (j % dmax + 1)``: the dimension seeds' common factor."""
    return block_seed(p, j // dmax) * (j % dmax + 1)


@cache
def _table(U, values: tuple) -> object:
    """A read-only device copy of a uint32 table (one per array type and contents)."""
    return U(np.asarray(values, dtype=np.uint32))


class Field:
    """GF(q) arithmetic on ``UInt32`` arrays: mod q for a prime q, else gathers
    from :func:`pyoa.gf.tables` (the tables the kernels and NumPy read)."""

    def __init__(self, U, q: int):
        self.U, self.q = U, q
        self.tabled = gf.prime_power(q)[1] > 1
        if self.tabled:
            add, mul = gf.tables(q)
            self._add = _table(U, tuple(int(v) for v in add))
            self._mul = _table(U, tuple(int(v) for v in mul))

    def add(self, a, b):
        if self.tabled:
            return dr.gather(self.U, self._add, a * self.q + b)
        return (a + b) % self.q

    def mul(self, a, b):
        if self.tabled:
            return dr.gather(self.U, self._mul, a * self.q + b)
        return (a * b) % self.q


@cache
def field(U, q: int) -> Field:
    return Field(U, q)


def bose_cell(i, col, s: int):
    """``(A_ij, A_ik)`` of Bose column ``col < s+1`` and its partner column, over GF(s)."""
    U = type(i)
    F = field(U, s)
    a0, a1 = i // s, i % s
    k = dr.select(col % 2 == 1, col - 1, col + 1)
    # columns 0 and 1 use multiplier 0 only to keep table indices in range
    m_j = dr.select(col >= 2, col - 1, U(0)) % s
    m_k = dr.select(col >= 2, k - 1, U(0)) % s
    aij = dr.select(col == 0, a0, dr.select(col == 1, a1, F.add(a0, F.mul(m_j, a1))))
    aik = dr.select(col == 0, a1, dr.select(col == 1, a0, F.add(a0, F.mul(m_k, a1))))
    return aij, aik


def bush_cell(i, col, s: int, t: int):
    """``(A_ij, u)`` of Bush column ``col < s+1`` (the row polynomial at ``col``,
    its leading coefficient for ``col == s``) and the sub-stratum index."""
    U = type(i)
    F = field(U, s)
    M = s ** (t - 1)
    x = dr.minimum(col, U(s - 1))  # column s evaluates nothing; keep indices in range
    acc = U(0)
    for l in range(t - 1, -1, -1):  # Horner
        acc = F.add(F.mul(acc, x), (i // s**l) % s)
    last = col == s
    return dr.select(last, i // M, acc), dr.select(last, i % M, i // s)


def cmjnd_cell(i, col, s: int, t: int):
    """``(A_ij, v)``: digit ``col`` of ``i`` in base ``s``, and the other digits."""
    U = type(i)
    sj = U(1)
    for k in range(1, t):  # s**col for col < t, without a per-lane power
        sj = dr.select(col >= k, sj * s, sj)
    return (i // sj) % s, i % sj + (i // (sj * s)) * sj


def offset_sub(offset: str, u, M: int, cell_key, aij, P2):
    """The integer sub-stratum of the hashed offset styles (``centered`` has none)."""
    seed = {"j": cell_key * P2, "mj": (aij + 1) * P2, "cmj": P2}[offset]
    return permute(u, M, seed)


def oa_value(i, stratum, u, M: int, s: int, offset: str, jitter: float, q, cell_key, aij):
    """x from the stratum, the sub-stratum index ``u`` and the column key ``q``."""
    jit = jitter_value(randfloat(i, q * JITTER_KEY), jitter)
    if offset == "centered":
        return centered_value(stratum, jit, M, s)
    sub = offset_sub(offset, u, M, cell_key, aij, q * SUBSTRATUM_KEY)
    return sample_value(stratum, sub, jit, M, s)


def bose(i, j, s: int, p, offset: str = "cmj", jitter: float = 1.0):
    """:func:`pyoa.reference.bose` over Dr.Jit arrays."""
    q = column_key(p, j, s + 1)
    aij, aik = bose_cell(i, j % (s + 1), s)
    stratum = permute(aij, s, q * STRATUM_KEY)
    return oa_value(i, stratum, aik, s, s, offset, jitter, q, aik * s + aij + 1, aij)


def cmjnd(i, j, s: int, t: int, p, offset: str = "cmj", jitter: float = 1.0):
    """:func:`pyoa.reference.cmjnd` over Dr.Jit arrays."""
    q = column_key(p, j, t)
    aij, v = cmjnd_cell(i, j % t, s, t)
    stratum = permute(aij, s, q * STRATUM_KEY)
    return oa_value(i, stratum, v, s ** (t - 1), s, offset, jitter, q, i + 1, aij)


def bush(i, j, s: int, t: int, p, offset: str = "cmj", jitter: float = 1.0):
    """:func:`pyoa.reference.bush` over Dr.Jit arrays."""
    q = column_key(p, j, s + 1)
    aij, u = bush_cell(i, j % (s + 1), s, t)
    stratum = permute(aij, s, q * STRATUM_KEY)
    return oa_value(i, stratum, u, s ** (t - 1), s, offset, jitter, q, i + 1, aij)


def addelman_kempthorne_cell(i, col, q: int):
    """``(A_ij, u)`` of Addelman-Kempthorne column ``col < 2q+1``."""
    U = type(i)
    F = field(U, q)
    kappa, b, k, c = gf.ak_constants(q)
    tb, tk, tc = (_table(U, tuple(int(v) for v in arr)) for arr in (b, k, c))
    h, x, y = i // (q * q), (i // q) % q, i % q
    x2 = F.mul(x, x)
    # columns 1..q-1 use m = col, q..2q-1 use m = col - q; other lanes take m = 0 (in range, discarded)
    mA = dr.select((col >= 1) & (col < q), col, U(0))
    mB = dr.select((col >= q) & (col < 2 * q), col - q, U(0))
    colA = F.add(F.add(x, F.mul(mA, y)), dr.select(h == 1, dr.gather(U, tb, mA), U(0)))
    colB = dr.select(
        h == 1,
        F.add(F.add(F.add(y, F.mul(dr.gather(U, tk, mB), x)), F.mul(U(kappa), x2)), dr.gather(U, tc, mB)),
        F.add(F.add(y, F.mul(mB, x)), x2),
    )
    aij = dr.select(col == 0, y, dr.select(col < q, colA, dr.select(col < 2 * q, colB, x)))
    u = h * q + dr.select((col == 0) | ((col >= q) & (col < 2 * q)), x, y)
    return aij, u


def bose_bush_cell(i, col, s: int):
    """``(A_ij, u)`` of Bose-Bush column ``col < 2s+1``, computed in GF(2s)."""
    U = type(i)
    F = field(U, 2 * s)
    x, k = i // s, i % s
    a = (F.mul(x, dr.minimum(col, U(2 * s - 1))) % s) ^ k
    last = col == 2 * s
    return dr.select(last, x % s, a), dr.select(last, (x // s) * s + k, x)


def _index2(cell, i, j, s: int, p, offset: str, jitter: float):
    q = column_key(p, j, 2 * s + 1)
    aij, u = cell(i, j % (2 * s + 1), s)
    stratum = permute(aij, s, q * STRATUM_KEY)
    return oa_value(i, stratum, u, 2 * s, s, offset, jitter, q, i + 1, aij)


def addelman_kempthorne(i, j, q: int, p, offset: str = "cmj", jitter: float = 1.0):
    """:func:`pyoa.reference.addelman_kempthorne` over Dr.Jit arrays."""
    return _index2(addelman_kempthorne_cell, i, j, q, p, offset, jitter)


def bose_bush(i, j, s: int, p, offset: str = "cmj", jitter: float = 1.0):
    """:func:`pyoa.reference.bose_bush` over Dr.Jit arrays."""
    return _index2(bose_bush_cell, i, j, s, p, offset, jitter)
