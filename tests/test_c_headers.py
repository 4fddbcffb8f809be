"""pyoa's portable C headers (kernels/include/pyoa, ``pyoa.get_include()``):
every header compiles alone as C99, C++14, C++17 and CUDA with warnings as
errors, ``keys.h`` matches the reference's keys, and the header functions,
built into a shared library under several language modes and flags, give
the reference's bits (docs/spec.md sections 2, 3, 6 and 7).

The flags include ``-std=gnu11 -O2 -march=native -ffp-contract=fast``: GCC's
GNU modes contract ``a * b + c`` into an FMA on a CPU that has one, which
changes the last bit of ``jitter_value`` for some inputs; the headers switch
contraction off themselves (pyoa/config.h), and this build proves it.
Set ``PYOA_REQUIRE_C=1`` (CI does) to fail instead of skip without gcc/g++,
and ``PYOA_REQUIRE_NVCC=1`` without nvcc."""

from __future__ import annotations

import ctypes
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pyoa import c_headers
from pyoa.reference import floats as rf
from pyoa.reference import hashes as rh

INCLUDE = Path(c_headers.get_include())
HEADERS = sorted((INCLUDE / "pyoa").glob("*.h"))
SHIM = Path(__file__).parent / "c" / "shim.c"
U32 = 0xFFFFFFFF
WARN = ["-Wall", "-Wextra", "-Werror", "-pedantic"]

#: id -> (compiler, source suffix, flags): the language modes the headers promise.
MODES = {
    "gcc-c99": ("gcc", ".c", ["-std=c99", *WARN]),
    "g++-c++14": ("g++", ".cpp", ["-std=c++14", *WARN]),
    "g++-c++17": ("g++", ".cpp", ["-std=c++17", *WARN]),
}
#: id -> (compiler, suffix, flags) of the shared libraries compared with the reference.
BUILDS = {
    "c99-O0": ("gcc", ".c", ["-std=c99", "-O0", *WARN]),
    "gnu11-O2-native-contract": ("gcc", ".c", ["-std=gnu11", "-O2", "-march=native", "-ffp-contract=fast", *WARN]),
    "c++14-O2": ("g++", ".cpp", ["-std=c++14", "-O2", *WARN]),
}


def need(tool: str, env: str) -> str:
    path = shutil.which(tool)
    if path is None:
        if os.environ.get(env) == "1":
            pytest.fail(f"{tool} not found and {env}=1")
        pytest.skip(f"{tool} not found (set {env}=1 to make this a failure)")
    return path


def compile_(compiler: str, args: list[str], cwd: Path) -> None:
    proc = subprocess.run([compiler, *args], cwd=cwd, capture_output=True, text=True)
    assert proc.returncode == 0, f"{compiler} {' '.join(args)}:\n{proc.stderr}"


def test_headers_exist():
    assert {h.name for h in HEADERS} >= {"config.h", "keys.h", "hashes.h", "floats.h"}


def test_keys_header_matches_the_reference():
    """keys.h is generated from pyoa.reference's *_KEY constants; a key
    changed there and not regenerated here (python -m pyoa.c_headers) fails."""
    assert (INCLUDE / "pyoa" / "keys.h").read_text() == c_headers.keys_header()


@pytest.mark.parametrize("mode", list(MODES))
@pytest.mark.parametrize("header", [h.name for h in HEADERS])
def test_every_header_compiles_alone(tmp_path, mode, header):
    compiler, suffix, flags = MODES[mode]
    need(compiler, "PYOA_REQUIRE_C")
    src = tmp_path / f"tu{suffix}"
    src.write_text(f"#include <pyoa/{header}>\nint pyoa_tu_{header.replace('.', '_')} = 1;\n")
    compile_(compiler, [*flags, f"-I{INCLUDE}", "-c", str(src), "-o", str(tmp_path / "tu.o")], tmp_path)


