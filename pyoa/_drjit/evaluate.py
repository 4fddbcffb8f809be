"""The catalogue's entries in Dr.Jit: which are supported, and x(pixel, i, j) for them.

An entry's Dr.Jit implementation is called exactly as its other three are
(:class:`pyoa.catalogue.entries.Construction`): ``function(i, j,
*shape_args(params), *seed_args(pixel_seed, seed, pixel), *options(offset,
jitter))``, with this package's :func:`.hashes.pixel_seed`.
"""

from __future__ import annotations

import drjit as dr

from .. import catalogue
from . import baselines, faure, hashes, oa, zfaure

#: The modules of the Dr.Jit implementations, by the name an entry gives
#: (``entry.drjit_module``): an entry is supported when its module defines a
#: function named as the entry (``entry.function``). Every orthogonal array,
#: faure, zfaure and random; the other comparison samplers read tables
#: (Sobol' matrices, PMJ02 points) and are left to Mitsuba's own samplers.
MODULES = {"oa": oa, "faure": faure, "zfaure": zfaure, "baselines": baselines}

#: Entry name -> its Dr.Jit implementation, from the catalogue.
IMPLEMENTATIONS = {
    entry.name: f
    for entry in catalogue.SAMPLERS.values()
    if callable(f := getattr(MODULES[entry.drjit_module], entry.function, None))
}

#: The supported names, in the catalogue's order.
SUPPORTED = tuple(n for n in catalogue.names() if n in IMPLEMENTATIONS)


def supports(name: str) -> bool:
    """Whether sampler ``name`` (any spelling :func:`pyoa.catalogue.get` accepts) has a Dr.Jit implementation."""
    try:
        return catalogue.get(name).name in IMPLEMENTATIONS
    except (TypeError, ValueError):
        return False


def implementation(name: str):
    """The Dr.Jit function of sampler ``name``; ValueError naming the supported ones otherwise.

    ``name`` is resolved through the catalogue first (case, and the pbrt/Mitsuba
    names of :data:`pyoa.catalogue.ALIASES`: ``"orthogonal"`` is ``bose``), as
    :func:`pyoa.sampler` and the CLI resolve it; an unknown name gets the
    catalogue's own message.
    """
    entry = catalogue.get(name)
    try:
        return IMPLEMENTATIONS[entry.name]
    except KeyError:
        shown = entry.name if entry.name == name else f"{name} ({entry.name})"
        raise ValueError(f"{shown} has no Dr.Jit implementation (pyoa.mitsuba); supported: "
                         f"{', '.join(SUPPORTED)}") from None


def evaluate(name: str, i, j, params, seed, pixel, offset=None, jitter=1.0):
    """x(pixel, i, j) of sampler ``name`` with resolved ``params`` over Dr.Jit ``UInt32`` arrays.

    ``i``, ``j`` and ``pixel`` are arrays of one backend (or Python ints that
    broadcast); ``seed`` is the user seed (uint32). ``offset`` defaults to
    the OA samplers' ``"cmj"``. Returns ``Float32`` values with the bits of
    ``pyoa.sampler(...).generate`` (tested in ``tests/test_drjit.py``).
    """
    entry = catalogue.get(name)
    f = implementation(name)
    U = next((type(x) for x in (i, j, pixel) if dr.is_array_v(x)), None)
    if U is None:
        raise TypeError("evaluate needs at least one Dr.Jit UInt32 array among i, j and pixel")
    i, j, pixel = U(i), U(j), U(pixel)
    offset = "cmj" if offset is None else offset
    return f(i, j, *entry.shape_args(params), *entry.seed_args(hashes.pixel_seed, U(seed), pixel),
             *entry.options(offset, jitter))
