"""Backend choice (pyoa.backends): explicit, $PYOA_BACKEND, OpenCL default, the
NumPy fallback with its warning, and pyoa.backends()'s report."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest

import pyoa
from tests.helpers import assert_same_bits

B = importlib.import_module("pyoa.backends")  # the module (pyoa.backends is the function)


@pytest.fixture
def no_opencl(monkeypatch):
    """Make OpenCL unusable in this process: constructing the backend fails."""
    import pyoa._opencl.backend as ocl

    def broken(*args, **kwargs):
        raise RuntimeError("simulated: no OpenCL platform")

    monkeypatch.setattr(ocl, "OpenCLBackend", broken)
    monkeypatch.setattr(B, "_opencl", {})
    monkeypatch.setattr(B, "_warned", False)
    monkeypatch.delenv("PYOA_BACKEND", raising=False)


@pytest.fixture
def fresh_cache(monkeypatch):
    monkeypatch.setattr(B, "_opencl", {})
    monkeypatch.setattr(B, "_warned", False)


def test_backends_report_structure(monkeypatch):
    monkeypatch.delenv("PYOA_BACKEND", raising=False)
    report = pyoa.backends()
    assert [e["name"] for e in report] == ["opencl", "numpy"]
    for e in report:
        assert {"name", "usable", "device", "default", "reason"} <= set(e)
        assert isinstance(e["usable"], bool) and isinstance(e["default"], bool)
        assert (e["reason"] is None) == e["usable"]
        assert (e["device"] is not None) == e["usable"]
    assert isinstance(report[0]["devices"], list)
    assert report[1]["usable"] and "NumPy" in report[1]["device"]
    assert sum(e["default"] for e in report) == 1
    assert report[0]["default"] == report[0]["usable"]


def test_backends_report_follows_environment(monkeypatch):
    monkeypatch.setenv("PYOA_BACKEND", "numpy")
    report = pyoa.backends()
    assert [e["default"] for e in report] == [False, True]


@pytest.mark.opencl
def test_backends_report_with_opencl(monkeypatch):
    monkeypatch.delenv("PYOA_BACKEND", raising=False)
    ocl = pyoa.backends()[0]
    assert ocl["usable"] and ocl["default"] and ocl["devices"] and ocl["fix"] is None
    for d in ocl["devices"]:
        assert {"selector", "description", "compiler", "works", "used", "reason", "fix", "log"} <= set(d)
        assert d["selector"].count(":") == 1 and d["description"] and d["compiler"]
        assert (d["reason"] is None) == d["works"] == (d["log"] is None) == (d["fix"] is None)
        if not d["works"]:
            assert "\n" not in d["reason"] and "\n" not in d["fix"]
    used = [d for d in ocl["devices"] if d["used"]]
    assert len(used) == 1 and used[0]["works"]
    assert used[0]["description"] == ocl["device"]


def test_fallback_warns_once_and_uses_numpy(no_opencl):
    with pytest.warns(pyoa.PyoaFallbackWarning, match="simulated: no OpenCL platform") as rec:
        s = pyoa.sampler("bose", spp=25, dims=4, seed=9)
    assert s.backend == "numpy"
    assert "PYOA_BACKEND=numpy" in str(rec[0].message)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s2 = pyoa.sampler("bose", spp=25, dims=4, seed=9)  # no second warning
    assert s2.backend == "numpy"
    want = pyoa.sampler("bose", spp=25, dims=4, seed=9, backend="numpy").generate(pixels=range(3))
    assert_same_bits(s.generate(pixels=range(3)), want)
    # the report says why
    ocl = pyoa.backends()[0]
    assert not ocl["usable"] and "simulated" in ocl["reason"] and not ocl["default"]
    assert pyoa.backends()[1]["default"]


def test_explicit_opencl_raises_instead_of_falling_back(no_opencl):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(RuntimeError, match="simulated: no OpenCL platform"):
            pyoa.sampler("bose", spp=25, dims=4, backend="opencl")
        with pytest.raises(RuntimeError, match="simulated"):
            pyoa.sampler("bose", spp=25, dims=4, backend=" OpenCL ")


def test_pyoa_backend_numpy_never_touches_opencl(monkeypatch):
    import pyoa._opencl.backend as ocl

    def forbidden(*a, **k):
        raise AssertionError("OpenCL was initialised although PYOA_BACKEND=numpy")

    monkeypatch.setattr(ocl, "OpenCLBackend", forbidden)
    monkeypatch.setattr(B, "_opencl", {})
    monkeypatch.setenv("PYOA_BACKEND", "numpy")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert pyoa.sampler("bose", spp=9, dims=2).backend == "numpy"


def test_explicit_argument_beats_environment(monkeypatch):
    monkeypatch.setenv("PYOA_BACKEND", "opencl")
    assert pyoa.sampler("bose", spp=9, dims=2, backend="numpy").backend == "numpy"


def test_bad_environment_backend(monkeypatch):
    monkeypatch.setenv("PYOA_BACKEND", "bogus")
    with pytest.raises(ValueError, match=r"unknown \$PYOA_BACKEND 'bogus'.*opencl, numpy"):
        pyoa.sampler("bose", spp=9, dims=2)


@pytest.mark.opencl
def test_environment_names_opencl(monkeypatch):
    monkeypatch.setenv("PYOA_BACKEND", " OpenCL ")
    assert pyoa.sampler("bose", spp=9, dims=2).backend == "opencl"


@pytest.mark.opencl
def test_unknown_device_from_environment_raises_listing_devices(monkeypatch, fresh_cache):
    monkeypatch.delenv("PYOA_BACKEND", raising=False)
    monkeypatch.setenv("PYOA_OPENCL_DEVICE", "nonexistent-device")
    with pytest.raises(ValueError) as exc:
        pyoa.sampler("bose", spp=9, dims=2)
    msg = str(exc.value)
    assert "nonexistent-device" in msg and "devices:" in msg and "0:0" in msg
    # a bad selector is a user error, not a reason to fall back silently, and not cached
    monkeypatch.delenv("PYOA_OPENCL_DEVICE")
    assert pyoa.sampler("bose", spp=9, dims=2).backend == "opencl"


# ----------------------------------------------------------------------------- subprocesses

SCRIPT = textwrap.dedent("""
    import sys, warnings
    import numpy as np
    warnings.simplefilter("always")
    with warnings.catch_warnings(record=True) as rec:
        import pyoa
        s = pyoa.sampler("cmjnd", spp=125, dims=7, seed=31, offset="mj")
        s2 = pyoa.sampler("bose", spp=49, dims=3)
    np.save(sys.argv[1], s.generate(pixels=range(5)))
    print("BACKEND", s.backend, s2.backend)
    for w in rec:
        print("WARNING", w.category.__name__, w.message)
