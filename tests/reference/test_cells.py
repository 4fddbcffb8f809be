"""The integer cells of the reference samplers (``pyoa.reference.oa.*_cell``):
``(A_ij, u)`` of one sample in one column, ``u`` the sub-stratum index (Bose:
the partner column's entry ``A_ik``).

Three checks: the reference cells equal NumPy's (``pyoa._numpy.oa.*_cell``)
for every sample and column of small arrays (the kernels' cells are checked
against NumPy's in tests/_opencl/test_kernels.py); the reference cells form
an orthogonal array of the construction's strength and index; and inside each
stratum of a column the sub-stratum index takes every value in ``[0, M)``
exactly once, which is what makes ``mj`` and ``cmj`` Latin hypercubes. A last
test ties the public samplers to their cells through the block rule.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pyoa._numpy import oa as noa
from pyoa.reference import oa as roa
from pyoa.reference.hashes import BLOCK_ORDER_KEY, block_seed, dimension_seeds, hash_pair, mix32, permute
from tests.helpers import assert_oa

U32 = np.uint32

BOSE_S = [2, 3, 4, 5, 8, 9, 13]
BUSH_ST = [(3, 2), (4, 3), (5, 4)]
CMJND_ST = [(2, 3), (3, 2), (6, 4)]
AK_Q = [3, 5, 9]
BB_S = [2, 4, 8]


class Case:
    """One small array: the reference cell, NumPy's cell, the public sampler and
    the array's shape.

    ``s`` symbols, ``N`` rows, ``d`` columns per block, strength ``t`` and
    index ``lam`` (``N = lam * s**t``), ``M = N // s`` sub-strata; ``sample``
    is the number of rows compared with NumPy (None: all of them);
    ``value(i, j, p)`` is the public sampler with offset ``cmj`` and jitter 0."""

    def __init__(self, name, ref_cell, np_cell, value, s, N, d, t, lam, sample=None):
        self.name, self.ref_cell, self.np_cell, self.value = name, ref_cell, np_cell, value
        self.s, self.N, self.d, self.t, self.lam, self.sample = s, N, d, t, lam, sample
        self.M = N // s
        assert N == lam * s**t

    def __repr__(self):
        return self.name


def _cases() -> list[Case]:
    out = []
    for s in BOSE_S:
        out.append(Case(f"bose-s{s}", lambda i, c, s=s: roa.bose_cell(i, c, s),
                        lambda i, c, s=s: noa.bose_cell(i, c, s),
                        lambda i, j, p, s=s: roa.bose(i, j, s, p, "cmj", 0.0), s, s * s, s + 1, 2, 1))
    for s, t in BUSH_ST:
        out.append(Case(f"bush-s{s}-t{t}", lambda i, c, s=s, t=t: roa.bush_cell(i, c, s, t),
                        lambda i, c, s=s, t=t: noa.bush_cell(i, c, s, t),
                        lambda i, j, p, s=s, t=t: roa.bush(i, j, s, t, p, "cmj", 0.0), s, s**t, s + 1, t, 1))
    for s, t in CMJND_ST:
        out.append(Case(f"cmjnd-s{s}-t{t}", lambda i, c, s=s: roa.cmjnd_cell(i, c, s),
                        lambda i, c, s=s: noa.cmjnd_cell(i, c, s),
                        lambda i, j, p, s=s, t=t: roa.cmjnd(i, j, s, t, p, "cmj", 0.0), s, s**t, t, t, 1,
                        sample=300 if s**t > 1000 else None))
    for q in AK_Q:
        out.append(Case(f"addelman-kempthorne-q{q}", lambda i, c, q=q: roa.addelman_kempthorne_cell(i, c, q),
                        lambda i, c, q=q: noa.addelman_kempthorne_cell(i, c, q),
                        lambda i, j, p, q=q: roa.addelman_kempthorne(i, j, q, p, "cmj", 0.0), q, 2 * q * q, 2 * q + 1, 2, 2))
    for s in BB_S:
        out.append(Case(f"bose-bush-s{s}", lambda i, c, s=s: roa.bose_bush_cell(i, c, s),
                        lambda i, c, s=s: noa.bose_bush_cell(i, c, s),
                        lambda i, j, p, s=s: roa.bose_bush(i, j, s, p, "cmj", 0.0), s, 2 * s * s, 2 * s + 1, 2, 2))
    return out


CASES = _cases()


def reference_array(case: Case, rows=None) -> tuple[np.ndarray, np.ndarray]:
    """``(A, U)``: the reference cells of ``rows`` (default: all) x every column."""
    rows = range(case.N) if rows is None else rows
    cells = [[case.ref_cell(i, c) for c in range(case.d)] for i in rows]
    for row in cells:
        for a, u in row:
            assert type(a) is int and type(u) is int
    arr = np.array(cells, dtype=np.int64).reshape(len(cells), case.d, 2)
    return arr[..., 0], arr[..., 1]


@pytest.mark.parametrize("case", CASES, ids=repr)
def test_reference_cells_match_numpy(case):
    """Every column of every row (a random sample plus the ends for the large
    CMJND) of the reference cells against NumPy's vectorized cells."""
    if case.sample is None:
        rows = list(range(case.N))
    else:
        rng = np.random.default_rng(case.N)
        rows = sorted(set(rng.integers(0, case.N, case.sample).tolist()) | {0, 1, case.N - 2, case.N - 1})
    A, U = reference_array(case, rows)
    i, col = np.meshgrid(np.asarray(rows, dtype=U32), np.arange(case.d, dtype=U32), indexing="ij")
    nA, nU = (np.broadcast_to(x, i.shape) for x in case.np_cell(i, col))
    assert nA.dtype == U32 and nU.dtype == U32
    bad = np.argwhere((A != nA) | (U != nU))
    assert bad.size == 0, f"{case}: first mismatch at (row {rows[bad[0][0]]}, column {bad[0][1]})"


