"""SPEC section 7: the float32 rules of the reference (pyoa.reference.floats)."""

from __future__ import annotations

import struct

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


def test_sample_value_operation_order():
    """(stratum + (sub + jitter) / M) / s, each step rounded to float32: compare with
    numpy float32 scalars step by step for random inputs."""
    rng = np.random.default_rng(5)
    f = np.float32
    for _ in range(3000):
        s = int(rng.integers(2, 5000))
        M = int(rng.integers(1, 5000))
        stratum = int(rng.integers(0, s))
        sub = float(rng.integers(0, M))
        jit = float(f(rng.random()))
        want = (f(stratum) + (f(sub) + f(jit)) / f(M)) / f(s)
        want = min(want, f(rf.ONE_MINUS_ULP))
        assert bits(rf.sample_value(stratum, sub, jit, M, s)) == int(f(want).view(np.uint32))


def test_jitter_value_two_roundings():
    rng = np.random.default_rng(6)
    f = np.float32
    for _ in range(3000):
        r, J = f(rng.random()), f(rng.random())
        want = f(0.5) + J * (r - f(0.5))
        assert bits(rf.jitter_value(float(r), float(J))) == int(want.view(np.uint32))
    assert rf.jitter_value(0.123, 0.0) == 0.5
    assert rf.jitter_value(0.8125, 1.0) == 0.8125  # exact: r - 0.5 and back lose no bits for r >= 0.25
