"""Shared fixtures of the pyoa test suite.

OpenCL
------
Tests that need a usable OpenCL device carry the ``opencl`` marker (or use the
``opencl`` fixture, or the ``"opencl"`` value of the ``backend`` fixture).
Without a device they are skipped, unless ``PYOA_REQUIRE_OPENCL=1`` is set
(CI sets it): then a missing device makes them fail.

Hypothesis
----------
Profiles: ``ci`` (default: moderate ``max_examples``, no deadline), ``dev``
(quick) and ``thorough``; pick one with ``HYPOTHESIS_PROFILE=...``.

C oracle
--------
The ``spec_c`` fixture compiles ``tests/reference/spec_hashes.c`` (an
independent implementation of SPEC sections 2, 3, 5-7) with ``cc`` and
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


@functools.lru_cache(maxsize=None)
def opencl_status():
    """``(backend object or None, reason)`` for the default OpenCL device, probed once."""
    import pyoa

    try:
        smp = pyoa.sampler("bose", spp=4, dims=1, backend="opencl")
        smp.generate()
    except Exception as exc:  # noqa: BLE001 - any failure means "not usable"
        return None, f"{type(exc).__name__}: {exc}"
    return smp._backend, None


def require_opencl():
    """Skip (or, with PYOA_REQUIRE_OPENCL=1, fail) unless OpenCL is usable; return the backend."""
    backend, reason = opencl_status()
    if backend is None:
        if REQUIRE_OPENCL:
            pytest.fail(f"PYOA_REQUIRE_OPENCL=1 but no usable OpenCL device: {reason}", pytrace=False)
        pytest.skip(f"no usable OpenCL device ({reason}); set PYOA_REQUIRE_OPENCL=1 to fail instead")
    return backend


def pytest_runtest_setup(item):
    if item.get_closest_marker("opencl") is not None:
        require_opencl()


@pytest.fixture(scope="session")
def opencl():
    """The OpenCL backend object pyoa uses by default (skips/fails as described above)."""
    return require_opencl()


#: Backend names for parametrization; the OpenCL one carries the marker.
BACKEND_PARAMS = [pytest.param("numpy", id="numpy"), pytest.param("opencl", id="opencl", marks=pytest.mark.opencl)]


@pytest.fixture(scope="session", params=BACKEND_PARAMS)
def backend(request):
    """Each bulk backend name in turn ("numpy", "opencl")."""
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
