"""The renderer API of the portable headers (pyoa/sampler.h), bit for bit
against the Python API: every catalogue sampler, at every test case of its
catalogue entry, every offset, seeds and pixels at both ends of their
ranges, first and last samples, first and last dimensions (and the first
dimension of each later block), and hypothesis draws. The C side is a
shared library built from the headers as C99 and as C++14
(tests/c/sampler_shim.c), the oracle NumPy's ``generate`` (equal to the
reference by the conformance suites) plus the reference's ``value`` on a
few values of each sampler.

Set ``PYOA_REQUIRE_C=1`` (CI does) to fail instead of skip without
gcc/g++."""

from __future__ import annotations

import ctypes
import itertools
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pyoa
from pyoa import catalogue, c_headers
from pyoa.catalogue.entries import OFFSETS
from tests.test_c_headers import INCLUDE, WARN, compile_, need
from tests.test_zfaure import VECTORS as ZFAURE_VECTORS

SHIM = Path(__file__).parent / "c" / "sampler_shim.c"
U32_MAX = 2**32 - 1
ENTRIES = list(catalogue.SAMPLERS.values())
#: id -> (compiler, suffix, flags) of the libraries under test.
BUILDS = {
    "c99-O2": ("gcc", ".c", ["-std=c99", "-O2", *WARN]),
    "c++14-O2": ("g++", ".cpp", ["-std=c++14", "-O2", *WARN]),
}
#: pyoa/sampler.h's error codes (pyoa/counts.h's enum and PYOA_ERROR_JITTER).
ERRORS = {"name": 1, "spp": 2, "strength": 3, "offset": 4, "resolution": 5, "dims": 6, "base": 7, "jitter": 8}


@pytest.fixture(scope="module", params=list(BUILDS))
def lib(request, tmp_path_factory):
    compiler, suffix, flags = BUILDS[request.param]
    need(compiler, "PYOA_REQUIRE_C")
    tmp = tmp_path_factory.mktemp(request.param)
    src = tmp / f"sampler_shim{suffix}"
    src.write_text(SHIM.read_text())
    so = tmp / "libsampler.so"
    compile_(compiler, [*flags, "-shared", "-fPIC", f"-I{INCLUDE}", f"-I{SHIM.parent}", str(src), "-o", str(so)], tmp)
    dll = ctypes.CDLL(str(so))
    u32p = np.ctypeslib.ndpointer(np.uint32, flags="C")
    dll.t_values.argtypes = [ctypes.c_char_p, ctypes.c_uint32, ctypes.c_uint32, ctypes.c_uint32, ctypes.c_char_p,
                             ctypes.c_float, ctypes.c_uint32, ctypes.c_uint32, ctypes.c_uint32, ctypes.c_uint32,
                             ctypes.c_size_t, u32p, u32p, u32p, np.ctypeslib.ndpointer(np.float32, flags="C"), u32p,
                             ctypes.c_char_p, ctypes.c_size_t]
    dll.t_values.restype = ctypes.c_int
    return dll


def c_values(lib, name, *, spp, dims=0, seed=0, offset=None, jitter=1.0, strength=None, base=None,
             resolution=None, pixels=(0,), samples=(0,), dim_list=(0,)):
    """(rc, message, values of the outer product pixels x samples x dims, info)."""
    P, S, D = np.meshgrid(np.asarray(pixels, np.uint32), np.asarray(samples, np.uint32),
                          np.asarray(dim_list, np.uint32), indexing="ij")
    P, S, D = (np.ascontiguousarray(a.ravel()) for a in (P, S, D))
    out = np.zeros(P.size, np.float32)
    info = np.zeros(7, np.uint32)
    msg = ctypes.create_string_buffer(1024)
    width, height = resolution or (0, 0)
    rc = lib.t_values(name.encode(), spp, dims, seed, (offset or "").encode(), jitter, strength or 0, base or 0,
                      width, height, P.size, P, S, D, out, info, msg, len(msg))
    return rc, msg.value.decode(), out.reshape(len(pixels), len(samples), len(dim_list)), info


def edges(n: int, extra=()) -> list[int]:
    """0, 1, n - 2, n - 1 and ``extra`` (those below n), each once, sorted."""
    return sorted({v for v in (0, 1, n - 2, n - 1, *extra) if 0 <= v < n})


def cases():
    """(entry, options) for every test case of every catalogue entry, with
    every offset for the orthogonal arrays."""
    for c in ENTRIES:
        for case in c.test_cases():
            offsets = OFFSETS if c.family == "oa" else (None,)
            for offset in offsets:
                yield pytest.param(c.name, dict(case, offset=offset) if offset else dict(case),
                                   id=f"{c.name}-{'-'.join(f'{k}{v}' for k, v in case.items())}-{offset}")


