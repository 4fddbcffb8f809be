"""Sampler.to_dask: a lazy Dask array with generate's bits, whatever the chunking.

Equality with generate bit for bit for several samplers, chunkings and index
arguments; laziness (no generate call before compute, one per chunk after);
the graph (small, pickles, deterministic names); errors raised at to_dask
time; and one compute on a two-process distributed cluster.
"""

from __future__ import annotations

import pickle
import sys

import numpy as np
import pytest

import pyoa
from pyoa.samplers import Sampler

da = pytest.importorskip("dask.array")
cloudpickle = pytest.importorskip("cloudpickle")

U32_MAX = 2**32 - 1

#: name -> keyword arguments of pyoa.sampler
SAMPLERS = {
    "bose": {"spp": 49, "dims": 9},
    "bush": {"spp": 27, "dims": 7, "strength": 3},
    "sobol": {"spp": 32, "dims": 6},
    "random": {"spp": 10, "dims": 5},
    "faure": {"spp": 25, "dims": 6},
    "zsobol": {"spp": 16, "dims": 5, "resolution": (8, 6)},
    "zfaure": {"spp": 25, "dims": 7, "resolution": (8, 6)},
    "cmjnd": {"spp": 27, "dims": 7, "strength": 3},
}

CHUNKS = {
    "1-pixels": (1, -1, -1),
    "1-samples": (-1, 1, -1),
    "1-dims": (-1, -1, 1),
    "uneven": (3, 5, 2),
    "auto": "auto",
    "dict": {1: 7},
}


def make(name, backend="numpy", **extra):
    return pyoa.sampler(name, seed=11, backend=backend, **SAMPLERS[name], **extra)


def scattered_pixels(smp) -> list[int]:
    """Scattered pixel indices, unsorted and with a repeat, incl. the last valid one (2**32-1 without a resolution)."""
    last = smp.n_pixels - 1
    return [last, 0, 17, last // 3, 5, last - 1, 17, last // 2]


def assert_bits(arr, expected):
    got = np.asarray(arr)
    assert got.dtype == np.float32 and got.shape == expected.shape
    assert np.array_equal(got.view(np.uint32), expected.view(np.uint32))


@pytest.mark.parametrize("chunks", list(CHUNKS.values()), ids=list(CHUNKS))
@pytest.mark.parametrize("pixels", ["range", "scattered"])
@pytest.mark.parametrize("name", list(SAMPLERS))
def test_same_bits_as_generate(name, pixels, chunks):
    smp = make(name)
    pix = range(3, 14) if pixels == "range" else scattered_pixels(smp)
    arr = smp.to_dask(pixels=pix, chunks=chunks)
    expected = smp.generate(pixels=pix)
    assert isinstance(arr, da.Array)
    assert arr.dtype == np.float32 and arr.shape == expected.shape
    assert_bits(arr.compute(), expected)


@pytest.mark.parametrize("name", list(SAMPLERS))
def test_subsets_of_samples_and_dims(name):
    smp = make(name)
    samples = range(smp.spp - 1, -1, -2)  # reversed, every other one
    dims = [smp.dims - 1, 0, 2, 2]
    pix = scattered_pixels(smp)
    expected = smp.generate(pixels=pix, samples=samples, dims=dims)
    for chunks in [(3, 5, 2), "auto", 1, {0: 2, 2: 1}]:
        arr = smp.to_dask(pix, samples=samples, dims=dims, chunks=chunks)
        assert arr.shape == (len(pix), len(samples), len(dims))
        assert_bits(arr.compute(), expected)
    # a NumPy index array, and generate's defaults
    assert_bits(smp.to_dask(np.array(pix, dtype=np.int64), samples=np.arange(3)).compute(),
                smp.generate(pix, samples=range(3)))
    assert_bits(smp.to_dask().compute(), smp.generate())


def test_shape_dtype_chunks_and_slicing():
    smp = make("bose")
    arr = smp.to_dask(pixels=range(U32_MAX - 9, U32_MAX + 1), chunks=(3, 5, 2))
    assert arr.shape == (10, 49, 9) and arr.dtype == np.float32
    assert arr.chunks == ((3, 3, 3, 1), (5,) * 9 + (4,), (2, 2, 2, 2, 1))
    assert isinstance(arr._meta, np.ndarray) and arr._meta.dtype == np.float32
    expected = smp.generate(pixels=range(U32_MAX - 9, U32_MAX + 1))
    assert_bits(arr[2:7, ::3, [8, 1]].compute(), expected[2:7, ::3][:, :, [8, 1]])
    # empty axes
    for kw, shape in [({"pixels": []}, (0, 49, 9)), ({"dims": []}, (1, 49, 0)), ({"samples": range(0)}, (1, 0, 9))]:
        for chunks in ["auto", (3, 5, 2)]:
            got = smp.to_dask(**kw, chunks=chunks)
            assert got.shape == shape and got.compute().shape == shape


def test_auto_chunks_whole_rows_and_chunk_size():
    import dask

    smp = make("bose")
    with dask.config.set({"array.chunk-size": "64KiB"}):
        arr = smp.to_dask(pixels=range(10_000))
    row = 49 * 9 * 4
    assert arr.chunks[1:] == ((49,), (9,))  # whole samples x dims rows
    assert max(arr.chunks[0]) * row <= 64 * 1024 and max(arr.chunks[0]) > 1
    # a row larger than the chunk size: split along samples, whole dims
    big = pyoa.sampler("random", spp=4096, dims=64, backend="numpy")
    with dask.config.set({"array.chunk-size": "64KiB"}):
        arr = big.to_dask(pixels=range(2))
    assert arr.chunks[0] == (1, 1) and arr.chunks[2] == (64,) and max(arr.chunks[1]) * 64 * 4 <= 64 * 1024
    # at most half of max_bytes, whatever dask's chunk size
    small = pyoa.sampler("bose", spp=49, dims=9, seed=11, backend="numpy", max_bytes="64KiB")
    arr = small.to_dask(pixels=range(10_000))
    assert max(arr.chunks[0]) * row <= 32 * 1024
    assert_bits(arr.compute(), smp.generate(pixels=range(10_000)))


def test_lazy_one_generate_call_per_chunk(monkeypatch):
    calls = []
    original = Sampler.generate

    def counting(self, *args, **kwargs):
        calls.append(args)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Sampler, "generate", counting)
    smp = make("sobol")
    arr = smp.to_dask(pixels=range(2**32 - 10**6, 2**32), chunks=(10**5, 8, 3))
    view = arr[5:20, 1:30, ::2].sum()
    assert calls == []  # building, slicing and reducing compute nothing
    assert arr.numblocks == (10, 4, 2)
    view.compute()
    assert len(calls) == 1 * 4 * 2  # only the chunks the slice touches, one call each
    calls.clear()
    small = smp.to_dask(pixels=range(7), chunks=(3, 8, 3))
    small.compute()
    assert len(calls) == small.npartitions == 3 * 4 * 2


