"""The NumPy hashes (pyoa._numpy.hashes) against the independent C oracle."""

from __future__ import annotations

import numpy as np
import pytest

from pyoa._numpy import hashes as nh
from tests.helpers import U32_MAX, permute_cases, randfloat_cases, seed_pair_cases

U32 = np.uint32


def test_permute_matches_c_oracle(spec_c):
    cases = permute_cases()
    want = spec_c.permute(*zip(*cases))
    # permute takes a scalar l: group by l, with vectors of (i, p)
    by_l: dict[int, list[int]] = {}
    for k, (_, l, _) in enumerate(cases):
        by_l.setdefault(l, []).append(k)
    for l, ks in by_l.items():
        i = np.array([cases[k][0] for k in ks], dtype=U32)
        p = np.array([cases[k][2] for k in ks], dtype=U32)
        got = nh.permute(i, l, p)
        assert got.dtype == U32
        assert got.tolist() == [want[k] for k in ks], f"l={l}"


def test_randfloat_bits_match_c_oracle(spec_c):
    cases = randfloat_cases()
    i, p = (np.array(v, dtype=U32) for v in zip(*cases))
    got = nh.randfloat(i, p)
    assert got.dtype == np.float32
    assert got.view(U32).tolist() == spec_c.randfloat_bits(*zip(*cases))


def test_seed_hashes_match_c_oracle(spec_c):
    cases = seed_pair_cases()
    a, b = (np.array(v, dtype=U32) for v in zip(*cases))
    A, B = zip(*cases)
    assert nh.mix32(a).tolist() == spec_c.mix32(A)
    assert nh.pixel_seed(a, b).tolist() == spec_c.pixel_seed(A, B)
    assert nh.block_seed(a, b).tolist() == spec_c.block_seed(A, B)


def test_dimension_seeds_wrap_like_uint32():
    p = np.array([1, 0x9E3779B9, U32_MAX, 0], dtype=U32)
    j = np.array([0, 7, 4093, 3], dtype=U32)
    got = nh.dimension_seeds(p, j)
    for k, key in enumerate((0x51633E2D, 0x68BC21EB, 0x02E5BE93)):
        want = [(int(a) * (int(b) + 1) * key) % 2**32 for a, b in zip(p, j)]
        assert got[k].tolist() == want


@pytest.mark.parametrize("l", [4093, 4096, 13**3, 2**20 + 1, 2**23])
@pytest.mark.parametrize("p", [0x9E3779B9, U32_MAX, U32_MAX - 3])
def test_permute_bijection_large_l(l, p):
    """The largest sub-strata counts (M up to 2^23 for cmjnd s=2, t=24)."""
    got = nh.permute(np.arange(l, dtype=U32), l, U32(p))
    assert np.array_equal(np.sort(got), np.arange(l, dtype=U32))
    assert not np.array_equal(got, np.arange(l, dtype=U32))


def test_permute_seeds_within_l_of_2_32():
    for l in (3, 7, 13, 64, 1021):
        p = (U32_MAX - np.arange(l + 1, dtype=np.int64)).astype(U32)
        got = nh.permute(np.arange(l, dtype=U32)[:, None], l, p[None, :])
        assert np.array_equal(np.sort(got, axis=0), np.broadcast_to(np.arange(l)[:, None], got.shape)), f"l={l}"


def test_permute_mixed_zero_and_nonzero_seeds():
    """Lanes with p == 0 are the identity, the others are permuted, in one call."""
    i = np.arange(13, dtype=U32)
    p = np.where(i % 2 == 0, U32(0), U32(12345))
    got = nh.permute(i, 13, p)
    assert np.array_equal(got[::2], i[::2])
    from pyoa import reference as ref

    assert got[1::2].tolist() == [ref.permute(int(v), 13, 12345) for v in i[1::2]]


def test_randfloat_zero_seed_is_half_and_range():
    i = np.arange(1000, dtype=U32)
    assert np.all(nh.randfloat(i, U32(0)) == np.float32(0.5))
    r = nh.randfloat(np.arange(200000, dtype=U32), U32(0xABCDEF12))
    assert r.min() >= 0 and r.max() < 1 and r.max() <= 1 - 2**-23


def test_pixel_seeds_distinct_over_many_pixels():
    pix = np.arange(1 << 18, dtype=U32)
    for seed in (0, 1, U32_MAX):
        ps = nh.pixel_seed(U32(seed), pix)
        assert np.count_nonzero(ps == 0) == 0
        assert np.unique(ps).size == pix.size
