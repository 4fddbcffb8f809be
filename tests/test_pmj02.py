"""pmj02: the table (pyoa.tables.pmj02), its builders and cache, and the sampler
values of the three backends (pyoa.reference.pmj02, pyoa._numpy.pmj02,
kernels/include/pyoa/pmj02.h).

Every check of stratification is exact and integer: table coordinates and
sampler values are ``k * 2**-24`` with 24-bit ``k``, so the elementary
interval ``2**-u x 2**-v`` holding a point is ``(kx >> (24 - u), ky >> (24 -
v))``, and a set of ``2**m`` points is a (0,m,2)-net iff, for every ``u``,
the ``2**m`` combined interval codes are all different (:func:`net_failures`
counts them with :func:`numpy.bincount`, all sets at once).

The module builds the table once, through :func:`pyoa.tables.pmj02.tables`
with ``PYOA_CACHE_DIR`` pointing at a temporary directory (so the numba build
and the cache write run for real, and nothing is written under ``~``).
"""

from __future__ import annotations

import importlib
import pkgutil
import re
import warnings
from importlib import resources

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from pyoa.tables import pmj02 as T
from pyoa import reference
from pyoa._numpy import pmj02 as npmj
from pyoa._numpy.hashes import pixel_seed
from pyoa.reference import pmj02 as R
from pyoa.reference import pmj02_build as B
from pyoa.reference.hashes import hash_pair
from tests.helpers import U32_MAX, assert_same_bits, kernel_runner

U32 = np.uint32
F32 = np.float32


# ----------------------------------------------------------------------------- helpers

def net_failures(x: np.ndarray, y: np.ndarray, m: int, block: int = 2**16) -> list[int]:
    """The shapes ``u`` (``2**-u x 2**-(m-u)``) for which some aligned block of
    ``2**m`` consecutive points, among the first ``block`` of each row, does not
    have exactly one point in every elementary interval. ``x``, ``y``: 24-bit
    integers, shape (rows, points)."""
    x = np.asarray(x, dtype=np.int64)[:, :block]
    y = np.asarray(y, dtype=np.int64)[:, :block]
    rows, n = x.shape
    assert n % (1 << m) == 0
    group = np.arange(rows * n, dtype=np.int64).reshape(rows, n) >> m  # (row, block) number
    bad = []
    for u in range(m + 1):
        v = m - u
        codes = (group << m) | ((x >> (24 - u)) << v) | (y >> (24 - v))
        if np.bincount(codes.ravel(), minlength=rows * n).max() != 1:
            bad.append(u)
    return bad


def as_ints(values: np.ndarray) -> np.ndarray:
    """float32 values ``k * 2**-24`` back to ``k`` (exact; checked)."""
    k = np.asarray(values, dtype=np.float64) * 2.0**24
    assert np.array_equal(k, np.floor(k)) and k.min() >= 0 and k.max() < 2**24
    return k.astype(np.int64)


# ----------------------------------------------------------------------------- fixtures

@pytest.fixture(scope="module")
def cache_env(tmp_path_factory):
    """PYOA_CACHE_DIR at an empty temporary directory for the whole module."""
    d = tmp_path_factory.mktemp("pmj02-cache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PYOA_CACHE_DIR", str(d))
        T.tables.cache_clear()
        yield d
    T.tables.cache_clear()


@pytest.fixture(scope="module")
def table(cache_env):
    """The table, built by tables() (numba) and cached in cache_env."""
    assert not (cache_env / T.CACHE_NAME).exists()
    t = T.tables()
    assert (cache_env / T.CACHE_NAME).is_file()
    return t


@pytest.fixture
def fresh_cache(tmp_path, monkeypatch, table):
    """A new empty cache directory and no table in memory; afterwards tables()
    falls back to the module's cache (cleared again, so it reloads it)."""
    d = tmp_path / "cache"
    monkeypatch.setenv("PYOA_CACHE_DIR", str(d))
    monkeypatch.setattr(T, "_warned_unwritable", False)
    T.tables.cache_clear()
    yield d
    T.tables.cache_clear()


def counting_build(monkeypatch, table, allowed: int = 1):
    """Replace T.build by one that returns a copy of ``table`` and fails after
    ``allowed`` calls; returns the list of calls."""
    calls = []

    def fake_build(*args, **kwargs):
        calls.append((args, kwargs))
        if len(calls) > allowed:
            raise AssertionError("the table was rebuilt although the cache is valid")
        return np.array(table)

    monkeypatch.setattr(T, "build", fake_build)
    return calls


# ----------------------------------------------------------------------------- constants

