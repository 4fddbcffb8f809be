"""A rough conductor: the GGX microfacet BRDF with Schlick's Fresnel term.

Cook-Torrance microfacet reflection (Walter et al. 2007)

.. math::

    f(\\omega_o, \\omega_i) = \\frac{F(\\omega_o\\cdot h)\\, D(h)\\,
        G_2(\\omega_o, \\omega_i)}{4 \\cos\\theta_o \\cos\\theta_i},
    \\qquad h = \\frac{\\omega_o + \\omega_i}{\\lVert \\omega_o + \\omega_i \\rVert},

with the isotropic GGX (Trowbridge-Reitz) distribution of roughness
:math:`\\alpha` (clamped to :math:`\\ge` :data:`ALPHA_MIN`),

.. math::

    D(h) = \\frac{1}{\\pi \\alpha^2 \\left( (h_x^2 + h_y^2)/\\alpha^2 + h_z^2
        \\right)^2},

Smith's **height-correlated** masking-shadowing function (Heitz 2014,
eq. 99)

.. math::

    G_2 = \\frac{1}{1 + \\Lambda(\\omega_o) + \\Lambda(\\omega_i)},\\qquad
    \\Lambda(\\omega) = \\frac{-1 + \\sqrt{1 + \\alpha^2 \\tan^2\\theta}}{2},\\qquad
    G_1(\\omega) = \\frac{1}{1 + \\Lambda(\\omega)},

and Schlick's Fresnel approximation :math:`F = F_0 + (1 - F_0)(1 - \\omega_o
\\cdot h)^5` with :math:`F_0` the RGB ``specular`` colour. Directions are
sampled by sampling the **visible normals** (Heitz 2018), whose density is
:math:`D_{\\omega_o}(h) = G_1(\\omega_o) \\max(0, \\omega_o\\cdot h) D(h) /
\\cos\\theta_o`, then reflecting ``wo`` about ``h``; with the Jacobian
:math:`d\\omega_h / d\\omega_i = 1 / (4\\, \\omega_o\\cdot h)` of the reflection
(Walter et al. 2007, eq. 14)

.. math::

    p(\\omega_i) = \\frac{D_{\\omega_o}(h)}{4\\, \\omega_o\\cdot h}
        = \\frac{G_1(\\omega_o)\\, D(h)}{4 \\cos\\theta_o},
    \\qquad
    \\frac{f \\cos\\theta_i}{p} = F\\, \\frac{G_2(\\omega_o,\\omega_i)}{G_1(\\omega_o)}
        \\le F.

Reflected directions that end below the surface are discarded (weight 0,
pdf 0), so :math:`\\int_{H^2} p \\, d\\omega_i` equals the probability that a
visible-normal reflection stays above the surface (< 1 at grazing angles).

Numerics: every quantity is written free of :math:`\\tan\\theta` and of
divisions by :math:`\\cos\\theta`: with :math:`a(\\omega) = \\sqrt{\\omega_z^2 +
\\alpha^2 (\\omega_x^2 + \\omega_y^2)}`, :math:`G_1(\\omega) = 2\\omega_z /
(\\omega_z + a(\\omega))`, :math:`f\\cos\\theta_i = F D \\cos\\theta_i / (2 (a_o
\\cos\\theta_i + a_i \\cos\\theta_o))` and :math:`p = D / (2 (\\cos\\theta_o +
a_o))`, so every output stays finite for grazing directions and tiny
roughness.

Scene keys: ``specular`` (:math:`F_0`, RGB in [0, 1], default white) and
``roughness`` (:math:`\\alpha` as Mitsuba's ``alpha``, in (0, 1], default 0.1).

References
----------
B. Walter, S. R. Marschner, H. Li, K. E. Torrance, "Microfacet Models for
Refraction through Rough Surfaces", EGSR 2007.

E. Heitz, "Understanding the Masking-Shadowing Function in Microfacet-Based
BRDFs", JCGT 3(2), 2014.

E. Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4), 2018.

M. Pharr, W. Jakob, G. Humphreys, "Physically Based Rendering", 3rd ed.,
8.4 (microfacet models), 14.1.
"""

from __future__ import annotations

import math

import numpy as np

from .base import TINY, Key, lanes, scalar
from .warps import cos_sin_turn

NAME = "ggx"
KEYS = (Key("specular", (1.0, 1.0, 1.0), lo=0.0, hi=1.0), Key("roughness", 0.1, lo=0.0, hi=1.0, lo_open=True))
DELTA = False
LANES = True

#: The roughness is clamped to at least this value when shading.
ALPHA_MIN = 1e-3


def params(values: dict) -> tuple[float, ...]:
    """The material table's numbers: :math:`F_0` (r, g, b) and :math:`\\alpha`."""
    return (*values["specular"], values["roughness"])


# --------------------------------------------------------------------------- NumPy forms


