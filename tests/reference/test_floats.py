"""docs/spec.md section 7: the float32 rules of the reference (pyoa.reference.floats)."""

from __future__ import annotations

import struct
from fractions import Fraction

import numpy as np
import pytest

from pyoa._numpy import floats as nf
from pyoa.reference import floats as rf


def bits(x: float) -> int:
    return struct.unpack("<I", struct.pack("<f", x))[0]


def test_constants():
    assert bits(rf.UNIT_SCALE) == 0x2F7FFFFE
    assert rf.UNIT_SCALE == (1 - 2**-23) * 2**-32
    assert bits(rf.ONE_MINUS_ULP) == 0x3F7FFFFF
    assert rf.ONE_MINUS_ULP == 1 - 2**-24


@pytest.mark.parametrize("s, M", [(2, 2), (3, 3), (3, 9), (13, 13), (2, 2**23), (4093, 4093), (4096, 4096)])
def test_sample_value_clamps_to_largest_float_below_one(s, M):
    """stratum s-1, sub M-1 and a jitter just below 1: the float32 result rounds to
    1.0 and must become 0x3f7fffff, in the reference and in NumPy."""
    jit = rf.ONE_MINUS_ULP
    exact = ((s - 1) + ((M - 1) + jit) / M) / s
    assert exact < 1.0  # the true value is below 1: only rounding reaches 1.0
    got = rf.sample_value(s - 1, M - 1, jit, M, s)
    assert bits(got) == 0x3F7FFFFF
    got_np = nf.sample_value(np.array([s - 1], np.uint32), np.float32(M - 1), np.array([jit], np.float32), M, s)
    assert got_np.dtype == np.float32 and got_np.view(np.uint32)[0] == 0x3F7FFFFF


def exact_floor(c: int, n: int) -> int:
    """Bits of the smallest float32 >= c/n, found by bisection over the bit
    patterns with exact rational comparisons: an oracle that shares no code
    or reasoning with cell_floor's single rounding step."""
    lo, hi = 0, 0x3F800000  # bits of 0.0 and 1.0; float32 order = bit order for x >= 0
    while lo < hi:
        mid = (lo + hi) // 2
        if Fraction(struct.unpack("<f", struct.pack("<I", mid))[0]) >= Fraction(c, n):
            hi = mid
        else:
            lo = mid + 1
    return lo


def cell_cases():
    """(c, n) pairs with n <= 2**24: the ends of [0, n], powers of two (edges
    that are floats themselves), the largest n of every construction, and
    random ones."""
    rng = np.random.default_rng(11)
    ns = [1, 2, 3, 7, 121, 2**12, 16129, 2**23, 2**24 - 1, 2**24, 4093**2, 2 * 2887**2, 8**3 * 8, 5**4 * 5]
    ns += [int(v) for v in rng.integers(1, 2**24 + 1, 40)]
    for n in ns:
        for c in {0, 1, n // 2, n - 1, n, *(int(v) for v in rng.integers(0, n + 1, 6))}:
            yield c, n


def test_cell_floor_is_the_smallest_float_at_or_above_the_edge():
    cases = list(cell_cases())
    for c, n in cases:
        assert bits(rf.cell_floor(c, n)) == exact_floor(c, n), (c, n)
    c = np.array([c for c, _ in cases], np.uint32)
    n = np.array([n for _, n in cases], np.uint32)
    want = np.array([exact_floor(int(a), int(b)) for a, b in zip(c, n)], np.uint32)
    np.testing.assert_array_equal(nf.cell_floor(c, n).view(np.uint32), want)


def test_cell_clamp_moves_only_values_outside_their_cell():
    """Every float32 within 4 units in the last place of both edges of a cell:
    inside ones keep their bits, outside ones go to the nearest float32
    inside (checked with exact rationals), in the reference and NumPy."""
    for c, n in cell_cases():
        if c == n:
            continue
        lo, hi = exact_floor(c, n), exact_floor(c + 1, n) - 1
        xs = [b for e in (lo, hi) for b in range(max(e - 4, 0), min(e + 5, 0x3F800000))]
        got_np = nf.cell_clamp(np.array(xs, np.uint32).view(np.float32), np.uint32(c), np.uint32(n)).view(np.uint32)
        for b, g_np in zip(xs, got_np):
            x = Fraction(struct.unpack("<f", struct.pack("<I", b))[0])
            want = lo if x < Fraction(c, n) else hi if x >= Fraction(c + 1, n) else b
            got = bits(rf.cell_clamp(struct.unpack("<f", struct.pack("<I", b))[0], c, n))
            assert got == want == int(g_np), (c, n, hex(b))


def test_sample_value_operation_order():
    """(stratum + (sub + jitter) / M) / s, each step rounded to float32 (numpy
    float32 scalars step by step), then clamped into the fine cell decided with
    exact rationals, for random inputs with N = s * M <= 2**24."""
    rng = np.random.default_rng(5)
    f = np.float32
    moved = 0
    for _ in range(3000):
        s = int(rng.integers(2, 5000))
        M = int(rng.integers(1, min(5000, 2**24 // s) + 1))
        stratum = int(rng.integers(0, s))
        sub = int(rng.integers(0, M))
        # jitters near 0 and 1 are the ones that cross an edge
        jit = float(f(rng.choice([rng.random(), 1 - rng.random() * 2**-20, rng.random() * 2**-20])))
        x = (f(stratum) + (f(sub) + f(jit)) / f(M)) / f(s)
        c, N = stratum * M + sub, s * M
        want = int(f(x).view(np.uint32))
        if Fraction(float(x)) >= Fraction(c + 1, N):
            want = exact_floor(c + 1, N) - 1
        elif Fraction(float(x)) < Fraction(c, N):
            want = exact_floor(c, N)
        moved += want != int(f(x).view(np.uint32))
        assert bits(rf.sample_value(stratum, float(sub), jit, M, s)) == want
        got_np = nf.sample_value(np.array([stratum], np.uint32), f(sub), np.array([jit], f), M, s)
        assert int(got_np.view(np.uint32)[0]) == want
    assert moved > 0  # the jitters near the edges did reach the clamp


def test_centered_even_M_is_clamped_into_its_coarse_stratum():
    """sub = (M-1)/2 is a half-integer for even M: no fine cell, the coarse one."""
    for s, M in [(2, 2), (11, 4), (4093, 4096), (2, 2**23)]:
        jit = rf.ONE_MINUS_ULP
        x = rf.sample_value(s - 1, (M - 1) / 2, jit, M, s)
        assert Fraction(s - 1, s) <= Fraction(x) < 1
        got_np = nf.sample_value(np.array([s - 1], np.uint32), np.float32((M - 1) / 2), np.array([jit], np.float32), M, s)
        assert bits(x) == int(got_np.view(np.uint32)[0])


def test_jitter_value_two_roundings():
    rng = np.random.default_rng(6)
    f = np.float32
    for _ in range(3000):
        r, J = f(rng.random()), f(rng.random())
        want = f(0.5) + J * (r - f(0.5))
        assert bits(rf.jitter_value(float(r), float(J))) == int(want.view(np.uint32))
    assert rf.jitter_value(0.123, 0.0) == 0.5
    assert rf.jitter_value(0.8125, 1.0) == 0.8125  # exact: r - 0.5 and back lose no bits for r >= 0.25