@pytest.mark.parametrize("header", [h.name for h in HEADERS])
def test_every_header_compiles_as_cuda(tmp_path, header):
    """CUDA: compile only (nothing built here runs without a GPU). The
    header's functions are __host__ __device__; a kernel calls them so that
    the device side is compiled too."""
    nvcc = need("nvcc", "PYOA_REQUIRE_NVCC")
    src = tmp_path / "tu.cu"
    src.write_text(f"#include <pyoa/{header}>\n"
                   "#include <pyoa/hashes.h>\n#include <pyoa/floats.h>\n"
                   "__global__ void k(float *out, unsigned n) {\n"
                   "    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;\n"
                   "    if (i < n) out[i] = pyoa_jitter_value(pyoa_randfloat(pyoa_block_row(i, n, 7u), 3u), 0.5f)"
                   " + pyoa_sample_value(i % 11u, i % 7u, 0.25f, 7u, 11u);\n}\n")
    compile_(nvcc, ["-std=c++14", f"-I{INCLUDE}", "--Werror", "all-warnings", "-Xcompiler", "-Wall,-Wextra,-Werror",
                    "-c", str(src), "-o", str(tmp_path / "tu.o")], tmp_path)


@pytest.fixture(scope="module", params=list(BUILDS))
def lib(request, tmp_path_factory):
    """The shim (tests/c/shim.c) built as a shared library in one mode, loaded with ctypes."""
    compiler, suffix, flags = BUILDS[request.param]
    need(compiler, "PYOA_REQUIRE_C")
    d = tmp_path_factory.mktemp(request.param)
    src = d / f"shim{suffix}"
    src.write_text(SHIM.read_text())
    so = d / "shim.so"
    compile_(compiler, [*flags, "-shared", "-fPIC", f"-I{INCLUDE}", str(src), "-o", str(so)], d)
    return ctypes.CDLL(str(so))


def call(lib, name: str, *arrays, out_dtypes=(np.uint32,), out_shapes=None):
    """lib.name(n, *arrays, *outs) over 1-D arrays of one length n; the outputs."""
    n = len(arrays[0])
    ins = [np.ascontiguousarray(a) for a in arrays]
    outs = [np.zeros(shape if shape else n, dt) for dt, shape in zip(out_dtypes, out_shapes or [None] * len(out_dtypes))]
    getattr(lib, name)(ctypes.c_size_t(n), *(a.ctypes.data_as(ctypes.c_void_p) for a in ins + outs))
    return outs


def u32(xs) -> np.ndarray:
    return np.asarray(xs, dtype=np.uint32)


def f32(xs) -> np.ndarray:
    return np.asarray(xs, dtype=np.float32)


def bits(x) -> np.ndarray:
    return np.asarray(x, np.float32).view(np.uint32)


# ----------------------------------------------------------------------------- hashes

permute_inputs = st.integers(1, 2**31).flatmap(
    lambda l: st.tuples(st.integers(0, l - 1), st.just(l), st.integers(0, U32)))
EDGE_PERMUTES = [(0, 1, 5), (0, 2, 0), (1, 2, U32), (2**31 - 1, 2**31, U32), (2**24 - 1, 2**24, 1),
                 (120, 121, U32), (0, 121, 0), (126, 127, 0x80000000), (3, 4, 2**27)]


@settings(max_examples=60, deadline=None)
@given(st.lists(permute_inputs, min_size=1, max_size=40))
def test_permute_and_block_row_match_the_reference(lib, cases):
    cases = cases + EDGE_PERMUTES
    i, l, p = (u32(c) for c in zip(*cases))
    (got,) = call(lib, "t_permute", i, l, p)
    assert got.tolist() == [rh.permute(*c) for c in cases]
    (rows,) = call(lib, "t_block_row", i, l, p)
    assert rows.tolist() == [rh.block_row(*c) for c in cases]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(0, U32), st.integers(0, U32), st.integers(0, U32)), min_size=1, max_size=40))
def test_seeds_and_randfloat_match_the_reference(lib, cases):
    cases = cases + [(0, 0, 0), (U32, U32, U32), (0, 1, 0), (U32, 0, 1)]
    a, b, key = (u32(c) for c in zip(*cases))
    out, order = call(lib, "t_seeds", a, b, key, out_dtypes=(np.uint32, np.uint32), out_shapes=(5 * len(a), None))
    want = [[rh.mix32(x), rh.hash_pair(x, y, k), rh.pixel_seed(x, y), rh.block_seed(x, y), rh.frame_seed(x, y)]
            for x, y, k in cases]
    assert out.reshape(-1, 5).tolist() == want
    assert order.tolist() == [rh.block_order_seed(x, y, k) for x, y, k in cases]
    (r,) = call(lib, "t_randfloat", a, b, out_dtypes=(np.float32,))
    assert bits(r).tolist() == bits([rh.randfloat(x, y) for x, y, _ in cases]).tolist()


