"""The Dr.Jit implementation (:mod:`pyoa._drjit`) against the NumPy backend, bit for bit.

Driven by the catalogue like the other conformance suites: every entry with
a Dr.Jit implementation, on each of its ``test_cases()`` (smallest and
largest shapes, last sample, last dimension, the largest seeds and pixels),
every offset style, and on random parameters (hypothesis). Runs on Dr.Jit's
LLVM backend (``drjit.llvm``), the one Mitsuba's ``llvm_*`` variants use.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import pyoa
from pyoa import catalogue
from pyoa.reference.oa import OFFSETS

from .mitsuba_support import need

_drjit = need("pyoa._drjit")
import drjit as dr
from drjit.llvm import UInt32

SEEDS = (0, 1, 2**32 - 1)
PIXELS = np.array([0, 1, 7, 2**32 - 1], dtype=np.uint32)


def pixels_of(smp) -> np.ndarray:
    """:data:`PIXELS`, or for a sampler of an image (``zfaure``) its corners, the ends of its first
    two rows, a pixel in the middle and the last pixel: all of its grid's top digits."""
    if smp.resolution is None:
        return PIXELS
    w, h = smp.resolution
    picks = [0, 1, w - 1, w, 2 * w - 1, (h // 2) * w + w // 2, (h - 1) * w, h * w - 1]
    return np.unique(np.array([p for p in picks if p < w * h], dtype=np.uint32))


def offsets(name):
    return list(OFFSETS) if catalogue.get(name).family == "oa" else [None]


def drjit_values(smp, pixels, samples, dims) -> np.ndarray:
    """``smp``'s values at every (pixel, sample, dim) of the grids, from pyoa._drjit.evaluate."""
    P, I, J = np.meshgrid(np.arange(len(pixels)), np.arange(len(samples)), np.arange(len(dims)), indexing="ij")
    got = _drjit.evaluate(smp.name, UInt32(np.asarray(samples, np.uint32)[I.ravel()]),
                          UInt32(np.asarray(dims, np.uint32)[J.ravel()]), smp.params, smp.seed,
                          UInt32(np.asarray(pixels, np.uint32)[P.ravel()]),
                          smp.offset if catalogue.get(smp.name).family == "oa" else None, smp.jitter)
    return np.asarray(got).reshape(P.shape)


def numpy_values(smp, pixels, samples, dims) -> np.ndarray:
    return smp.generate(pixels=pixels, samples=np.asarray(samples, np.int64))[:, :, np.asarray(dims)]


def edges(n: int, k: int = 24) -> np.ndarray:
    """The first and last ``k`` of ``range(n)``."""
    return np.unique(np.r_[np.arange(min(n, k)), n - 1 - np.arange(min(n, k))])


def assert_same_bits(got, want, what):
    bad = got.view(np.uint32) != want.view(np.uint32)
    assert not bad.any(), f"{what}: {bad.sum()} of {bad.size} values differ, first at {np.argwhere(bad)[0]}"


CASES = [(name, case, off) for name in _drjit.SUPPORTED for case in catalogue.get(name).test_cases()
         for off in offsets(name)]


def test_supported_names_are_the_catalogue_entries_with_an_implementation():
    assert set(_drjit.SUPPORTED) >= set(catalogue.names("oa")) | {"faure", "zfaure", "random"}
    with pytest.raises(ValueError, match="no Dr.Jit implementation.*supported: bose"):
        _drjit.implementation("sobol")
    with pytest.raises(ValueError, match="unknown sampler|valid"):
        _drjit.implementation("nonsense")


@pytest.mark.parametrize("name,case,offset", CASES, ids=[f"{n}-{i}-{o}" for i, (n, _, o) in enumerate(CASES)])
@pytest.mark.parametrize("seed", SEEDS)
def test_drjit_equals_numpy_on_the_catalogue_cases(name, case, offset, seed):
    kw = dict(case)
    if offset is not None:
        kw["offset"] = offset
    smp = pyoa.sampler(name, seed=seed, backend="numpy", **kw)
    samples, dims, pixels = edges(smp.spp), edges(smp.dims, 20), pixels_of(smp)
    assert_same_bits(drjit_values(smp, pixels, samples, dims), numpy_values(smp, pixels, samples, dims),
                     f"{name} {kw} seed {seed}")


def test_zfaure_spec_vectors():
    """docs/spec.md section 5.12's vectors (read by tests/test_zfaure.py), from Dr.Jit: past the first
    block and past a 32-bit index."""
    from .test_zfaure import VECTORS

    assert VECTORS
    for b, N, W, H, px, seed, _z, i, j, want in VECTORS:
        smp = pyoa.sampler("zfaure", spp=N, dims=j + 1, resolution=(W, H), seed=seed, backend="numpy")
        got = _drjit.evaluate("zfaure", UInt32([i]), UInt32([j]), smp.params, seed, UInt32([px]))
        assert np.asarray(got).view(np.uint32)[0] == want, (b, N, W, H, px, seed, i, j)


def test_jitter_amounts_and_every_value_of_a_small_array():
    for jitter in (0.0, 0.25, 1.0):
        smp = pyoa.sampler("bose", spp=49, dims=20, seed=5, jitter=jitter, backend="numpy")
        assert_same_bits(drjit_values(smp, PIXELS, range(49), range(20)),
                         numpy_values(smp, PIXELS, range(49), range(20)), f"jitter {jitter}")


@pytest.mark.parametrize("s", [2, 3, 5, 7, 11, 13])
def test_bose_cells_of_a_prime_s_on_every_row_and_column(s):
    """Over a prime s the cell takes one remainder per entry (pyoa._arrays.oa.bose_cell);
    Dr.Jit's cells of every (row, column), the last column included, against the reference's."""
    from pyoa.reference import oa as reference_oa

    rows, cols = np.meshgrid(np.arange(s * s), np.arange(s + 1), indexing="ij")
    got = _drjit.oa.bose_cell(UInt32(rows.ravel().astype(np.uint32)), UInt32(cols.ravel().astype(np.uint32)), s)
    want = np.array([reference_oa.bose_cell(int(i), int(c), s) for i, c in zip(rows.ravel(), cols.ravel())]).T
    for g, w in zip(got, want):
        assert (np.asarray(g) == w).all()


def test_the_namespace_defines_every_operation():
    from pyoa import _arrays
    from pyoa._drjit import ops

    assert not [name for name in _arrays.OPERATIONS if not callable(getattr(ops, name, None))]


def test_the_namespace_agrees_with_numpys():
    """The operations whose Dr.Jit form differs from NumPy's: the power by bits, the fused
    loops (lanes stop after different numbers of steps, per loop), the table gather."""
    from pyoa._drjit import ops as dj
    from pyoa._numpy import ops as npo

    e = np.arange(32, dtype=np.uint32)
    for base in (2, 3, 13, 4093):
        assert (np.asarray(dj.power(base, UInt32(e))) == npo.power(base, e)).all()

    def countdown(n, step):
        return ((n, step), lambda n, step: n >= step, lambda n, step: (n - step, step))

    n = np.arange(200, dtype=np.uint32)
    steps = (np.uint32(3), np.uint32(41))
    want = npo.while_loops([countdown(n, k) for k in steps], "test")
    got = dj.while_loops([countdown(UInt32(n), UInt32(k)) for k in steps], "test")
    for (g, _), (w, _) in zip(got, want):
        assert (np.asarray(g) == w).all()
    table = np.arange(100, 150, dtype=np.uint32)
    idx = np.array([0, 49, 7, 7], dtype=np.uint32)
    assert (np.asarray(dj.gather(table, UInt32(idx))) == npo.gather(table, idx)).all()


@st.composite
def random_sampler(draw):
    name = draw(st.sampled_from(_drjit.SUPPORTED))
    entry = catalogue.get(name)
    dims = draw(st.integers(1, 64))
    if name == "faure":
        base = draw(st.sampled_from([2, 3, 5, 7, 11, 13, 31, 127, 4093]))
        spp = draw(st.integers(1, 4096))
        kw = dict(base=base)
    elif name == "zfaure":
        base = draw(st.sampled_from([2, 3, 5, 7, 11, 13, 31, 127]))
        spp = base ** draw(st.integers(2, max(2, int(np.log(4096) / np.log(base)))))  # b^m, m >= 2
        kw = dict(base=base, resolution=(draw(st.integers(1, 2000)), draw(st.integers(1, 2000))))
    else:
        choices = entry.choices(dims=dims)
        spp = draw(st.sampled_from([c.spp for c in choices[: min(len(choices), 60)]]))
        kw = {}
    if entry.family == "oa":
        kw["offset"] = draw(st.sampled_from(list(OFFSETS)))
        kw["jitter"] = draw(st.sampled_from([0.0, 0.5, 1.0]))
    seed = draw(st.integers(0, 2**32 - 1))
    return pyoa.sampler(name, spp=spp, dims=dims, seed=seed, backend="numpy", **kw)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(smp=random_sampler(), pixel=st.integers(0, 2**32 - 1))
def test_drjit_equals_numpy_on_random_parameters(smp, pixel):
    pixels = (np.array([pixel, pixel ^ 1], dtype=np.uint64) % smp.n_pixels).astype(np.uint32)  # in the image
    samples, dims = edges(smp.spp, 12), edges(smp.dims, 12)
    assert_same_bits(drjit_values(smp, pixels, samples, dims), numpy_values(smp, pixels, samples, dims),
                     repr(smp))


def test_division_is_correctly_rounded():
    """Dr.Jit rewrites ``x / literal`` as a multiply by the reciprocal; pyoa's floats must not."""
    from pyoa._drjit.ops import divide

    x = np.float32(np.random.default_rng(0).random(50_000) * 7)
    F = dr.float32_array_t(UInt32)
    assert (np.asarray(divide(F(x), 7)) == x / np.float32(7)).all()


def test_evaluate_needs_an_array():
    smp = pyoa.sampler("bose", spp=4, dims=2, backend="numpy")
    with pytest.raises(TypeError, match="Dr.Jit UInt32 array"):
        _drjit.evaluate("bose", 0, 0, smp.params, 0, 0)
