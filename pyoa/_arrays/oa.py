"""The orthogonal-array samplers over an array namespace (:mod:`pyoa._arrays`):
the mathematics of :mod:`pyoa.reference.oa` (docs/spec.md sections 4 to 6)
on uint32 arrays, piece by piece as ``kernels/include/pyoa/oa.h``.

A construction supplies only its cell (``*_cell``: the integer cell of row
``row`` in column ``col``) and the ``j`` offset's cell key; one frame,
:func:`oa_value`, applies the block rule (:mod:`.blocks`) and turns the cell
into x. Each sampler takes uint32 arrays of sample indices ``i``,
dimensions ``j`` (any ``j >= 0``) and array seeds ``p``, which broadcast;
its shape (``s``, ``t``), offset style and jitter amount are Python values
(in Dr.Jit, fixed when the code is traced), assumed valid (the catalogue
checked them). Values are float32 arrays.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..tables import gf
from ..reference import oa as G  # the constructions' geometries (N, B, s, M)
from .blocks import locate
from .floats import jitter_value, sample_value
from .hashes import dimension_seeds, permute, permutes, randfloat


class Field:
    """GF(q) arithmetic on uint32 code arrays: mod q for a prime q, else
    gathers from :func:`pyoa.tables.gf.tables` (the tables the kernels read too)."""

    def __init__(self, xp, q: int):
        self.xp, self.q = xp, q
        self.tabled = gf.prime_power(q)[1] > 1
        if self.tabled:
            self._add, self._mul = (np.asarray(t, dtype=np.uint32) for t in gf.tables(q))

    def add(self, a, b):
        if self.tabled:
            return self.xp.gather(self._add, a * self.q + b)
        return (a + b) % self.q

    def mul(self, a, b):
        if self.tabled:
            return self.xp.gather(self._mul, a * self.q + b)
        return (a * b) % self.q


@lru_cache(maxsize=None)
def field(xp, q: int) -> Field:
    """The (cached) :class:`Field` of order q: its tables are built once per namespace."""
    return Field(xp, q)


def bose_cell(xp, i, col, s: int):
    """``(A_ij, A_ik)`` of Bose column ``col < s+1`` and its partner column, over GF(s)."""
    i, col = xp.as_uint32(i, col)
    F = field(xp, s)
    a0, a1 = i // s, i % s
    k = xp.select(col % 2 == 1, col - 1, col + 1)
    if not F.tabled:
        # Prime s: each entry as one remainder, (c0 a0 + c1 a1) % s, with the column's coefficients
        # (1, 0), (0, 1) or (1, col - 1): the same integers as the field's form below, with one
        # remainder per entry instead of two (the sums stay below s + s^2). The coefficients depend
        # on the column only (the same in every lane inside Mitsuba, small arrays in NumPy); the
        # remainders are per value (a multiply-high each in Dr.Jit, where the cell was a third of a
        # value's time).
        def entry(c):
            c1 = xp.select(c == 0, 0, xp.select(c == 1, 1, (c - 1) % s))
            return (xp.u32(c != 1) * a0 + c1 * a1) % s

        return entry(col), entry(k)
    # columns 0 and 1 take multiplier 0 only to keep table indices in range; the selects drop those lanes
    m_j = xp.select(col >= 2, col - 1, 0) % s
    m_k = xp.select(col >= 2, k - 1, 0) % s
    aij = xp.select(col == 0, a0, xp.select(col == 1, a1, F.add(a0, F.mul(m_j, a1))))
    aik = xp.select(col == 0, a1, xp.select(col == 1, a0, F.add(a0, F.mul(m_k, a1))))
    return aij, aik


def bush_cell(xp, i, col, s: int, t: int):
    """``(A_ij, u)`` of Bush column ``col < s+1``: the row polynomial at ``col``
    (or its leading coefficient for ``col == s``) and the sub-stratum index."""
    i, col = xp.as_uint32(i, col)
    F = field(xp, s)
    M = s ** (t - 1)
    x = xp.minimum(col, s - 1)  # column s evaluates nothing; keep table indices in range
    acc = 0
    for l in range(t - 1, -1, -1):  # Horner
        acc = F.add(F.mul(acc, x), (i // s**l) % s)
    last = col == s
    return xp.select(last, i // M, acc), xp.select(last, i % M, i // s)


def cmjnd_cell(xp, i, col, s: int):
    """``(A_ij, v)``: digit ``col`` of ``i`` in base ``s``, and the other digits."""
    i, col = xp.as_uint32(i, col)
    sj = xp.power(s, col)  # s**col <= s**(t-1) < 2**24
    return (i // sj) % s, i % sj + (i // (sj * s)) * sj


@lru_cache(maxsize=None)
def _ak_tables(q: int) -> tuple:
    """:func:`pyoa.tables.gf.ak_constants`: kappa, and b, k, c as host uint32 arrays."""
    kappa, *tables = gf.ak_constants(q)
    return (kappa, *(np.asarray(v, dtype=np.uint32) for v in tables))


def addelman_kempthorne_cell(xp, i, col, q: int):
    """``(A_ij, u)`` of Addelman-Kempthorne column ``col < 2q+1`` (see the reference)."""
    i, col = xp.as_uint32(i, col)
    F = field(xp, q)
    kappa, b, k, c = _ak_tables(q)
    h, x, y = i // (q * q), (i // q) % q, i % q
    x2 = F.mul(x, x)
    # Columns 1..q-1 use multiplier m = col; q..2q-1 use m = col - q (m = 0
    # is column q, since k[0] = c[0] = 0). Other lanes take m = 0 (in
    # range for the tables); the selects drop them.
    mA = xp.select((col >= 1) & (col < q), col, 0)
    mB = xp.select((col >= q) & (col < 2 * q), col - q, 0)
    colA = F.add(F.add(x, F.mul(mA, y)), xp.select(h == 1, xp.gather(b, mA), 0))
    colB = xp.select(
        h == 1,
        F.add(F.add(F.add(y, F.mul(xp.gather(k, mB), x)), F.mul(kappa, x2)), xp.gather(c, mB)),
        F.add(F.add(y, F.mul(mB, x)), x2),
    )
    aij = xp.select(col == 0, y, xp.select(col < q, colA, xp.select(col < 2 * q, colB, x)))
    u = h * q + xp.select((col == 0) | ((col >= q) & (col < 2 * q)), x, y)
    return aij, u


def bose_bush_cell(xp, i, col, s: int):
    """``(A_ij, u)`` of Bose-Bush column ``col < 2s+1``, computed in GF(2s)."""
    i, col = xp.as_uint32(i, col)
    F = field(xp, 2 * s)
    x, k = i // s, i % s
    a = (F.mul(x, xp.minimum(col, 2 * s - 1)) % s) ^ k
    last = col == 2 * s
    return xp.select(last, x % s, a), xp.select(last, (x // s) * s + k, x)


def oa_value(xp, i, j, p, offset: str, jitter: float, geometry, cell, cell_key, located=None):
    """:func:`pyoa.reference.oa.oa_value` over arrays: the frame every construction shares.

    The block rule (:func:`.blocks.locate`) gives the copy's seed, the row
    and the column; ``cell(row, col)`` gives ``(A_ij, u)`` and
    ``cell_key(row, A_ij, u)`` the ``j`` offset's key; then stratum, offset
    and the jitter of the row (docs/spec.md section 5.2).

    ``located``, when given, is ``(P, row)`` of dimension ``j``'s block as
    :func:`.blocks.locate_block` gives them, kept by a caller that draws the
    dimensions of a block one after another (the Mitsuba plugin keeps them
    per lane, :mod:`pyoa.mitsuba`): they depend on (pixel, block, sample)
    only, so the block's hashes and its two row permutations are then paid
    once per block, not once per value. The bits are the same.
    """
    N, B, s, M = geometry
    if located is None:
        P, row, col = locate(xp, p, i, j, B, N)
    else:
        (P, row), col = located, xp.as_uint32(j, located[1])[0] % B
    aij, u = cell(row, col)
    P1, P2, P3 = dimension_seeds(xp, P, col)
    jit = jitter_value(xp, randfloat(xp, row, P3), jitter)
    if offset == "centered":
        return sample_value(xp, permute(xp, aij, s, P1), (M - 1) / 2, jit, M, s)
    # the sub-stratum seed of the offset style (docs/spec.md section 4), only that one computed
    seed = {"j": lambda: cell_key(row, aij, u) * P2, "mj": lambda: (aij + 1) * P2, "cmj": lambda: P2}[offset]()
    # both permutations' walks in one loop (permutes says why)
    stratum, sub = permutes(xp, (aij, s, P1), (u, M, seed))
    return sample_value(xp, stratum, sub, jit, M, s)


def _row_key(row, aij, u):
    """The ``j`` offset's cell key of every construction but Bose: ``row + 1``."""
    return row + 1