def _lambda_root(w: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """:math:`a(\\omega) = \\sqrt{\\omega_z^2 + \\alpha^2(\\omega_x^2 + \\omega_y^2)}`,
    so that :math:`\\Lambda(\\omega) = (a/\\omega_z - 1)/2`."""
    return np.sqrt(w[:, 2] ** 2 + alpha**2 * (w[:, 0] ** 2 + w[:, 1] ** 2))


def _d(h: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """GGX normal distribution :math:`D(h)` (Walter et al. 2007, eq. 33), cancellation-free form."""
    t = (h[:, 0] ** 2 + h[:, 1] ** 2) / alpha**2 + h[:, 2] ** 2
    return 1.0 / np.maximum(np.pi * alpha**2 * t * t, TINY)


def _eval(color: np.ndarray, alpha: np.ndarray, wo: np.ndarray, wi: np.ndarray):
    """``(f_cos, pdf)`` for lanes with ``wo.z > 0`` and ``wi.z > 0``."""
    h = wo + wi
    h = h / np.maximum(np.linalg.norm(h, axis=1), TINY)[:, None]
    d = _d(h, alpha)
    zo, zi = wo[:, 2], wi[:, 2]
    ao, ai = _lambda_root(wo, alpha), _lambda_root(wi, alpha)
    cos_oh = np.clip(np.sum(wo * h, axis=1), 0.0, 1.0)
    fresnel = color + (1.0 - color) * ((1.0 - cos_oh) ** 5)[:, None]
    # f cos_i = F D G2 / (4 zo) with G2 = 2 zo zi / (ao zi + ai zo)
    f_cos = fresnel * (d * zi / np.maximum(2.0 * (ao * zi + ai * zo), TINY))[:, None]
    # p = G1(wo) D / (4 zo) with G1(wo) = 2 zo / (zo + ao)
    pdf = d / np.maximum(2.0 * (zo + ao), TINY)
    return f_cos, pdf


def _sample_vndf(wo: np.ndarray, alpha: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Sample a visible microfacet normal (Heitz 2018, listing 1)."""
    vh = np.stack([alpha * wo[:, 0], alpha * wo[:, 1], wo[:, 2]], axis=1)
    vh = vh / np.maximum(np.linalg.norm(vh, axis=1), TINY)[:, None]
    lensq = vh[:, 0] ** 2 + vh[:, 1] ** 2
    has_t = lensq > 0.0
    inv = np.where(has_t, 1.0 / np.sqrt(np.where(has_t, lensq, 1.0)), 0.0)
    t1 = np.stack(
        [np.where(has_t, -vh[:, 1] * inv, 1.0), np.where(has_t, vh[:, 0] * inv, 0.0), np.zeros_like(lensq)], axis=1
    )
    t2 = np.cross(vh, t1)
    r = np.sqrt(u[:, 0])
    phi = 2.0 * np.pi * u[:, 1]
    p1 = r * np.cos(phi)
    p2 = r * np.sin(phi)
    s = 0.5 * (1.0 + vh[:, 2])
    p2 = (1.0 - s) * np.sqrt(np.maximum(0.0, 1.0 - p1 * p1)) + s * p2
    p3 = np.sqrt(np.maximum(0.0, 1.0 - p1 * p1 - p2 * p2))
    nh = p1[:, None] * t1 + p2[:, None] * t2 + p3[:, None] * vh
    ne = np.stack([alpha * nh[:, 0], alpha * nh[:, 1], np.maximum(0.0, nh[:, 2])], axis=1)
    norm = np.linalg.norm(ne, axis=1)
    ok = norm > TINY
    return np.where(ok[:, None], ne / np.where(ok, norm, 1.0)[:, None], np.array([0.0, 0.0, 1.0]))


def sample(p: np.ndarray, wo: np.ndarray, u: np.ndarray, front: np.ndarray):
    """``(wi, weight, pdf, delta)``: visible-normal sampling (Heitz 2018),
    :math:`p = G_1(\\omega_o) D(h) / (4\\cos\\theta_o)`, weight :math:`F\\, G_2 /
    G_1(\\omega_o)`; weight and pdf 0 where ``wi`` ends below the surface.
    ``p``: the ``(n, PARAMS)`` material numbers; ``wo.z > 0``; ``front`` unused."""
    color, alpha = p[:, :3], np.maximum(p[:, 3], ALPHA_MIN)
    h = _sample_vndf(wo, alpha, u)
    d = 2.0 * np.sum(wo * h, axis=1)[:, None] * h - wo
    d = d / np.maximum(np.linalg.norm(d, axis=1), TINY)[:, None]
    above = d[:, 2] > 0.0
    f_cos, pd = _eval(color, alpha, wo, np.where(above[:, None], d, np.array([0.0, 0.0, 1.0])))
    ok = above & (pd > 0.0) & np.isfinite(pd)
    weight = np.where(ok[:, None], f_cos / np.where(ok, pd, 1.0)[:, None], 0.0)
    return d, weight, np.where(ok, pd, 0.0), np.zeros(len(wo), dtype=bool)


def evaluate(p: np.ndarray, wo: np.ndarray, wi: np.ndarray, front: np.ndarray):
    """``(f_cos, pdf)``: :math:`f \\cos\\theta_i` and :func:`sample`'s density of
    ``wi``, 0 where ``wi.z <= 0``."""
    f_cos, pd = np.zeros((len(wo), 3)), np.zeros(len(wo))
    m = lanes(wi[:, 2] > 0.0)
    if m is not None:
        f_cos[m], pd[m] = _eval(p[m, :3], np.maximum(p[m, 3], ALPHA_MIN), wo[m], wi[m])
    return f_cos, pd


def pdf(p: np.ndarray, wo: np.ndarray, wi: np.ndarray, front: np.ndarray) -> np.ndarray:
    """:func:`sample`'s density of ``wi``: :math:`D(h) / (2(\\cos\\theta_o + a_o))` above the surface."""
    return evaluate(p, wo, wi, front)[1]


# --------------------------------------------------------------------------- one-point forms


@scalar
def lambda_root(x, y, z, alpha):
    """:math:`a(\\omega) = \\sqrt{\\omega_z^2 + \\alpha^2(\\omega_x^2 + \\omega_y^2)}`."""
    return math.sqrt(z * z + alpha * alpha * (x * x + y * y))


@scalar
def d_point(hx, hy, hz, alpha):
    """GGX normal distribution :math:`D(h)`, cancellation-free form."""
    t = (hx * hx + hy * hy) / (alpha * alpha) + hz * hz
    return 1.0 / max(math.pi * alpha * alpha * t * t, TINY)


@scalar
def eval_point(cr, cg, cb, alpha, ox, oy, oz, ix, iy, iz):
    """``(f_cos r, g, b, pdf)`` for ``wo.z > 0`` and ``wi.z > 0`` (as ``_eval``)."""
    hx, hy, hz = ox + ix, oy + iy, oz + iz
    hn = max(math.sqrt(hx * hx + hy * hy + hz * hz), TINY)
    hx, hy, hz = hx / hn, hy / hn, hz / hn
    d = d_point(hx, hy, hz, alpha)
    ao = lambda_root(ox, oy, oz, alpha)
    ai = lambda_root(ix, iy, iz, alpha)
    cos_oh = min(max(ox * hx + oy * hy + oz * hz, 0.0), 1.0)
    s5 = (1.0 - cos_oh) ** 5
    g = d * iz / max(2.0 * (ao * iz + ai * oz), TINY)
    pdf = d / max(2.0 * (oz + ao), TINY)
    return (cr + (1.0 - cr) * s5) * g, (cg + (1.0 - cg) * s5) * g, (cb + (1.0 - cb) * s5) * g, pdf


@scalar
def sample_vndf_point(ox, oy, oz, alpha, u0, u1):
    """A visible microfacet normal (Heitz 2018, listing 1), as ``_sample_vndf``."""
    vx, vy, vz = alpha * ox, alpha * oy, oz
    vn = max(math.sqrt(vx * vx + vy * vy + vz * vz), TINY)
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
    ok = norm > TINY
    return ex / norm if ok else 0.0, ey / norm if ok else 0.0, ez / norm if ok else 1.0


@scalar
def sample_point(m0, m1, m2, m3, front, ox, oy, oz, u0, u1):
    """:func:`sample` for one point, free of branches: ``(wi x, y, z, weight
    r, g, b, pdf, delta)``."""
    a = max(m3, ALPHA_MIN)
    hx, hy, hz = sample_vndf_point(ox, oy, oz, a, u0, u1)
    c = 2.0 * (ox * hx + oy * hy + oz * hz)
    dx, dy, dz = c * hx - ox, c * hy - oy, c * hz - oz
    dn = max(math.sqrt(dx * dx + dy * dy + dz * dz), TINY)
    dx, dy, dz = dx / dn, dy / dn, dz / dn
    # evaluated for every lane (where dz <= 0 its values are not used), then selected
    fr, fg, fb, p = eval_point(m0, m1, m2, a, ox, oy, oz, dx, dy, dz)
    ok = (dz > 0.0) & (p > 0.0) & (abs(p) < math.inf)
    return dx, dy, dz, fr / p if ok else 0.0, fg / p if ok else 0.0, fb / p if ok else 0.0, p if ok else 0.0, False


@scalar
def evaluate_point(m0, m1, m2, m3, front, ox, oy, oz, ix, iy, iz):
    """:func:`evaluate` for one point, free of branches: ``(f_cos r, g, b,
    pdf)``, 0 where ``wo`` or ``wi`` lies below the surface."""
    f_r, f_g, f_b, pdf = eval_point(m0, m1, m2, max(m3, ALPHA_MIN), ox, oy, oz, ix, iy, iz)
    lit = not ((oz <= 0.0) | (iz <= 0.0))  # selects: a NaN passes (the shading never makes one)
    return f_r if lit else 0.0, f_g if lit else 0.0, f_b if lit else 0.0, pdf if lit else 0.0
