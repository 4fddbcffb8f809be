"""``zfaure``: one Faure sequence ordered across the pixels (docs/spec.md
section 5.12; pyoa/reference/zfaure.py, pyoa/_arrays/zfaure.py,
kernels/include/pyoa/zfaure.h), exactly.

- The order: every seed scrambles (0 included); every seed's order is a bijection of
  the padded grid, whose runs of ``b**(2u)`` positions are ``b**u x b**u``
  tiles and whose runs of ``b`` are a row or a column of a ``b x b`` tile.
- The value: block 0 is ``faure`` read at ``T = z N + i`` (while
  ``T < 2**24``); the reference equals NumPy on hypothesis-drawn arguments
  (every base up to 4093, images up to 65536 x 65536, 64-bit ``T``) and the
  bulk backends (NumPy, OpenCL) equal the reference at the edges; the spec's
  test vectors, from every backend.
- The promises of section 5.12, counted box by box in blocks 0 and 1: every
  pixel a (0,m,b)-net, every row (or column) of a tile a (0,m+1,b)-net,
  every ``b x b`` tile a (0,m+2,b)-net and every ``b**2 x b**2`` tile a
  (0,m+4,b)-net (checked to the strength the helper counts); no sample
  shared between pixels.
- Blue noise: the error image of a 4D integrand has less low-frequency power
  than ``faure``'s and ``zsobol``'s (fixed seeds: deterministic).
- The API: counts (prime powers, the count fixes the base), the image and
  the 64-bit limit refused with what is valid.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import pyoa
from pyoa.analysis import error_spectrum
from pyoa.catalogue.faure import zfaure_counts
from pyoa._numpy import zfaure as nz
from pyoa.reference import faure as rf
from pyoa.reference import zfaure as rz
from tests.helpers import U32_MAX, assert_same_bits, net_failures

U32 = np.uint32
F32 = np.float32
SPEC = Path(__file__).resolve().parent.parent / "docs" / "spec.md"


def zf(spp, dims, resolution, seed=0, backend="numpy", **kw):
    return pyoa.sampler("zfaure", spp=spp, dims=dims, resolution=resolution, seed=seed, backend=backend, **kw)


def morton(x: int, y: int, b: int, k: int) -> int:
    """Plain base-b Morton code, y's digit above x's at every level, written independently."""
    dx = [x // b ** (k - 1 - l) % b for l in range(k)]
    dy = [y // b ** (k - 1 - l) % b for l in range(k)]
    return sum((dy[l] * b + dx[l]) * b ** (2 * (k - 1 - l)) for l in range(k))


# ----------------------------------------------------------------------------- the order of the pixels

@pytest.mark.parametrize("b, k", [(2, 3), (3, 2), (5, 2), (7, 1)])
def test_every_seed_scrambles_seed_zero_too(b, k):
    """User seed 0 (a render's default) is no plain Morton order and no unscrambled sequence: both
    repeat one arrangement in every tile, a periodic pattern in the error image."""
    n = b**k
    for seed in (0, 1):
        S = rz.sequence_seed(seed, b)
        assert S != 0
        assert [rz.pixel_code(x, y, b, k, S) for y in range(n) for x in range(n)] != \
            [morton(x, y, b, k) for y in range(n) for x in range(n)]
    assert rz.zfaure(0, 0, b * b, b, k, n, 0, 0) != rf.faure(morton(0, 0, b, k) * b * b, 0, b, rf.out_digits(b), 0)


@pytest.mark.parametrize("b, k", [(2, 4), (3, 3), (5, 2), (7, 2)])
@pytest.mark.parametrize("seed", [0, 1, 7, U32_MAX])
def test_the_order_is_a_bijection_of_tiles_and_rows(b, k, seed):
    """z is a permutation of the b^k x b^k grid; each run of b^(2u) positions
    is one aligned b^u x b^u tile; each run of b is one row or one column of
    a b x b tile; NumPy's codes are the reference's."""
    n = b**k
    S = rz.sequence_seed(seed, b)
    y, x = np.divmod(np.arange(n * n), n)
    z = np.array([rz.pixel_code(int(a), int(c), b, k, S) for a, c in zip(x, y)])
    assert np.array_equal(np.sort(z), np.arange(n * n))
    got = nz_code(x, y, b, k, S)
    assert np.array_equal(got, z)
    where = np.empty((n * n, 2), np.int64)
    where[z] = np.stack([x, y], axis=1)
    for u in range(1, k + 1):
        tiles = where.reshape(-1, b ** (2 * u), 2) // b**u
        assert (tiles == tiles[:, :1]).all(), f"a run of {b}^{2 * u} positions is not one tile"
    runs = where.reshape(-1, b, 2)
    same_y = (runs[:, :, 1] == runs[:, :1, 1]).all(axis=1)
    same_x = (runs[:, :, 0] == runs[:, :1, 0]).all(axis=1)
    assert (same_x | same_y).all(), "a run of b positions is neither a row nor a column"
    if k >= 2:
        assert same_x.any() and same_y.any(), "the tiles are never transposed (or always)"


def nz_code(x, y, b, k, S):
    from pyoa._arrays import bind, zfaure as generic
    from pyoa._numpy import ops
    return bind(ops, generic.pixel_code)(np.asarray(x, U32), np.asarray(y, U32), b, k, np.asarray(S, U32))


# ----------------------------------------------------------------------------- the values, exactly

@pytest.mark.parametrize("b, W, H, N", [(5, 25, 25, 25), (2, 16, 16, 16), (3, 9, 7, 27), (7, 5, 5, 49)])
@pytest.mark.parametrize("seed", [0, 3, U32_MAX])
def test_block_zero_is_faure_read_along_the_order(b, W, H, N, seed):
    """Block 0 of zfaure is faure (seed S, the sequence's) at index z N + i, while D = K and T < 2^24."""
    k = rz.grid_digits(b, W, H)
    S = rz.sequence_seed(seed, b)
    assert rz.total_digits(b, k, N) == rf.out_digits(b)
    for px in (0, 1, W * H // 2, W * H - 1):
        z = rz.pixel_code(px % W, px // W, b, k, S)
        for i in (0, 1, N - 1):
            for j in range(b):
                assert rz.zfaure(i, j, N, b, k, W, px, seed) == rf.faure(z * N + i, j, b, rf.out_digits(b), S)


@st.composite
def _case(draw):
    N, (b, m) = draw(st.sampled_from(sorted(zfaure_counts().items())))
    sides = st.sampled_from([1, 2, 3, 5, 7, 8, 25, 1080, 1920, 4093, 65535, 65536]) | st.integers(1, 65536)
    W, H = draw(sides), draw(sides)
    k = rz.grid_digits(b, W, H)
    if b ** (2 * k) * N > rz.MAX_TOTAL:
        W = H = 1
        k = 0
    pixels = draw(st.lists(st.integers(0, W * H - 1), min_size=1, max_size=3))
    samples = draw(st.lists(st.integers(0, N - 1), min_size=1, max_size=3))
    dims = draw(st.lists(st.integers(0, 3 * b + 1) | st.just(U32_MAX), min_size=1, max_size=3))
    seed = draw(st.sampled_from([0, 1, U32_MAX]) | st.integers(0, U32_MAX))
    return dict(N=N, b=b, W=W, H=H, k=k, pixels=pixels, samples=samples, dims=dims, seed=seed)


@settings(max_examples=60, deadline=None)
@given(c=_case())
@example(c=dict(N=2**24, b=2, W=65536, H=65536, k=16, pixels=[65536**2 - 1, 0], samples=[2**24 - 1, 0],
                dims=[0, 1, 2, U32_MAX], seed=U32_MAX))
@example(c=dict(N=4093**2, b=4093, W=4093, H=1, k=1, pixels=[4092], samples=[4093**2 - 1], dims=[4092, 4093],
                seed=7))
@example(c=dict(N=4, b=2, W=1, H=1, k=0, pixels=[0], samples=[0, 3], dims=[0, 1, 2], seed=0))
def test_reference_equals_numpy(c):
    N, b, k, W = c["N"], c["b"], c["k"], c["W"]
    px = np.array(c["pixels"], U32)[:, None, None]
    i = np.array(c["samples"], U32)[None, :, None]
    j = np.array(c["dims"], U32)[None, None, :]
    got = nz.zfaure(i, j, N, b, k, W, px, U32(c["seed"]))
    assert got.dtype == F32
    want = np.empty(got.shape, F32)
    for (a, s, d), _ in np.ndenumerate(want):
        want[a, s, d] = rz.zfaure(int(i[0, s, 0]), int(j[0, 0, d]), N, b, k, W, int(px[a, 0, 0]), c["seed"])
    assert_same_bits(got, want, f"numpy vs reference {c}")


EDGES = [dict(spp=4, dims=3, resolution=(1, 1)), dict(spp=125, dims=11, resolution=(7, 3)),
         dict(spp=4096, dims=6, resolution=(1920, 1080)), dict(spp=2**24, dims=3, resolution=(4096, 4096)),
         dict(spp=4093**2, dims=4094, resolution=(2, 2)), dict(spp=343, dims=15, resolution=(65536, 3))]


@pytest.mark.parametrize("kw", EDGES, ids=lambda kw: f"{kw['spp']}-{kw['resolution'][0]}x{kw['resolution'][1]}")
def test_backends_equal_the_reference_at_the_edges(kw, backend):
    """First, last and middle pixel, sample and dimension (the last of several blocks), seeds 0 and 2^32-1."""
    for seed in (0, U32_MAX):
        smp = zf(seed=seed, backend=backend, **kw)
        n_pix = smp.n_pixels
        pixels = sorted({0, n_pix // 2, n_pix - 1})
        samples = sorted({0, smp.spp // 3, smp.spp - 1})
        dims = sorted({0, smp.base - 1, min(smp.base, smp.dims - 1), smp.dims - 1})
        got = smp.generate(pixels=pixels, samples=samples, dims=dims)
        W = kw["resolution"][0]
        k = rz.grid_digits(smp.base, *kw["resolution"])
        want = np.array([[[rz.zfaure(i, j, smp.spp, smp.base, k, W, p, seed) for j in dims] for i in samples]
                         for p in pixels], F32)
        assert_same_bits(got, want, f"{backend} vs reference, {kw}, seed {seed}")


ROW = re.compile(r"^\| `zfaure` b = (\d+), N = (\d+), (\d+) x (\d+), pixel (\d+), seed (\d+)[^|]*\| (\d+) \| (\d+) \| "
                 r"(\d+) \| `0x([0-9a-f]{8})` \|$", re.MULTILINE)
VECTORS = [tuple(int(g, 16) if n == 9 else int(g) for n, g in enumerate(m.groups())) for m in ROW.finditer(
    SPEC.read_text())]


def test_the_page_has_zfaure_vectors():
    assert len(VECTORS) >= 5
    assert any(j >= b for b, *_, j, _ in VECTORS), "no vector past the first block"
    assert any(z * N + i >= 2**32 for b, N, W, H, px, seed, z, i, j, _ in VECTORS), "no 64-bit index"


@pytest.mark.parametrize("vector", VECTORS, ids=lambda v: f"b{v[0]}-N{v[1]}-px{v[4]}-j{v[8]}")
def test_spec_vectors(vector, backend):
    b, N, W, H, px, seed, z, i, j, want = vector
    k = rz.grid_digits(b, W, H)
    assert rz.pixel_code(px % W, px // W, b, k, rz.sequence_seed(seed, b)) == z
    assert int(F32(rz.zfaure(i, j, N, b, k, W, px, seed)).view(U32)) == want
    smp = zf(N, j + 1, (W, H), seed=seed, backend=backend)
    assert smp.base == b
    assert int(smp.generate(pixels=[px], samples=[i], dims=[j]).view(U32)[0, 0, 0]) == want


# ----------------------------------------------------------------------------- section 5.12's promises

def _tile_points(x, W, H, b, u, where):
    """(tiles, b^(2u) N, dims): the samples of every full b^u x b^u tile of the image, pixels gathered."""
    t = b**u
    out = []
    for ty in range(H // t):
        for tx in range(W // t):
            pix = [(ty * t + dy) * W + tx * t + dx for dy in range(t) for dx in range(t)]
            out.append(x[pix].reshape(-1, x.shape[2]))
    return np.stack(out)


def _row_points(x, W, H, b, seed, k):
    """(rows, b N, dims): the b pixels of each run of b positions on the order (a row or a column of a tile)."""
    codes = {}
    for y in range(H):
        for c in range(W):
            codes[rz.pixel_code(c, y, b, k, rz.sequence_seed(seed, b))] = y * W + c
    runs = []
    for start in range(0, b ** (2 * k), b):
        pix = [codes.get(start + r) for r in range(b)]
        if None not in pix:
            runs.append(x[pix].reshape(-1, x.shape[2]))
    return np.stack(runs)


@pytest.mark.parametrize("b, m, W, H", [(2, 2, 8, 8), (3, 2, 9, 9), (5, 2, 10, 5), (2, 3, 4, 8)])
@pytest.mark.parametrize("seed", [0, 11, U32_MAX])
def test_pixels_rows_and_tiles_are_nets(b, m, W, H, seed):
    """In blocks 0 and 1 (every dimension of both): each pixel a (0,m,b)-net,
    each run of b positions (a row or column of a tile) a (0,m+1,b)-net, each
    b x b tile a (0,m+2,b)-net, and for base 2 each 4 x 4 tile a (0,m+4,2)-net
    (projections up to 3 dimensions); no two pixels share a sample."""
    N = b**m
    smp = zf(N, 2 * b, (W, H), seed=seed)
    x = smp.generate(pixels=range(W * H))
    k = rz.grid_digits(b, W, H)
    assert not net_failures(x, b, m, b), "a pixel is not a net"
    assert not net_failures(_row_points(x, W, H, b, seed, k), b, m + 1, b), "a row of a tile is not a net"
    assert not net_failures(_tile_points(x, W, H, b, 1, None), b, m + 2, b), "a tile is not a net"
    if b == 2 and W >= 4 and H >= 4:
        assert not net_failures(_tile_points(x, W, H, b, 2, None), b, m + 4, b), "a 4 x 4 tile is not a net"
    flat = x.reshape(-1, x.shape[2])
    assert len(np.unique(flat, axis=0)) == len(flat), "two samples are equal"


def test_a_copy_has_its_own_order_of_pixels_and_samples():
    """Dimension c + b is no function of dimension c: within a pixel, and across the pixels of a tile."""
    b, N = 5, 25
    x = zf(N, 2 * b, (5, 5), seed=3).generate(pixels=range(25)).astype(np.float64)
    for c in range(b):
        a, bb = x[:, :, c].ravel(), x[:, :, c + b].ravel()
        order = np.argsort(a)
        # were bb a function of a, sorting by a would sort bb by a fixed rule: compare with a shuffle
        assert abs(np.corrcoef(a, bb)[0, 1]) < 0.1
        assert not np.array_equal(np.argsort(bb), order)
    # the copy's per-pixel sets are not block 0's sets of any pixel
    sets0 = {tuple(sorted(np.round(x[p, :, 0] * 2**24).astype(int))) for p in range(25)}
    sets1 = {tuple(sorted(np.round(x[p, :, b] * 2**24).astype(int))) for p in range(25)}
    assert not sets0 & sets1


def test_the_error_is_blue_noise_in_4d():
    """section 5.12 (and docs/samplers.md): neighbouring pixels' errors cancel
    in every dimension of a block. A 4D Gaussian over a 32 x 32 image at 25
    samples: zfaure's low-frequency power is below 0.6, faure's and zsobol's
    (32 samples) above 0.8. Fixed seeds: the figures are deterministic."""
    kw = dict(size=32, seeds=4, integrand="gaussian", dims=4, backend="numpy")
    z = error_spectrum("zfaure", spp=25, **kw)
    f = error_spectrum("faure", spp=25, base=5, **kw)
    s = error_spectrum("zsobol", spp=32, **kw)
    assert z.low < 0.6 < 0.8 < min(f.low, s.low), (z.low, f.low, s.low)


# ----------------------------------------------------------------------------- the API

def test_counts_are_prime_powers_and_fix_the_base():
    counts = [c.spp for c in pyoa.valid_spp("zfaure") if c.spp <= 130]
    assert counts == [4, 8, 9, 16, 25, 27, 32, 49, 64, 81, 121, 125, 128]
    assert zf(125, 4, (8, 8)).base == 5 and zf(64, 4, (8, 8)).base == 2 and zf(49, 9, (8, 8)).base == 7
    assert zf(125, 4, (8, 8), base=5).base == 5
    assert zfaure_counts()[4093**2] == (4093, 2) and max(zfaure_counts()) == 2**24


@pytest.mark.parametrize("kw, message", [
    (dict(spp=100, dims=4, resolution=(8, 8)), r"100 is not a power b\^m of a prime b with m >= 2.*nearest: 81 \(b=3\), "
                                               r"121 \(b=11\)"),
    (dict(spp=5, dims=2, resolution=(8, 8)), r"5 is not a power b\^m"),
    (dict(spp=64, dims=4, resolution=(8, 8), base=5), r"64 samples are 2\^6, base 2; base 5 takes 25, 125, 625"),
    (dict(spp=64, dims=4, resolution=(8, 8), base=4), r"base must be a prime"),
    (dict(spp=64, dims=4), r"zfaure needs the image: resolution=\(width, height\)"),
    (dict(spp=64, dims=4, resolution=(0, 8)), r"resolution width must be in \[1, 65536\]"),
    (dict(spp=4093**2, dims=2, resolution=(65536, 65536)), r"pass the 64-bit index"),
])
def test_bad_arguments_say_what_is_valid(kw, message):
    with pytest.raises(ValueError, match=message):
        pyoa.sampler("zfaure", backend="numpy", **kw)


def test_pixels_beyond_the_image_are_refused():
    smp = zf(25, 2, (7, 3))
    assert smp.n_pixels == 21
    with pytest.raises(ValueError, match="pixel"):
        smp.generate(pixels=[21])


def test_reference_refuses_what_it_cannot_compute():
    with pytest.raises(ValueError, match="N must be b\\^m"):
        rz.zfaure(0, 0, 50, 5, 1, 5, 0, 0)
    with pytest.raises(ValueError, match="sample index"):
        rz.zfaure(25, 0, 25, 5, 1, 5, 0, 0)
    with pytest.raises(ValueError, match="pixel"):
        rz.zfaure(0, 0, 25, 5, 1, 5, 25, 0)
    with pytest.raises(ValueError, match="seed"):
        rz.zfaure(0, 0, 25, 5, 1, 5, 0, 2**32)