def test_graph_is_small_deterministic_and_pickles():
    smp = make("bose")
    arr = smp.to_dask(pixels=range(10**9), chunks=(10**5, -1, -1))
    assert arr.npartitions == 10**4  # 176 GB of values, a graph of ranges
    small = smp.to_dask(pixels=range(10**4), chunks=(1000, -1, -1))
    # the graph holds parameters and index slices, no values (10**4 x 49 x 9 float32 = 17.6 MB)
    assert len(pickle.dumps(small)) < 50_000
    assert smp.to_dask(pixels=range(10)).name == make("bose").to_dask(pixels=range(10)).name
    assert smp.to_dask(pixels=range(10)).name != pyoa.sampler("bose", seed=12, spp=49, dims=9,
                                                                        backend="numpy").to_dask(pixels=range(10)).name
    assert smp.to_dask(pixels=range(10)).name != smp.to_dask(pixels=list(range(10))[::-1]).name
    assert smp.to_dask(pixels=range(10)).name.startswith("pyoa-bose-")
    expected = smp.generate(pixels=range(10**4))
    for dumps, loads in [(pickle.dumps, pickle.loads), (cloudpickle.dumps, cloudpickle.loads)]:
        assert_bits(loads(dumps(small)).compute(), expected)


@pytest.mark.opencl
def test_opencl_sampler_pickles_and_gives_the_same_bits():
    smp = pyoa.sampler("bose", spp=49, dims=9, seed=11, backend="opencl")
    for dumps, loads in [(pickle.dumps, pickle.loads), (cloudpickle.dumps, cloudpickle.loads)]:
        copy = loads(dumps(smp))
        assert copy.backend == "opencl" and copy is not smp
        arr = loads(dumps(smp.to_dask(pixels=scattered_pixels(smp), chunks=(3, 5, 2))))
        assert_bits(arr.compute(), make("bose").generate(pixels=scattered_pixels(smp)))


