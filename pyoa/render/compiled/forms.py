"""The one-point forms of :mod:`pyoa.render.bsdfs`, compiled.

The BSDF modules and their shared warps write these forms in plain Python,
marked :func:`pyoa.render.bsdfs.base.scalar`, so that a scene loads, and the
NumPy reference renders, where numba cannot be imported. Here each marked
function gets a compiled twin: a numba function of the same code, inlined
into the loops that call it by numba itself (``inline="always"``, so that
LLVM vectorizes those loops: registered with ``register_jitable`` instead,
the forms were left as calls and the sampling loops did not vectorize, and
inlined through it numba warned of its IR), with IEEE divisions
(``error_model="numpy"``, as the NumPy reference's). The twin
reads its module's globals from a copy of that module's namespace in which
every marked function is replaced by its twin, so a form calling another
(``ggx.sample_point`` calls ``sample_vndf_point``, which calls
``warps.cos_sin_turn``) calls the compiled one, and the BSDF modules
themselves are left as they are. Twins are not cached by themselves: they
are compiled into the cached functions that call them
(:mod:`pyoa.render.compiled`).
"""

from __future__ import annotations

import sys
import types

from numba import njit

from ..bsdfs import base

__all__ = ["FORMS", "compiled"]

_INLINE = dict(nogil=True, inline="always", error_model="numpy")


def _twins() -> dict:
    """``{id(plain function): its compiled twin}`` for every marked function."""
    spaces, twins = {}, {}
    for fn in base.SCALAR:
        ns = spaces.get(fn.__module__)
        if ns is None:
            ns = spaces[fn.__module__] = dict(vars(sys.modules[fn.__module__]))
        copy = types.FunctionType(fn.__code__, ns, fn.__name__, fn.__defaults__, fn.__closure__)
        copy.__qualname__, copy.__module__, copy.__doc__ = fn.__qualname__, fn.__module__, fn.__doc__
        twins[id(fn)] = njit(**_INLINE)(copy)
    # numba compiles lazily, at the first call: every namespace names the twins before any compiles
    for ns in spaces.values():
        for name, value in ns.items():
            if id(value) in twins and value in base.SCALAR:
                ns[name] = twins[id(value)]
    return twins


#: The compiled twin of every marked function, by the plain function's ``id``.
FORMS = _twins()


def compiled(fn):
    """The compiled twin of the marked one-point form ``fn``."""
    return FORMS[id(fn)]
