"""Properties of the comparison samplers (pyoa.catalogue.baselines): random, jittered2d,
cmj2d, sobol02, halton and sobol.

What the docstrings of :mod:`pyoa.reference.baselines` promise, checked on the
values the samplers produce (bulk values from the NumPy functions or from
``pyoa.sampler(...).generate``; the pure-Python reference only on small sets):
stratification over many seeds, equality with SciPy's unscrambled Sobol and
with an independently computed radical inverse, Owen (nested) rather than
positional scrambling, independence of the padded pairs, unbiasedness of
estimates (docs/spec.md 8.6), the catalogue, the API and the command line.
Bit-for-bit agreement of the backends is tests/test_baselines_conformance.py.

Exact stratification of float32 values
--------------------------------------
``random``, ``sobol02``, ``halton`` and ``sobol`` values are ``k * 2**-24``:
for power-of-two cell counts ``floor(x * 2**u)`` is exact.

``jittered2d`` and ``cmj2d`` values are ``(stratum + (sub + jitter) / M) / s``
in float32 (docs/spec.md section 7), clamped into their cell: ``c / N <= x < (c + 1) /
N`` as real numbers for the cell ``c = stratum * M + sub`` of ``N = s * M``
(:func:`pyoa.reference.floats.sample_value`). For a float32 ``x`` and an
integer ``n <= 2**24`` the float64 product ``x * n`` is exact (24 + 25
significant bits fit in 53), so ``floor(x * n)`` *is* the index of the cell
``[c / n, (c + 1) / n)`` holding ``x`` (:func:`cells`): the checks compare
integers, with no tolerance. Without the clamp they would fail: the rounded
formula puts values on, or one ulp across, a cell edge
(:func:`test_clamp_keeps_values_in_their_cells` shows it happen).

``halton`` truncates the exact scrambled fraction ``t`` to 24 bits, ``x =
floor(2**24 t) / 2**24``, by design. A point of interval ``[a, a+1) / b**k``
has ``2**24 x`` in ``[T_a, T_a+1]`` with the integers ``T_a = floor(2**24 a /
b**k)``: it may sit exactly on the truncated upper boundary (this happens, for
b**k ~ 250 about once per 10**5 points), so ``floor(x * b**k)`` is not its
interval. The check is still tolerance-free: a value strictly inside ``(T_a,
T_a+1) / 2**24`` belongs to interval a alone, a value equal to a boundary to
either neighbour, and the set is stratified iff the points can be matched one
to one with the intervals they may belong to
(:func:`assert_one_per_closed_cell`).
"""

from __future__ import annotations

import math
import re
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import pyoa
from pyoa.tables import sequences
from pyoa._numpy import baselines as nb
from pyoa._numpy.floats import jitter_value
from pyoa._numpy.hashes import permute, pixel_seed, randfloat
from pyoa.reference import baselines as rb
from tests.helpers import U32_MAX, assert_same_bits, run_cli

F32 = np.float32
U32 = np.uint32
UNIT24 = 2.0**-24
NAMES = ["random", "jittered2d", "cmj2d", "sobol02", "halton", "sobol"]

#: Seeds p of the point sets: the unrandomized 0, the extremes and random ones.
P_SEEDS = np.array([0, 1, U32_MAX] + [int(v) for v in np.random.default_rng(2019).integers(2, U32_MAX, 61)],
                   dtype=np.uint32)
#: Pixels of the sampler-level checks (pixel seeds from pyoa.reference.pixel_seed).
PIXELS = [0, 1, 2, 3, 77, 1000, 65535, 2**31, U32_MAX - 1, U32_MAX]
seeds = st.integers(0, U32_MAX)


# =============================================================================== helpers

def independent_primes(count: int) -> list[int]:
    """The first ``count`` primes by trial division (not pyoa.tables.sequences' sieve)."""
    out: list[int] = []
    n = 2
    while len(out) < count:
        if all(n % q for q in out if q * q <= n):
            out.append(n)
        n += 1
    return out


PRIMES = independent_primes(6543)


def most_square(N: int) -> tuple[int, int]:
    """(m, n): m the largest divisor of N with m <= sqrt(N), n = N / m."""
    m = max(d for d in range(1, math.isqrt(N) + 1) if N % d == 0)
    return m, N // m


def cells(x: np.ndarray, n: int) -> np.ndarray:
    """``floor(x * n)`` for float32 ``x`` and an integer ``1 <= n <= 2**24``: the
    index c of the cell ``[c / n, (c + 1) / n)`` that holds ``x``, exactly (the
    float64 product of a 24-bit significand and a 25-bit integer is not rounded)."""
    assert 1 <= n <= 2**24
    return np.floor(np.asarray(x, dtype=F32).astype(np.float64) * n).astype(np.int64)


def assert_one_per_cell(cx: np.ndarray, nx: int, cy: np.ndarray | None = None, ny: int = 1,
                        what: str = "") -> None:
    """Every point set holds exactly one point in every cell of an ``nx x ny`` grid.

    ``cx`` and ``cy`` are integer cell indices (:func:`cells`) of shape ``(sets,
    N)``, ``cy = None`` a 1D stratification into ``nx`` cells. Since the indices
    are exact, a set is stratified iff its cell codes are a permutation of 0..N-1.
    """
    cx = np.atleast_2d(cx)
    cy = np.zeros_like(cx) if cy is None else np.atleast_2d(cy)
    S, N = cx.shape
    assert N == nx * ny, f"{what}: {N} points for a {nx} x {ny} grid"
    assert cx.min() >= 0 and cx.max() < nx and cy.min() >= 0 and cy.max() < ny, f"{what}: a value outside [0, 1)"
    code = np.sort(cx * ny + cy, axis=1)
    bad = np.flatnonzero(np.any(code != np.arange(N), axis=1))
    if bad.size:  # N codes in [0, N) that are not a permutation: one repeats
        s = int(bad[0])
        c = int(code[s, 1:][code[s, 1:] == code[s, :-1]][0])
        raise AssertionError(f"{what}: {bad.size} of {S} sets are not one point per cell; first: set {s}, "
                             f"cell (x {c // ny} of {nx}, y {c % ny} of {ny}) holds several points")


