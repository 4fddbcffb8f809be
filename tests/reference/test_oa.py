"""docs/spec.md sections 5, 6 and 8: the orthogonal-array properties of Bose and CMJND,
on the pure-Python reference (few seeds) and on the bulk API (many pixels, each
an independently randomized array).

Recovering the integer structure from float32 values: every value is clamped
into its fine cell, ``c/N <= x < (c+1)/N`` as real numbers (docs/spec.md section 7,
:func:`pyoa.reference.floats.sample_value`), and ``x * N`` is exact in float64
for a float32 ``x`` and ``N <= 2**24``, so ``floor(x*s)`` is the stratum and
``floor(x*N)`` the fine cell exactly, at any jitter amount. The one exception
is ``centered`` with an even number M of sub-strata: its sub-stratum (M-1)/2
is a half-integer, the jitter-0 point lies on the edge between the two middle
fine cells, and the value is clamped into its coarse stratum only.
"""

from __future__ import annotations

import numpy as np
import pytest

import pyoa
from pyoa import reference as ref
from pyoa._numpy import oa as noa
from pyoa.reference.floats import jitter_value, sample_value
from pyoa.reference.hashes import hash_pair
from tests.helpers import (
    AK_Q,
    BB_S,
    U32_MAX,
    ak_constants_independent,
    assert_latin_exact,
    assert_oa,
    assert_same_bits,
    bose_partner_symbol,
    bose_symbol,
    bush_sub_index,
    bush_symbol,
    field_for,
    gf_bose_partner_symbol,
    gf_bose_symbol,
    in_unit_interval,
    index2_symbol,
    plain_ak_array,
    plain_bush_array,
    plain_gf_bose_array,
    plain_index2_array,
    strata_exact,
)

OFFSETS = ["centered", "j", "mj", "cmj"]
BOSE_S = [2, 3, 5, 7, 11, 13]
CMJND_ST = [(s, t) for s in range(2, 7) for t in range(2, 5)]


# ----------------------------------------------------------------------------- independent C oracle

def test_reference_values_match_c_oracle(spec_c):
    """pyoa.reference.bose / cmjnd against spec_hashes.c written from docs/spec.md sections 3, 5-7."""
    rng = np.random.default_rng(8)
    seeds = [0, 1, U32_MAX, U32_MAX - 1, 0x9E3779B9]
    rows = []
    for s in [2, 3, 5, 13, 31, 4093]:
        for _ in range(150):
            rows.append((int(rng.integers(0, s * s)), int(rng.integers(0, 3 * (s + 1))), s,
                         int(rng.choice(seeds)) if rng.random() < 0.4 else int(rng.integers(0, 2**32)),
                         str(rng.choice(OFFSETS)), float(rng.choice([0.0, 1.0, rng.random()]))))
    want = spec_c.bose_bits(rows)
    got = [int(np.float32(ref.bose(*r)).view(np.uint32)) for r in rows]
    bad = [(r, g, w) for r, g, w in zip(rows, got, want) if g != w]
    assert not bad, f"{len(bad)} bose mismatches: {bad[:3]}"

    rows = []
    for s, t in [(2, 1), (7, 1), (2, 2), (3, 3), (6, 4), (2, 24), (4096, 2), (3, 15), (255, 3)]:
        for _ in range(100):
            rows.append((int(rng.integers(0, s**t)), int(rng.integers(0, 3 * t)), s, t,
                         int(rng.choice(seeds)) if rng.random() < 0.4 else int(rng.integers(0, 2**32)),
                         str(rng.choice(OFFSETS)), float(rng.choice([0.0, 1.0, rng.random()]))))
    want = spec_c.cmjnd_bits(rows)
    got = [int(np.float32(ref.cmjnd(*r)).view(np.uint32)) for r in rows]
    bad = [(r, g, w) for r, g, w in zip(rows, got, want) if g != w]
    assert not bad, f"{len(bad)} cmjnd mismatches: {bad[:3]}"


def _block_rule_seeds(spec_c):
    """Array seeds for the block-rule comparisons, as (C's seed, Python's seed): plain
    seeds, and pixel seeds of pixels near 2**32 (C's from its own pixel_seed, command
    S; Python's from pyoa.reference.pixel_seed)."""
    plain = [0, 1, 0x9E3779B9, U32_MAX - 1, U32_MAX]
    pixels = [(0, U32_MAX), (U32_MAX, U32_MAX), (U32_MAX, U32_MAX - 1), (12345, 2**32 - 7)]
    c_pix = spec_c.pixel_seed(*zip(*pixels))
    return [(p, p) for p in plain] + [(c, ref.pixel_seed(seed, pix)) for c, (seed, pix) in zip(c_pix, pixels)]


def _compare_bits(rows_c, rows_py, c_query, py_fn, what):
    want = c_query(rows_c)
    got = [int(np.float32(py_fn(*r)).view(np.uint32)) for r in rows_py]
    bad = [(r, hex(g), hex(w)) for r, g, w in zip(rows_py, got, want) if g != w]
    assert not bad, f"{len(bad)} of {len(rows_py)} {what} mismatches, first (args), got, want: {bad[:3]}"


@pytest.mark.parametrize("jitter", [0.0, 1.0, 0.375])
def test_block_rule_bose_matches_c_oracle(spec_c, jitter):
    """docs/spec.md section 6's block rule, Bose s = 11 (12 columns a block): every
    dimension of blocks 0-3, first, last and some middle samples, every offset, against
    the C oracle (which permutes the rows of blocks >= 1 by block_order_seed)."""
    s, dims = 11, range(48)
    samples = [0, 1, 60, s * s - 2, s * s - 1]
    rows_c, rows_py = [], []
    for pc, pp in _block_rule_seeds(spec_c):
        for i in samples:
            for j in dims:
                for off in OFFSETS:
                    rows_c.append((i, j, s, pc, off, jitter))
                    rows_py.append((i, j, s, pp, off, jitter))
    _compare_bits(rows_c, rows_py, spec_c.bose_bits, ref.bose, "bose")


@pytest.mark.parametrize("jitter", [0.0, 1.0, 0.375])
def test_block_rule_cmjnd_matches_c_oracle(spec_c, jitter):
    """As above for CMJND s = 4, t = 3 (3 columns a block, 64 rows): dimensions
    0-11 (blocks 0-3), every sample, every offset; and s = 3, t = 1 (one column
    a block) for dimensions 0-7."""
    rows_c, rows_py = [], []
    for s, t, dims in [(4, 3, range(12)), (3, 1, range(8))]:
        for pc, pp in _block_rule_seeds(spec_c):
            for i in range(s**t):
                for j in dims:
                    for off in OFFSETS:
                        rows_c.append((i, j, s, t, pc, off, jitter))
                        rows_py.append((i, j, s, t, pp, off, jitter))
    _compare_bits(rows_c, rows_py, spec_c.cmjnd_bits, ref.cmjnd, "cmjnd")


