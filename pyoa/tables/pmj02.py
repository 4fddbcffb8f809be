"""The pmj02 table: 16 progressive multi-jittered (0,2) sequences of 2**16 points.

:func:`tables` returns a read-only ``uint32`` array of shape ``(SETS, POINTS,
2) = (16, 65536, 2)``, 8 MiB: coordinate ``c`` of point ``i`` of set ``s``
is ``k = table[s, i, c]``, a 24-bit integer, and the point is ``k * 2**-24``.
Every prefix of length ``2**k`` (``k = 0..16``) of every set is a
(0,k,2)-net (one point in every elementary interval ``2**-u x 2**-(k-u)``),
and so is every aligned block ``[a 2**k, (a+1) 2**k)``. The samplers
(:mod:`pyoa.reference.pmj02` and its NumPy and OpenCL twins) read it.

Algorithm
---------
Christensen, Kensler and Kilpatrick's pmj02 (EGSR 2018) with integer
coordinates, Pharr's product-of-strata search for valid positions (JCGT
2019), a balanced subquadrant order (one random choice per pass, as S.
Brown's and A. Helmer's implementations) and counter-based randomness from
pyoa's integer hashes, seeded per set by ``hash_pair(BUILD_SEED, s,
PMJ02_BUILD_KEY)``: the same bits on every machine. The algorithm, its
references and the argument that it never branches are in the docstring of
:mod:`pyoa.reference.pmj02`, whose :func:`~pyoa.reference.pmj02.build_set`
is the readable pure-Python version of :func:`build` (the tests check that
both give the same bits).

Build and cache
---------------
:func:`build` compiles the algorithm with numba on first use in a process
and builds the 16 sets: 5-12 s in all, of which 0.3-0.8 s is the build
(later builds take that long), measured with Python 3.11 and numba 0.68 at
4.6 s on a 2-core AMD EPYC VM, 9.1 s on an AMD EPYC Zen 5 and 11.6 s on 2
shared cores of an Intel Xeon (family 6 model 207); the pure-Python reference
takes 0.017 s for the first ``2**10`` points of one set and 1.5 s for a
whole set (on the 2-core AMD EPYC VM). Loading the cached file and checking
its SHA-256 takes about 10 ms. :func:`tables` builds the
table once and keeps it in a file, ``pmj02-v1-16x65536.npy`` in the cache
directory:

1. ``$PYOA_CACHE_DIR`` if set (and not empty),
2. else ``$XDG_CACHE_HOME/pyoa`` if ``XDG_CACHE_HOME`` is set,
3. else ``~/.cache/pyoa``,

written atomically (:mod:`pyoa.util.atomic`). A cached file is used only if its
shape, dtype and SHA-256 (:data:`TABLE_SHA256`, of the little-endian bytes)
are right; otherwise a :class:`RuntimeWarning` says so and the table is
rebuilt and rewritten. If the directory cannot be written the table is built
in memory, with one warning. Within a process the table is kept in memory
(:func:`functools.cache`; ``tables.cache_clear()`` forgets it).
"""

from __future__ import annotations

import functools
import hashlib
import os
import sys
import threading
import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..util.atomic import atomic_path
from ..reference.hashes import MASK
from ..reference.pmj02_build import (
    BITS,
    BUILD_SEED,
    PMJ02_DRAW_KEY,
    POINTS,
    POINTS_LOG2,
    SETS,
    SWAP,
    X_LOW,
    X_STRATUM,
    Y_LOW,
    Y_STRATUM,
    check_points,
    set_seed,
)

__all__ = ["BUILD_SEED", "CACHE_NAME", "POINTS", "POINTS_LOG2", "SETS", "SHAPE", "TABLE_SHA256",
           "build", "cache_dir", "cache_path", "table_sha256", "tables"]

#: Shape of the table: (sets, points, coordinates).
SHAPE = (SETS, POINTS, 2)
#: File name of the cached table (version 1 of the algorithm).
CACHE_NAME = f"pmj02-v1-{SETS}x{POINTS}.npy"
#: How long the first build takes, numba's compile included (the module docstring names the CPUs); the
#: build announces itself with it on stderr, and every doc that times the build gives this range.
BUILD_TIME = "5-12 s"
#: SHA-256 of the table's little-endian bytes, as :func:`build` makes it.
TABLE_SHA256 = "5c7049b680fae7663f3c77a2e03c3de50ebd77e3c6a4fd57a16d1087fd837cbd"

_lock = threading.Lock()
_warned_unwritable = False


# --------------------------------------------------------------------------- the numba builder

