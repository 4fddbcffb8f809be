"""The pmj02 table builder: ``SETS`` progressive multi-jittered (0,2) sequences of ``POINTS`` points.

The sampler that reads these tables, its randomization and the argument
that every prefix and aligned block stays a net are in :mod:`pyoa.reference.pmj02`;
this module is the construction alone, so that the fast builder and cache of
:mod:`pyoa.tables.pmj02` (and ``kernels/include/pyoa/pmj02_build.h``) can
follow it without importing the sampler that reads their tables.

The table builder
-----------------
Christensen, Kensler and Kilpatrick's pmj02 [1]_, with integer coordinates
and counter-based randomness. After ``n = 2**m`` points the set is a
(0,m,2)-net; the next ``n`` points complete a (0,m+1,2)-net:

* ``m`` even, ``n = 4**k``: the ``2**k x 2**k`` cells each hold one point;
  for each point ``i < n`` in order, point ``n + i`` goes into the
  *subquadrant* (the cell of the ``2**(k+1)`` grid) diagonally opposite
  point ``i``'s, inside the same cell.
* ``m`` odd, ``n = 2 * 4**k``: every cell holds two points in diagonally
  opposite subquadrants; the two remaining subquadrants are filled, points
  ``n .. n + n/2 - 1`` one of them (for the cell of point ``i < n/2``, in
  order) and points ``n + n/2 .. 2n - 1`` the other.

Which remaining subquadrant is filled first is, in the paper, a free (random)
choice per cell. pyoa draws one bit per pass instead and makes the same
choice in every cell (flip x first, or flip y first): the "balanced" rule of
S. Brown's and A. Helmer's pmj implementations [3]_. With it every aligned
block ``[a 2**k, (a+1) 2**k)`` of the sequence, not only every prefix, is a
(0,k,2)-net (as for Sobol's (0,2)-sequence); with per-cell random choices
blocks of 4 points are nets only half the time. Neither rule ever reached a
dead end (tried on 2000 sets of ``2**12`` points and 16 of ``2**16``).

Each new point of a pass that completes a net of ``2**M`` points (``M = m +
1``) is placed at random among the positions of its subquadrant whose
elementary intervals of every shape ``2**-u x 2**-(M-u)``, ``u = 0..M``,
are still empty (the 1D strata ``u = M`` and ``u = 0`` included). As Pharr
observed [2]_, that set is a product ``X x Y`` of 1D strata of width
``2**-M``, found by walking down two chains of intervals: the x chain starts
at the interval of shape ``(u, M - u) = (q, M - q)`` holding the
subquadrant (``q`` its level, ``M - q <= q``) and at each step halves the
width and doubles the height, keeping the empty intervals, down to the 1D x
strata (``u = M``); the y chain likewise. The point takes a uniformly chosen
stratum of each (a uniform index below the count ``n``: the low bits of a
draw, redrawn with the next attempt number while ``>= n``) and uniformly
random low ``24 - M`` bits inside it.

*The chains never branch.* The two intervals ``(u + 1, M - u - 1)`` below
an interval ``(u, M - u)`` are the halves of the interval ``(u, M - u -
1)`` of the coarser level ``M - 1``, which holds exactly one of the ``2**(M
- 1)`` old points (they are a (0,M-1,2)-net): at most one child is empty.
So the valid set is a single stratum per axis or none, the uniform index is
always 0 (no redraw ever happens) and the only freedom of pmj02 is the
subquadrant order and the low bits, as Helmer et al. [4]_ make explicit. A
subquadrant with no valid position would raise :class:`RuntimeError`; the
tests build every set and show it never happens.

**Randomness** is counter-based and machine-independent: set ``s`` has seed
``set_seed(s) = hash_pair(BUILD_SEED, s, PMJ02_BUILD_KEY)``, and every random
integer of the build is ``draw(seed, index, purpose, attempt)``, a hash of
the set seed, the index of the point being placed (or of the pass, ``n``),
what the number is for and the attempt number. Integer arithmetic only.

References
----------
.. [1] P. Christensen, A. Kensler, C. Kilpatrick, "Progressive Multi-Jittered
   Sample Sequences", Computer Graphics Forum 37(4) (EGSR 2018), 21-33.
.. [2] M. Pharr, "Efficient Generation of Points that Satisfy Two-Dimensional
   Elementary Intervals", Journal of Computer Graphics Techniques 8(1), 2019.
.. [3] A. Helmer, pmj-cpp (github.com/Andrew-Helmer/pmj-cpp),
   ``GetSubQuadrantsSwapXOrY``, crediting S. Brown's pmj (github.com/sjb3d/pmj).
.. [4] A. Helmer, P. Christensen, A. Kensler, "Stochastic Generation of (t, s)
   Sample Sequences", EGSR 2021 (Symposium Track).
"""