def test_block_rule_reorders_later_blocks(spec_c):
    """The C oracle's rows: block 0 reads row i (block_order_seed 0), blocks 1-3 a
    permutation of the rows that is not the identity, different per block and seed;
    so the comparisons above would see the old rule (row i in every block)."""
    from pyoa.reference.hashes import locate

    for N, B in [(121, 12), (64, 3)]:
        for p in [0, 1, U32_MAX]:
            P = spec_c.block_seed([p] * 4, range(4))
            K = spec_c.query([f"K {P[b]} {b} {N}" for b in range(4)])
            assert K[0] == 0 and all(K[1:])
            once = [spec_c.permute(range(N), [N] * N, [K[b]] * N) for b in range(4)]
            second = spec_c.mix32(K)  # block_row: a second permutation, seeded mix32(r)
            orders = [spec_c.permute(once[b], [N] * N, [second[b]] * N) for b in range(4)]
            assert orders[0] == list(range(N))
            for b in range(1, 4):
                assert sorted(orders[b]) == list(range(N)) and orders[b] != list(range(N))
                assert orders[b] not in orders[:b]
                # the Python reference's block rule reads the same rows
                assert [locate(p, i, b * B + 1, B, N) for i in range(N)] == [(P[b], r, 1) for r in orders[b]]


# ----------------------------------------------------------------------------- canonical arrays (p = 0)

@pytest.mark.parametrize("s", BOSE_S)
def test_bose_canonical_array_is_the_plain_bose_array(s):
    N = s * s
    for offset in OFFSETS:
        x = np.array([[ref.bose(i, j, s, 0, offset) for j in range(s + 1)] for i in range(N)], np.float32)
        A = np.array([[bose_symbol(i, j, s) for j in range(s + 1)] for i in range(N)])
        assert np.array_equal(strata_exact(x, s), A), offset
        if offset == "centered":
            # (A + ((s-1)/2 + 0.5)/s)/s == (A + 1/2)/s, correctly rounded
            assert_same_bits(x, ((A + 0.5) / s).astype(np.float32), "canonical centred")
        else:
            # identity permutations and jitter 0.5: fine cell A_ij*s + A_ik, at its centre
            Ak = np.array([[bose_partner_symbol(i, j, s) for j in range(s + 1)] for i in range(N)])
            assert np.array_equal(np.floor(x.astype(np.float64) * N), A * s + Ak), offset
    assert_oa(A, s, 2, what=f"plain Bose s={s}")
    # the plain array by its formula, written out for s = 3 (docs/spec.md section 5)
    if s == 3:
        assert A.T.tolist() == [[0, 0, 0, 1, 1, 1, 2, 2, 2],
                                [0, 1, 2, 0, 1, 2, 0, 1, 2],
                                [0, 1, 2, 1, 2, 0, 2, 0, 1],
                                [0, 2, 1, 1, 0, 2, 2, 1, 0]]


