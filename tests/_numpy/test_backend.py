"""The NumPy backend (pyoa._numpy.backend): direct and table paths, chunks."""

from __future__ import annotations

import numpy as np
import pytest

import pyoa
import pyoa._numpy.backend as nb
from tests.helpers import assert_same_bits, reference_block


@pytest.mark.parametrize("offset", ["cmj", "centered", "j", "mj"])
def test_table_path_and_direct_path_agree(offset):
    smp = pyoa.sampler("cmjnd", spp=64, dims=6, strength=3, seed=4, offset=offset, backend="numpy")
    full = smp.generate(pixels=[0, 1])  # 64 samples per pixel: tables for cmj/centered
    one_by_one = np.concatenate([smp.generate(pixels=[0, 1], samples=[i]) for i in range(64)], axis=1)
    assert_same_bits(full, one_by_one)
    req = smp._request([0], range(64), None)
    assert req.tables_pay_off(*req.rectangles(0, 64)) == (offset in ("cmj", "centered"))
    req = smp._request([0], [5], None)
    assert not req.tables_pay_off(*req.rectangles(0, 1))
    assert_same_bits(full[:, ::9], reference_block(smp, [0, 1], range(0, 64, 9), range(6)))


def test_table_work_is_bounded_by_the_values_computed(monkeypatch):
    """The table path exists to do less permutation work than computing every value
    (two permutes per value). When a pixel's samples are split over many chunks,
    each chunk must not rebuild the whole per-pixel table: with cmjnd s=2, t=12
    (M = 2048), 8 dims, all 4096 samples of one pixel in 256-row chunks, the
    tables would cost 16 x 8 x 2050 permutes, 8x the 32768 values."""
    counted = []
    real = nb.permute

    def counting(i, l, p):
        counted.append(np.broadcast(np.asarray(i), np.asarray(p)).size)
        return real(i, l, p)

    monkeypatch.setattr(nb, "permute", counting)
    monkeypatch.setattr(nb, "CHUNK_VALUES", 8 * 256)
    smp = pyoa.sampler("cmjnd", spp=2**12, dims=8, strength=12, offset="cmj", backend="numpy")
    x = smp.generate(pixels=[0])
    n_values = x.size
    table_lanes = sum(counted)
    assert table_lanes <= 2 * n_values, (
        f"table path computed {table_lanes} permutation lanes for {n_values} values "
        f"({table_lanes / n_values:.1f} per value; computing each value directly costs 2)"
    )


def test_rows_per_chunk():
    b = nb.NumpyBackend()
    assert b.rows_per_chunk(1) == nb.CHUNK_VALUES
    assert b.rows_per_chunk(nb.CHUNK_VALUES * 3) == 1
    assert b.rows_per_chunk(0) >= 1


LATER_BLOCK_CASES = [
    pytest.param("bose", dict(spp=25), id="bose-s5"),
    pytest.param("bush", dict(spp=27, strength=3), id="bush-s3-t3"),
    pytest.param("cmjnd", dict(spp=27, strength=3), id="cmjnd-s3-t3"),
    pytest.param("addelman-kempthorne", dict(spp=50), id="addelman-kempthorne-q5"),
    pytest.param("bose-bush", dict(spp=32), id="bose-bush-s4"),
]


@pytest.mark.parametrize("offset", ["cmj", "centered"])
@pytest.mark.parametrize("name, options", LATER_BLOCK_CASES)
def test_later_blocks_on_the_table_path(monkeypatch, name, options, offset):
    """Dimensions past block 0 on the table path, bit for bit against the
    direct path and the pure-Python reference. Whole pixels (every sample, in
    order or not) take row space: the block's values at every row of its
    copy, gathered at each pixel's rows; a run of fewer than N samples
    computes the cells at its own rows. Dimensions that skip blocks (0, 30,
    31) and that interleave blocks (not a run of the request's dimensions)
    are both written where they belong."""
    from pyoa.catalogue.request import Request

    smp = pyoa.sampler(name, dims=40, seed=3, offset=offset, backend="numpy", **options)
    N, B = smp.spp, smp.block_dims
    stride = smp._request([0], None, None).table_stride
    assert stride < N  # else no run of samples takes the table path's per-row cells
    pixels = [0, 7, 2**32 - 1]
    sample_sets = {"whole": range(N), "reversed": range(N - 1, -1, -1), "subset": range(2, 2 + (stride + N) // 2)}
    dim_sets = {"all": range(40), "skipping": [0, 30, 31], "interleaved": [2 * B + 1, 0, B, 1, 39, B + 1]}
    calls = []
    real = nb.NumpyBackend._values_at

    def spy(req, rows, aij, u, q):
        calls.append(rows.ndim == 1 and len(rows) == N)  # a run of every row: row space (or block 0)
        return real(req, rows, aij, u, q)

    monkeypatch.setattr(nb.NumpyBackend, "_values_at", staticmethod(spy))
    tabled = {}
    for sk, samples in sample_sets.items():
        for dk, dims in dim_sets.items():
            req = smp._request(pixels, samples, dims)
            assert all(req.tables_pay_off(rect) for rect in req.rectangles(0, req.n_rows))
            calls.clear()
            tabled[sk, dk] = smp.generate(pixels=pixels, samples=samples, dims=dims)
            # whole pixels never compute cells per (pixel, sample, dimension); a subset does so for its later blocks
            assert all(calls) == (sk != "subset"), (sk, dk, calls)
    # Chunks of 1.5 pixels: whole pixels in row space beside the heads and tails of split ones.
    monkeypatch.setattr(nb, "CHUNK_VALUES", 40 * (3 * N // 2))
    assert_same_bits(smp.generate(pixels=pixels), tabled["whole", "all"], "in chunks of 1.5 pixels")
    monkeypatch.setattr(Request, "tables_pay_off", lambda self, rect: False)
    for (sk, dk), got in tabled.items():
        direct = smp.generate(pixels=pixels, samples=sample_sets[sk], dims=dim_sets[dk])
        assert_same_bits(got, direct, f"{sk} samples, {dk} dims: table path vs direct path")
    for sk in ("reversed", "subset"):
        samples = list(sample_sets[sk])[::4]
        at = [list(sample_sets[sk]).index(i) for i in samples]
        assert_same_bits(tabled[sk, "skipping"][:, at], reference_block(smp, pixels, samples, dim_sets["skipping"]),
                         f"{sk} samples vs reference")
