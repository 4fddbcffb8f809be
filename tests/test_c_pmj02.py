"""The C pmj02 table builder (kernels/include/pyoa/pmj02_build.h) against
pyoa.tables.pmj02 and pyoa.reference.pmj02: the whole table bit for bit
(its SHA-256 is the pinned TABLE_SHA256), single sets built with caller
scratch, prefixes of other sets against the reference's build_set, and the
builder's parts (draw, uniform index, Pharr's strata walk on random
occupancies, where the walk branches as it never does in pmj02).

The shim (tests/c/pmj02_shim.c) is built as C99 and as C++14 with -O2 and
warnings as errors. ``PYOA_REQUIRE_C=1`` makes a missing gcc/g++ a failure.
The Python table comes from pyoa.tables.pmj02.tables(): from its disk cache,
or built once (numba, 5-12 s) when the cache is cold.
"""

from __future__ import annotations

import ctypes
import os
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from pyoa import c_headers
from pyoa.tables import pmj02 as T
from pyoa.reference import pmj02_build as B

INCLUDE = Path(c_headers.get_include())
SHIM = Path(__file__).parent / "c" / "pmj02_shim.c"
WARN = ["-Wall", "-Wextra", "-Werror", "-pedantic"]
BUILDS = {
    "c99-O2": ("gcc", ".c", ["-std=c99", "-O2", *WARN]),
    "c++14-O2": ("g++", ".cpp", ["-std=c++14", "-O2", *WARN]),
}
U32 = 0xFFFFFFFF
VP = ctypes.c_void_p


def need(tool: str) -> None:
    if shutil.which(tool) is None:
        if os.environ.get("PYOA_REQUIRE_C") == "1":
            pytest.fail(f"{tool} not found and PYOA_REQUIRE_C=1")
        pytest.skip(f"{tool} not found (set PYOA_REQUIRE_C=1 to make this a failure)")