def bose(xp, i, j, s: int, p, offset: str = "cmj", jitter: float = 1.0, located=None):
    """:func:`pyoa.reference.bose` over arrays."""
    return oa_value(xp, i, j, p, offset, jitter, G.bose_geometry(s), lambda row, col: bose_cell(xp, row, col, s),
                    lambda row, aij, aik: aik * s + aij + 1, located)  # Bose's key: its (A_ij, A_ik) cell


def cmjnd(xp, i, j, s: int, t: int, p, offset: str = "cmj", jitter: float = 1.0, located=None):
    """:func:`pyoa.reference.cmjnd` over arrays."""
    return oa_value(xp, i, j, p, offset, jitter, G.cmjnd_geometry(s, t), lambda row, col: cmjnd_cell(xp, row, col, s),
                    _row_key, located)


def bush(xp, i, j, s: int, t: int, p, offset: str = "cmj", jitter: float = 1.0, located=None):
    """:func:`pyoa.reference.bush` over arrays."""
    return oa_value(xp, i, j, p, offset, jitter, G.bush_geometry(s, t), lambda row, col: bush_cell(xp, row, col, s, t),
                    _row_key, located)


def addelman_kempthorne(xp, i, j, q: int, p, offset: str = "cmj", jitter: float = 1.0, located=None):
    """:func:`pyoa.reference.addelman_kempthorne` over arrays."""
    return oa_value(xp, i, j, p, offset, jitter, G.addelman_kempthorne_geometry(q),
                    lambda row, col: addelman_kempthorne_cell(xp, row, col, q), _row_key, located)


def bose_bush(xp, i, j, s: int, p, offset: str = "cmj", jitter: float = 1.0, located=None):
    """:func:`pyoa.reference.bose_bush` over arrays."""
    return oa_value(xp, i, j, p, offset, jitter, G.bose_bush_geometry(s),
                    lambda row, col: bose_bush_cell(xp, row, col, s), _row_key, located)
