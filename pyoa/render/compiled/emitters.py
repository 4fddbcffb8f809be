"""Emitter sampling of :mod:`pyoa.render.emitters`, compiled, one lane at a time."""

from __future__ import annotations

import numpy as np
from numba import njit

from .geometry import triangle_point

_INLINE = dict(nogil=True, cache=True, error_model="numpy", inline="always")
#: The largest float64 below 1 (the sample is clamped to [0, 1) like the reference).
_BELOW_ONE = float(np.nextafter(1.0, 0.0))


@njit(**_INLINE)
def sample_emitter(em, em_cdf, em_prob, verts, normals, areas, u0, u1):
    """A point on an emitter chosen by power: ``(triangle, point, normal, pdf
    per unit area)``, as :meth:`pyoa.render.emitters.Emitters.sample` (``em``,
    ``em_cdf``, ``em_prob`` are its ``index``, ``cdf`` and ``prob``)."""
    # the first k with em_cdf[k] > u0 (NumPy's searchsorted, side="right",
    # which costs a generic call per lane), clamped to the last emitter
    lo, hi = 0, em_cdf.shape[0]
    while lo < hi:
        mid = (lo + hi) >> 1
        if em_cdf[mid] <= u0:
            lo = mid + 1
        else:
            hi = mid
    k = min(lo, em.shape[0] - 1)
    lo = em_cdf[k - 1] if k > 0 else 0.0
    v = min(max((u0 - lo) / (em_cdf[k] - lo), 0.0), _BELOW_ONE)
    tri = em[k]
    w0, w1, w2 = triangle_point(v, u1)
    px = w0 * verts[tri, 0, 0] + w1 * verts[tri, 1, 0] + w2 * verts[tri, 2, 0]
    py = w0 * verts[tri, 0, 1] + w1 * verts[tri, 1, 1] + w2 * verts[tri, 2, 1]
    pz = w0 * verts[tri, 0, 2] + w1 * verts[tri, 1, 2] + w2 * verts[tri, 2, 2]
    return tri, px, py, pz, normals[tri, 0], normals[tri, 1], normals[tri, 2], em_prob[tri] / areas[tri]