@pytest.fixture(scope="module", params=list(BUILDS))
def lib(request, tmp_path_factory):
    compiler, suffix, flags = BUILDS[request.param]
    need(compiler)
    d = tmp_path_factory.mktemp(f"pmj02-{request.param}")
    src = d / f"pmj02_shim{suffix}"
    src.write_text(SHIM.read_text())
    so = d / "pmj02_shim.so"
    proc = subprocess.run([compiler, *flags, "-shared", "-fPIC", f"-I{INCLUDE}", str(src), "-o", str(so)],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    lib = ctypes.CDLL(str(so))
    lib.t_pmj02_table_entries.restype = ctypes.c_uint32
    lib.t_pmj02_scratch_bytes.restype = ctypes.c_size_t
    lib.t_pmj02_fill_set.argtypes = [ctypes.c_uint32, ctypes.c_uint32, VP, VP]
    lib.t_pmj02_strata.restype = ctypes.c_uint32
    lib.t_pmj02_strata.argtypes = [VP, *[ctypes.c_uint32] * 5, VP]
    return lib


@pytest.fixture(scope="module")
def table():
    return T.tables()


def ptr(a: np.ndarray):
    return a.ctypes.data_as(VP)


def batch(lib, name: str, *arrays) -> list[int]:
    ins = [np.ascontiguousarray(a, dtype=np.uint32) for a in arrays]
    out = np.zeros(len(ins[0]), np.uint32)
    getattr(lib, name)(ctypes.c_size_t(len(out)), *map(ptr, ins), ptr(out))
    return out.tolist()


def garbage_scratch(lib) -> np.ndarray:
    """Scratch of the documented size, all ones (the builder must not read what it did not write)."""
    nbytes = lib.t_pmj02_scratch_bytes()
    assert nbytes % 4 == 0
    return np.full(nbytes // 4, U32, np.uint32)


def fill_set(lib, s: int, points: int, scratch: np.ndarray) -> tuple[int, np.ndarray]:
    out = np.full((points, 2), U32, np.uint32)
    rc = lib.t_pmj02_fill_set(s, points, ptr(out), ptr(scratch))
    return rc, out


# ----------------------------------------------------------------------------- constants

def test_constants_and_sizes_match_python(lib):
    got = np.zeros(10, np.uint32)
    lib.t_pmj02_constants(ptr(got))
    assert got.tolist() == [B.BUILD_SEED, B.SETS, B.POINTS_LOG2, B.POINTS, B.BITS,
                            B.X_STRATUM, B.Y_STRATUM, B.X_LOW, B.Y_LOW, B.SWAP]
    assert lib.t_pmj02_table_entries() == int(np.prod(T.SHAPE)) == 16 * 65536 * 2
    # (M + 1) * 2**M occupancy bits at the last level M = 16, packed
    assert lib.t_pmj02_scratch_bytes() == (B.POINTS_LOG2 + 1) * B.POINTS // 8


@settings(max_examples=30, deadline=None)
@given(st.lists(st.tuples(st.integers(0, U32), st.integers(0, U32), st.integers(0, 7), st.integers(0, 2**29 - 1)),
                min_size=1, max_size=20))
def test_set_seed_and_draw_match_the_reference(lib, cases):
    sets = [c[0] for c in cases] + list(range(B.SETS))
    assert batch(lib, "t_pmj02_set_seed", sets) == [B.set_seed(s) for s in sets]
    cases = cases + [(0, 0, 0, 0), (U32, U32, 7, 2**29 - 1)]
    assert batch(lib, "t_pmj02_draw", *zip(*cases)) == [B.draw(*c) for c in cases]


@settings(max_examples=30, deadline=None)
@given(st.lists(st.tuples(st.integers(0, U32), st.integers(0, U32), st.integers(0, 4), st.integers(1, 2**16)),
                min_size=1, max_size=20))
@example([(1, 2, 0, 1), (5, 6, 1, 2), (7, 8, 0, 3), (9, 9, 1, 2**16), (3, 4, 0, 2**15 + 1)])
def test_uniform_index_matches_the_reference(lib, cases):
    assert batch(lib, "t_pmj02_uniform_index", *zip(*cases)) == [B.uniform_index(*c) for c in cases]


# ----------------------------------------------------------------------------- the strata walk

@st.composite
def walks(draw):
    """A random occupancy of level M (dense or sparse, so that chains branch
    and die) and a subquadrant (qa, qb) of the 2**q grid, M - q <= q <= M."""
    M = draw(st.integers(0, 9))
    q = draw(st.integers((M + 1) // 2, M))
    density = draw(st.sampled_from([0.0, 0.05, 0.3, 0.7]))
    seed = draw(st.integers(0, U32))
    rng = np.random.default_rng(seed)
    cells = [bytearray((rng.random(1 << M) < density).astype(np.uint8).tobytes()) for _ in range(M + 1)]
    return M, q, draw(st.integers(0, (1 << q) - 1)), draw(st.integers(0, (1 << q) - 1)), cells


@settings(max_examples=60, deadline=None)
@given(walks(), st.sampled_from([0, 1]))
def test_strata_walk_matches_the_reference(lib, walk, axis):
    """The depth-first walk lists the same strata in the same order as the
    reference's breadth-first chain lists, also where chains branch."""
    M, q, qa, qb, cells = walk
    occ = B.Occupancy(M, [], [])
    occ.cells = cells
    want = occ.strata(q, qa, qb, axis)
    flat = np.concatenate([np.frombuffer(bytes(c), np.uint8) for c in cells])  # bit (u << M) | i
    words = np.zeros(max(1, (len(flat) + 31) // 32), np.uint32)
    for k in np.flatnonzero(flat):
        words[k >> 5] |= np.uint32(1 << (k & 31))
    out = np.full(1 << M, U32, np.uint32)
    count = lib.t_pmj02_strata(ptr(words), M, q, qa, qb, axis, ptr(out))
    assert out[:count].tolist() == want


# ----------------------------------------------------------------------------- sets and the table

def test_whole_table_matches_python_bit_for_bit(lib, table):
    """pyoa_pmj02_fill into a buffer of garbage (all ones: its top bytes hold
    the occupancy during the build) gives pyoa.tables.pmj02.tables()."""
    out = np.full(T.SHAPE, U32, np.uint32)
    t0 = time.perf_counter()
    rc = lib.t_pmj02_fill(ptr(out))
    seconds = time.perf_counter() - t0
    print(f"C pmj02 table build: {seconds:.3f} s")
    assert rc == 0
    assert T.table_sha256(out) == T.TABLE_SHA256
    assert np.array_equal(out, table)
    assert int(out.max()) < 1 << B.BITS


def test_fill_set_with_scratch_matches_the_table(lib, table):
    """One set at a time with caller scratch (garbage-filled), as threads
    would: the table's rows; and a used scratch reused gives the same bits."""
    scratch = garbage_scratch(lib)
    for s in (0, 5, 15):
        rc, out = fill_set(lib, s, B.POINTS, scratch)
        assert rc == 0
        assert np.array_equal(out, table[s]), s
    rc, out = fill_set(lib, 0, 1 << 12, scratch)
    assert rc == 0 and np.array_equal(out, table[0, :1 << 12])


def test_first_points_of_set_0_match_the_reference(lib, table):
    scratch = garbage_scratch(lib)
    rc, out = fill_set(lib, 0, 1 << 10, scratch)
    assert rc == 0
    assert [tuple(p) for p in out.tolist()] == B.build_set(0, 1 << 10)
    assert np.array_equal(out, table[0, :1 << 10])


@settings(max_examples=20, deadline=None)
@given(st.integers(0, U32), st.integers(0, 9))
@example(16, 9)
@example(U32, 0)
def test_prefixes_of_other_sets_match_the_reference(lib, s, log2points):
    """Sets beyond the table's 16 (any uint32 index) and every prefix length:
    the C builder is the reference's algorithm, not only its 16 outputs."""
    rc, out = fill_set(lib, s, 1 << log2points, garbage_scratch(lib))
    assert rc == 0
    assert [tuple(p) for p in out.tolist()] == B.build_set(s, 1 << log2points)


@pytest.mark.parametrize("points", [0, 3, 6, 1 << 17, (1 << 16) + 1, U32])
def test_fill_set_rejects_points_that_are_not_powers_of_two_up_to_2_16(lib, points):
    out = np.full(4, 7, np.uint32)
    assert lib.t_pmj02_fill_set(0, points, ptr(out), ptr(garbage_scratch(lib))) == -1
    assert out.tolist() == [7] * 4  # nothing written
