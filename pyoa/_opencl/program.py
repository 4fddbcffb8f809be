"""Building pyoa's OpenCL program once per process and device.

The sources of :mod:`pyoa.kernels` are concatenated in order, followed by
the dispatch generated from the catalogue (:func:`dispatch_source`), and
built with ``-D`` defines carrying Python-side constants into them
(:func:`defines`: the construction and offset codes of
:mod:`pyoa.catalogue`, the hash keys of the :mod:`pyoa.reference` modules,
which the ``.cl`` files never copy) and ``-cl-fp32-correctly-rounded-divide-sqrt`` (SPEC
section 7). Never add ``-cl-fast-relaxed-math`` or ``-cl-mad-enable``: they
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

from .. import catalogue
from ..catalogue_types import OFFSET_CODES
from .device import DeviceInfo

BUILD_OPTIONS = ["-cl-fp32-correctly-rounded-divide-sqrt"]

_lock = threading.Lock()
_cache: dict[tuple, tuple] = {}


def key_modules() -> list:
    """Every module of :mod:`pyoa.reference`: their ``*_KEY`` constants are
    the kernels' under the same names, and their only definition (the ``.cl``
    files check, with ``#error``, that each one they use is defined). A new
    sampler's reference module is picked up without being listed anywhere."""
    import importlib
    import pkgutil

    from .. import reference

    return [importlib.import_module(f"{reference.__name__}.{m.name}")
            for m in sorted(pkgutil.iter_modules(reference.__path__), key=lambda m: m.name)]


def kernel_keys() -> dict[str, int]:
    """``name -> value`` of every ``*_KEY`` uint32 constant of :func:`key_modules`."""
    keys: dict[str, int] = {}
    for module in key_modules():
        for name, value in vars(module).items():
            if name.endswith("_KEY") and name.isupper() and isinstance(value, int):
                if not 0 <= value <= 0xFFFFFFFF:
                    raise ValueError(f"{module.__name__}.{name} = {value:#x} is not a uint32")
                if keys.get(name, value) != value:
                    raise ValueError(f"{name} has two values: {keys[name]:#x} and {value:#x} ({module.__name__})")
                keys[name] = value
    return keys


def defines() -> list[str]:
    """``-D`` options carrying the Python-side integer codes and hash keys into
    the kernels (keys as uint literals: ``-DSTRATUM_KEY=0x51633e2du``)."""
    opts = [f"-DOFFSET_{name.upper()}={code}" for name, code in OFFSET_CODES.items()]
    opts += [f"-DCONSTRUCTION_{c.function.upper()}={c.code}" for c in catalogue.SAMPLERS.values()]
    opts += [f"-D{name}=0x{value:08x}u" for name, value in kernel_keys().items()]
    return opts


def dispatch_source() -> str:
    """The kernels' dispatch, generated from the catalogue's entries.

    ``oa_dispatch`` (called by ``generate`` in kernels/generate.cl, which
    declares it) applies the block rule (``oa_locate``), then has one
    ``case`` per orthogonal-array entry, running its ``kernel`` statements
    (the construction's cell), then the common tail (``oa_tail``); its ``default`` (an unregistered code, which the
    host never launches) gives NaN, never another construction's value. Each
    comparison sampler gets its own kernel ``generate_<name>``
    (``GENERATE_BASELINE``). Registering an entry is all it takes."""
    entries = list(catalogue.SAMPLERS.values())
    lines = [
        "/* ---- generated from the catalogue (pyoa._opencl.program.dispatch_source) ---- */",
        "float oa_dispatch(uint construction, uint i, uint j, uint s, uint t, uint B, uint N, uint M, uint p,",
        "                  uint offset, float J, __global const ushort *gf, uint gf_tabled, __global const uint *consts)",
        "{",
        "    uint P, row, col, aij = 0u, u = 0u, ck = 0u;",
        "    oa_locate(p, i, j, B, N, &P, &row, &col);  /* the block rule, docs/spec.md section 6 */",
        "    switch (construction) {",
    ]
    lines += [f"    case CONSTRUCTION_{c.function.upper()}: {c.kernel}; break;" for c in entries if c.family == "oa"]
    lines += ["    default: return NAN;  /* not a registered construction */", "    }",
              "    return oa_tail(row, col, P, aij, u, ck, s, M, offset, J);", "}"]
    lines += [f"GENERATE_BASELINE({c.function}, {c.kernel})" for c in entries if c.family != "oa"]
    return "\n".join(lines) + "\n"


def source(names: tuple[str, ...] | None = None) -> str:
    """The program text: the files ``names`` of :mod:`pyoa.kernels` (default
    :data:`pyoa.kernels.SOURCES`), in that order, then (with
    ``generate.cl``) :func:`dispatch_source`."""
    from .. import kernels

    names = names or kernels.SOURCES
    root = resources.files(kernels)
    # The pragma applies from where it appears to the end of the program:
    # first, so no float operation of any file can be contracted into an FMA.
    text = "#pragma OPENCL FP_CONTRACT OFF\n" + "\n".join(
        f"/* ---- {name} ---- */\n" + root.joinpath(name).read_text() for name in names
    )
    return text + ("\n" + dispatch_source() if "generate.cl" in names else "")


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
                    prg = cl.Program(ctx, source() if text is None else text).build(options=BUILD_OPTIONS + defines())
            except cl.Error as exc:
                noise = "".join(printed)
                log = str(exc) + (f"\n(the compiler also printed)\n{noise}" if noise.strip() else "")
                raise BuildError(info, stage, log) from exc
            _cache[key] = (ctx, queue, prg)
        return _cache[key]