def compare(lib, name, options, *, seed, pixels=None, samples=None, dims=None):
    smp = pyoa.sampler(name, backend="numpy", seed=seed, **options)
    n_pix = (smp.resolution[0] * smp.resolution[1]) if smp.resolution else 2**32
    pixels = pixels if pixels is not None else edges(n_pix, (12345 % n_pix,))
    samples = samples if samples is not None else edges(smp.spp, (smp.spp // 2,))
    block = smp.block_dims or smp.dims
    dims = dims if dims is not None else edges(smp.dims, (block, block + 1, 2 * block))
    want = smp.generate(pixels=pixels, samples=samples, dims=dims)
    rc, msg, got, info = c_values(lib, name, spp=options["spp"], dims=options["dims"], seed=seed,
                                  offset=options.get("offset"), jitter=options.get("jitter", 1.0),
                                  strength=options.get("strength"), base=options.get("base"),
                                  resolution=options.get("resolution"), pixels=pixels, samples=samples,
                                  dim_list=dims)
    assert rc == 0, msg
    assert got.view(np.uint32).tolist() == want.view(np.uint32).tolist(), (
        f"{name} {options} seed {seed}: C differs from NumPy at "
        f"{np.argwhere(got.view(np.uint32) != want.view(np.uint32))[:5].tolist()}")
    assert info[2] == smp.spp and info[3] == smp.s and info[4] == smp.strength
    return smp, pixels, samples, dims, got


@pytest.mark.parametrize("name, options", list(cases()))
def test_every_catalogue_sampler_matches_numpy_at_the_edges(lib, name, options):
    for seed in (0, 1, U32_MAX):
        compare(lib, name, options, seed=seed)


@pytest.mark.parametrize("name", list(catalogue.SAMPLERS))
def test_every_catalogue_sampler_matches_the_reference(lib, name):
    """A few values of each sampler against the pure-Python reference itself
    (Sampler.value): the C source and the oracle share no code."""
    case = catalogue.get(name).test_cases()[1]
    smp, pixels, samples, dims, got = compare(lib, name, case, seed=2024, pixels=[7, U32_MAX] if "resolution" not in case else [0], samples=[0, case["spp"] - 1], dims=[0, case["dims"] - 1])
    for (a, p), (b, i), (c, j) in itertools.product(enumerate(pixels), enumerate(samples), enumerate(dims)):
        assert np.float32(smp.value(p, i, j)).view(np.uint32) == got[a, b, c].view(np.uint32), (name, p, i, j)


def test_jitter_amounts_match(lib):
    for name, options in [("bose", dict(spp=49, dims=9)), ("bush", dict(spp=64, dims=5, strength=3)),
                          ("jittered2d", dict(spp=16, dims=5)), ("cmj2d", dict(spp=12, dims=4))]:
        for jitter in (0.0, 0.25, 0.7):
            compare(lib, name, dict(options, jitter=jitter), seed=99)


@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_random_samplers_and_positions_match(lib, data):
    entry = data.draw(st.sampled_from(ENTRIES))
    case = data.draw(st.sampled_from(entry.test_cases()))
    if case["spp"] > 2**20 or entry.name == "pmj02" and data.draw(st.booleans()):
        case = entry.test_cases()[0]  # keep NumPy's side small
    options = dict(case)
    if entry.family == "oa":
        options["offset"] = data.draw(st.sampled_from(OFFSETS))
    seed = data.draw(st.integers(0, U32_MAX))
    smp = pyoa.sampler(entry.name, backend="numpy", seed=seed, **options)
    n_pix = (smp.resolution[0] * smp.resolution[1]) if smp.resolution else 2**32
    pixels = data.draw(st.lists(st.integers(0, n_pix - 1), min_size=1, max_size=3, unique=True))
    samples = data.draw(st.lists(st.integers(0, smp.spp - 1), min_size=1, max_size=4, unique=True))
    dims = data.draw(st.lists(st.integers(0, smp.dims - 1), min_size=1, max_size=4, unique=True))
    compare(lib, entry.name, options, seed=seed, pixels=pixels, samples=samples, dims=dims)


def test_zsobol_with_unknown_dims_and_sobol_with_all_dimensions(lib):
    """dims = 0 (a renderer that does not know how many it reads): sobol's
    table then holds all 21201 dimensions, and its last one matches."""
    rc, msg, got, info = c_values(lib, "sobol", spp=64, dims=0, seed=5, samples=[0, 63], dim_list=[0, 21200])
    assert rc == 0, msg
    assert info[0] == 21201 * 32 * 4
    want = pyoa.sampler("sobol", spp=64, dims=21201, seed=5, backend="numpy").generate(samples=[0, 63],
                                                                                       dims=[0, 21200])
    assert got.view(np.uint32).tolist() == want.view(np.uint32).tolist()


def test_zfaure_near_the_64_bit_limit(lib):
    """zfaure at the count and image closest to its 64-bit limit: 1621^2 samples on a 1622 x 1622
    image (k = 2, b^(2k) N = 0.98 * 2^64), the image's corners (top digits 0 and 1) at the first and
    last samples, in three blocks; seeds 0 and 2 put an index T = z N + i past 2^63 (the reference's
    pixel_code; tests/_opencl/test_kernels.py asserts it of the same shape)."""
    b, side = 1621, 1622
    options = dict(spp=b * b, dims=3 * b, resolution=(side, side))
    corners = [y * side + x for x in (0, side - 1) for y in (0, side - 1)]
    for seed in (0, 1, 2):
        compare(lib, "zfaure", options, seed=seed, pixels=corners, samples=[0, 1, b * b - 1],
                dims=[0, b - 1, b, 3 * b - 1])


@pytest.mark.parametrize("vector", ZFAURE_VECTORS, ids=lambda v: f"b{v[0]}-N{v[1]}-px{v[4]}-j{v[8]}")
def test_zfaure_spec_vectors(lib, vector):
    """docs/spec.md section 5.12's test vectors (tests/test_zfaure.py reads them) from the C API, its
    base resolved from the count."""
    b, N, W, H, px, seed, z, i, j, want = vector
    rc, msg, got, info = c_values(lib, "zfaure", spp=N, dims=j + 1, seed=seed, resolution=(W, H), pixels=[px],
                                  samples=[i], dim_list=[j])
    assert rc == 0, msg
    assert info[3] == b and int(got.view(np.uint32)[0, 0, 0]) == want


@pytest.mark.parametrize("name, options, error, shown", [
    ("bose", dict(spp=50, dims=3), "spp", ["49", "64"]),
    ("addelman-kempthorne", dict(spp=100, dims=3), "spp", ["98", "162"]),
    ("bush", dict(spp=64, dims=3, strength=9), "strength", []),
    ("bose", dict(spp=49, dims=3, offset="cmjj"), "offset", ["cmj"]),
    ("sobol", dict(spp=64, dims=3, offset="cmj"), "offset", []),
    ("no-such-sampler", dict(spp=16, dims=3), "name", ["bose"]),
    ("zsobol", dict(spp=16, dims=3), "resolution", []),
    ("zfaure", dict(spp=30, dims=3, resolution=(8, 8)), "spp", ["27 (b=3), 32 (b=2)", "valid for faure"]),
    ("zfaure", dict(spp=25, dims=3), "resolution", ["Morton order"]),
    ("zfaure", dict(spp=25, dims=3, resolution=(8, 8), base=2), "base", ["are 5^2", "base 2 takes 4, 8, 16"]),
    ("zfaure", dict(spp=4093**2, dims=3, resolution=(4094, 1)), "resolution", ["64-bit index"]),
    ("sobol", dict(spp=64, dims=3, jitter=0.5), "jitter", ["jittered2d"]),
    # the jitter is checked before the count, as in Python
    ("sobol", dict(spp=100, dims=3, jitter=0.5), "jitter", ["jittered2d"]),
    ("bose", dict(spp=49, dims=3, jitter=1.5), "jitter", ["[0, 1]"]),
])
def test_invalid_options_are_refused_with_the_python_apis_reasons(lib, name, options, error, shown):
    """The error code names what is wrong, and the message the same valid
    values as Python's ValueError (the nearest counts below and above)."""
    rc, msg, _, _ = c_values(lib, name, **options)
    assert rc == ERRORS[error], (rc, msg)
    with pytest.raises(ValueError) as exc:
        pyoa.sampler(name, backend="numpy", **options)
    for text in shown:
        assert text in msg and text in str(exc.value), (msg, str(exc.value))


def test_message_buffers_are_never_overrun(lib):
    """A 1-byte message buffer gets only its terminating 0."""
    P = np.zeros(1, np.uint32)
    buf = ctypes.create_string_buffer(b"\xff" * 8)
    rc = lib.t_values(b"bose", 50, 3, 0, b"", 1.0, 0, 0, 0, 0, 1, P, P, P, np.zeros(1, np.float32),
                      np.zeros(7, np.uint32), buf, 1)
    assert rc == ERRORS["spp"] and buf.raw[:8] == b"\x00" + b"\xff" * 7


def test_the_api_is_documented_where_renderers_look():
    text = (INCLUDE / "pyoa" / "sampler.h").read_text()
    for fn in ("pyoa_options_default", "pyoa_sampler_make", "pyoa_sampler_table_bytes", "pyoa_sampler_fill_table",
               "pyoa_sampler_bind_table", "pyoa_sampler_value", "pyoa_pixel_index"):
        assert f"{fn}(" in text
    assert c_headers.get_include() == str(INCLUDE)
