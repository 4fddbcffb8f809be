"""Orthogonal-array samplers in Dr.Jit operations (mirrors :mod:`pyoa._numpy.oa`
and ``kernels/include/pyoa/oa.h`` piece by piece; the mathematics is in :mod:`pyoa.reference.oa`
and docs/spec.md sections 4 to 6).

Each sampler takes ``UInt32`` arrays of sample indices ``i``, dimensions ``j``
(any ``j >= 0``; blocks per section 6) and point-set seeds ``p``; its shape
(``s``, ``t``), offset style and jitter amount are Python values fixed when the
code is traced. Values are ``Float32`` arrays of the same backend.

As in the reference, a construction supplies only its cell (``*_cell``: the
integer cell of row ``row`` in column ``col``); one shared frame,
:func:`oa_value`, applies the block rule (:func:`.hashes.locate`) and turns
the cell into x.
"""

from __future__ import annotations

from functools import cache

import drjit as dr
import numpy as np

from .. import gf
from ..reference import oa as G  # the constructions' geometries (N, B, s, M)
from ..reference.hashes import JITTER_KEY, STRATUM_KEY, SUBSTRATUM_KEY
from .floats import centered_value, jitter_value, sample_value
from .hashes import locate, permute, permutes, randfloat


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
    if not F.tabled:
        # Prime s: each entry as one remainder, (c0 a0 + c1 a1) % s, with the column's coefficients
        # (1, 0), (0, 1) or (1, col - 1): the same integers as the selects below, but one remainder
        # per entry instead of two (the sums stay below s + s^2). Inside Mitsuba the column is the
        # same in every lane, so the coefficients cost nothing per lane; the remainders do (a
        # multiply-high each), and the cell was a third of a value's time there.
        def entry(c):
            c0 = dr.select(c == 1, U(0), U(1))
            c1 = dr.select(c == 0, U(0), dr.select(c == 1, U(1), (c - 1) % s))
            return (c0 * a0 + c1 * a1) % s

        return entry(col), entry(k)
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


def offset_seed(offset: str, cell_key, aij, P2):
    """The seed of the sub-stratum permutation of the hashed offset styles (``centered`` has none)."""
    return {"j": cell_key * P2, "mj": (aij + 1) * P2, "cmj": P2}[offset]


def oa_value(i, j, p, offset: str, jitter: float, geometry, cell, located=None):
    """:func:`pyoa.reference.oa.oa_value` over Dr.Jit arrays: the frame every
    construction shares. The block rule (:func:`.hashes.locate`) gives the
    copy's seed, the row and the column; ``cell(row, col)`` gives
    ``(A_ij, u, cell_key)``; then stratum, offset and the jitter of the row
    (docs/spec.md section 5.2).

    ``located``, when given, is ``(P, row)`` of dimension ``j``'s block as
    :func:`.hashes.locate` gives them, kept by a caller that draws the
    dimensions of a block one after another (the Mitsuba plugin keeps them
    per lane, :mod:`pyoa.mitsuba`): they depend on (pixel, block, sample)
    only, so the block's hashes and its two row permutations are then paid
    once per block, not once per value. The bits are the same."""
    N, B, s, M = geometry
    if located is None:
        P, row, col = locate(p, i, j, B, N)
    else:
        (P, row), col = located, type(located[1])(j) % B
    aij, u, cell_key = cell(row, col)
    q = P * (col + 1)  # times the three keys: the column's seeds (section 3.3)
    jit = jitter_value(randfloat(row, q * JITTER_KEY), jitter)
    if offset == "centered":
        return centered_value(permute(aij, s, q * STRATUM_KEY), jit, M, s)
    # both permutations' walks in one loop (permutes says why)
    stratum, sub = permutes((aij, s, q * STRATUM_KEY), (u, M, offset_seed(offset, cell_key, aij, q * SUBSTRATUM_KEY)))
    return sample_value(stratum, sub, jit, M, s)


def _row_key(cell, *shape):
    """A construction's cell with the 'j' offset's key ``row + 1``."""
    return lambda row, col: (*cell(row, col, *shape), row + 1)


def bose(i, j, s: int, p, offset: str = "cmj", jitter: float = 1.0, located=None):
    """:func:`pyoa.reference.bose` over Dr.Jit arrays."""
    def cell(row, col):
        aij, aik = bose_cell(row, col, s)
        return aij, aik, aik * s + aij + 1  # the 'j' offset's key is the (A_ij, A_ik) cell

    return oa_value(i, j, p, offset, jitter, G.bose_geometry(s), cell, located)


def cmjnd(i, j, s: int, t: int, p, offset: str = "cmj", jitter: float = 1.0, located=None):
    """:func:`pyoa.reference.cmjnd` over Dr.Jit arrays."""
    return oa_value(i, j, p, offset, jitter, G.cmjnd_geometry(s, t), _row_key(cmjnd_cell, s, t), located)


def bush(i, j, s: int, t: int, p, offset: str = "cmj", jitter: float = 1.0, located=None):
    """:func:`pyoa.reference.bush` over Dr.Jit arrays."""
    return oa_value(i, j, p, offset, jitter, G.bush_geometry(s, t), _row_key(bush_cell, s, t), located)


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


def addelman_kempthorne(i, j, q: int, p, offset: str = "cmj", jitter: float = 1.0, located=None):
    """:func:`pyoa.reference.addelman_kempthorne` over Dr.Jit arrays."""
    return oa_value(i, j, p, offset, jitter, G.addelman_kempthorne_geometry(q), _row_key(addelman_kempthorne_cell, q), located)


def bose_bush(i, j, s: int, p, offset: str = "cmj", jitter: float = 1.0, located=None):
    """:func:`pyoa.reference.bose_bush` over Dr.Jit arrays."""
    return oa_value(i, j, p, offset, jitter, G.bose_bush_geometry(s), _row_key(bose_bush_cell, s), located)