# ----------------------------------------------------------------------------- floats

def floats_of(draw_bits):
    """float32 jitters in [0, 1) from their bits (every float32 of [0, 1) is
    a bit pattern below that of 1.0)."""
    return np.asarray(draw_bits, np.uint32).view(np.float32)


value_inputs = st.tuples(st.integers(1, 4096), st.integers(1, 4096)).flatmap(
    lambda sm: st.tuples(st.integers(0, sm[0] - 1), st.integers(0, sm[1] - 1), st.integers(0, 0x3F7FFFFF),
                         st.just(sm[1]), st.just(sm[0])))
EDGE_VALUES = [(0, 0, 0, 1, 1), (4095, 4095, 0x3F7FFFFF, 4096, 4096), (10, 10, 0x3F7FFFFF, 11, 11),
               (0, 0, 1, 4096, 4096), (3, 0, 0x3F000000, 1, 7)]


@settings(max_examples=60, deadline=None)
@given(st.lists(value_inputs, min_size=1, max_size=40))
def test_sample_and_centered_values_match_the_reference(lib, cases):
    cases = cases + EDGE_VALUES
    stratum, sub, jb, M, s = (u32(c) for c in zip(*cases))
    jitter = floats_of(jb)
    (got,) = call(lib, "t_sample_value", stratum, sub, jitter, M, s, out_dtypes=(np.float32,))
    want = [rf.sample_value(int(a), int(b), float(j), int(m), int(ss))
            for a, b, j, m, ss in zip(stratum, sub, jitter, M, s)]
    assert bits(got).tolist() == bits(want).tolist()
    (cen,) = call(lib, "t_centered_value", stratum, jitter, M, s, out_dtypes=(np.float32,))
    want = [rf.sample_value(int(a), (int(m) - 1) / 2, float(j), int(m), int(ss))
            for a, j, m, ss in zip(stratum, jitter, M, s)]
    assert bits(cen).tolist() == bits(want).tolist()


def test_jitter_value_is_not_contracted(lib):
    """0.5 + amount * (r - 0.5) in three rounded operations: 200,000 random
    (r, amount) pairs, among which a fused multiply-add gives other bits for
    some (the gnu11 -march=native -ffp-contract=fast build would, without
    the headers' own guard)."""
    rng = np.random.default_rng(5)
    r = floats_of(rng.integers(0, 0x3F800000, 200_000))
    amount = floats_of(rng.integers(0, 0x3F800000, 200_000))
    (got,) = call(lib, "t_jitter_value", r, amount, out_dtypes=(np.float32,))
    want = np.float32(0.5) + amount * (r - np.float32(0.5))  # NumPy: each operation rounded alone
    fused = (np.float64(amount) * (np.float64(r) - 0.5) + 0.5).astype(np.float32)
    assert (bits(fused) != bits(want)).any()  # the inputs do tell the two apart
    assert bits(got).tolist() == bits(want).tolist()


def test_a_wheel_ships_every_header():
    """setup.cfg's package data for pyoa.kernels covers every header, so that
    get_include() names a complete folder in a regular (non-editable) install."""
    import configparser
    import fnmatch

    root = Path(__file__).resolve().parent.parent
    cfg = configparser.ConfigParser()
    cfg.read(root / "setup.cfg")
    patterns = [pat.strip() for pat in cfg["options.package_data"]["pyoa.kernels"].split(",")]
    headers = [p.relative_to(root / "kernels").as_posix() for p in (root / "kernels" / "include").rglob("*.h")]
    assert headers
    missing = [h for h in headers if not any(fnmatch.fnmatch(h, pat) for pat in patterns)]
    assert not missing, f"headers outside setup.cfg's package_data for pyoa.kernels: {missing}"
