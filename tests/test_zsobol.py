"""pbrt-v4's ZSobol sampler (pyoa/reference/zsobol.py, pyoa/_numpy/zsobol.py,
kernels/include/pyoa/zsobol.h): the three give the same float32 bits, the permuted
indices of a pixel are an aligned block of ``N`` consecutive integers
(disjoint between pixels, a bijection for a square power-of-two image), and
every pixel's samples of a pair are a (0,k,2)-net, exactly.

The reference is the oracle of NumPy (hypothesis-drawn parameters: every
sample count, images from 1 x 1 to 65536 x 65536, the last pixel and sample,
edge seeds and dimensions); NumPy, once equal to it, is the bulk oracle of
the kernel and of the net checks.
"""

from __future__ import annotations

import itertools
import zlib

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from pyoa.tables import sequences
from pyoa._numpy import zsobol as nz
from pyoa.reference import baselines as rbl
from pyoa.reference import zsobol as rz
from pyoa.reference.hashes import hash_pair
from tests.helpers import U32_MAX, assert_same_bits, kernel_runner

U32 = np.uint32
F32 = np.float32
MAX_SIDE = 2**16
#: image sides worth drawing: 1, powers of two and their neighbours, HD
SIDES = [1, 2, 3, 4, 5, 7, 8, 9, 1080, 1920, 2047, 2048, 2049, 65535, MAX_SIDE]


def f32_bits(x: float) -> int:
    return int(np.float32(x).view(U32))


# ----------------------------------------------------------------------------- small pieces by hand

def test_perms_are_the_24_permutations_in_lexicographic_order():
    P = rz.PERMS
    assert len(P) == 24 and len(set(P)) == 24
    assert all(sorted(p) == [0, 1, 2, 3] for p in P)
    assert list(P) == sorted(P) == list(itertools.permutations(range(4)))
    assert P[0] == (0, 1, 2, 3) and P[1] == (0, 1, 3, 2) and P[23] == (3, 2, 1, 0)


def test_morton2_by_hand():
    assert [rz.morton2(x, y) for y in range(2) for x in range(2)] == [0, 1, 2, 3]
    # x = 3 = 0b11 -> bits 0, 2; y = 5 = 0b101 -> bits 1, 5
    assert rz.morton2(3, 5) == 1 + 4 + 2 + 32 == 39
    assert rz.morton2(4, 0) == 16 and rz.morton2(0, 4) == 32
    assert rz.morton2(0xFFFF, 0) == 0x55555555 and rz.morton2(0, 0xFFFF) == 0xAAAAAAAA
    assert rz.morton2(0xFFFF, 0xFFFF) == U32_MAX
    # a bijection of the 16 x 16 square onto [0, 256), quadrant by quadrant (Z order)
    codes = [rz.morton2(x, y) for y in range(16) for x in range(16)]
    assert sorted(codes) == list(range(256))
    assert all(rz.morton2(x, y) >> 6 == (x >> 3) + 2 * (y >> 3) for x in range(16) for y in range(16))
    xs, ys = np.meshgrid(np.arange(300), np.arange(0, 65536, 257))
    want = [rz.morton2(int(a), int(b)) for a, b in zip(xs.ravel(), ys.ravel())]
    assert nz.morton2(xs.ravel(), ys.ravel()).tolist() == want
    assert nz.morton2([0xFFFF], [0xFFFF]).tolist() == [U32_MAX]
    with pytest.raises(ValueError, match="non-negative"):
        rz.morton2(-1, 0)


def test_resolution_log2():
    cases = {(1, 1): 0, (2, 1): 1, (1, 2): 1, (3, 3): 2, (4, 4): 2, (5, 4): 3, (1920, 1080): 11,
             (2048, 2048): 11, (2049, 7): 12, (65535, 1): 16, (65536, 65536): 16, (1, 65536): 16}
    for (w, h), want in cases.items():
        assert rz.resolution_log2(w, h) == want, (w, h)
        assert 1 << want >= max(w, h) and (want == 0 or 1 << (want - 1) < max(w, h))
    for bad in [(0, 1), (1, 0), (65537, 1), (1, 65537), (-1, 5)]:
        with pytest.raises(ValueError, match="width|height"):
            rz.resolution_log2(*bad)