from __future__ import annotations

from .hashes import MASK, hash_pair

#: Key of the set seeds of the table build.
PMJ02_BUILD_KEY = 0x61C88647
#: Key of the build's random draws.
PMJ02_DRAW_KEY = 0x510E527F

#: Seed of the table build (the year of [1]_): set ``s`` has seed
#: ``hash_pair(BUILD_SEED, s, PMJ02_BUILD_KEY)``.
BUILD_SEED = 2018
#: Independent sequences in the table: ``h >> 28`` picks one.
SETS = 16
#: ``log2`` of the points per sequence, and the points.
POINTS_LOG2 = 16
POINTS = 1 << POINTS_LOG2
#: Bits of a table coordinate: the value is ``k * 2**-24``.
BITS = 24

#: Purposes of :func:`draw` (its third argument).
X_STRATUM, Y_STRATUM, X_LOW, Y_LOW, SWAP = range(5)


def set_seed(s: int) -> int:
    """Seed of set ``s`` of the table: ``hash_pair(BUILD_SEED, s, PMJ02_BUILD_KEY)``."""
    return hash_pair(BUILD_SEED, s, PMJ02_BUILD_KEY)


def draw(seed: int, index: int, purpose: int, attempt: int) -> int:
    """The build's random uint32 number ``attempt`` for ``purpose`` at point (or pass) ``index``::

        hash_pair(hash_pair(seed, index, PMJ02_DRAW_KEY), (attempt << 3) | purpose, PMJ02_DRAW_KEY)
    """
    return hash_pair(hash_pair(seed, index, PMJ02_DRAW_KEY), ((attempt << 3) | purpose) & MASK, PMJ02_DRAW_KEY)


def uniform_index(seed: int, index: int, purpose: int, n: int, stats: dict | None = None) -> int:
    """A uniform integer in ``[0, n)``: the low bits of :func:`draw` under the
    least all-ones mask covering ``n - 1``, redrawn with the next attempt
    number while ``>= n`` (exact, no modulo bias; ``n == 1`` gives 0)."""
    mask = (1 << (n - 1).bit_length()) - 1
    attempt = 0
    while True:
        r = draw(seed, index, purpose, attempt) & mask
        if r < n:
            if stats is not None:
                stats["redraws"] = stats.get("redraws", 0) + attempt
            return r
        attempt += 1


class Occupancy:
    """Which elementary intervals of area ``2**-M`` hold a point.

    ``cells[u][(a << (M - u)) | c]`` is set when the interval ``[a 2**-u,
    (a+1) 2**-u) x [c 2**-(M-u), (c+1) 2**-(M-u))`` holds one, for
    ``u = 0..M`` (``u = M``: the 1D x strata, ``u = 0``: the 1D y strata).
    """

    def __init__(self, M: int, xs, ys):
        self.M = M
        self.cells = [bytearray(1 << M) for _ in range(M + 1)]
        for x, y in zip(xs, ys):
            self.mark(x, y)

    def mark(self, x: int, y: int) -> None:
        """Mark every interval holding the point ``(x, y)`` (24-bit integers)."""
        M = self.M
        for u in range(M + 1):
            v = M - u
            self.cells[u][((x >> (BITS - u)) << v) | (y >> (BITS - v))] = 1

    def empty(self, u: int, a: int, c: int) -> bool:
        """Whether the interval of shape ``(u, M - u)`` with indices ``(a, c)`` is empty."""
        return not self.cells[u][(a << (self.M - u)) | c]

    def strata(self, q: int, qa: int, qb: int, axis: int) -> list[int]:
        """The 1D strata of width ``2**-M`` along ``axis`` (0: x, 1: y) where a
        point of the subquadrant ``(qa, qb)`` of the ``2**q`` grid (``qa``
        along ``axis``, ``qb`` along the other) meets only empty intervals:
        the chain walk of Pharr [2]_, in ascending order."""
        M = self.M
        chain = [qa]
        for t in range(q, M + 1):  # t bits along axis, M - t along the other
            cb = qb >> (q - (M - t))  # the subquadrant fixes the other axis' top M - t <= q bits
            if axis == 0:
                chain = [a for a in chain if self.empty(t, a, cb)]
            else:
                chain = [a for a in chain if self.empty(M - t, cb, a)]
            if t < M:
                chain = [2 * a + half for a in chain for half in (0, 1)]
        return chain


