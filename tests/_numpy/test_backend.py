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