def test_constants():
    assert (T.SETS, T.POINTS, T.POINTS_LOG2) == (16, 2**16, 16)
    assert T.SHAPE == (16, 65536, 2)
    assert T.CACHE_NAME == "pmj02-v1-16x65536.npy"
    assert 1 << (32 - 28) == T.SETS  # h >> 28 picks the set
    assert re.fullmatch(r"[0-9a-f]{64}", T.TABLE_SHA256)


def test_keys_are_new_odd_uint32():
    ours = {name: getattr(R, name) for name in ("PMJ02_KEY", "PMJ02_SHIFT_KEY")}
    ours.update({name: getattr(B, name) for name in ("PMJ02_BUILD_KEY", "PMJ02_DRAW_KEY")})
    others = {}
    for m in pkgutil.iter_modules(reference.__path__):
        if m.name in ("pmj02", "pmj02_build"):
            continue
        module = importlib.import_module(f"pyoa.reference.{m.name}")
        others.update({k: v for k, v in vars(module).items() if k.endswith("_KEY") and isinstance(v, int)})
    for name, value in ours.items():
        assert 0 < value <= U32_MAX and value % 2 == 1, name
        assert value not in others.values(), f"{name} = {value:#x} is already a key of pyoa.reference"
    assert len(set(ours.values())) == len(ours)


def test_keys_are_in_the_generated_header():
    keys_h = resources.files("pyoa.kernels").joinpath("include", "pyoa", "keys.h").read_text()
    for name in ("PMJ02_KEY", "PMJ02_SHIFT_KEY"):
        assert f"#define PYOA_{name} 0x{getattr(R, name):08x}u\n" in keys_h


def test_kernel_constants_match_python():
    text = resources.files("pyoa.kernels").joinpath("include", "pyoa", "pmj02.h").read_text()
    defined = dict(re.findall(r"^#define\s+PYOA_(PMJ02_\w+)\s+(\d+)u\s*$", text, re.MULTILINE))
    assert defined == {"PMJ02_SETS": str(T.SETS), "PMJ02_POINTS": str(T.POINTS)}
    assert "h >> 28" in text
    # the keys come from keys.h only (their single definition is Python's)
    assert not re.search(r"^#define\s+PMJ02_(SHIFT_)?KEY\b", text, re.MULTILINE)


# ----------------------------------------------------------------------------- the table

def test_table_is_read_only_24bit_and_pinned(table):
    assert table.shape == T.SHAPE and table.dtype == np.uint32
    assert not table.flags.writeable
    assert int(table.max()) < 2**24
    assert T.table_sha256(table) == T.TABLE_SHA256
    assert table.nbytes == 8 * 2**20


def test_every_prefix_is_a_net(table):
    """Prefix [0, 2**k) of every set, k = 0..16: one point in every elementary
    interval of area 2**-k (all k + 1 shapes)."""
    x, y = table[..., 0], table[..., 1]
    for k in range(T.POINTS_LOG2 + 1):
        assert net_failures(x, y, k, block=1 << k) == [], f"prefix of 2^{k} points"


def test_every_aligned_block_is_a_net(table):
    """The balanced subquadrant order makes every block [a 2**k, (a+1) 2**k) a
    net too, not only the prefixes (reference.pmj02 docstring)."""
    x, y = table[..., 0], table[..., 1]
    for k in range(T.POINTS_LOG2 + 1):
        assert net_failures(x, y, k) == [], f"blocks of 2^{k} points"


@pytest.mark.parametrize("k", [1, 2, 5, 8, 11, 16])
def test_prefixes_are_stratified_in_1d(table, k):
    n = 1 << k
    for c in (0, 1):
        strata = np.sort(table[:, :n, c] >> (24 - k), axis=1)
        assert np.array_equal(strata, np.broadcast_to(np.arange(n), strata.shape)), f"coordinate {c}"


def test_sets_differ(table):
    """16 different sequences (from their first points on)."""
    assert len({tuple(table[s, :4].ravel()) for s in range(T.SETS)}) == T.SETS


def test_build_is_deterministic(table):
    stats = {}
    again = T.build(stats=stats)
    assert again.dtype == np.uint32 and again.shape == T.SHAPE
    assert again.tobytes() == table.tobytes()
    assert T.table_sha256(again) == T.TABLE_SHA256
    # the chains of valid strata never branch: one stratum per axis, no redraw
    assert stats == {"redraws": 0, "max_strata": 1}


