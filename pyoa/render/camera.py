"""Camera rays: the pixel filter's warp and the thin-lens perspective camera.

Conventions are Mitsuba 3's: camera space has +z forward, +y up and +x
towards the image's left; the field of view spans the smaller image axis; a
lens of radius ``aperture`` focuses on the plane ``z = focus_distance``; the
camera moves by ``motion`` over the shutter interval [0, 1).

References
----------
.. [1] M. Pharr, W. Jakob, G. Humphreys, "Physically Based Rendering", 4th
   ed., 2023, sections 5.2 (thin-lens camera) and 8.8 (pixel filters).
"""

from __future__ import annotations

import math

import numpy as np

from .geometry import concentric_disk, normalize

FILTERS = ("box", "gaussian")


def check_filter(filter) -> str:
    """``filter`` if it is one of :data:`FILTERS`, else a ValueError naming them."""
    if filter not in FILTERS:
        raise ValueError(f"unknown pixel filter {filter!r}; valid: {', '.join(FILTERS)}")
    return filter


def filter_offsets(u: np.ndarray, filter: str) -> np.ndarray:
    """Offsets in the pixel (``(N, 2)``, pixel units from its corner) for
    uniform ``u``, importance-sampling the pixel filter so that every sample
    has weight 1: ``box`` is uniform over the pixel; ``gaussian`` (Mitsuba's
    default filter) is a Gaussian of standard deviation 0.5 pixel around the
    centre, truncated at 2 pixels (4 sigma), by inverting its CDF."""
    if filter == "box":
        return u
    from scipy.special import ndtr, ndtri

    lo, hi = ndtr(-4.0), ndtr(4.0)  # +-4 sigma = +-2 pixels
    return 0.5 + 0.5 * ndtri(lo + u * (hi - lo))


def rotate(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``v @ R.T`` written out per element: BLAS could round differently for
    different batch sizes, and the image must not depend on them."""
    return v[:, :1] * R[:, 0] + v[:, 1:2] * R[:, 1] + v[:, 2:3] * R[:, 2]


class PerspectiveCamera:
    """A scene's camera (:class:`pyoa.render.scene.Camera`) for a film of
    ``width`` x ``height`` pixels."""

    def __init__(self, camera, width: int, height: int):
        self.width, self.height = width, height
        self.rot = np.ascontiguousarray(np.asarray(camera.to_world, dtype=np.float64)[:3, :3])
        self.pos = np.ascontiguousarray(np.asarray(camera.to_world, dtype=np.float64)[:3, 3])
        small = min(width, height)
        tan = math.tan(math.radians(camera.fov) / 2)
        self.tan_x, self.tan_y = tan * width / small, tan * height / small
        self.aperture, self.focus_distance = float(camera.aperture), float(camera.focus_distance)
        self.motion = np.asarray(camera.motion, dtype=np.float64)

    def rays(self, pixel: np.ndarray, offset: np.ndarray, lens=None, shutter=None):
        """Origins and directions (``(N, 3)`` float64, unit directions) of the
        rays through ``offset`` (:func:`filter_offsets`) in pixels ``pixel``
        (row-major index), through the lens point ``concentric_disk(lens)`` and
        at shutter times ``shutter`` (None: pinhole, time 0)."""
        fx = ((pixel % self.width) + offset[:, 0]) / self.width
        fy = ((pixel // self.width) + offset[:, 1]) / self.height
        d = np.stack([(1.0 - 2.0 * fx) * self.tan_x, (1.0 - 2.0 * fy) * self.tan_y, np.ones_like(fx)], axis=1)
        o = np.zeros_like(d)
        if lens is not None:
            disk = concentric_disk(lens) * self.aperture
            focus = d * self.focus_distance  # d.z == 1: the point on the plane of focus
            o = np.concatenate([disk, np.zeros((len(d), 1))], axis=1)
            d = focus - o
        o = rotate(self.rot, o) + self.pos
        if shutter is not None:
            o = o + shutter[:, None] * self.motion[None, :]
        return o, normalize(rotate(self.rot, d))
