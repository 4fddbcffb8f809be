"""pyoa in a renderer (docs/renderers.md): the example programs, the C++
class ``pyoa::Sampler`` (kernels/include/pyoa/sampler.hpp) and the page's
CUDA example.

- The page's bash block that builds and runs ``examples/c/integrate7d.c`` and
  ``examples/cpp/integrate7d.cpp`` runs here as written (in a copy of
  ``examples/``, with ``cc``/``c++`` being gcc/g++), so the commands a reader
  copies are the ones tested; its output must be the one the page shows.
  Both programs estimate a 7-dimensional Genz Gaussian integral per pixel
  (exact value (sqrt(pi) erf(1/2))^7) and print the RMS error over pixels of
  bose and of pyoa's random sampler: bose's must be at least MARGIN times
  smaller (measured 13.5; jittered2d gets 3.3 and random 1.0, both below
  the margin, which the tests check too, so the margin can fail).
- ``pyoa::Sampler``'s Get1D/Get2D/GetPixel2D give the Python API's values
  bit for bit at pixel index y * width + x, from any starting dimension,
  with the seed folded by ``pyoa::FrameSeed`` (the page's formula).
- ``sampler.hpp`` compiles alone as C++14 and C++17 with warnings as errors
  (tests/test_c_headers.py globs only ``*.h``), and nvcc compiles the page's
  CUDA example, whose first line includes the header (compile only).

Set ``PYOA_REQUIRE_C=1`` (CI does) to fail instead of skip without gcc/g++,
and ``PYOA_REQUIRE_NVCC=1`` without nvcc.
"""

from __future__ import annotations

import ctypes
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pytest_codeblocks import extract_from_file

import pyoa
from pyoa import c_headers, catalogue
from pyoa.reference.hashes import frame_seed, hash_pair

from .test_c_headers import WARN, need

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "renderers.md"
INCLUDE = Path(c_headers.get_include())
HPPS = sorted((INCLUDE / "pyoa").glob("*.hpp"))
#: bose's RMS error must be at least this many times below random's (measured: 13.5 at 49 spp).
MARGIN = 5.0
#: the page's numbers are 4 significant digits (ratios 3): stale by more than this fails.
DOC_RTOL = 1e-2
#: the key of the page's frame rule (pyoa::FrameSeed).
FRAME_KEY = 0x7F4A7C15
LINE = re.compile(r"^(?P<name>\S+)\s+RMS error (?P<err>\S+)$")
RATIO = re.compile(r"^random / (?P<name>\S+): (?P<ratio>\S+)$")


def doc_block(needle: str, syntax: str = "bash"):
    """The one code block of docs/renderers.md in `syntax` whose code contains `needle`."""
    found = [b for b in extract_from_file(DOC) if (b.syntax or "").strip() == syntax and needle in b.code]
    assert len(found) == 1, f"{DOC.name}: {len(found)} {syntax} blocks contain {needle!r}"
    return found[0]


def block_after(block):
    """The code block that follows `block` on the page (an output shown as text)."""
    blocks = extract_from_file(DOC)
    i = next(k for k, b in enumerate(blocks) if b.lineno == block.lineno)
    return blocks[i + 1]


def results(text: str) -> dict:
    """{sampler name: RMS error} and the ratio lines of one program's output."""
    errors, ratios = {}, {}
    for line in text.splitlines():
        if m := LINE.match(line):
            errors[m["name"]] = float(m["err"])
        elif m := RATIO.match(line):
            ratios[m["name"]] = float(m["ratio"])
    return {"errors": errors, "ratios": ratios}


