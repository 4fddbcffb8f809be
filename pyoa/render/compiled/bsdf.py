"""The BSDFs of :mod:`pyoa.render.bsdf`, one shading point at a time, compiled.

Same models, same formulas and the same guards as the NumPy reference
(Lambertian with Malley's method, mirror, GGX conductor with visible-normal
sampling and the height-correlated Smith term in its tan-free form): read the
reference's docstring for the math. Functions are named after the
reference's (``ggx_d`` mirrors ``bsdf._ggx_d``, ...). Vectors are passed as
three floats, directions are unit vectors in the local shading frame
(normal = +z) with ``wo.z > 0``.
"""

from __future__ import annotations

import math

from numba import njit

from ..bsdf import ALPHA_MIN, DIFFUSE, GGX, MIRROR
from .geometry import concentric_disk, cos_sin_turn

_TINY = 1e-300
#: error_model="numpy": divisions follow IEEE (as the NumPy reference's do)
#: instead of numba's default per-division ZeroDivisionError check.
_JIT = dict(nogil=True, cache=True, inline="always", error_model="numpy")


@njit(**_JIT)
def ggx_lambda_root(x, y, z, alpha):
    """:math:`a(\\omega) = \\sqrt{\\omega_z^2 + \\alpha^2(\\omega_x^2 + \\omega_y^2)}`."""
    return math.sqrt(z * z + alpha * alpha * (x * x + y * y))


@njit(**_JIT)
def ggx_d(hx, hy, hz, alpha):
    """GGX normal distribution :math:`D(h)`, cancellation-free form."""
    t = (hx * hx + hy * hy) / (alpha * alpha) + hz * hz
    return 1.0 / max(math.pi * alpha * alpha * t * t, _TINY)


@njit(**_JIT)
def ggx_eval(cr, cg, cb, alpha, ox, oy, oz, ix, iy, iz):
    """GGX ``(f_cos r, g, b, pdf)`` for ``wo.z > 0`` and ``wi.z > 0``."""
    hx, hy, hz = ox + ix, oy + iy, oz + iz
    hn = max(math.sqrt(hx * hx + hy * hy + hz * hz), _TINY)
    hx, hy, hz = hx / hn, hy / hn, hz / hn
    d = ggx_d(hx, hy, hz, alpha)
    ao = ggx_lambda_root(ox, oy, oz, alpha)
    ai = ggx_lambda_root(ix, iy, iz, alpha)
    cos_oh = min(max(ox * hx + oy * hy + oz * hz, 0.0), 1.0)
    s5 = (1.0 - cos_oh) ** 5
    g = d * iz / max(2.0 * (ao * iz + ai * oz), _TINY)
    pdf = d / max(2.0 * (oz + ao), _TINY)
    return (cr + (1.0 - cr) * s5) * g, (cg + (1.0 - cg) * s5) * g, (cb + (1.0 - cb) * s5) * g, pdf


@njit(**_JIT)
def ggx_sample_vndf(ox, oy, oz, alpha, u0, u1):
    """A visible microfacet normal (Heitz 2018, listing 1)."""
    vx, vy, vz = alpha * ox, alpha * oy, oz
    vn = max(math.sqrt(vx * vx + vy * vy + vz * vz), _TINY)
    vx, vy, vz = vx / vn, vy / vn, vz / vn
    lensq = vx * vx + vy * vy
    # selects rather than branches (as every function here that a lane loop
    # calls): the same values, and the loop vectorizes
    has = lensq > 0.0
    inv = 1.0 / math.sqrt(lensq)  # inf where lensq is 0, and not used there
    t1x, t1y, t1z = -vy * inv if has else 1.0, vx * inv if has else 0.0, 0.0
    # t2 = vh x t1
    t2x = vy * t1z - vz * t1y
    t2y = vz * t1x - vx * t1z
    t2z = vx * t1y - vy * t1x
    r = math.sqrt(u0)
    c, s_ = cos_sin_turn(u1)  # of the angle 2 pi u1
    p1 = r * c
    p2 = r * s_
    s = 0.5 * (1.0 + vz)
    p2 = (1.0 - s) * math.sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2
    p3 = math.sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2))
    nx = p1 * t1x + p2 * t2x + p3 * vx
    ny = p1 * t1y + p2 * t2y + p3 * vy
    nz = p1 * t1z + p2 * t2z + p3 * vz
    ex, ey, ez = alpha * nx, alpha * ny, max(0.0, nz)
    norm = math.sqrt(ex * ex + ey * ey + ez * ez)
    ok = norm > _TINY
    return ex / norm if ok else 0.0, ey / norm if ok else 0.0, ez / norm if ok else 1.0


