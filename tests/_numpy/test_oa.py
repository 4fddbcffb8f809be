"""The NumPy OA functions (pyoa._numpy.oa), called directly: seed 0 (the canonical
array, which no Sampler pixel reaches), broadcasting, against the reference and C."""

from __future__ import annotations

import numpy as np
import pytest

from pyoa import reference as ref
from pyoa._numpy import oa as noa
from tests.helpers import U32_MAX, assert_same_bits

U32 = np.uint32


@pytest.mark.parametrize("offset", ["centered", "j", "mj", "cmj"])
@pytest.mark.parametrize("p", [0, 1, U32_MAX])
@pytest.mark.parametrize("s", [2, 5, 13])
def test_bose_equals_reference_including_seed_zero(s, p, offset):
    i = np.arange(s * s, dtype=U32)[:, None]
    j = np.arange(2 * (s + 1) + 1, dtype=U32)[None, :]
    for J in (1.0, 0.0, 0.3):
        got = noa.bose(i, j, s, U32(p), offset, J)
        want = np.array([[ref.bose(a, b, s, p, offset, J) for b in range(j.size)] for a in range(i.size)], np.float32)
        assert_same_bits(got, want, f"bose s={s} p={p} {offset} J={J}")


@pytest.mark.parametrize("offset", ["centered", "j", "mj", "cmj"])
@pytest.mark.parametrize("p", [0, 0xDEADBEEF])
@pytest.mark.parametrize("s, t", [(2, 1), (3, 3), (4, 2), (2, 5)])
def test_cmjnd_equals_reference_including_seed_zero(s, t, p, offset):
    i = np.arange(s**t, dtype=U32)[:, None]
    j = np.arange(2 * t + 1, dtype=U32)[None, :]
    got = noa.cmjnd(i, j, s, t, U32(p), offset, 0.75)
    want = np.array([[ref.cmjnd(a, b, s, t, p, offset, 0.75) for b in range(j.size)] for a in range(i.size)], np.float32)
    assert_same_bits(got, want, f"cmjnd s={s} t={t} p={p} {offset}")


def test_per_lane_seeds_broadcast():
    """Different seeds per row (pixels) give the reference value of each."""
    s = 7
    p = np.array([0, 1, 99, U32_MAX], dtype=U32)[:, None]
    i = np.array([0, 5, 48, 17], dtype=U32)[:, None]
    j = np.array([0, 3, 8, 9], dtype=U32)[None, :]
    got = noa.bose(i, j, s, p, "mj", 1.0)
    want = np.array([[ref.bose(int(a), int(b), s, int(q), "mj") for b in j[0]] for a, q in zip(i[:, 0], p[:, 0])], np.float32)
    assert_same_bits(got, want)


def test_c_oracle_agrees_on_seed_zero(spec_c):
    for off in ("cmj", "j"):
        rows = [(i, j, 5, 0, off, 1.0) for i in range(25) for j in range(9)]
        want = np.array(spec_c.bose_bits(rows), dtype=np.uint32).view(np.float32).reshape(25, 9)
        got = noa.bose(np.arange(25, dtype=U32)[:, None], np.arange(9, dtype=U32)[None, :], 5, U32(0), off, 1.0)
        assert_same_bits(got, want, off)


# ----------------------------------------------------------------------------- Bose over GF(q), Bush

@pytest.mark.parametrize("offset", ["centered", "j", "mj", "cmj"])
@pytest.mark.parametrize("p", [0, 1, U32_MAX])
@pytest.mark.parametrize("q", [4, 9, 8])
def test_gf_bose_equals_reference_including_seed_zero(q, p, offset):
    i = np.arange(q * q, dtype=U32)[:, None]
    j = np.arange(2 * (q + 1) + 1, dtype=U32)[None, :]
    got = noa.bose(i, j, q, U32(p), offset, 0.3)
    want = np.array([[ref.bose(a, b, q, p, offset, 0.3) for b in range(j.size)] for a in range(i.size)], np.float32)
    assert_same_bits(got, want, f"bose q={q} p={p} {offset}")


@pytest.mark.parametrize("offset", ["centered", "j", "mj", "cmj"])
@pytest.mark.parametrize("p", [0, 0xDEADBEEF])
@pytest.mark.parametrize("s, t", [(2, 2), (3, 3), (4, 3), (5, 2), (8, 2), (9, 2)])
def test_bush_equals_reference_including_seed_zero(s, t, p, offset):
    i = np.arange(s**t, dtype=U32)[:, None]
    j = np.arange(2 * (s + 1) + 1, dtype=U32)[None, :]
    got = noa.bush(i, j, s, t, U32(p), offset, 0.75)
    want = np.array([[ref.bush(a, b, s, t, p, offset, 0.75) for b in range(j.size)] for a in range(i.size)],
                    np.float32)
    assert_same_bits(got, want, f"bush s={s} t={t} p={p} {offset}")


