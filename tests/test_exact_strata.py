"""Exact strata at every sample count (docs/spec.md section 7's cell clamp, section 8's properties).

Every value must lie in its own fine cell ``[c/N, (c+1)/N)`` exactly, so the
checks here use no tolerance: ``floor(float64(x) * k)`` is the exact cell index
of a float32 ``x`` at ``k <= 2**24`` cells (the product has at most 48
significant bits), and a point on a cell's edge belongs to the upper cell.

For each construction at its largest accepted ``N`` (and at the sizes where
float32 rounding used to break the strata: Bose s = 11 and 127, Bush 5^4 and
8^3, Addelman-Kempthorne q = 7), through the public API on both bulk
backends, with several seeds including the largest:

- the coarse strata ``floor(x * s)`` of every t columns of a block form an
  orthogonal array of strength t (index lambda) in every pixel;
- ``mj`` and ``cmj`` put exactly one point in each of the N fine cells of
  every dimension (a 1D Latin hypercube);
- ``j`` and ``centered`` keep the coarse strata.

Before the clamp, Bose s = 127 failed the Latin hypercube in 495 of 512
(pixel, dimension) pairs and Bose s = 11 lost a coarse stratum in 86 of 3.1
million; ``test_the_clamp_is_what_makes_them_exact`` keeps that evidence.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest

from pyoa._arrays import floats as array_floats
from tests.helpers import assert_oa, make

#: Seeds: 0 (the canonical array), small, random and the largest uint32.
SEEDS = [0, 1, 0x9E3779B9, 0xFFFFFFFF]


def cells(x: np.ndarray, k: int) -> np.ndarray:
    """Exact cell indices ``floor(x * k)`` of float32 values at ``k <= 2**24`` cells."""
    c = np.floor(np.asarray(x, np.float64) * k).astype(np.int64)
    assert c.min() >= 0 and c.max() < k, f"a value outside [0, 1): cells {c.min()}..{c.max()} of {k}"
    return c


def assert_latin(x: np.ndarray, N: int, what: str) -> None:
    """One point in each of the N fine cells of every (pixel, dimension) column
    of ``x`` (shape (pixels, N, dims)); counts per cell with bincount, so that
    N = 2^24 costs O(N), not a sort."""
    P, n, D = x.shape
    assert n == N
    c = cells(x, N)
    bad = 0
    for p in range(P):
        for d in range(D):
            bad += not np.array_equal(np.bincount(c[p, :, d], minlength=N), np.ones(N, np.int64))
    assert bad == 0, f"{what}: {bad} of {P * D} (pixel, dimension) columns are not Latin hypercubes at {N} cells"


def assert_strata(x: np.ndarray, smp, what: str) -> None:
    """The coarse strata of each block's columns form an OA of the sampler's
    strength (every t-subset of the requested columns, or all of them when
    fewer than t are requested) in every pixel."""
    s, t, B = smp.s, smp.strength, smp.block_dims
    S = cells(x, s)
    dims = np.arange(x.shape[2])
    for block in np.unique(dims // B):
        cols = dims[dims // B == block]
        k = min(t, len(cols))
        subsets = list(combinations(cols.tolist(), k))
        if len(subsets) > 40:  # many columns: every k-subset containing the first, plus a sample
            rng = np.random.default_rng(len(cols))
            subsets = subsets[:20] + [subsets[i] for i in rng.choice(len(subsets), 20, replace=False)]
        for sub in subsets:
            assert_oa(S, s, k, cols=list(sub), what=f"{what} block {block}")


def generate(name: str, spp: int, dims: int, pixels: int, backend: str, **kw) -> tuple[np.ndarray, object]:
    smp = make(name, spp, dims, backend=backend, **kw)
    return smp.generate(pixels=range(pixels)), smp


#: (construction, spp, strength, dims, pixels per seed): the largest N of every
#: construction (one pixel, two dimensions: 2^24 values each), and the sizes
#: where rounding used to break the strata (many pixels and dimensions).
LARGEST = [
    ("bose", 4093**2, None, 2, 1),
    ("addelman-kempthorne", 2 * 2887**2, None, 2, 1),
    ("cmjnd", 2**24, 24, 2, 1),
    ("bose-bush", 2 * 128**2, None, 3, 2),
    ("cmjnd", 6**4, 4, 8, 16),
]
ROUNDING = [
    ("bose", 121, None, 12, 512),
    ("bose", 127**2, None, 8, 8),
    ("bush", 5**4, 4, 6, 64),
    ("bush", 8**3, 3, 9, 64),
    ("addelman-kempthorne", 98, None, 15, 512),
    ("bose-bush", 32, None, 9, 256),
]


@pytest.mark.parametrize("name, spp, strength, dims, pixels", LARGEST + ROUNDING,
                         ids=[f"{c[0]}-{c[1]}" for c in LARGEST + ROUNDING])
@pytest.mark.parametrize("offset", ["cmj", "mj"])
def test_latin_hypercube_and_strata_exact(backend, name, spp, strength, dims, pixels, offset):
    seeds = SEEDS if spp <= 2**16 else SEEDS[-1:]  # the largest N: one seed (the largest) per offset
    for seed in seeds:
        x, smp = generate(name, spp, dims, pixels, backend, strength=strength, offset=offset, seed=seed)
        what = f"{name} spp={spp} {offset} seed={seed:#x} ({backend})"
        assert_latin(x, spp, what)
        assert_strata(x, smp, what)


@pytest.mark.parametrize("name, spp, strength, dims, pixels", ROUNDING, ids=[f"{c[0]}-{c[1]}" for c in ROUNDING])
@pytest.mark.parametrize("offset", ["j", "centered"])
def test_coarse_strata_exact_for_j_and_centered(backend, name, spp, strength, dims, pixels, offset):
    for seed in SEEDS[::3]:
        x, smp = generate(name, spp, dims, pixels, backend, strength=strength, offset=offset, seed=seed)
        assert_strata(x, smp, f"{name} spp={spp} {offset} seed={seed:#x} ({backend})")


def test_the_clamp_is_what_makes_them_exact(monkeypatch):
    """Without the clamp (the cell_clamp of pyoa._arrays.floats replaced by the identity) the same
    checks fail: Bose s = 127 breaks the Latin hypercube in most columns. So the
    exact tests above can fail, and the clamp is what makes them pass."""
    x, _ = generate("bose", 127**2, 8, 8, "numpy")
    assert_latin(x, 127**2, "clamped")
    monkeypatch.setattr(array_floats, "cell_clamp", lambda xp, v, c, n: v)
    y, _ = generate("bose", 127**2, 8, 8, "numpy")
    with pytest.raises(AssertionError, match="are not Latin hypercubes"):
        assert_latin(y, 127**2, "unclamped")
    moved = np.count_nonzero(x != y)
    assert 0 < moved < x.size // 1000  # few values move, and only by a little:
    assert np.abs(x.astype(np.float64) - y).max() <= 4 * 2.0**-24