def tokens_match(got: str, want: str, rtol: float) -> bool:
    """Same words; numbers equal to rtol."""
    a, b = got.split(), want.split()
    if len(a) != len(b):
        return False
    for x, y in zip(a, b):
        try:
            fx, fy = float(x.rstrip(";,")), float(y.rstrip(";,"))
        except ValueError:
            if x != y:
                return False
            continue
        if not math.isclose(fx, fy, rel_tol=rtol):
            return False
    return True


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The page's build-and-run block, run as written in a copy of examples/."""
    gcc = need("gcc", "PYOA_REQUIRE_C")
    gpp = need("g++", "PYOA_REQUIRE_C")
    d = tmp_path_factory.mktemp("examples")
    shutil.copytree(ROOT / "examples", d / "examples")
    tools = d / "bin"
    tools.mkdir()
    (tools / "cc").symlink_to(gcc)  # the page says cc and c++; the test's compilers are gcc and g++
    (tools / "c++").symlink_to(gpp)
    env = dict(os.environ, PATH=os.pathsep.join([str(tools), str(Path(sys.executable).parent),
                                                 os.environ.get("PATH", "")]))
    block = doc_block("examples/c/integrate7d.c")
    res = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", block.code], cwd=d, env=env, capture_output=True,
                         text=True, timeout=600)
    assert res.returncode == 0, f"{DOC.name} line {block.lineno}:\n{res.stdout}\n{res.stderr}"
    return SimpleNamespace(dir=d, env=env, block=block, stdout=res.stdout)


def run_example(built, program: str, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(built.dir / program), *args], cwd=built.dir, capture_output=True, text=True,
                          timeout=120)


def test_the_block_builds_only_with_pyoas_flags():
    """The page's two builds take their include flags from `python -m pyoa.config --cflags` and add
    only -std, -O2, -o and -lm: nothing that could break bit-exactness (-ffast-math, ...)."""
    block = doc_block("examples/c/integrate7d.c")
    builds = [line for line in block.code.splitlines() if line.startswith(("cc ", "c++ "))]
    assert [line.split()[1] for line in builds] == ["-std=c99", "-std=c++14"]
    for line in builds:
        assert line.count("$(python -m pyoa.config --cflags)") == 1
        rest = line.replace("$(python -m pyoa.config --cflags)", "").split()[1:]
        assert sorted(w for w in rest if w.startswith("-")) == sorted([rest[0], "-O2", "-o", "-lm"])


def test_the_page_shows_what_the_programs_print(built):
    want = built.block.expected_output
    assert want is not None, "the block must be followed by <!--pytest-codeblocks:expected-output--> and its output"
    assert tokens_match(built.stdout, want, DOC_RTOL), f"printed:\n{built.stdout}\nthe page shows:\n{want}"


def test_the_c_and_cpp_programs_print_the_same_lines(built):
    """The C++ program draws dimensions 0..6 with GetPixel2D, Get1D, Get2D, Get2D: the C program's
    pyoa_sampler_value calls, in order, so every byte agrees."""
    lines = built.stdout.splitlines()
    assert len(lines) == 8 and lines[:4] == lines[4:]


def test_bose_beats_random_by_the_margin(built):
    out = results(built.stdout)
    bose, rand = out["errors"]["bose"], out["errors"]["random"]
    assert all(math.isfinite(e) and e > 0 for e in (bose, rand))
    assert rand / bose >= MARGIN, f"random / bose = {rand / bose:.2f} < {MARGIN}"
    assert math.isclose(out["ratios"]["bose"], rand / bose, rel_tol=0.01)
    exact = float(re.search(r"exact integral (\S+);", built.stdout)[1])
    assert math.isclose(exact, (math.sqrt(math.pi) * math.erf(0.5)) ** 7, rel_tol=1e-6)


@pytest.mark.parametrize("name", ["random", "jittered2d"])
def test_the_margin_fails_for_samplers_that_do_not_stratify_every_pair(built, name):
    """The margin is not a tautology: random against itself (ratio 1) and a padded 2D sampler (3.3,
    which stratifies only pairs 0-1, 2-3, 4-5) fall below it."""
    res = run_example(built, "integrate7d-c", name)
    assert res.returncode == 0, res.stderr
    out = results(res.stdout)
    ratio = out["errors"]["random"] / out["errors"][name]
    assert ratio < MARGIN
    if name == "random":
        assert out["errors"]["random"] == out["errors"][name]


