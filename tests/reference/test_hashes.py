"""docs/spec.md sections 2 and 3: the integer hashes of the pure-Python reference.

Expected values come from ``spec_hashes.c``, an independent C implementation
written from docs/spec.md (compiled at test time by the ``spec_c`` fixture), and
from a small table of golden values produced by that C program; never from
pyoa's own output.
"""

from __future__ import annotations

import struct

import numpy as np
import pytest

from pyoa import reference as ref
from pyoa.reference.hashes import block_order_seed, hash_pair
from tests.helpers import (
    BLOCK_KEY,
    BOSE_PRIMES,
    PIXEL_KEY,
    U32_MAX,
    permute_cases,
    randfloat_cases,
    randfloat_preimage,
    seed_pair_cases,
)


def f32_bits(x: float) -> int:
    """IEEE bits of a Python float that must already hold a float32 value exactly."""
    b = struct.unpack("<I", struct.pack("<f", x))[0]
    assert struct.unpack("<f", struct.pack("<I", b))[0] == x, f"{x!r} is not a float32 value"
    return b


# Golden values, produced by tests/reference/spec_hashes.c (the C program compiled
# with `cc -std=c99 -O2 -ffp-contract=off`) from queries such as
# `printf 'P 0 7 4294967294\nR 0 1\n' | ./spec_hashes`.
GOLDEN_PERMUTE = [  # (i, l, p) -> permute(i, l, p)
    (0, 7, 0xFFFFFFFE, 6),
    (3, 7, 0xFFFFFFFE, 2),
    (5, 11, 1, 0),
    (100, 4093, 0x12345678, 1758),
    (0, 1, 0xDEADBEEF, 0),
    (2**31 - 1, 2**31, 0x9E3779B9, 1784725642),
    (17, 64, 0xFFFFFFFF, 2),
    (6, 169, 42, 144),
    (123456, 2**23, 0xFFFFFFFA, 810870),
]
#: The whole permutation of 0..6 with p = 0xfffffffe (docs/spec.md section 2's example
#: seed, where Kensler's unfixed (i + p) % l is not a permutation).
GOLDEN_PERMUTATION_7 = [6, 1, 3, 2, 5, 0, 4]
GOLDEN_RANDFLOAT_BITS = [  # (i, p) -> float32 bits of randfloat(i, p)
    (0, 1, 1017623385),
    (1, 1, 1063218782),
    (12345, 0xDEADBEEF, 1064380346),
    (0xFFFFFFFF, 0xFFFFFFFF, 1060668319),
    (7, 0x3FFFF, 1059214643),
    (0x9E3779B9, 0x12345678, 1044376274),
    (5, 0, 0x3F000000),  # p == 0: exactly 0.5
]
GOLDEN_MIX32 = [(0, 0), (1, 1753845952), (0xFFFFFFFF, 1734902346)]
GOLDEN_PIXEL_SEED = [(0, 0, 958780621), (7, 3, 12263333), (0xFFFFFFFF, 0xFFFFFFFF, 868172127)]
GOLDEN_BLOCK_SEED = [(0x12345678, 0, 0x12345678), (0x12345678, 1, 2818029927), (0, 1, 3701689947)]


# ----------------------------------------------------------------------------- golden table

@pytest.mark.parametrize("i, l, p, want", GOLDEN_PERMUTE)
def test_permute_golden(i, l, p, want):
    assert ref.permute(i, l, p) == want


def test_permute_golden_permutation_of_7():
    assert [ref.permute(i, 7, 0xFFFFFFFE) for i in range(7)] == GOLDEN_PERMUTATION_7


@pytest.mark.parametrize("i, p, want", GOLDEN_RANDFLOAT_BITS)
def test_randfloat_golden_bits(i, p, want):
    assert f32_bits(ref.randfloat(i, p)) == want


@pytest.mark.parametrize("x, want", GOLDEN_MIX32)
def test_mix32_golden(x, want):
    assert ref.mix32(x) == want


@pytest.mark.parametrize("seed, pixel, want", GOLDEN_PIXEL_SEED)
def test_pixel_seed_golden(seed, pixel, want):
    assert ref.pixel_seed(seed, pixel) == want


@pytest.mark.parametrize("p, block, want", GOLDEN_BLOCK_SEED)
def test_block_seed_golden(p, block, want):
    assert ref.block_seed(p, block) == want