@njit(**_JIT)
def sample_diffuse(cr, cg, cb, u0, u1):
    """The Lambertian lobe's sample (Malley's method), free of branches so
    that a loop over lanes vectorizes: ``(wi x, y, z, weight r, g, b, pdf)``."""
    x, y = concentric_disk(u0, u1)
    z = math.sqrt(max(0.0, 1.0 - x * x - y * y))
    inv = 1.0 / math.sqrt(x * x + y * y + z * z)
    x, y, z = x * inv, y * inv, z * inv
    up = z > 0.0
    return (x, y, z, cr if up else 0.0, cg if up else 0.0, cb if up else 0.0, z / math.pi if up else 0.0)


@njit(**_JIT)
def sample_ggx(cr, cg, cb, alpha, ox, oy, oz, u0, u1):
    """The GGX conductor's sample (visible normals): ``(wi x, y, z, weight r,
    g, b, pdf)``, free of branches so that a loop over lanes vectorizes
    (:func:`pyoa.render.compiled.shading.ggx_sample`)."""
    a = max(alpha, ALPHA_MIN)
    hx, hy, hz = ggx_sample_vndf(ox, oy, oz, a, u0, u1)
    c = 2.0 * (ox * hx + oy * hy + oz * hz)
    dx, dy, dz = c * hx - ox, c * hy - oy, c * hz - oz
    dn = max(math.sqrt(dx * dx + dy * dy + dz * dz), _TINY)
    dx, dy, dz = dx / dn, dy / dn, dz / dn
    # evaluated for every lane (where dz <= 0 its values are not used), then selected
    fr, fg, fb, p = ggx_eval(cr, cg, cb, a, ox, oy, oz, dx, dy, dz)
    ok = (dz > 0.0) & (p > 0.0) & (abs(p) < math.inf)
    return dx, dy, dz, fr / p if ok else 0.0, fg / p if ok else 0.0, fb / p if ok else 0.0, p if ok else 0.0


@njit(**_JIT)
def sample(kind, cr, cg, cb, alpha, ox, oy, oz, u0, u1):
    """``(wi x, y, z, weight r, g, b, pdf, delta)``: :func:`pyoa.render.bsdf.sample` for one point."""
    if oz <= 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, kind == MIRROR
    if kind == DIFFUSE:
        x, y, z, wr, wg, wb, pdf = sample_diffuse(cr, cg, cb, u0, u1)
        return x, y, z, wr, wg, wb, pdf, False
    if kind == MIRROR:
        return -ox, -oy, oz, cr, cg, cb, 0.0, True
    x, y, z, wr, wg, wb, pdf = sample_ggx(cr, cg, cb, alpha, ox, oy, oz, u0, u1)
    return x, y, z, wr, wg, wb, pdf, False


@njit(**_JIT)
def evaluate_diffuse(cr, cg, cb, oz, iz):
    """The Lambertian lobe's ``(f_cos r, g, b, pdf)``, free of branches."""
    c = iz / math.pi
    lit = oz > 0.0 and iz > 0.0
    return cr * c if lit else 0.0, cg * c if lit else 0.0, cb * c if lit else 0.0, c if lit else 0.0


@njit(**_JIT)
def evaluate_ggx(cr, cg, cb, alpha, ox, oy, oz, ix, iy, iz):
    """The GGX lobe's ``(f_cos r, g, b, pdf)``, zero where ``wo`` or ``wi``
    lies below the surface, free of branches (the lane loop:
    :func:`pyoa.render.compiled.shading.ggx_evaluate`)."""
    f_r, f_g, f_b, pdf = ggx_eval(cr, cg, cb, max(alpha, ALPHA_MIN), ox, oy, oz, ix, iy, iz)
    lit = not ((oz <= 0.0) | (iz <= 0.0))  # as evaluate's test, NaN included
    return f_r if lit else 0.0, f_g if lit else 0.0, f_b if lit else 0.0, pdf if lit else 0.0


@njit(**_JIT)
def evaluate(kind, cr, cg, cb, alpha, ox, oy, oz, ix, iy, iz):
    """``(f_cos r, g, b, pdf)``: :func:`pyoa.render.bsdf.evaluate` for one point."""
    if oz <= 0.0 or iz <= 0.0 or kind == MIRROR:
        return 0.0, 0.0, 0.0, 0.0
    if kind == DIFFUSE:
        return evaluate_diffuse(cr, cg, cb, oz, iz)
    if kind == GGX:
        return evaluate_ggx(cr, cg, cb, alpha, ox, oy, oz, ix, iy, iz)
    return 0.0, 0.0, 0.0, 0.0
