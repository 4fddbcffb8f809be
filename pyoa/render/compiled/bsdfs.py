"""The BSDFs of :mod:`pyoa.render.bsdfs` for one shading point, compiled, with
the dispatch on a material's kind built from the registry.

Each BSDF module writes its one-point forms (``sample_point``,
``evaluate_point``) in plain Python; :mod:`~pyoa.render.compiled.forms`
compiles them. numba needs the call on a kind to be static: :func:`sample` and
:func:`evaluate` are each a chain of small compiled functions, one per kind
of :data:`pyoa.render.bsdfs.BSDFS` (``if kind == k: that BSDF's form, else
the next link``), made from the registry when this module is imported, so a
new BSDF needs no line here. (numba inlines the links into the caller, whose
own cache entry holds them; a link is not cached by itself.)
"""

from __future__ import annotations

from numba import njit

from ..bsdfs import BSDFS
from .forms import compiled

#: error_model="numpy": IEEE divisions, as the NumPy reference's.
_JIT = dict(nogil=True, cache=True, error_model="numpy")
_LINK = dict(nogil=True, error_model="numpy", inline="always")
#: Per kind: every lobe is a Dirac delta (what a sample below the surface reports).
_DELTA = tuple(bool(m.DELTA) for m in BSDFS)


def _sample_link(kind, form, rest):
    def link(k, m0, m1, m2, m3, front, ox, oy, oz, u0, u1):
        if k == kind:
            return form(m0, m1, m2, m3, front, ox, oy, oz, u0, u1)
        return rest(k, m0, m1, m2, m3, front, ox, oy, oz, u0, u1)

    return njit(**_LINK)(link)


def _evaluate_link(kind, form, rest):
    def link(k, m0, m1, m2, m3, front, ox, oy, oz, ix, iy, iz):
        if k == kind:
            return form(m0, m1, m2, m3, front, ox, oy, oz, ix, iy, iz)
        return rest(k, m0, m1, m2, m3, front, ox, oy, oz, ix, iy, iz)

    return njit(**_LINK)(link)


@njit(**_LINK)
def _no_sample(k, m0, m1, m2, m3, front, ox, oy, oz, u0, u1):
    return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, False


@njit(**_LINK)
def _no_value(k, m0, m1, m2, m3, front, ox, oy, oz, ix, iy, iz):
    return 0.0, 0.0, 0.0, 0.0


def _chain(make, form, tail):
    """``make``'s links for every kind of the registry, in kind order, ending in ``tail``."""
    link = tail
    for kind in range(len(BSDFS) - 1, -1, -1):
        link = make(kind, compiled(getattr(BSDFS[kind], form)), link)
    return link


_SAMPLE = _chain(_sample_link, "sample_point", _no_sample)
_EVALUATE = _chain(_evaluate_link, "evaluate_point", _no_value)


@njit(**_JIT)
def sample(kind, m0, m1, m2, m3, front, ox, oy, oz, u0, u1):
    """``(wi x, y, z, weight r, g, b, pdf, delta)``: :func:`pyoa.render.bsdfs.sample`
    for one point of a material of kind ``kind`` and numbers ``m0 .. m3``
    (``front``: ``wo`` lies on the side of the geometric normal): where
    ``wo.z <= 0``, ``wi = +z`` with weight and pdf 0."""
    if oz <= 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, _DELTA[kind]
    return _SAMPLE(kind, m0, m1, m2, m3, front, ox, oy, oz, u0, u1)


@njit(**_JIT)
def evaluate(kind, m0, m1, m2, m3, front, ox, oy, oz, ix, iy, iz):
    """``(f_cos r, g, b, pdf)``: :func:`pyoa.render.bsdfs.evaluate` for one point
    (0 where ``wo.z <= 0``: each BSDF's ``evaluate_point`` sees to it)."""
    return _EVALUATE(kind, m0, m1, m2, m3, front, ox, oy, oz, ix, iy, iz)