""")


def _run(tmp_path, env_extra, extra_path=None):
    # pyoa's own settings are dropped, but the device under test is kept
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYOA_") or k == "PYOA_OPENCL_DEVICE"}
    env.update(env_extra)
    if extra_path:
        env["PYTHONPATH"] = os.pathsep.join([str(extra_path)] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    out = tmp_path / "x.npy"
    res = subprocess.run([sys.executable, "-c", SCRIPT, str(out)], capture_output=True, text=True, env=env, timeout=120)
    assert res.returncode == 0, res.stderr
    return res.stdout, np.load(out)


def _want():
    return pyoa.sampler("cmjnd", spp=125, dims=7, seed=31, offset="mj", backend="numpy").generate(pixels=range(5))


def test_subprocess_pyoa_backend_numpy(tmp_path):
    stdout, x = _run(tmp_path, {"PYOA_BACKEND": "numpy"})
    assert "BACKEND numpy numpy" in stdout
    assert "WARNING" not in stdout
    assert_same_bits(x, _want())


def test_subprocess_without_pyopencl_falls_back_with_one_warning(tmp_path):
    """OpenCL switched off for real: a `pyopencl` that cannot be imported."""
    fake = tmp_path / "fake"
    fake.mkdir()
    (fake / "pyopencl.py").write_text("raise ImportError('pyopencl hidden by the test suite')\n")
    stdout, x = _run(tmp_path, {}, extra_path=fake)
    assert "BACKEND numpy numpy" in stdout
    warns = [line for line in stdout.splitlines() if line.startswith("WARNING")]
    assert len(warns) == 1 and "PyoaFallbackWarning" in warns[0] and "pyopencl" in warns[0], stdout
    assert_same_bits(x, _want())


@pytest.mark.opencl
def test_subprocess_default_is_opencl_with_same_bits(tmp_path):
    stdout, x = _run(tmp_path, {})
    assert "BACKEND opencl opencl" in stdout and "WARNING" not in stdout
    assert_same_bits(x, _want())


@pytest.mark.opencl
def test_subprocess_unknown_device_raises(tmp_path):
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYOA_")}
    env["PYOA_OPENCL_DEVICE"] = "nonexistent-device"
    code = "import pyoa; pyoa.sampler('bose', spp=9, dims=2)"
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert res.returncode != 0
    assert "ValueError" in res.stderr and "no OpenCL device matches 'nonexistent-device'" in res.stderr
    assert "devices: 0:0" in res.stderr
