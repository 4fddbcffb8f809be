"""The bulk path of the renderer API (pyoa/fill.h), bit for bit against
pyoa_sampler_value and NumPy's ``generate``: every catalogue sampler at every
test case of its catalogue entry, every offset, seeds 0, 1 and 2^32 - 1,
pixels 0 and 2^32 - 1 (the last pixel of the image for zsobol), sample
ranges from 0 and from the middle, whole pixels where the count is small,
dimension ranges from 0 and across the block boundaries (section 6), and
hypothesis draws.

Each request is evaluated three ways by tests/c/fill_shim.c:
``pyoa_sampler_fill`` on a scratch full of garbage, ``pyoa_fill_pixel`` for a
second pixel on the plan that fill left, and the first pixel again (the
plan's cells are reused, the per-pixel tables rewritten); the scratch's
size is checked with a guard zone after it. The shim is built as C99 -O2,
C++14 -O2, GNU C -O3 -march=native -ffp-contract=fast (the vectorized
loops, with FMA contraction asked for) and C99 -O2 with tiny PYOA_FILL_*
bounds, which sends every request through fill.h's fallbacks (per-value
permutations, cells computed per pixel, several passes of samples).

Set ``PYOA_REQUIRE_C=1`` (CI does) to fail instead of skip without
gcc/g++."""

from __future__ import annotations

import ctypes
import functools
import subprocess
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pyoa
from pyoa import catalogue
from pyoa.catalogue.entries import OFFSETS
from tests.test_c_headers import INCLUDE, WARN, need

SHIM = Path(__file__).parent / "c" / "fill_shim.c"
U32_MAX = 2**32 - 1
ENTRIES = list(catalogue.SAMPLERS.values())
TINY = ["-DPYOA_FILL_MAX_TABLE=8u", "-DPYOA_FILL_MAX_CELL_ROWS=24u", "-DPYOA_FILL_CHUNK=16u"]
#: id -> (compiler, suffix, flags) of the libraries under test.
BUILDS = {
    "c99-O2": ("gcc", ".c", ["-std=c99", "-O2", *WARN]),
    "c++14-O2": ("g++", ".cpp", ["-std=c++14", "-O2", *WARN]),
    "gnu99-O3-native-contract": ("gcc", ".c", ["-std=gnu99", "-O3", "-march=native", "-ffp-contract=fast", *WARN]),
    "c99-O2-tiny-bounds": ("gcc", ".c", ["-std=c99", "-O2", *TINY, *WARN]),
}
#: fill.h's cell modes (PYOA_FILL_CELLS_*), as bits of the shim's info[4].
PER_PIXEL, BY_SAMPLE, BY_ROW = 1, 2, 4
#: at most this many samples per request (whole pixels up to WHOLE samples)
SAMPLES, WHOLE = 24, 1300


@pytest.fixture(scope="module")
def libraries(tmp_path_factory):
    """Every build's shared library path, compiled concurrently (CI's 2 cores halve the ~20 s of
    compilation: sampler.h brings the catalogue's count rules, Sobol's data and the pmj02 builder)."""
    for compiler, _, _ in BUILDS.values():
        need(compiler, "PYOA_REQUIRE_C")
    procs = {}
    for build, (compiler, suffix, flags) in BUILDS.items():
        tmp = tmp_path_factory.mktemp(build)
        src = tmp / f"fill_shim{suffix}"
        src.write_text(SHIM.read_text())
        cmd = [compiler, *flags, "-shared", "-fPIC", f"-I{INCLUDE}", f"-I{SHIM.parent}", str(src), "-o", str(tmp / "libfill.so")]
        procs[build] = (cmd, tmp / "libfill.so", subprocess.Popen(cmd, cwd=tmp, stdout=subprocess.PIPE,
                                                                   stderr=subprocess.PIPE, text=True))
    out = {}
    for build, (cmd, so, proc) in procs.items():
        _, err = proc.communicate()
        assert proc.returncode == 0, f"{' '.join(cmd)}:\n{err}"
        out[build] = so
    return out


