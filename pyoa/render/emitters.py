"""Emitters: the scene's emissive triangles, chosen in proportion to their
power (area x mean radiance), and a uniform point on the chosen one.

The probability of triangle ``k`` is ``P_k = power_k / sum(power)``; the
point is uniform on it, so its density per unit area is ``P_k / area_k``
(:meth:`Emitters.pdf_area`). One uniform number picks the triangle by
inverting the CDF and is then rescaled to [0, 1) within the chosen interval
to place the point, so the pair of numbers of a ``light<k>`` dimension stays
stratified on each triangle.
"""

from __future__ import annotations

import numpy as np

from .geometry import triangle_point


class Emitters:
    """The emissive triangles of a scene (:class:`pyoa.render.scene.Scene`).

    Attributes
    ----------
    index : numpy.ndarray
        ``(E,)`` int64 triangle indices of the emitters.
    cdf : numpy.ndarray
        ``(E,)`` float64 cumulative probabilities (last = 1).
    prob : numpy.ndarray
        ``(T,)`` float64 probability of each triangle of the scene (0 for
        non-emitters).
    """

    def __init__(self, scene):
        self.scene = scene
        em = np.asarray(scene.emitters, dtype=np.int64)
        power = scene.areas[em] * scene.emission[em].mean(axis=1)
        self.index = em
        self.cdf = np.cumsum(power) / power.sum()
        self.prob = np.zeros(len(scene.areas))
        self.prob[em] = power / power.sum()

    def pdf_area(self, tri: np.ndarray) -> np.ndarray:
        """Density per unit area of the points :meth:`sample` puts on triangles ``tri``."""
        return self.prob[tri] / self.scene.areas[tri]

    def sample(self, u: np.ndarray):
        """A point on an emitter per row of ``u`` (``(N, 2)`` in [0, 1)):
        ``(triangle, point, normal, pdf per unit area)``."""
        k = np.minimum(np.searchsorted(self.cdf, u[:, 0], side="right"), len(self.index) - 1)
        lo = np.where(k > 0, self.cdf[np.maximum(k - 1, 0)], 0.0)
        u0 = np.clip((u[:, 0] - lo) / (self.cdf[k] - lo), 0.0, np.nextafter(1.0, 0.0))
        tri = self.index[k]
        w = triangle_point(np.stack([u0, u[:, 1]], axis=1))
        v = self.scene.triangles[tri].astype(np.float64)
        p = np.einsum("ij,ijk->ik", w, v)
        return tri, p, self.scene.normals[tri], self.prob[tri] / self.scene.areas[tri]