def truncated_bounds(ncells: int) -> np.ndarray:
    """``floor(2**24 a / ncells) / 2**24`` for a = 0..ncells, as float32 (exact):
    the closed float32 images of halton's intervals ``[a, a+1) / ncells``."""
    a = np.arange(ncells + 1, dtype=np.int64)
    return ((a << 24) // ncells).astype(np.float64).astype(F32) * F32(UNIT24)


def candidates(x: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cell of each value for the closed cells ``[B_r, B_r+1]``: ``(hi, amb)``
    where ``hi`` is the highest cell containing ``x`` and ``amb`` says that ``x``
    equals the interior boundary ``B_hi`` (so cell ``hi - 1`` holds it too)."""
    x = np.asarray(x)
    B = np.asarray(B, dtype=x.dtype)
    assert np.all(np.diff(B) > 0), "cell boundaries must increase strictly"
    assert np.all(x >= B[0]) and np.all(x <= B[-1]), "values outside [0, 1]"
    inner = B[1:-1]
    hi = np.searchsorted(inner, x, side="right")
    amb = (hi > 0) & (inner[np.maximum(hi - 1, 0)] == x) if inner.size else np.zeros(x.shape, bool)
    return hi.astype(np.int64), amb


def _perfect_matching(cands: list[list[int]], free: set[int]) -> bool:
    """Kuhn's augmenting paths: can every point take a distinct cell of its list?"""
    owner: dict[int, int] = {}

    def place(k: int, seen: set[int]) -> bool:
        for c in cands[k]:
            if c in free and c not in seen:
                seen.add(c)
                if c not in owner or place(owner[c], seen):
                    owner[c] = k
                    return True
        return False

    return all(place(k, set()) for k in range(len(cands)))


def assert_one_per_closed_cell(cols, rows=None, what: str = "") -> None:
    """Every point set holds exactly one point in every closed cell of a grid
    (halton's truncated intervals, see the module docstring).

    ``cols`` and ``rows`` are ``(hi, amb, ncells)`` of :func:`candidates` for
    the x and y axes, ``hi`` and ``amb`` of shape ``(sets, N)``; ``rows=None``
    is a 1D stratification. Exact: a point on a boundary may go to either
    cell, and the sets must admit a one-to-one matching of points to cells.
    """
    xh, xa, nx = cols
    xh, xa = np.atleast_2d(xh), np.atleast_2d(xa)
    if rows is None:
        yh, ya, ny = np.zeros_like(xh), np.zeros_like(xa), 1
    else:
        yh, ya, ny = rows
        yh, ya = np.atleast_2d(yh), np.atleast_2d(ya)
    S, N = xh.shape
    assert N == nx * ny, f"{what}: {N} points for a {nx} x {ny} grid"
    amb = xa | ya
    cell = xh * ny + yh
    occ = np.zeros((S, N), dtype=np.int64)
    sets, pts = np.nonzero(~amb)
    np.add.at(occ, (sets, cell[sets, pts]), 1)
    crowded = np.argwhere(occ > 1)
    if crowded.size:
        s, c = crowded[0]
        raise AssertionError(f"{what}: {len(crowded)} cells hold several points; first in set {s}: cell "
                             f"(x {c // ny} of {nx}, y {c % ny} of {ny}) holds {occ[s, c]}")
    for s in np.flatnonzero(amb.any(axis=1)):
        free = set(np.flatnonzero(occ[s] == 0).tolist())
        cands = []
        for k in np.flatnonzero(amb[s]):
            xs = [xh[s, k]] + ([xh[s, k] - 1] if xa[s, k] else [])
            ys = [yh[s, k]] + ([yh[s, k] - 1] if ya[s, k] else [])
            cands.append([int(a * ny + b) for a in xs for b in ys])
        assert len(cands) == len(free) and _perfect_matching(cands, free), (
            f"{what}: set {s} is not one point per cell (boundary points {len(cands)}, empty cells {len(free)})")


def assert_dyadic_net(x: np.ndarray, y: np.ndarray | None, what: str) -> None:
    """x, y of shape (sets, 2**L), values multiples of 2**-24. For every prefix
    2**k (k = 0..L): with y None every prefix is stratified into 2**k intervals;
    else it has one point in every elementary interval 2**-u x 2**-(k-u)."""
    S, N = x.shape
    L = N.bit_length() - 1
    assert N == 1 << L
    X = np.asarray(x, np.float64) * 2**24
    assert np.all(X == np.floor(X)) and X.min() >= 0 and X.max() < 2**24, f"{what}: not 24-bit values"
    X = X.astype(np.int64)
    Y = None if y is None else (np.asarray(y, np.float64) * 2**24).astype(np.int64)
    for k in range(L + 1):
        want = np.arange(1 << k)
        for u in ([k] if Y is None else range(k + 1)):
            v = k - u
            code = X[:, : 1 << k] >> (24 - u)
            if Y is not None:
                code = (code << v) | (Y[:, : 1 << k] >> (24 - v))
            ok = np.all(np.sort(code, axis=1) == want, axis=1)
            assert ok.all(), (f"{what}: prefix of 2^{k} samples is not stratified into {2**u} x {2**v} "
                              f"intervals in {np.count_nonzero(~ok)} of {S} sets (first: set {np.argmin(ok)})")


def grid(f, N: int, dims, p, *shape, jitter=None) -> np.ndarray:
    """``f(i, j, *shape, p[, jitter])`` of a pyoa._numpy.baselines function for
    every (seed, sample i < N, dimension) as an array (len(p), N, len(dims))."""
    i = np.arange(N, dtype=np.uint32)[None, :, None]
    j = np.asarray(dims, dtype=np.uint32)[None, None, :]
    p = np.asarray(p, dtype=np.uint32)[:, None, None]
    extra = () if jitter is None else (jitter,)
    return np.broadcast_to(f(i, j, *shape, p, *extra), (p.shape[0], N, j.shape[-1]))


# =============================================================================== jittered2d

def check_jittered2d(x: np.ndarray, m: int, dims: int, what: str) -> None:
    """x: (sets, m*m, dims). Pairs (0,1), (2,3)...: one point in every cell of the
    m x m grid; a lone last dimension: one point in every one of its m*m strata."""
    N = m * m
    for a in range(0, dims - 1, 2):
        assert_one_per_cell(cells(x[:, :, a], m), m, cells(x[:, :, a + 1], m), m,
                            f"{what}: pair ({a},{a + 1}) as an {m}x{m} grid")
    if dims % 2:
        assert_one_per_cell(cells(x[:, :, dims - 1], N), N, what=f"{what}: lone last dimension {dims - 1} in {N} strata")


@pytest.mark.parametrize("m", [1, 2, 3, 5, 8, 13, 16, 45, 64])
@pytest.mark.parametrize("jitter", [1.0, 0.37])
def test_jittered2d_grids_many_seeds(m, jitter):
    dims = 5
    x = grid(nb.jittered2d, m * m, range(dims), P_SEEDS, m, dims, jitter=jitter)
    check_jittered2d(x, m, dims, f"jittered2d m={m} jitter={jitter}")


@pytest.mark.parametrize("m, n_seeds", [(181, 8), (256, 4), (1024, 1)])
def test_jittered2d_large_grids(m, n_seeds):
    """Fewer seeds, larger grids: the lone dimension's strata get as narrow as
    2**-20 (m = 1024), only 16 float32 steps below 1, and N = 181**2 is no power
    of two (its cell edges are not float32 values, so the formula can round
    below a cell as well as onto the next one)."""
    dims = 3
    x = grid(nb.jittered2d, m * m, range(dims), P_SEEDS[:n_seeds], m, dims, jitter=1.0)
    check_jittered2d(x, m, dims, f"jittered2d m={m}")


@given(p=seeds, m=st.integers(1, 24), dims=st.integers(1, 7),
       jitter=st.floats(0, 1) | st.sampled_from([0.0, 1.0]))
def test_jittered2d_hypothesis(p, m, dims, jitter):
    x = grid(nb.jittered2d, m * m, range(dims), [p], m, dims, jitter=jitter)
    check_jittered2d(x, m, dims, f"jittered2d p={p} m={m} dims={dims} jitter={jitter}")


def test_jittered2d_jitter0_cell_centres():
    """jitter = 0: every value is the float32 centre f32(c + 0.5) / m of its cell
    (the lone dimension: of its N strata), for any seed."""
    for m, dims in [(1, 3), (3, 5), (7, 3), (16, 7), (45, 1), (64, 3)]:
        N = m * m
        x = grid(nb.jittered2d, N, range(dims), P_SEEDS, m, dims, jitter=0.0)
        for j in range(dims):
            s = N if (j == dims - 1 and j % 2 == 0) else m
            c = cells(x[:, :, j], s)
            assert_same_bits(x[:, :, j], (c.astype(F32) + F32(0.5)) / F32(s), f"jittered2d m={m} dim {j} centres")
        check_jittered2d(x, m, dims, f"jittered2d m={m} jitter=0")
    # p = 0: cell centres in natural order (cell k = i: column i mod m, row i // m)
    m = 5
    x = grid(nb.jittered2d, m * m, range(3), [0], m, 3, jitter=1.0)[0]
    i = np.arange(m * m)
    assert_same_bits(x[:, 0], ((i % m).astype(F32) + F32(0.5)) / F32(m), "p=0 column centres")
    assert_same_bits(x[:, 1], ((i // m).astype(F32) + F32(0.5)) / F32(m), "p=0 row centres")
    assert_same_bits(x[:, 2], (i.astype(F32) + F32(0.5)) / F32(m * m), "p=0 lone dimension centres")


@pytest.mark.parametrize("m", [11, 64])
@pytest.mark.parametrize("jitter", [1.0, 0.37])
def test_jittered2d_jitter_moves_points_within_their_cell(m, jitter):
    """Jitter only moves a point inside its cell: the values of the same (p, i, j)
    at jitter 0 (the centre) and at jitter J lie in the same cell, exactly (the
    shuffle does not depend on the jitter amount)."""
    dims = 5
    c0 = grid(nb.jittered2d, m * m, range(dims), P_SEEDS, m, dims, jitter=0.0)
    c1 = grid(nb.jittered2d, m * m, range(dims), P_SEEDS, m, dims, jitter=jitter)
    for j in range(dims):
        n = m * m if j == dims - 1 else m
        moved = np.flatnonzero(cells(c1[:, :, j], n) != cells(c0[:, :, j], n))
        assert moved.size == 0, f"dim {j}: jitter {jitter} moved {moved.size} points out of their cell"
        assert np.any(c1[:, :, j] != c0[:, :, j]), f"dim {j}: jitter {jitter} moved no point"


@pytest.mark.parametrize("m, dims", [(8, 7), (12, 4), (64, 3)])
def test_jittered2d_sampler_pixels(backend, m, dims):
    for seed in (0, 1, 99):
        smp = pyoa.sampler("jittered2d", spp=m * m, dims=dims, seed=seed, backend=backend)
        check_jittered2d(smp.generate(pixels=PIXELS), m, dims, f"sampler seed={seed}")


# =============================================================================== cmj2d

def check_cmj2d(x: np.ndarray, N: int, dims: int, what: str) -> None:
    """x: (sets, N, dims). Pairs: m x n grids (x in m columns, y in n rows, m, n
    from :func:`most_square`), every dimension a Latin hypercube of N strata
    (a lone last dimension is the x of its pair: the Latin check is all there is
    for it)."""
    m, n = most_square(N)
    for a in range(dims):
        assert_one_per_cell(cells(x[:, :, a], N), N, what=f"{what}: dim {a} Latin in {N}")
    for a in range(0, dims - 1, 2):
        assert_one_per_cell(cells(x[:, :, a], m), m, cells(x[:, :, a + 1], n), n,
                            f"{what}: pair ({a},{a + 1}) as an {m}x{n} grid")


CMJ_COUNTS = [1, 2, 3, 7, 12, 36, 120, 127, 128, 250, 1000, 4093, 4096]


@pytest.mark.parametrize("N", CMJ_COUNTS)
def test_cmj2d_grids_and_latin_many_seeds(N):
    dims = 5
    m, n = most_square(N)
    x = grid(nb.cmj2d, N, range(dims), P_SEEDS if N <= 1000 else P_SEEDS[:8], m, n, jitter=1.0)
    check_cmj2d(x, N, dims, f"cmj2d N={N} ({m}x{n})")


@pytest.mark.parametrize("N", [2**16, 2**20, 1000 * 1009])
def test_cmj2d_large_grids(N):
    """One seed, large grids: fine strata of width 2**-20 (N = 2**20) and of a
    width that is no power of two (1000 x 1009)."""
    m, n = most_square(N)
    x = grid(nb.cmj2d, N, range(3), P_SEEDS[1:2], m, n, jitter=1.0)
    check_cmj2d(x, N, 3, f"cmj2d N={N} ({m}x{n})")


@given(p=seeds, N=st.integers(1, 300), dims=st.integers(1, 5), jitter=st.floats(0, 1) | st.just(1.0))
def test_cmj2d_hypothesis(p, N, dims, jitter):
    m, n = most_square(N)
    x = grid(nb.cmj2d, N, range(dims), [p], m, n, jitter=jitter)
    check_cmj2d(x, N, dims, f"cmj2d p={p} N={N} ({m}x{n}) dims={dims} jitter={jitter}")


def test_cmj2d_jitter0_centres_of_fine_strata():
    """jitter = 0: every coordinate is the float32 centre of its fine stratum r
    of N (x: column r // n, sub-column r % n; y: row r // m, sub-row r % m)."""
    for N in (6, 120, 128, 127, 4096):
        m, n = most_square(N)
        x = grid(nb.cmj2d, N, range(2), P_SEEDS, m, n, jitter=0.0)
        for j, (c, f) in enumerate([(m, n), (n, m)]):
            r = cells(x[:, :, j], N)
            want = ((r // f).astype(F32) + ((r % f).astype(F32) + F32(0.5)) / F32(f)) / F32(c)
            assert_same_bits(x[:, :, j], want, f"cmj2d N={N} dim {j} centres")
        check_cmj2d(x, N, 2, f"cmj2d N={N} jitter=0")


@pytest.mark.parametrize("N", [120, 4096])
def test_cmj2d_jitter_moves_points_within_their_fine_stratum(N):
    """As for jittered2d: jitter moves a point inside its fine stratum, never out."""
    m, n = most_square(N)
    c0 = grid(nb.cmj2d, N, range(4), P_SEEDS, m, n, jitter=0.0)
    for jitter in (1.0, 0.37):
        c1 = grid(nb.cmj2d, N, range(4), P_SEEDS, m, n, jitter=jitter)
        for j in range(4):
            moved = np.flatnonzero(cells(c1[:, :, j], N) != cells(c0[:, :, j], N))
            assert moved.size == 0, f"dim {j}: jitter {jitter} moved {moved.size} points out of their fine stratum"
            assert np.any(c1[:, :, j] != c0[:, :, j]), f"dim {j}: jitter {jitter} moved no point"


@pytest.mark.parametrize("N, dims", [(120, 5), (128, 4), (97, 3), (4096, 3)])
def test_cmj2d_sampler_pixels(backend, N, dims):
    for seed in (0, 5):
        smp = pyoa.sampler("cmj2d", spp=N, dims=dims, seed=seed, backend=backend)
        m, n = most_square(N)
        assert (smp.s, smp.params.a, smp.params.c) == (m, m, n)
        check_cmj2d(smp.generate(pixels=PIXELS), N, dims, f"sampler N={N} seed={seed}")


# =============================================================================== the cell clamp

def unclamped(stratum, sub, jit, M: int, s: int) -> np.ndarray:
    """docs/spec.md section 7's ``(stratum + (sub + jitter) / M) / s`` as four correctly
    rounded float32 operations, *without* the cell clamp."""
    return (np.asarray(stratum).astype(F32) + (np.asarray(sub).astype(F32) + jit) / F32(M)) / F32(s)


def construction(name: str, size: tuple[int, int], i, j: int, p, jitter: float):
    """``(stratum, sub, jit, M, s)`` of dimension ``j`` of ``jittered2d`` (``size
    = (m, dims)``) or ``cmj2d`` (``size = (m, n)``), written out from the docstrings
    of :mod:`pyoa.reference.baselines` with pyoa's hash primitives (checked against
    the C oracle in tests/reference/test_hashes.py); the cell of the value is
    ``stratum * M + sub`` of ``s * M``."""
    i, p = np.asarray(i, dtype=U32), np.asarray(p, dtype=U32)
    q = nb.derived_seed(p, U32(j >> 1), rb.PAD_KEY)
    a, b = size
    k = permute(i, a * a if name == "jittered2d" else a * b, q * U32(rb.SHUFFLE_KEY))
    jit = jitter_value(randfloat(k, q * U32(rb.JITY_KEY if j % 2 else rb.JITX_KEY)), F32(jitter))
    zero = np.zeros(k.shape, dtype=U32)
    if name == "jittered2d":
        m, dims = a, b
        if j % 2 == 0 and j + 1 == dims:  # a lone last dimension: m*m strata
            return k, zero, jit, 1, m * m
        return (k // U32(m) if j % 2 else k % U32(m)), zero, jit, 1, m
    m, n = a, b
    if j % 2 == 0:  # x: column k mod m, sub-column permute(k // m, n, q SUBY_KEY)
        return k % U32(m), permute(k // U32(m), n, q * U32(rb.SUBY_KEY)), jit, n, m
    return k // U32(m), permute(k % U32(m), m, q * U32(rb.SUBX_KEY)), jit, m, n


def check_clamped(name: str, size: tuple[int, int], x: np.ndarray, i, p, jitter: float,
                  what: str) -> tuple[int, int]:
    """The values ``x`` (``(..., dims)``, from sample indices ``i`` and seeds ``p``
    that broadcast to ``x[..., 0]``) lie in their cells exactly, and the clamp is
    the only change to the float32 formula: a formula value inside its cell is
    kept bit for bit, one outside becomes the nearest float32 inside (the largest
    below the cell's upper edge, or the smallest at or above its lower edge).
    Returns the numbers of formula values above and below their cells."""
    above = below = 0
    for j in range(x.shape[-1]):
        stratum, sub, jit, M, s = construction(name, size, i, j, p, jitter)
        stratum, sub, jit = np.broadcast_arrays(stratum, sub, jit)
        n, xj = s * M, x[..., j]
        c = stratum.astype(np.int64) * M + sub
        bad = np.argwhere(cells(xj, n) != c)
        assert bad.size == 0, (f"{what}: dim {j}: {len(bad)} values outside their cell of {n}; first at "
                               f"{tuple(bad[0])}: {xj[tuple(bad[0])]!r} not in cell {c[tuple(bad[0])]}")
        u = unclamped(stratum, sub, jit, M, s)
        cu = cells(u, n)
        inside, up, down = cu == c, cu > c, cu < c
        assert_same_bits(xj[inside], u[inside], f"{what}: dim {j}: a value inside its cell was changed")
        assert np.all(cells(np.nextafter(xj[up], F32(np.inf)), n) == c[up] + 1), f"{what}: dim {j}: not the top"
        assert np.all(cells(np.nextafter(xj[down], F32(-np.inf)), n) == c[down] - 1), f"{what}: dim {j}: not the bottom"
        above += int(up.sum())
        below += int(down.sum())
    return above, below


#: (name, size, sample count (None: all N samples, else that many random ones), seeds, lower)
#: ``lower``: N is no power of two, so formula values also fall below their cells.
CLAMP_CASES = [
    pytest.param("jittered2d", (64, 3), None, 48, False, id="jittered2d-64x64"),
    pytest.param("jittered2d", (181, 3), None, 8, True, id="jittered2d-181x181"),
    pytest.param("jittered2d", (4096, 3), 1 << 16, 8, False, id="jittered2d-4096x4096"),
    pytest.param("jittered2d", (4093, 1), 1 << 16, 8, True, id="jittered2d-4093x4093"),
    pytest.param("cmj2d", (64, 64), None, 64, False, id="cmj2d-64x64"),
    pytest.param("cmj2d", (1000, 1009), 1 << 16, 8, True, id="cmj2d-1000x1009"),
    pytest.param("cmj2d", (4096, 4096), 1 << 16, 8, False, id="cmj2d-4096x4096"),
    pytest.param("cmj2d", (4093, 4093), 1 << 16, 8, True, id="cmj2d-4093x4093"),
]


@pytest.mark.parametrize("name, size, n_samples, n_seeds, lower", CLAMP_CASES)
def test_clamp_keeps_values_in_their_cells(name, size, n_samples, n_seeds, lower):
    """Why the checks above can use ``floor(x * N)``: the float32 formula rounds
    values onto or across their cells' edges (``stratum + jitter`` rounds up to
    the next integer for jitter within half an ulp of 1; a division by an N that
    is no power of two can round below ``c / N``), and the clamp puts exactly
    those back. The counts of such values make sure the test cannot pass
    without the clamp doing something: N = 4096 already has some per 10**5
    values, N near 2**24 (cells of one float32 step near 1) a third of them.
    Random sample indices stand for all N of the large sets."""
    a, b = size
    N = a * a if name == "jittered2d" else a * b
    dims = b if name == "jittered2d" else 2
    p = (np.arange(1, n_seeds + 1, dtype=U32) * U32(0x9E3779B1))[:, None]
    if n_samples is None:
        i = np.arange(N, dtype=U32)[None, :]
    else:
        i = np.random.default_rng(N).integers(0, N, (1, n_samples)).astype(U32)
    fn = nb.jittered2d if name == "jittered2d" else nb.cmj2d
    x = np.stack([fn(i, U32(j), a, b, p, 1.0) for j in range(dims)], axis=-1)
    above, below = check_clamped(name, size, x, i, p, 1.0, f"{name} {a}x{b}")
    assert above + below > 0, f"{name} {a}x{b}: no formula value outside its cell: the test shows nothing"
    assert below > 0 or not lower, f"{name} {a}x{b}: no formula value below its cell: the lower clamp is untested"


@pytest.mark.parametrize("name, spp, dims", [("jittered2d", 4096, 3), ("cmj2d", 4096, 2)])
def test_clamp_keeps_sampler_values_in_their_cells(backend, name, spp, dims):
    """The same on ``generate`` of each backend (the kernels clamp too)."""
    pixels = np.arange(64, dtype=U32)
    smp = pyoa.sampler(name, spp=spp, dims=dims, seed=2024, backend=backend)
    m, n = most_square(spp)
    size = (m, dims) if name == "jittered2d" else (m, n)
    p = pixel_seed(U32(2024), pixels)[:, None]
    i = np.arange(spp, dtype=U32)[None, :]
    above, below = check_clamped(name, size, smp.generate(pixels=pixels.tolist()), i, p, 1.0,
                                 f"{name} sampler [{backend}]")
    assert above + below > 0, f"{name}: no formula value outside its cell: the test shows nothing"


# =============================================================================== sobol02

def check_sobol02(x: np.ndarray, what: str) -> None:
    for a in range(0, x.shape[2] - 1, 2):
        assert_dyadic_net(x[:, :, a], x[:, :, a + 1], f"{what}: pair ({a},{a + 1})")
    if x.shape[2] % 2:
        assert_dyadic_net(x[:, :, -1], None, f"{what}: lone last dim")


@pytest.mark.parametrize("log2n", [0, 1, 2, 5, 8, 10])
def test_sobol02_elementary_intervals_many_seeds(log2n):
    x = grid(nb.sobol02, 1 << log2n, range(5), P_SEEDS, log2n)
    check_sobol02(x, f"sobol02 N=2^{log2n}")


@given(p=seeds, log2n=st.integers(0, 9), dim0=st.integers(0, 2**19).map(lambda d: 2 * d))
def test_sobol02_hypothesis(p, log2n, dim0):
    x = grid(nb.sobol02, 1 << log2n, [dim0, dim0 + 1], [p], log2n)
    assert_dyadic_net(x[:, :, 0], x[:, :, 1], f"sobol02 p={p} N=2^{log2n} pair ({dim0},{dim0 + 1})")


def test_sobol02_sampler_pixels(backend):
    for seed in (0, 3):
        smp = pyoa.sampler("sobol02", spp=256, dims=7, seed=seed, backend=backend)
        check_sobol02(smp.generate(pixels=PIXELS), f"sampler seed={seed}")


def test_sobol02_unrandomized_is_first_two_sobol_dims():
    """p = 0: the plain first two Sobol dimensions in natural order, the same
    set of points as SciPy's first 2**k (which come in Gray-code order)."""
    from scipy.stats import qmc

    N = 256
    x = grid(nb.sobol02, N, range(4), [0], 8)[0].astype(np.float64)
    s = qmc.Sobol(2, scramble=False).random(N)
    ours = sorted(map(tuple, np.floor(x[:, :2] * 2**24).astype(np.int64).tolist()))
    theirs = sorted(map(tuple, np.floor(s * 2**24).astype(np.int64).tolist()))
    assert ours == theirs
    g = np.arange(N)
    gray = g ^ (g >> 1)
    assert np.array_equal(np.floor(x[gray, 0] * 2**24), np.floor(s[:, 0] * 2**24)), "p=0 order is not natural"
    assert np.array_equal(x[:, 2:], x[:, :2]), "p=0: every pair is the same plain set"


def test_sobol02_pairs_have_independent_sample_orders():
    """The per-pair index shuffle: without it every pair visits its dyadic cells in
    the same order, and floor(2 x_0) XOR floor(2 x_2) (the first bit of the
    sample's Sobol index, each flipped by a per-pair constant) would be the
    same for every sample of a pixel. With it the orders differ."""
    N = 64
    P = 200
    x = pyoa.sampler("sobol02", spp=N, dims=6, seed=17, backend="numpy").generate(pixels=range(P))
    for a, b in [(0, 2), (0, 4), (2, 4), (1, 3)]:
        xor = (x[:, :, a] >= 0.5) ^ (x[:, :, b] >= 0.5)
        constant = np.all(xor == xor[:, :1], axis=1)
        assert constant.sum() <= 2, (f"dims {a} and {b}: the two pairs share their sample order in "
                                     f"{constant.sum()} of {P} pixels (missing per-pair index shuffle?)")
        # and the orders are not identical at the finest level either
        same = np.all(np.argsort(x[:, :, a], axis=1) == np.argsort(x[:, :, b], axis=1), axis=1)
        assert same.sum() == 0, f"dims {a}, {b}: identical sample order in {same.sum()} pixels"


def test_sobol02_is_owen_scrambled_not_digitally_shifted():
    """N = 2: the two points are Sobol points 0 and 1/2 (dimension 0) scrambled.
    Nested (Owen) scrambling draws the bits below the first independently for
    the two halves, so |x_0 - x_1| = 1/2 exactly only by chance (2**-23); an XOR
    (digital shift) scramble keeps it exactly 1/2."""
    x = pyoa.sampler("sobol02", spp=2, dims=4, seed=8, backend="numpy").generate(pixels=range(300))
    d = np.abs(x[:, 0, :].astype(np.float64) - x[:, 1, :])
    assert np.all((x[:, 0, :] < 0.5) != (x[:, 1, :] < 0.5)), "N=2 is not stratified in halves"
    assert np.count_nonzero(d == 0.5) <= 2, f"{np.count_nonzero(d == 0.5)} of {d.size} pairs differ by exactly 1/2"


# =============================================================================== sobol

@pytest.mark.parametrize("d, n", [(1, 1024), (2, 64), (40, 4096), (512, 256)])
def test_sobol_unscrambled_equals_scipy(d, n):
    from scipy.stats import qmc

    want = np.floor(qmc.Sobol(d, scramble=False).random(n) * 2**24)
    got = grid(nb.sobol, n, range(d), [0])[0].astype(np.float64) * 2**24
    bad = np.argwhere(got != want)
    assert bad.size == 0, f"{len(bad)} values differ from scipy; first (i, j) = {tuple(bad[0])}"


def test_sobol_unscrambled_last_dimensions_equal_scipy():
    from scipy.stats import qmc

    n = 64
    dims = list(range(21185, 21201))
    want = np.floor(qmc.Sobol(21201, scramble=False).random(n)[:, dims] * 2**24)
    got = grid(nb.sobol, n, dims, [0])[0].astype(np.float64) * 2**24
    bad = np.argwhere(got != want)
    assert bad.size == 0, f"{len(bad)} values differ from scipy; first (i, dim) = {bad[0][0], dims[bad[0][1]]}"
    # and the pure-Python reference, on a few
    for i in (0, 1, 5, 37, 63):
        for c, j in enumerate(dims[-4:]):
            assert rb.sobol(i, j, 0) * 2**24 == want[i, c + len(dims) - 4], (i, j)


def joe_kuo_directions(poly: int, vinit, bits: int = 32) -> list[int]:
    """The direction numbers V_1..V_bits of one dimension, written from Joe and
    Kuo's generator (the "V form" of the Bratley-Fox recurrence, not the m form
    pyoa.tables.sequences uses): V_i = m_i 2^(32-i) for i <= s, then
    V_i = V_(i-s) ^ (V_(i-s) >> s) ^ XOR_(k=1..s-1) a_k V_(i-k), where SciPy's
    ``poly`` holds x^s + a_1 x^(s-1) + ... + a_(s-1) x + 1 as bits."""
    s = poly.bit_length() - 1
    a = (poly >> 1) & ((1 << (s - 1)) - 1) if s > 1 else 0
    V = [0] * (bits + 1)  # 1-based
    for i in range(1, bits + 1):
        if i <= s:
            V[i] = int(vinit[i - 1]) << (32 - i)
        else:
            V[i] = V[i - s] ^ (V[i - s] >> s)
            for k in range(1, s):
                if (a >> (s - 1 - k)) & 1:
                    V[i] ^= V[i - k]
    return V[1:]


def test_sobol_direction_numbers_follow_joe_kuo():
    """All 32 direction numbers, so also the bits the unscrambled-vs-SciPy tests
    (small n) never reach in the high dimensions (degree up to 18 there)."""
    from importlib import resources

    with resources.as_file(resources.files("scipy.stats") / "_sobol_direction_numbers.npz") as f, np.load(f) as d:
        poly, vinit = d["poly"], d["vinit"]
    V = sequences.sobol_matrices()
    assert V.shape == (sequences.SOBOL_MAX_DIMS, 32) == (21201, 32) and V.dtype == np.uint32
    assert not V.flags.writeable
    assert V[0].tolist() == [1 << (31 - k) for k in range(32)], "dimension 0 is not van der Corput"
    rng = np.random.default_rng(6)
    dims = list(range(1, 48)) + sorted(rng.choice(np.arange(48, 21185), 60, replace=False).tolist()) + \
        list(range(21185, 21201))
    for j in dims:
        want = joe_kuo_directions(int(poly[j]), vinit[j])
        assert V[j].tolist() == want, f"Sobol dimension {j}: direction numbers differ from the Joe-Kuo recurrence"
    # SciPy's own direction numbers at 32 bits (a private attribute: only where it exists)
    from scipy.stats import qmc

    sv = getattr(qmc.Sobol(21201, scramble=False, bits=32), "_sv", None)
    if sv is not None and sv.shape == V.shape:
        assert np.array_equal(np.asarray(sv, np.uint64), V.astype(np.uint64))


def check_sobol(x: np.ndarray, dims, what: str) -> None:
    for c, j in enumerate(dims):
        assert_dyadic_net(x[:, :, c], None, f"{what}: dim {j}")
    if dims[:2] == [0, 1]:
        assert_dyadic_net(x[:, :, 0], x[:, :, 1], f"{what}: dims (0,1)")


SOBOL_DIMS = [0, 1, 2, 3, 4, 7, 30, 100, 1000, 5000, 21198, 21199, 21200]


def test_sobol_scrambled_nets_many_seeds():
    x = grid(nb.sobol, 1024, SOBOL_DIMS, P_SEEDS)
    check_sobol(x, SOBOL_DIMS, "sobol N=1024")


@given(p=seeds, log2n=st.integers(0, 10), dim=st.integers(2, 21200))
def test_sobol_hypothesis(p, log2n, dim):
    dims = [0, 1, dim]
    check_sobol(grid(nb.sobol, 1 << log2n, dims, [p]), dims, f"sobol p={p} N=2^{log2n}")


def test_sobol_sampler_pixels(backend):
    for seed in (0, 12):
        smp = pyoa.sampler("sobol", spp=512, dims=64, seed=seed, backend=backend)
        check_sobol(smp.generate(pixels=PIXELS), list(range(64)), f"sampler seed={seed}")


def test_sobol_is_owen_scrambled_not_digitally_shifted():
    """Samples 0 and 1 are Sobol points 0 and 1/2 in every dimension; after
    nested scrambling they differ by exactly 1/2 only by chance."""
    x = pyoa.sampler("sobol", spp=2, dims=64, seed=4, backend="numpy").generate(pixels=range(100))
    d = np.abs(x[:, 0, :].astype(np.float64) - x[:, 1, :])
    assert np.all((x[:, 0, :] < 0.5) != (x[:, 1, :] < 0.5))
    assert np.count_nonzero(d == 0.5) <= 2, f"{np.count_nonzero(d == 0.5)} of {d.size} pairs differ by exactly 1/2"


# =============================================================================== halton

def test_halton_primes():
    got = sequences.primes()
    assert sequences.HALTON_MAX_DIMS == 6542 == len(got)
    assert got.tolist() == PRIMES[:6542]
    assert PRIMES[6542] > 2**16 > PRIMES[6541] == 65521


def radical_inverse24(i: int, b: int) -> Fraction:
    """floor(2**24 RI_b(i)) / 2**24 with RI_b(i) = sum d_k b**-k (d_1 the least
    significant digit of i), exactly."""
    ri, scale = Fraction(0), Fraction(1, b)
    while i:
        i, d = divmod(i, b)
        ri += d * scale
        scale /= b
    return Fraction(math.floor(ri * 2**24), 2**24)


def test_halton_unscrambled_is_radical_inverse():
    dims = list(range(12)) + [100, 1000, 6540, 6541]
    idx = list(range(200)) + [242, 243, 65520, 65521, 65522, 12345678, 2**24 - 2, 2**24 - 1]
    x = nb.halton(np.array(idx, np.uint32)[:, None], np.array(dims, np.uint32)[None, :], 0)
    for c, j in enumerate(dims):
        b = PRIMES[j]
        for r, i in enumerate(idx):
            want = radical_inverse24(i, b)
            assert Fraction(float(x[r, c])) == want, f"halton p=0 dim {j} (base {b}) i={i}: {x[r, c]!r} != {want}"
    for j, i in [(0, 5), (1, 7), (5, 12345678), (6541, 65522), (6541, 2**24 - 1)]:
        assert Fraction(rb.halton(i, j, 0)) == radical_inverse24(i, PRIMES[j]), (i, j)


def check_halton(x: np.ndarray, dims, what: str) -> None:
    """x: (sets, n, len(dims)); in dim j of base b, for every k with b**k <= n
    the first b**k samples are one in each interval [a, a+1) / b**k (exact, with
    the truncated boundaries of the module docstring)."""
    n = x.shape[1]
    for c, j in enumerate(dims):
        b = PRIMES[j]
        assert b <= n, f"{what}: dim {j} (base {b}) needs at least {b} samples, got {n}"
        k = 1
        while b**k <= n:
            assert_one_per_closed_cell(candidates(x[:, : b**k, c], truncated_bounds(b**k)) + (b**k,),
                                       what=f"{what}: dim {j} (base {b}), first {b**k} samples")
            k += 1


def test_halton_scrambled_stratified_many_seeds():
    dims = [0, 1, 2, 3, 4, 5, 10, 25, 100, 300]  # bases 2 .. 1993
    x = grid(nb.halton, 2048, dims, P_SEEDS)
    check_halton(x, dims, "halton N=2048")
    for j in (1000, 6541):  # bases 7927 and 65521 (the largest): b samples, one per interval
        b = PRIMES[j]
        check_halton(grid(nb.halton, b, [j], P_SEEDS[:6]), [j], "halton")


def test_halton_boundary_truncation_happens():
    """The truncation onto an interval's upper boundary really occurs (so the exact
    closed-interval check is needed, not floor): with floor(x * b**k) some
    first-b**k sets look unstratified although no point is misplaced."""
    n = 3**5
    x = grid(nb.halton, n, [1], np.arange(1, 2001, dtype=np.uint32) * 0x9E3779B1)[:, :, 0]
    naive = np.all(np.sort(np.floor(x.astype(np.float64) * n), axis=1) == np.arange(n), axis=1)
    assert not naive.all(), "no truncation onto a boundary in 2000 sets (expected a few)"
    assert_one_per_closed_cell(candidates(x, truncated_bounds(n)) + (n,), what="halton base 3, first 243")


@given(p=seeds, j=st.integers(0, 6541), n=st.integers(1, 700))
def test_halton_hypothesis(p, j, n):
    n = max(n, PRIMES[j])  # at least one level: b samples in b intervals
    x = nb.halton(np.arange(n, dtype=np.uint32), j, p)[None, :, None]
    check_halton(x, [j], f"halton p={p}")


def test_halton_2d_prefixes_of_dims_0_and_1():
    """Dims 0 and 1 (bases 2 and 3): the first 2**a 3**c samples have one point in
    each of the 2**a x 3**c boxes (digit scrambling permutes the boxes; Chinese
    remainder theorem)."""
    for a, c in [(1, 1), (2, 1), (3, 2), (4, 3), (6, 4)]:
        n = 2**a * 3**c
        x = grid(nb.halton, n, [0, 1], P_SEEDS)
        assert_one_per_closed_cell(candidates(x[:, :, 0], truncated_bounds(2**a)) + (2**a,),
                                   candidates(x[:, :, 1], truncated_bounds(3**c)) + (3**c,), f"halton {2**a}x{3**c}")


def test_halton_is_owen_scrambled_not_positional():
    """Each digit is permuted by a hash of the digits before it (nested). i = 0 and
    i = 1 differ only in their first digit; with positional (per-digit-position)
    scrambling all their later scrambled digits would agree, so b x_0 - b x_1
    would be an integer (up to the 24-bit truncation)."""
    dims = [0, 1, 2, 3, 7, 50]
    x = pyoa.sampler("halton", spp=2, dims=51, seed=6, backend="numpy").generate(pixels=range(200), dims=dims)
    for c, j in enumerate(dims):
        b = PRIMES[j]
        t = (x[:, 0, c].astype(np.float64) - x[:, 1, c]) * b
        tail_equal = np.abs(t - np.round(t)) <= b * 2.0**-23
        assert tail_equal.sum() <= 2, (f"dim {j} (base {b}): samples 0 and 1 share every digit after the first "
                                       f"in {tail_equal.sum()} of 200 pixels (digit permutations not nested?)")


def test_halton_sampler_pixels(backend):
    dims = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9]
    for seed in (0, 21):
        smp = pyoa.sampler("halton", spp=1000, dims=10, seed=seed, backend=backend)
        check_halton(smp.generate(pixels=PIXELS), dims, f"sampler seed={seed}")


# =============================================================================== random

@given(p=seeds, j=st.integers(0, 2**20), i=st.integers(0, U32_MAX))
def test_random_values_are_24_bit_in_unit_interval(p, j, i):
    v = rb.random(i, j, p)
    assert 0 <= v < 1 and v * 2**24 == int(v * 2**24)
    assert float(nb.random(i, j, p)) == v


def test_random_few_collisions():
    """mix32 is a bijection: distinct samples give distinct 32-bit hashes, and two
    of n share a 24-bit value only through the truncation, each pair with
    probability 255 / (2**32 - 1): about n**2 / 2**25 collisions."""
    n = 1 << 14
    expected = n * (n - 1) / 2 * 255 / (2**32 - 1)  # ~8
    for p, j in [(0, 0), (1, 3), (U32_MAX, 2**20 - 1), (123456789, 77)]:
        x = nb.random(np.arange(n, dtype=np.uint32), j, p)
        assert np.all((x >= 0) & (x < 1))
        dup = n - np.unique(x).size
        assert dup <= expected + 6 * math.sqrt(expected) + 2, f"p={p} j={j}: {dup} collisions, ~{expected:.1f} expected"


def test_random_uniform_chi_square(backend):
    smp = pyoa.sampler("random", spp=1024, dims=8, seed=2024, backend=backend)
    x = smp.generate(pixels=range(128)).astype(np.float64)
    bins = 1024
    dof = bins - 1
    bound = 7 * math.sqrt(2 * dof)

    def chi2(counts):
        e = counts.sum() / counts.size
        return ((counts - e) ** 2 / e).sum()

    for j in range(8):
        c = chi2(np.bincount(np.floor(x[:, :, j] * bins).astype(int).ravel(), minlength=bins))
        assert abs(c - dof) < bound, f"dim {j}: chi-square {c:.0f} for {dof} degrees of freedom"
    for a, b in [(0, 1), (0, 5), (3, 4)]:
        cell = np.floor(x[:, :, a] * 32).astype(int) * 32 + np.floor(x[:, :, b] * 32).astype(int)
        c = chi2(np.bincount(cell.ravel(), minlength=bins))
        assert abs(c - dof) < bound, f"dims ({a},{b}): 2D chi-square {c:.0f} for {dof} degrees of freedom"


# =============================================================================== reference, small sets

def test_reference_small_sets_are_stratified():
    """The pure-Python reference alone, on small sets (the same properties)."""
    ps = [0, 1, U32_MAX, 0xDEADBEEF]
    m, dims = 3, 3
    x = np.array([[[rb.jittered2d(i, j, m, dims, p) for j in range(dims)] for i in range(m * m)] for p in ps], F32)
    check_jittered2d(x, m, dims, "reference jittered2d")
    N, (cm, cn) = 12, most_square(12)
    x = np.array([[[rb.cmj2d(i, j, cm, cn, p) for j in range(3)] for i in range(N)] for p in ps], F32)
    check_cmj2d(x, N, 3, "reference cmj2d")
    x = np.array([[[rb.sobol02(i, j, 4, p) for j in range(4)] for i in range(16)] for p in ps], F32)
    check_sobol02(x, "reference sobol02")
    x = np.array([[[rb.sobol(i, j, p) for j in (0, 1, 21200)] for i in range(16)] for p in ps], F32)
    check_sobol(x, [0, 1, 21200], "reference sobol")
    x = np.array([[[rb.halton(i, j, p) for j in (0, 1, 2)] for i in range(27)] for p in ps], F32)
    check_halton(x, [0, 1, 2], "reference halton")


# =============================================================================== unbiasedness (docs/spec.md 8.6)

UNBIASED = [("random", 64), ("jittered2d", 64), ("cmj2d", 60), ("sobol02", 64), ("halton", 64), ("sobol", 64)]


@pytest.mark.parametrize("name, spp", UNBIASED, ids=[n for n, _ in UNBIASED])
@pytest.mark.parametrize("dims", [5, 6])
def test_unbiased(backend, name, spp, dims):
    """400 pixels = 400 independent randomizations: the mean of the per-pixel
    estimates of known integrals is within 5 empirical standard errors."""
    P = 400
    x = pyoa.sampler(name, spp=spp, dims=dims, seed=31, backend=backend).generate(pixels=range(P))
    x = x.astype(np.float64)
    integrands = {
        "prod(1 + (x_k - 1/2) / 2)": (np.prod(1 + 0.5 * (x - 0.5), axis=2), 1.0),
        "[x0 + x1 < 1]": (x[:, :, 0] + x[:, :, 1] < 1, 0.5),
        "[x1 + x2 < 1]": (x[:, :, 1] + x[:, :, 2] < 1, 0.5),
        "[x0 < 0.3][x_last > 0.6]": ((x[:, :, 0] < 0.3) & (x[:, :, -1] > 0.6), 0.3 * 0.4),
        "x0 x_last": (x[:, :, 0] * x[:, :, -1], 0.25),
    }
    for label, (f, exact) in integrands.items():
        est = np.mean(f, axis=1)
        se = est.std(ddof=1) / math.sqrt(P)
        err = abs(est.mean() - exact)
        # 1e-6: a zero-variance estimator may still differ by float32 rounding of the points
        assert err <= 5 * se + 1e-6, (f"{name} spp={spp} dims={dims}: {label}: mean {est.mean():.6f} vs exact "
                                      f"{exact} ({err / max(se, 1e-300):.1f} standard errors, se={se:.2e})")


@pytest.mark.parametrize("name", NAMES)
def test_single_point_uniform_over_randomizations(name):
    """What unbiasedness rests on: over independent randomizations (pixels) one
    sample point is uniform in every 2D projection. One sample per pixel (i =
    pixel mod 16, pixels independent), so the counts in 16 x 16 cells are
    multinomial; a 7-sigma chi-square bound."""
    P, N = 8192, 16
    smp = pyoa.sampler(name, spp=N, dims=4, seed=77, backend="numpy")
    x = smp.generate(pixels=range(P)).astype(np.float64)
    x = x[np.arange(P), np.arange(P) % N, :]
    dof = 255
    for a, b in [(0, 1), (1, 2), (0, 3), (2, 3)]:
        cell = np.floor(x[:, a] * 16).astype(int) * 16 + np.floor(x[:, b] * 16).astype(int)
        counts = np.bincount(cell, minlength=256)
        chi2 = ((counts - P / 256) ** 2 / (P / 256)).sum()
        assert abs(chi2 - dof) < 7 * math.sqrt(2 * dof), (
            f"{name}: dims ({a},{b}) of one sample are not uniform over pixels: chi-square {chi2:.0f} "
            f"for {dof} degrees of freedom; {np.count_nonzero(counts == 0)} of 256 cells empty")


SMALL = [("random", 16), ("jittered2d", 16), ("cmj2d", 16), ("sobol02", 16), ("halton", 16), ("sobol", 16)]


@pytest.mark.parametrize("name, spp", SMALL, ids=[n for n, _ in SMALL])
def test_unbiased_for_small_squares(name, spp):
    """Unbiasedness below the resolution of the stratification: with 16 samples,
    the estimate of the area of each of the 256 squares [a, a+1) x [b, b+1) / 16
    (the fraction of a pixel's points in it) must average to 1/256 over 2048
    pixels. 6 empirical standard errors (512 squares are tested at once); a
    square no pixel ever reaches has zero variance and fails outright."""
    P = 2048
    x = pyoa.sampler(name, spp=spp, dims=3, seed=12, backend="numpy").generate(pixels=range(P))
    for a, b in [(0, 1), (1, 2)]:
        cell = (np.floor(x[:, :, a] * 16.0) * 16 + np.floor(x[:, :, b] * 16.0)).astype(np.int64)
        counts = np.zeros((P, 256))
        np.add.at(counts, (np.repeat(np.arange(P), spp), cell.ravel()), 1.0)
        est = counts / spp
        err = np.abs(est.mean(axis=0) - 1 / 256)
        se = est.std(axis=0, ddof=1) / math.sqrt(P)
        bad = np.flatnonzero(err > 6 * se + 1e-9)
        assert bad.size == 0, (
            f"{name}: dims ({a},{b}): {bad.size} of 256 squares have a biased area estimate; first "
            f"[{bad[0] // 16}/16, {bad[0] // 16 + 1}/16) x [{bad[0] % 16}/16, {bad[0] % 16 + 1}/16): mean "
            f"{est.mean(axis=0)[bad[0]]:.5f} vs {1 / 256:.5f} (se {se[bad[0]]:.1e}); "
            f"{np.count_nonzero(counts.sum(axis=0) == 0)} squares never reached")


@pytest.mark.parametrize("N", [16, 60, 120])
def test_cmj2d_column_and_subrow_are_independent(N):
    """In Kensler's CMJ [2] a point in column c of its pair lies in sub-row
    permute(c) of its row: the column and the sub-row are tied only through a
    random permutation, so over randomizations they are independent and the
    fraction of points with sub-row == column is 1/m on average. If the same
    permuted index sets both (column sx and sub-row sx), every point has
    sub-row == column and x, y are correlated (Cov = (m^2 - 1) / (12 m^2 n) > 0,
    a bias of E[x y])."""
    m, n = most_square(N)
    P = 400
    x = pyoa.sampler("cmj2d", spp=N, dims=2, seed=3, backend="numpy").generate(pixels=range(P)).astype(np.float64)
    col = np.floor(x[:, :, 0] * m)
    subrow = np.floor((x[:, :, 1] * n) % 1 * m)
    frac = np.mean(col == subrow)
    # per pixel the fraction is (fixed points of a random permutation) / m: mean 1/m, sd 1/m
    assert abs(frac - 1 / m) < 6 / (m * math.sqrt(P)), (
        f"cmj2d N={N} ({m}x{n}): {frac:.3f} of the points have sub-row == column, 1/m = {1 / m:.3f} expected")
    cov = np.mean(x[:, :, 0] * x[:, :, 1]) - 0.25
    est = np.mean(x[:, :, 0] * x[:, :, 1], axis=1)
    assert abs(cov) <= 5 * est.std(ddof=1) / math.sqrt(P) + 1e-6, f"cmj2d N={N}: E[x y] - 1/4 = {cov:.2e}"


# =============================================================================== catalogue and API

def test_samplers_lists_the_six():
    names = pyoa.samplers()
    for name in NAMES:
        assert names.get(name)


def test_valid_spp_catalogue():
    for name in ("sobol", "sobol02"):
        c = pyoa.valid_spp(name)
        assert [v.spp for v in c] == [2**k for k in range(25)]
        assert [v.detail for v in c] == [f"2^{k}" for k in range(25)]
    sq = pyoa.valid_spp("jittered2d")
    assert [v.spp for v in sq] == [m * m for m in range(1, 4097)]
    assert sq[0].detail == "1x1" and sq[10].detail == "11x11" and sq[-1].detail == "4096x4096"
    for name in ("random", "cmj2d", "halton"):
        c = pyoa.valid_spp(name)
        assert not isinstance(c, list) and len(c) == 2**24
        assert c[0].spp == 1 and c[-1].spp == 2**24 and c[2**24 - 1].spp == 2**24
        assert [v.spp for v in c[99:102]] == [100, 101, 102]
        with pytest.raises(IndexError):
            c[2**24]
    cm = pyoa.valid_spp("cmj2d")
    for N, detail in [(1, "1x1"), (2, "1x2"), (120, "10x12"), (128, "8x16"), (127, "1x127"), (36, "6x6"),
                      (4093, "1x4093"), (2**24, "4096x4096"), (2**23, "2048x4096")]:
        assert cm[N - 1].detail == detail, (N, cm[N - 1])
        assert detail == "{}x{}".format(*most_square(N))
    assert pyoa.valid_spp("random")[5].detail == "" and pyoa.valid_spp("halton")[5].detail == ""


@pytest.mark.parametrize("name, spp, near", [("sobol", 100, [64, 128]), ("sobol02", 3, [2, 4]),
                                             ("sobol", 2**24 + 5, [2**24]),
                                             ("jittered2d", 120, [100, 121]), ("jittered2d", 50, [49, 64]),
                                             ("random", 7, [6, 7, 8]), ("halton", 2**24, [2**24 - 1, 2**24]),
                                             ("cmj2d", 0, [1]), ("halton", 2**24 + 5, [2**24])])
def test_nearest_counts(name, spp, near):
    assert [c.spp for c in pyoa.valid_spp(name, near=spp)] == near


@pytest.mark.parametrize("name, spp, words", [("sobol", 100, ["100", "power of two", "64", "128"]),
                                              ("sobol02", 24, ["24", "16", "32"]),
                                              ("jittered2d", 120, ["120", "square", "100", "121", "cmj2d"])])
def test_invalid_count_errors_name_nearest(name, spp, words):
    with pytest.raises(ValueError) as exc:
        pyoa.sampler(name, spp=spp, dims=2)
    for w in words:
        assert w in str(exc.value), (w, str(exc.value))


def test_max_dims():
    h = pyoa.sampler("halton", spp=4, dims=6542, backend="numpy")
    assert h.generate(dims=[0, 6541]).shape == (1, 4, 2)
    s = pyoa.sampler("sobol", spp=4, dims=21201, backend="numpy")
    assert s.generate(dims=[21200]).shape == (1, 4, 1)
    for name, limit, dims in [("halton", 6542, 6543), ("sobol", 21201, 21202), ("sobol", 21201, 10**5)]:
        with pytest.raises(ValueError, match=f"at most {limit} dimensions"):
            pyoa.sampler(name, spp=4, dims=dims)
        with pytest.raises(ValueError, match=str(limit)):
            pyoa.valid_spp(name, dims=dims)
    for name in ("random", "jittered2d", "cmj2d", "sobol02"):  # padded or independent: up to MAX_DIMS
        assert pyoa.sampler(name, spp=4, dims=2**20, backend="numpy").generate(dims=[2**20 - 1]).shape == (1, 4, 1)
    with pytest.raises(ValueError):
        rb.halton(0, 6542, 1)
    with pytest.raises(ValueError):
        rb.sobol(0, 21201, 1)


@pytest.mark.parametrize("name", NAMES)
def test_options_refused_or_accepted(name):
    spp = 16
    for offset in ("cmj", "j", "centered"):
        with pytest.raises(ValueError, match="offset"):
            pyoa.sampler(name, spp=spp, dims=2, offset=offset)
    with pytest.raises(ValueError, match="strength"):
        pyoa.sampler(name, spp=spp, dims=2, strength=2)
    assert pyoa.sampler(name, spp=spp, dims=2, jitter=1.0).jitter == 1.0
    if name in ("jittered2d", "cmj2d"):
        for jitter in (0.0, 0.5, 0.25):
            smp = pyoa.sampler(name, spp=spp, dims=2, jitter=jitter, backend="numpy")
            assert smp.jitter == jitter and f"jitter={jitter:g}" in repr(smp)
        with pytest.raises(ValueError, match="jitter"):
            pyoa.sampler(name, spp=spp, dims=2, jitter=1.5)
    else:
        for jitter in (0.0, 0.5, 0.999):
            with pytest.raises(ValueError, match="jitter"):
                pyoa.sampler(name, spp=spp, dims=2, jitter=jitter)


@pytest.mark.parametrize("name, spp, grid_text", [("random", 10, None), ("jittered2d", 64, "8x8"),
                                                  ("cmj2d", 120, "10x12"), ("cmj2d", 128, "8x16"),
                                                  ("sobol02", 32, "2^5"), ("halton", 10, None), ("sobol", 128, "2^7")])
def test_value_equals_generate_and_repr(backend, name, spp, grid_text):
    smp = pyoa.sampler(name, spp=spp, dims=5, seed=9, backend=backend)
    pixels = [0, 3, U32_MAX]
    x = smp.generate(pixels=pixels)
    for a, px in enumerate(pixels):
        for i in (0, 1, spp - 1):
            for j in (0, 3, 4):
                assert x[a, i, j] == F32(smp.value(px, i, j)), (px, i, j)
                assert np.float32(smp.value(px, i, j)).view(np.uint32) == x[a, i, j].view(np.uint32)
    r = repr(smp)
    assert r.startswith(f"Sampler({name!r}, spp={spp}, dims=5, seed=9") and "offset" not in r
    if grid_text:
        assert f"grid {grid_text}" in r, r
    else:
        assert "grid" not in r, r


# =============================================================================== command line


@pytest.mark.parametrize("name, spp, extra", [("random", 10, []), ("jittered2d", 16, ["--jitter", "0.5"]),
                                              ("cmj2d", 12, []), ("sobol02", 16, []), ("halton", 10, []),
                                              ("sobol", 32, [])])
def test_cli_points(tmp_path, capsys, name, spp, extra):
    out = tmp_path / "x.npy"
    args = ["points", name, "--spp", spp, "--dims", 5, "--pixels", 3, "--pixel0", 7,
            "--seed", 42, "--backend", "numpy", "--out", out, *extra]
    code, stdout, err = run_cli(args, capsys)
    assert code == 0, err
    assert f"Sampler({name!r}" in stdout and "x.npy" in stdout
    jitter = float(extra[1]) if extra else 1.0
    want = pyoa.sampler(name, spp=spp, dims=5, seed=42, jitter=jitter, backend="numpy").generate(pixels=range(7, 10))
    assert_same_bits(np.load(out), want, f"pyoa points --sampler {name}")


def test_cli_points_refuses_offset_for_baselines(tmp_path, capsys):
    code, _, err = run_cli(["points", "sobol", "--spp", 16, "--offset", "mj", "--out",
                            tmp_path / "x.npy"], capsys)
    assert code == 2 and "offset" in err
    code, _, err = run_cli(["points", "sobol", "--spp", 100, "--out", tmp_path / "x.npy"], capsys)
    assert code == 2 and "64" in err and "128" in err
    assert not (tmp_path / "x.npy").exists()


def test_cli_spp_and_samplers(capsys):
    code, out, _ = run_cli(["spp", "sobol"], capsys)
    assert code == 0
    rows = [line.split() for line in out.splitlines()[1:]]
    assert [int(r[0]) for r in rows] == [2**k for k in range(25)]
    assert [r[1] for r in rows] == [f"2^{k}" for k in range(25)]
    code, out, _ = run_cli(["spp", "cmj2d", "--near", 120], capsys)
    assert code == 0 and re.search(r"\b120\s+10x12\b", out) and re.search(r"\b121\s+11x11\b", out)
    code, out, _ = run_cli(["spp", "halton", "--limit", 3], capsys)
    assert code == 0 and "16777213 more" in out
    code, out, _ = run_cli(["samplers"], capsys)
    assert code == 0 and all(re.search(rf"^{n}\s", out, re.MULTILINE) for n in NAMES)
