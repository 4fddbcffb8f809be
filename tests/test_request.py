"""Request.rectangles: how a range of rows is split for the table path."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

import pyoa


@st.composite
def row_ranges(draw):
    n_s = draw(st.integers(1, 40))
    n_pix = draw(st.integers(1, 6))
    row0 = draw(st.integers(0, n_s * n_pix - 1))
    row1 = draw(st.integers(row0 + 1, n_s * n_pix))
    return n_s, n_pix, row0, row1


@given(row_ranges())
def test_rectangles_tile_the_rows(case):
    n_s, n_pix, row0, row1 = case
    req = pyoa.sampler("random", spp=n_s, dims=2)._request(range(n_pix), None, None)
    rects = req.rectangles(row0, row1)
    assert 1 <= len(rects) <= 3  # head, whole pixels, tail
    assert rects[0].row0 == row0 and rects[-1].row1 == row1
    for a, b in zip(rects, rects[1:]):
        assert a.row1 == b.row0
    whole = [r for r in rects if r.n_k == n_s]
    assert len(whole) <= 1 or n_s == 1
    for r in rects:
        assert r.row1 > r.row0
        # rows map to exactly the rectangle's pixels x sample positions
        assert r.row0 == r.pix0 * n_s + r.k0 and r.row1 == (r.pix1 - 1) * n_s + r.k1
        assert r.n_pixels == 1 or (r.k0, r.k1) == (0, n_s)
        assert 0 <= r.k0 < r.k1 <= n_s


def test_table_path_needs_a_run_of_samples_as_long_as_a_table():
    smp = pyoa.sampler("bose", spp=121, dims=3)  # cmj: tables of 11 + 11 + 1 entries, stride 24
    req = smp._request([0, 1], None, None)
    assert (req.table_entries, req.table_stride) == (23, 24)
    head, whole = req.rectangles(121 - 24, 242)
    assert req.tables_pay_off(head) and req.tables_pay_off(whole)
    assert not req.tables_pay_off(req.rectangles(121 - 23, 121)[0])
    jit = pyoa.sampler("bose", spp=121, dims=3, offset="j")._request([0], None, None)
    assert not jit.tables_pay_off(jit.rectangles(0, 121)[0])
