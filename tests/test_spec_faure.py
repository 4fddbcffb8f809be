"""docs/spec.md sections 5.10 and 5.11: faure's end-to-end test vectors, as
the page states them, from every implementation."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import pyoa
from pyoa.reference.faure import faure
from pyoa.reference.hashes import pixel_seed

SPEC = Path(__file__).resolve().parent.parent / "docs" / "spec.md"
ROW = re.compile(r"^\| `faure` b = (\d+)[^|]*\| (\d+) \| (\d+) \| `0x([0-9a-f]{8})` \|$", re.MULTILINE)
VECTORS = [tuple(int(g, 16) if k == 3 else int(g) for k, g in enumerate(m.groups()))
           for m in ROW.finditer(SPEC.read_text())]


def test_the_page_has_faure_vectors():
    assert len(VECTORS) >= 3 and any(j >= b for b, _, j, _ in VECTORS)  # one past the first block


@pytest.mark.parametrize("vector", VECTORS, ids=lambda v: f"b{v[0]}-i{v[1]}-j{v[2]}")
def test_spec_vectors(vector, backend):
    """Pixel 3 of a sampler with seed 7 (p = pixel_seed(7, 3) = 0x00bb1fa5)."""
    b, i, j, want = vector
    assert pixel_seed(7, 3) == 0x00BB1FA5
    assert np.float32(faure(i, j, b, 12, pixel_seed(7, 3))).view(np.uint32) == want
    smp = pyoa.sampler("faure", spp=1 << 12, dims=j + 1, seed=7, base=b, backend=backend)
    assert smp.generate(pixels=[3], samples=[i], dims=[j]).view(np.uint32)[0, 0, 0] == want
