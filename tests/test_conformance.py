"""docs/spec.md section 8.4: every (pixel, sample, dimension) has the same float32 bits
whichever backend computes it (OpenCL kernel == NumPy == pure-Python reference),
in any batch. One suite over every sampler and backend: the ``backend`` fixture
runs each test for "numpy" and "opencl"."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

import pyoa
from pyoa import reference as ref
from pyoa._numpy import hashes as nh
from pyoa.tables import gf
from tests.helpers import (
    AK_Q,
    BB_S,
    BOSE_PRIMES,
    GF_POWERS,
    PIXEL_KEY,
    U32_MAX,
    assert_same_bits,
    bits,
    index2_levels,
    reference_block,
)

OFFSETS = ["centered", "j", "mj", "cmj"]
SMALL_BOSE = [2, 3, 5, 7, 11, 13]
SMALL_GF = [4, 8, 9, 16, 25, 27]


def zero_hash_pixel(seed: int) -> int:
    """The pixel whose raw pixel hash is 0 (pixel_seed must remap it): mix32 is a
    bijection with mix32(0) == 0, so pixel = mix32(seed ^ key) gives 0."""
    return ref.mix32(seed ^ PIXEL_KEY)


def max_s(t: int) -> int:
    s = int(round(2 ** (24 / t)))
    while s**t > 2**24:
        s -= 1
    while (s + 1) ** t <= 2**24:
        s += 1
    return s


def bush_s(t: int) -> list[int]:
    """Every s of Bush at strength t: s a prime or a prime power <= 256, s >= t, s^t <= 2^24."""
    return [s for s in range(t, max_s(t) + 1) if gf.is_supported(s)]


BUSH_S = {t: bush_s(t) for t in range(2, 9)}
INDEX2 = ("addelman-kempthorne", "bose-bush")
AK_LEVELS = index2_levels("addelman-kempthorne")  # 3 .. 2887
BB_LEVELS = index2_levels("bose-bush")  # 2 .. 128


def spp_of(name: str, s: int, t: int) -> int:
    return 2 * s * s if name in INDEX2 else s**t


@st.composite
def configs(draw):
    # the five constructions of the paper and its index-2 extensions, with
    # parameters drawn per construction below; every registered sampler also
    # runs the catalogue-driven suite of tests/test_catalogue.py
    name = draw(st.sampled_from(["bose", "bush", "cmjnd", *INDEX2]))
    if name == "addelman-kempthorne":
        # small q, any q (prime up to 2887, odd prime power up to 243), the largest of each kind
        s = draw(st.sampled_from(AK_Q) | st.sampled_from(AK_LEVELS) | st.sampled_from([243, 2887]))
        t, spp, block = 2, 2 * s * s, 2 * s + 1
    elif name == "bose-bush":
        s = draw(st.sampled_from(BB_S) | st.sampled_from(BB_LEVELS))
        t, spp, block = 2, 2 * s * s, 2 * s + 1
    elif name == "bose":
        s = draw(st.sampled_from(SMALL_BOSE) | st.sampled_from(SMALL_GF) | st.sampled_from(GF_POWERS)
                 | st.sampled_from(BOSE_PRIMES))
        t, spp, block = 2, s * s, s + 1
    elif name == "bush":
        t = draw(st.integers(2, 8))
        ok = BUSH_S[t]
        s = draw(st.sampled_from([v for v in ok if v <= 16] or ok) | st.sampled_from(ok) | st.just(ok[-1]))
        spp, block = s**t, s + 1
    else:
        t = draw(st.integers(1, 24))
        hi = max_s(t)
        s = draw(st.integers(2, min(hi, 8)) | st.integers(2, hi) | st.just(hi))
        spp, block = s**t, t
    dims = draw(st.integers(1, block) | st.integers(block, 4 * block + 1))
    seed = draw(st.sampled_from([0, 1, U32_MAX, U32_MAX - 1]) | st.integers(0, U32_MAX))
    offset = draw(st.sampled_from(OFFSETS))
    # amounts with many significant bits make jitter_value's product inexact, so a
    # fused multiply-add would change the bits
    jitter = draw(st.sampled_from([0.0, 1.0]) | st.floats(0.0, 1.0)
                  | st.integers(1, 2**24 - 1).map(lambda k: k * 2.0**-24))
    many = draw(st.booleans())  # many samples per pixel: the backends' table paths (cmj, centered)
    pixels = draw(st.lists(st.sampled_from([0, U32_MAX, zero_hash_pixel(seed)]) | st.integers(0, U32_MAX),
                           min_size=1, max_size=2 if many else 3))
    if many:
        # the pure-Python reference of GF arithmetic costs ~1 ms a value at s ~ 4093
        # (pyoa.tables.gf factors s on every call); such s never reach the table path (E > 300) anyway
        slow = name != "cmjnd" and s > 256
        n = min(spp, draw(st.integers(1, 24 if slow else 300)))
        start = draw(st.integers(0, spp - n))
        samples = list(range(start, start + n))
        if draw(st.booleans()):
            samples = samples[::-1]
    else:
        samples = draw(st.lists(st.sampled_from([0, spp - 1]) | st.integers(0, spp - 1), min_size=1, max_size=6))
    samples.append(spp - 1)  # always the last sample
    dim_idx = draw(st.lists(st.integers(0, dims - 1), min_size=0, max_size=6))
    dim_idx.append(dims - 1)  # always the last dimension
    return dict(name=name, s=s, t=t, spp=spp, dims=dims, seed=seed, offset=offset, jitter=jitter,
                pixels=pixels, samples=samples, dim_idx=dim_idx)


def make_sampler(cfg, backend):
    smp = pyoa.sampler(cfg["name"], spp=cfg["spp"], dims=cfg["dims"], seed=cfg["seed"], offset=cfg["offset"],
                       jitter=cfg["jitter"], strength=cfg["t"] if cfg["name"] != "bose" else None, backend=backend)
    assert (smp.s, smp.strength) == (cfg["s"], cfg["t"])
    if cfg["name"] in INDEX2:
        assert (smp.block_dims, smp.params.M) == (2 * cfg["s"] + 1, 2 * cfg["s"])
    return smp


def _cfg(name, s, t, dims, seed, offset, jitter, pixels, samples, dim_idx):
    return dict(name=name, s=s, t=t, spp=spp_of(name, s, t), dims=dims, seed=seed, offset=offset, jitter=jitter,
                pixels=pixels, samples=samples, dim_idx=dim_idx)


@given(cfg=configs())
@example(cfg=_cfg("bose", 4093, 2, 3 * 4094, U32_MAX, "cmj", 1.0, [U32_MAX], [0, 1, 4093**2 - 1],
                  [0, 1, 2, 4092, 4093, 4094, 8187, 8188, 3 * 4094 - 1]))
@example(cfg=_cfg("cmjnd", 2, 24, 49, 0, "j", 1.0, [0, U32_MAX], [0, 1, 2**23, 2**24 - 1], [0, 23, 24, 47, 48]))
@example(cfg=_cfg("cmjnd", 4096, 2, 5, 1, "mj", 0.5, [7], [0, 4096**2 - 1], [0, 1, 4]))
@example(cfg=_cfg("cmjnd", 2**24, 1, 3, 5, "cmj", 1.0, [3], [0, 2**24 - 1], [0, 2]))
@example(cfg=_cfg("cmjnd", 7, 1, 4, 9, "centered", 0.0, [0], [0, 6], [0, 3]))
@example(cfg=_cfg("bose", 2, 2, 7, 0, "j", 0.0, [zero_hash_pixel(0)], [0, 3], [0, 2, 3, 6]))
@example(cfg=_cfg("bose", 13, 2, 30, 5, "cmj", 1.0, [1, U32_MAX], list(range(169)), [0, 13, 14, 29]))
@example(cfg=_cfg("cmjnd", 3, 4, 9, 6, "centered", 0.3, [2], list(range(80, -1, -1)), [0, 3, 4, 8]))
# GF(256), the largest table: last sample, last column (j = q), past the block
@example(cfg=_cfg("bose", 256, 2, 3 * 257, U32_MAX, "mj", 1.0, [0, U32_MAX], [0, 257, 256**2 - 1],
                  [0, 1, 2, 255, 256, 257, 513, 514, 3 * 257 - 1]))
@example(cfg=_cfg("bose", 243, 2, 250, 0, "cmj", 1.0, [5], list(range(243**2 - 600, 243**2)), [0, 242, 243, 244, 249]))
# Bush: largest t at small s, the largest N = 8^8 = 2^24, last column j = s, past the block
@example(cfg=_cfg("bush", 8, 8, 3 * 9 + 1, 0, "cmj", 1.0, [1], [0, 1, 2**21, 2**24 - 1], [0, 7, 8, 9, 17, 26, 27]))
@example(cfg=_cfg("bush", 7, 7, 17, U32_MAX, "j", 0.5, [U32_MAX], [0, 7**6, 7**7 - 1], [0, 6, 7, 8, 16]))
@example(cfg=_cfg("bush", 5, 5, 13, 9, "mj", 1.0, [0, 3], [0, 1, 3124, 624, 625], [0, 4, 5, 6, 12]))
@example(cfg=_cfg("bush", 4, 4, 11, U32_MAX, "cmj", 1.0, [2, 3], list(range(256)), [0, 3, 4, 5, 9, 10]))
@example(cfg=_cfg("bush", 4, 4, 6, 0, "centered", 0.0, [7], list(range(255, -1, -1)), [0, 4, 5]))
@example(cfg=_cfg("bush", 256, 3, 258, 3, "cmj", 1.0, [0], [0, 65536, 2**24 - 1], [0, 1, 255, 256, 257]))
@example(cfg=_cfg("bush", 4093, 2, 4095, 1, "mj", 1.0, [4], [0, 4093, 4093**2 - 1], [0, 4092, 4093, 4094]))
@example(cfg=_cfg("bush", 27, 3, 30, 11, "cmj", 0.75, [1, 2], list(range(19683 - 900, 19683)), [0, 26, 27, 28, 29]))
# Addelman-Kempthorne: the largest q = 2887 (a prime: no tables), few samples, the
# last sample and last column j = 2q, the first columns of blocks 1 and 2
@example(cfg=_cfg("addelman-kempthorne", 2887, 2, 2 * 5775 + 2, U32_MAX, "cmj", 1.0, [0, U32_MAX],
                  [0, 1, 2887**2 - 1, 2887**2, 2 * 2887**2 - 1],
                  [0, 1, 2886, 2887, 2888, 5773, 5774, 5775, 2 * 5775, 2 * 5775 + 1]))
@example(cfg=_cfg("addelman-kempthorne", 2887, 2, 5776, 0, "mj", 0.5, [zero_hash_pixel(0)], [2 * 2887**2 - 1],
                  [5774, 5775]))
# the largest GF-table q = 243 = 3^5, enough samples for the table path (E = 3q + 1 = 730
# per pixel and dimension), across both halves of the array
@example(cfg=_cfg("addelman-kempthorne", 243, 2, 2 * 487 + 1, 0, "cmj", 1.0, [3],
                  list(range(243**2 - 400, 243**2 + 400)), [0, 1, 242, 243, 244, 485, 486, 487, 974]))
@example(cfg=_cfg("addelman-kempthorne", 243, 2, 490, U32_MAX, "j", 0.25, [U32_MAX], [0, 2 * 243**2 - 1],
                  [0, 242, 243, 486, 487, 489]))
@example(cfg=_cfg("addelman-kempthorne", 3, 2, 15, 0, "centered", 0.0, [0], list(range(17, -1, -1)),
                  [0, 2, 3, 5, 6, 7, 13, 14]))
@example(cfg=_cfg("addelman-kempthorne", 9, 2, 40, 1, "mj", 1.0, [1, 2], list(range(162)), [0, 8, 9, 17, 18, 19, 39]))
# Bose-Bush: the largest s = 128 (GF(256), spp 32768): table path (E = 385) and the last column j = 2s
@example(cfg=_cfg("bose-bush", 128, 2, 2 * 257 + 1, U32_MAX, "cmj", 1.0, [U32_MAX],
                  list(range(32768 - 400, 32768)), [0, 1, 127, 128, 255, 256, 257, 513, 514]))
@example(cfg=_cfg("bose-bush", 128, 2, 260, 0, "mj", 1.0, [7], [0, 127, 128, 16384, 32767], [0, 255, 256, 257, 259]))
@example(cfg=_cfg("bose-bush", 2, 2, 11, U32_MAX, "centered", 1.0, [5], list(range(8)), [0, 3, 4, 5, 9, 10]))
@example(cfg=_cfg("bose-bush", 4, 2, 20, 0, "j", 0.0, [zero_hash_pixel(0), 0], list(range(32)), [0, 7, 8, 9, 17, 19]))
def test_backend_matches_reference(backend, cfg):
    smp = make_sampler(cfg, backend)
    assert smp.backend == backend
    got = smp.generate(pixels=cfg["pixels"], samples=cfg["samples"], dims=cfg["dim_idx"])
    want = reference_block(smp, cfg["pixels"], cfg["samples"], cfg["dim_idx"])
    assert_same_bits(got, want, f"{backend} vs reference")
    assert np.all(got >= 0) and np.all(got < 1)
    # Sampler.value (the reference, one value) is the same entry
    assert smp.value(cfg["pixels"][-1], cfg["samples"][-1], cfg["dim_idx"][-1]) == got[-1, -1, -1]


@pytest.mark.opencl
@given(cfg=configs(), n_pixels=st.integers(1, 40))
def test_opencl_matches_numpy_in_bulk(cfg, n_pixels):
    """Larger batches (every sample of many pixels, up to ~10^5 values), kernel vs NumPy."""
    a = make_sampler(cfg, "numpy")
    b = make_sampler(cfg, "opencl")
    n_s = min(cfg["spp"], 2000)
    samples = range(cfg["spp"] - n_s, cfg["spp"])  # includes the last sample
    dims = sorted(set(cfg["dim_idx"]) | set(range(min(cfg["dims"], 12))))
    p0 = cfg["pixels"][0] if cfg["pixels"][0] + n_pixels <= U32_MAX + 1 else U32_MAX + 1 - n_pixels
    pixels = range(p0, p0 + n_pixels)
    assert_same_bits(b.generate(pixels, samples, dims), a.generate(pixels, samples, dims), "opencl vs numpy")


# ----------------------------------------------------------------------------- explicit edge cases

@pytest.mark.parametrize("offset", ["cmj", "centered", "mj"])
@pytest.mark.parametrize("name, spp, strength", [("bose", 49, None), ("cmjnd", 27, 3), ("cmjnd", 16, 2),
                                                 ("bose", 961, None), ("cmjnd", 256, 4),
                                                 ("bose", 64, None), ("bose", 729, None), ("bush", 64, 3),
                                                 ("bush", 81, 2), ("bush", 625, 4), ("bush", 27, 3),
                                                 ("addelman-kempthorne", 50, None), ("addelman-kempthorne", 162, 2),
                                                 ("bose-bush", 32, None), ("bose-bush", 128, 2)])
def test_table_path_threshold(backend, name, spp, strength, offset):
    """Both backends switch to precomputed permutation tables for `cmj` and
    `centered` once the samples per pixel reach the table size (s, plus M for
    `cmj`, plus one): sample counts on both sides of that switch give the
    reference bits, as do chunks that split a pixel's samples."""
    smp = pyoa.sampler(name, spp=spp, dims=7, strength=strength, seed=21, offset=offset, backend=backend)
    entries = smp.s + (smp.params.M if offset == "cmj" else 0)
    for n in sorted({max(1, entries - 1), entries, entries + 1, entries + 2, spp}):
        n = min(n, spp)
        samples = list(range(spp - n, spp))
        got = smp.generate(pixels=[3, U32_MAX], samples=samples)
        assert_same_bits(got, reference_block(smp, [3, U32_MAX], samples, range(7)), f"{n} samples")


