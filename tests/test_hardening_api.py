"""Hardening of the sampler API: immutability, pickling, memory sizes,
index arguments, device selectors and analysis inputs refused with clear
errors instead of wrong answers, crashes or raw NumPy messages."""

from __future__ import annotations

import copy
import pickle
import subprocess
import sys
import textwrap
from types import SimpleNamespace

import numpy as np
import pytest

import pyoa
from pyoa import analysis as A
from pyoa import catalogue as constructions
from pyoa.samplers import _physical_memory, parse_bytes
from tests.helpers import assert_same_bits

# ----------------------------------------------------------------------------- immutability


@pytest.mark.parametrize("attr, value", [
    ("spp", 49), ("jitter", 50.0), ("dims", 2), ("seed", 1), ("offset", "j"), ("s", 7), ("strength", 3),
    ("params", None), ("max_bytes", 1), ("backend", "opencl"), ("_backend", None), ("_construction", None),
    ("name", "sobol"), ("new_attribute", 1),
])
def test_sampler_is_immutable(attr, value):
    smp = pyoa.sampler("bose", spp=121, dims=8, seed=5, backend="numpy")
    want = smp.generate(pixels=range(2))
    with pytest.raises(AttributeError, match=f"cannot set '{attr}': samplers are immutable; make a new one "
                                             r"with pyoa\.sampler"):
        setattr(smp, attr, value)
    if hasattr(smp, attr):
        with pytest.raises(AttributeError, match=f"cannot delete '{attr}': samplers are immutable"):
            delattr(smp, attr)
    assert (smp.spp, smp.jitter) == (121, 1.0)
    assert_same_bits(smp.generate(pixels=range(2)), want)


def test_constructions_are_immutable():
    """The catalogue's constructions are shared by every sampler of the process."""
    bose = constructions.get("bose")
    max_s = bose.max_s
    with pytest.raises(AttributeError, match="constructions are immutable"):
        bose.max_s = 3
    with pytest.raises(AttributeError, match="constructions are immutable"):
        del constructions.get("sobol").name
    assert constructions.get("bose").max_s == max_s


# ----------------------------------------------------------------------------- pickling


@pytest.mark.parametrize("name, kw", [
    ("cmjnd", dict(spp=125, dims=7, seed=11, offset="mj", jitter=0.3, strength=3)),
    ("bose", dict(spp=49, dims=20, seed=2**32 - 1)),
    ("sobol", dict(spp=64, dims=5, seed=3)),
    ("jittered2d", dict(spp=16, dims=4, jitter=0.5)),
])
def test_sampler_pickles_and_deep_copies(backend, name, kw):
    """A sampler (an OpenCL one holds an unpicklable context) travels as its
    parameters and gives the same bits on the other side."""
    smp = pyoa.sampler(name, backend=backend, max_bytes="64M", **kw)
    want = smp.generate(pixels=range(5))
    for other in (pickle.loads(pickle.dumps(smp)), copy.deepcopy(smp), copy.copy(smp)):
        assert other is not smp and repr(other) == repr(smp)
        assert (other.backend, other.max_bytes, other.jitter) == (backend, 64 << 20, smp.jitter)
        assert_same_bits(other.generate(pixels=range(5)), want)


