"""``faure``: Owen-scrambled Faure (0, s)-sequences in a prime base
(pyoa/catalogue/faure.py, pyoa/reference/faure.py, pyoa/_numpy/faure.py,
kernels/include/pyoa/faure.h), exactly.

- Nets: every aligned block of ``b**m`` samples of a pixel is a (0, m, b)-net
  in base ``b``, in every block of ``b`` dimensions (block 0 and the
  re-scrambled copies, blocks 1 and 2), for bases 2 to 31, edge seeds and
  pixels, over two or more aligned blocks; every prefix of ``lam * b**m``
  samples holds ``lam`` points in every elementary box, counted directly.
- The unscrambled sequence (point-set seed ``p == 0``, reachable only through
  the functions themselves) equals Faure's, computed here again from the
  generator matrices ``P**c`` (``P[k][r] = C(r, k) mod b``), truncated to 24
  bits with the cell clamp.
- Progressive: the first ``n`` samples of a larger count are the samples of
  ``spp=n`` (same base), bit for bit, on both backends; every catalogue
  entry's ``spp_invariant`` flag is checked against its values.
- Kernel == NumPy == reference at the edges (``2**24`` samples in base 2, the
  largest base 4093, the last of ``2**20`` dimensions, seeds 0 and
  ``2**32 - 1``), and on hypothesis-drawn arguments (reference vs NumPy).
- Unbiased over randomizations; the API (``base=`` validation, the default
  base, ``Sampler.base``, pickle, repr), the qmc engine and the CLI.

Every stratification check counts the ``floor(x * b**e)`` of float32 values,
which is exact in float64.
"""

from __future__ import annotations

import copy
import functools
import itertools
import math
import pickle
import random
import re
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

import pyoa
from pyoa import catalogue
from pyoa.catalogue import faure as prog
from pyoa._numpy import faure as nf
from pyoa.qmc import OrthogonalArray
from pyoa.reference import faure as rf
from pyoa.samplers import trial_options
from tests.helpers import (
    U32_MAX,
    assert_same_bits,
    compositions,
    kernel_runner,
    net_failures,
    reference_block,
    run_cli,
)

U32 = np.uint32
F32 = np.float32
MAX_SPP = 2**24
MAX_DIMS = 2**20


def faure(spp, dims, base=None, seed=0, backend="numpy"):
    return pyoa.sampler("faure", spp=spp, dims=dims, seed=seed, base=base, backend=backend)


# =============================================================================== nets

#: (base, largest m checked, triples checked at m >= 3 per block: None = all).
#: Bases >= 13 check, at m = 3, every 1D projection and every pair of block 0,
#: but only a fixed random sample of its triples (and of the pairs and triples
#: of blocks 1 and 2), so that the suite stays fast; smaller bases check every
#: 1D, 2D and 3D projection of all three blocks, up to m = 8 (base 2).
NET_BASES = [(2, 8, None), (3, 5, None), (5, 4, None), (7, 3, None), (11, 3, None), (13, 3, 120), (31, 3, 120)]
#: (user seed, pixels): seeds 0 and 2**32 - 1, the first and the last pixel
#: (bases >= 13: the first two, one pixel each)
NET_SEEDS = [(0, [0, U32_MAX]), (U32_MAX, [U32_MAX]), (20190710, [7])]
#: nets of m < m_max digits are checked on the first max(2 b^m, this) samples
NET_LOWER_SAMPLES = 4096
#: a fixed sample (its own generator: the test order cannot change it)
SAMPLE_SEED = 2026


def box_failures(x: np.ndarray, b: int, m: int, subsets) -> list[str]:
    """Where an aligned block of ``b**m`` samples of ``x`` (pixels, n, dims)
    does not put exactly one point in each elementary box of volume
    ``b**-m`` of the projection onto a subset of ``subsets``: boxes
    ``prod [a_k b**-e_k, (a_k + 1) b**-e_k)`` with every ``e_k >= 1`` (a box
    with some ``e_k = 0`` is one of a smaller subset, checked as that).
    :func:`tests.helpers.net_failures` checks the same boxes (and those again
    for every superset); this one caches each ``floor(x * b**e)``, so the
    bases with many dimensions stay fast. Empty: every net holds."""
    P, N, _ = x.shape
    size = b**m
    nblk = N // size
    xs = np.asarray(x[:, :nblk * size], np.float64).reshape(P * nblk * size, -1)
    block = np.arange(xs.shape[0], dtype=np.int64) // size * size  # first box of each (pixel, block)

    @functools.cache
    def digits(c, e):
        return np.floor(xs[:, c] * b**e).astype(np.int64)

    fails = []
    for sub in subsets:
        if len(sub) > m:
            continue
        for rest in compositions(m - len(sub), len(sub)):
            split = tuple(r + 1 for r in rest)
            code = np.zeros(xs.shape[0], np.int64)
            for c, e in zip(sub, split):
                code = code * b**e + digits(c, e)
            if np.bincount(block + code, minlength=xs.shape[0]).max() != 1:
                fails.append(f"dims {sub} split {split}")
    return fails


