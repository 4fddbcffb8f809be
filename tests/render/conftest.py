"""Fixtures of the renderer's tests: the memory cap of child processes (see limits.py)."""

from __future__ import annotations

import pytest

from .limits import HEADROOM, python_child


@pytest.fixture(scope="session")
def as_limit(tmp_path_factory) -> int:
    """RLIMIT_AS for children: a tiny render's peak address space + HEADROOM."""
    out = tmp_path_factory.mktemp("as_limit") / "t.exr"
    res = python_child(f"""
        from pyoa.commands import main
        main(["render", "cornell", "--size", "8", "8", "--spp", "4", "-q", "--out", {str(out)!r}])
        print(next(l for l in open("/proc/self/status") if l.startswith("VmPeak")).split()[1])
    """, None)
    assert res.returncode == 0, res.stderr
    return int(res.stdout.split()[-1]) * 1024 + HEADROOM
