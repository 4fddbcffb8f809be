"""Child processes under a memory cap (RLIMIT_AS), for the renderer's tests.

A test that runs ``pyoa`` in a child caps its address space, so that a
regression which allocates without bound (a huge image, a sample count
snapped to millions) fails its test instead of exhausting the machine. The
cap is measured, not guessed (numba, Embree and OpenCL reserve much address
space): the ``as_limit`` fixture (conftest.py) is the peak of a child that
renders a tiny image, plus ``HEADROOM``.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import textwrap

#: Address space a child may take beyond what a tiny render of it needs.
HEADROOM = 2 << 30


def run_child(argv: list[str], limit: int | None, cwd=None) -> subprocess.CompletedProcess:
    """Run ``argv`` (text output) under RLIMIT_AS = ``limit`` bytes, with the
    default memory limit of pyoa (``$PYOA_MAX_BYTES`` unset: half the RAM)."""

    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    env = {k: v for k, v in os.environ.items() if k != "PYOA_MAX_BYTES"}
    return subprocess.run(argv, capture_output=True, text=True, cwd=cwd, env=env, timeout=300,
                          preexec_fn=cap if limit else None)


def python_child(code: str, limit: int | None, cwd=None) -> subprocess.CompletedProcess:
    """Run ``python -c code`` under :func:`run_child`."""
    return run_child([sys.executable, "-c", textwrap.dedent(code)], limit, cwd)