def test_numba_builder_equals_python_builder(table):
    """The pure-Python reference builder gives the same bits: the first 2**12
    points of sets 0 and 15, and the whole of set 15 (every level, 1 to 16)."""
    stats = {}
    for s, points in [(0, 2**12), (15, 2**12), (15, T.POINTS)]:
        want = np.array(B.build_set(s, points, stats), dtype=U32)
        assert np.array_equal(T.build(sets=[s], points=points)[0], want), (s, points)
        assert np.array_equal(table[s, :points], want), (s, points)
    assert stats == {"max_strata": 1, "redraws": 0}


def test_build_prefixes_and_set_selection(table):
    assert np.array_equal(T.build(sets=[3, 7], points=256), table[[3, 7], :256])
    assert np.array_equal(T.build(sets=2, points=1), table[:2, :1])
    assert T.build(sets=[], points=4).shape == (0, 4, 2)


@pytest.mark.parametrize("points", [0, 3, 48, 2**17, -4])
def test_build_rejects_bad_sizes(points):
    with pytest.raises(ValueError, match="power of two"):
        T.build(sets=1, points=points)
    with pytest.raises(ValueError, match="power of two"):
        B.build_set(0, points)


def test_dead_end_raises():
    """A subquadrant without a valid position fails loudly (it never happens
    for the table's seeds: the builds above succeed)."""
    occ = B.Occupancy(3, [], [])
    for cells in occ.cells:
        cells[:] = b"\x01" * len(cells)
    with pytest.raises(RuntimeError, match="dead end"):
        B.place(occ, 2, 1, 2, B.set_seed(0), 8)
    # one empty chain: x strata exist, y strata do not
    occ = B.Occupancy(1, [], [])
    occ.cells[0][:] = b"\x01\x01"
    assert occ.strata(1, 0, 0, 0) == [0]
    assert occ.strata(1, 0, 0, 1) == []


def test_draws_are_counter_based():
    """The build's random numbers are hashes of (set seed, index, purpose, attempt)."""
    seed = B.set_seed(5)
    assert seed == hash_pair(B.BUILD_SEED, 5, B.PMJ02_BUILD_KEY)
    assert B.draw(seed, 9, B.X_LOW, 0) == hash_pair(hash_pair(seed, 9, B.PMJ02_DRAW_KEY), B.X_LOW, B.PMJ02_DRAW_KEY)
    values = {B.draw(seed, 9, purpose, attempt) for purpose in range(5) for attempt in range(4)}
    assert len(values) == 20
    # uniform_index: exact rejection, in range, and every value reachable
    got = {B.uniform_index(seed, i, B.X_STRATUM, 5) for i in range(200)}
    assert got == set(range(5))
    assert B.uniform_index(seed, 0, B.X_STRATUM, 1) == 0


# ----------------------------------------------------------------------------- the cache