@pytest.mark.parametrize("case", CASES, ids=repr)
def test_reference_cells_are_an_orthogonal_array(case):
    """Strength t, index lam: every t of the d columns show each of the s**t
    t-tuples exactly lam times (and no symbol leaves [0, s))."""
    A, _ = reference_array(case)
    assert_oa(A, case.s, case.t, what=case.name)


@pytest.mark.parametrize("case", CASES, ids=repr)
def test_substratum_index_is_a_permutation_per_stratum(case):
    """Inside each stratum of each column (the N/s = M rows with A_ij = a) the
    sub-stratum index takes every value in [0, M) once."""
    A, U = reference_array(case)
    for c in range(case.d):
        for a in range(case.s):
            got = np.sort(U[A[:, c] == a, c])
            assert np.array_equal(got, np.arange(case.M)), f"{case}: column {c}, stratum {a}"


@pytest.mark.parametrize("case", CASES, ids=repr)
@pytest.mark.parametrize("offset", ["mj", "cmj"])
def test_fine_cells_are_a_latin_hypercube(case, offset):
    """Hence ``mj`` and ``cmj``: the fine cell ``permute(A_ij, s, P1) M +
    permute(u, M, seed)`` (seed per stratum or per column) runs over all N
    fine cells of every column, for a few array seeds."""
    A, U = reference_array(case)
    for p in [0, 1, 0xDEADBEEF]:
        for c in range(case.d):
            P1, P2, _ = dimension_seeds(p, c)
            fine = [
                permute(int(a), case.s, P1) * case.M
                + permute(int(u), case.M, ((int(a) + 1) * P2) & 0xFFFFFFFF if offset == "mj" else P2)
                for a, u in zip(A[:, c], U[:, c])
            ]
            assert sorted(fine) == list(range(case.N)), f"{case}: seed {p}, column {c}"


SAMPLED = ["bose-s4", "bose-s5", "bush-s4-t3", "cmjnd-s3-t2", "addelman-kempthorne-q5", "bose-bush-s4"]


@pytest.mark.parametrize("case", [c for c in CASES if c.name in SAMPLED], ids=repr)
def test_public_samplers_sit_in_their_cell(case):
    """With jitter 0 and ``cmj`` a value is the centre of its fine cell, so
    ``floor(x N)`` recovers ``permute(A_ij, s, P1) M + permute(u, M, P2)`` of
    the cell of column ``j % d`` with the seeds of block ``j // d``: two blocks."""
    for p in [0, 0x9E3779B9]:
        for j in range(2 * case.d):
            block, col = divmod(j, case.d)
            P = block_seed(p, block)
            P1, P2, _ = dimension_seeds(P, col)
            order = hash_pair(P, case.N, BLOCK_ORDER_KEY) if block else 0  # docs/spec.md section 6
            for i in range(case.N):
                a, u = case.ref_cell(permute(permute(i, case.N, order), case.N, mix32(order)), col)
                want = permute(a, case.s, P1) * case.M + permute(u, case.M, P2)
                assert math.floor(case.value(i, j, p) * case.N) == want, f"{case}: i={i}, j={j}, seed {p}"