def test_mix64():
    M = 2**64 - 1

    def by_hand(v):  # pbrt's MixBits, written out again
        v = v ^ (v >> 31)
        v = v * 0x7FB5D329728EA185 % 2**64
        v = v ^ (v >> 27)
        v = v * 0x81DADEF4BC2DD44D % 2**64
        return v ^ (v >> 33)

    vals = [0, 1, 2, 0x55555555, 0x55555555 * U32_MAX, 2**56 - 1, 2**63, M] + list(range(3, 1000, 37))
    assert [rz.mix64(v) for v in vals] == [by_hand(v) for v in vals]
    assert rz.mix64(0) == 0
    assert nz.mix64(np.array(vals, dtype=np.uint64)).tolist() == [by_hand(v) for v in vals]


def test_sobol_dimensions_0_and_1_have_32_direction_numbers():
    """Why only ``g mod 2**32`` matters: dimensions 0 and 1 have 32 direction
    numbers (index bits 0..31); also the recurrences pyoa/zsobol.h uses
    instead of a table (dimension 0: bit reversal; dimension 1: Pascal's
    triangle mod 2, v_(k+1) = v_k ^ (v_k >> 1))."""
    V = sequences.sobol_matrices()
    assert V.shape[1] == 32
    assert [int(v) for v in V[0]] == [1 << (31 - k) for k in range(32)]
    v, row = 1 << 31, []
    for _ in range(32):
        row.append(v)
        v ^= v >> 1
    assert [int(v) for v in V[1]] == row


def _key(seed, b):
    return 0x55555555 * hash_pair(seed, b, rz.ZSOBOL_KEY)


def test_tiny_cases_by_hand():
    """The permuted index of tiny images from the definition, digit by digit."""
    for seed, b in [(0, 0), (7, 3), (U32_MAX, 2**31 - 1)]:
        K = _key(seed, b)
        # 1 x 1 image, 1 sample: no digit at all
        assert rz.sample_index(0, b, 0, 0, 1, 0, seed) == 0
        # 1 x 1, 2 samples: only the lone bit, flipped by a hash of m >> 1 = 0
        flip = rz.mix64(0 ^ K) & 1
        assert [rz.sample_index(i, b, 1, 0, 1, 0, seed) for i in range(2)] == [flip, 1 - flip]
        # 1 x 1, 4 samples: one base-4 digit, permuted by PERMS[p] with higher = 0
        p = (rz.mix64(K) >> 24) % 24
        assert [rz.sample_index(i, b, 2, 0, 1, 0, seed) for i in range(4)] == list(rz.PERMS[p])
        # 2 x 2 image, 1 sample: the pixel's Z code is the one digit
        assert [rz.sample_index(0, b, 0, 1, 2, px, seed) for px in range(4)] == [rz.PERMS[p][z]
                                                                               for z in (0, 1, 2, 3)]
        # 2 x 1 image (log2res = 1), 2 samples: digit (1, 2) = Z code, bit 0 flipped by mix64(z ^ K)
        for px in range(2):
            z = rz.morton2(px, 0)
            for i in range(2):
                want = (rz.PERMS[p][z] << 1) | (i ^ (rz.mix64(z ^ K) & 1))
                assert rz.sample_index(i, b, 1, 1, 2, px, seed) == want
        # 1 x 1, 8 samples: digit (1, 2) with higher = 0, then bit 0 keyed by the unpermuted m >> 1
        for i in range(8):
            hi = rz.PERMS[p][i >> 1]
            assert rz.sample_index(i, b, 3, 0, 1, 0, seed) == (hi << 1) | ((i & 1) ^ (rz.mix64((i >> 1) ^ K) & 1))


@pytest.mark.parametrize("width, height, log2n, pixel, i", [
    (65536, 65536, 24, 65536**2 - 1, 2**24 - 1), (1920, 1080, 7, 1920 * 1080 - 1, 5), (3, 1, 0, 2, 0),
    (65536, 1, 24, 65535, 12345), (1, 65536, 23, 65535, 2**23 - 1)])