def _python_rms(name: str, spp: int, seed: int, width: int = 32, height: int = 32) -> float:
    """The programs' experiment from the Python API: RMS over pixels of the per-pixel estimate."""
    resolution = (width, height) if catalogue.get(name).needs_resolution else None
    s = pyoa.sampler(name, spp=spp, dims=7, seed=seed, resolution=resolution, backend="numpy")
    x = s.generate(pixels=range(width * height)).astype(np.float64)
    estimate = np.exp(-((x - 0.5) ** 2).sum(axis=-1)).mean(axis=1)
    exact = (math.sqrt(math.pi) * math.erf(0.5)) ** 7
    return float(np.sqrt(np.mean((estimate - exact) ** 2)))


@pytest.mark.parametrize("args", [("sobol", "64", "5"), ("zsobol", "64", "1"), ("cmjnd", "121", "3"),
                                  ("addelman-kempthorne", "50", "0"), ("halton", "49", "2"), ("zfaure", "49", "1")])
def test_other_samplers_agree_between_c_cpp_and_python(built, args):
    """Samplers with tables (sobol, halton, addelman-kempthorne) and zsobol and zfaure, which need the image:
    the C and C++ programs print the same lines, and the errors are the Python API's."""
    c, cpp = run_example(built, "integrate7d-c", *args), run_example(built, "integrate7d-cpp", *args)
    assert c.returncode == 0 and cpp.returncode == 0, c.stderr + cpp.stderr
    assert c.stdout == cpp.stdout
    errors = results(c.stdout)["errors"]
    name, spp, seed = args[0], int(args[1]), int(args[2])
    assert errors[name] == pytest.approx(_python_rms(name, spp, seed), rel=2e-3)
    assert errors["random"] == pytest.approx(_python_rms("random", spp, seed), rel=2e-3)


def test_a_count_the_sampler_cannot_make_is_refused_with_the_python_message(built):
    """The page's refusal: its command, its exit status 1 and its message, which is the Python API's."""
    block = doc_block("./integrate7d-c bose 50")
    command = block.code.split("#")[0].split()
    shown = block_after(block).code.strip()
    with pytest.raises(ValueError) as exc:
        pyoa.sampler("bose", spp=50, dims=7)
    assert shown == f"integrate7d: {exc.value}"
    for program in ("integrate7d-c", "integrate7d-cpp"):
        res = run_example(built, program, *command[1:])
        assert res.returncode == 1 and res.stdout == ""
        assert res.stderr == shown + "\n"


# ----------------------------------------------------------------------------- the C++ class

