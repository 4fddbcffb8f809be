"""Bit-exact conformance of the comparison samplers (random, jittered2d, cmj2d,
sobol02, halton, sobol): every (pixel, sample, dimension) has the same float32
bits from the OpenCL kernels (kernels/include/pyoa/baselines.h, the GENERATE_BASELINE
kernels of kernels/generate.cl), NumPy (pyoa/_numpy/baselines.py) and the
pure-Python reference (pyoa/reference/baselines.py), in any batch, order or
chunking. The ``backend`` fixture runs a test for "numpy" and "opencl".

The reference is slow (Halton in base 2 permutes 24 digits per value), so it
checks small blocks; NumPy, once equal to the reference, is the bulk oracle of
the kernels. ``p == 0`` (the unscrambled sets) cannot come out of
``pixel_seed``, so it is checked through the functions directly, and through
the kernels' functions with a small test kernel.
"""

from __future__ import annotations

import math
import zlib

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

import pyoa
import pyoa.catalogue
import pyoa._numpy.backend as numpy_backend
from pyoa import reference as ref
from pyoa.tables import sequences
from pyoa._numpy import baselines as nbl
from pyoa.reference import baselines as rbl
from tests.helpers import PIXEL_KEY, U32_MAX, assert_same_bits, kernel_runner

U32 = np.uint32
F32 = np.float32

#: The paper's six comparison samplers, which this deeper suite checks with
#: shapes worked out independently of the catalogue (shape_of). Every
#: registered sampler, these and later ones, also runs the catalogue-driven
#: suite of tests/test_catalogue.py, which needs no list.
NAMES = ["random", "jittered2d", "cmj2d", "sobol02", "halton", "sobol"]
#: the samplers that take a jitter amount
JITTERED = {"jittered2d", "cmj2d"}
#: the samplers whose values are k * 2^-24 (the 24-bit float rule)
GRID24 = {"random", "sobol02", "halton", "sobol"}
MAX_SPP = 2**24
MAX_DIMS = 2**20
HALTON_DIMS = 6542
SOBOL_DIMS = 21201
MAX_DIMS_OF = {"halton": HALTON_DIMS, "sobol": SOBOL_DIMS}
#: the largest prime below 2^24 (cmj2d: a 1 x N grid), and 4093 x 4099 (two primes,
#: the most nearly square factorization of 16777207)
BIG_PRIME = 16777213
TWIN = 4093 * 4099
#: cmj2d counts: primes (1 x N), squares, highly composite, prime times 2, 2^24
CMJ_SPECIAL = [1, 2, 3, 5, 7, 12, 4093, 4099, 65521, BIG_PRIME, TWIN, 2 * 8388593, 4095 * 4096, 5040,
               720720, 4096 * 4096, 2**23, 3 * 2**22]
#: jitter amounts with many significant bits: jitter_value's product is inexact, so
#: a fused multiply-add (kernel) would change the bits
MANY_BITS = [float(F32(math.sqrt(0.5))), float(F32(1 / 3)), 1 - 2**-24, 2**-24, float(F32(0.1))]


def zero_hash_pixel(seed: int) -> int:
    """The pixel whose raw pixel hash is 0 (pixel_seed must remap it): see test_conformance."""
    return ref.mix32(seed ^ PIXEL_KEY)


def is_prime(n: int) -> bool:
    return n > 1 and all(n % d for d in range(2, math.isqrt(n) + 1))


# ----------------------------------------------------------------------------- the reference side

