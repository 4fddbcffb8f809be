"""pyoa's fourth implementation: the samplers in Dr.Jit operations.

The same bits as :mod:`pyoa.reference`, :mod:`pyoa._numpy` and ``kernels/``
(docs/spec.md), written with Dr.Jit array operations (uint32 arithmetic,
``dr.select``, ``dr.gather``, ``dr.while_loop``) so that they can be traced
into a JIT kernel: inside Mitsuba 3 (:mod:`pyoa.mitsuba`) a sampler's values
are computed in the renderer's own kernel, with no host round trip.

Every function takes Dr.Jit ``UInt32`` arrays (any backend: ``drjit.llvm``,
``drjit.cuda``, with or without ``.ad``) and derives the other types it needs
(``Float32``, ``Float64``, ``UInt64``) from them, so one implementation
serves every Mitsuba variant of a JIT backend. Parameters that fix the shape
of the computation (``s``, ``t``, the offset style, the base) are Python ints
and strings: they unroll loops and pick code paths at trace time, as the
kernels' ``-D`` options do.

Dr.Jit is optional (``pip install 'pyoa[mitsuba]'``); importing this package
without it raises ImportError with that advice. :func:`evaluate` is the
entry point the catalogue's tests use: x(pixel, i, j) for every supported
sampler, over Dr.Jit arrays.
"""

from __future__ import annotations

from ..util.drjit_llvm import configure as _configure_llvm

_configure_llvm()  # before Dr.Jit's LLVM backend starts: an LLVM that compiles Mitsuba 3.9's kernels

try:
    import drjit as dr  # noqa: F401
except ImportError as exc:  # pragma: no cover - exercised only without drjit
    raise ImportError("pyoa's Dr.Jit implementation needs drjit (pip install 'pyoa[mitsuba]')") from exc

from .evaluate import SUPPORTED, evaluate, implementation, supports  # noqa: F401
