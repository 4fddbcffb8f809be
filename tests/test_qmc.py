"""pyoa.qmc.OrthogonalArray: SciPy's QMCEngine behaviours (after scipy's own
``QMCEngineTests``), the array-by-array layout of the sequence, and the
stratification of one array."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from numpy.testing import assert_array_equal
from scipy.integrate import qmc_quad
from scipy.stats import qmc

import pyoa
import pyoa.qmc
from pyoa.qmc import OrthogonalArray

SEED = 170382760648021597650530316304495310428  # scipy's QMCEngineTests seed


def engine(d=3, **kw):
    kw.setdefault("spp", 49)
    if "seed" not in kw:
        kw.setdefault("rng", SEED)
    return OrthogonalArray(d, **kw)


# --------------------------------------------------------------------------- QMCEngine behaviours

def test_is_a_qmc_engine():
    eng = engine()
    assert isinstance(eng, qmc.QMCEngine)
    assert (eng.d, eng.spp, eng.sampler_name, eng.s, eng.strength, eng.block_dims) == (3, 49, "bose", 7, 2, 8)
    assert eng.maxn == 49 * 2**32
    assert "spp=49" in repr(eng) and "bose" in repr(eng)


@pytest.mark.parametrize("name,spp,d", [("bose", 49, 3), ("bose", 49, 20), ("bush", 125, 4),
                                        ("addelman-kempthorne", 18, 5), ("sobol", 64, 3), ("random", 7, 2)])
def test_bounds_shape_dtype(name, spp, d):
    eng = engine(d, sampler=name, spp=spp)
    sample = eng.random(3 * spp + 5)
    assert sample.shape == (3 * spp + 5, d)
    assert sample.dtype == np.float64
    assert np.all(sample >= 0) and np.all(sample < 1)
    assert eng.num_generated == 3 * spp + 5


def test_0sample_and_1sample():
    eng = engine(d=2)
    assert_array_equal(eng.random(0), np.empty((0, 2)))
    assert eng.num_generated == 0
    assert eng.random(1).shape == (1, 2)
    assert eng.random().shape == (1, 2)
    assert eng.num_generated == 2


def test_pieces_equal_one_call():
    ref = engine().random(5 * 49 + 3)
    eng = engine()
    sizes = [0, 1, 20, 28, 49, 0, 100, 1, 49]  # crosses array boundaries at odd places
    assert sum(sizes) == len(ref)
    got = np.concatenate([eng.random(n) for n in sizes])
    assert_array_equal(got, ref)
    assert eng.num_generated == len(ref)


def test_continuing():  # scipy's test_continuing
    ref = engine(d=2).random(n=8)
    eng = engine(d=2)
    eng.random(n=4)
    assert_array_equal(eng.random(n=4), ref[4:])


@pytest.mark.parametrize("rng", [SEED, lambda: np.random.default_rng(SEED), None])
def test_reset(rng):
    if callable(rng):
        rng = rng()
    eng = engine(rng=rng)
    ref = eng.random(n=130)  # three arrays, the last one partly
    assert eng.reset() is eng
    assert eng.num_generated == 0
    assert_array_equal(eng.random(n=130), ref)
    eng.reset()
    assert_array_equal(eng.random(n=1), ref[:1])  # array 0, point 0


@pytest.mark.parametrize("k", [0, 1, 4, 48, 49, 50, 100])
def test_fast_forward_equals_slicing(k):
    ref = engine().random(160)
    eng = engine()
    assert eng.fast_forward(k) is eng
    assert eng.num_generated == k
    assert_array_equal(eng.random(160 - k), ref[k:])
    assert eng.num_generated == 160


def test_fast_forward_alternating():  # scipy's test_fast_forward, second half
    ref = engine(d=2, spp=4).random(n=8)
    eng = engine(d=2, spp=4)
    even = []
    for i in range(8):
        if i % 2 == 0:
            even.append(eng.random())
        else:
            eng.fast_forward(1)
    assert_array_equal(np.concatenate(even), ref[::2])
    assert eng.num_generated == 8


def test_fast_forward_is_cheap_and_bounded():
    eng = engine(d=2, spp=4)
    eng.fast_forward(4 * 2**32 - 2)  # to the last pixel, without generating
    last = eng.random(2)
    ref = pyoa.sampler("bose", spp=4, dims=2, seed=eng.pyoa_seed).generate(pixels=[2**32 - 1], samples=[2, 3])[0]
    assert_array_equal(last, ref)
    with pytest.raises(ValueError, match=r"At most spp \* 2\*\*32"):
        eng.random(1)
    with pytest.raises(ValueError, match=r"At most spp \* 2\*\*32"):
        eng.fast_forward(1)


def test_reproducible_with_same_seed():
    ref = engine(rng=42).random(60)
    assert_array_equal(engine(rng=42).random(60), ref)
    assert_array_equal(engine(rng=np.random.default_rng(42)).random(60), engine(rng=np.random.default_rng(42)).random(60))
    assert engine(rng=42).pyoa_seed == engine(rng=42).pyoa_seed
    # the legacy keyword, as in SciPy 1.17 (an int is used as given, not spawned)
    assert_array_equal(engine(seed=42).random(60), engine(seed=42).random(60))
    assert_array_equal(engine(seed=np.random.RandomState(3)).random(5), engine(seed=np.random.RandomState(3)).random(5))


def test_different_seeds_differ():
    a, b = engine(rng=1), engine(rng=2)
    assert a.pyoa_seed != b.pyoa_seed
    assert not np.array_equal(a.random(49), b.random(49))
    assert not np.array_equal(engine().random(49), engine(rng=None).random(49))


def test_consume_prng_state():  # scipy's test_consume_prng_state
    rng = np.random.default_rng(0xA29CABB11CFDF44FF6CAC8BEC254C2A0)
    samples = [engine(rng=rng).random(4) for _ in range(3)]
    assert not np.array_equal(samples[0], samples[1])
    assert not np.array_equal(samples[0], samples[2])


def test_num_generated():
    eng = engine()
    eng.random(10)
    eng.fast_forward(45)
    eng.integers(5, n=3)
    assert eng.num_generated == 58
    eng.reset()
    assert eng.num_generated == 0


# --------------------------------------------------------------------------- the sequence is pyoa's arrays

@pytest.mark.parametrize("name,spp,d", [("bose", 49, 3), ("bose", 9, 11), ("sobol", 64, 3), ("halton", 10, 2)])
def test_arrays_are_pyoa_pixels(name, spp, d):
    eng = engine(d, sampler=name, spp=spp)
    got = eng.random(3 * spp - 7)  # arrays 0 and 1, and most of array 2
    smp = pyoa.sampler(name, spp=spp, dims=d, seed=eng.pyoa_seed)
    ref = smp.generate(pixels=range(3)).reshape(-1, d)[: 3 * spp - 7]
    assert ref.dtype == np.float32
    assert_array_equal(got, ref.astype(np.float64))
    # crossing from array 0 into array 1 in one call
    eng.reset().fast_forward(spp - 2)
    assert_array_equal(eng.random(4), ref[spp - 2: spp + 2])
    assert_array_equal(eng.pyoa_sampler.generate(pixels=[1]), smp.generate(pixels=[1]))


def test_many_full_arrays_in_one_call(monkeypatch):
    # the middle arrays are generated in chunks; force small chunks
    monkeypatch.setattr(pyoa.qmc, "_CHUNK_VALUES", 2 * 9 * 2)
    eng = engine(d=2, spp=9)
    got = eng.random(9 * 11 + 4)
    smp = pyoa.sampler("bose", spp=9, dims=2, seed=eng.pyoa_seed)
    assert_array_equal(got, smp.generate(pixels=range(12)).reshape(-1, 2)[: 9 * 11 + 4])


def test_backends_agree(backend):
    a = engine(d=5, backend=backend).random(120)
    b = engine(d=5, backend="numpy").random(120)
    assert_array_equal(a, b)


# --------------------------------------------------------------------------- stratification

def _one_per_cell(sample, dims, s):
    cells = np.floor(sample[:, dims] * s).astype(np.int64)
    return len({tuple(c) for c in cells}) == s ** len(dims) == len(sample)


def test_bose_array_is_strength_2():
    eng = engine(d=3, spp=49)
    for _ in range(3):  # arrays 0, 1 and 2, each an OA(49, 3, 7, 2)
        arr = eng.random_arrays(1)
        for pair in itertools.combinations(range(3), 2):
            assert _one_per_cell(arr, list(pair), 7), pair
        for j in range(3):  # cmj offsets: 1D Latin hypercube with 49 strata
            assert _one_per_cell(arr, [j], 49)


def test_bose_blocks():
    # s = 5: 6 dimensions per block; d = 14 spans three blocks
    arr = engine(d=14, spp=25).random(25)
    for block in ([0, 1, 2, 3, 4, 5], [6, 7, 8, 9, 10, 11], [12, 13]):
        for pair in itertools.combinations(block, 2):
            assert _one_per_cell(arr, list(pair), 5), pair
    for j in range(14):
        assert _one_per_cell(arr, [j], 25)


def test_bush_array_is_strength_3():
    eng = engine(d=4, sampler="bush", spp=125, strength=3)
    assert (eng.s, eng.strength) == (5, 3)
    arr = eng.random(125)
    for triple in itertools.combinations(range(4), 3):
        assert _one_per_cell(arr, list(triple), 5), triple


def test_partial_run_is_not_a_full_array():
    eng = engine(d=3, spp=49)
    eng.random(20)
    with pytest.raises(ValueError, match="random_arrays draws whole arrays"):
        eng.random_arrays(1)
    eng.fast_forward(29)
    assert eng.random_arrays(2).shape == (98, 3)


def test_sobol_array_is_a_net():
    eng = engine(d=3, sampler="sobol", spp=64)
    arr = eng.random(64)
    for j in range(3):
        assert _one_per_cell(arr, [j], 64)
    assert _one_per_cell(arr, [0, 1], 8)  # a (0, 6, 2)-net in its first two dimensions


def test_discrepancy_lower_than_random():
    eng = engine(d=3, spp=49)
    rng = np.random.default_rng(0)
    oa = [qmc.discrepancy(eng.random_arrays(1)) for _ in range(20)]
    mc = [qmc.discrepancy(rng.random((49, 3))) for _ in range(20)]
    assert np.mean(oa) < 0.5 * np.mean(mc)


# --------------------------------------------------------------------------- SciPy tooling

def test_scale_and_integers():
    eng = engine(d=3)
    sample = eng.random(49)
    scaled = qmc.scale(sample, [0, -1, 10], [1, 1, 20])
    assert np.all(scaled >= [0, -1, 10]) and np.all(scaled < [1, 1, 20])
    eng.reset()
    ints = eng.integers([-5, 0, 0], u_bounds=[7, 7, 1], n=49)
    assert ints.dtype == np.int64
    assert_array_equal(ints, np.floor(qmc.scale(sample, [-5, 0, 0], [7, 7, 1])).astype(np.int64))
    assert_array_equal(ints.min(axis=0), [-5, 0, 0])
    assert_array_equal(ints.max(axis=0), [6, 6, 0])


def test_optimization():
    eng = engine(d=2, spp=49, optimization="random-cd")
    sample = eng.random(49)
    assert sample.shape == (49, 2) and np.all((sample >= 0) & (sample < 1))
    with pytest.raises(ValueError, match="'toto' is not a valid optimization method"):
        engine(d=1, optimization="toto")


def test_qmc_quad():
    f = lambda x: np.prod(x, axis=0)  # noqa: E731 - integral 1/16 over [0, 1]^4
    res = qmc_quad(f, np.zeros(4), np.ones(4), qrng=engine(d=4, spp=121), n_points=121, n_estimates=8)
    assert abs(res.integral - 1 / 16) < 5 * res.standard_error + 1e-3
    again = qmc_quad(f, np.zeros(4), np.ones(4), qrng=engine(d=4, spp=121), n_points=121, n_estimates=8)
    assert res.integral == again.integral


# --------------------------------------------------------------------------- defaults and errors

@pytest.mark.parametrize("name,kw,spp", [("bose", {}, 121), ("sobol", {}, 128), ("bose-bush", {}, 128),
                                         ("addelman-kempthorne", {}, 98), ("bush", {"strength": 3}, 125),
                                         ("random", {}, 121)])
def test_default_spp(name, kw, spp):
    assert OrthogonalArray(3, sampler=name, rng=0, **kw).spp == spp


@pytest.mark.parametrize("d", [0, -1, 2.5, True, (2,), "3", 2**20 + 1])
def test_invalid_d(d):
    with pytest.raises(ValueError, match=r"d must be"):
        OrthogonalArray(d)


def test_invalid_arguments():
    with pytest.raises(ValueError, match=r"'nope' is not a valid sampler. It must be one of \['bose'"):
        OrthogonalArray(2, sampler="nope")
    with pytest.raises(ValueError, match=r"is not a valid sampler"):
        OrthogonalArray(2, sampler=3)
    with pytest.raises(ValueError, match=r"120 is not s\^2.*nearest: 81 \(s=9\), 121 \(s=11\)"):
        OrthogonalArray(2, spp=120)
    with pytest.raises(ValueError, match=r"sobol.*nearest"):
        OrthogonalArray(2, sampler="sobol", spp=100)
    with pytest.raises(TypeError, match="spp must be an integer"):
        OrthogonalArray(2, spp=49.0)
    with pytest.raises(ValueError, match="offset"):
        OrthogonalArray(2, sampler="sobol", spp=64, offset="cmj")
    with pytest.raises(ValueError, match="jitter"):
        OrthogonalArray(2, jitter=2.0)
    with pytest.raises(TypeError, match="Specify one of `rng` or `seed`"):
        OrthogonalArray(2, rng=1, seed=1)
    with pytest.raises(ValueError, match="cannot be used to seed"):
        OrthogonalArray(2, seed="abc")
    eng = engine()
    for bad in (-1, 1.5, True):
        with pytest.raises(ValueError, match="n must be a non-negative integer"):
            eng.random(bad)
        with pytest.raises(ValueError, match="n must be a non-negative integer"):
            eng.fast_forward(bad)
    with pytest.raises(ValueError, match="'u_bounds' and 'l_bounds' must be integers"):
        eng.integers(1, u_bounds=1.5)
    assert eng.num_generated == 0
