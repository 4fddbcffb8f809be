"""Shared fixtures of the pyoa test suite.

OpenCL
------
Tests that need a usable OpenCL device carry the ``opencl`` marker (or use the
``opencl`` fixture, or the ``"opencl"`` value of the ``backend`` fixture).
Without a device they are skipped, unless ``PYOA_REQUIRE_OPENCL=1`` is set
(CI sets it): then a missing device makes them fail.

They run on pyoa's default device, or once per device with
``PYOA_TEST_DEVICES=all`` (every device that builds pyoa's program, e.g. pip's
PoCL 3.0 on LLVM 14 and Debian's PoCL 3.1 on LLVM 15: both must give the same
bits) or ``PYOA_TEST_DEVICES=0:0,1:0`` (those selectors). The session fixture
``opencl_device`` points ``PYOA_OPENCL_DEVICE`` at the device under test, so
everything a test does with the default device, subprocesses included, runs
there; test ids name it (``[opencl-1.0]``). The header of the run lists every
device and why any fails.

Hypothesis
----------
Profiles: ``ci`` (default: moderate ``max_examples``, no deadline), ``dev``
(quick) and ``thorough``; pick one with ``HYPOTHESIS_PROFILE=...``.

C oracle
--------
The ``spec_c`` fixture compiles ``tests/reference/spec_hashes.c`` (an
independent implementation of docs/spec.md sections 2, 3, 5-7) with ``cc`` and
returns a :class:`tests.helpers.SpecC` that answers queries in bulk.
"""

from __future__ import annotations

import functools
import os
import shutil
import subprocess
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

from tests.helpers import SpecC

