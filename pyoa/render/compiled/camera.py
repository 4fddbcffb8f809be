"""Camera rays of :mod:`pyoa.render.camera`, compiled: the thin-lens
perspective camera of :class:`~pyoa.render.camera.PerspectiveCamera`
(the filter's warp is :func:`~pyoa.render.camera.filter_offsets`, shared with
the reference: it needs SciPy's inverse normal CDF).

Rays are made :data:`LANES` at a time in a scratch of one row per quantity
(as :mod:`pyoa.render.compiled.shading` shades, and for the same reasons: a
loop over lanes that touches one flat array, rows a constant distance apart
and one cache line more than a power of two, vectorizes): a scalar loop
copies each lane's pixel column and row and its samples in, a vectorized one
(:func:`_rays`) makes the rays, a scalar one copies them out. Each lane does
the reference's operations in the same order, so a pinhole camera's rays
are the reference's to the bit (moving or not, either filter); a thin
lens's disk point takes its sine and cosine from
:func:`~pyoa.render.bsdfs.warps.sin_cos` instead of NumPy's, so those
rays are within 2 ulps of the reference's (both tested:
``tests/render/test_compiled.py``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .geometry import concentric_disk

#: error_model="numpy": IEEE divisions, as the NumPy reference's.
_JIT = dict(nogil=True, cache=True, error_model="numpy")

#: Rays made together, and the distance between the scratch's rows.
LANES = 256
ROW = LANES + 8
#: The scratch's rows: the inputs (pixel column and row, offsets in the
#: pixel, lens sample, time), then the ray.
COL, LINE, U, V, LENS_U, LENS_V, TIME, OX, OY, OZ, DX, DY, DZ = (k * ROW for k in range(13))
#: Length of the scratch (:func:`camera_rays`' ``scratch``): one ROW past the last row.
SCRATCH = DZ + ROW


@njit(**_JIT, inline="always")
def _rays(m, has_lens, has_time, width, height, tan_x, tan_y, r, p, aperture, focus, mo, C):
    """The rays of the ``m`` lanes of the scratch ``C`` (vectorized); ``r``,
    ``p`` and ``mo`` are the rotation, position and motion as tuples of
    scalars, so that the loop reads no array but the scratch."""
    for j in range(m):
        fx = (C[COL + j] + C[U + j]) / width
        fy = (C[LINE + j] + C[V + j]) / height
        # Mitsuba's camera space: +z forward, +y up, +x towards the image's left.
        dx, dy, dz = (1.0 - 2.0 * fx) * tan_x, (1.0 - 2.0 * fy) * tan_y, 1.0
        ox, oy, oz = 0.0, 0.0, 0.0
        if has_lens:
            lx, ly = concentric_disk(C[LENS_U + j], C[LENS_V + j])
            ox, oy = lx * aperture, ly * aperture
            dx, dy, dz = dx * focus - ox, dy * focus - oy, dz * focus
        o0 = ox * r[0] + oy * r[1] + oz * r[2] + p[0]
        o1 = ox * r[3] + oy * r[4] + oz * r[5] + p[1]
        o2 = ox * r[6] + oy * r[7] + oz * r[8] + p[2]
        if has_time:
            s = C[TIME + j]
            o0, o1, o2 = o0 + s * mo[0], o1 + s * mo[1], o2 + s * mo[2]
        C[OX + j], C[OY + j], C[OZ + j] = o0, o1, o2
        wx = dx * r[0] + dy * r[1] + dz * r[2]
        wy = dx * r[3] + dy * r[4] + dz * r[5]
        wz = dx * r[6] + dy * r[7] + dz * r[8]
        n = math.sqrt(wx * wx + wy * wy + wz * wz)
        n = n if n > 0 else 1.0
        C[DX + j], C[DY + j], C[DZ + j] = wx / n, wy / n, wz / n


@njit(**_JIT)
def camera_rays(pixel, x, u, columns, width, height, tan_x, tan_y, rot, pos, aperture, focus, motion, scratch, o, d):
    """Camera rays of the paths ``pixel[i]`` whose sampler rows are ``x[i]``
    (as ``PerspectiveCamera.rays``) into ``o`` and ``d``. ``u`` are the
    offsets in the pixel already warped by a Gaussian filter
    (:func:`~pyoa.render.camera.filter_offsets`), empty for the box filter,
    whose offsets are the samples themselves; ``columns`` the sampler
    columns of the pixel offsets, the lens and the time (-1 where the camera
    has none); ``scratch`` :data:`SCRATCH` float64."""
    C = scratch
    has_lens, has_time, filtered = columns[2] >= 0, columns[4] >= 0, u.shape[0] > 0
    # the columns in locals: read from ``columns`` inside the loops, they would be read again after every
    # store to the scratch, which the compiler cannot tell apart from them
    cu, cv, cl, cm, ct = columns[0], columns[1], columns[2], columns[3], columns[4]
    r = (rot[0, 0], rot[0, 1], rot[0, 2], rot[1, 0], rot[1, 1], rot[1, 2], rot[2, 0], rot[2, 1], rot[2, 2])
    p = (pos[0], pos[1], pos[2])
    mo = (motion[0], motion[1], motion[2])
    n = pixel.shape[0]
    last, col, line = -1, 0, 0
    for start in range(0, n, LANES):
        m = min(LANES, n - start)
        # the inputs, one quantity per loop: a loop that tests the camera's options lane by lane is slower
        for j in range(m):
            i = start + j
            if pixel[i] != last:  # a pixel's samples are consecutive: one integer division per pixel
                last = pixel[i]
                col, line = last % width, last // width
            C[COL + j], C[LINE + j] = col, line
        if filtered:
            for j in range(m):
                C[U + j], C[V + j] = u[start + j, 0], u[start + j, 1]
        else:
            for j in range(m):
                C[U + j], C[V + j] = np.float64(x[start + j, cu]), np.float64(x[start + j, cv])
        if has_lens:
            for j in range(m):
                C[LENS_U + j], C[LENS_V + j] = np.float64(x[start + j, cl]), np.float64(x[start + j, cm])
        if has_time:
            for j in range(m):
                C[TIME + j] = np.float64(x[start + j, ct])
        # one call per combination of options, the options constants in each: the compiler drops what the
        # camera does not do from the vectorized loop (_rays is inlined)
        if has_lens and has_time:
            _rays(m, True, True, width, height, tan_x, tan_y, r, p, aperture, focus, mo, C)
        elif has_lens:
            _rays(m, True, False, width, height, tan_x, tan_y, r, p, aperture, focus, mo, C)
        elif has_time:
            _rays(m, False, True, width, height, tan_x, tan_y, r, p, aperture, focus, mo, C)
        else:
            _rays(m, False, False, width, height, tan_x, tan_y, r, p, aperture, focus, mo, C)
        for j in range(m):
            i = start + j
            o[i, 0], o[i, 1], o[i, 2] = C[OX + j], C[OY + j], C[OZ + j]
            d[i, 0], d[i, 1], d[i, 2] = C[DX + j], C[DY + j], C[DZ + j]