def place(occ: Occupancy, q: int, qx: int, qy: int, seed: int, index: int,
          stats: dict | None = None) -> tuple[int, int]:
    """Point ``index`` in subquadrant ``(qx, qy)`` of the ``2**q`` grid: a
    uniform stratum of each valid set, uniform low bits; marked in ``occ``.

    Raises
    ------
    RuntimeError
        The subquadrant has no valid position (a dead end of the construction).
    """
    M = occ.M
    X = occ.strata(q, qx, qy, 0)
    Y = occ.strata(q, qy, qx, 1)
    if not X or not Y:
        raise RuntimeError(f"pmj02 dead end: point {index} has no valid position in subquadrant "
                           f"({qx}, {qy}) of the 2^{q} grid at level {M} ({len(X)} x strata, {len(Y)} y strata)")
    if stats is not None:
        stats["max_strata"] = max(stats.get("max_strata", 0), len(X), len(Y))
    low = (1 << (BITS - M)) - 1
    x = (X[uniform_index(seed, index, X_STRATUM, len(X), stats)] << (BITS - M)) | (draw(seed, index, X_LOW, 0) & low)
    y = (Y[uniform_index(seed, index, Y_STRATUM, len(Y), stats)] << (BITS - M)) | (draw(seed, index, Y_LOW, 0) & low)
    occ.mark(x, y)
    return x, y


def check_points(points: int) -> None:
    """``points`` must be a power of two in ``[1, POINTS]``."""
    if not (1 <= points <= POINTS and points & (points - 1) == 0):
        raise ValueError(f"points must be a power of two in [1, {POINTS}], got {points}")


def build_set(s: int, points: int = POINTS, stats: dict | None = None) -> list[tuple[int, int]]:
    """The first ``points`` points of set ``s`` as 24-bit integer pairs: the
    readable reference of :func:`pyoa.tables.pmj02.build` (same bits).

    Parameters
    ----------
    s : int
        Set index (its seed is :func:`set_seed`).
    points : int
        A power of two in ``[1, POINTS]``; a prefix of the full set.
    stats : dict, optional
        Filled with ``max_strata`` (the largest valid set met, 1 by the
        argument in the module docstring) and ``redraws`` (0).
    """
    check_points(points)
    seed = set_seed(s)
    xs, ys = [0] * points, [0] * points
    xs[0], ys[0] = place(Occupancy(0, [], []), 0, 0, 0, seed, 0, stats)  # anywhere in the square
    n, m = 1, 0  # the first n = 2**m points are a (0,m,2)-net
    while n < points:
        occ = Occupancy(m + 1, xs[:n], ys[:n])
        q = m // 2 + 1  # subquadrants: cells of the 2**q grid
        if m % 2 == 0:  # n = 4**k: the diagonally opposite subquadrant of each point
            for i in range(n):
                sx, sy = xs[i] >> (BITS - q), ys[i] >> (BITS - q)
                xs[n + i], ys[n + i] = place(occ, q, sx ^ 1, sy ^ 1, seed, n + i, stats)
        else:  # n = 2 * 4**k: the two remaining subquadrants of each cell, in a balanced order
            h = n // 2
            fx = draw(seed, n, SWAP, 0) & 1  # flip x first (1) or y first (0), in every cell
            for i in range(h):
                sx, sy = xs[i] >> (BITS - q), ys[i] >> (BITS - q)
                xs[n + i], ys[n + i] = place(occ, q, sx ^ fx, sy ^ (1 - fx), seed, n + i, stats)
            for i in range(h):
                sx, sy = xs[i] >> (BITS - q), ys[i] >> (BITS - q)
                xs[n + h + i], ys[n + h + i] = place(occ, q, sx ^ (1 - fx), sy ^ fx, seed, n + h + i, stats)
        n, m = 2 * n, m + 1
    return list(zip(xs, ys))