@pytest.mark.parametrize("s, t", [(2, 2), (3, 3), (4, 4), (5, 5), (8, 3), (9, 2), (27, 2), (256, 2)])
def test_bush_cell_is_the_polynomial_array(s, t):
    """bush_cell over whole columns, against the independent plain array and the
    documented sub-stratum index (u = i // s, column s: i mod s^(t-1))."""
    from tests.helpers import plain_bush_array

    N, M = s**t, s ** (t - 1)
    rows = np.arange(N) if N <= 4096 else np.random.default_rng(s).integers(0, N, 4096)
    A = plain_bush_array(s, t)[rows] if N <= 4096 else None
    i = rows.astype(U32)[:, None]
    col = np.arange(s + 1, dtype=U32)[None, :]
    aij, u = noa.bush_cell(i, col, s, t)
    if A is not None:
        assert np.array_equal(aij, A)
    assert np.array_equal(u[:, :s], np.broadcast_to(i // U32(s), (len(rows), s)))
    assert np.array_equal(u[:, s], rows % M)
    assert np.array_equal(aij[:, s], rows // M)
    assert np.array_equal(aij[:, 0], rows % s)  # f(0) = c_0
    assert aij.max() < s and u.max() < M


# ----------------------------------------------------------------------------- index 2: Addelman-Kempthorne, Bose-Bush

@pytest.mark.parametrize("offset", ["centered", "j", "mj", "cmj"])
@pytest.mark.parametrize("p", [0, 1, U32_MAX])
@pytest.mark.parametrize("name, s", [("addelman_kempthorne", 3), ("addelman_kempthorne", 9),
                                     ("bose_bush", 2), ("bose_bush", 8)])
def test_index2_equals_reference_including_seed_zero(name, s, p, offset):
    """Every sample, the 2s+1 columns of blocks 0 and 1 and the first of block 2."""
    N, d = 2 * s * s, 2 * s + 1
    i = np.arange(N, dtype=U32)[:, None]
    j = np.arange(2 * d + 1, dtype=U32)[None, :]
    got = getattr(noa, name)(i, j, s, U32(p), offset, 0.3)
    fn = getattr(ref, name)
    want = np.array([[fn(a, b, s, p, offset, 0.3) for b in range(j.size)] for a in range(N)], np.float32)
    assert_same_bits(got, want, f"{name} s={s} p={p} {offset}")


def _sample_rows_cols(s, n_rows, n_cols, seed):
    """Rows of both halves (the first, last and boundary rows) and columns (the first,
    the boundaries q-1, q, q+1 and the last ones) plus random ones."""
    rng = np.random.default_rng(seed)
    N, d = 2 * s * s, 2 * s + 1
    rows = sorted({0, 1, s - 1, s, s * s - 1, s * s, s * s + 1, N - s, N - 1, *map(int, rng.integers(0, N, n_rows))})
    cols = sorted({0, 1, 2, s - 2, s - 1, s, s + 1, s + 2, 2 * s - 2, 2 * s - 1, 2 * s,
                   *map(int, rng.integers(0, d, n_cols))} & set(range(d)))
    return rows, cols


@pytest.mark.parametrize("name, s", [("addelman-kempthorne", q) for q in (3, 5, 9, 13, 25, 27, 243, 251, 2887)]
                         + [("bose-bush", s) for s in (2, 4, 8, 16, 32, 64, 128)])
def test_index2_cell_is_the_plain_array(name, s):
    """addelman_kempthorne_cell / bose_bush_cell over whole columns against the
    independent plain arrays and the documented sub-stratum index u (whole arrays
    up to N = 2048, sampled rows and columns, both halves and the last column,
    for the larger ones); symbols in [0, s), u in [0, 2s)."""
    from tests.helpers import index2_symbol, plain_index2_array

    N, d = 2 * s * s, 2 * s + 1
    cell = noa.addelman_kempthorne_cell if name == "addelman-kempthorne" else noa.bose_bush_cell
    if N <= 2048:
        A, U = plain_index2_array(name, s)
        aij, u = cell(np.arange(N, dtype=U32)[:, None], np.arange(d, dtype=U32)[None, :], s)
        assert np.array_equal(aij, A) and np.array_equal(u, U)
        return
    rows, cols = _sample_rows_cols(s, 12 if s > 256 else 30, 40 if s > 64 else d, s)
    aij, u = cell(np.array(rows, U32)[:, None], np.array(cols, U32)[None, :], s)
    want = np.array([[index2_symbol(name, i, j, s) for j in cols] for i in rows])
    assert np.array_equal(aij, want[..., 0]) and np.array_equal(u, want[..., 1])
    assert aij.max() < s and u.max() < 2 * s