def test_value_is_the_owen_scrambled_sobol_point_of_g_mod_2_32(width, height, log2n, pixel, i):
    """x = unit24(owen_scramble(sobol_bits(g mod 2**32, c), hash_pair(q, 1 + c, OWEN_KEY))),
    with g up to 2**56 (its bits >= 32 dropped)."""
    lr = rz.resolution_log2(width, height)
    for j in [0, 1, 2, 5, U32_MAX - 1, U32_MAX]:
        for seed in [0, 99, U32_MAX]:
            b, c = j >> 1, j & 1
            q = hash_pair(seed, b, rz.ZSOBOL_KEY)
            g = rz.sample_index(i, b, log2n, lr, width, pixel, seed)
            assert 0 <= g < 2 ** (2 * lr + log2n)
            want = rbl.unit24(rbl.owen_scramble(rbl.sobol_bits(g % 2**32, c), hash_pair(q, 1 + c, rbl.OWEN_KEY)))
            x = rz.zsobol(i, j, log2n, lr, width, pixel, seed)
            assert x == want and 0 <= x < 1 and x * 2**24 == int(x * 2**24)
    if 2 * lr + log2n > 32:  # the large cases do have index bits above 32
        assert max(rz.sample_index(i, b, log2n, lr, width, pixel, s) for s in range(8) for b in range(8)) >= 2**32


def test_argument_errors():
    ok = {"i": 0, "j": 0, "log2n": 2, "log2res": 1, "width": 2, "pixel": 0, "seed": 0}
    bad = [("i", -1), ("i", 4), ("j", -1), ("j", 2**32), ("log2n", -1), ("log2n", 25), ("log2res", -1),
           ("log2res", 17), ("width", 0), ("width", 3), ("pixel", -1), ("pixel", 2**32), ("seed", -1),
           ("seed", 2**32)]
    names = {"i": "sample index i", "j": "dimension j", "width": "width", "pixel": "pixel", "seed": "seed",
             "log2n": "log2n", "log2res": "log2res"}
    for name, value in bad:
        args = {**ok, name: value}
        with pytest.raises(ValueError, match=names[name]):
            rz.zsobol(**args)
        if name != "j":
            idx = {k: v for k, v in args.items() if k != "j"}
            with pytest.raises(ValueError, match=names[name]):
                rz.sample_index(b=0, **idx)
    with pytest.raises(ValueError, match="pair b"):
        rz.sample_index(0, 2**32, 2, 1, 2, 0, 0)
    # the edges themselves are valid
    assert 0 <= rz.zsobol(2**24 - 1, U32_MAX, 24, 16, 2**16, U32_MAX, U32_MAX) < 1