@pytest.fixture(scope="module", params=list(BUILDS))
def lib(request, libraries):
    dll = ctypes.CDLL(str(libraries[request.param]))
    u32, f32p = ctypes.c_uint32, np.ctypeslib.ndpointer(np.float32, flags="C")
    dll.t_fill.argtypes = [ctypes.c_char_p, u32, u32, u32, ctypes.c_char_p, ctypes.c_float, u32, u32, u32, u32,
                           u32, u32, u32, u32, u32, u32, f32p, f32p, np.ctypeslib.ndpointer(np.uint32, flags="C"),
                           ctypes.c_char_p, ctypes.c_size_t]
    dll.t_fill.restype = ctypes.c_int
    for fn in (dll.t_floats, dll.t_clamped):
        fn.argtypes, fn.restype = [u32, u32], u32
    dll.build = request.param
    return dll


def c_fill(lib, name, options, *, seed, pixels, sample0, n_samples, dim0, n_dims):
    """(fill, fill_pixel of the other pixel, fill_pixel again, value, info) of one request, each of shape
    (n_samples, n_dims) but fill_pixel's and value's, (2, n_samples, n_dims) for the two pixels."""
    n = n_samples * n_dims
    out = np.full(3 * n, np.nan, np.float32)
    want = np.full(2 * n, np.nan, np.float32)
    info = np.zeros(10, np.uint32)
    msg = ctypes.create_string_buffer(1024)
    width, height = options.get("resolution") or (0, 0)
    rc = lib.t_fill(name.encode(), options["spp"], options["dims"], seed, (options.get("offset") or "").encode(),
                    options.get("jitter", 1.0), options.get("strength") or 0, options.get("base") or 0, width, height,
                    pixels[0], pixels[1], sample0, n_samples, dim0, n_dims, out, want, info, msg, len(msg))
    assert rc == 0, msg.value.decode()
    shape = (n_samples, n_dims)
    return (out[:n].reshape(shape), out[n:2 * n].reshape(shape), out[2 * n:].reshape(shape),
            want.reshape((2, *shape)), info)


@functools.lru_cache(maxsize=None)
def numpy_sampler(name, items, seed):
    return pyoa.sampler(name, backend="numpy", seed=seed, **dict(items))


@functools.lru_cache(maxsize=4096)
def numpy_values(name, items, seed, pixels, sample0, n_samples, dim0, n_dims):
    smp = numpy_sampler(name, items, seed)
    return smp.generate(pixels=list(pixels), samples=list(range(sample0, sample0 + n_samples)),
                        dims=list(range(dim0, dim0 + n_dims)))


def bits(a):
    return np.ascontiguousarray(a).view(np.uint32)


def check(lib, name, options, *, seed, pixels, sample0, n_samples, dim0, n_dims):
    """Compare one request's three C evaluations with pyoa_sampler_value and NumPy; the info."""
    fill, other, again, value, info = c_fill(lib, name, options, seed=seed, pixels=pixels, sample0=sample0,
                                             n_samples=n_samples, dim0=dim0, n_dims=n_dims)
    where = f"{name} {options} seed {seed} pixels {pixels} samples {sample0}+{n_samples} dims {dim0}+{n_dims}"
    want = numpy_values(name, tuple(sorted(options.items())), seed, tuple(pixels), sample0, n_samples, dim0, n_dims)
    assert np.array_equal(bits(value), bits(want)), f"{where}: pyoa_sampler_value differs from NumPy"
    for got, pix, what in ((fill, 0, "pyoa_sampler_fill"), (other, 1, "pyoa_fill_pixel (second pixel)"),
                           (again, 0, "pyoa_fill_pixel (first pixel again)")):
        bad = np.argwhere(bits(got) != bits(value[pix]))
        assert not len(bad), f"{where}: {what} differs from pyoa_sampler_value at (k, d) {bad[:5].tolist()}"
    assert info[5] == 1, f"{where}: the fill wrote past pyoa_fill_scratch_bytes"
    oa = catalogue.get(name).family == "oa"
    tabled = oa and options.get("offset", "cmj") in ("cmj", "centered")
    assert info[1] == int(tabled), f"{where}: table path {info[1]}, expected {int(tabled)}"
    return info