def test_golden_table_agrees_with_the_c_program(spec_c):
    """The hard-coded table above is what spec_hashes.c computes (guards the table itself)."""
    assert spec_c.permute(*zip(*[c[:3] for c in GOLDEN_PERMUTE])) == [c[3] for c in GOLDEN_PERMUTE]
    assert spec_c.permute(range(7), [7] * 7, [0xFFFFFFFE] * 7) == GOLDEN_PERMUTATION_7
    assert spec_c.randfloat_bits(*zip(*[c[:2] for c in GOLDEN_RANDFLOAT_BITS])) == [c[2] for c in GOLDEN_RANDFLOAT_BITS]
    assert spec_c.mix32([c[0] for c in GOLDEN_MIX32]) == [c[1] for c in GOLDEN_MIX32]
    assert spec_c.pixel_seed(*zip(*[c[:2] for c in GOLDEN_PIXEL_SEED])) == [c[2] for c in GOLDEN_PIXEL_SEED]
    assert spec_c.block_seed(*zip(*[c[:2] for c in GOLDEN_BLOCK_SEED])) == [c[2] for c in GOLDEN_BLOCK_SEED]


# ----------------------------------------------------------------------------- against the C oracle

def test_permute_matches_c_oracle(spec_c):
    cases = permute_cases()
    assert len(cases) > 3000
    want = spec_c.permute(*zip(*cases))
    got = [ref.permute(i, l, p) for i, l, p in cases]
    bad = [(c, g, w) for c, g, w in zip(cases, got, want) if g != w]
    assert not bad, f"{len(bad)} mismatches, first (i, l, p), got, want: {bad[:5]}"


def test_randfloat_bits_match_c_oracle(spec_c):
    cases = randfloat_cases()
    want = spec_c.randfloat_bits(*zip(*cases))
    got = [f32_bits(ref.randfloat(i, p)) for i, p in cases]
    bad = [(c, hex(g), hex(w)) for c, g, w in zip(cases, got, want) if g != w]
    assert not bad, f"{len(bad)} mismatches, first (i, p), got, want: {bad[:5]}"


def test_mix32_pixel_seed_block_seed_match_c_oracle(spec_c):
    cases = seed_pair_cases()
    a, b = zip(*cases)
    assert [ref.mix32(x) for x in a] == spec_c.mix32(a)
    assert [ref.pixel_seed(x, y) for x, y in cases] == spec_c.pixel_seed(a, b)
    assert [ref.block_seed(x, y) for x, y in cases] == spec_c.block_seed(a, b)


def test_block_order_seed_matches_c_oracle(spec_c):
    """block_order_seed(P, block, N) of docs/spec.md section 6 (command K of spec_hashes.c):
    0 for block 0, else hash_pair(P, N, 0x94d049bb), never 0."""
    rng = np.random.default_rng(11)
    specials = [0, 1, 2, 0x1B873593, 0x94D049BB, U32_MAX - 1, U32_MAX]
    Ns = [1, 2, 4, 64, 121, 169, 2**24, 2**31]
    cases = [(P, block, N) for P in specials for block in range(4) for N in Ns]
    cases += [(int(P), int(block), int(N)) for P, block, N in
              zip(rng.integers(0, 2**32, 500), rng.integers(0, 2**32, 500), rng.integers(1, 2**31 + 1, 500))]
    want = spec_c.query([f"K {P} {block} {N}" for P, block, N in cases])
    got = [block_order_seed(P, block, N) for P, block, N in cases]
    bad = [(c, g, w) for c, g, w in zip(cases, got, want) if g != w]
    assert not bad, f"{len(bad)} mismatches, first (P, block, N), got, want: {bad[:5]}"
    assert all((w == 0) == (block == 0) for (_, block, _), w in zip(cases, want))


# ----------------------------------------------------------------------------- permute properties

@pytest.mark.parametrize("l", range(1, 65))
def test_permute_is_a_bijection_small_l(l):
    """Every l in 1..64 for ordinary seeds and for every seed within l of 2^32,
    where Kensler's unfixed (i + p) % l wraps."""
    seeds = [1, 2, 3, 0x12345678, 0x80000000, 0xF8000000] + [U32_MAX - k for k in range(l + 1)]
    for p in seeds:
        got = [ref.permute(i, l, p) for i in range(l)]
        assert sorted(got) == list(range(l)), f"l={l}, p={p:#x}: {got}"


