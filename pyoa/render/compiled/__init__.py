"""The path tracer's shading compiled with numba, Embree called from it.

It mirrors the NumPy reference (:mod:`pyoa.render.integrator`,
:mod:`pyoa.render.bsdfs`, :mod:`pyoa.render.geometry`) function by function,
the same operations in the same order, shades a bounce in vectorized loops
over lanes (:mod:`~pyoa.render.compiled.shading`) and traces through
:mod:`pyoa.render.embree`. Chosen with
``shading="numba"`` (the default), ``pyoa render --shading`` or
``PYOA_SHADING``.

The BSDFs' one-point forms and the warps they share are plain Python in
:mod:`pyoa.render.bsdfs` (marked :func:`pyoa.render.bsdfs.base.scalar`), so
that a scene loads without numba; :mod:`~pyoa.render.compiled.forms` gives
each a compiled twin, inlined into the loops that call it.

numba's on-disk cache (``cache=True``) knows a compiled function only by its
own source file: code and constants it compiled in from other files (the
BSDFs, the warps, Embree's queries, the offset constants) would be reused
unchanged after those files change, as after a ``git pull`` into an editable
install. So the modules of this package are imported with numba's cache
directory set to a folder named after a digest of every source they compile
from (:data:`SOURCES`, :func:`cache_dir`, in
:mod:`~pyoa.render.compiled.cache`): a changed source compiles again instead
of rendering with the old code.
"""

from __future__ import annotations

from .cache import SOURCES, cache_dir, salted_cache, sources_digest  # noqa: F401  (this package's cache)

with salted_cache():
    from . import bsdfs, camera, emitters, forms, geometry, integrator, shading  # noqa: F401  (decorated here)