def requests(smp):
    """(sample0, n_samples, dim0, n_dims) of the edge tests: samples from 0 and from the middle (the whole
    pixel when it is small), dimensions from 0 and across the first and second block boundaries."""
    spp, dims = smp.spp, smp.dims
    B = smp.block_dims or dims
    mid = max(0, spp // 2 - 5)
    n0 = spp if spp <= WHOLE else min(spp, SAMPLES)
    out = [(0, n0, 0, min(dims, 2 * B + 3, 12)), (mid, min(spp - mid, SAMPLES), 0, min(dims, 3))]
    for b in (B, 2 * B):
        if b < dims:
            d0 = max(0, b - 2)
            out.append((mid, min(spp - mid, 9), d0, min(dims - d0, 4)))
    return out


def cases():
    """(name, options) for every test case of every catalogue entry, every offset for the orthogonal
    arrays, each with dims raised to 2 B + 3 (three blocks) where the case has fewer."""
    for c in ENTRIES:
        for case in c.test_cases():
            offsets = OFFSETS if c.family == "oa" else (None,)
            for offset in offsets:
                options = dict(case, offset=offset) if offset else dict(case)
                if c.family == "oa":  # the case's strength kept (bush's and cmjnd's default follows dims)
                    smp = numpy_sampler(c.name, tuple(sorted(options.items())), 0)
                    options.update(dims=max(options["dims"], min(2 * smp.block_dims + 3, 2**20)),
                                   strength=smp.strength)
                yield pytest.param(c.name, options,
                                   id=f"{c.name}-{'-'.join(f'{k}{v}' for k, v in case.items())}-{offset}")


@pytest.mark.parametrize("name, options", list(cases()))
def test_every_catalogue_sampler_fills_like_pyoa_sampler_value_and_numpy(lib, name, options):
    tabled = catalogue.get(name).family == "oa" and options.get("offset") in ("cmj", "centered")
    if lib.build.endswith("tiny-bounds") and not tabled:
        return  # the per-value fallback does not depend on the bounds: the other builds cover it
    smp = numpy_sampler(name, tuple(sorted(options.items())), 0)
    n_pix = smp.resolution[0] * smp.resolution[1] if smp.resolution else 2**32
    for seed in (0, 1, U32_MAX):
        for sample0, n_samples, dim0, n_dims in requests(smp):
            check(lib, name, options, seed=seed, pixels=(0, n_pix - 1), sample0=sample0, n_samples=n_samples,
                  dim0=dim0, n_dims=n_dims)


@pytest.mark.parametrize("name, options, expect, expect_tiny", [
    # name, options, (stab, mtab, cell modes), the same under the tiny bounds (tables <= 8, cells <= 24 rows)
    ("bose", dict(spp=121, dims=10), (1, 1, BY_SAMPLE), (0, 0, PER_PIXEL)),
    ("bose", dict(spp=49, dims=20), (1, 1, BY_SAMPLE | BY_ROW), (1, 1, PER_PIXEL)),
    ("bose", dict(spp=49, dims=20, offset="centered"), (1, 0, BY_SAMPLE | BY_ROW), (1, 0, PER_PIXEL)),
    ("bush", dict(spp=64, dims=7, strength=3), (1, 1, BY_SAMPLE | BY_ROW), (1, 0, PER_PIXEL)),
    ("addelman-kempthorne", dict(spp=18, dims=9), (1, 1, BY_SAMPLE | BY_ROW), (1, 1, BY_SAMPLE | BY_ROW)),
])
def test_the_table_path_takes_its_tables_and_cells_where_they_pay(lib, name, options, expect, expect_tiny):
    """Whole pixels of small arrays take both tables and hold their cells (block 0 by sample, later
    blocks by row); under the tiny bounds the same requests fall back and still agree."""
    smp = numpy_sampler(name, tuple(sorted(options.items())), 0)
    info = check(lib, name, options, seed=7, pixels=(3, 99), sample0=0, n_samples=smp.spp, dim0=0,
                 n_dims=options["dims"])
    want = expect_tiny if lib.build.endswith("tiny-bounds") else expect
    assert (info[2], info[3], info[4]) == want


def test_a_few_samples_of_a_large_array_skip_the_tables(lib):
    """Bose at 65536 spp (s = M = 256): 10 samples do not pay for 256-entry tables (permute per value),
    and a later block's cells are computed per pixel (N = 65536 rows would not pay)."""
    info = check(lib, "bose", dict(spp=65536, dims=600), seed=3, pixels=(5, U32_MAX), sample0=40000,
                 n_samples=10, dim0=255, n_dims=4)
    assert (info[2], info[3]) == (0, 0) and info[4] & PER_PIXEL


def test_requests_outside_the_samples_fall_back_to_the_value_function(lib):
    """sample0 + n_samples > spp: the values are pyoa_sampler_value's (unspecified, but the same, and no
    table is indexed out of range); block 0 only (a later block's walk needs i < N)."""
    fill, other, again, value, info = c_fill(lib, "bose", dict(spp=49, dims=8), seed=1, pixels=(0, 1),
                                             sample0=45, n_samples=8, dim0=0, n_dims=3)
    assert info[1] == 0 and info[5] == 1
    assert np.array_equal(bits(fill), bits(value[0])) and np.array_equal(bits(other), bits(value[1]))


def test_the_scratch_is_as_small_as_documented(lib):
    """fill.h's stated size, H + 4 (5 CHUNK + n_dims (16 + s' + M' + 2 R')) bytes: 1216 bytes per dimension
    for Bose at 121 spp, at most 163904 for any sampler (tables above 4096 entries and cells above 16384
    rows are not held), H alone for the samplers that fall back."""
    def size(name, options, n_dims=10):
        *_, info = c_fill(lib, name, options, seed=0, pixels=(0, 1), sample0=0, n_samples=1, dim0=0, n_dims=1)
        *_, wide = c_fill(lib, name, options, seed=0, pixels=(0, 1), sample0=0, n_samples=1, dim0=0,
                          n_dims=n_dims)
        return int(info[0]), (int(wide[0]) - int(info[0])) // (n_dims - 1)  # (bytes for 1 dim, bytes per dim)

    header, per_dim = size("sobol", dict(spp=128, dims=10))
    assert header <= 256 and header % 64 == 0 and per_dim == 0
    assert size("bose", dict(spp=121, dims=10, offset="mj")) == (header, 0)
    assert size("random", dict(spp=12, dims=5)) == (header, 0)
    if lib.build.endswith("tiny-bounds"):
        return
    chunk = 5 * 4 * 256
    assert size("bose", dict(spp=121, dims=10)) == (header + chunk + 1216, 1216)
    assert size("bose", dict(spp=121, dims=10, offset="centered")) == (header + chunk + 1216 - 64, 1216 - 64)
    largest = 4 * (16 + 4096 + 4096 + 2 * 16384)
    assert size("bose", dict(spp=16752649, dims=3))[1] == largest == 163904
    assert size("cmjnd", dict(spp=16777216, dims=25, strength=24))[1] == 4 * (16 + 16 + 2 * 16384)
    assert size("cmjnd", dict(spp=16777216, dims=1, strength=1), n_dims=2)[1] == 4 * (16 + 16 + 2 * 16384)


def test_the_vectorizable_clamp_keeps_the_bits_of_the_nested_one(lib):
    """floats.h's pyoa_sample_value and pyoa_centered_value, whose clamp makes its two comparisons
    unconditionally (so that GCC vectorizes fill.h's loops) and whose centered cell is chosen on M
    alone, give the bits of the clamp as first written (a nested ?:) on 400000 random inputs, jitters
    at 0, just below 1 and near 0.5 included; over 1 % of them are values the clamp changes (so the
    clamp is exercised, not only the formula)."""
    assert lib.t_floats(1, 200000) == 0 and lib.t_floats(2**31 + 5, 200000) == 0
    assert lib.t_clamped(1, 100000) > 1000


@settings(max_examples=40, deadline=None)
@given(data=st.data())
def test_random_samplers_and_requests_fill_like_the_value_function(lib, data):
    entry = data.draw(st.sampled_from(ENTRIES))
    case = data.draw(st.sampled_from(entry.test_cases()))
    options = dict(case)
    if entry.family == "oa":
        options["offset"] = data.draw(st.sampled_from(OFFSETS))
        options["strength"] = numpy_sampler(entry.name, tuple(sorted(dict(case).items())), 0).strength
        options["dims"] = data.draw(st.integers(case["dims"], case["dims"] + 30))
        if data.draw(st.booleans()):
            options["jitter"] = data.draw(st.sampled_from([0.0, 0.3, 1.0]))
    seed = data.draw(st.integers(0, U32_MAX))
    smp = numpy_sampler(entry.name, tuple(sorted(options.items())), seed)
    n_pix = smp.resolution[0] * smp.resolution[1] if smp.resolution else 2**32
    pixels = tuple(data.draw(st.lists(st.integers(0, n_pix - 1), min_size=2, max_size=2)))
    sample0 = data.draw(st.integers(0, smp.spp - 1))
    n_samples = data.draw(st.integers(1, min(smp.spp - sample0, 40)))
    dim0 = data.draw(st.integers(0, smp.dims - 1))
    n_dims = data.draw(st.integers(1, min(smp.dims - dim0, 12)))
    check(lib, entry.name, options, seed=seed, pixels=pixels, sample0=sample0, n_samples=n_samples, dim0=dim0,
          n_dims=n_dims)
