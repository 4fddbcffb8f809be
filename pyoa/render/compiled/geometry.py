"""The warps and frames of :mod:`pyoa.render.geometry`, one point at a time, compiled."""

from __future__ import annotations

import math

from numba import njit

#: error_model="numpy": divisions follow IEEE (as the NumPy reference's do)
#: instead of numba's default per-division ZeroDivisionError check.
_JIT = dict(nogil=True, cache=True, inline="always", error_model="numpy")


@njit(**_JIT)
def concentric_disk(u0, u1):
    """Shirley and Chiu's concentric map of ``[0,1)^2`` onto the unit disk."""
    a = 2.0 * u0 - 1.0
    b = 2.0 * u1 - 1.0
    if a == 0.0 and b == 0.0:
        return 0.0, 0.0
    if abs(a) > abs(b):
        r, phi = a, (math.pi / 4) * (b / a)
    else:
        r, phi = b, math.pi / 2 - (math.pi / 4) * (a / b)
    return r * math.cos(phi), r * math.sin(phi)


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
