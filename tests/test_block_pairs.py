"""Pairs of dimensions in different blocks (docs/spec.md section 6).

Each block past the first reads its copy of the array in its own seeded order
of the rows, so a pair of dimensions from different blocks is two stratified
coordinates paired at random, as padding pairs them. Before that rule every
copy was read in block 0's order: dimension j + B was then a fixed function of
dimension j, and one pixel's N points filled only s of the s x s coarse cells
of the pair (Bose 121: 11 of 121).

The measure here is the one of issue 31: per pixel, how many of the s x s
coarse cells of a pair the pixel's N points fill. A random pairing of two
coordinates whose every coarse stratum holds N/s points leaves cell (a, b)
empty when none of the N/s points of row stratum a draws column stratum b,
a hypergeometric event, so it fills on average

    E = s^2 (1 - C(N - N/s, N/s) / C(N, N/s))

cells (Bose 121: 80.0; Bush 125, t = 3: 24.95). The test asks the mean over
pixels, for every pair tried, to be at least E minus five standard errors of
that mean (measured from the pixels) and at least 0.9 E. The old rule fails it:
:func:`test_the_old_rule_fails` evaluates the same measure on values made
with the old rule (the reference's frame with every block read at row i).
"""

from __future__ import annotations

import itertools
from math import comb

import numpy as np
import pytest

import pyoa
from pyoa.reference import hashes as rh

#: (sampler, generate keywords) of every construction: small B (every pair of
#: blocks 0 x 1) and larger B (pairs sampled across blocks 0-3).
CASES = [
    ("bose", dict(spp=16)),                       # GF(4), B = 5
    ("bose", dict(spp=121)),                      # s = 11, B = 12: the issue's example
    ("bush", dict(spp=125, strength=3)),          # s = 5, t = 3, B = 6: the issue's example
    ("bush", dict(spp=64, strength=3)),           # GF(4), t = 3
    ("cmjnd", dict(spp=64, strength=3)),          # s = 4, B = t = 3
    ("cmjnd", dict(spp=81, strength=2)),          # s = 9, B = 2
    ("addelman-kempthorne", dict(spp=50)),        # q = 5, index 2, B = 11
    ("bose-bush", dict(spp=32)),                  # s = 4, index 2, B = 9
]
PIXELS = 48
SEEDS = (0, 7, 2**32 - 1)


def random_pairing_cells(N: int, s: int) -> float:
    """Mean coarse cells of s x s filled by a random pairing of two
    coordinates with N/s points in each coarse stratum (module docstring)."""
    m = N // s
    return s * s * (1 - comb(N - m, m) / comb(N, m))


def pairs(B: int, dims: int, rng) -> list[tuple[int, int]]:
    """Every pair of blocks 0 x 1 for small B, else 150 pairs sampled across
    blocks 0-3, always including the same column in blocks 0 and 1 (the pair
    the old rule made a function) and the last column of each block."""
    if B <= 12:
        return [(a, B + b) for a in range(B) for b in range(B)]
    same = [(c, c + B) for c in (0, 1, B - 1)] + [(B - 1, 3 * B + B - 1)]
    cand = [(a, b) for a, b in itertools.combinations(range(dims), 2) if a // B != b // B]
    pick = rng.choice(len(cand), 150, replace=False)
    return same + [cand[k] for k in pick]


def filled(x: np.ndarray, s: int, a: int, b: int) -> np.ndarray:
    """Coarse cells of s x s that each pixel's points fill in dimensions (a, b)."""
    cells = np.sort(np.floor(x[:, :, a] * s).astype(np.int64) * s + np.floor(x[:, :, b] * s).astype(np.int64), axis=1)
    return 1 + np.count_nonzero(np.diff(cells, axis=1), axis=1)


def check_pairs(x: np.ndarray, s: int, N: int, dim_pairs, what: str) -> None:
    want = random_pairing_cells(N, s)
    for a, b in dim_pairs:
        f = filled(x, s, a, b)
        se = f.std(ddof=1) / np.sqrt(len(f)) if len(f) > 1 else 0.0
        floor = min(want - 5 * se, want) if se else want
        assert f.mean() >= max(floor, 0.9 * want) - 1e-9, (
            f"{what}: dimensions ({a}, {b}) fill {f.mean():.2f} of {s * s} coarse cells per pixel "
            f"(min {f.min()}), a random pairing {want:.2f}")


@pytest.mark.parametrize("name,kw", CASES, ids=[f"{n}-{kw['spp']}" for n, kw in CASES])
def test_pairs_across_blocks_are_random_pairings(name, kw, backend):
    offsets = ("cmj", "mj", "j", "centered")
    rng = np.random.default_rng(5)
    for seed, offset in zip(SEEDS, itertools.cycle(offsets)):
        probe = pyoa.sampler(name, **kw, dims=1)
        B, s, N = probe.block_dims, probe.s, probe.spp
        dims = 2 * B if B <= 12 else 4 * B
        smp = pyoa.sampler(name, **kw, dims=dims, seed=seed, offset=offset, backend=backend)
        x = smp.generate(pixels=range(2**32 - PIXELS // 2, 2**32)) if seed else smp.generate(pixels=range(PIXELS))
        check_pairs(x, s, N, pairs(B, dims, rng), f"{name} {kw} seed={seed} {offset} [{backend}]")


@pytest.mark.parametrize("name,kw,dims,want", [("bush", dict(spp=125, strength=3), (0, 6), 22),
                                               ("bose", dict(spp=121), (0, 12), 70)])
def test_the_issue_numbers(name, kw, dims, want):
    """Issue 31's criterion, as stated: 64 pixels, seed 0, the default backend."""
    x = pyoa.sampler(name, **kw, dims=dims[1] + 1).generate(pixels=range(64))
    assert filled(x, pyoa.sampler(name, **kw, dims=1).s, *dims).mean() >= want


def _old_rule(i: int, j: int, p: int, *, N: int, B: int, s: int, M: int, cell) -> float:
    """The value the old block rule gave: every copy read at row i (block 0's
    order), built from the reference's own pieces."""
    from pyoa.reference.floats import jitter_value, sample_value

    block, col = divmod(j, B)
    P = rh.block_seed(p, block)
    aij, u, _ = cell(i, col)
    P1, P2, P3 = rh.dimension_seeds(P, col)
    return sample_value(rh.permute(aij, s, P1), rh.permute(u, M, P2), jitter_value(rh.randfloat(i, P3), 1.0), M, s)


def test_the_old_rule_fails():
    """The measure catches the defect: values made with the old rule (Bose 121,
    cmj) fill only s of the s x s cells in dimensions (c, c + B)."""
    from pyoa.reference import oa

    s, N, B = 11, 121, 12

    def cell(row, col):
        aij, aik = oa.bose_cell(row, col, s)
        return aij, aik, 0

    ps = [rh.pixel_seed(0, px) for px in range(8)]
    x = np.array([[[_old_rule(i, j, p, N=N, B=B, s=s, M=s, cell=cell) for j in (0, 1, B, B + 1)]
                   for i in range(N)] for p in ps])
    assert np.all(filled(x, s, 0, 2) == s) and np.all(filled(x, s, 1, 3) == s)
    with pytest.raises(AssertionError, match="fill 11.00 of 121"):
        check_pairs(x, s, N, [(0, 2)], "old rule")
    # the new rule's reference values, same pixels: a random pairing
    y = np.array([[[oa.bose(i, j, s, p) for j in (0, B)] for i in range(N)] for p in ps])
    assert filled(y, s, 0, 1).mean() > 60