@functools.cache
def _kernels():
    """The numba-compiled builder (compiled on first use: importing this
    module does not import numba). Operation for operation the functions of
    :mod:`pyoa.reference.pmj02`, on int64 arrays."""
    import numba

    from .._numba.hashes import hash_pair

    jit = numba.njit(cache=False)

    @jit
    def draw(seed, index, purpose, attempt):
        return hash_pair(hash_pair(seed, index, PMJ02_DRAW_KEY), ((attempt << 3) | purpose) & MASK, PMJ02_DRAW_KEY)

    @jit
    def uniform_index(seed, index, purpose, n, stats):
        mask = 0
        while mask < n - 1:
            mask = 2 * mask + 1
        attempt = 0
        while True:
            r = draw(seed, index, purpose, attempt) & mask
            if r < n:
                stats[0] += attempt
                return r
            attempt += 1

    @jit
    def mark(cells, M, x, y):
        for u in range(M + 1):
            v = M - u
            cells[u, ((x >> (BITS - u)) << v) | (y >> (BITS - v))] = 1

    @jit
    def strata(cells, M, q, qa, qb, axis, chain, scratch):
        """Pharr's chain walk into chain[:count]; returns count."""
        chain[0] = qa
        count = 1
        for t in range(q, M + 1):
            cb = qb >> (q - (M - t))
            kept = 0
            for r in range(count):
                a = chain[r]
                if axis == 0:
                    full = cells[t, (a << (M - t)) | cb]
                else:
                    full = cells[M - t, (cb << t) | a]
                if full == 0:
                    if t < M:
                        scratch[kept] = 2 * a
                        scratch[kept + 1] = 2 * a + 1
                        kept += 2
                    else:
                        scratch[kept] = a
                        kept += 1
            for r in range(kept):
                chain[r] = scratch[r]
            count = kept
        return count

    @jit
    def place(cells, M, q, qx, qy, seed, index, xs, ys, chain, scratch, stats):
        """Point index in subquadrant (qx, qy) of the 2**q grid; False at a dead end."""
        nx = strata(cells, M, q, qx, qy, 0, chain, scratch)
        if nx == 0:
            return False
        stats[1] = max(stats[1], nx)
        x = chain[uniform_index(seed, index, X_STRATUM, nx, stats)]
        ny = strata(cells, M, q, qy, qx, 1, chain, scratch)
        if ny == 0:
            return False
        stats[1] = max(stats[1], ny)
        y = chain[uniform_index(seed, index, Y_STRATUM, ny, stats)]
        low = (1 << (BITS - M)) - 1
        x = (x << (BITS - M)) | (draw(seed, index, X_LOW, 0) & low)
        y = (y << (BITS - M)) | (draw(seed, index, Y_LOW, 0) & low)
        xs[index] = x
        ys[index] = y
        mark(cells, M, x, y)
        return True

    @jit
    def remark(cells, M, n, xs, ys):
        cells[:M + 1, :1 << M] = 0
        for i in range(n):
            mark(cells, M, xs[i], ys[i])

    @jit
    def build_set(seed, points, xs, ys, cells, chain, scratch, stats):
        """The first `points` points of one set into xs, ys; returns -1, or the
        index of the point that met a dead end."""
        remark(cells, 0, 0, xs, ys)
        if not place(cells, 0, 0, 0, 0, seed, 0, xs, ys, chain, scratch, stats):
            return 0
        n = 1
        m = 0
        while n < points:
            M = m + 1
            q = m // 2 + 1
            remark(cells, M, n, xs, ys)
            if m % 2 == 0:
                for i in range(n):
                    sx = xs[i] >> (BITS - q)
                    sy = ys[i] >> (BITS - q)
                    if not place(cells, M, q, sx ^ 1, sy ^ 1, seed, n + i, xs, ys, chain, scratch, stats):
                        return n + i
            else:
                h = n // 2
                fx = draw(seed, n, SWAP, 0) & 1
                for i in range(h):
                    sx = xs[i] >> (BITS - q)
                    sy = ys[i] >> (BITS - q)
                    if not place(cells, M, q, sx ^ fx, sy ^ (1 - fx), seed, n + i, xs, ys, chain, scratch, stats):
                        return n + i
                for i in range(h):
                    sx = xs[i] >> (BITS - q)
                    sy = ys[i] >> (BITS - q)
                    if not place(cells, M, q, sx ^ (1 - fx), sy ^ fx, seed, n + h + i, xs, ys, chain, scratch,
                                 stats):
                        return n + h + i
            n *= 2
            m += 1
        return -1

    return build_set