def shape_of(name: str, spp: int, dims: int) -> tuple:
    """The shape arguments of the reference functions, worked out here (not by the
    catalogue): jittered2d (m, dims) with m^2 = spp; cmj2d (m, n) the most nearly
    square m x n = spp, m <= n; sobol02 log2(spp)."""
    if name == "jittered2d":
        m = math.isqrt(spp)
        assert m * m == spp
        return (m, dims)
    if name == "cmj2d":
        m = next(d for d in range(math.isqrt(spp), 0, -1) if spp % d == 0)
        return (m, spp // m)
    if name == "sobol02":
        k = spp.bit_length() - 1
        assert 1 << k == spp
        return (k,)
    return ()


def ref_value(name: str, i: int, j: int, shape: tuple, p: int, jitter: float) -> float:
    f = getattr(rbl, name)
    return f(i, j, *shape, p, jitter) if name in JITTERED else f(i, j, *shape, p)


def np_values(name: str, i, j, shape: tuple, p, jitter: float) -> np.ndarray:
    f = getattr(nbl, name)
    return f(i, j, *shape, p, jitter) if name in JITTERED else f(i, j, *shape, p)


def reference_block(smp, pixels, samples, dims) -> np.ndarray:
    """What ``smp.generate(pixels, samples, dims)`` must return, from pyoa.reference.baselines."""
    shape = shape_of(smp.name, smp.spp, smp.dims)
    out = np.empty((len(pixels), len(samples), len(dims)), dtype=F32)
    for a, pix in enumerate(pixels):
        p = ref.pixel_seed(smp.seed, int(pix))
        for b, i in enumerate(samples):
            for c, j in enumerate(dims):
                out[a, b, c] = ref_value(smp.name, int(i), int(j), shape, p, smp.jitter)
    return out


def make_sampler(cfg, backend):
    smp = pyoa.sampler(cfg["name"], spp=cfg["spp"], dims=cfg["dims"], seed=cfg["seed"], jitter=cfg["jitter"],
                       backend=backend)
    assert smp.backend == backend
    # the catalogue's shape arguments are the ones worked out independently here
    assert tuple(smp._construction.shape_args(smp.params)) == shape_of(cfg["name"], cfg["spp"], cfg["dims"])
    return smp


def assert_value_rules(name, x):
    x = np.asarray(x)
    assert np.all(x >= 0) and np.all(x < 1)
    if name in GRID24:
        k = x.astype(np.float64) * 2**24
        assert np.array_equal(k, np.floor(k)), f"{name}: a value is not k * 2^-24"


# ----------------------------------------------------------------------------- hypothesis strategy

def _special_dims(name: str, dims: int) -> list[int]:
    """The first and last dimensions, the pair boundaries, and Halton's bases 2, 3,
    65519, 65521 / Sobol's last dimension where they exist."""
    cand = [0, 1, 2, 3, dims - 3, dims - 2, dims - 1]
    if name == "halton":
        cand += [6540, 6541]
    if name == "sobol":
        cand += [21199, 21200]
    return sorted({d for d in cand if 0 <= d < dims})


@st.composite
def configs(draw):
    name = draw(st.sampled_from(NAMES))
    if name in ("random", "halton"):
        spp = draw(st.integers(1, MAX_SPP) | st.integers(1, 300) | st.sampled_from([1, 2, 3, 65521, 65522,
                                                                                      MAX_SPP - 1, MAX_SPP]))
    elif name == "jittered2d":
        m = draw(st.integers(1, 4096) | st.integers(1, 20) | st.sampled_from([1, 2, 3, 4095, 4096]))
        spp = m * m
    elif name == "cmj2d":
        spp = draw(st.integers(1, MAX_SPP) | st.integers(1, 300) | st.sampled_from(CMJ_SPECIAL))
    else:
        spp = 1 << draw(st.integers(0, 24) | st.sampled_from([0, 1, 24]))
    top = MAX_DIMS_OF.get(name, MAX_DIMS)
    dims = draw(st.integers(1, 9) | st.integers(1, top) | st.sampled_from([top - 1, top]))
    seed = draw(st.sampled_from([0, 1, U32_MAX, U32_MAX - 1]) | st.integers(0, U32_MAX))
    jitter = 1.0
    if name in JITTERED:
        jitter = draw(st.sampled_from([0.0, 1.0]) | st.sampled_from(MANY_BITS) | st.floats(0.0, 1.0)
                      | st.integers(1, 2**24 - 1).map(lambda k: k * 2.0**-24))
        jitter = float(F32(jitter))
    many = draw(st.booleans())
    pixels = draw(st.lists(st.sampled_from([0, U32_MAX, zero_hash_pixel(seed)]) | st.integers(0, U32_MAX),
                           min_size=1, max_size=2 if many else 3))
    if many:  # a run of consecutive samples (all of them for small counts), possibly reversed
        n = min(spp, draw(st.integers(1, 64)))
        start = draw(st.integers(0, spp - n))
        samples = list(range(start, start + n))
        if draw(st.booleans()):
            samples = samples[::-1]
    else:
        samples = draw(st.lists(st.sampled_from([0, 1, spp // 2, spp - 1]).filter(lambda v: v < spp)
                                | st.integers(0, spp - 1), min_size=1, max_size=6))
    samples.append(spp - 1)  # always the last sample
    dim_idx = draw(st.lists(st.sampled_from(_special_dims(name, dims)) | st.integers(0, dims - 1),
                            min_size=0, max_size=6))
    dim_idx.append(dims - 1)  # always the last dimension
    return dict(name=name, spp=spp, dims=dims, seed=seed, jitter=jitter, pixels=pixels, samples=samples,
                dim_idx=dim_idx)


def _cfg(name, spp, dims, seed, jitter, pixels, samples, dim_idx):
    return dict(name=name, spp=spp, dims=dims, seed=seed, jitter=jitter, pixels=pixels, samples=samples,
                dim_idx=dim_idx)


@given(cfg=configs())
# the largest count of each, the last sample, edge seeds and pixels
@example(cfg=_cfg("random", MAX_SPP, MAX_DIMS, U32_MAX, 1.0, [0, U32_MAX], [0, MAX_SPP - 1], [0, 1, MAX_DIMS - 1]))
@example(cfg=_cfg("random", 1, 1, 0, 1.0, [zero_hash_pixel(0)], [0], [0]))
@example(cfg=_cfg("jittered2d", 4096**2, 7, U32_MAX - 1, MANY_BITS[0], [U32_MAX], [0, 4095, 4096, 4096**2 - 1],
                  [0, 1, 5, 6]))
@example(cfg=_cfg("jittered2d", 4096**2, 8, 1, 1.0, [0], [0, 4096**2 - 1], [6, 7]))
@example(cfg=_cfg("jittered2d", 1, 1, 0, 0.0, [0], [0], [0]))
@example(cfg=_cfg("jittered2d", 9, 3, 5, MANY_BITS[1], [zero_hash_pixel(5)], list(range(9)), [0, 1, 2]))
@example(cfg=_cfg("jittered2d", 16, MAX_DIMS - 1, 7, MANY_BITS[2], [3], list(range(16)),
                  [0, MAX_DIMS - 3, MAX_DIMS - 2]))
@example(cfg=_cfg("cmj2d", BIG_PRIME, 3, U32_MAX, MANY_BITS[0], [0, U32_MAX], [0, 1, BIG_PRIME - 1], [0, 1, 2]))
@example(cfg=_cfg("cmj2d", TWIN, 4, 0, MANY_BITS[4], [7], [0, 4092, 4093, TWIN - 1], [0, 1, 2, 3]))
@example(cfg=_cfg("cmj2d", MAX_SPP, 5, 1, 1.0, [U32_MAX], [0, 4096, MAX_SPP - 1], [0, 1, 4]))
@example(cfg=_cfg("cmj2d", 720720, 2, U32_MAX - 1, 2**-24, [1], [0, 720719], [0, 1]))
@example(cfg=_cfg("cmj2d", 7, 3, 9, MANY_BITS[1], [2], list(range(7)), [0, 1, 2]))
@example(cfg=_cfg("sobol02", 1, 3, 0, 1.0, [0], [0], [0, 1, 2]))
@example(cfg=_cfg("sobol02", MAX_SPP, MAX_DIMS, U32_MAX, 1.0, [0, U32_MAX], [0, 1, MAX_SPP - 1],
                  [0, 1, MAX_DIMS - 2, MAX_DIMS - 1]))
@example(cfg=_cfg("sobol02", 64, 4, 3, 1.0, [4], list(range(63, -1, -1)), [0, 1, 2, 3]))
@example(cfg=_cfg("halton", MAX_SPP, HALTON_DIMS, U32_MAX, 1.0, [U32_MAX, zero_hash_pixel(U32_MAX)],
                  [0, 1, 65520, 65521, MAX_SPP - 1], [0, 1, 6540, 6541]))
@example(cfg=_cfg("halton", 65522, 2, 0, 1.0, [0], [65519, 65520, 65521], [0, 1]))
@example(cfg=_cfg("halton", 1, 1, 1, 1.0, [0], [0], [0]))
@example(cfg=_cfg("sobol", MAX_SPP, SOBOL_DIMS, U32_MAX - 1, 1.0, [0, U32_MAX], [0, 1, 2**23, MAX_SPP - 1],
                  [0, 1, 2, 21199, 21200]))
@example(cfg=_cfg("sobol", 1, SOBOL_DIMS, 0, 1.0, [zero_hash_pixel(0)], [0], [0, 21200]))
@example(cfg=_cfg("sobol", 32, 3, 11, 1.0, [5, 6], list(range(32)), [0, 1, 2]))
def test_backend_matches_reference(backend, cfg):
    smp = make_sampler(cfg, backend)
    got = smp.generate(pixels=cfg["pixels"], samples=cfg["samples"], dims=cfg["dim_idx"])
    want = reference_block(smp, cfg["pixels"], cfg["samples"], cfg["dim_idx"])
    assert_same_bits(got, want, f"{backend} vs reference")
    assert_value_rules(cfg["name"], got)
    # Sampler.value (the reference through the catalogue, one value) is the same entry
    assert smp.value(cfg["pixels"][-1], cfg["samples"][-1], cfg["dim_idx"][-1]) == got[-1, -1, -1]


def _bulk_request(cfg, n_pixels):
    n_s = min(cfg["spp"], 1024)
    samples = range(cfg["spp"] - n_s, cfg["spp"])  # every sample of small counts; always the last
    dims = sorted(set(cfg["dim_idx"]) | set(range(min(cfg["dims"], 6))))
    p0 = min(cfg["pixels"][0], U32_MAX + 1 - n_pixels)
    return range(p0, p0 + n_pixels), samples, dims


@pytest.mark.opencl
@given(cfg=configs(), n_pixels=st.integers(1, 40), n_chunks=st.integers(2, 9), skew=st.integers(0, 5))
def test_opencl_matches_numpy_in_bulk(cfg, n_pixels, n_chunks, skew):
    """Larger batches (up to 40 pixels x 1024 samples), kernel vs NumPy, unsplit and
    split into chunks that cut pixels in the middle."""
    a = make_sampler(cfg, "numpy")
    b = make_sampler(cfg, "opencl")
    pixels, samples, dims = _bulk_request(cfg, n_pixels)
    want = a.generate(pixels, samples, dims)
    assert_same_bits(b.generate(pixels, samples, dims), want, "opencl vs numpy")
    rows = len(pixels) * len(samples)
    step = max(1, -(-rows // n_chunks) + skew)  # rows per chunk
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(numpy_backend, "CHUNK_VALUES", step * len(dims))
        mp.setattr(b._backend, "max_chunk_values", step * len(dims))
        assert b._backend.rows_per_chunk(len(dims)) == step
        assert_same_bits(b.generate(pixels, samples, dims), want, f"opencl in chunks of {step} rows vs numpy")
        assert_same_bits(a.generate(pixels, samples, dims), want, f"numpy in chunks of {step} rows vs unsplit")


# ----------------------------------------------------------------------------- chunks, explicit

CHUNK_CASES = [
    pytest.param("random", 37, 5, id="random"),
    pytest.param("jittered2d", 49, 7, id="jittered2d-odd"),
    pytest.param("jittered2d", 36, 6, id="jittered2d-even"),
    pytest.param("cmj2d", 31, 5, id="cmj2d-prime"),
    pytest.param("cmj2d", 60, 4, id="cmj2d-6x10"),
    pytest.param("sobol02", 64, 5, id="sobol02"),
    pytest.param("halton", 45, 6542, id="halton"),
    pytest.param("sobol", 32, 21201, id="sobol"),
]


@pytest.mark.parametrize("name, spp, dims", CHUNK_CASES)
def test_chunks_give_the_same_bits(monkeypatch, backend, name, spp, dims):
    """Every sample of 3 pixels, then the same request in chunks of 7 rows (which
    cut every pixel's samples): the same bits, and the reference's on a subset."""
    jitter = MANY_BITS[0] if name in JITTERED else 1.0
    smp = pyoa.sampler(name, spp=spp, dims=dims, seed=2, jitter=jitter, backend=backend)
    pixels = [7, 8, U32_MAX]
    check = _special_dims(name, dims)
    whole = smp.generate(pixels=pixels, dims=check)
    if backend == "numpy":
        monkeypatch.setattr(numpy_backend, "CHUNK_VALUES", 7 * len(check))
    else:
        monkeypatch.setattr(smp._backend, "max_chunk_values", 7 * len(check))
    assert smp._backend.rows_per_chunk(len(check)) == 7
    assert_same_bits(smp.generate(pixels=pixels, dims=check), whole, "chunks of 7 rows vs unsplit")
    sub = sorted({0, 1, 6, 7, spp // 2, spp - 1})
    assert_same_bits(whole[:, sub], reference_block(smp, pixels, sub, check), "vs reference")


# ----------------------------------------------------------------------------- explicit edge cases

LARGEST = [
    pytest.param("random", MAX_SPP, 5, id="random-2^24"),
    pytest.param("jittered2d", 4096**2, 5, id="jittered2d-4096^2-odd"),
    pytest.param("jittered2d", 4096**2, 6, id="jittered2d-4096^2-even"),
    pytest.param("cmj2d", MAX_SPP, 5, id="cmj2d-2^24"),
    pytest.param("cmj2d", BIG_PRIME, 3, id="cmj2d-prime-1xN"),
    pytest.param("cmj2d", TWIN, 4, id="cmj2d-4093x4099"),
    pytest.param("sobol02", MAX_SPP, 5, id="sobol02-2^24"),
    pytest.param("halton", MAX_SPP, 5, id="halton-2^24"),
    pytest.param("sobol", MAX_SPP, 5, id="sobol-2^24"),
]


@pytest.mark.parametrize("name, spp, dims", LARGEST)
def test_largest_spp(backend, name, spp, dims):
    """The largest count of each sampler at the last sample, with edge seeds and pixels."""
    samples = [0, 1, spp // 2, spp - 2, spp - 1]
    for seed in (0, U32_MAX):
        for jitter in ([1.0, MANY_BITS[0], 0.0] if name in JITTERED else [1.0]):
            smp = pyoa.sampler(name, spp=spp, dims=dims, seed=seed, jitter=jitter, backend=backend)
            assert smp.spp == spp
            pixels = [0, U32_MAX, zero_hash_pixel(seed)]
            got = smp.generate(pixels=pixels, samples=samples)
            assert_same_bits(got, reference_block(smp, pixels, samples, range(dims)), f"seed={seed} J={jitter}")
            assert_value_rules(name, got)


def test_catalogue_grids():
    """The grids the edge cases rely on (a prime gives 1 x N; Halton's first and last bases)."""
    c = pyoa.catalogue.SAMPLERS["cmj2d"]
    assert (c.params(BIG_PRIME, 3).a, c.params(BIG_PRIME, 3).c) == (1, BIG_PRIME)
    assert (c.params(TWIN, 3).a, c.params(TWIN, 3).c) == (4093, 4099)
    assert (c.params(MAX_SPP, 3).a, c.params(MAX_SPP, 3).c) == (4096, 4096)
    assert is_prime(BIG_PRIME) and is_prime(4093) and is_prime(4099)
    primes = sequences.primes()
    assert len(primes) == HALTON_DIMS and list(primes[:2]) == [2, 3] and list(primes[-2:]) == [65519, 65521]
    assert sequences.sobol_matrices().shape == (SOBOL_DIMS, 32)


LARGEST_DIMS = [
    pytest.param("halton", MAX_SPP, HALTON_DIMS, [0, 1, 2, 3, 6539, 6540, 6541], id="halton-6542"),
    pytest.param("halton", 65522, HALTON_DIMS, [0, 6540, 6541], id="halton-6542-two-digits"),
    pytest.param("halton", 7, HALTON_DIMS, [6541], id="halton-6542-small"),
    pytest.param("sobol", MAX_SPP, SOBOL_DIMS, [0, 1, 2, 21199, 21200], id="sobol-21201"),
    pytest.param("sobol", 1, SOBOL_DIMS, [21200], id="sobol-21201-one-sample"),
    pytest.param("random", 3, MAX_DIMS, [0, MAX_DIMS - 2, MAX_DIMS - 1], id="random-2^20"),
    pytest.param("jittered2d", 25, MAX_DIMS, [0, MAX_DIMS - 2, MAX_DIMS - 1], id="jittered2d-2^20"),
    pytest.param("jittered2d", 25, MAX_DIMS - 1, [0, MAX_DIMS - 3, MAX_DIMS - 2], id="jittered2d-2^20-1-lone"),
    pytest.param("cmj2d", 12, MAX_DIMS - 1, [0, MAX_DIMS - 3, MAX_DIMS - 2], id="cmj2d-2^20-1"),
    pytest.param("sobol02", 16, MAX_DIMS, [0, MAX_DIMS - 2, MAX_DIMS - 1], id="sobol02-2^20"),
]


@pytest.mark.parametrize("name, spp, dims, check", LARGEST_DIMS)
def test_largest_dims(backend, name, spp, dims, check):
    """The most dimensions of each sampler at the last dimension (Halton's base
    65521, Sobol's last Joe-Kuo dimension), at the first and last samples."""
    samples = sorted(v for v in {0, 1, 2, 65520, 65521, spp // 2, spp - 1} if v < spp)
    for seed in (0, U32_MAX):
        jitter = MANY_BITS[1] if name in JITTERED else 1.0
        smp = pyoa.sampler(name, spp=spp, dims=dims, seed=seed, jitter=jitter, backend=backend)
        pixels = [1, U32_MAX]
        got = smp.generate(pixels=pixels, samples=samples, dims=check)
        assert_same_bits(got, reference_block(smp, pixels, samples, check), f"seed={seed}")
        assert_value_rules(name, got)


@pytest.mark.parametrize("name, top", [("halton", HALTON_DIMS), ("sobol", SOBOL_DIMS)])
def test_every_dimension(backend, name, top):
    """Every Halton base and every Sobol dimension, at the first, a random and the
    last sample: the reference on one value per dimension (the samples in turn),
    and for the kernels the NumPy functions on all of them."""
    rng = np.random.default_rng(top)
    samples = [0, int(rng.integers(1, MAX_SPP - 1)), MAX_SPP - 1]
    smp = pyoa.sampler(name, spp=MAX_SPP, dims=top, seed=5, backend=backend)
    got = smp.generate(pixels=[U32_MAX], samples=samples)[0]
    p = ref.pixel_seed(5, U32_MAX)
    jj = np.arange(top)
    which = jj % 3
    want = np.array([ref_value(name, samples[w], j, (), p, 1.0) for j, w in zip(jj.tolist(), which.tolist())], F32)
    assert_same_bits(got[which, jj], want, "vs reference")
    if backend != "numpy":
        i = np.array(samples, U32)[:, None]
        assert_same_bits(got, np_values(name, i, jj.astype(U32)[None, :], (), U32(p), 1.0), "vs numpy functions")


EDGE_SEED_CASES = [
    pytest.param("random", 10, 5, id="random"),
    pytest.param("jittered2d", 16, 5, id="jittered2d"),
    pytest.param("cmj2d", 15, 4, id="cmj2d"),
    pytest.param("sobol02", 16, 5, id="sobol02"),
    pytest.param("halton", 12, 4, id="halton"),
    pytest.param("sobol", 16, 4, id="sobol"),
]


@pytest.mark.parametrize("name, spp, dims", EDGE_SEED_CASES)
@pytest.mark.parametrize("seed", [0, 1, U32_MAX - 1, U32_MAX])
def test_edge_seeds(backend, name, spp, dims, seed):
    jitter = MANY_BITS[2] if name in JITTERED else 1.0
    smp = pyoa.sampler(name, spp=spp, dims=dims, seed=seed, jitter=jitter, backend=backend)
    pixels = [0, 1, U32_MAX, zero_hash_pixel(seed)]
    got = smp.generate(pixels=pixels)
    assert_same_bits(got, reference_block(smp, pixels, range(spp), range(dims)))


@pytest.mark.parametrize("jitter", [0.0, 1.0, 0.5, 1e-30, *MANY_BITS,
                                    float(np.nextafter(F32(1), F32(0)))])
@pytest.mark.parametrize("name, spp", [("jittered2d", 25), ("cmj2d", 24)])
def test_jitter_amounts(backend, name, spp, jitter):
    smp = pyoa.sampler(name, spp=spp, dims=5, seed=4, jitter=jitter, backend=backend)
    got = smp.generate(pixels=[0, 3])
    assert_same_bits(got, reference_block(smp, [0, 3], range(spp), range(5)))


ORDER_CASES = [
    pytest.param("random", 50, 9, id="random"),
    pytest.param("jittered2d", 49, 9, id="jittered2d"),
    pytest.param("cmj2d", 50, 9, id="cmj2d"),
    pytest.param("sobol02", 64, 9, id="sobol02"),
    pytest.param("halton", 50, 6542, id="halton"),
    pytest.param("sobol", 64, 21201, id="sobol"),
]


@pytest.mark.parametrize("name, spp, dims", ORDER_CASES)
def test_order_independence(backend, name, spp, dims):
    """Shuffled pixels, samples and dimensions (with repeats) give the same values, permuted."""
    rng = np.random.default_rng(spp * 7919 + dims)
    smp = pyoa.sampler(name, spp=spp, dims=dims, seed=31, jitter=MANY_BITS[0] if name in JITTERED else 1.0,
                       backend=backend)
    pixels = [0, 5, U32_MAX]
    dsel = _special_dims(name, dims) + sorted(set(map(int, rng.integers(0, dims, 5))))
    block = smp.generate(pixels=pixels, samples=range(spp), dims=dsel)
    pp = rng.permutation(len(pixels))
    ps = np.concatenate([rng.permutation(spp), rng.integers(0, spp, 10)])
    pd = np.concatenate([rng.permutation(len(dsel)), [0, len(dsel) - 1]])
    got = smp.generate(pixels=[pixels[k] for k in pp], samples=ps.tolist(), dims=[dsel[k] for k in pd])
    assert_same_bits(got, block[pp][:, ps][:, :, pd], "shuffled request vs permuted block")
    # one value at a time
    for a, b, c in [(0, 0, 0), (2, spp - 1, len(dsel) - 1), (1, spp // 2, 1)]:
        one = smp.generate(pixels=[pixels[a]], samples=[b], dims=[dsel[c]])
        assert_same_bits(one, block[a : a + 1, b : b + 1, c : c + 1], "single value")


@pytest.mark.parametrize("name, spp, dims", ORDER_CASES)
def test_the_comparisons_compare_something(backend, name, spp, dims):
    """Guards the suite: other seeds, pixels (and jitter amounts) give other bits."""
    kw = dict(spp=spp, dims=dims, backend=backend)
    d = [0, 1, dims - 1]
    x = pyoa.sampler(name, seed=1, **kw).generate(pixels=[0], dims=d)
    assert not np.array_equal(x, pyoa.sampler(name, seed=2, **kw).generate(pixels=[0], dims=d))
    assert not np.array_equal(x, pyoa.sampler(name, seed=1, **kw).generate(pixels=[1], dims=d))
    assert not np.array_equal(x[..., 0], x[..., 1])
    if name in JITTERED:
        assert not np.array_equal(x, pyoa.sampler(name, seed=1, jitter=0.5, **kw).generate(pixels=[0], dims=d))


# ----------------------------------------------------------------------------- the functions directly

RNG_SEED = 20190710


def _u32_inputs(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    specials = [0, 1, 2, 3, 0xFF, 0x100, 0xFFFFFF, 0x1000000, 0x7FFFFFFF, 0x80000000, 0x80000001,
                0x55555555, 0xAAAAAAAA, U32_MAX - 1, U32_MAX]
    return np.concatenate([np.array(specials, dtype=U32), rng.integers(0, 2**32, n, dtype=np.uint64).astype(U32)])


def test_helpers_numpy_equal_reference():
    x = _u32_inputs(3000, RNG_SEED)
    seeds = np.roll(x, 7)
    seeds[::5] = 0  # owen_scramble's identity, mixed in with real seeds
    rev = nbl.reverse_bits(x)
    lk = nbl.laine_karras(x, seeds)
    owen = nbl.owen_scramble(x, seeds)
    u24 = nbl.unit24(x)
    assert u24.dtype == F32
    for k, (v, s) in enumerate(zip(x.tolist(), seeds.tolist())):
        assert int(rev[k]) == rbl.reverse_bits(v), (v,)
        assert int(lk[k]) == rbl.laine_karras(v, s), (v, s)
        assert int(owen[k]) == rbl.owen_scramble(v, s), (v, s)
        assert float(u24[k]) == rbl.unit24(v), (v,)
    assert np.array_equal(nbl.reverse_bits(rev), x)  # an involution
    assert np.array_equal(owen[seeds == 0], x[seeds == 0])
    assert np.count_nonzero(owen != x) > len(x) // 2
    # derived_seed: 0 exactly for p == 0
    idx = np.roll(x, 3)
    ds = nbl.derived_seed(seeds, idx, rbl.SOBOL_KEY)
    for k in range(0, len(x), 7):
        assert int(ds[k]) == rbl.derived_seed(int(seeds[k]), int(idx[k]), rbl.SOBOL_KEY)
    assert np.all((ds == 0) == (seeds == 0))


def test_sobol_bits_numpy_equal_reference():
    rng = np.random.default_rng(RNG_SEED + 1)
    g = _u32_inputs(1500, RNG_SEED + 2)
    dim = rng.integers(0, SOBOL_DIMS, len(g)).astype(U32)
    dim[:4] = [0, 1, SOBOL_DIMS - 2, SOBOL_DIMS - 1]
    dim[-4:] = [0, 1, SOBOL_DIMS - 1, SOBOL_DIMS - 1]
    got = nbl.sobol_bits(g, dim)
    for k in range(len(g)):
        assert int(got[k]) == rbl.sobol_bits(int(g[k]), int(dim[k])), (int(g[k]), int(dim[k]))
    # g = 2^k picks direction number k alone
    V = sequences.sobol_matrices()
    for d in (0, 1, SOBOL_DIMS - 1):
        assert np.array_equal(nbl.sobol_bits(U32(1) << np.arange(32, dtype=U32), U32(d)), V[d])


#: (name, shape arguments) of the direct tests: catalogue shapes and the extremes
DIRECT_CASES = [
    ("random", ()),
    ("jittered2d", (1, 1)), ("jittered2d", (1, 2)), ("jittered2d", (2, 3)), ("jittered2d", (3, 4)),
    ("jittered2d", (7, 5)), ("jittered2d", (4096, 7)), ("jittered2d", (4096, MAX_DIMS - 1)),
    ("cmj2d", (1, 1)), ("cmj2d", (1, 7)), ("cmj2d", (1, BIG_PRIME)), ("cmj2d", (3, 5)), ("cmj2d", (840, 858)),
    ("cmj2d", (4093, 4099)), ("cmj2d", (4096, 4096)), ("cmj2d", (2, 8388593)),
    *[("sobol02", (k,)) for k in (0, 1, 2, 5, 12, 23, 24)],
    ("halton", ()),
    ("sobol", ()),
]


def _direct_inputs(name, shape, n, rng, p_mode):
    """Sample indices, dimensions and seeds for a direct test: the first and last
    samples and dimensions, random ones; p all 0, all random, or mixed."""
    if name == "random":
        N, D = 2**32, MAX_DIMS
    elif name == "jittered2d":
        N, D = shape[0] ** 2, shape[1]
    elif name == "cmj2d":
        N, D = shape[0] * shape[1], 9
    elif name == "sobol02":
        N, D = 1 << shape[0], 9
    else:
        N, D = MAX_SPP, MAX_DIMS_OF[name]
    i = rng.integers(0, N, n, dtype=np.uint64).astype(U32)
    j = rng.integers(0, D, n).astype(U32)
    i[:4] = [0, N - 1, N - 1, min(1, N - 1)]
    j[:4] = [0, D - 1, 0, min(1, D - 1)]
    j[4:8] = [max(D - 2, 0), max(D - 3, 0), D - 1, D - 1]
    if name == "halton":  # bases 2, 3, 65519, 65521 more often
        j[8: n // 2: 2] = rng.choice([0, 1, 6540, 6541], len(j[8: n // 2: 2]))
    if p_mode == "zero":
        p = np.zeros(n, U32)
    else:
        p = rng.integers(0, 2**32, n, dtype=np.uint64).astype(U32)
        p[:2] = [1, U32_MAX]
        if p_mode == "mixed":
            p[::3] = 0
    return i, j, p


@pytest.mark.parametrize("p_mode", ["zero", "random", "mixed"])
@pytest.mark.parametrize("name, shape", DIRECT_CASES, ids=[n + "".join(f"-{v}" for v in s) for n, s in DIRECT_CASES])
def test_direct_functions_numpy_equal_reference(name, shape, p_mode):
    """pyoa._numpy.baselines vs pyoa.reference.baselines, element by element, with
    p = 0 (the unscrambled sets), random p, and both in one call."""
    rng = np.random.default_rng(zlib.crc32(repr((name, shape, p_mode)).encode()))
    n = 40 if name == "halton" else 120
    i, j, p = _direct_inputs(name, shape, n, rng, p_mode)
    for jitter in ([1.0, MANY_BITS[0], 0.0] if name in JITTERED else [1.0]):
        got = np_values(name, i, j, shape, p, jitter)
        assert got.dtype == F32 and got.shape == i.shape
        want = np.array([ref_value(name, int(a), int(b), shape, int(c), jitter) for a, b, c in zip(i, j, p)],
                        dtype=F32)
        assert_same_bits(got, want, f"numpy vs reference, J={jitter}")
        assert_value_rules(name, got)


@pytest.mark.parametrize("name, spp, dims", [("jittered2d", 16, 5), ("cmj2d", 12, 5), ("sobol02", 16, 5),
                                             ("halton", 30, 6542), ("sobol", 32, 21201)])
def test_unscrambled_sets_whole(name, spp, dims):
    """p = 0, every sample of a few dimensions, as NumPy arrays (broadcast (N, 1) x
    (1, d)) vs the reference; with a few values known by hand."""
    shape = shape_of(name, spp, dims)
    d = _special_dims(name, dims)
    i = np.arange(spp, dtype=U32)[:, None]
    J = 0.0 if name in JITTERED else 1.0
    got = np_values(name, i, np.array(d, U32)[None, :], shape, U32(0), J)
    want = np.array([[ref_value(name, a, b, shape, 0, J) for b in d] for a in range(spp)], dtype=F32)
    assert_same_bits(got, want, "p = 0")
    if name == "jittered2d":  # cell centres in natural order; the lone last dimension has N strata
        m = shape[0]
        assert np.array_equal(got[:, 0], ((np.arange(spp) % m + 0.5) / m).astype(F32))
        assert np.array_equal(got[:, 1], ((np.arange(spp) // m + 0.5) / m).astype(F32))
        assert np.array_equal(got[:, d.index(dims - 1)], ((np.arange(spp) + 0.5) / spp).astype(F32))
    if name == "halton":  # the plain radical inverse in base 2 and 3
        assert got[:8, 0].tolist() == [0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875]
        assert got[:4, 1].tolist() == [0, (2**24 // 3) * 2**-24, (2**25 // 3) * 2**-24, (2**24 // 9) * 2**-24]
    if name == "sobol":  # dimension 0 in Gray-code order is van der Corput of i ^ (i >> 1)
        gray = [k ^ (k >> 1) for k in range(8)]
        assert got[:8, 0].tolist() == [int(f"{g:03b}"[::-1], 2) / 8 for g in gray]


# ----------------------------------------------------------------------------- the kernels' functions directly

TEST_KERNELS = r"""
__kernel void tb_helpers(__global const uint *x, __global const uint *seed, __global uint *rev, __global uint *lk,
                         __global uint *owen, __global float *u24)
{ size_t g = get_global_id(0); rev[g] = pyoa_reverse_bits(x[g]); lk[g] = pyoa_laine_karras(x[g], seed[g]);
  owen[g] = pyoa_owen_scramble(x[g], seed[g]); u24[g] = pyoa_unit24(x[g]); }

__kernel void tb_sobol_bits(__global const uint *g, __global const uint *dim, __global const uint *V,
                            __global uint *out)
{ size_t k = get_global_id(0); out[k] = pyoa_sobol_bits(g[k], V + 32u * dim[k]); }

__kernel void tb_sample(__global const uint *i, __global const uint *j, __global const uint *p, const uint which,
                        const uint a, const uint b, const float J, __global const uint *table, __global float *out)
{
    size_t g = get_global_id(0);
    uint ii = i[g], jj = j[g], pp = p[g];
    float x;
    if (which == 0u)      x = pyoa_sample_random(ii, jj, pp);
    else if (which == 1u) x = pyoa_sample_jittered2d(ii, jj, a, b, pp, J);
    else if (which == 2u) x = pyoa_sample_cmj2d(ii, jj, a, b, pp, J);
    else if (which == 3u) x = pyoa_sample_sobol02(ii, jj, a, pp, table);
    else if (which == 4u) x = pyoa_sample_halton(ii, jj, pp, table);
    else                  x = pyoa_sample_sobol(ii, jj, pp, table);
    out[g] = x;
}
"""


@pytest.fixture(scope="module")
def harness(opencl):
    """Run a test kernel of TEST_KERNELS, built with pyoa's own source and options."""
    return kernel_runner(opencl, TEST_KERNELS)


@pytest.mark.opencl
def test_kernel_helpers_equal_numpy(harness):
    x = _u32_inputs(20000, RNG_SEED + 3)
    seeds = np.roll(x, 11)
    seeds[::5] = 0
    rev, lk, owen, u24 = harness("tb_helpers", [U32, U32, U32, F32], x, seeds, n=len(x))
    assert np.array_equal(rev, nbl.reverse_bits(x))
    assert np.array_equal(lk, nbl.laine_karras(x, seeds))
    assert np.array_equal(owen, nbl.owen_scramble(x, seeds))
    assert np.array_equal(owen[seeds == 0], x[seeds == 0])
    assert_same_bits(u24, nbl.unit24(x), "unit24")
    rng = np.random.default_rng(RNG_SEED + 4)
    dim = rng.integers(0, SOBOL_DIMS, len(x)).astype(U32)
    dim[:3] = [0, 1, SOBOL_DIMS - 1]
    got = harness("tb_sobol_bits", [U32], x, dim, np.ascontiguousarray(sequences.sobol_matrices()), n=len(x))
    assert np.array_equal(got, nbl.sobol_bits(x, dim))


KERNEL_CODE = {"random": 0, "jittered2d": 1, "cmj2d": 2, "sobol02": 3, "halton": 4, "sobol": 5}


@pytest.mark.opencl
@pytest.mark.parametrize("p_mode", ["zero", "mixed"])
@pytest.mark.parametrize("name, shape", DIRECT_CASES, ids=[n + "".join(f"-{v}" for v in s) for n, s in DIRECT_CASES])
def test_kernel_functions_equal_numpy(harness, name, shape, p_mode):
    """The kernels' sample_* functions with explicit p (p = 0 included, which no
    pixel seed gives) vs NumPy (equal to the reference above), on 4000 values."""
    rng = np.random.default_rng(zlib.crc32(repr((name, shape, p_mode, 1)).encode()))
    i, j, p = _direct_inputs(name, shape, 4000, rng, p_mode)
    table = {"halton": sequences.primes(), "sobol": sequences.sobol_matrices(),
             "sobol02": sequences.sobol_matrices()[:2]}.get(name, np.zeros(1, U32))
    a, b = (*shape, 0, 0)[:2]
    for jitter in ([1.0, MANY_BITS[0], 0.0] if name in JITTERED else [1.0]):
        got = harness("tb_sample", [F32], i, j, p, U32(KERNEL_CODE[name]), U32(a), U32(b), F32(jitter),
                      np.ascontiguousarray(table, dtype=U32), n=len(i))
        assert_same_bits(got, np_values(name, i, j, shape, p, jitter), f"kernel vs numpy, J={jitter}")
