"""SPEC sections 5, 6 and 8: the orthogonal-array properties of Bose and CMJND,
on the pure-Python reference (few seeds) and on the bulk API (many pixels, each
an independently randomized array).

Recovering the integer structure from float32 values: with jitter amount 0
every point sits at the centre of its fine cell, far from any boundary, so
``floor(x*s)`` is the stratum and ``floor(x*N)`` the fine cell exactly. With full
jitter a value may round onto the upper boundary of its cell, so those values
are checked against the closed cells of the jitter-0 run (same seed: jitter
does not change the permutations).
"""

from __future__ import annotations

import numpy as np
import pytest

import pyoa
from pyoa import reference as ref
from tests.helpers import (
    OFFSET_CODE,
    U32_MAX,
    assert_latin_closed,
    assert_latin_exact,
    assert_oa,
    assert_same_bits,
    bose_partner_symbol,
    bose_symbol,
    in_unit_interval,
    strata_exact,
)

OFFSETS = ["centered", "j", "mj", "cmj"]
BOSE_S = [2, 3, 5, 7, 11, 13]
CMJND_ST = [(s, t) for s in range(2, 7) for t in range(2, 5)]


# ----------------------------------------------------------------------------- independent C oracle

def test_reference_values_match_c_oracle(spec_c):
    """pyoa.reference.bose / cmjnd against spec_hashes.c written from SPEC sections 3, 5-7."""
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
    # the plain array by its formula, written out for s = 3 (SPEC section 5)
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
    """x0: jitter-0 values, x1: full-jitter values, shape (..., N, d)."""
    assert in_unit_interval(x0) and in_unit_interval(x1), what
    S = strata_exact(x0, s)
    for cols in cols_blocks:
        assert_oa(S, s, t, cols=cols, what=what)
    if offset in ("mj", "cmj"):
        assert_latin_exact(x0, N, what)
        assert_latin_closed(x1, N, what)
    if offset == "centered":
        assert_same_bits(x0, ((S + 0.5) / s).astype(np.float32), f"{what}: centred, jitter 0")
    # full jitter stays inside the (closed) fine cell chosen by the permutations: the
    # cell whose centre is the jitter-0 point (for `centered` with M even that centre
    # is the middle of the coarse stratum, so the cell straddles two fine cells)
    low = x0.astype(np.float64) * N - 0.5
    pos = x1.astype(np.float64) * N - low
    tol = 4 * N * 2.0**-24
    assert pos.min() >= -tol and pos.max() <= 1 + tol, f"{what}: jitter leaves the fine cell"
    # and it does jitter (not all at the centre)
    assert np.abs(pos - 0.5).max() > 0.2 or N > 2**20, what


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


def _bulk(name, spp, dims, backend, offset, strength=None, seed=0):
    kw = dict(spp=spp, dims=dims, offset=offset, strength=strength, seed=seed, backend=backend)
    pixels = list(range(N_PIXELS - 2)) + [U32_MAX - 1, U32_MAX]
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


# ----------------------------------------------------------------------------- unbiasedness (SPEC 8.6)

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
     ("cmjnd", 81, 6, 2, "mj"), ("bose", 25, 4, None, "mj"), ("cmjnd", 9, 3, 1, "j")],
)
def test_estimates_are_unbiased(backend, name, spp, dims, strength, offset):
    """Mean over pixels (independent arrays) of the per-pixel estimate is within 5
    standard errors of the integral. Not for `centered`: SPEC section 4 puts every
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
    """SPEC section 4's `centered` only covers the middle fine cell of each coarse
    stratum (sub = (M-1)/2), so it cannot be unbiased (SPEC 8.6 excludes it in effect)."""
    s = 5
    x = pyoa.sampler("bose", spp=25, dims=3, offset="centered", backend="numpy").generate(pixels=range(50))
    frac = (x.astype(np.float64) * s) % 1
    assert frac.min() >= 0.4 - 1e-6 and frac.max() <= 0.6 + 1e-6
