"""The NumPy array namespace (pyoa._numpy.ops) against plain NumPy, and the binding of
the generic source (pyoa._arrays.bind). The Dr.Jit namespace is checked against this
one in tests/test_drjit.py."""

from __future__ import annotations

import inspect
import warnings

import numpy as np
import pytest

from pyoa import _arrays
from pyoa._arrays import hashes
from pyoa._numpy import ops
from pyoa._numpy.hashes import permute, pixel_seed

U32 = np.uint32


def test_the_namespace_defines_every_operation():
    missing = [name for name in _arrays.OPERATIONS if not callable(getattr(ops, name, None))]
    assert not missing


def countdown(n, step):
    """A loop whose lanes stop after different numbers of steps: n -> n - step while n >= step."""
    return ((n, step), lambda n, step: n >= step, lambda n, step: (n - step, step))


def test_while_loop_runs_each_lane_until_its_condition_fails():
    n = np.arange(40, dtype=U32).reshape(5, 8)
    step = np.array([1, 3, 7, 40, 41], dtype=U32)[:, None]  # an invariant of another shape
    before = n.copy()
    (got, _), = ops.while_loops([countdown(n, step)], "test")
    assert np.array_equal(got, n % step)
    assert np.array_equal(n, before)  # the caller's arrays are not written


def test_while_loop_with_no_lane_or_every_lane_looping():
    n = np.array([1, 2, 3], dtype=U32)
    (got, _), = ops.while_loops([countdown(n, U32(5))], "test")
    assert got is n  # nothing to do: the state as given
    (got, _), = ops.while_loops([countdown(n, U32(1))], "test")
    assert np.array_equal(got, [0, 0, 0])
    once = ((n, n != 0), lambda x, todo: todo, lambda x, todo: (x * 2, todo & False))
    (got, _), = ops.while_loops([once], "test")
    assert np.array_equal(got, 2 * n)


def test_where_needed_computes_the_needed_lanes_only():
    rng = np.random.default_rng(1)
    x = rng.random((6, 7), dtype=np.float32).T  # another memory order than the mask's
    c = rng.integers(0, 9, (7, 1)).astype(np.float32)
    needed = rng.random((6, 7)).T < 0.2
    want = np.where(needed, x + c, x)
    seen = []

    def f(x, c):
        seen.append(x.size)
        return x + c

    got = ops.where_needed(needed, f, x.copy(), c)
    assert np.array_equal(got, want) and seen == [np.count_nonzero(needed)]
    assert np.array_equal(ops.where_needed(None, f, x.copy(), c), x + c)


def test_power_wraps_like_uint32():
    e = np.arange(32, dtype=U32)
    for base in (2, 3, 13, 4093):
        assert ops.power(base, e).tolist() == [pow(base, int(k), 2**32) for k in e]


def test_bound_functions_drop_xp_and_take_scalars_without_warnings():
    assert list(inspect.signature(permute).parameters) == ["i", "l", "p"]
    assert permute.__doc__ == hashes.permute.__doc__ and permute.__name__ == "permute"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # uint32 scalars that overflow warn outside ops.wrapping()
        assert int(pixel_seed(0, 1)) == int(pixel_seed(np.zeros(1, U32), np.ones(1, U32))[0])
        assert int(permute(5, 13, 0xDEADBEEF)) == int(permute(np.array([5], U32), 13, 0xDEADBEEF)[0])
    with pytest.warns(RuntimeWarning, match="overflow"):
        hashes.mix32(ops, 0xFFFFFFFF)  # the same hash, unbound: NumPy warns on its scalars
