"""Shared set-up of the Dr.Jit and Mitsuba tests: skip without Mitsuba, unless
``PYOA_REQUIRE_MITSUBA=1`` (CI sets it, as it sets ``PYOA_REQUIRE_OPENCL``),
which turns the skip into a failure."""

from __future__ import annotations

import os

import pytest

REQUIRE_MITSUBA = os.environ.get("PYOA_REQUIRE_MITSUBA", "").strip() == "1"


def need(module: str):
    """Import ``module`` (``pyoa._drjit`` or ``pyoa.mitsuba``) or skip (fail under PYOA_REQUIRE_MITSUBA=1)."""
    try:
        return __import__(module, fromlist=["_"])
    except ImportError as exc:
        if REQUIRE_MITSUBA:
            pytest.fail(f"PYOA_REQUIRE_MITSUBA=1 but {module} cannot be imported: {exc}", pytrace=False)
        pytest.skip(f"{module} needs Mitsuba 3 / Dr.Jit (pip install 'pyoa[mitsuba]'): {exc}", allow_module_level=True)
