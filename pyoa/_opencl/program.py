"""Building pyoa's OpenCL program once per process and device.

The sources of :mod:`pyoa.kernels` are concatenated in order, prefixed with
the construction and offset codes of :mod:`pyoa.constructions` as ``-D``
defines, and built with ``-cl-fp32-correctly-rounded-divide-sqrt`` (SPEC
section 7). Never add ``-cl-fast-relaxed-math`` or ``-cl-mad-enable``: they
break bit-exactness. PoCL caches the compiled binary on disk (``~/.cache/pocl``),
so later processes build fast.
"""

from __future__ import annotations

import threading
from importlib import resources

from .. import constructions
from .device import DeviceInfo

BUILD_OPTIONS = ["-cl-fp32-correctly-rounded-divide-sqrt"]

_lock = threading.Lock()
_cache: dict[int, tuple] = {}


def defines() -> list[str]:
    """``-D`` options carrying the Python-side integer codes into the kernels."""
    opts = [f"-DOFFSET_{name.upper()}={code}" for name, code in constructions.OFFSET_CODES.items()]
    opts += [f"-DCONSTRUCTION_{c.function.upper()}={c.code}" for c in constructions.SAMPLERS.values()]
    return opts


def source() -> str:
    """The whole program text, files in :data:`pyoa.kernels.SOURCES` order."""
    from .. import kernels

    root = resources.files(kernels)
    # The pragma applies from where it appears to the end of the program:
    # first, so no float operation of any file can be contracted into an FMA.
    return "#pragma OPENCL FP_CONTRACT OFF\n" + "\n".join(
        f"/* ---- {name} ---- */\n" + root.joinpath(name).read_text() for name in kernels.SOURCES
    )


def build(info: DeviceInfo):
    """Return ``(context, queue, program)`` for a device, building it on first use.

    Raises
    ------
    RuntimeError
        If the device cannot create a context or the program does not build
        (the message carries the build log).
    """
    import pyopencl as cl

    key = info.device.int_ptr
    with _lock:
        if key not in _cache:
            try:
                ctx = cl.Context([info.device])
                queue = cl.CommandQueue(ctx)
                prg = cl.Program(ctx, source()).build(options=BUILD_OPTIONS + defines())
            except cl.Error as exc:
                raise RuntimeError(f"OpenCL build failed on {info.describe()}: {exc}") from exc
            _cache[key] = (ctx, queue, prg)
        return _cache[key]