def test_pixels_beyond_the_image():
    """Any uint32 pixel is defined: its row is taken modulo 2^16, so pixel
    ``y W + x`` with ``y >= 2^16`` has the samples of row ``y mod 2^16``;
    NumPy agrees with the reference there too."""
    for W, k, lr in [(1, 3, 0), (7, 2, 3), (1920, 5, 11), (MAX_SIDE, 1, 16)]:
        for px in [U32_MAX, W * MAX_SIDE, W * MAX_SIDE + W - 1, 3 * W * MAX_SIDE + 5 % W]:
            if px > U32_MAX:
                continue
            inside = px - W * MAX_SIDE * ((px // W) >> 16)
            assert (inside // W) == (px // W) % MAX_SIDE and inside % W == px % W
            for i in (0, (1 << k) - 1):
                for j in (0, 1, 6, U32_MAX):
                    x = rz.zsobol(i, j, k, lr, W, px, 9)
                    assert x == rz.zsobol(i, j, k, lr, W, inside, 9)
                    assert f32_bits(x) == int(nz.zsobol(i, j, k, lr, W, px, 9).view(U32)[0])


# ----------------------------------------------------------------------------- reference == NumPy

@st.composite
def cases(draw):
    width = draw(st.sampled_from(SIDES) | st.integers(1, MAX_SIDE))
    height = draw(st.sampled_from(SIDES) | st.integers(1, MAX_SIDE))
    log2n = draw(st.integers(0, 24) | st.sampled_from([0, 1, 2, 23, 24]))
    N, P = 1 << log2n, width * height
    seed = draw(st.sampled_from([0, 1, U32_MAX]) | st.integers(0, U32_MAX))
    pixels = draw(st.lists(st.sampled_from([0, P - 1, width - 1, P - width]) | st.integers(0, P - 1),
                           min_size=1, max_size=3))
    samples = draw(st.lists(st.sampled_from([0, 1 % N, N // 2, N - 1]) | st.integers(0, N - 1),
                            min_size=1, max_size=4))
    dims = draw(st.lists(st.sampled_from([0, 1, 2, 3, U32_MAX - 1, U32_MAX]) | st.integers(0, U32_MAX),
                         min_size=1, max_size=4))
    return _case(width, height, log2n, seed, pixels + [P - 1], samples + [N - 1], dims)


def _case(width, height, log2n, seed, pixels, samples, dims):
    return {"width": width, "height": height, "log2n": log2n, "seed": seed, "pixels": pixels, "samples": samples,
            "dims": dims}


@given(c=cases())
@example(c=_case(MAX_SIDE, MAX_SIDE, 24, U32_MAX, [0, MAX_SIDE**2 - 1], [0, 2**24 - 1], [0, 1, U32_MAX]))
@example(c=_case(MAX_SIDE, MAX_SIDE, 23, 0, [MAX_SIDE**2 - 1, 12345678], [2**23 - 1], [2, 3, U32_MAX - 1]))
@example(c=_case(1, 1, 0, 0, [0], [0], [0, 1]))
@example(c=_case(1, 1, 24, U32_MAX, [0], [0, 2**24 - 1], [0, 1]))
@example(c=_case(1920, 1080, 5, 7, [0, 1919, 1920 * 1080 - 1], [0, 31], [0, 1, 2, 3]))
@example(c=_case(1, MAX_SIDE, 1, 1, [MAX_SIDE - 1], [0, 1], [U32_MAX]))
@example(c=_case(MAX_SIDE, 1, 2, 1, [MAX_SIDE - 1], [3], [U32_MAX]))
def test_reference_equals_numpy(c):
    W, H, k, seed = c["width"], c["height"], c["log2n"], c["seed"]
    lr = rz.resolution_log2(W, H)
    px = np.array(c["pixels"], dtype=U32)[:, None, None]
    i = np.array(c["samples"], dtype=U32)[None, :, None]
    j = np.array(c["dims"], dtype=U32)[None, None, :]
    got = nz.zsobol(i, j, k, lr, W, px, seed)
    got_g = nz.sample_index(i, j >> U32(1), k, lr, W, px, seed)
    assert got.dtype == F32 and got_g.dtype == np.uint64
    want = np.empty(got.shape, dtype=F32)
    want_g = np.empty(got.shape, dtype=np.uint64)
    for (a, b, d), _ in np.ndenumerate(want):
        args = (int(i[0, b, 0]), int(j[0, 0, d]), k, lr, W, int(px[a, 0, 0]), seed)
        want[a, b, d] = rz.zsobol(*args)
        want_g[a, b, d] = rz.sample_index(args[0], args[1] >> 1, *args[2:])
    assert_same_bits(got, want, f"numpy vs reference {c}")
    assert np.array_equal(got_g, want_g)
    # int64 inputs give the same values as uint32 ones
    assert_same_bits(nz.zsobol(i.astype(np.int64), j.astype(np.int64), k, lr, W, px.astype(np.int64), seed), got,
                     "int64 inputs")


# ----------------------------------------------------------------------------- the blocks of indices

def _check_blocks(g, N, square_res=None):
    """g: (pixels, N) permuted indices. Each row an aligned block of N consecutive
    integers, rows disjoint; with square_res, the union is [0, res^2 N)."""
    g = np.sort(np.asarray(g, dtype=np.int64), axis=1)
    start = g[:, :1]
    assert np.all(start % N == 0), "a block is not aligned"
    assert np.array_equal(g, start + np.arange(N)), "a pixel's indices are not consecutive"
    assert len(np.unique(start)) == len(start), "two pixels share a block"
    if square_res is not None:
        assert np.array_equal(np.sort(g.ravel()), np.arange(square_res**2 * N))


@pytest.mark.parametrize("width, height", [(1, 1), (2, 2), (4, 4), (8, 8), (3, 2), (5, 3), (1, 7), (6, 1)])
def test_reference_blocks(width, height):
    """Reference sample_index: aligned, consecutive, disjoint; a bijection onto
    [0, res^2 N) for square power-of-two images (odd log2n too)."""
    lr = rz.resolution_log2(width, height)
    square = 1 << lr if width == height == 1 << lr else None
    for log2n in range(6):
        N = 1 << log2n
        for seed, b in [(0, 0), (U32_MAX, 1), (12345, 2**31 - 1)]:
            g = [[rz.sample_index(i, b, log2n, lr, width, px, seed) for i in range(N)]
                 for px in range(width * height)]
            _check_blocks(g, N, square)


@pytest.mark.parametrize("width, height, log2n", [(16, 16, 8), (32, 32, 7), (64, 64, 4), (13, 17, 6), (1920, 1080, 0),
                                                  (1920, 1080, 3), (300, 1, 9), (1, 500, 5)])
def test_numpy_blocks(width, height, log2n):
    """The same in bulk (NumPy's sample_index, equal to the reference above);
    of a 1920 x 1080 image its first and last 16 rows."""
    lr = rz.resolution_log2(width, height)
    N = 1 << log2n
    P = width * height
    px = np.arange(P) if P <= 2**16 else np.concatenate([np.arange(16 * width), np.arange(P - 16 * width, P)])
    i = np.arange(N, dtype=U32)[None, :]
    square = 1 << lr if width == height == 1 << lr else None
    for seed, b in [(0, 0), (U32_MAX, 7)]:
        _check_blocks(nz.sample_index(i, b, log2n, lr, width, px.astype(U32)[:, None], seed), N, square)


def test_blocks_of_a_big_image():
    """Pixels of a 65536 x 65536 image: at N = 2^16 and 2^15 all samples, at
    N = 2^24 and 2^23 4096 of them: they agree on g >> log2n and differ in
    g mod N (an aligned block of N indices)."""
    rng = np.random.default_rng(5)
    lr = 16
    px = np.concatenate([[0, MAX_SIDE - 1, MAX_SIDE**2 - 1], rng.integers(0, MAX_SIDE**2, 2)]).astype(U32)
    for log2n in (15, 16, 23, 24):
        N = 1 << log2n
        i = np.arange(N) if N <= 2**16 else np.concatenate([[0, N - 1], rng.choice(N, 4094, replace=False)])
        i = np.unique(i).astype(U32)
        for seed in (0, U32_MAX):
            g = nz.sample_index(i[None, :], 3, log2n, lr, MAX_SIDE, px[:, None], seed)
            start = g >> np.uint64(log2n)
            assert np.all(start == start[:, :1])
            low = np.sort(g & np.uint64(N - 1), axis=1)
            assert np.all(np.diff(low, axis=1) > 0)
            if N <= 2**16:
                assert np.array_equal(low, np.broadcast_to(np.arange(N, dtype=np.uint64), low.shape))
            starts = {int(v) for v in start[:, 0]}
            assert len(starts) == len(px)  # distinct pixels, distinct blocks
            assert max(starts) < MAX_SIDE**2


# ----------------------------------------------------------------------------- per-pixel (0,k,2)-nets

def _assert_nets(x, y, log2n, what):
    """x, y: (pixels, N) float32 values. Every row is a (0, log2n, 2)-net: one point
    in each elementary interval 2^-u x 2^-v, u + v = log2n (exact integer arithmetic)."""
    N = 1 << log2n
    kx = (x.astype(np.float64) * 2**24).astype(np.int64)
    ky = (y.astype(np.float64) * 2**24).astype(np.int64)
    assert np.array_equal(kx, x.astype(np.float64) * 2**24), f"{what}: x not on the 2^-24 grid"
    assert np.all((kx >= 0) & (kx < 2**24) & (ky >= 0) & (ky < 2**24))
    for u in range(log2n + 1):
        cell = ((kx >> (24 - u)) << (log2n - u)) | (ky >> (24 - (log2n - u)))
        assert np.array_equal(np.sort(cell, axis=1), np.broadcast_to(np.arange(N), cell.shape)), \
            f"{what}: not a net for intervals 2^-{u} x 2^-{log2n - u}"


@pytest.mark.parametrize("width, height", [(8, 8), (5, 3)])
def test_every_pixel_is_a_net(width, height):
    """Every pixel of a small image, N = 1 .. 256 (odd log2n too), pairs 0 and 1."""
    lr = rz.resolution_log2(width, height)
    px = np.arange(width * height, dtype=U32)[:, None]
    for log2n in range(9):
        i = np.arange(1 << log2n, dtype=U32)[None, :]
        for seed in (0, U32_MAX):
            for pair in (0, 1):
                x = nz.zsobol(i, 2 * pair, log2n, lr, width, px, seed)
                y = nz.zsobol(i, 2 * pair + 1, log2n, lr, width, px, seed)
                _assert_nets(x, y, log2n, f"{width}x{height} N=2^{log2n} seed={seed} pair={pair}")


def test_nets_in_large_images_and_far_pairs():
    """Pixels of 1920 x 1080 and 65536 x 65536 images at N = 2^10, 2^11 and 2^14,
    pairs 0 and 2^31 - 1."""
    rng = np.random.default_rng(11)
    for (W, H), log2n in [((1920, 1080), 10), ((MAX_SIDE, MAX_SIDE), 11), ((MAX_SIDE, 3), 14)]:
        lr = rz.resolution_log2(W, H)
        px = np.concatenate([[0, W * H - 1], rng.integers(0, W * H, 4)]).astype(U32)[:, None]
        i = np.arange(1 << log2n, dtype=U32)[None, :]
        for pair in (0, 2**31 - 1):
            x = nz.zsobol(i, 2 * pair, log2n, lr, W, px, 77)
            y = nz.zsobol(i, 2 * pair + 1, log2n, lr, W, px, 77)
            _assert_nets(x, y, log2n, f"{W}x{H} N=2^{log2n} pair={pair}")


def test_reference_net_of_one_pixel():
    """The reference alone, one pixel of a 3 x 3 image at N = 32."""
    log2n, lr = 5, 2
    x = np.array([[rz.zsobol(i, 2, log2n, lr, 3, 4, 5) for i in range(32)]], dtype=F32)
    y = np.array([[rz.zsobol(i, 3, log2n, lr, 3, 4, 5) for i in range(32)]], dtype=F32)
    _assert_nets(x, y, log2n, "reference")


# ----------------------------------------------------------------------------- NumPy == kernel

TEST_KERNELS = r"""
__kernel void tz_sample(__global const uint *i, __global const uint *j, __global const uint *log2n,
                        __global const uint *log2res, __global const uint *width, __global const uint *pixel,
                        __global const uint *seed, __global float *out, __global uint *index)
{
    size_t g = get_global_id(0);
    out[g] = pyoa_sample_zsobol(i[g], j[g], log2n[g], log2res[g], width[g], pixel[g], seed[g]);
    index[g] = pyoa_zsobol_index(i[g], log2n[g], log2res[g], width[g], pixel[g],
                            pyoa_hash_pair(seed[g], j[g] >> 1, PYOA_ZSOBOL_KEY));
}

__kernel void tz_helpers(__global const uint *a, __global const uint *b, __global uint *perm,
                         __global uint *morton, __global ulong *mix, __global uint *sob)
{
    size_t g = get_global_id(0);
    perm[g] = pyoa_zsobol_perm(a[g] % 24u, b[g] & 3u);
    morton[g] = pyoa_morton2(a[g] & 0xffffu, b[g] & 0xffffu);
    mix[g] = pyoa_mix64(((ulong)a[g] << 32) | b[g]);
    sob[g] = pyoa_zsobol_sobol_bits(a[g], b[g] & 1u);
}
"""


@pytest.fixture(scope="module")
def harness(opencl):
    return kernel_runner(opencl, TEST_KERNELS)


@pytest.mark.opencl
def test_kernel_helpers_equal_numpy(harness):
    rng = np.random.default_rng(3)
    a = rng.integers(0, 2**32, 5000, dtype=np.uint64).astype(U32)
    b = rng.integers(0, 2**32, 5000, dtype=np.uint64).astype(U32)
    a[:96] = np.arange(96) // 4  # every permutation and digit
    b[:96] = np.arange(96) % 4
    a[96:100] = [0, U32_MAX, 0xFFFF, U32_MAX]
    b[96:100] = [0, U32_MAX, 0xFFFF, 0]
    perm, morton, mix, sob = harness("tz_helpers", [U32, U32, np.uint64, U32], a, b)
    assert perm.tolist() == [rz.PERMS[x % 24][y & 3] for x, y in zip(a.tolist(), b.tolist())]
    assert np.array_equal(morton, nz.morton2(a & U32(0xFFFF), b & U32(0xFFFF)))
    assert np.array_equal(mix, nz.mix64((a.astype(np.uint64) << np.uint64(32)) | b))
    from pyoa._numpy.baselines import sobol_bits

    assert np.array_equal(sob, sobol_bits(a, b & U32(1)))


#: (width, height, log2n, seed) of the kernel test: every log2n, odd and even,
#: images from 1 x 1 to 65536 x 65536, square, flat and tall, HD
KERNEL_CONFIGS = [(1, 1, k, s) for k, s in zip(range(25), itertools.cycle([0, U32_MAX, 3]))] + [
    (MAX_SIDE, MAX_SIDE, 24, U32_MAX), (MAX_SIDE, MAX_SIDE, 23, 0), (MAX_SIDE, MAX_SIDE, 0, 1),
    (MAX_SIDE, MAX_SIDE, 1, 5), (1920, 1080, 4, 9), (1920, 1080, 7, U32_MAX), (1920, 1080, 16, 0),
    (MAX_SIDE, 1, 24, 2), (1, MAX_SIDE, 13, 6), (3, 5, 2, 0), (8, 8, 8, 1), (2049, 17, 19, U32_MAX - 1),
    (MAX_SIDE - 1, 40000, 20, 123456789), (1000, 1000, 9, 42), (2, 1, 1, 0)]


@pytest.mark.opencl
def test_kernel_equals_numpy(harness):
    """sample_zsobol and zsobol_index vs NumPy (equal to the reference above) on
    KERNEL_CONFIGS, 256 values each: the first and last pixel and sample,
    dimensions up to 2^32 - 1."""
    cols = {n: [] for n in ("i", "j", "log2n", "log2res", "width", "pixel", "seed")}
    want, want_g = [], []

    def add(i, j, px, k, lr, W, seed):
        """One batch of kernel arguments and the values NumPy gives for it."""
        for name, v in (("i", i), ("j", j), ("pixel", px)):
            cols[name].append(v.astype(U32))
        for name, v in (("log2n", k), ("log2res", lr), ("width", W), ("seed", seed)):
            cols[name].append(np.full(len(i), v, dtype=U32))
        want.append(nz.zsobol(i, j, k, lr, W, px, seed))
        want_g.append((nz.sample_index(i, j >> 1, k, lr, W, px, seed) & np.uint64(U32_MAX)).astype(U32))
    for W, H, k, seed in KERNEL_CONFIGS:
        rng = np.random.default_rng(zlib.crc32(repr((W, H, k, seed)).encode()))
        n, N, P = 256, 1 << k, W * H
        i = rng.integers(0, N, n, dtype=np.int64)
        px = rng.integers(0, P, n, dtype=np.int64)
        j = rng.integers(0, 2**32, n, dtype=np.int64)
        j[: n // 2] %= 8
        i[:2], px[:2], j[:4] = [0, N - 1], [0, P - 1], [0, 1, U32_MAX - 1, U32_MAX]
        lr = rz.resolution_log2(W, H)
        add(i, j, px, k, lr, W, seed)
    # pixels beyond the image, any uint32 (rows taken modulo 2^16)
    for W, H, k, seed in [(7, 1, 6, 11), (MAX_SIDE, MAX_SIDE, 24, 3), (1, 1, 0, 0)]:
        rng = np.random.default_rng(W + k)
        n, lr = 256, rz.resolution_log2(W, H)
        i = rng.integers(0, 1 << k, n, dtype=np.int64)
        px = rng.integers(0, 2**32, n, dtype=np.int64)
        j = rng.integers(0, 16, n, dtype=np.int64)
        px[0] = U32_MAX
        add(i, j, px, k, lr, W, seed)
    args = [np.concatenate(cols[n]) for n in ("i", "j", "log2n", "log2res", "width", "pixel", "seed")]
    got, got_g = harness("tz_sample", [F32, U32], *args)
    assert np.array_equal(got_g, np.concatenate(want_g))
    assert_same_bits(got, np.concatenate(want), "kernel vs numpy")