@pytest.mark.parametrize("name, spp, strength, check_dims", [
    ("bose", 121, None, [0, 5, 11, 12, 13]),
    ("bose", 81, None, [0, 5, 9, 10, 13]),     # GF(9)
    ("bush", 125, 3, [0, 5, 6, 11, 13]),       # last column j = s, and past the block
    ("bush", 256, 4, [0, 3, 4, 5, 13]),        # GF(4), t = s
    ("addelman-kempthorne", 50, None, [0, 4, 5, 10, 11, 13]),  # q = 5: the last column is 10, then block 1
    ("addelman-kempthorne", 162, None, [0, 8, 9, 13]),         # GF(9), both halves of the array
    ("bose-bush", 32, None, [0, 3, 4, 7, 8, 9, 13]),           # GF(8): the last column j = 2s = 8
])
def test_table_path_with_chunks(monkeypatch, backend, name, spp, strength, check_dims):
    import pyoa._numpy.backend as nb

    smp = pyoa.sampler(name, spp=spp, dims=14, strength=strength, seed=2, backend=backend)
    want = reference_block(smp, [7, 8], range(spp), check_dims)
    if backend == "numpy":
        monkeypatch.setattr(nb, "CHUNK_VALUES", 14 * 50)
    else:
        monkeypatch.setattr(smp._backend, "max_chunk_values", 14 * 50)
    got = smp.generate(pixels=[7, 8])  # 50-row chunks split both pixels' samples
    assert_same_bits(got[:, :, check_dims], want)


