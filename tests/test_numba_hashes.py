"""The numba hashes (pyoa._numba.hashes, called by the compiled renderer and
the pmj02 table builder) against the reference, bit for bit: random words
and the edges of uint32 (a product of two words overflows int64, so a
multiplication that relied on wrapping would be caught where it matters)."""

from __future__ import annotations

import numpy as np
from hypothesis import example, given
from hypothesis import strategies as st
from numba import njit

from pyoa._numba import hashes as nbh
from pyoa.reference import hashes as ref

U32 = st.integers(0, 2**32 - 1)


@njit
def _pair(a, b, key):  # called from compiled code, as its users do (the functions are inlined)
    return nbh.hash_pair(a, b, key)


@njit
def _mix(x):
    return nbh.mix32(x)


@given(U32, U32, U32)
@example(0, 0, 0)
@example(2**32 - 1, 2**32 - 1, 2**32 - 1)
@example(0, 0, ref.PIXEL_KEY)
def test_hash_pair_and_mix32_match_the_reference(a, b, key):
    assert _mix(np.int64(a)) == ref.mix32(a)
    assert _pair(np.int64(a), np.int64(b), np.int64(key)) == ref.hash_pair(a, b, key)


@given(U32, U32)
@example(2**32 - 1, 2**32 - 1)
def test_mul32_is_the_product_modulo_2_32(a, b):
    assert nbh.mul32(np.int64(a), np.int64(b)) == (a * b) % 2**32


def test_hash_pair_takes_its_words_modulo_2_32():
    # the renderer hashes (sample * 64 + depth) and pixel indices held in int64
    for a, b in ((2**32 + 5, 7), (5, 2**33 + 7)):
        assert _pair(np.int64(a), np.int64(b), np.int64(ref.PIXEL_KEY)) == ref.hash_pair(a % 2**32, b % 2**32,
                                                                                            ref.PIXEL_KEY)