@pytest.mark.parametrize(("kwargs", "error"), [
    ({"pixels": [0, 2**32]}, ValueError),
    ({"pixels": [-1]}, ValueError),
    ({"pixels": range(2**32 - 1, 2**32 + 1)}, ValueError),
    ({"pixels": 5}, TypeError),
    ({"pixels": [1.5]}, TypeError),
    ({"pixels": {1, 2}}, TypeError),
    ({"pixels": [[1, 2]]}, ValueError),
    ({"samples": [49]}, ValueError),
    ({"dims": range(10)}, ValueError),
])
def test_bad_indices_fail_at_to_dask_time_with_generates_error(monkeypatch, kwargs, error):
    smp = make("bose")
    with pytest.raises(error) as from_generate:
        smp.generate(**kwargs)
    monkeypatch.setattr(Sampler, "generate", lambda *a, **k: pytest.fail("generate called"))
    with pytest.raises(error) as from_to_dask:
        smp.to_dask(**kwargs)
    assert str(from_to_dask.value) == str(from_generate.value)


def test_resolution_bounds_pixels():
    smp = make("zsobol")  # 8 x 6 image: pixels below 48
    assert_bits(smp.to_dask(pixels=[47]).compute(), smp.generate(pixels=[47]))
    with pytest.raises(ValueError, match=r"pixels must lie in \[0, 48\)"):
        smp.to_dask(pixels=[48])


def test_chunk_over_max_bytes_fails_at_once_but_the_array_may_be_larger():
    smp = pyoa.sampler("bose", spp=49, dims=9, backend="numpy", max_bytes="1MiB")
    with pytest.raises(ValueError, match="over the memory limit of 1.0 MiB; ask for smaller chunks"):
        smp.to_dask(pixels=range(10**4), chunks=-1)
    arr = smp.to_dask(pixels=range(10**4), chunks=(500, -1, -1))  # 17.6 MB in all, 0.9 MB per chunk
    assert arr.nbytes > smp.max_bytes
    assert_bits(arr[-3:].compute(), smp.generate(pixels=range(10**4 - 3, 10**4)))


def test_bad_chunks_are_dasks_errors():
    smp = make("bose")
    with pytest.raises(ValueError):
        smp.to_dask(pixels=range(10), chunks=((5, 4), -1, -1))  # does not add up to 10


def test_without_dask_an_import_error_names_the_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "dask", None)
    with pytest.raises(ImportError, match=r'pip install "dask\[distributed\]"'):
        make("bose").to_dask(pixels=range(4))


def test_distributed_cluster_gives_the_same_bits():
    distributed = pytest.importorskip("distributed")
    smp = make("bose")
    pix = [U32_MAX, 0, 12345, 2**31, 7, 99]
    arr = smp.to_dask(pixels=pix, samples=range(40), chunks=(2, 15, 4))
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1, dashboard_address=":0",
                                  timeout=15) as cluster, distributed.Client(cluster, timeout=15) as client:
        got = client.compute(arr).result(timeout=15)
        stored = client.persist(arr)
        distributed.wait(stored, timeout=15)
        on_workers = sum(len(keys) for keys in client.has_what().values())
    assert on_workers >= arr.npartitions  # the chunks live on the workers
    assert_bits(got, smp.generate(pixels=pix, samples=range(40)))


def test_to_zarr_round_trip(tmp_path):
    zarr = pytest.importorskip("zarr")
    smp = make("faure")
    arr = smp.to_dask(pixels=range(2**32 - 50, 2**32), chunks=(7, 10, -1))
    arr.to_zarr(str(tmp_path / "faure.zarr"))
    stored = zarr.open(str(tmp_path / "faure.zarr"), mode="r")
    assert stored.shape == arr.shape and stored.dtype == np.float32
    assert_bits(np.asarray(stored[:]), smp.generate(pixels=range(2**32 - 50, 2**32)))


def test_errors_in_generates_order():
    smp = make("bose")
    kwargs = {"pixels": [2**32], "samples": 5}  # an entry out of range, then an argument of the wrong kind
    with pytest.raises(TypeError) as from_generate:
        smp.generate(**kwargs)
    with pytest.raises(TypeError) as from_to_dask:
        smp.to_dask(**kwargs)
    assert str(from_to_dask.value) == str(from_generate.value)
