"""Finding an LLVM library that Dr.Jit (Mitsuba 3's JIT) can compile Mitsuba's kernels with.

Mitsuba 3.9's LLVM backend emits ``llvm.minimum``/``llvm.maximum``, which
LLVM before 16 cannot lower on x86 ("LLVM ERROR: Cannot select ...
fminimum"); Dr.Jit loads whichever ``libLLVM`` it finds first, which on
Debian 12 is LLVM 14 or 15 (PoCL's). :func:`configure` points Dr.Jit at the
newest system ``libLLVM`` >= 16 (Debian: ``apt-get install libllvm19``)
through ``DRJIT_LIBLLVM_PATH``, unless that is already set. Dr.Jit reads the
variable when its LLVM backend starts (the first ``mi.set_variant('llvm_*')``
or ``drjit.llvm`` array), so it must run before that: :mod:`pyoa.mitsuba`
and :mod:`pyoa._drjit` call it on import.

This module imports neither Dr.Jit nor Mitsuba.
"""

from __future__ import annotations

import glob
import os
import re

#: The oldest LLVM major version that compiles Mitsuba 3.9's kernels.
MIN_DRJIT_LLVM = 16


def drjit_llvm() -> str | None:
    """``$DRJIT_LIBLLVM_PATH`` if set, else the newest system libLLVM >= 16
    (e.g. Debian's ``libllvm19``), else None (Dr.Jit's own search)."""
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return os.environ["DRJIT_LIBLLVM_PATH"]
    found = []
    for path in glob.glob("/usr/lib/*/libLLVM.so.*") + glob.glob("/usr/lib/*/libLLVM-*.so") \
            + glob.glob("/usr/lib/llvm-*/lib/libLLVM.so"):
        m = re.search(r"LLVM(?:\.so\.|-)(\d+)|llvm-(\d+)/", path)
        major = int(next(g for g in m.groups() if g)) if m else 0
        if major >= MIN_DRJIT_LLVM:
            found.append((major, path))
    return max(found)[1] if found else None


def configure() -> str | None:
    """Set ``DRJIT_LIBLLVM_PATH`` to :func:`drjit_llvm` when it is unset and one is found; return the path."""
    path = drjit_llvm()
    if path and not os.environ.get("DRJIT_LIBLLVM_PATH"):
        os.environ["DRJIT_LIBLLVM_PATH"] = path
    return path