def test_cache_location(monkeypatch, tmp_path):
    monkeypatch.setenv("PYOA_CACHE_DIR", str(tmp_path / "a"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert T.cache_path() == tmp_path / "a" / "pmj02-v1-16x65536.npy"
    monkeypatch.setenv("PYOA_CACHE_DIR", "")
    assert T.cache_dir() == tmp_path / "xdg" / "pyoa"
    monkeypatch.delenv("PYOA_CACHE_DIR")
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert T.cache_dir() == tmp_path / "home" / ".cache" / "pyoa"


def test_cache_is_written_and_reused(fresh_cache, table, monkeypatch):
    calls = counting_build(monkeypatch, table, allowed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        first = T.tables()
        path = fresh_cache / T.CACHE_NAME
        assert path.is_file() and len(calls) == 1
        assert T.tables() is first  # kept in memory
        T.tables.cache_clear()
        second = T.tables()  # from the file: a second build would raise
    assert len(calls) == 1
    assert np.array_equal(first, table) and np.array_equal(second, table)
    assert not first.flags.writeable and not second.flags.writeable
    assert [p.name for p in fresh_cache.iterdir()] == [T.CACHE_NAME]  # no temporary file left


def _flip_last_byte(path):
    data = bytearray(path.read_bytes())
    data[-1] ^= 0x01
    path.write_bytes(bytes(data))


def _truncate(path):
    path.write_bytes(path.read_bytes()[:1000])


def _garbage(path):
    path.write_bytes(b"not a numpy file")


def _wrong_shape(path):
    np.save(path, np.zeros((16, 1024, 2), dtype=np.uint32))


def _wrong_dtype(path):
    np.save(path, np.zeros(T.SHAPE, dtype=np.int32))


@pytest.mark.parametrize("corrupt", [_flip_last_byte, _truncate, _garbage, _wrong_shape, _wrong_dtype])
def test_invalid_cache_is_rebuilt(fresh_cache, table, monkeypatch, corrupt):
    path = fresh_cache / T.CACHE_NAME
    fresh_cache.mkdir()
    np.save(path, table)
    corrupt(path)
    if corrupt is _flip_last_byte:  # one case with the real builder
        calls = []
    else:
        calls = counting_build(monkeypatch, table, allowed=1)
    with pytest.warns(RuntimeWarning, match="invalid .*rebuilding"):
        got = T.tables()
    assert np.array_equal(got, table)
    assert len(calls) == (0 if corrupt is _flip_last_byte else 1)
    reloaded = np.load(path)  # rewritten, valid
    assert T.table_sha256(reloaded) == T.TABLE_SHA256


def test_unwritable_cache_builds_in_memory_and_warns_once(fresh_cache, table, monkeypatch, tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    monkeypatch.setenv("PYOA_CACHE_DIR", str(blocker / "cache"))  # a directory under a file
    calls = counting_build(monkeypatch, table, allowed=2)
    with pytest.warns(RuntimeWarning, match="cannot write the pmj02 table cache"):
        got = T.tables()
    assert np.array_equal(got, table) and not got.flags.writeable
    T.tables.cache_clear()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.array_equal(T.tables(), table)  # rebuilt, not warned again
    assert len(calls) == 2


def test_builder_mismatch_raises(fresh_cache, table, monkeypatch):
    wrong = np.array(table)
    wrong[3, 5, 1] ^= 1

    monkeypatch.setattr(T, "build", lambda *a, **k: wrong)
    with pytest.raises(RuntimeError, match="pinned"):
        T.tables()
    assert not (fresh_cache / T.CACHE_NAME).exists()


# ----------------------------------------------------------------------------- sampler values

def _ref(i, j, log2n, p):
    return F32(R.pmj02(i, j, log2n, p))


@st.composite
def value_args(draw):
    log2n = draw(st.integers(0, 16))
    i = draw(st.one_of(st.integers(0, (1 << log2n) - 1), st.just((1 << log2n) - 1)))
    j = draw(st.one_of(st.integers(0, 7), st.integers(0, U32_MAX), st.sampled_from([U32_MAX - 1, U32_MAX])))
    p = draw(st.one_of(st.sampled_from([0, 1, U32_MAX]), st.integers(0, U32_MAX)))
    return i, j, log2n, p


@given(value_args())
@example((2**16 - 1, U32_MAX, 16, U32_MAX))
@example((2**16 - 1, 1, 16, 0))
@example((0, 0, 0, 0))
@example((12345, 2**31 + 7, 16, 1))
def test_reference_equals_numpy(table, args):
    i, j, log2n, p = args
    assert_same_bits(npmj.pmj02(U32(i), U32(j), log2n, U32(p)), _ref(i, j, log2n, p), f"pmj02{args}")


def test_numpy_broadcasts_and_equals_reference(table):
    rng = np.random.default_rng(20180702)
    i = rng.integers(0, 2**16, (40, 1)).astype(U32)
    i[0] = 2**16 - 1
    j = np.array([0, 1, 2, 3, 1001, U32_MAX - 1, U32_MAX], dtype=U32)
    p = rng.integers(0, 2**32, (40, 1), dtype=np.uint64).astype(U32)
    p[:3, 0] = [0, 1, U32_MAX]
    got = npmj.pmj02(i, j, 16, p)
    assert got.shape == (40, 7) and got.dtype == F32
    want = np.array([[_ref(int(a), int(b), 16, int(c)) for b in j] for a, c in zip(i[:, 0], p[:, 0])], dtype=F32)
    assert_same_bits(got, want, "broadcast")
    assert npmj.pmj02(5, 3, 4, 7).dtype == F32  # scalars


def test_unrandomized_is_set_zero_in_order(table):
    """p == 0: every pair reads set 0 unshifted, sample i = point i."""
    i = np.arange(2**16, dtype=U32)
    for j in (0, 1, 2, 3, 999):
        got = npmj.pmj02(i, U32(j), 16, U32(0))
        assert_same_bits(got, (table[0, :, j & 1] * 2.0**-24).astype(F32), f"j={j}")


def test_values_are_the_shifted_table_in_a_nested_order(table):
    """For p != 0: set h >> 28 read in a nested-scrambled order that does not
    depend on N (every prefix of 2^k samples is an aligned block of the set),
    XOR by one 24-bit constant per coordinate; the pairs of one pixel read
    their sets in different orders (padding)."""
    from pyoa.reference.baselines import owen_scramble

    p = 0x9E3779B9
    orders = []
    for b in (0, 1, 77):
        h = hash_pair(p, b, R.PMJ02_KEY)
        g = np.array([owen_scramble(i, hash_pair(h, 0, R.PMJ02_SHIFT_KEY)) & 0xFFFF for i in range(2**16)])
        assert sorted(g) == list(range(2**16))  # a permutation of the set
        for k in (1, 4, 9, 16):  # every prefix an aligned block
            assert g[: 1 << k].max() - g[: 1 << k].min() == (1 << k) - 1 and g[0] >> k == g[(1 << k) - 1] >> k
        orders.append(g)
        for c in (0, 1):
            k = as_ints(npmj.pmj02(np.arange(2**16, dtype=U32), U32(2 * b + c), 16, U32(p)))
            shift = k ^ table[h >> 28, g, c].astype(np.int64)
            assert np.all(shift == shift[0])
            assert shift[0] == hash_pair(h, 1 + c, R.PMJ02_SHIFT_KEY) >> 8
    assert not np.array_equal(orders[0], orders[1])


def test_every_pixel_prefix_is_a_net(table):
    """Per pixel seed and pair, the first 2**k samples are a (0,k,2)-net after
    the digital shift, k = 0..16 (and so is every aligned block)."""
    seeds = [1, U32_MAX, *map(int, pixel_seed(U32(12345), np.arange(6, dtype=U32)))]
    i = np.arange(2**16, dtype=U32)
    xs, ys = [], []
    for p in seeds:
        for b in (0, 1, 5, 2**31 - 1):
            xs.append(as_ints(npmj.pmj02(i, U32(2 * b), 16, U32(p))))
            ys.append(as_ints(npmj.pmj02(i, U32(2 * b + 1), 16, U32(p))))
    x, y = np.array(xs), np.array(ys)
    for k in range(17):
        assert net_failures(x, y, k, block=1 << k) == [], f"prefix of 2^{k}"
    for k in (1, 2, 7, 12):
        assert net_failures(x, y, k) == [], f"blocks of 2^{k}"


def test_pixels_use_every_set_and_pairs_differ(table):
    h = np.array([hash_pair(p, b, R.PMJ02_KEY) for p in range(1, 200) for b in range(3)])
    assert set(h >> 28) == set(range(16))
    i = np.arange(64, dtype=U32)
    a = npmj.pmj02(i, U32(0), 6, U32(42))
    b = npmj.pmj02(i, U32(2), 6, U32(42))
    assert not np.array_equal(a, b)


@pytest.mark.parametrize("args, what", [
    ((-1, 0, 4, 1), "sample index"),
    ((16, 0, 4, 1), "sample index"),
    ((1, 0, 0, 1), "sample index"),
    ((0, 0, -1, 1), "log2n"),
    ((0, 0, 17, 1), "log2n"),
    ((0, -1, 4, 1), "dimension"),
    ((0, 2**32, 4, 1), "dimension"),
    ((0, 0, 4, -1), "seed"),
    ((0, 0, 4, 2**32), "seed"),
])
def test_reference_argument_errors(args, what):
    with pytest.raises(ValueError, match=what):
        R.pmj02(*args)


# ----------------------------------------------------------------------------- OpenCL

TEST_KERNELS = r"""
__kernel void tp_pmj02(__global const uint *i, __global const uint *j, __global const uint *p,
                       __global const uint *table, __global float *out)
{ size_t g = get_global_id(0); out[g] = pyoa_sample_pmj02(i[g], j[g], p[g], table); }
"""


@pytest.mark.opencl
def test_kernel_equals_numpy(opencl, table):
    run = kernel_runner(opencl, TEST_KERNELS)
    rng = np.random.default_rng(2018)
    n = 20000
    i = rng.integers(0, 2**16, n).astype(U32)
    j = rng.integers(0, 2**32, n, dtype=np.uint64).astype(U32)
    p = rng.integers(0, 2**32, n, dtype=np.uint64).astype(U32)
    i[:4] = [0, 2**16 - 1, 2**16 - 1, 1]
    j[:4] = [0, 1, U32_MAX, 2]
    j[4:2000] = rng.integers(0, 8, 1996)
    p[:4] = [0, 0, U32_MAX, 1]
    p[4:1000] = 0
    got = run("tp_pmj02", [F32], i, j, p, np.ascontiguousarray(table).ravel(), n=n)
    assert_same_bits(got, npmj.pmj02(i, j, 16, p), "kernel vs numpy")