def build(sets: int | Sequence[int] = SETS, points: int = POINTS, *, stats: dict | None = None) -> np.ndarray:
    """Build pmj02 sets with the numba builder, without any cache.

    Parameters
    ----------
    sets : int or sequence of int
        How many sets (``0 .. sets-1``), or which set indices.
    points : int
        Points per set, a power of two in ``[1, POINTS]``: the first
        ``points`` points of each set (a prefix of the full set).
    stats : dict, optional
        Filled with ``redraws`` (index redraws of the uniform stratum
        choice) and ``max_strata`` (the largest valid stratum set): 0 and 1,
        as the reference's docstring proves.

    Returns
    -------
    numpy.ndarray
        ``uint32``, shape ``(len(sets), points, 2)``: 24-bit coordinates.

    Raises
    ------
    RuntimeError
        A point met a subquadrant with no valid position (never happens for
        the table's seeds).
    """
    check_points(points)
    indices = list(range(sets)) if isinstance(sets, (int, np.integer)) else [int(s) for s in sets]
    build_set = _kernels()
    levels = points.bit_length()  # log2(points) + 1
    cells = np.zeros((levels, points), dtype=np.uint8)
    chain = np.zeros(points + 2, dtype=np.int64)
    scratch = np.zeros(points + 2, dtype=np.int64)
    counters = np.zeros(2, dtype=np.int64)
    out = np.empty((len(indices), points, 2), dtype=np.uint32)
    xs = np.zeros(points, dtype=np.int64)
    ys = np.zeros(points, dtype=np.int64)
    for k, s in enumerate(indices):
        dead = build_set(set_seed(s), points, xs, ys, cells, chain, scratch, counters)
        if dead >= 0:
            raise RuntimeError(f"pmj02 dead end: set {s} (seed {set_seed(s):#010x}), point {dead} has no "
                               "valid position in its subquadrant")
        out[k, :, 0] = xs
        out[k, :, 1] = ys
    if stats is not None:
        stats["redraws"] = int(counters[0])
        stats["max_strata"] = int(counters[1])
    return out


# --------------------------------------------------------------------------- the cache

def cache_dir() -> Path:
    """``$PYOA_CACHE_DIR``, else ``$XDG_CACHE_HOME/pyoa``, else ``~/.cache/pyoa``."""
    if os.environ.get("PYOA_CACHE_DIR"):
        return Path(os.environ["PYOA_CACHE_DIR"])
    if os.environ.get("XDG_CACHE_HOME"):
        return Path(os.environ["XDG_CACHE_HOME"]) / "pyoa"
    return Path.home() / ".cache" / "pyoa"


def cache_path() -> Path:
    """Where :func:`tables` keeps the table: :data:`CACHE_NAME` in :func:`cache_dir`."""
    return cache_dir() / CACHE_NAME


def table_sha256(table: np.ndarray) -> str:
    """SHA-256 (hex) of the little-endian ``uint32`` bytes of ``table`` in C order."""
    return hashlib.sha256(np.ascontiguousarray(table, dtype="<u4").tobytes()).hexdigest()


def _load(path: Path) -> tuple[np.ndarray | None, str]:
    """The cached table, or None and why it cannot be used."""
    try:
        table = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError) as exc:
        return None, f"unreadable: {exc}"
    if table.shape != SHAPE or table.dtype != np.uint32:
        return None, f"shape {table.shape} and dtype {table.dtype}, not {SHAPE} and uint32"
    digest = table_sha256(table)
    if digest != TABLE_SHA256:
        return None, f"SHA-256 {digest[:16]}..., not {TABLE_SHA256[:16]}..."
    return table, ""


def _store(table: np.ndarray, path: Path) -> None:
    """Write the cache atomically; warn (once per process) when it cannot be written."""
    global _warned_unwritable
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(path) as tmp:
            np.save(tmp, table, allow_pickle=False)
    except OSError as exc:
        if not _warned_unwritable:
            _warned_unwritable = True
            warnings.warn(f"cannot write the pmj02 table cache {str(path)!r} ({exc}); using the table built in "
                          "memory (every process rebuilds it; set PYOA_CACHE_DIR to a writable directory)",
                          RuntimeWarning, stacklevel=4)


@functools.cache
def tables() -> np.ndarray:
    """The pmj02 table, ``uint32`` of shape ``(SETS, POINTS, 2)``, read-only.

    Loaded from :func:`cache_path` when that file is valid, else built with
    :func:`build` (and cached; see the module docstring). Kept in memory for
    the rest of the process.

    Raises
    ------
    RuntimeError
        The builder produced a table whose SHA-256 is not :data:`TABLE_SHA256`
        (it would give other bits than on other machines).
    """
    with _lock:
        path = cache_path()
        table = None
        if path.is_file():
            table, why = _load(path)
            if table is None:
                warnings.warn(f"the pmj02 table cache {str(path)!r} is invalid ({why}); rebuilding it",
                              RuntimeWarning, stacklevel=3)
        if table is None:
            # a wait of several seconds (compile and build) that would otherwise be silent
            print(f"building the pmj02 table (once: it is kept in {str(path)!r}; {BUILD_TIME}) ...", file=sys.stderr,
                  flush=True)
            table = np.ascontiguousarray(build(), dtype=np.uint32)
            digest = table_sha256(table)
            if table.shape != SHAPE or digest != TABLE_SHA256:
                raise RuntimeError(f"the pmj02 builder made a table with shape {table.shape} and SHA-256 {digest}, "
                                   f"not {SHAPE} and the pinned {TABLE_SHA256}")
            _store(table, path)
        table.flags.writeable = False
        return table