SAMPLER_CASES = [
    pytest.param(dict(name="bose", spp=49, dims=17, strength=None), id="bose-s7"),
    pytest.param(dict(name="cmjnd", spp=125, dims=10, strength=3), id="cmjnd-s5-t3"),
    pytest.param(dict(name="bose", spp=81, dims=21, strength=None), id="bose-gf9"),
    pytest.param(dict(name="bush", spp=64, dims=12, strength=3), id="bush-s4-t3"),
    pytest.param(dict(name="bush", spp=625, dims=13, strength=4), id="bush-s5-t4"),
    pytest.param(dict(name="addelman-kempthorne", spp=50, dims=25, strength=None), id="ak-q5"),
    pytest.param(dict(name="addelman-kempthorne", spp=2 * 27**2, dims=60, strength=2), id="ak-gf27"),
    pytest.param(dict(name="bose-bush", spp=32, dims=20, strength=None), id="bb-s4"),
]


@pytest.mark.parametrize("case", SAMPLER_CASES)
@pytest.mark.parametrize("seed", [0, 1, U32_MAX - 1, U32_MAX])
@pytest.mark.parametrize("offset", OFFSETS)
def test_edge_seeds(backend, case, seed, offset):
    smp = pyoa.sampler(**case, seed=seed, offset=offset, backend=backend)
    pixels = [0, 1, U32_MAX, zero_hash_pixel(seed)]
    samples = [0, 1, smp.spp // 2, smp.spp - 1]
    got = smp.generate(pixels=pixels, samples=samples)
    assert_same_bits(got, reference_block(smp, pixels, samples, range(smp.dims)))


def test_largest_bose(backend):
    """s = 4093, spp = 4093^2: only a handful of samples; dims across three blocks."""
    s = 4093
    smp = pyoa.sampler("bose", spp=s * s, dims=2 * (s + 1) + 3, seed=11, backend=backend)
    assert (smp.s, smp.block_dims) == (s, s + 1)
    samples, dims = [0, 1, s * s - 1], [0, 1, 2, s - 1, s, s + 1, s + 2, 2 * (s + 1), smp.dims - 1]
    got = smp.generate(pixels=[0, U32_MAX], samples=samples, dims=dims)
    assert_same_bits(got, reference_block(smp, [0, U32_MAX], samples, dims))


def test_largest_cmjnd_spp(backend):
    """s = 2, t = 24: spp = 2^24 (the maximum), M = 2^23."""
    smp = pyoa.sampler("cmjnd", spp=2**24, dims=50, seed=3, offset="cmj", backend=backend)
    assert (smp.s, smp.strength) == (2, 24)
    samples, dims = [0, 1, 2**23 - 1, 2**23, 2**24 - 2, 2**24 - 1], [0, 1, 22, 23, 24, 47, 48, 49]
    got = smp.generate(pixels=[5], samples=samples, dims=dims)
    assert_same_bits(got, reference_block(smp, [5], samples, dims))


def test_largest_gf_bose(backend):
    """q = 256 = 2^8, spp = 65536: the largest table (GF(256), AES's modulus); a few
    samples, the last column (j = q) and dimensions across three blocks."""
    q = 256
    smp = pyoa.sampler("bose", spp=q * q, dims=2 * (q + 1) + 3, seed=U32_MAX, backend=backend)
    assert (smp.s, smp.block_dims) == (q, q + 1)
    samples, dims = [0, 1, q, q * q - q, q * q - 1], [0, 1, 2, 3, q - 1, q, q + 1, q + 2, 2 * (q + 1), smp.dims - 1]
    for offset in OFFSETS:
        smp = pyoa.sampler("bose", spp=q * q, dims=2 * (q + 1) + 3, seed=U32_MAX, offset=offset, backend=backend)
        got = smp.generate(pixels=[0, U32_MAX], samples=samples, dims=dims)
        assert_same_bits(got, reference_block(smp, [0, U32_MAX], samples, dims), offset)


@pytest.mark.parametrize("s, t", [(2, 2), (3, 3), (4, 4), (5, 5), (7, 7), (8, 8), (16, 6), (64, 4), (256, 3),
                                  (251, 3), (4093, 2), (256, 2)])
def test_largest_bush(backend, s, t):
    """The largest strength at each s (t = s), the counts N = 2^24 (8^8, 16^6, 64^4,
    256^3), the largest prime s: few samples, including the last one and the
    last column j = s, and dimensions past the block."""
    N = s**t
    smp = pyoa.sampler("bush", spp=N, dims=2 * (s + 1) + 1, strength=t, seed=0, offset="mj", backend=backend)
    assert (smp.s, smp.strength, smp.block_dims, smp.params.M) == (s, t, s + 1, N // s)
    samples = sorted({0, 1, s - 1, s, N // s, N // 2, N - s, N - 1})
    dims = sorted({0, 1, s - 1, s, s + 1, 2 * s + 1, 2 * (s + 1), smp.dims - 1})
    for seed, offset in [(0, "mj"), (U32_MAX, "cmj"), (5, "j"), (6, "centered")]:
        smp = pyoa.sampler("bush", spp=N, dims=2 * (s + 1) + 1, strength=t, seed=seed, offset=offset, backend=backend)
        got = smp.generate(pixels=[1, U32_MAX], samples=samples, dims=dims)
        assert_same_bits(got, reference_block(smp, [1, U32_MAX], samples, dims), f"seed={seed} {offset}")


def _tabled_equals_direct(smp, monkeypatch, pixels, samples=None, dims=None):
    """Generate a block on the table path (asserting that it is taken), then with
    tables switched off (the direct path); assert the same bits and return the block."""
    from pyoa.catalogue.request import Request

    req = smp._request(pixels, samples, dims)
    assert all(req.tables_pay_off(rect) for rect in req.rectangles(0, req.n_rows))
    tabled = smp.generate(pixels=pixels, samples=samples, dims=dims)
    monkeypatch.setattr(Request, "tables_pay_off", lambda self, rect: False)
    assert_same_bits(tabled, smp.generate(pixels=pixels, samples=samples, dims=dims), "table path vs direct path")
    return tabled


@pytest.mark.parametrize("s, t", [(4, 3), (9, 2), (8, 3), (16, 2)])
@pytest.mark.parametrize("offset", ["cmj", "centered"])
def test_bush_table_and_direct_paths_agree(backend, s, t, offset, monkeypatch):
    """All samples of a few pixels (the table path) and the same values one sample
    at a time (the direct path) are the same bits, and match the reference."""
    N = s**t
    smp = pyoa.sampler("bush", spp=N, dims=2 * (s + 1), strength=t, seed=99, offset=offset, backend=backend)
    pixels = [0, 7, U32_MAX]
    tabled = _tabled_equals_direct(smp, monkeypatch, pixels)
    rng = np.random.default_rng(N)
    samples = sorted({0, N - 1, *map(int, rng.integers(0, N, 12))})
    assert_same_bits(tabled[:, samples], reference_block(smp, pixels, samples, range(smp.dims)), "vs reference")


@pytest.mark.parametrize("s", [2, 7, 4096, 2**24])
def test_cmjnd_strength_one(backend, s):
    """t = 1: every dimension is its own block, M = 1 (a plain 1D stratification)."""
    smp = pyoa.sampler("cmjnd", spp=s, dims=4, strength=1, seed=8, backend=backend)
    assert (smp.s, smp.strength, smp.block_dims) == (s, 1, 1)
    samples = sorted({0, 1, s // 2, s - 1})
    got = smp.generate(pixels=[0, 9], samples=samples)
    assert_same_bits(got, reference_block(smp, [0, 9], samples, range(4)))
    if s <= 4096:
        x = smp.generate(pixels=[2]).astype(np.float64)
        assert np.array_equal(np.sort(np.floor(x * s), axis=1), np.broadcast_to(np.arange(s)[:, None], (s, 4)).reshape(1, s, 4))


def _find_clamped_sample(max_tries: int = 40):
    """A (pixel, sample) of cmjnd s=2, t=24, dimension 0, whose value rounds to 1.0
    and must be clamped: stratum 1, sub-stratum M-1 = 2^23-1 and a jitter above 0.75
    (sub + jitter then rounds to 2^23 in float32). Found by inverting the permutations."""
    s, M = 2, 2**23  # t = 24
    for pixel in range(max_tries):
        p = ref.pixel_seed(0, pixel)
        P1, P2, P3 = ref.dimension_seeds(p, 0)
        a = next(a for a in range(s) if ref.permute(a, s, P1) == s - 1)
        perm = nh.permute(np.arange(M, dtype=np.uint32), M, np.uint32(P2))
        v = int(np.flatnonzero(perm == M - 1)[0])
        i = a + s * v  # digit 0 is a, the other digits are v
        if ref.randfloat(i, P3) > 0.75:
            return pixel, i
    raise AssertionError("no clamped sample found")


def test_value_that_rounds_to_one_is_clamped(backend):
    """docs/spec.md section 7 through the whole pipeline: the value is 0x3f7fffff in every backend."""
    pixel, i = _find_clamped_sample()
    smp = pyoa.sampler("cmjnd", spp=2**24, dims=24, seed=0, jitter=1.0, backend=backend)
    got = smp.generate(pixels=[pixel], samples=[i], dims=[0])
    assert int(bits(got)[0, 0, 0]) == 0x3F7FFFFF
    assert smp.value(pixel, i, 0) == float(got[0, 0, 0])


@pytest.mark.parametrize("jitter", [0.0, 1.0, 0.5, 1e-30, 0.999999, float(np.nextafter(np.float32(1), np.float32(0)))])
def test_jitter_amounts(backend, jitter):
    smp = pyoa.sampler("bose", spp=25, dims=7, seed=4, jitter=jitter, offset="mj", backend=backend)
    got = smp.generate(pixels=[0, 3])
    assert_same_bits(got, reference_block(smp, [0, 3], range(25), range(7)))


@pytest.mark.parametrize("name, spp, strength", [("bose", 121, None), ("cmjnd", 64, 3), ("cmjnd", 10, 1),
                                                 ("bose", 64, None), ("bush", 125, 3), ("bush", 256, 4),
                                                 ("addelman-kempthorne", 18, None), ("bose-bush", 8, None)])
def test_value_equals_generate(backend, name, spp, strength):
    smp = pyoa.sampler(name, spp=spp, dims=9, strength=strength, seed=77, backend=backend, offset="j")
    x = smp.generate(pixels=[0, 12345, U32_MAX])
    for a, pix in enumerate([0, 12345, U32_MAX]):
        for i in (0, 1, spp - 1):
            for j in (0, 3, 8):
                v = smp.value(pix, i, j)
                assert isinstance(v, float)
                assert np.float32(v).view(np.uint32) == x[a, i, j].view(np.uint32)


@pytest.mark.parametrize("name, s", [("addelman-kempthorne", 2887), ("addelman-kempthorne", 243),
                                     ("addelman-kempthorne", 251), ("addelman-kempthorne", 3),
                                     ("bose-bush", 128), ("bose-bush", 2)])
def test_largest_and_smallest_index2(backend, name, s):
    """The index-2 extremes: Addelman-Kempthorne q = 2887 (spp = 2 * 2887^2, the
    largest; prime arithmetic, no tables), q = 243 (the largest GF table), q = 251
    (the largest prime with tables skipped), q = 3; Bose-Bush s = 128 (GF(256),
    spp 32768) and s = 2 (GF(4)). Few samples (both halves of the array, the last
    one), the last column j = 2s and dimensions across three blocks, every offset
    and edge seeds."""
    N, d = 2 * s * s, 2 * s + 1
    samples = sorted({0, 1, s - 1, s, s * s - 1, s * s, s * s + s, N - s, N - 1})
    dims = sorted({0, 1, s - 1, s, s + 1, 2 * s - 1, 2 * s, d, d + 1, 2 * d - 1, 2 * d, 2 * d + 2})
    for seed, offset, jitter in [(0, "mj", 1.0), (U32_MAX, "cmj", 1.0), (5, "j", 0.5), (6, "centered", 0.0)]:
        smp = pyoa.sampler(name, spp=N, dims=2 * d + 3, seed=seed, offset=offset, jitter=jitter, backend=backend)
        assert (smp.s, smp.strength, smp.block_dims, smp.params.M) == (s, 2, d, 2 * s)
        got = smp.generate(pixels=[1, U32_MAX], samples=samples, dims=dims)
        assert_same_bits(got, reference_block(smp, [1, U32_MAX], samples, dims), f"seed={seed} {offset}")


@pytest.mark.parametrize("name, s", [("addelman-kempthorne", 2887), ("addelman-kempthorne", 243),
                                     ("addelman-kempthorne", 251), ("bose-bush", 128)])
@pytest.mark.parametrize("offset", ["cmj", "centered"])
def test_index2_table_path_at_the_largest_sizes(backend, name, s, offset, monkeypatch):
    """The table path at the largest orders: one pixel, E = s (+ 2s for cmj) + 1
    consecutive samples and a few more (the least that pays off), across the two
    halves of the array for Addelman-Kempthorne or ending at the last sample; the
    last column j = 2s and dimensions past the block. Same bits as the direct
    path, and as the reference on a subset."""
    N, d = 2 * s * s, 2 * s + 1
    smp = pyoa.sampler(name, spp=N, dims=2 * d + 1, seed=12, offset=offset, backend=backend)
    n = smp._request([0], [0], None).table_stride + 3
    start = s * s - n // 2 if name == "addelman-kempthorne" else N - n
    samples = range(start, start + n)
    dims = [0, 1, s - 1, s, 2 * s - 1, 2 * s, d, 2 * d]
    tabled = _tabled_equals_direct(smp, monkeypatch, [U32_MAX], samples, dims)
    rng = np.random.default_rng(s)
    sub = sorted({0, n // 2, n - 1, *map(int, rng.integers(0, n, 12))})
    assert_same_bits(tabled[:, sub], reference_block(smp, [U32_MAX], [samples[k] for k in sub], dims), "vs reference")


@pytest.mark.parametrize("name, s", [("addelman-kempthorne", 5), ("addelman-kempthorne", 9),
                                     ("addelman-kempthorne", 27), ("addelman-kempthorne", 31),
                                     ("bose-bush", 4), ("bose-bush", 16)])
@pytest.mark.parametrize("offset", ["cmj", "centered"])
def test_index2_table_and_direct_paths_agree(backend, name, s, offset, monkeypatch):
    """All samples of a few pixels (the table path: kernels tables and
    generate_cells, NumPy's gather) and the same values with tables
    switched off (the direct path) are the same bits, and match the reference."""
    N, d = 2 * s * s, 2 * s + 1
    smp = pyoa.sampler(name, spp=N, dims=d + 2, seed=99, offset=offset, backend=backend)
    pixels = [0, 7, U32_MAX]
    assert smp._request(pixels, None, None).table_entries == s + (2 * s if offset == "cmj" else 0) + 1
    tabled = _tabled_equals_direct(smp, monkeypatch, pixels)
    rng = np.random.default_rng(N)
    samples = sorted({0, s * s - 1, s * s, N - 1, *map(int, rng.integers(0, N, 10))})
    assert_same_bits(tabled[:, samples], reference_block(smp, pixels, samples, range(smp.dims)), "vs reference")


def test_reference_is_not_backend_dependent_by_accident(backend):
    """Guards the whole suite: different seeds, offsets and jitters give different bits,
    so the equality tests above compare something."""
    base = dict(spp=49, dims=9, backend=backend)
    x = pyoa.sampler("bose", seed=1, **base).generate(pixels=[0])
    assert not np.array_equal(x, pyoa.sampler("bose", seed=2, **base).generate(pixels=[0]))
    assert not np.array_equal(x, pyoa.sampler("bose", seed=1, offset="mj", **base).generate(pixels=[0]))
    assert not np.array_equal(x, pyoa.sampler("bose", seed=1, jitter=0.5, **base).generate(pixels=[0]))
    assert not np.array_equal(x, pyoa.sampler("bose", seed=1, **base).generate(pixels=[1]))