SHIM = r"""
#include <cstring>
#include <vector>
#include <pyoa/sampler.hpp>

namespace {
struct Point { int x, y; };  /* a renderer's point type */

int finish(const pyoa::Status &st, char *message, std::size_t size)
{
    std::strncpy(message, st.message, size - 1);
    message[size - 1] = '\0';
    return st.code;
}
}  // namespace

/* Make the sampler (options: dims given; convenience: Create(name, spp, width, height, seed)), then for
 * each point: a clone, StartPixelSample (the int overload for even k, the point template for odd k; the
 * two-argument form, dimension 0, where dim0 < 0), Get1D, Get2D, GetPixel2D. out: 5 values per point;
 * state: pixel index, sample, dimension after Start, dimension at the end. */
extern "C" int t_class(const char *name, int spp, int dims, int width, int height, unsigned seed, unsigned frame,
                       int convenience, std::size_t n, const int *xs, const int *ys, const int *samples,
                       const int *dim0, float *out, unsigned *state, int *spp_out, char *message,
                       std::size_t message_size)
{
    std::vector<pyoa_u64> table;
    auto allocate = [&table](std::size_t bytes) {
        table.resize((bytes + 7) / 8);
        return static_cast<void *>(table.data());
    };
    pyoa::Sampler s;
    pyoa::Status st;
    if (convenience) {
        st = pyoa::Sampler::Create(s, name, spp, width, height, (int)pyoa::FrameSeed(seed, frame), allocate);
    } else {
        pyoa_options o = pyoa_options_default(name, (pyoa_u32)spp);
        o.dims = (pyoa_u32)dims;
        o.seed = pyoa::FrameSeed(seed, frame);
        st = pyoa::Sampler::Create(s, o, width, height, allocate);
    }
    if (finish(st, message, message_size) != PYOA_OK)
        return st.code;
    *spp_out = s.SamplesPerPixel();
    for (std::size_t k = 0; k < n; ++k) {
        pyoa::Sampler c = s.Clone();
        if (dim0[k] < 0)
            c.StartPixelSample(Point{xs[k], ys[k]}, samples[k]);
        else if (k % 2)
            c.StartPixelSample(Point{xs[k], ys[k]}, samples[k], dim0[k]);
        else
            c.StartPixelSample(xs[k], ys[k], samples[k], dim0[k]);
        state[4 * k] = c.PixelIndex();
        state[4 * k + 1] = c.SampleIndex();
        state[4 * k + 2] = c.Dimension();
        out[5 * k] = c.Get1D();
        pyoa::Point2f a = c.Get2D();
        pyoa::Point2f b = c.GetPixel2D();
        out[5 * k + 1] = a.x;
        out[5 * k + 2] = a.y;
        out[5 * k + 3] = b.x;
        out[5 * k + 4] = b.y;
        state[4 * k + 3] = c.Dimension();
    }
    return 0;
}

extern "C" unsigned t_frame_seed(unsigned seed, unsigned frame) { return pyoa::FrameSeed(seed, frame); }

/* Create with an allocator that gives no memory. */
extern "C" int t_no_memory(const char *name, int spp, char *message, std::size_t message_size)
{
    pyoa::Sampler s;
    pyoa::Status st = pyoa::Sampler::Create(s, name, spp, 8, 8, 0, [](std::size_t) -> void * { return nullptr; });
    return finish(st, message, message_size);
}

/* Create with a bad width, height or count. */
extern "C" int t_bad_args(int spp, int width, int height, char *message, std::size_t message_size)
{
    pyoa::Sampler s;
    std::vector<pyoa_u64> table;
    pyoa::Status st = pyoa::Sampler::Create(s, "bose", spp, width, height, 0, [&table](std::size_t bytes) {
        table.resize((bytes + 7) / 8);
        return static_cast<void *>(table.data());
    });
    return finish(st, message, message_size);
}
"""

WIDTH, HEIGHT = 37, 23  # not square: a swapped x and y or a wrong width shows


@pytest.fixture(scope="module")
def cls(tmp_path_factory):
    gpp = need("g++", "PYOA_REQUIRE_C")
    d = tmp_path_factory.mktemp("hpp")
    src = d / "class_shim.cpp"
    src.write_text(SHIM)
    so = d / "class_shim.so"
    res = subprocess.run([gpp, "-std=c++14", "-O1", *WARN, "-shared", "-fPIC", f"-I{INCLUDE}", str(src), "-o",
                          str(so)], capture_output=True, text=True, cwd=d)
    assert res.returncode == 0, res.stderr
    lib = ctypes.CDLL(str(so))
    lib.t_frame_seed.restype = ctypes.c_uint
    lib.t_frame_seed.argtypes = [ctypes.c_uint, ctypes.c_uint]
    return lib


def class_values(lib, name, spp, points, *, dims=0, seed=0, frame=0, convenience=False):
    n = len(points)
    xs, ys, samples, dim0 = (np.ascontiguousarray(np.array(c, dtype=np.int32)) for c in zip(*points))
    out = np.zeros(5 * n, np.float32)
    state = np.zeros(4 * n, np.uint32)
    spp_out = ctypes.c_int(0)
    message = ctypes.create_string_buffer(1024)
    ptr = lambda a: a.ctypes.data_as(ctypes.c_void_p)  # noqa: E731
    code = lib.t_class(name.encode(), spp, dims, WIDTH, HEIGHT, ctypes.c_uint(seed), ctypes.c_uint(frame),
                       int(convenience), ctypes.c_size_t(n), ptr(xs), ptr(ys), ptr(samples), ptr(dim0), ptr(out),
                       ptr(state), ctypes.byref(spp_out), message, ctypes.c_size_t(len(message)))
    assert code == 0, message.value.decode()
    assert spp_out.value == spp
    return out.reshape(n, 5), state.reshape(n, 4)


