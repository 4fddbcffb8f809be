"""Camera rays of :mod:`pyoa.render.camera`, compiled: the thin-lens
perspective camera of :class:`~pyoa.render.camera.PerspectiveCamera`, one lane
at a time (the filter's warp is :func:`~pyoa.render.camera.filter_offsets`,
shared with the reference: it needs SciPy's inverse normal CDF)."""

from __future__ import annotations

import math

from numba import njit

from .geometry import concentric_disk

#: error_model="numpy": IEEE divisions, as the NumPy reference's.
_JIT = dict(nogil=True, cache=True, error_model="numpy")


@njit(**_JIT)
def camera_rays(pixel, u, lens, shutter, width, height, tan_x, tan_y, rot, pos, aperture, focus, motion, o, d):
    """Camera rays of the lanes (as ``PerspectiveCamera.rays``) into ``o`` and
    ``d``: ``u`` the offsets in the pixel (already warped by the filter),
    ``lens`` the lens samples and ``shutter`` the times (empty arrays when the
    camera has none)."""
    has_lens, has_time = lens.shape[0] > 0, shutter.shape[0] > 0
    for i in range(pixel.shape[0]):
        fx = ((pixel[i] % width) + u[i, 0]) / width
        fy = ((pixel[i] // width) + u[i, 1]) / height
        # Mitsuba's camera space: +z forward, +y up, +x towards the image's left.
        dx, dy, dz = (1.0 - 2.0 * fx) * tan_x, (1.0 - 2.0 * fy) * tan_y, 1.0
        ox, oy, oz = 0.0, 0.0, 0.0
        if has_lens:
            lx, ly = concentric_disk(lens[i, 0], lens[i, 1])
            ox, oy = lx * aperture, ly * aperture
            dx, dy, dz = dx * focus - ox, dy * focus - oy, dz * focus
        for k in range(3):
            o[i, k] = ox * rot[k, 0] + oy * rot[k, 1] + oz * rot[k, 2] + pos[k]
            if has_time:
                o[i, k] = o[i, k] + shutter[i] * motion[k]
        wx = dx * rot[0, 0] + dy * rot[0, 1] + dz * rot[0, 2]
        wy = dx * rot[1, 0] + dy * rot[1, 1] + dz * rot[1, 2]
        wz = dx * rot[2, 0] + dy * rot[2, 1] + dz * rot[2, 2]
        n = math.sqrt(wx * wx + wy * wy + wz * wz)
        n = n if n > 0 else 1.0
        d[i, 0], d[i, 1], d[i, 2] = wx / n, wy / n, wz / n
