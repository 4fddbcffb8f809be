"""The warps and frames of :mod:`pyoa.render.geometry`, one point at a time, compiled.

The warps that the BSDFs' one-point forms share with the camera (the
concentric disk, the polynomial sines and cosines) are written in
:mod:`pyoa.render.bsdfs.warps`, plain Python compiled by
:mod:`pyoa.render.compiled.forms`.
"""

from __future__ import annotations

import math

from numba import njit

from ..bsdfs import warps
from .forms import compiled

#: error_model="numpy": divisions follow IEEE (as the NumPy reference's do)
#: instead of numba's default per-division ZeroDivisionError check.
_JIT = dict(nogil=True, cache=True, inline="always", error_model="numpy")

#: Shirley and Chiu's concentric disk (:func:`pyoa.render.bsdfs.warps.concentric_disk`), the thin lens's.
concentric_disk = compiled(warps.concentric_disk)


@njit(**_JIT)
def frame(nx, ny, nz):
    """Tangents ``(t, b)`` completing the unit normal ``n`` (Duff et al. 2017)."""
    sign = 1.0 if nz >= 0 else -1.0
    a = -1.0 / (sign + nz)
    b = nx * ny * a
    return (1.0 + sign * nx * nx * a, sign * b, -sign * nx), (b, sign + ny * ny * a, -ny)


@njit(**_JIT)
def triangle_point(u0, u1):
    """Barycentric weights of a uniform point in a triangle (square-root warp)."""
    su = math.sqrt(u0)
    w1 = u1 * su
    w0 = 1.0 - su
    return w0, w1, 1.0 - w0 - w1