def python_values(name, spp, dims, seed, points):
    s = pyoa.sampler(name, spp=spp, dims=dims, seed=seed, backend="numpy",
                     resolution=(WIDTH, HEIGHT) if catalogue.get(name).needs_resolution else None)
    rows = []
    for x, y, i, d0 in points:
        d0 = max(d0, 0)
        rows.append(s.generate(pixels=[y * WIDTH + x], samples=[i], dims=range(d0, d0 + 5))[0, 0])
    return np.asarray(rows, np.float32)


def bits(a) -> list:
    return np.asarray(a, np.float32).view(np.uint32).tolist()


#: (name, spp): samplers without a table (random, bose over a prime, zsobol and zfaure with their image)
#: and with one (sobol's direction numbers, bose over GF(8), cmjnd).
CLASS_CASES = [("bose", 49), ("bose", 64), ("cmjnd", 27), ("sobol", 32), ("zsobol", 16), ("random", 10),
               ("faure", 25), ("zfaure", 25)]
DIMS = 24


def points_strategy(spp: int):
    return st.lists(st.tuples(st.integers(0, WIDTH - 1), st.integers(0, HEIGHT - 1), st.integers(0, spp - 1),
                              st.integers(-1, DIMS - 5)), min_size=1, max_size=12)


@pytest.mark.parametrize(("name", "spp"), CLASS_CASES)
@settings(max_examples=8, deadline=None)
@given(data=st.data())
def test_the_class_gives_the_python_apis_bits(cls, name, spp, data):
    """Get1D, Get2D and GetPixel2D read dimensions d, d+1.. d+4 of pixel y * width + x (the class's
    width), bit for bit the Python API's; the dimension counter advances by 1 and 2 as pbrt's does."""
    points = data.draw(points_strategy(spp))
    seed = data.draw(st.integers(0, 2**32 - 1))
    points = points + [(0, 0, 0, 0), (WIDTH - 1, HEIGHT - 1, spp - 1, DIMS - 5)]
    got, state = class_values(cls, name, spp, points, dims=DIMS, seed=seed)
    assert bits(got) == bits(python_values(name, spp, DIMS, seed, points))
    for (x, y, i, d0), (pixel, sample, start, end) in zip(points, state.tolist()):
        assert (pixel, sample, start, end) == (y * WIDTH + x, i, max(d0, 0), max(d0, 0) + 5)


@pytest.mark.parametrize(("name", "spp"), [("bose", 49), ("sobol", 32), ("zsobol", 16), ("zfaure", 25)])
def test_the_convenience_create_and_frames(cls, name, spp):
    """Create(name, spp, width, height, seed) (dims not given, zsobol's and zfaure's image set by the
    class) gives the same values; frame f uses the seed hash_pair(seed, f, 0x7f4a7c15) (the page's rule),
    frame 0 the seed."""
    points = [(3, 4, 1, 0), (WIDTH - 1, 0, spp - 1, 7), (0, HEIGHT - 1, 0, -1)]
    seed = 0xFFFFFFFF  # pbrt's seed -1
    for frame in (0, 1, 12345):
        got, _ = class_values(cls, name, spp, points, seed=seed, frame=frame, convenience=True)
        want = hash_pair(seed, frame, FRAME_KEY) if frame else seed  # the page's formula
        assert cls.t_frame_seed(seed, frame) == want == frame_seed(seed, frame)  # and spec 3.5's reference
        assert bits(got) == bits(python_values(name, spp, DIMS, want, points))
    assert cls.t_frame_seed(7, 0) == 7 and cls.t_frame_seed(7, 1) != cls.t_frame_seed(7, 2) != 7