def _block_subsets(cols, m, triples, rng):
    """Every projection onto ``k <= min(m, 3)`` of ``cols`` (one block), with
    only ``triples`` (drawn by ``rng``) of the 3D ones when that is given."""
    subs = []
    for k in range(1, min(m, 3, len(cols)) + 1):
        ks = list(itertools.combinations(cols, k))
        if triples is not None and k == 3 and len(ks) > triples:
            ks = rng.sample(ks, triples)
        subs += ks
    return subs


@pytest.mark.parametrize("b, m_max, triples", NET_BASES, ids=[f"b{b}" for b, _, _ in NET_BASES])
def test_aligned_blocks_are_nets(b, m_max, triples):
    """Every aligned block of ``b**m`` samples (``1 <= m <= m_max``; two
    blocks of ``b**m_max`` and at least two of each smaller ``b**m``, so
    blocks past the first are checked too) is a (0, m, b)-net: each
    elementary box of volume ``b**-m`` of each 1D, 2D and 3D projection
    inside one block of ``b`` dimensions holds exactly one point, in
    dimension blocks 0, 1 and 2."""
    N = 2 * b**m_max
    dims = 3 * b
    if triples is None:  # every dimension of the three blocks
        sel = list(range(dims))
        blocks = [list(range(k * b, (k + 1) * b)) for k in range(3)]
    else:  # block 0 whole; blocks 1 and 2: their first four and last two dimensions
        sel = list(range(b)) + [k * b + c for k in (1, 2) for c in (0, 1, 2, 3, b - 2, b - 1)]
        blocks = [list(range(b)), list(range(b, b + 6)), list(range(b + 6, b + 12))]
    seeds = NET_SEEDS if triples is None else [(0, [U32_MAX]), (U32_MAX, [0])]
    for seed, pixels in seeds:
        x = faure(N, dims, base=b, seed=seed).generate(pixels=pixels, dims=sel)
        rng = random.Random(SAMPLE_SEED)
        for m in range(1, m_max + 1):
            n = N if m == m_max else min(N, max(2 * b**m, NET_LOWER_SAMPLES))
            subsets = []
            for k, cols in enumerate(blocks):
                if triples is None or (k == 0 and m < 3):
                    subsets += _block_subsets(cols, m, None, rng)
                elif k == 0:  # every pair, a sample of the triples
                    subsets += _block_subsets(cols, m, triples, rng)
                else:  # the other blocks: a sample of their pairs and triples
                    pairs = list(itertools.combinations(cols, 2))
                    subsets += [(c,) for c in cols] + rng.sample(pairs, min(len(pairs), 6))
                    if m >= 3:
                        subsets += rng.sample(list(itertools.combinations(cols, 3)), 4)
            fails = box_failures(x[:, :n], b, m, subsets)
            assert not fails, f"base {b}, seed {seed}, pixels {pixels}: blocks of {b}^{m} not nets: {fails[:4]}"


def test_box_check_agrees_with_net_failures():
    """The local check gives the verdict of :func:`tests.helpers.net_failures`
    on nets, on the same points with two values of one dimension swapped
    across blocks, and on uniform random points (both fail)."""
    b, m = 3, 3
    x = faure(2 * b**m, 2 * b, base=b, seed=8).generate(pixels=[0, 1])
    subsets = [s for blk in (range(b), range(b, 2 * b)) for k in (1, 2, 3) for s in itertools.combinations(blk, k)]
    assert box_failures(x, b, m, subsets) == [] == net_failures(x, b, m, b)
    bad = x.copy()
    bad[1, 0, 4], bad[1, b**m, 4] = x[1, b**m, 4], x[1, 0, 4]  # pixel 1: samples 0 and 27 trade dimension 4
    assert box_failures(bad, b, m, subsets) and net_failures(bad, b, m, b)
    assert {f.split(" split")[0] for f in box_failures(bad, b, m, subsets)} <= {
        f"dims {s}" for s in subsets if 4 in s}
    noise = np.random.default_rng(1).random(x.shape).astype(F32)
    assert box_failures(noise, b, m, subsets) and net_failures(noise, b, m, b)