settings.register_profile(
    "ci", max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow], print_blob=True,
    database=None,
)
settings.register_profile("dev", max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.register_profile(
    "thorough", max_examples=500, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

REQUIRE_OPENCL = os.environ.get("PYOA_REQUIRE_OPENCL", "").strip() == "1"
TESTS = Path(__file__).resolve().parent


def pytest_configure(config):
    config.addinivalue_line(
        "markers",
        "opencl: needs a usable OpenCL device (skipped without one; FAILS instead when PYOA_REQUIRE_OPENCL=1)",
    )


TEST_DEVICES_ENV = "PYOA_TEST_DEVICES"
DEVICE_ENV = "PYOA_OPENCL_DEVICE"


@functools.lru_cache(maxsize=None)
def device_statuses():
    """Every OpenCL device's :class:`pyoa._opencl.choice.DeviceStatus` (empty without OpenCL)."""
    from pyoa._opencl.choice import probe_all

    try:
        return tuple(probe_all())
    except RuntimeError:
        return ()


@functools.lru_cache(maxsize=None)
def test_devices() -> tuple:
    """The selectors the OpenCL tests run on (None: pyoa's default device)."""
    value = os.environ.get(TEST_DEVICES_ENV, "").strip()
    if not value or value.lower() == "default":
        return (None,)
    if value.lower() == "all":
        return tuple(st.info.selector for st in device_statuses() if st.works) or (None,)
    return tuple(v.strip() for v in value.split(",") if v.strip())


def _device_id(prefix: str, selector) -> str:
    return prefix if selector is None else f"{prefix}-{selector.replace(':', '.')}"


def _devices_report():
    lines = [f"OpenCL devices under test ({TEST_DEVICES_ENV}={os.environ[TEST_DEVICES_ENV]}): "
             + ", ".join(s or "default" for s in test_devices())]
    for st in device_statuses():
        verdict = "works" if st.works else f"fails: {st.reason}"
        lines.append(f"  {st.info.selector} {st.info.device.name.strip()} [{st.info.compiler()}]: {verdict}")
    return lines


def pytest_collection_finish(session):
    """With PYOA_TEST_DEVICES set, say which devices the OpenCL tests run on
    and why any other fails (written even under -q, unlike a report header)."""
    if not os.environ.get(TEST_DEVICES_ENV, "").strip():
        return
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if reporter is not None:
        reporter.write_line("")
        for line in _devices_report():
            reporter.write_line(line)


def pytest_generate_tests(metafunc):
    """Run OpenCL tests once per device under test (see the module docstring)."""
    devices = test_devices()
    if "backend" in metafunc.fixturenames:
        params = [pytest.param("numpy", None, id="numpy")]
        params += [pytest.param("opencl", sel, id=_device_id("opencl", sel), marks=pytest.mark.opencl)
                   for sel in devices]
        metafunc.parametrize(("backend", "opencl_device"), params, indirect=True, scope="session")
    elif len(devices) > 1 and (metafunc.definition.get_closest_marker("opencl") is not None
                               or "opencl" in metafunc.fixturenames):
        metafunc.parametrize("opencl_device", [pytest.param(sel, id=_device_id("opencl", sel)) for sel in devices],
                             indirect=True, scope="session")


@functools.lru_cache(maxsize=None)
def opencl_status(selector=None):
    """``(backend object or None, reason)`` for an OpenCL device (None: the default), probed once."""
    import pyoa

    try:
        smp = pyoa.sampler("bose", spp=4, dims=1, backend="opencl", device=selector)
        smp.generate()
    except Exception as exc:  # noqa: BLE001 - any failure means "not usable"
        return None, f"{type(exc).__name__}: {exc}"
    return smp._backend, None


def require_opencl(selector=None):
    """Skip (or, with PYOA_REQUIRE_OPENCL=1, fail) unless OpenCL is usable; return the backend."""
    backend, reason = opencl_status(selector)
    if backend is None:
        if REQUIRE_OPENCL:
            pytest.fail(f"PYOA_REQUIRE_OPENCL=1 but no usable OpenCL device: {reason}", pytrace=False)
        pytest.skip(f"no usable OpenCL device ({reason}); set PYOA_REQUIRE_OPENCL=1 to fail instead")
    return backend


def pytest_runtest_setup(item):
    if item.get_closest_marker("opencl") is not None:
        callspec = getattr(item, "callspec", None)
        require_opencl(callspec.params.get("opencl_device") if callspec else None)


@pytest.fixture(scope="session", autouse=True)
def opencl_device(request):
    """The selector of the OpenCL device under test (None: pyoa's default).

    While it is active, ``PYOA_OPENCL_DEVICE`` names that device, so pyoa's
    default OpenCL backend is that device in this process and in subprocesses.
    """
    selector = getattr(request, "param", None)
    if selector is None:
        yield None
        return
    old = os.environ.get(DEVICE_ENV)
    os.environ[DEVICE_ENV] = selector
    try:
        yield selector
    finally:
        if old is None:
            os.environ.pop(DEVICE_ENV, None)
        else:
            os.environ[DEVICE_ENV] = old


@pytest.fixture(scope="session")
def opencl(opencl_device):
    """The OpenCL backend object of the device under test (skips/fails as described above)."""
    return require_opencl(opencl_device)


@pytest.fixture(scope="session")
def backend(request, opencl_device):
    """Each bulk backend name in turn ("numpy", then "opencl" once per device under test)."""
    return request.param


@pytest.fixture(scope="session")
def spec_c(tmp_path_factory):
    """The compiled C oracle of ``tests/reference/spec_hashes.c``."""
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if not cc or not shutil.which(cc.split()[0]):
        pytest.skip("no C compiler (cc/gcc/clang) found: cannot build the independent C oracle spec_hashes.c")
    exe = tmp_path_factory.mktemp("spec_c") / "spec_hashes"
    cmd = [*cc.split(), "-std=c99", "-O2", "-ffp-contract=off", "-o", str(exe), str(TESTS / "reference" / "spec_hashes.c")]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        pytest.fail(f"compiling the C oracle failed: {' '.join(cmd)}\n{res.stderr}")
    return SpecC(exe)