def _message(fn, *args) -> tuple[int, str]:
    buf = ctypes.create_string_buffer(1024)
    code = fn(*args, buf, ctypes.c_size_t(len(buf)))
    return code, buf.value.decode()


def test_create_reports_the_c_apis_errors(cls):
    code, message = _message(cls.t_bad_args, 50, 32, 32)
    with pytest.raises(ValueError) as exc:
        pyoa.sampler("bose", spp=50, dims=7)
    assert code == 2 and message == str(exc.value)  # PYOA_ERROR_SPP, the Python API's message
    assert _message(cls.t_bad_args, 0, 32, 32) == (2, "pyoa::Sampler::Create: samplesPerPixel must be positive")
    assert _message(cls.t_bad_args, 49, 0, 32) == (5, "pyoa::Sampler::Create: width and height must be positive")
    assert _message(cls.t_bad_args, 49, 32, 32) == (0, "")


def test_create_refuses_an_allocator_without_memory(cls):
    """A sampler with a table (sobol) needs the allocator: no memory is PYOA_ERROR_ALLOCATION; one
    without (random) never calls it."""
    code, message = _message(cls.t_no_memory, b"sobol", 32)
    assert code == 100 and "no 8-byte-aligned memory" in message
    assert _message(cls.t_no_memory, b"random", 32) == (0, "")
    code, message = _message(cls.t_no_memory, b"nope", 32)
    assert code == 1 and message.startswith("unknown sampler 'nope'; valid: bose, ")


# ----------------------------------------------------------------------------- compiling

MODES = {"g++-c++14": ["-std=c++14", *WARN], "g++-c++17": ["-std=c++17", *WARN]}


def test_there_is_a_cpp_header():
    assert "sampler.hpp" in {h.name for h in HPPS}


@pytest.mark.parametrize("mode", list(MODES))
@pytest.mark.parametrize("header", [h.name for h in HPPS])
def test_every_cpp_header_compiles_alone(tmp_path, mode, header):
    gpp = need("g++", "PYOA_REQUIRE_C")
    src = tmp_path / "tu.cpp"
    src.write_text(f"#include <pyoa/{header}>\nint pyoa_tu = 1;\n")
    res = subprocess.run([gpp, *MODES[mode], f"-I{INCLUDE}", "-c", str(src), "-o", str(tmp_path / "tu.o")],
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stderr


def test_the_cpp_header_refuses_c(tmp_path):
    gcc = need("gcc", "PYOA_REQUIRE_C")
    src = tmp_path / "tu.c"
    src.write_text("#include <pyoa/sampler.hpp>\n")
    res = subprocess.run([gcc, "-std=c99", f"-I{INCLUDE}", "-c", str(src), "-o", str(tmp_path / "tu.o")],
                         capture_output=True, text=True)
    assert res.returncode != 0 and "pyoa/sampler.hpp is C++" in res.stderr


def test_the_pages_cuda_example_compiles(tmp_path):
    """The page's CUDA code, with the page's nvcc command, compiles without a warning (nothing runs: no GPU
    here). Its first line includes pyoa/sampler.hpp, so this also compiles the header alone as CUDA: the
    class's methods in a kernel, pyoa::Sampler passed by value."""
    nvcc = need("nvcc", "PYOA_REQUIRE_NVCC")
    block = doc_block("__global__", syntax="cpp")
    assert block.code.splitlines()[0] == "#include <pyoa/sampler.hpp>"
    (tmp_path / "render.cu").write_text(block.code)
    command = re.search(r"`(nvcc [^`]*render\.cu)`", DOC.read_text())
    assert command, "the page names its nvcc command in backquotes"
    env = dict(os.environ, PATH=os.pathsep.join([str(Path(nvcc).parent), str(Path(sys.executable).parent),
                                                 os.environ.get("PATH", "")]))
    res = subprocess.run(["bash", "-e", "-c", command[1] + " --Werror all-warnings"], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, f"{command[1]}:\n{res.stderr}"
    assert (tmp_path / "render.o").is_file()
