"""docs/spec.md section 6: the block rule's test vectors, as the page states
them, from every implementation (reference, NumPy, OpenCL, Dr.Jit), and the
row each one reads."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import pyoa
from pyoa import catalogue
from pyoa.reference import hashes as rh

SPEC = Path(__file__).resolve().parent.parent / "docs" / "spec.md"
SECTION = SPEC.read_text().split("## 6. ", 1)[1].split("## 7. ", 1)[0]
ROW = re.compile(r"^\| `([a-z-]+)` ([^|]*?) \| `(\w+)` \| (\d+) \| (\d+) \| (\d+), (\d+) \| (\d+) \| `0x([0-9a-f]{8})` \|$",
                 re.MULTILINE)
VECTORS = [m.groups() for m in ROW.finditer(SECTION)]
P = rh.pixel_seed(7, 3)
#: the page's parameter text -> the sampler's keywords
PARAMS = {"s = 11": dict(spp=121), "s = 8 (GF(8))": dict(spp=64), "s = 5, t = 3": dict(spp=125, strength=3),
          "s = 4, t = 3": dict(spp=64, strength=3), "q = 3": dict(spp=18), "s = 2": dict(spp=8)}


def test_the_page_has_every_construction_and_offset():
    got = {(name, params, offset, int(block)) for name, params, offset, _, _, block, *_ in VECTORS}
    names = {n for n, *_ in VECTORS}
    assert names == set(catalogue.names("oa")), names
    for name, params, *_ in VECTORS:
        for offset in ("cmj", "mj", "j", "centered"):
            assert {(name, params, offset, 1), (name, params, offset, 2)} <= got


def vector_id(v):
    return f"{v[0]}-{v[1].replace(' ', '')}-{v[2]}-i{v[3]}-j{v[4]}"


@pytest.mark.parametrize("vector", VECTORS, ids=vector_id)
def test_spec_vectors(vector, backend):
    name, params, offset, i, j, block, col, row, bits = vector
    i, j, block, col, row, want = int(i), int(j), int(block), int(col), int(row), int(bits, 16)
    assert rh.pixel_seed(7, 3) == 0x00BB1FA5
    smp = pyoa.sampler(name, **PARAMS[params], dims=j + 1, seed=7, offset=offset, backend=backend)
    B, N = smp.block_dims, smp.spp
    assert (j // B, j % B) == (block, col)
    assert rh.locate(P, i, j, B, N) == (rh.block_seed(P, block), row, col)
    assert np.float32(smp.value(3, i, j)).view(np.uint32) == want
    assert smp.generate(pixels=[3], samples=[i], dims=[j]).view(np.uint32)[0, 0, 0] == want
    # the whole pixel, so that the table and vector paths run too
    assert smp.generate(pixels=[3]).view(np.uint32)[0, i, j] == want


def test_spec_vectors_drjit():
    from .mitsuba_support import need

    _drjit = need("pyoa._drjit")
    from drjit.llvm import UInt32

    for name, params, offset, i, j, *_, bits in VECTORS:
        smp = pyoa.sampler(name, **PARAMS[params], dims=int(j) + 1, seed=7, offset=offset)
        got = _drjit.evaluate(name, UInt32([int(i)]), UInt32([int(j)]), smp.params, 7, UInt32([3]), offset, 1.0)
        assert np.asarray(got).view(np.uint32)[0] == int(bits, 16), (name, params, offset, i, j)


def test_hash_vectors():
    assert rh.block_order_seed(0x12345678, 0, 121) == 0
    assert rh.block_order_seed(0x12345678, 1, 121) == 2197909557
    assert rh.block_row(5, 121, 2197909557) == 102
    assert rh.block_order_seed(0x12345678, 2, 16) == 4187562215
    assert rh.block_row(5, 16, 4187562215) == 4
    assert all(rh.block_row(i, 121, 0) == i for i in range(121))


def test_the_limit_example():
    """Section 6's limit: a block whose seed equals block 0's reads its values
    in another order, no longer the same bits."""
    p = rh.pixel_seed(0, 362237)
    assert rh.block_seed(p, 12684) == p
    smp = pyoa.sampler("cmjnd", spp=16, strength=1, dims=12685, backend="numpy")
    x = smp.generate(pixels=[362237], dims=[0, 12684])[0]
    assert sorted(x[:, 0]) == sorted(x[:, 1]) and not np.array_equal(x[:, 0], x[:, 1])
    assert [rh.locate(p, i, 12684, 1, 16)[1] for i in range(8)] == [6, 12, 8, 2, 3, 15, 9, 13]
    assert np.array_equal(x[:, 1], x[[rh.locate(p, i, 12684, 1, 16)[1] for i in range(16)], 0])
