"""Building pyoa's OpenCL program once per process and device.

The portable headers of :mod:`pyoa.kernels` (``include/pyoa``: the
language configuration, the hash keys and catalogue codes generated from
:mod:`pyoa.reference` and :mod:`pyoa.catalogue`, and every sampler's value
function) and its ``.cl`` sources (launch shapes and memory layouts) are
concatenated in order and built with
``-cl-fp32-correctly-rounded-divide-sqrt`` (SPEC section 7). Never add ``-cl-fast-relaxed-math`` or ``-cl-mad-enable``: they
break bit-exactness. PoCL caches the compiled binary on disk (``~/.cache/pocl``),
so later processes build fast.
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
import tempfile
import threading
from importlib import resources

from .device import DeviceInfo

BUILD_OPTIONS = ["-cl-fp32-correctly-rounded-divide-sqrt"]

_lock = threading.Lock()
_cache: dict[tuple, tuple] = {}


def source(names: tuple[str, ...] | None = None) -> str:
    """The program text: the portable headers (:data:`pyoa.kernels.HEADERS`),
    then the files ``names`` of :mod:`pyoa.kernels` (default
    :data:`pyoa.kernels.SOURCES`), in that order. Nothing is generated or
    spliced: every value function is a header's."""
    from .. import kernels

    names = names or kernels.SOURCES
    root = resources.files(kernels)
    # The headers first: config.h opens with the FP_CONTRACT OFF pragma, which
    # applies from there to the end of the program, so no float operation of
    # any file can be contracted into an FMA. Their #include lines go (the
    # program has no include path; each header they name is already above).
    headers = "\n".join(
        f"/* ---- pyoa/{name} ---- */\n" + _INCLUDE.sub("", root.joinpath("include", "pyoa", name).read_text())
        for name in kernels.HEADERS
    )
    text = headers + "\n" + "\n".join(f"/* ---- {name} ---- */\n" + root.joinpath(name).read_text() for name in names)
    return text


#: A header's #include line (dropped from the program text: see :func:`source`).
_INCLUDE = re.compile(r'^#include "[^"]+"\n', re.MULTILINE)


class BuildError(RuntimeError):
    """pyoa's program cannot be used on a device.

    ``stage`` is ``"context"`` (the device could not be opened) or ``"build"``
    (its compiler rejected the program); ``log`` is the whole message of the
    OpenCL error, build log and options included, for ``pyoa backends
    --verbose``; ``str()`` is one line.
    """

    def __init__(self, info: DeviceInfo, stage: str, log: str):
        self.info, self.stage, self.log = info, stage, log
        first = first_error(log)
        super().__init__(f"OpenCL {stage} failed on {info.short()}: {first[:200]}")


def first_error(log: str) -> str:
    """The first compiler diagnostic of a build log without its source
    location (``error: expected ')'``), else the log's first line."""
    lines = [ln.strip() for ln in log.splitlines() if ln.strip()]
    for ln in lines:
        m = re.search(r"\berror\s*:\s*(?:[^\s:]+:\d+(?::\d+)?(?:\s*<.*>)?\s*:\s*)?(.*)", ln, re.IGNORECASE)
        if m:
            return f"error: {m[1]}"
    return lines[0] if lines else ""


@contextlib.contextmanager
def _captured_stderr():
    """Capture file descriptor 2 for the duration into the yielded list (one
    string, appended on exit): PoCL's compiler prints its diagnostics straight
    to the process's stderr, and a failed build must not flood every user with
    them (they go into the build log)."""
    sys.stderr.flush()
    saved = os.dup(2)
    printed: list[str] = []
    with tempfile.TemporaryFile() as fh:
        os.dup2(fh.fileno(), 2)
        try:
            yield printed
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            fh.seek(0)
            printed.append(fh.read().decode(errors="replace"))


def build(info: DeviceInfo, *, text: str | None = None):
    """Return ``(context, queue, program)`` for a device, building it on first use.

    ``text`` replaces the program text (default: :func:`source`); the build
    options are always pyoa's. Successful builds are cached per (device,
    text); failed ones are not (the caller remembers why).

    Raises
    ------
    BuildError
        If the device cannot create a context or the program does not build
        (it carries the build log).
    """
    import pyopencl as cl

    key = (info.device.int_ptr, text)
    with _lock:
        if key not in _cache:
            stage, printed = "context", []
            try:
                ctx = cl.Context([info.device])
                queue = cl.CommandQueue(ctx)
                stage = "build"
                with _captured_stderr() as printed:
                    prg = cl.Program(ctx, source() if text is None else text).build(options=BUILD_OPTIONS)
            except cl.Error as exc:
                noise = "".join(printed)
                log = str(exc) + (f"\n(the compiler also printed)\n{noise}" if noise.strip() else "")
                raise BuildError(info, stage, log) from exc
            _cache[key] = (ctx, queue, prg)
        return _cache[key]