def _box_counts(x, b, sub, split):
    """Points of each pixel of ``x`` (pixels, n, dims) in each elementary box
    ``prod [a_k b**-e_k, (a_k + 1) b**-e_k)`` of the projection onto ``sub``."""
    P, n, _ = x.shape
    m = sum(split)
    code = np.zeros((P, n), np.int64)
    for c, e in zip(sub, split):
        code = code * b**e + np.floor(np.asarray(x[:, :, c], np.float64) * b**e).astype(np.int64)
    code += np.arange(P)[:, None] * b**m
    return np.bincount(code.ravel(), minlength=P * b**m).reshape(P, b**m)


@pytest.mark.parametrize("b, m_max", [(3, 3), (5, 3), (7, 2)])
def test_every_prefix_of_lam_b_m_samples_has_lam_points_per_box(b, m_max):
    """The first ``lam * b**m`` samples (``1 <= lam < b``) put exactly ``lam``
    points in every elementary box of volume ``b**-m`` (every 1D, 2D and 3D
    projection of dimension blocks 0 and 1), counted box by box."""
    x = faure(b ** (m_max + 1), 2 * b, base=b, seed=U32_MAX).generate(pixels=[0, 5, U32_MAX])
    subsets = [s for blk in (range(b), range(b, 2 * b)) for k in (1, 2, 3) for s in itertools.combinations(blk, k)]
    for m in range(1, m_max + 1):
        for lam in range(1, b):
            n = lam * b**m
            for sub in subsets:
                for split in compositions(m, len(sub)):
                    counts = _box_counts(x[:, :n], b, sub, split)
                    assert (counts == lam).all(), (
                        f"base {b}: first {n} = {lam} x {b}^{m} samples, dims {sub}, box {split}: counts "
                        f"{sorted(set(counts.ravel().tolist()))}, not all {lam}")


# =============================================================================== unscrambled: Faure's sequence

def _matmul(A, B, b):
    n = len(A)
    return [[sum(A[r][k] * B[k][c] for k in range(n)) % b for c in range(n)] for r in range(n)]


def pascal_power(c: int, n: int, b: int) -> list[list[int]]:
    """Faure's generator matrix of coordinate ``c``: ``P**c mod b``, with
    ``P[k][r] = C(r, k) mod b`` (upper triangular), by repeated squaring."""
    P = [[math.comb(r, k) % b for r in range(n)] for k in range(n)]
    R = [[int(r == k) for r in range(n)] for k in range(n)]
    while c:
        if c & 1:
            R = _matmul(R, P, b)
        P = _matmul(P, P, b)
        c >>= 1
    return R