def test_pickled_sampler_in_another_process(backend, tmp_path):
    """What a worker process receives: a pickle, unpickled where no sampler was made."""
    smp = pyoa.sampler("bose", spp=121, dims=8, seed=7, backend=backend)
    (tmp_path / "s.pkl").write_bytes(pickle.dumps(smp))
    code = ("import pickle, sys, numpy as np\n"
            "s = pickle.loads(open(sys.argv[1], 'rb').read())\n"
            "np.save(sys.argv[2], s.generate(pixels=range(3)))\n")
    res = subprocess.run([sys.executable, "-c", code, str(tmp_path / "s.pkl"), str(tmp_path / "x.npy")],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert_same_bits(np.load(tmp_path / "x.npy"), smp.generate(pixels=range(3)))


# ----------------------------------------------------------------------------- max_bytes


@pytest.mark.parametrize("value, want", [
    (4096, 4096), ("100", 100), ("1e9", 10**9), ("4G", 4 << 30), ("512MiB", 512 << 20), ("1.5GB", 3 << 29),
    (" 2k ", 2048), ("100B", 100), ("1", 1), ("0.5K", 512), (np.int64(7), 7),
])
def test_parse_bytes_accepts(value, want):
    assert parse_bytes(value) == want


@pytest.mark.parametrize("value", [0.25, "0.25", "1.0", ".5", np.float32(0.5)])
def test_parse_bytes_fraction_of_ram(value):
    assert parse_bytes(value) == int(float(value) * _physical_memory())


@pytest.mark.parametrize("value, exc, words", [
    ("1e999", ValueError, ["'1e999'", "not a finite size", "4G"]),
    ("e", ValueError, ["'e'", "memory size", "512MiB"]),
    ("1.01", ValueError, ["'1.01'", "fraction of RAM", "(0, 1]"]),
    ("2.5", ValueError, ["fraction of RAM"]),
    (2.0, ValueError, ["fraction of RAM", "(0, 1]"]),
    (float("inf"), ValueError, ["(0, 1]"]),
    (float("nan"), ValueError, ["(0, 1]"]),
    (0.0, ValueError, ["(0, 1]"]),
    ("0", ValueError, ["less than one byte"]),
    (0, ValueError, ["less than one byte"]),
    (-5, ValueError, ["less than one byte"]),
    ("0.0001K", ValueError, ["less than one byte"]),
    ("5e-1", ValueError, ["not a whole number of bytes"]),
    ("-1", ValueError, ["memory size"]),
    ("inf", ValueError, ["memory size"]),
    ("3iB", ValueError, ["memory size"]),
    ("", ValueError, ["memory size"]),
    (True, TypeError, ["bool"]),
    ([1], TypeError, ["list"]),
])
def test_parse_bytes_refuses(value, exc, words):
    with pytest.raises(exc) as info:
        parse_bytes(value)
    msg = str(info.value)
    assert "max_bytes" in msg and "\n" not in msg
    for w in words:
        assert w in msg, msg


def test_max_bytes_argument_forms():
    assert pyoa.sampler("bose", spp=9, dims=2, backend="numpy", max_bytes=0.25).max_bytes == \
        int(0.25 * _physical_memory())
    for bad in ("1e999", "e", "1.01", 2.5):
        with pytest.raises(ValueError, match="max_bytes="):
            pyoa.sampler("bose", spp=9, dims=2, backend="numpy", max_bytes=bad)


@pytest.mark.parametrize("env", ["lots", "1e999", "1.01", "0"])
def test_bad_environment_max_bytes_is_named(monkeypatch, env):
    monkeypatch.setenv("PYOA_MAX_BYTES", env)
    with pytest.raises(ValueError, match=r"\$PYOA_MAX_BYTES="):
        pyoa.sampler("bose", spp=9, dims=2, backend="numpy")


# ----------------------------------------------------------------------------- memory

def run_limited(code: str, extra_gib: float = 1.5) -> subprocess.CompletedProcess:
    """Run ``code`` in a child whose address space is capped at what it uses
    after importing pyoa plus ``extra_gib``: a regression that allocates the
    whole request fails the test (MemoryError) instead of exhausting the machine."""
    prelude = textwrap.dedent(f"""
        import resource
        import numpy as np
        import pyoa, pyoa.qmc
        pyoa.sampler("bose", spp=9, dims=2).generate()  # warm up: threads, caches
        size = next(int(l.split()[1]) * 1024 for l in open("/proc/self/status") if l.startswith("VmSize"))
        limit = size + int({extra_gib} * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    """)
    return subprocess.run([sys.executable, "-c", prelude + textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=120, env={**__import__("os").environ, "PYOA_BACKEND": "numpy"})


def test_default_limit_follows_an_address_space_limit():
    """The default memory limit is half of what the process may use: under
    ``ulimit -v`` (here: 1.5 GiB beyond the current size) a 3 GiB request is
    refused with the size, not attempted (it used to be sized from the
    physical memory alone and fail with MemoryError)."""
    code = """
        s = pyoa.sampler("bose", spp=121, dims=8, backend="numpy")
        try:
            s.generate(pixels=range(832_000))
        except Exception as exc:
            print(type(exc).__name__, exc)
    """
    res = run_limited(code)
    assert res.returncode == 0, res.stderr
    line = res.stdout.strip()
    assert line.startswith("ValueError") and "memory limit" in line and "3.0 GiB" in line, line


def test_huge_pixel_ranges_are_refused_before_allocating():
    code = """
        import time
        s = pyoa.sampler("bose", spp=121, dims=8, max_bytes=1000)
        for pixels in (range(2**32), range(2**28), range(0, 2**32, 3), list(range(2**20))):
            t0 = time.perf_counter()
            try:
                s.generate(pixels=pixels)
            except Exception as exc:
                print(type(exc).__name__, round(time.perf_counter() - t0, 3), exc)
        big = pyoa.sampler("bose", spp=121, dims=8)  # the default limit: half the RAM
        try:
            big.generate(pixels=range(2**32))
        except Exception as exc:
            print(type(exc).__name__, 0, exc)
        one = pyoa.sampler("bose", spp=121, dims=1, max_bytes="1G")
        try:  # output 1 GiB, plus 1 GiB of pixel indices
            one.generate(pixels=range(2**28), samples=[0], dims=[0])
        except Exception as exc:
            print(type(exc).__name__, 0, exc)
    """
    res = run_limited(code)
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    assert len(lines) == 6, res.stdout
    for line in lines:
        kind, seconds, msg = line.split(" ", 2)
        assert kind == "ValueError", line
        assert float(seconds) < 0.5, line  # refused before building any index array
        assert "over the memory limit" in msg and "index arrays" in msg
    assert "4294967296 x 121 x 8" in lines[0] and "1000 B" in lines[0]
    assert "268435456 x 1 x 1" in lines[5] and "2.0 GiB" in lines[5] and "1.0 GiB" in lines[5]


def test_huge_qmc_draw_is_refused_before_allocating():
    code = """
        from pyoa.qmc import OrthogonalArray
        engine = OrthogonalArray(d=3, rng=1)
        for n in (10**9, 10**11):
            try:
                engine.random(n)
            except Exception as exc:
                print(type(exc).__name__, exc)
        small = OrthogonalArray(d=2, spp=49, rng=1, max_bytes="1K")
        print(small.random(64).shape)
        try:
            small.random(65)
        except Exception as exc:
            print(type(exc).__name__, exc)
    """
    res = run_limited(code)
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    assert lines[0].startswith("ValueError random(n=1000000000) needs 22.4 GiB"), res.stdout
    assert "memory limit" in lines[0] and "max_bytes" in lines[0]
    assert lines[1].startswith("ValueError random(n=100000000000) needs 2.2 TiB"), res.stdout
    assert lines[2] == "(64, 2)"  # 64 * 2 * 8 = 1 KiB exactly
    assert lines[3].startswith("ValueError random(n=65)") and "1.0 KiB" in lines[3]


# ----------------------------------------------------------------------------- index arguments

class Pixels:
    """An array-like that is not a sequence (pandas, xarray...)."""

    def __init__(self, values):
        self.values = values

    def __array__(self, dtype=None, copy=None):
        return np.asarray(self.values, dtype=dtype)


@pytest.mark.parametrize("value, exc, words", [
    ([-1, 2**64 - 1], ValueError, ["must lie in [0,", "got -1"]),
    ([3, 2**64 - 1], ValueError, ["must lie in [0,", str(2**64 - 1)]),
    ({1, 2}, TypeError, ["range or a sequence", "set", "no order"]),
    ({1: 2}, TypeError, ["range or a sequence", "dict"]),
    (frozenset([1]), TypeError, ["frozenset"]),
    ([[0], [1, 2]], ValueError, ["one-dimensional", "position 0"]),
    ([0, [1, 2]], ValueError, ["one-dimensional", "list at position 1"]),
    (np.array([1, 2], dtype="timedelta64[s]"), TypeError, ["integers", "timedelta64"]),
    ([np.timedelta64(1, "s")], TypeError, ["integers", "timedelta64"]),
    (np.array(["2020-01-01"], dtype="datetime64[D]"), TypeError, ["integers", "datetime64"]),
    (4, TypeError, ["e.g. [4] or range(4)", "int"]),
    (np.int64(4), TypeError, ["e.g. [4] or range(4)"]),
    (np.array(4), TypeError, ["e.g. [4] or range(4)"]),
    ([1, None], TypeError, ["integers", "None at position 1"]),
    ([True, 2], TypeError, ["bool True at position 0"]),
    ([np.float64(1.0)], TypeError, ["float64"]),
    (np.array([[1, 2]], dtype=object), ValueError, ["one-dimensional", "(1, 2)"]),
    (np.array([1, "a"], dtype=object), TypeError, ["str 'a' at position 1"]),
    (Pixels([[1], [2]]), ValueError, ["one-dimensional"]),
    (Pixels([0.5]), TypeError, ["float64"]),
])
@pytest.mark.parametrize("arg", ["pixels", "samples", "dims"])
def test_bad_index_messages(arg, value, exc, words):
    s = pyoa.sampler("bose", spp=9, dims=3, backend="numpy")
    with pytest.raises(exc) as info:
        s.generate(**{arg: value})
    msg = str(info.value)
    assert msg.startswith(f"{arg} must"), msg
    for w in words:
        assert w in msg, msg


@pytest.mark.parametrize("pixels", [range(10, -1, -3), [10, 7, 4, 1], (10, 7, 4, 1), Pixels([10, 7, 4, 1]),
                                    np.array([10, 7, 4, 1], dtype=object), range(4294967295, 4294967286, -3)])
def test_good_index_forms_equal(pixels):
    s = pyoa.sampler("bose", spp=9, dims=3, backend="numpy")
    want = [s.value(int(p), 2, 1) for p in list(np.asarray(pixels, dtype=np.int64))]
    assert s.generate(pixels=pixels)[:, 2, 1].tolist() == want


# ----------------------------------------------------------------------------- device selectors

@pytest.mark.parametrize("device", [0, 1, 1.5, b"gpu", ("0", "0")])
def test_device_must_be_a_string(device):
    with pytest.raises(TypeError, match=r"device must be an OpenCL device selector string \('P:D'"):
        pyoa.sampler("bose", spp=9, dims=2, device=device)
    with pytest.raises(TypeError, match="device must be"):  # whichever backend would be used
        pyoa.sampler("bose", spp=9, dims=2, device=device, backend="numpy")


@pytest.mark.parametrize("device", ["", "   "])
def test_empty_device_selector_refused(device):
    with pytest.raises(ValueError, match="device must not be empty"):
        pyoa.sampler("bose", spp=9, dims=2, device=device, backend="numpy")


@pytest.fixture
def fake_devices(monkeypatch):
    """Two platforms whose descriptions are such that a substring match of
    "0" would pick platform 1 and one of "1" nothing."""
    pytest.importorskip("pyopencl")
    from pyoa._opencl import device as dev

    def fake(pi, name, version, dname):
        plat = SimpleNamespace(name=name, version=version)
        return dev.DeviceInfo(pi, 0, plat, SimpleNamespace(name=dname, type=2))  # 2: CL_DEVICE_TYPE_CPU

    devices = [fake(0, "Alpha", "OpenCL X", "a"), fake(1, "Beta", "OpenCL 3.0", "b")]
    monkeypatch.setattr(dev, "list_devices", lambda: devices)
    return dev, devices


def test_bare_integer_selector_is_a_platform(fake_devices):
    dev, devices = fake_devices
    assert dev.select_device("0") is devices[0]
    assert dev.select_device(" 1 ") is devices[1]
    assert dev.select_device("1:0") is devices[1]
    assert dev.select_device("beta") is devices[1]  # names still match by substring
    with pytest.raises(ValueError, match="no OpenCL device matches '2'; devices: 0:0 .*; 1:0 "):
        dev.select_device("2")


def test_bare_integer_selector_from_environment(fake_devices, monkeypatch):
    dev, devices = fake_devices
    monkeypatch.setenv(dev.ENV_DEVICE, "1")
    assert dev.select_device(None) is devices[1]


# ----------------------------------------------------------------------------- valid_spp

VALID_SPP_REFUSALS = [
    (dict(name="bush", strength=99), "ValueError", ["bush strength", "[2, 8]", "99"]),
    (dict(name="bose", strength=3), "ValueError", ["bose has strength 2 only"]),
    (dict(name="cmjnd", dims=-4), "ValueError", ["dims must be in [1,", "-4"]),
    (dict(name="cmjnd", dims=0), "ValueError", ["dims"]),
    # strength 0 once listed s**0 = 1 <= 2**24 forever, filling memory
    (dict(name="cmjnd", strength=0), "ValueError", ["strength must be >= 1"]),
    (dict(name="bush", strength=0), "ValueError", ["strength must be >= 1"]),
    (dict(name="bose", near=-1), "ValueError", ["near must be >= 0, got -1"]),
    (dict(name="bose", near=120.0), "TypeError", ["near must be an integer"]),
    (dict(name="random", strength=2), "ValueError", ["no strength parameter"]),
]


def test_valid_spp_refuses_what_sampler_refuses():
    """Refused, not answered with an empty list (or an endless one): in a
    child under a memory limit, since a regression of strength=0 fills memory."""
    code = f"""
        for kw in {[kw for kw, _, _ in VALID_SPP_REFUSALS]!r}:
            try:
                print("returned", len(pyoa.valid_spp(**kw)))
            except Exception as exc:
                print(type(exc).__name__, exc)
    """
    res = run_limited(code)
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    assert len(lines) == len(VALID_SPP_REFUSALS), res.stdout
    for line, (kw, exc, words) in zip(lines, VALID_SPP_REFUSALS):
        assert line.startswith(exc + " "), (kw, line)
        for w in words:
            assert w in line, (kw, line)


def test_cmjnd_strength_one_is_listed_lazily():
    """Every count 2 .. 2**24 is valid at t = 1: a list of 16.7 million tuples
    took gigabytes; the listing is lazy, like the comparison samplers'."""
    code = """
        import time
        t0 = time.perf_counter()
        for kw in (dict(dims=1), dict(strength=1), dict(strength=1, dims=5)):
            c = pyoa.valid_spp("cmjnd", **kw)
            print(len(c), c[0].label(), c[-1].spp, [x.spp for x in c[10:12]])
        print(time.perf_counter() - t0 < 1.0)
        print(c[5] == pyoa.SppChoice(7, 7, 1, 1), c[-2:] == [c[-2], c[-1]])
        try:
            c[2**24 - 1]
        except IndexError:
            print("IndexError")
    """
    res = run_limited(code, extra_gib=0.5)
    assert res.returncode == 0, res.stderr
    assert res.stdout.splitlines() == (["16777215 2 (s=2, t=1) 16777216 [12, 13]"] * 3
                                       + ["True", "True True", "IndexError"])


def test_nearest_spp_still_none_for_impossible_strength():
    """Convergence studies skip a sampler that has no count at a strength."""
    assert constructions.nearest_spp("bush", 100, dims=10, strength=10) is None


# ----------------------------------------------------------------------------- analysis.cells

@pytest.mark.parametrize("x, words", [
    (np.array([np.nan]), ["finite"]),
    (np.array([0.5, np.inf]), ["finite"]),
    (np.array([np.float32(np.nan)]), ["finite"]),
    (np.array([-0.1]), ["[0, 1)", "-0.1"]),
    (np.array([1.0]), ["[0, 1)", "1.0"]),
    (np.array([2]), ["[0, 1)"]),
    (np.array([True]), ["real", "bool"]),
    (np.array([0.5j]), ["real", "complex"]),
    (np.array([1], dtype="timedelta64[s]"), ["real", "timedelta64"]),
    (["a"], ["real"]),
    ([[0.1], [0.2, 0.3]], ["real", "ragged"]),
])
def test_cells_refuses_what_the_others_refuse(x, words):
    with pytest.raises(ValueError) as info:
        A.cells(x, 4)
    for w in words:
        assert w in str(info.value), str(info.value)
    if isinstance(x, np.ndarray) and x.dtype.kind == "f":  # the others refuse it too
        with pytest.raises(ValueError):
            A.stratification(np.asarray(x).reshape(1, 1), 1, 1)


def test_cells_still_accepts_any_shape():
    assert A.cells(0.3, 10) == 2
    assert A.cells([], 3).shape == (0,)
    assert A.cells(np.array([[0.0, 0.5]], dtype=np.float32), 2).tolist() == [[0, 1]]
    assert A.cells(np.array([0]), 5).tolist() == [0]


def test_convergence_plot_into_a_directory_names_it(tmp_path):
    res = A.convergence(["random"], "gaussian", 2, [4, 16], trials=4, backend="numpy")
    with pytest.raises(IsADirectoryError) as info:
        res.plot(tmp_path)
    assert str(info.value) == f"cannot write {str(tmp_path)!r}: it is a directory; name a file in it"
    assert list(tmp_path.iterdir()) == []