@pytest.mark.parametrize("s, t", [(2, 1), (2, 3), (3, 2), (4, 3), (5, 2), (3, 4)])
def test_cmjnd_canonical_array_is_the_digit_grid(s, t):
    N, M = s**t, s ** (t - 1)
    for offset in ("cmj", "centered"):
        x = np.array([[ref.cmjnd(i, j, s, t, 0, offset) for j in range(t)] for i in range(N)], np.float32)
        for i in range(N):
            digits = [(i // s**j) % s for j in range(t)]
            for j in range(t):
                assert int(np.floor(np.float64(x[i, j]) * s)) == digits[j]
                if offset == "cmj":
                    others = [d for k, d in enumerate(digits) if k != j]
                    v = sum(d * s**k for k, d in enumerate(others))
                    assert int(np.floor(np.float64(x[i, j]) * N)) == digits[j] * M + v
                else:
                    assert x[i, j] == np.float32((digits[j] + 0.5) / s)


def test_canonical_array_is_randomized_past_its_first_block():
    s = 5
    b0 = np.array([[ref.bose(i, j, s, 0) for j in range(s + 1)] for i in range(s * s)], np.float32)
    b1 = np.array([[ref.bose(i, j, s, 0) for j in range(s + 1, 2 * (s + 1))] for i in range(s * s)], np.float32)
    assert not np.array_equal(b0, b1)
    assert (np.float64(b1) * s * s % 1 != 0.5).any()  # jittered, not cell centres


# ----------------------------------------------------------------------------- properties, reference

def _ref_array(fn, N, dims, **kw):
    return np.array([[fn(i, j, **kw) for j in dims] for i in range(N)], np.float32)


def check_array(x0, x1, s, t, N, cols_blocks, offset, what):
    """x0: jitter-0 values, x1: full-jitter values of the same arrays (jitter does
    not change the permutations), shape (..., N, d); N = s * M fine cells."""
    M, rem = divmod(N, s)  # every construction: s strata of M sub-strata each
    assert rem == 0, what
    assert in_unit_interval(x0) and in_unit_interval(x1), what
    S = strata_exact(x0, s)
    for cols in cols_blocks:
        assert_oa(S, s, t, cols=cols, what=what)
    if offset in ("mj", "cmj"):
        assert_latin_exact(x0, N, what)
        assert_latin_exact(x1, N, what)
    if offset == "centered":
        assert_same_bits(x0, ((S + 0.5) / s).astype(np.float32), f"{what}: centred, jitter 0")
    if offset == "centered" and M % 2 == 0:
        # sub-stratum (M-1)/2: x0 is the middle of its coarse stratum, on the edge
        # between fine cells M/2 - 1 and M/2; full jitter stays in the coarse stratum
        moved = np.count_nonzero(strata_exact(x1, s) != S)
        assert moved == 0, f"{what}: full jitter moved {moved} values out of their coarse stratum"
    else:
        # full jitter stays inside the fine cell chosen by the permutations: the cell
        # whose centre is the jitter-0 point
        moved = np.count_nonzero(strata_exact(x1, N) != strata_exact(x0, N))
        assert moved == 0, f"{what}: full jitter moved {moved} values out of their fine cell"
    # and it does jitter (not all at the centre)
    assert np.abs(x1.astype(np.float64) * N - x0.astype(np.float64) * N).max() > 0.2 or N > 2**20, what


@pytest.mark.parametrize("s", BOSE_S)
def test_bose_oa_reference(s):
    N, d = s * s, s + 1
    for p in (1, 0xC0FFEE, U32_MAX):
        for offset in OFFSETS:
            x0 = _ref_array(ref.bose, N, range(d), s=s, p=p, offset=offset, jitter=0.0)
            x1 = _ref_array(ref.bose, N, range(d), s=s, p=p, offset=offset, jitter=1.0)
            check_array(x0, x1, s, 2, N, [range(d)], offset, f"bose s={s} p={p} {offset}")
            if s >= 3:  # randomized: strata are not the plain array
                assert not np.array_equal(strata_exact(x0, s), [[bose_symbol(i, j, s) for j in range(d)] for i in range(N)])


@pytest.mark.parametrize("s, t", CMJND_ST)
def test_cmjnd_full_grid_reference(s, t):
    N = s**t
    for p in (1, U32_MAX):
        for offset in OFFSETS if N <= 256 else ("cmj", "j"):
            x0 = _ref_array(ref.cmjnd, N, range(t), s=s, t=t, p=p, offset=offset, jitter=0.0)
            x1 = _ref_array(ref.cmjnd, N, range(t), s=s, t=t, p=p, offset=offset, jitter=1.0)
            check_array(x0, x1, s, t, N, [range(t)], offset, f"cmjnd s={s} t={t} p={p} {offset}")


# ----------------------------------------------------------------------------- properties, bulk API

N_PIXELS = 48


def _bulk(name, spp, dims, backend, offset, strength=None, seed=0, n_pixels=N_PIXELS):
    kw = {"spp": spp, "dims": dims, "offset": offset, "strength": strength, "seed": seed, "backend": backend}
    pixels = list(range(n_pixels - 2)) + [U32_MAX - 1, U32_MAX]
    x0 = pyoa.sampler(name, jitter=0.0, **kw).generate(pixels=pixels)
    x1 = pyoa.sampler(name, jitter=1.0, **kw).generate(pixels=pixels)
    return x0, x1


def check_blocks(x0, x1, s, t, N, block_dims, n_blocks, offset, what):
    blocks = [range(b * block_dims, (b + 1) * block_dims) for b in range(n_blocks)]
    check_array(x0, x1, s, t, N, blocks, offset, what)
    for b in range(1, n_blocks):
        cols0, cols_b = x1[..., blocks[0]], x1[..., blocks[b]]
        # not a repeat of block 0, and not constant
        assert not np.array_equal(cols0, cols_b), f"{what}: block {b} repeats block 0"
        same = np.all(cols0 == cols_b, axis=-2)  # per pixel and column
        assert same.mean() < 0.01, f"{what}: block {b} repeats block-0 columns"
        assert np.all(np.ptp(cols_b, axis=-2) > 0), f"{what}: constant column in block {b}"
    # different pixels are different arrays
    assert not np.array_equal(x1[0], x1[1])


@pytest.mark.parametrize("offset", OFFSETS)
@pytest.mark.parametrize("s", BOSE_S)
def test_bose_oa_bulk(backend, s, offset):
    d = s + 1
    dims = 2 * d + 2  # two full blocks and part of a third
    for seed in (0, 0xDEADBEEF):
        x0, x1 = _bulk("bose", s * s, dims, backend, offset, seed=seed)
        check_blocks(x0, x1, s, 2, s * s, d, 2, offset, f"bose s={s} {offset} seed={seed} [{backend}]")
        # the partial third block: pairs of its columns are stratified too
        assert_oa(strata_exact(x0, s), s, 2, cols=range(2 * d, dims))


@pytest.mark.parametrize("offset", OFFSETS)
@pytest.mark.parametrize("s, t", CMJND_ST)
def test_cmjnd_full_grid_bulk(backend, s, t, offset):
    x0, x1 = _bulk("cmjnd", s**t, 3 * t, backend, offset, strength=t, seed=7)
    check_blocks(x0, x1, s, t, s**t, t, 3, offset, f"cmjnd s={s} t={t} {offset} [{backend}]")


@pytest.mark.parametrize("s, t", [(2, 1), (17, 1), (16, 2), (4, 6), (2, 10)])
def test_cmjnd_other_sizes_bulk(backend, s, t):
    x0, x1 = _bulk("cmjnd", s**t, 2 * t, backend, "cmj", strength=t)
    check_blocks(x0[:8], x1[:8], s, t, s**t, t, 2, "cmj", f"cmjnd s={s} t={t} [{backend}]")


@pytest.mark.parametrize("s", [31, 61])
def test_bose_larger_s_bulk(backend, s):
    x0, x1 = _bulk("bose", s * s, s + 3, backend, "cmj")
    check_array(x0[:6], x1[:6], s, 2, s * s, [range(s + 1)], "cmj", f"bose s={s}")


def test_bose_cmj_is_correlated_jj_is_not(backend):
    """cmj uses one sub-stratum permutation per dimension (Kensler's correlation),
    mj one per stratum: with cmj the sub-stratum of a point depends only on its
    partner column's symbol, which the fine cells reveal."""
    s = 7
    N = s * s
    x = pyoa.sampler("bose", spp=N, dims=2, seed=3, jitter=0.0, backend=backend, offset="cmj").generate(pixels=range(8))
    cells = np.floor(x.astype(np.float64) * N).astype(int)
    strata, sub = cells // s, cells % s
    # dimension 0's sub-stratum is a function of dimension 1's stratum (same for every stratum of dim 0)
    for px in range(8):
        m = {}
        for a, b in zip(strata[px, :, 1], sub[px, :, 0]):
            assert m.setdefault(a, b) == b
    x = pyoa.sampler("bose", spp=N, dims=2, seed=3, jitter=0.0, backend=backend, offset="mj").generate(pixels=range(8))
    cells = np.floor(x.astype(np.float64) * N).astype(int)
    strata, sub = cells // s, cells % s
    functional = 0
    for px in range(8):
        m, ok = {}, True
        for a, b in zip(strata[px, :, 1], sub[px, :, 0]):
            ok &= m.setdefault(a, b) == b
        functional += ok
    assert functional < 8


# ----------------------------------------------------------------------------- Bose over GF(q), Bush

GF_BOSE_Q = [4, 8, 9, 16, 25, 27]
#: (s, t) of Bush: prime and prime-power s, t from 2 up to s (N = s^t moderate)
BUSH_ST = [(2, 2), (3, 2), (3, 3), (4, 2), (4, 3), (4, 4), (5, 4), (5, 5), (7, 3), (8, 3), (9, 2), (8, 4), (16, 2)]


def _canonical(fn, N, d, **kw):
    """Values of the canonical array (seed 0: identity permutations, jitter 0.5)
    from the reference for small N, else from the NumPy functions (bit-equal to
    the reference at seed 0: tests/_numpy/test_oa.py)."""
    if N * d <= 6000:
        if fn == "addelman_kempthorne":  # its reference calls the order q
            return _ref_array(getattr(ref, fn), N, range(d), p=0, q=kw["s"],
                              **{k: v for k, v in kw.items() if k != "s"})
        return _ref_array(getattr(ref, fn), N, range(d), p=0, **kw)
    i = np.arange(N, dtype=np.uint32)[:, None]
    j = np.arange(d, dtype=np.uint32)[None, :]
    args = (kw["s"],) if fn in ("bose", "addelman_kempthorne", "bose_bush") else (kw["s"], kw["t"])
    return getattr(noa, fn)(i, j, *args, np.uint32(0), kw["offset"], kw.get("jitter", 1.0))


@pytest.mark.parametrize("q", GF_BOSE_Q)
def test_gf_bose_canonical_array_is_the_plain_bose_array_over_gf(q):
    """Seed 0 is A_ij = a0 + (j-1) a1 in GF(q) (codes: base-p digits, modulus of
    KNOWN_MODULI), computed by an independent polynomial implementation; the fine
    cell is A_ij*q + A_ik (partner column k, docs/spec.md section 5); an OA(q^2, q+1, q, 2)."""
    N, d = q * q, q + 1
    A, Ak = plain_gf_bose_array(q)
    F = field_for(q)  # spot check the vectorized array against the scalar definition
    assert all(A[i, j] == gf_bose_symbol(i, j, F) for i in (0, 1, q + 2, N - 1) for j in range(d))
    assert_oa(A, q, 2, what=f"plain GF({q}) Bose")
    for offset in ("cmj", "mj", "j") if q <= 9 else ("cmj",):
        x = _canonical("bose", N, d, s=q, offset=offset)
        assert np.array_equal(strata_exact(x, q), A), offset
        assert np.array_equal(np.floor(x.astype(np.float64) * N), A * q + Ak), offset
    x = _canonical("bose", N, d, s=q, offset="centered")
    assert_same_bits(x, ((A + 0.5) / q).astype(np.float32), "canonical centred")


@pytest.mark.parametrize("q", [4, 8, 9, 16, 27])
def test_integer_mod_q_is_not_an_oa_for_prime_powers(q):
    """Why GF(q) is needed (docs/spec.md section 5): the integer formula (a0 + (j-1) a1) mod q
    is no OA for composite q, and the OA check above detects it."""
    A = np.array([[bose_symbol(i, j, q) for j in range(q + 1)] for i in range(q * q)])
    with pytest.raises(AssertionError, match="not an OA"):
        assert_oa(A, q, 2)


def _block_rule(p, i, j, B, N):
    """docs/spec.md section 6, written out with pyoa's hash primitives only (not
    reference.hashes.locate): ``(P, row, col)``, the copy's seed, the row that
    sample ``i`` reads (``row = i`` in block 0, else permuted with seed
    ``hash_pair(P, N, 0x94d049bb)``) and the column."""
    block, col = divmod(j, B)
    P = ref.block_seed(p, block)
    r = hash_pair(P, N, 0x94D049BB)
    row = i if block == 0 else ref.permute(ref.permute(i, N, r), N, ref.mix32(r))
    return P, row, col


def _bose_from_symbols(i, j, q, p, offset, jitter, symbol, partner):
    """docs/spec.md section 5 Bose value from independently computed symbols: ``symbol``
    and ``partner`` give A_ij and A_ik of column ``j < q+1``; seeds, offsets and
    floats use pyoa's hash and float primitives only; the block rule of section 6
    by :func:`_block_rule`."""
    P, i, j = _block_rule(p, i, j, q + 1, q * q)
    P1, P2, P3 = ref.dimension_seeds(P, j)
    aij, aik = symbol(i, j), partner(i, j)
    stratum = ref.permute(aij, q, P1)
    if offset == "centered":
        sub = (q - 1) / 2
    else:
        seed = {"j": (aik * q + aij + 1) * P2, "mj": (aij + 1) * P2, "cmj": P2}[offset] & U32_MAX
        sub = ref.permute(aik, q, seed)
    return sample_value(stratum, sub, jitter_value(ref.randfloat(i, P3), float(np.float32(jitter))), q, q)


def _bose_mod_s(i, j, s, p, offset, jitter):
    """The pre-GF Bose value (docs/spec.md section 5, prime s), with plain mod-s integers."""
    return _bose_from_symbols(i, j, s, p, offset, jitter,
                              lambda i, j: bose_symbol(i, j, s), lambda i, j: bose_partner_symbol(i, j, s))


@pytest.mark.parametrize("s", [2, 3, 5, 7, 13, 31, 251, 257, 4093])
def test_prime_bose_is_unchanged_by_gf(s):
    """For prime s the GF code path gives the bits of the integer formula."""
    rng = np.random.default_rng(s)
    for k in range(150 if s < 1000 else 25):
        i, j = int(rng.integers(0, s * s)), int(rng.integers(0, 3 * (s + 1)))
        if k < 4:
            i, j = [(0, 0), (s * s - 1, s), (s * s - 1, s + 1), (s, s - 1)][k]
        p = int(rng.choice([0, 1, U32_MAX])) if k % 5 == 0 else int(rng.integers(0, 2**32))
        offset, J = OFFSETS[k % 4], [1.0, 0.0, 0.4375][k % 3]
        want = _bose_mod_s(i, j, s, p, offset, J)
        got = ref.bose(i, j, s, p, offset, J)
        assert np.float32(got).view(np.uint32) == np.float32(want).view(np.uint32), (i, j, s, p, offset, J)


def _gf_bose_from_spec(i, j, q, p, offset, jitter):
    """docs/spec.md section 5 "Bose over GF(q)", with the independent field of tests.helpers."""
    F = field_for(q)
    return _bose_from_symbols(i, j, q, p, offset, jitter,
                              lambda i, j: gf_bose_symbol(i, j, F), lambda i, j: gf_bose_partner_symbol(i, j, F))


def _bush_from_spec(i, j, s, t, p, offset, jitter):
    """docs/spec.md section 5 "Bush" (with pyoa's documented u = i mod M in column s),
    with the independent field of tests.helpers."""
    F = field_for(s)
    M = s ** (t - 1)
    P, i, j = _block_rule(p, i, j, s + 1, s**t)
    P1, P2, P3 = ref.dimension_seeds(P, j)
    aij, u = bush_symbol(i, j, t, F), bush_sub_index(i, j, s, t)
    stratum = ref.permute(aij, s, P1)
    if offset == "centered":
        sub = (M - 1) / 2
    else:
        seed = {"j": (i + 1) * P2, "mj": (aij + 1) * P2, "cmj": P2}[offset] & U32_MAX
        sub = ref.permute(u, M, seed)
    return sample_value(stratum, sub, jitter_value(ref.randfloat(i, P3), float(np.float32(jitter))), M, s)


def _same_f32(a, b):
    return np.float32(a).view(np.uint32) == np.float32(b).view(np.uint32)


@pytest.mark.parametrize("q", [4, 8, 9, 16, 25, 27, 49, 256])
def test_gf_bose_reference_follows_spec(q):
    """Whole values (permutations, offsets, jitter, blocks) of reference.bose over
    GF(q) against docs/spec.md section 5 written out with an independent GF(q)."""
    rng = np.random.default_rng(q)
    for k in range(120):
        i, j = int(rng.integers(0, q * q)), int(rng.integers(0, 3 * (q + 1)))
        if k < 3:
            i, j = [(q * q - 1, q), (q * q - 1, q + 1), (0, 2 * q + 1)][k]
        p = int(rng.choice([0, 1, U32_MAX])) if k % 4 == 0 else int(rng.integers(0, 2**32))
        offset, J = OFFSETS[k % 4], [1.0, 0.0, 0.8125][k % 3]
        assert _same_f32(ref.bose(i, j, q, p, offset, J), _gf_bose_from_spec(i, j, q, p, offset, J)), \
            (i, j, q, p, offset, J)


@pytest.mark.parametrize("s, t", [(2, 2), (3, 3), (4, 4), (5, 5), (7, 3), (8, 8), (9, 2), (16, 6), (27, 3),
                                  (256, 3), (4093, 2)])
def test_bush_reference_follows_spec(s, t):
    """Whole values of reference.bush against docs/spec.md section 5 (Bush) written out
    with an independent GF(s), including column s, blocks and edge seeds."""
    rng = np.random.default_rng(s * 100 + t)
    N = s**t
    for k in range(100 if s < 4093 else 12):
        i, j = int(rng.integers(0, N)), int(rng.integers(0, 3 * (s + 1)))
        if k < 4:
            i, j = [(N - 1, s), (N - 1, s + 1), (0, 2 * s + 1), (N // 2, s)][k]
        p = int(rng.choice([0, 1, U32_MAX])) if k % 4 == 0 else int(rng.integers(0, 2**32))
        offset, J = OFFSETS[k % 4], [1.0, 0.0, 0.8125][k % 3]
        assert _same_f32(ref.bush(i, j, s, t, p, offset, J), _bush_from_spec(i, j, s, t, p, offset, J)), \
            (i, j, s, t, p, offset, J)


@pytest.mark.parametrize("s, t", BUSH_ST)
def test_bush_canonical_array_is_the_polynomial_array(s, t):
    """Seed 0: column j < s is the row polynomial (base-s digits of i, c_0 least
    significant) at x = j in GF(s), column s its leading coefficient, recomputed
    by an independent GF(s); every t of the s+1 columns is a full grid (index 1).
    The fine cell is A_ij*M + u with u = i // s in columns j < s and u = i mod M in
    column s (pyoa's documented deviation from SPEC, reference.oa.bush)."""
    F = field_for(s)
    N, M, d = s**t, s ** (t - 1), s + 1
    A = plain_bush_array(s, t)
    rng = np.random.default_rng(N)
    for i in [0, 1, N - 1] + [int(v) for v in rng.integers(0, N, 30)]:  # vectorized == scalar definition
        assert [bush_symbol(i, j, t, F) for j in range(d)] == A[i].tolist(), i
    U = np.array([[bush_sub_index(i, j, s, t) for j in range(d)] for i in range(N)])
    assert_oa(A, s, t, what=f"plain Bush s={s} t={t}")
    for offset in ("cmj", "mj", "j") if N * d <= 6000 else ("cmj",):
        x = _canonical("bush", N, d, s=s, t=t, offset=offset)
        assert np.array_equal(strata_exact(x, s), A), offset
        assert np.array_equal(np.floor(x.astype(np.float64) * N), A * M + U), offset
        assert_latin_exact(x, N, f"canonical Bush s={s} t={t} {offset}")
    x = _canonical("bush", N, d, s=s, t=t, offset="centered")
    assert_same_bits(x, ((A + 0.5) / s).astype(np.float32), "canonical centred")


@pytest.mark.parametrize("s, t", [(2, 2), (3, 3), (4, 3), (5, 4)])
def test_bush_last_column_needs_the_deviation(s, t):
    """SPEC's literal u = i // s in column s repeats sub-strata within a stratum
    (i // s contains the stratum digit c_{t-1}), so it would not be a Latin
    hypercube; u = i mod s^(t-1) is, and every other column keeps SPEC's u."""
    N, M = s**t, s ** (t - 1)
    lead = np.arange(N) // M
    spec_cells = lead * M + np.arange(N) // s
    assert len(np.unique(spec_cells)) < N
    pyoa_cells = lead * M + np.arange(N) % M
    assert np.array_equal(np.sort(pyoa_cells), np.arange(N))
    x = np.array([ref.bush(i, s, s, t, 0, "cmj", 0.0) for i in range(N)], np.float32)
    assert np.array_equal(np.floor(x.astype(np.float64) * N), pyoa_cells)
    x = np.array([ref.bush(i, 0, s, t, 0, "cmj", 0.0) for i in range(N)], np.float32)
    assert np.array_equal(np.floor(x.astype(np.float64) * N) % M, np.arange(N) // s)


@pytest.mark.parametrize("q", [4, 8, 9])
def test_gf_bose_oa_reference(q):
    N, d = q * q, q + 1
    plain = plain_gf_bose_array(q)[0]
    for p in (1, U32_MAX):
        for offset in OFFSETS:
            x0 = _ref_array(ref.bose, N, range(d), s=q, p=p, offset=offset, jitter=0.0)
            x1 = _ref_array(ref.bose, N, range(d), s=q, p=p, offset=offset, jitter=1.0)
            check_array(x0, x1, q, 2, N, [range(d)], offset, f"bose q={q} p={p} {offset}")
            assert not np.array_equal(strata_exact(x0, q), plain)


@pytest.mark.parametrize("s, t", [(2, 2), (3, 3), (4, 2), (4, 3), (5, 2)])
def test_bush_oa_reference(s, t):
    N, d = s**t, s + 1
    plain = plain_bush_array(s, t)
    for p in (1, 0xC0FFEE, U32_MAX):
        for offset in OFFSETS:
            x0 = _ref_array(ref.bush, N, range(d), s=s, t=t, p=p, offset=offset, jitter=0.0)
            x1 = _ref_array(ref.bush, N, range(d), s=s, t=t, p=p, offset=offset, jitter=1.0)
            check_array(x0, x1, s, t, N, [range(d)], offset, f"bush s={s} t={t} p={p} {offset}")
            if s >= 3:
                assert not np.array_equal(strata_exact(x0, s), plain)


def _pixels_for(N):
    """Enough independently randomized arrays, fewer for larger N (run time)."""
    return int(min(48, max(6, 20000 // N)))


@pytest.mark.parametrize("offset", OFFSETS)
@pytest.mark.parametrize("q", GF_BOSE_Q)
def test_gf_bose_oa_bulk(backend, q, offset):
    """Many seeds (pixels), both backends: every pair of the q+1 columns of each
    block is a full q x q grid, mj/cmj are Latin hypercubes at q^2 cells in every
    column, and block 1 is a differently randomized valid copy."""
    d = q + 1
    dims = 2 * d + 2
    seed = {"centered": 0, "j": 7, "mj": 0xDEADBEEF, "cmj": U32_MAX}[offset]
    x0, x1 = _bulk("bose", q * q, dims, backend, offset, seed=seed, n_pixels=_pixels_for(q * q))
    check_blocks(x0, x1, q, 2, q * q, d, 2, offset, f"bose q={q} {offset} seed={seed} [{backend}]")
    assert_oa(strata_exact(x0, q), q, 2, cols=range(2 * d, dims))


@pytest.mark.parametrize("offset", OFFSETS)
@pytest.mark.parametrize("s, t", BUSH_ST)
def test_bush_oa_bulk(backend, s, t, offset):
    """Every t-subset of ALL s+1 columns (column s included) of each block holds
    every t-tuple exactly once; mj/cmj give a Latin hypercube at N cells in every
    column; blocks past the first are differently randomized valid copies (the
    partial third block: its t columns are a full grid too)."""
    N, d = s**t, s + 1
    dims = 2 * d + t
    seed = {"centered": 0, "j": 7, "mj": 0xDEADBEEF, "cmj": U32_MAX}[offset]
    x0, x1 = _bulk("bush", N, dims, backend, offset, strength=t, seed=seed, n_pixels=_pixels_for(N))
    check_blocks(x0, x1, s, t, N, d, 2, offset, f"bush s={s} t={t} {offset} [{backend}]")
    assert_oa(strata_exact(x0, s), s, t, cols=range(2 * d, dims))
    # each pixel's array is randomized, not the canonical one
    plain = plain_bush_array(s, t)
    if s >= 3:
        assert not (strata_exact(x0[..., :d], s) == plain).all(axis=(-2, -1)).any()


@pytest.mark.parametrize("s, t", [(2, 2), (3, 3), (4, 4), (9, 2), (16, 3), (32, 2), (49, 2), (64, 2), (11, 3)])
def test_bush_latin_many_seeds(backend, s, t):
    """mj and cmj: 1D Latin hypercube at N cells in every column, column s included,
    over many seeds (pixels x user seeds)."""
    N, d = s**t, s + 1
    for offset in ("mj", "cmj"):
        for seed in (1, 2**31, U32_MAX):
            x = pyoa.sampler("bush", spp=N, dims=d, strength=t, seed=seed, offset=offset, jitter=0.0,
                             backend=backend).generate(pixels=range(max(4, 20000 // N)))
            assert_latin_exact(x, N, f"bush s={s} t={t} {offset} seed={seed}")
            assert_oa(strata_exact(x, s), s, t, cols=range(d) if d <= 6 else [0, 1, s - 1, s])


# ----------------------------------------------------------------------------- index 2: Addelman-Kempthorne, Bose-Bush

INDEX2 = [pytest.param("addelman-kempthorne", q, id=f"ak-q{q}") for q in AK_Q] + \
         [pytest.param("bose-bush", s, id=f"bb-s{s}") for s in BB_S]


@pytest.mark.parametrize("name, s", INDEX2)
def test_index2_canonical_array_is_the_plain_array(name, s):
    """Seed 0 (identity permutations, jitter 0.5) is the plain array, recomputed
    independently (tests.helpers: the Addelman-Kempthorne table of Hedayat-Sloane-
    Stufken 3.4 with constants from an independent GF(q); Bose-Bush in an
    independent GF(2s)): strata = A, fine cell = A*M + u with pyoa's documented
    sub-stratum index u (M = 2s). A is an OA of strength 2 and index 2 in every
    pair of ALL 2s+1 columns (each of the s^2 cells exactly twice), and A*M + u
    is a permutation of the N = 2s^2 fine cells in every column."""
    N, M, d = 2 * s * s, 2 * s, 2 * s + 1
    A, U = plain_index2_array(name, s)
    assert A.shape == U.shape == (N, d)
    rng = np.random.default_rng(N)
    for i in [0, 1, s * s - 1, s * s, N - 1] + [int(v) for v in rng.integers(0, N, 20)]:  # vectorized == scalar
        assert [index2_symbol(name, i, j, s) for j in range(d)] == list(zip(A[i].tolist(), U[i].tolist())), i
    assert_oa(A, s, 2, what=f"plain {name} s={s}")
    assert A.min() == 0 and A.max() == s - 1 and U.min() == 0 and U.max() == M - 1
    assert np.array_equal(np.sort(A * M + U, axis=0), np.broadcast_to(np.arange(N)[:, None], (N, d)))
    fn = name.replace("-", "_")
    for offset in ("cmj", "mj", "j") if N * d <= 6000 else ("cmj",):
        x = _canonical(fn, N, d, s=s, offset=offset)
        assert np.array_equal(strata_exact(x, s), A), offset
        assert np.array_equal(np.floor(x.astype(np.float64) * N), A * M + U), offset
        assert_latin_exact(x, N, f"canonical {name} s={s} {offset}")
    x = _canonical(fn, N, d, s=s, offset="centered")
    assert_same_bits(x, ((A + 0.5) / s).astype(np.float32), "canonical centred")


def test_index2_plain_arrays_written_out():
    """The smallest arrays by hand. Addelman-Kempthorne q = 3: kappa = 2, b = (0, 2, 1),
    k = (0, 2, 1), c = (0, 1, 1); rows (h, x, y) in order. Bose-Bush s = 2 over GF(4)
    (x^2 + x + 1): the products x*j of GF(4), low bit, plus k."""
    assert ak_constants_independent(3) == (2, (0, 2, 1), (0, 2, 1), (0, 1, 1))
    A = plain_ak_array(3)[0]
    assert A.T.tolist() == [
        [0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2],  # y
        [0, 1, 2, 1, 2, 0, 2, 0, 1, 2, 0, 1, 0, 1, 2, 1, 2, 0],  # x + y (+ 2)
        [0, 2, 1, 1, 0, 2, 2, 1, 0, 1, 0, 2, 2, 1, 0, 0, 2, 1],  # x + 2y (+ 1)
        [0, 1, 2, 1, 2, 0, 1, 2, 0, 0, 1, 2, 2, 0, 1, 2, 0, 1],  # y + x^2, y + 2 x^2
        [0, 1, 2, 2, 0, 1, 0, 1, 2, 1, 2, 0, 2, 0, 1, 1, 2, 0],  # y + x + x^2, y + 2x + 2x^2 + 1
        [0, 1, 2, 0, 1, 2, 2, 0, 1, 1, 2, 0, 1, 2, 0, 2, 0, 1],  # y + 2x + x^2, y + x + 2x^2 + 1
        [0, 0, 0, 1, 1, 1, 2, 2, 2, 0, 0, 0, 1, 1, 1, 2, 2, 2],  # x
    ]
    B = plain_index2_array("bose-bush", 2)[0]
    assert B.T.tolist() == [
        [0, 1, 0, 1, 0, 1, 0, 1],  # low bit of x*0 = 0, 0, 0, 0 (x = 0..3), plus k
        [0, 1, 1, 0, 0, 1, 1, 0],  # x*1 = 0, 1, 2, 3
        [0, 1, 0, 1, 1, 0, 1, 0],  # x*2 = 0, 2, 3, 1
        [0, 1, 1, 0, 1, 0, 0, 1],  # x*3 = 0, 3, 1, 2
        [0, 0, 1, 1, 0, 0, 1, 1],  # x mod 2
    ]


@pytest.mark.parametrize("q", [3, 5, 7, 9, 25])
def test_ak_needs_a_non_square_kappa(q):
    """The construction's one condition: with a square in place of kappa (1, whose
    constants are b = c = 0 and k = m) the array is not an OA, and the OA check
    says so; another non-square (the largest, Owen's choice) gives an OA too."""
    from tests.helpers import field_for

    F = field_for(q)
    squares = {F.mul(x, x) for x in range(q)}
    with pytest.raises(AssertionError, match="not an OA"):
        assert_oa(plain_ak_array(q, 1)[0], q, 2)
    largest = max(x for x in range(q) if x not in squares)
    assert_oa(plain_ak_array(q, largest)[0], q, 2, what=f"AK q={q} kappa={largest}")
    if q > 3:
        square = max(squares)
        with pytest.raises(AssertionError, match="not an OA"):
            assert_oa(plain_ak_array(q, square)[0], q, 2)


@pytest.mark.parametrize("name, s", [("addelman-kempthorne", 3), ("addelman-kempthorne", 5), ("addelman-kempthorne", 9),
                                     ("bose-bush", 2), ("bose-bush", 4), ("bose-bush", 8)])
def test_index2_last_column_adds_only_triple_coincidences(name, s):
    """The documented cost of the full column set: two rows agree in at most 2 of
    the first 2s columns, and the last column (j = 2s) adds pairs of rows that agree
    in exactly 3 (s^3 such pairs); strength 2 is kept (test above). Randomizing the
    symbols per column (any pixel of the sampler) does not change coincidences."""
    A = plain_index2_array(name, s)[0]
    x = pyoa.sampler(name, spp=2 * s * s, dims=2 * s + 1, seed=5, jitter=0.0, backend="numpy").generate(pixels=[3])[0]
    for arr in (A, strata_exact(x, s)):
        agree = arr[:, None, :] == arr[None, :, :]
        iu = np.triu_indices(len(arr), 1)
        assert agree[..., :-1].sum(-1)[iu].max() == 2
        full = agree.sum(-1)[iu]
        assert full.max() == 3 and np.count_nonzero(full == 3) == s**3


def _index2_from_spec(name, i, j, s, p, offset, jitter):
    """One value of an index-2 sampler written out from the docstrings of
    reference.addelman_kempthorne / bose_bush, with the independent plain arrays:
    blocks of 2s+1 columns, M = 2s, the 'j' seed (row + 1) P2 (the row of :func:`_block_rule`)."""
    M = 2 * s
    P, i, j = _block_rule(p, i, j, 2 * s + 1, 2 * s * s)
    P1, P2, P3 = ref.dimension_seeds(P, j)
    aij, u = index2_symbol(name, i, j, s)
    stratum = ref.permute(aij, s, P1)
    if offset == "centered":
        sub = (M - 1) / 2
    else:
        seed = {"j": (i + 1) * P2, "mj": (aij + 1) * P2, "cmj": P2}[offset] & U32_MAX
        sub = ref.permute(u, M, seed)
    return sample_value(stratum, sub, jitter_value(ref.randfloat(i, P3), float(np.float32(jitter))), M, s)


@pytest.mark.parametrize("name, s", [*INDEX2, pytest.param("addelman-kempthorne", 243, id="ak-q243"),
                                     pytest.param("addelman-kempthorne", 2887, id="ak-q2887"),
                                     pytest.param("addelman-kempthorne", 251, id="ak-q251"),
                                     pytest.param("bose-bush", 128, id="bb-s128")])
def test_index2_reference_follows_spec(name, s):
    """Whole values (permutations, offsets, jitter, blocks) of the reference against
    the documented construction with an independent field: random rows, columns in
    three blocks, the last sample and the last column j = 2s, edge seeds."""
    rng = np.random.default_rng(s + (0 if name == "bose-bush" else 10**6))
    N, d = 2 * s * s, 2 * s + 1
    for k in range(100 if s <= 256 else 25):
        i, j = int(rng.integers(0, N)), int(rng.integers(0, 3 * d))
        if k < 5:
            i, j = [(N - 1, 2 * s), (N - 1, d), (0, 2 * d - 1), (s * s, 2 * s), (s * s - 1, s)][k]
        p = int(rng.choice([0, 1, U32_MAX])) if k % 4 == 0 else int(rng.integers(0, 2**32))
        offset, J = OFFSETS[k % 4], [1.0, 0.0, 0.8125][k % 3]
        fn = getattr(ref, name.replace("-", "_"))
        assert _same_f32(fn(i, j, s, p, offset, J), _index2_from_spec(name, i, j, s, p, offset, J)), \
            (name, i, j, s, p, offset, J)


@pytest.mark.parametrize("name, s", [("addelman-kempthorne", 3), ("addelman-kempthorne", 5), ("bose-bush", 2),
                                     ("bose-bush", 4)])
def test_index2_oa_reference(name, s):
    N, d = 2 * s * s, 2 * s + 1
    fn = getattr(ref, name.replace("-", "_"))
    plain = plain_index2_array(name, s)[0]
    for p in (1, U32_MAX):
        for offset in OFFSETS:
            x0 = _ref_array(lambda i, j, **kw: fn(i, j, s, **kw), N, range(d), p=p, offset=offset, jitter=0.0)
            x1 = _ref_array(lambda i, j, **kw: fn(i, j, s, **kw), N, range(d), p=p, offset=offset, jitter=1.0)
            check_array(x0, x1, s, 2, N, [range(d)], offset, f"{name} s={s} p={p} {offset}")
            if s >= 3:
                assert not np.array_equal(strata_exact(x0, s), plain)


#: (name, s, offset) of the bulk property test: every offset for the smaller arrays,
#: the Latin-hypercube offsets (cmj: the table path; mj: the direct path) for the larger
INDEX2_BULK = [pytest.param(name, s, offset, id=f"{tag}{s}-{offset}")
               for name, tag, levels in (("addelman-kempthorne", "ak-q", AK_Q), ("bose-bush", "bb-s", BB_S))
               for s in levels
               for offset in (OFFSETS if s <= 13 else ("cmj", "mj") if s < 32 else ("cmj",))]


@pytest.mark.parametrize("name, s, offset", INDEX2_BULK)
def test_index2_oa_bulk(backend, name, s, offset):
    """Many seeds (pixels), both backends: every pair of ALL 2s+1 columns of each
    block shows each of the s^2 cells exactly twice (index 2), mj/cmj are Latin
    hypercubes at N = 2s^2 cells in every column (the last one included), values
    lie in [0, 1), and blocks past the first (dimensions past 2s+1, the partial
    third block too) are differently randomized valid copies."""
    N, d = 2 * s * s, 2 * s + 1
    dims = 2 * d + 2
    seed = {"centered": 0, "j": 7, "mj": 0xDEADBEEF, "cmj": U32_MAX}[offset]
    x0, x1 = _bulk(name, N, dims, backend, offset, seed=seed, n_pixels=4 if s >= 32 else _pixels_for(N * d // 6))
    check_blocks(x0, x1, s, 2, N, d, 2, offset, f"{name} s={s} {offset} seed={seed} [{backend}]")
    assert_oa(strata_exact(x0, s), s, 2, cols=range(2 * d, dims))
    if s >= 3:  # each pixel's array is randomized, not the canonical one
        plain = plain_index2_array(name, s)[0]
        assert not (strata_exact(x0[..., :d], s) == plain).all(axis=(-2, -1)).any()


@pytest.mark.parametrize("name, s", [("addelman-kempthorne", 3), ("addelman-kempthorne", 9),
                                     ("addelman-kempthorne", 49), ("addelman-kempthorne", 61),
                                     ("bose-bush", 2), ("bose-bush", 8), ("bose-bush", 32), ("bose-bush", 64)])
def test_index2_latin_many_seeds(backend, name, s):
    """mj and cmj: 1D Latin hypercube at N = 2s^2 cells in every column, the last
    one (j = 2s) included, over many seeds (pixels x user seeds)."""
    N, d = 2 * s * s, 2 * s + 1
    cols = range(d) if d <= 20 else [0, 1, s - 1, s, s + 1, 2 * s - 1, 2 * s]
    for offset in ("mj", "cmj"):
        for seed in (1, 2**31, U32_MAX):
            x = pyoa.sampler(name, spp=N, dims=d, seed=seed, offset=offset, jitter=0.0,
                             backend=backend).generate(pixels=range(max(2, 6000 // N)), dims=cols)
            assert in_unit_interval(x)
            assert_latin_exact(x, N, f"{name} s={s} {offset} seed={seed}")
            assert_oa(strata_exact(x, s), s, 2)


# ----------------------------------------------------------------------------- unbiasedness (docs/spec.md 8.6)

def _f_cos(x):
    """prod_d (1 + 0.4 cos(2 pi x_d + d)): integral 1."""
    ph = np.arange(x.shape[-1])
    return np.prod(1 + 0.4 * np.cos(2 * np.pi * x + ph), axis=-1)


def _f_sq(x):
    """(sum_d x_d)^2: integral d/12 + d^2/4."""
    return np.sum(x, axis=-1) ** 2


def _f_step(x):
    """1 if x_0 + x_1 + x_2 < 1.2 (a discontinuous integrand) else 0: integral of the
    simplex-like region, P(U1+U2+U3 < 1.2) = 1.2^3/6 - 3*0.2^3/6 = 0.284."""
    return (x[..., 0] + x[..., 1] + x[..., 2] < 1.2).astype(np.float64)


@pytest.mark.parametrize(
    "name, spp, dims, strength, offset",
    [("bose", 49, 11, None, "cmj"), ("bose", 121, 5, None, "j"), ("cmjnd", 64, 7, 3, "cmj"),
     ("cmjnd", 81, 6, 2, "mj"), ("bose", 25, 4, None, "mj"), ("cmjnd", 9, 3, 1, "j"),
     ("bose", 64, 11, None, "cmj"), ("bush", 64, 7, 3, "cmj"), ("bush", 81, 5, 2, "mj"), ("bush", 256, 6, 4, "j"),
     ("addelman-kempthorne", 50, 13, None, "cmj"), ("addelman-kempthorne", 18, 9, None, "j"),
     ("bose-bush", 32, 11, None, "mj"), ("bose-bush", 8, 6, None, "cmj")],
)
def test_estimates_are_unbiased(backend, name, spp, dims, strength, offset):
    """Mean over pixels (independent arrays) of the per-pixel estimate is within 5
    standard errors of the integral. Not for `centered`: docs/spec.md section 4 puts every
    point in the middle fine cell of its coarse stratum, which is not uniform on
    [0, 1) (see test_centered_offset_is_not_uniform)."""
    n_pixels = 3000
    smp = pyoa.sampler(name, spp=spp, dims=dims, strength=strength, offset=offset, seed=2024, backend=backend)
    x = smp.generate(pixels=range(n_pixels)).astype(np.float64)
    for f, truth in ((_f_cos, 1.0), (_f_sq, dims / 12 + dims**2 / 4), (_f_step, 1.2**3 / 6 - 3 * 0.2**3 / 6)):
        est = f(x).mean(axis=1)  # one estimate per pixel (an independent array)
        se = est.std(ddof=1) / np.sqrt(n_pixels)
        err = abs(est.mean() - truth)
        assert err <= 5 * se + 1e-12, f"{f.__name__}: mean {est.mean():.6f} vs {truth:.6f}, {err / se:.1f} standard errors"


def test_unbiasedness_check_detects_a_biased_sampler():
    """The bound above has teeth: shifting every value by a fraction of a fine cell
    (a bias far below the per-pixel noise) is detected."""
    n_pixels = 3000
    x = pyoa.sampler("bose", spp=49, dims=4, seed=2024, backend="numpy").generate(pixels=range(n_pixels)).astype(np.float64)
    xb = np.minimum(x + 0.25 / 49, 1 - 1e-9)
    est = _f_sq(xb).mean(axis=1)
    se = est.std(ddof=1) / np.sqrt(n_pixels)
    assert abs(est.mean() - (4 / 12 + 4)) > 5 * se


def test_centered_offset_is_not_uniform():
    """docs/spec.md section 4's `centered` only covers the middle fine cell of each coarse
    stratum (sub = (M-1)/2), so it cannot be unbiased (docs/spec.md 8.6 excludes it in effect)."""
    s = 5
    x = pyoa.sampler("bose", spp=25, dims=3, offset="centered", backend="numpy").generate(pixels=range(50))
    frac = (x.astype(np.float64) * s) % 1
    assert frac.min() >= 0.4 - 1e-6 and frac.max() <= 0.6 + 1e-6


# ----------------------------------------------------------------------------- reference parameter checks

@pytest.mark.parametrize("s", [1, 6, 12, 289, 512, 4096])
def test_reference_bose_refuses_unsupported_s(s):
    with pytest.raises(ValueError, match=f"prime power.*s={s}"):
        ref.bose(0, 0, s, 0)


@pytest.mark.parametrize("s, t", [(2, 3), (3, 4), (4, 5), (4, 1), (5, 0), (6, 2), (10, 3), (289, 2), (512, 2)])
def test_reference_bush_refuses_bad_s_or_t(s, t):
    with pytest.raises(ValueError, match=f"s={s}, t={t}"):
        ref.bush(0, 0, s, t, 0)


@pytest.mark.parametrize("kw, words", [
    ({"i": 64}, ["[0, 64)", "64"]), ({"i": -1}, ["[0, 64)"]), ({"j": -1}, ["dimension"]),
    ({"p": 2**32}, ["seed"]), ({"p": -1}, ["seed"]), ({"offset": "cj"}, ["offset", "'cj'"]),
    ({"jitter": 1.5}, ["jitter"]), ({"jitter": float("nan")}, ["jitter"]),
])
def test_reference_bush_refuses_bad_arguments(kw, words):
    args = {"i": 0, "j": 0, "s": 4, "t": 3, "p": 0, "offset": "cmj", "jitter": 1.0, **kw}
    with pytest.raises(ValueError) as info:
        ref.bush(**args)
    for w in words:
        assert w in str(info.value)
    if "i" not in kw and "j" not in kw:
        with pytest.raises(ValueError):
            ref.bose(**{k: v for k, v in args.items() if k != "t"})


@pytest.mark.parametrize("q", [1, 2, 4, 8, 15, 45, 256, 289, 343, 729, 4096])
def test_reference_addelman_kempthorne_refuses_unsupported_q(q):
    """q must be odd and a prime, or a prime power <= 256 (289 = 17^2, 343 = 7^3 and
    729 = 3^6 have no tables)."""
    with pytest.raises(ValueError, match=f"odd prime.*got {q}$"):
        ref.addelman_kempthorne(0, 0, q, 0)


@pytest.mark.parametrize("s", [0, 1, 3, 6, 12, 256, 512])
def test_reference_bose_bush_refuses_unsupported_s(s):
    with pytest.raises(ValueError, match=f"power of two.*got {s}$"):
        ref.bose_bush(0, 0, s, 0)


@pytest.mark.parametrize("fn, s", [(ref.addelman_kempthorne, 3), (ref.bose_bush, 4)])
@pytest.mark.parametrize("kw, words", [
    ({"i": "N"}, ["[0, N)"]), ({"i": -1}, ["[0, N)"]), ({"j": -1}, ["dimension"]),
    ({"p": 2**32}, ["seed"]), ({"p": -1}, ["seed"]), ({"offset": "cj"}, ["offset", "'cj'"]),
    ({"jitter": 1.5}, ["jitter"]), ({"jitter": float("nan")}, ["jitter"]),
])
def test_reference_index2_refuses_bad_arguments(fn, s, kw, words):
    N = 2 * s * s
    args = {"i": 0, "j": 0, "p": 0, "offset": "cmj", "jitter": 1.0, **kw}
    if args["i"] == "N":
        args["i"] = N
    with pytest.raises(ValueError) as info:
        fn(args["i"], args["j"], s, args["p"], args["offset"], args["jitter"])
    for w in words:
        assert w.replace("N", str(N)) in str(info.value)
    # the last sample and any dimension are fine
    assert 0 <= fn(N - 1, 10 * (2 * s + 1), s, U32_MAX) < 1