@pytest.mark.parametrize("l", [BOSE_PRIMES[-1], 4091, 2039, 13**2, 5**4, 6**3, 2**12, 3**7])
def test_permute_is_a_bijection_bose_s_and_cmjnd_m(l):
    """The largest Bose s (4093) and sub-strata counts M = s^(t-1) of CMJND."""
    for p in (0x9E3779B9, U32_MAX, U32_MAX - (l - 1), U32_MAX - l // 2):
        got = [ref.permute(i, l, p) for i in range(l)]
        assert sorted(got) == list(range(l)), f"l={l}, p={p:#x} is not a permutation"


def test_largest_bose_s_is_4093():
    assert BOSE_PRIMES[-1] == 4093
    assert 4093**2 <= 2**24 < 4099**2


@pytest.mark.parametrize("l", [1, 2, 7, 64, 4093, 2**23, 2**31])
def test_permute_seed_zero_is_identity(l):
    for i in {0, 1 % l, l // 3, l - 1}:
        assert ref.permute(i, l, 0) == i


def test_permute_is_not_the_identity_for_nonzero_seeds():
    """Guards against a permute that ignores its seed."""
    for l in (5, 13, 64, 4093):
        identity = list(range(l))
        moved = [p for p in (1, 2, 3, 99, U32_MAX) if [ref.permute(i, l, p) for i in range(l)] != identity]
        assert len(moved) >= 4, f"l={l}: seeds {moved} move something"


def test_permute_unfixed_kensler_shift_would_fail():
    """The SPEC's reason for (i + p % l) % l: the pre-shift value plus p wraps for
    p = 0xfffffffe, l = 7 and Kensler's (i + p) % l repeats values (2 4 3 2 1 3 0);
    pyoa's permute must still be a permutation there."""
    p, l = 0xFFFFFFFE, 7
    got = [ref.permute(i, l, p) for i in range(l)]
    assert sorted(got) == list(range(l))
    # undo pyoa's shift to get the pre-shift values, then apply Kensler's
    pre = [(g - p % l) % l for g in got]
    kensler = [((v + p) & U32_MAX) % l for v in pre]
    assert kensler == [2, 4, 3, 2, 1, 3, 0]


@pytest.mark.parametrize("i, l", [(-1, 5), (5, 5), (0, 0), (0, 2**31 + 1)])
def test_permute_rejects_out_of_range(i, l):
    with pytest.raises(ValueError, match="permute"):
        ref.permute(i, l, 1)


# ----------------------------------------------------------------------------- randfloat properties

@pytest.mark.parametrize("i", [0, 1, 12345, U32_MAX])
def test_randfloat_seed_zero_is_half(i):
    assert ref.randfloat(i, 0) == 0.5
    assert f32_bits(ref.randfloat(i, 0)) == 0x3F000000


def test_randfloat_values_are_float32_in_unit_interval():
    rng = np.random.default_rng(3)
    vals = [ref.randfloat(int(i), int(p)) for i, p in rng.integers(0, 2**32, (20000, 2))]
    for v in vals:
        f32_bits(v)  # raises if not exactly a float32
    arr = np.array(vals)
    assert arr.min() >= 0.0 and arr.max() < 1.0
    assert arr.max() <= 1 - 2**-23
    # a hash, not a constant: roughly uniform
    assert abs(arr.mean() - 0.5) < 0.01
    assert np.histogram(arr, bins=10, range=(0, 1))[0].min() > 1700


@pytest.mark.parametrize("p", [1, 0x3FFFF, 0x40000, 0xDEADBEEF, U32_MAX])
def test_randfloat_extremes(spec_c, p):
    """Inputs whose integer hash is 2^32 - 1, 2^32 - 128 (both round up to 2^32 as
    float32) and 0 give exactly 1 - 2^-23 (the maximum) and 0.0."""
    hi = randfloat_preimage(U32_MAX, p)
    hi2 = randfloat_preimage(U32_MAX - 127, p)
    lo = randfloat_preimage(0, p)
    # the preimages are right according to the independent C program
    assert spec_c.randfloat_bits([hi, hi2, lo], [p] * 3) == [f32_bits(1 - 2**-23)] * 2 + [0]
    assert ref.randfloat(hi, p) == 1 - 2**-23
    assert f32_bits(ref.randfloat(hi, p)) == 0x3F7FFFFE  # 1 - 2^-23, one ulp below the largest float32 < 1
    assert ref.randfloat(hi2, p) == 1 - 2**-23
    assert ref.randfloat(lo, p) == 0.0


def test_randfloat_float_conversion_rounds_to_nearest_even(spec_c):
    """Hashes just below a float32 rounding tie: 2^31 + 127 rounds down, 2^31 + 128
    (a tie) to even (down), 2^31 + 384 (a tie) up: a truncating or round-up
    conversion gives other bits."""
    p = 0xC0FFEE
    hs = [2**31 + 127, 2**31 + 128, 2**31 + 129, 2**31 + 384, 2**31 + 383]
    want_u = [2**31, 2**31, 2**31 + 256, 2**31 + 512, 2**31 + 256]
    scale = struct.unpack("<f", struct.pack("<I", 0x2F7FFFFE))[0]
    ins = [randfloat_preimage(h, p) for h in hs]
    for i, u in zip(ins, want_u):
        want = float(np.float32(np.float32(u) * np.float32(scale)))
        assert ref.randfloat(i, p) == want
    assert [f32_bits(ref.randfloat(i, p)) for i in ins] == spec_c.randfloat_bits(ins, [p] * len(ins))


# ----------------------------------------------------------------------------- seeds (docs/spec.md section 3)

def test_pixel_seed_never_zero_even_when_the_hash_is_zero(spec_c):
    """mix32 is a bijection with mix32(0) == 0, so pixel = mix32(seed ^ key) makes the raw
    hash 0: pixel_seed must still be non-zero (it maps 0 to the key)."""
    for seed in (0, 1, 7, 0xDEADBEEF, U32_MAX):
        pixel = spec_c.mix32([seed ^ PIXEL_KEY])[0]
        assert ref.mix32(pixel ^ ref.mix32(seed ^ PIXEL_KEY)) == 0  # really the zero case
        assert ref.pixel_seed(seed, pixel) == PIXEL_KEY != 0
        assert spec_c.pixel_seed([seed], [pixel]) == [PIXEL_KEY]


def test_block_seed_never_zero_even_when_the_hash_is_zero(spec_c):
    for p in (0, 1, 0xDEADBEEF, U32_MAX):
        block = spec_c.mix32([p ^ BLOCK_KEY])[0]
        if block == 0:
            continue
        assert ref.block_seed(p, block) == BLOCK_KEY
    assert hash_pair(5, ref.mix32(5 ^ 99), 99) == 99


def test_pixel_seeds_are_nonzero_and_distinct():
    for seed in (0, 1, 0x5BD1E995, U32_MAX):
        pixels = list(range(3000)) + [U32_MAX - k for k in range(1000)] + [2**31 + k for k in range(500)]
        got = [ref.pixel_seed(seed, px) for px in pixels]
        assert 0 not in got
        assert len(set(got)) == len(got), f"seed {seed}: pixel seeds collide"
        assert all(0 < g <= U32_MAX for g in got)


def test_pixel_seed_depends_on_the_user_seed():
    a = [ref.pixel_seed(1, px) for px in range(100)]
    b = [ref.pixel_seed(2, px) for px in range(100)]
    assert len(set(a) & set(b)) <= 1


@pytest.mark.parametrize("p", [0, 1, 0x9E3779B9, U32_MAX])
def test_block_seed_zero_is_p_and_later_blocks_are_distinct_nonzero(p):
    assert ref.block_seed(p, 0) == p
    later = [ref.block_seed(p, b) for b in range(1, 2000)]
    assert 0 not in later
    assert len(set(later)) == len(later)
    assert p not in later


def test_dimension_seeds_follow_spec_formula():
    """docs/spec.md section 3: p*(j+1)*K mod 2^32 for the three keys (j+1, not j)."""
    for p in (1, 0x9E3779B9, U32_MAX):
        for j in (0, 1, 12, 4093):
            q = p * (j + 1)
            want = tuple((q * k) % 2**32 for k in (0x51633E2D, 0x68BC21EB, 0x02E5BE93))
            assert ref.dimension_seeds(p, j) == want
    assert ref.dimension_seeds(0, 5) == (0, 0, 0)
    assert all(v != 0 for v in ref.dimension_seeds(1, 0))  # dimension 0 is randomized