def faure_exact(i: int, c: int, b: int, n: int) -> Fraction:
    """Point ``i``, coordinate ``c`` of Faure's sequence: the radical inverse
    of ``P**c`` applied to the ``n`` digits of ``i`` (least significant first)."""
    a = [(i // b**r) % b for r in range(n)]
    C = pascal_power(c, n, b)
    y = [sum(C[k][r] * a[r] for r in range(n)) % b for k in range(n)]
    return sum(Fraction(y[k], b ** (k + 1)) for k in range(n))


def float24(F: Fraction, b: int) -> Fraction:
    """``F`` as pyoa stores it: ``floor(2**24 F)``, raised to the first
    multiple of ``2**-24`` of ``F``'s cell of width ``b**-L`` (``L`` the most
    digits with ``b**L <= 2**24``) when the truncation left that cell."""
    L = max(e for e in range(25) if b**e <= MAX_SPP)
    cell = math.floor(F * b**L)
    x = max(math.floor(F * MAX_SPP), math.ceil(Fraction(cell * MAX_SPP, b**L)))
    return Fraction(x, MAX_SPP)


#: (base, indices): every index of a few blocks, and the last indices below 2**24
UNSCRAMBLED = [(2, list(range(64)) + [2**23, MAX_SPP - 1]), (3, list(range(81)) + [3**15 - 1, MAX_SPP - 1]),
               (5, list(range(125)) + [MAX_SPP - 1]), (7, list(range(0, 2401, 7)) + [MAX_SPP - 1]),
               (13, list(range(0, 13**3, 11)) + [MAX_SPP - 1]), (31, [0, 1, 30, 31, 961, 29790, MAX_SPP - 1]),
               (4093, [0, 1, 4092, 4093, 4093**2 - 1, 4093**2, MAX_SPP - 1])]


@pytest.mark.parametrize("b, indices", UNSCRAMBLED, ids=[f"b{b}" for b, _ in UNSCRAMBLED])
def test_unscrambled_is_faures_sequence(b, indices):
    """``p == 0`` (first block of dimensions): the value is Faure's point from
    ``P**c`` truncated by :func:`float24`, for the fewest digits ``n`` of the
    index and for more (the value does not depend on ``n``); within
    ``2**-24`` of the exact rational point and in the same ``b**-L`` cell;
    NumPy gives the same bits."""
    L = max(e for e in range(25) if b**e <= MAX_SPP)
    cols = sorted({0, 1, 2, b // 2, b - 1} & set(range(b)))
    for c in cols:
        for i in indices:
            n = rf.index_digits(b, i + 1)
            F = faure_exact(i, c, b, n)
            want = float24(F, b)
            for digits in (n, n + 1):
                got = rf.faure(i, c, b, digits, 0)
                assert Fraction(got) == want, f"b={b} i={i} c={c} n={digits}: {got!r} != {float(want)!r} (F={F})"
            assert abs(want - F) < Fraction(1, MAX_SPP)
            assert math.floor(want * b**L) == math.floor(F * b**L)
        if c == 0:  # coordinate 0 is van der Corput's radical inverse
            for i in indices[:20]:
                n = rf.index_digits(b, i + 1)
                radical = sum(Fraction((i // b**r) % b, b ** (r + 1)) for r in range(n))
                assert faure_exact(i, 0, b, n) == radical
        n = rf.index_digits(b, max(indices) + 1)
        got = nf.faure(np.array(indices, U32), U32(c), b, n, U32(0))
        want = np.array([rf.faure(i, c, b, n, 0) for i in indices], F32)
        assert_same_bits(got, want, f"numpy b={b} c={c} p=0")


def test_pascal_power_is_the_taylor_shift():
    """The independent generator matrices, checked against their closed form
    ``(P**c)[k][r] = C(r, k) c**(r - k) mod b``."""
    for b, n in [(2, 6), (3, 5), (7, 4), (13, 3)]:
        for c in range(b):
            want = [[math.comb(r, k) * c ** (r - k) % b if r >= k else 0 for r in range(n)] for k in range(n)]
            assert pascal_power(c, n, b) == want, (b, c)


def test_only_the_first_block_is_unscrambled_at_p_0():
    """``p == 0`` leaves dimensions ``0 .. b-1`` unscrambled; the copies of
    blocks 1, 2 are scrambled (they differ from the unscrambled coordinate)."""
    b, n = 5, 3
    for c in range(b):
        plain = [rf.faure(i, c, b, n, 0) for i in range(b**n)]
        assert plain == [float(float24(faure_exact(i, c, b, n), b)) for i in range(b**n)]
        for block in (1, 2):
            assert [rf.faure(i, block * b + c, b, n, 0) for i in range(b**n)] != plain, (c, block)


# =============================================================================== progressive

PROGRESSIVE_BASES = [2, 3, 7, 31]


@pytest.mark.parametrize("b", PROGRESSIVE_BASES)
def test_prefix_of_a_larger_count_is_the_smaller_count(b, backend):
    """For a given base, sample ``i`` of a pixel does not depend on ``spp``:
    the first ``n`` samples of ``spp=1000`` are ``spp=n``'s, bit for bit."""
    pixels = [0, 9, U32_MAX]
    dims = b + 3  # past the first block
    full = faure(1000, dims, base=b, seed=5, backend=backend).generate(pixels=pixels)
    for n in sorted({1, 2, b - 1, b, b + 1, b * b - 1, b * b, 100, 999}):
        if 1 <= n <= 1000:
            got = faure(n, dims, base=b, seed=5, backend=backend).generate(pixels=pixels)
            assert_same_bits(got, full[:, :n], f"base {b}: spp={n} vs the first {n} of spp=1000")


@pytest.mark.parametrize("b", PROGRESSIVE_BASES)
def test_sample_ranges_are_slices_of_the_whole(b, backend):
    smp = faure(1000, 6, base=b, seed=U32_MAX, backend=backend)
    full = smp.generate(pixels=[3, 4])
    for a, c in [(0, 1), (0, 1000), (b, b * b), (999, 1000), (123, 877)]:
        assert_same_bits(smp.generate(pixels=[3, 4], samples=range(a, c)), full[:, a:c], f"range({a}, {c})")
    order = [999, 0, 500, b, 1]
    assert_same_bits(smp.generate(pixels=[3, 4], samples=order), full[:, order], "samples in any order")


def test_the_default_base_depends_on_spp():
    """Without ``base`` the base follows ``spp`` (so do the samples); with it
    the prefixes agree: a render continued to another count gives the base."""
    small, large = faure(121, 40, seed=2), faure(1000, 40, seed=2)
    assert (small.base, large.base) == (11, 31)
    assert not np.array_equal(small.generate(), large.generate()[:, :121])
    assert_same_bits(faure(1000, 40, base=11, seed=2).generate()[:, :121], small.generate(), "base=11 given")


def _counts(name: str) -> list[int]:
    """A few valid counts of ``name``, from 1 to about 1000 (its own)."""
    return sorted({c.spp for t in (1, 5, 17, 64, 300, 1000) for c in pyoa.valid_spp(name, near=t, dims=4)
                   if c.spp <= 1024})


def _prefixes_agree(name: str, small: int, large: int) -> bool:
    kw = trial_options(name, {})
    a = pyoa.sampler(name, spp=small, dims=4, seed=31, backend="numpy", **kw)
    if a.base is not None:
        kw["base"] = a.base  # spp-invariant for a given base
    b = pyoa.sampler(name, spp=large, dims=4, seed=31, backend="numpy", **kw)
    pixels = [0, 7, 1000]
    return np.array_equal(a.generate(pixels=pixels).view(U32), b.generate(pixels=pixels, samples=range(small)).view(U32))


INVARIANT = [n for n, c in catalogue.SAMPLERS.items() if c.spp_invariant]
DEPENDENT = [n for n, c in catalogue.SAMPLERS.items() if not c.spp_invariant]


def test_faure_is_flagged_progressive_and_spp_invariant():
    entry = catalogue.get("faure")
    assert entry.progressive and entry.spp_invariant and entry.family == "progressive"
    assert "faure" in INVARIANT


@pytest.mark.parametrize("name", INVARIANT)
def test_spp_invariant_entries_keep_their_prefixes(name):
    """``spp_invariant = True``: the first ``n`` samples of every larger valid
    count are ``spp=n``'s (faure: for the base of ``spp=n``)."""
    counts = _counts(name)
    assert len(counts) >= 4
    for small, large in itertools.combinations(counts, 2):
        assert _prefixes_agree(name, small, large), f"{name}: spp={small} != first {small} of spp={large}"


@pytest.mark.parametrize("name", DEPENDENT)
def test_spp_dependent_entries_do_depend_on_spp(name):
    """``spp_invariant = False`` is honest: some smaller valid count is not
    the prefix of a larger one."""
    counts = _counts(name)
    assert len(counts) >= 2
    assert any(not _prefixes_agree(name, small, large) for small, large in itertools.combinations(counts, 2)), (
        f"{name}: every prefix of {counts} equals the smaller count's samples, yet spp_invariant is False")


# =============================================================================== kernel == NumPy == reference

#: (base, spp, dims): 2**24 samples in base 2 (24 index digits), the largest
#: base, the largest number of dimensions, a small odd case
EDGE_SHAPES = [(2, MAX_SPP, MAX_DIMS), (4093, MAX_SPP, MAX_DIMS), (3, MAX_SPP, 10), (31, 1000, 100), (4093, 5, 3)]


def _edges(n: int, extra=()) -> list[int]:
    return sorted(v for v in {0, 1, n // 2, n - 2, n - 1, *extra} if 0 <= v < n)


@pytest.mark.opencl
@pytest.mark.parametrize("b, spp, dims", EDGE_SHAPES, ids=[f"b{b}-spp{s}-dims{d}" for b, s, d in EDGE_SHAPES])
def test_kernel_numpy_and_reference_at_the_edges(opencl, b, spp, dims):
    samples = _edges(spp, [b - 1, b, b * b - 1, b * b])
    dim_sel = _edges(dims, [b - 1, b, 2 * b - 1])
    for seed in (0, U32_MAX):
        smp = faure(spp, dims, base=b, seed=seed, backend="opencl")
        got = smp.generate(pixels=[0, U32_MAX], samples=samples, dims=dim_sel)
        want = reference_block(smp, [0, U32_MAX], samples, dim_sel)
        assert_same_bits(got, want, f"kernel vs reference: base {b}, spp {spp}, seed {seed}")
        ref = faure(spp, dims, base=b, seed=seed).generate(pixels=[0, U32_MAX], samples=samples, dims=dim_sel)
        assert_same_bits(ref, want, f"numpy vs reference: base {b}, spp {spp}, seed {seed}")


TEST_KERNELS = r"""
__kernel void tf_faure(__global const uint *i, __global const uint *j, __global const uint *b,
                       __global const uint *n, __global const uint *p, __global float *out)
{
    size_t g = get_global_id(0);
    out[g] = pyoa_sample_faure(i[g], j[g], b[g], n[g], p[g]);
}
"""


@pytest.mark.opencl
def test_kernel_function_at_point_set_seeds_0_and_max(opencl):
    """``sample_faure`` itself at the point-set seeds the sampler API cannot
    choose (``p == 0``: unscrambled; ``2**32 - 1``), 1, 2 and the most index
    digits (24 in base 2), the largest bases, dimensions up to ``2**32 - 1``,
    against NumPy and the reference."""
    rows = []
    for b in (2, 3, 5, 4093, 4091, 257):
        top = rf.index_digits(b, MAX_SPP)
        for n in sorted({1, 2, top}):
            hi = min(MAX_SPP, b**n)
            for i in _edges(hi):
                for j in (0, b - 1, b, MAX_DIMS - 1, U32_MAX):
                    for p in (0, 1, U32_MAX):
                        rows.append((i, j, b, n, p))
    i, j, b, n, p = (np.array(col, U32) for col in zip(*rows))
    got = kernel_runner(opencl, TEST_KERNELS)("tf_faure", [F32], i, j, b, n, p)
    want = np.array([rf.faure(*r) for r in rows], F32)
    assert_same_bits(got, want, "kernel sample_faure vs reference")
    for key in sorted(set(zip(b.tolist(), n.tolist()))):
        sel = (b == key[0]) & (n == key[1])
        assert_same_bits(nf.faure(i[sel], j[sel], key[0], key[1], p[sel]), want[sel], f"numpy {key}")


@given(b=st.sampled_from(prog.BASES), data=st.data(), j=st.integers(0, U32_MAX), p=st.integers(0, U32_MAX))
@example(b=2, data=None, j=0, p=0)
@example(b=4093, data=None, j=U32_MAX, p=U32_MAX)
def test_reference_equals_numpy(b, data, j, p):
    """Hypothesis: any base, digit count, index, dimension and seed; the
    value does not depend on the digit count beyond the index's own."""
    top = rf.index_digits(b, MAX_SPP)
    if data is None:
        n, i = top, MAX_SPP - 1
    else:
        n = data.draw(st.integers(1, top), label="n")
        i = data.draw(st.integers(0, min(MAX_SPP, b**n) - 1), label="i")
    want = rf.faure(i, j, b, n, p)
    assert 0.0 <= want < 1.0 and want == float(F32(want))
    assert rf.faure(i, j, b, n + 1, p) == want
    got = nf.faure(np.array([i], U32), np.array([j], U32), b, n, np.array([p], U32))
    assert_same_bits(got, np.array([want], F32), f"i={i} j={j} b={b} n={n} p={p}")


# =============================================================================== unbiased

#: (base or None for the default, spp, dims): full nets, partial ones, many blocks
UNBIASED = [(3, 27, 7), (5, 40, 6), (2, 13, 5), (None, 50, 4), (11, 121, 3)]


@pytest.mark.parametrize("b, spp, dims", UNBIASED, ids=[f"b{b}-spp{s}-dims{d}" for b, s, d in UNBIASED])
def test_unbiased(b, spp, dims):
    """1000 pixels = 1000 independent randomizations: the mean of the per-pixel
    estimates of known integrals is within 5 empirical standard errors (1e-6:
    the 24-bit values bias an estimate by less than ``2**-24`` per coordinate)."""
    P = 1000
    x = faure(spp, dims, base=b, seed=41).generate(pixels=range(P)).astype(np.float64)
    integrands = {
        "x0 x1 x2": (x[:, :, 0] * x[:, :, 1] * x[:, :, 2], 1 / 8),
        "prod(1 + (x_k - 1/2) / 2)": (np.prod(1 + 0.5 * (x - 0.5), axis=2), 1.0),
        "exp(x0 + x_last)": (np.exp(x[:, :, 0] + x[:, :, -1]), (math.e - 1) ** 2),
        "[x0 + x1 < 1]": (x[:, :, 0] + x[:, :, 1] < 1, 0.5),
        "[x0 < 0.3][x_last > 0.6]": ((x[:, :, 0] < 0.3) & (x[:, :, -1] > 0.6), 0.3 * 0.4),
    }
    for label, (f, exact) in integrands.items():
        est = np.mean(f, axis=1)
        se = est.std(ddof=1) / math.sqrt(P)
        err = abs(est.mean() - exact)
        assert err <= 5 * se + 1e-6, (f"base {b} spp={spp} dims={dims}: {label}: mean {est.mean():.8f} vs "
                                      f"exact {exact} ({err / max(se, 1e-300):.1f} standard errors, se={se:.2e})")


def test_one_sample_is_uniform_over_randomizations():
    """One sample of each pixel (index ``pixel mod 25``), 16 x 16 cells of two
    pairs (one across dimension blocks): a 7-sigma chi-square bound."""
    P, N, b = 4096, 25, 5
    x = faure(N, 2 * b, base=b, seed=77).generate(pixels=range(P), dims=[0, 1, 3, 7]).astype(np.float64)
    x = x[np.arange(P), np.arange(P) % N, :]
    dof = 255
    for a, c in [(0, 1), (2, 3)]:  # dimensions (0, 1) and (3, 7)
        counts = np.bincount(np.floor(x[:, a] * 16).astype(int) * 16 + np.floor(x[:, c] * 16).astype(int),
                             minlength=256)
        chi2 = ((counts - P / 256) ** 2 / (P / 256)).sum()
        assert abs(chi2 - dof) < 7 * math.sqrt(2 * dof), f"dims ({a},{c}): chi-square {chi2:.0f} for {dof} dof"


# =============================================================================== API

@pytest.mark.parametrize("base, error, match", [
    (9, ValueError, r"faure: base must be a prime in \[2, 4093\], got 9; nearest: 7, 11"),
    (1, ValueError, r"got 1; nearest: 2, 3"),
    (0, ValueError, r"got 0; nearest: 2, 3"),
    (-7, ValueError, r"got -7; nearest: 2, 3"),
    (4094, ValueError, r"got 4094; nearest: 4091, 4093"),
    (4099, ValueError, r"got 4099; nearest: 4091, 4093"),  # a prime, above the largest base
    (True, TypeError, r"base must be an int \(a prime in \[2, 4093\]\), got bool True"),
    (5.0, TypeError, r"got float 5.0"),
    ("5", TypeError, r"got str '5'"),
])
def test_base_is_validated(base, error, match):
    with pytest.raises(error, match=match):
        faure(100, 3, base=base)


def test_integer_types_are_accepted_as_a_base():
    assert faure(100, 3, base=np.int64(7)).base == 7
    assert type(faure(100, 3, base=np.int64(7)).base) is int


@pytest.mark.parametrize("name", [n for n in catalogue.SAMPLERS if n not in ("faure", "zfaure")])
def test_other_samplers_refuse_a_base(name):
    spp = pyoa.valid_spp(name, dims=2)[0].spp
    with pytest.raises(ValueError, match=rf"^{name} takes no base \(got base=5\); only faure, zfaure have a digit base$"):
        pyoa.sampler(name, spp=spp, dims=2, base=5, **trial_options(name, {}))
    assert pyoa.sampler(name, spp=spp, dims=2, **trial_options(name, {})).base is None


@pytest.mark.parametrize("spp, dims, want", [
    (121, None, 11), (121, 8, 11), (1000, None, 31), (1000, 8, 11), (1000, 40, 31), (1000, 5, 5), (1000, 31, 31), (1000, 32, 31), (1, 1, 2),
    (2, 4, 2), (3, None, 2), (4, 1, 2), (9, 1, 2), (9, 3, 3), (9, 40, 3), (48, 100, 5), (49, 100, 7),
    (MAX_SPP, None, 4093), (MAX_SPP, 3, 3), (MAX_SPP, 4092, 4093), (4093**2 - 1, None, 4091),
])
def test_default_base(spp, dims, want):
    """The largest prime ``b`` with ``b**2 <= spp`` (2 below 4 samples), or
    the smallest prime ``>= dims`` when that is smaller."""
    assert prog.default_base(spp, dims) == want
    smp = faure(spp, dims or 1)
    assert smp.base == smp.s == smp.block_dims == prog.default_base(spp, dims or 1)


def test_the_docstring_examples_of_the_default_base():
    """pyoa.catalogue.faure's examples: ``default_base(121), default_base(1000),
    default_base(1000, dims=5), default_base(3)`` and the class docstring's
    ``spp=1000`` with 40, 8 and 5 dimensions."""
    assert (prog.default_base(121), prog.default_base(1000), prog.default_base(1000, dims=5),
            prog.default_base(3)) == (11, 31, 5, 2)
    assert (faure(121, 8).base, faure(1000, 40).base, faure(1000, 8).base, faure(1000, 5).base) == (11, 31, 11, 5)
    assert [faure(n, 8).base for n in (1, 2, 3)] == [2, 2, 2]


def test_sampler_base_and_full_nets():
    smp = faure(100, 4, base=3)
    assert (smp.base, smp.s, smp.block_dims, smp.strength) == (3, 3, 3, 4)  # 3^4 = 81 <= 100 < 243
    assert faure(4093, 2, base=4093).strength == 1 and faure(4092, 2, base=4093).strength == 0
    assert faure(MAX_SPP, 2, base=2).strength == 24


def test_pickle_copy_and_repr_keep_the_base(backend):
    smp = faure(50, 9, base=7, seed=U32_MAX, backend=backend)
    assert re.search(r"^Sampler\('faure', spp=50, dims=9, seed=4294967295, base=7; backend=", repr(smp))
    for other in (pickle.loads(pickle.dumps(smp)), copy.deepcopy(smp), copy.copy(smp)):
        assert other.base == 7 and repr(other) == repr(smp)
        assert_same_bits(other.generate(pixels=range(3)), smp.generate(pixels=range(3)), "copy")
    default = faure(50, 9, seed=1)
    assert pickle.loads(pickle.dumps(default)).base == default.base == 7


def test_qmc_engine_takes_a_base():
    eng = OrthogonalArray(d=3, sampler="faure", spp=50, base=5, rng=12345)
    assert (eng.base, eng.s, eng.block_dims, eng.pyoa_sampler.base) == (5, 5, 5, 5) and "base=5" in repr(eng)
    first = eng.random(120)  # two arrays and part of a third
    want = eng.pyoa_sampler.generate(pixels=range(3)).reshape(-1, 3)[:120]
    assert np.array_equal(first, want.astype(np.float64))
    assert eng._init_quad["base"] == 5
    with pytest.raises(ValueError, match="bose takes no base"):
        OrthogonalArray(d=3, base=5, rng=1)


# =============================================================================== CLI

def test_cli_points_with_a_base(tmp_path, capsys, backend):
    out = tmp_path / "f.npy"
    args = ["points", "faure", "--base", "5", "--spp", "30", "--dims", "7", "--pixels", "2",
            "--pixel0", U32_MAX - 1, "--seed", "9", "--backend", backend, "--out", out, "-q"]
    code, stdout, _ = run_cli(args, capsys)
    assert code == 0 and stdout == ""
    want = faure(30, 7, base=5, seed=9, backend=backend).generate(pixels=range(U32_MAX - 1, U32_MAX + 1))
    assert_same_bits(np.load(out), want, "pyoa points --base 5")
    code, stdout, _ = run_cli(args[:2] + args[4:], capsys)  # no --base: the default (5 = smallest prime >= 5)
    assert code == 0 and stdout == "" and np.load(out).shape == (2, 30, 7)
    assert_same_bits(np.load(out), faure(30, 7, seed=9).generate(pixels=range(U32_MAX - 1, U32_MAX + 1)),
                     "pyoa points, default base")


@pytest.mark.parametrize("args, message", [
    (["points", "bose", "--base", "5"], "pyoa points: error: bose takes no base (got base=5)"),
    (["points", "faure", "--base", "6"], "faure: base must be a prime in [2, 4093], got 6; nearest: 5, 7"),
    (["spp", "sobol", "--base", "2"], "pyoa spp: error: sobol takes no base (got base=2)"),
    (["spp", "faure", "--base", "4096"], "got 4096; nearest: 4091, 4093"),
    (["plot", "bose", "--base", "3"], "pyoa plot: error: bose takes no base (got base=3)"),
    (["spectrum", "faure", "--base", "1"], "pyoa spectrum: error: faure: base must be a prime"),
])
def test_cli_refuses_a_bad_base(tmp_path, capsys, args, message):
    code, _, err = run_cli(args + ["--out", tmp_path / ("x.npy" if args[0] == "points" else "x.png")]
                                if args[0] != "spp" else args, capsys)
    assert code == 2 and message in err, err
    assert list(tmp_path.iterdir()) == []


def _spp_rows(out: str) -> list[list[str]]:
    return [line.split() for line in out.strip().splitlines()]


def test_cli_spp_lists_the_base_of_each_count(capsys):
    code, out, _ = run_cli(["spp", "faure", "--near", "100"], capsys)
    assert code == 0 and _spp_rows(out) == [["spp", "base", "full", "nets", "dims/block"],
                                            ["99", "7", "7^2", "7"], ["100", "7", "7^2", "7"],
                                            ["101", "7", "7^2", "7"]]
    assert [c.label() for c in pyoa.valid_spp("faure", near=100)] == ["99 (b=7)", "100 (b=7)", "101 (b=7)"]
    code, out, _ = run_cli(["spp", "faure", "--near", "100", "--dims", "5"], capsys)
    assert code == 0 and _spp_rows(out)[2] == ["100", "5", "5^2", "5"]
    code, out, _ = run_cli(["spp", "faure", "--near", "100", "--base", "3"], capsys)
    assert code == 0 and _spp_rows(out)[1:] == [["99", "3", "3^4", "3"], ["100", "3", "3^4", "3"], ["101", "3", "3^4", "3"]]
    code, out, _ = run_cli(["spp", "faure", "--near", "100", "--base", "4093"], capsys)
    assert code == 0 and _spp_rows(out)[2] == ["100", "4093", "4093^0", "4093"]
    code, out, _ = run_cli(["spp", "faure", "--base", "5", "--limit", "6"], capsys)
    rows = _spp_rows(out)
    assert [r[2] for r in rows[1:7]] == ["5^0"] * 4 + ["5^1"] * 2
    assert rows[-1][:2] == ["...", f"{MAX_SPP - 6:d}"]


def test_cli_plot_with_a_base(tmp_path, capsys):
    out = tmp_path / "p.png"
    code, _, err = run_cli(["plot", "faure", "--base", "3", "--spp", "27", "--dims", "3", "--size", "200",
                                 "--backend", "numpy", "--out", out, "-q"], capsys)
    assert code == 0 and out.stat().st_size > 0, err
