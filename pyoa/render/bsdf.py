"""Vectorized BSDFs in a local shading frame.

Every direction is a unit ``float64`` vector in the *local* frame of the shading
point, where the shading normal is ``+z``; arrays hold one lane per shading
point, shape ``(N, 3)``. ``wo`` points away from the surface towards the viewer
and the caller guarantees ``wo[:, 2] > 0`` (it flips the shading normal towards
``wo``: every surface is two-sided). Lanes whose ``wo`` breaks that contract get
zero weight, zero value and zero pdf rather than garbage.

Material kinds
--------------
``DIFFUSE``
    Lambertian reflection, :math:`f = \\rho / \\pi`, sampled with Malley's method
    (Shirley-Chiu concentric disk mapping lifted to the hemisphere), so
    :math:`p(\\omega_i) = \\cos\\theta_i / \\pi` and the sample weight is
    exactly :math:`\\rho`.
``MIRROR``
    Perfect specular reflection :math:`\\omega_i = (-\\omega_{o,x}, -\\omega_{o,y},
    \\omega_{o,z})` with weight equal to the tint. It is a Dirac delta lobe:
    :func:`sample` flags it with ``delta`` and reports pdf 0 by convention;
    :func:`evaluate` returns 0 for it (a delta cannot be hit by another
    strategy).
``GGX``
    Rough conductor: Cook-Torrance microfacet BRDF (Walter et al. 2007)

    .. math::

        f(\\omega_o, \\omega_i) = \\frac{F(\\omega_o\\cdot h)\\, D(h)\\,
            G_2(\\omega_o, \\omega_i)}{4 \\cos\\theta_o \\cos\\theta_i},
        \\qquad h = \\frac{\\omega_o + \\omega_i}{\\lVert \\omega_o + \\omega_i \\rVert},

    with the isotropic GGX (Trowbridge-Reitz) distribution of roughness
    :math:`\\alpha` (clamped to :math:`\\ge 10^{-3}`),

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
    \\cdot h)^5` with :math:`F_0` the RGB ``color``. Directions are sampled by
    sampling the **visible normals** (Heitz 2018), whose density is
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

Numerics
--------
All GGX quantities are written in forms free of :math:`\\tan\\theta` and of
divisions by :math:`\\cos\\theta`: with :math:`a(\\omega) = \\sqrt{\\omega_z^2 +
\\alpha^2 (\\omega_x^2 + \\omega_y^2)}`,
:math:`G_1(\\omega) = 2\\omega_z / (\\omega_z + a(\\omega))`,
:math:`f\\cos\\theta_i = F D \\cos\\theta_i / (2 (a_o \\cos\\theta_i + a_i
\\cos\\theta_o))` and :math:`p = D / (2 (\\cos\\theta_o + a_o))`, so every
output stays finite for grazing directions and tiny roughness.

References
----------
B. Walter, S. R. Marschner, H. Li, K. E. Torrance, "Microfacet Models for
Refraction through Rough Surfaces", EGSR 2007.

E. Heitz, "Understanding the Masking-Shadowing Function in Microfacet-Based
BRDFs", JCGT 3(2), 2014.

E. Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4), 2018.

M. Pharr, W. Jakob, G. Humphreys, "Physically Based Rendering: From Theory to
Implementation", 3rd ed., sections 8.4 (microfacet models), 13.6.2-13.6.3
(concentric disk and cosine-weighted hemisphere sampling), 14.1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import concentric_disk

__all__ = ["DIFFUSE", "MIRROR", "GGX", "KINDS", "ALPHA_MIN", "Materials", "sample", "evaluate"]

DIFFUSE, MIRROR, GGX = 0, 1, 2
KINDS = {"diffuse": DIFFUSE, "mirror": MIRROR, "ggx": GGX}

#: GGX roughness is clamped to at least this value when shading.
ALPHA_MIN = 1e-3

_TINY = 1e-300


@dataclass(frozen=True, eq=False)
class Materials:
    """Parameters of ``M`` materials as arrays (index = material id).

    Attributes
    ----------
    names : tuple of str
        Material names, unique, ``names[i]`` is material id ``i``.
    kind : numpy.ndarray
        ``(M,)`` ``int32``: one of :data:`DIFFUSE`, :data:`MIRROR`, :data:`GGX`.
    color : numpy.ndarray
        ``(M, 3)`` ``float64`` in ``[0, 1]``: diffuse reflectance, mirror tint,
        or GGX normal-incidence Fresnel reflectance :math:`F_0`.
    alpha : numpy.ndarray
        ``(M,)`` ``float64``: GGX roughness :math:`\\alpha` in ``(0, 1]``
        (ignored by the other kinds).

    The arrays are made read-only. Build instances with :meth:`build`.
    """

    names: tuple[str, ...]
    kind: np.ndarray
    color: np.ndarray
    alpha: np.ndarray

    @classmethod
    def build(cls, specs: list[tuple[str, str, tuple[float, float, float], float]]) -> "Materials":
        """Build the material table from ``(name, kind name, color, alpha)`` tuples.

        Parameters
        ----------
        specs : list of tuple
            ``(name, kind, color, alpha)`` per material, in id order; ``kind``
            is a key of :data:`KINDS`, ``color`` three floats in ``[0, 1]``,
            ``alpha`` the GGX roughness in ``(0, 1]`` (any finite number for
            the other kinds).

        Returns
        -------
        Materials

        Raises
        ------
        ValueError
            On an unknown kind (the message names the valid kinds), a duplicate
            name, a color that is not three finite numbers in ``[0, 1]``, or a
            GGX alpha outside ``(0, 1]``.
        """
        names, kinds, colors, alphas = [], [], [], []
        for spec in specs:
            try:
                name, kind_name, color, alpha = spec
            except (TypeError, ValueError):
                raise ValueError(f"material spec must be (name, kind, color, alpha), got {spec!r}") from None
            name = str(name)
            if name in names:
                raise ValueError(f"duplicate material name {name!r}")
            if kind_name not in KINDS:
                raise ValueError(
                    f"material {name!r}: unknown kind {kind_name!r}; valid kinds: {', '.join(sorted(KINDS))}"
                )
            try:
                c = np.asarray(color, dtype=np.float64)
            except (TypeError, ValueError):
                raise ValueError(f"material {name!r}: color must be three numbers, got {color!r}") from None
            if c.shape != (3,) or not np.all(np.isfinite(c)) or np.any(c < 0.0) or np.any(c > 1.0):
                raise ValueError(f"material {name!r}: color must be three numbers in [0, 1], got {color!r}")
            try:
                a = float(alpha)
            except (TypeError, ValueError):
                raise ValueError(f"material {name!r}: alpha must be a number, got {alpha!r}") from None
            if KINDS[kind_name] == GGX and not (0.0 < a <= 1.0):
                raise ValueError(f"material {name!r}: ggx alpha must be in (0, 1], got {alpha!r}")
            if not np.isfinite(a):
                a = 0.0  # ignored by non-GGX kinds; keep the table finite
            names.append(name)
            kinds.append(KINDS[kind_name])
            colors.append(c)
            alphas.append(a)
        kind = np.asarray(kinds, dtype=np.int32).reshape(-1)
        color = np.asarray(colors, dtype=np.float64).reshape(-1, 3)
        alpha_arr = np.asarray(alphas, dtype=np.float64).reshape(-1)
        for arr in (kind, color, alpha_arr):
            arr.setflags(write=False)
        return cls(tuple(names), kind, color, alpha_arr)


# --------------------------------------------------------------------------- helpers


def _ggx_lambda_root(w: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """:math:`a(\\omega) = \\sqrt{\\omega_z^2 + \\alpha^2(\\omega_x^2 + \\omega_y^2)}`,
    so that :math:`\\Lambda(\\omega) = (a/\\omega_z - 1)/2`."""
    return np.sqrt(w[:, 2] ** 2 + alpha**2 * (w[:, 0] ** 2 + w[:, 1] ** 2))


def _ggx_d(h: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """GGX normal distribution :math:`D(h)` (Walter et al. 2007, eq. 33), cancellation-free form."""
    t = (h[:, 0] ** 2 + h[:, 1] ** 2) / alpha**2 + h[:, 2] ** 2
    return 1.0 / np.maximum(np.pi * alpha**2 * t * t, _TINY)


def _ggx_eval(color: np.ndarray, alpha: np.ndarray, wo: np.ndarray, wi: np.ndarray):
    """GGX ``(f_cos, pdf)`` for lanes with ``wo.z > 0`` and ``wi.z > 0``."""
    h = wo + wi
    h = h / np.maximum(np.linalg.norm(h, axis=1), _TINY)[:, None]
    d = _ggx_d(h, alpha)
    zo, zi = wo[:, 2], wi[:, 2]
    ao, ai = _ggx_lambda_root(wo, alpha), _ggx_lambda_root(wi, alpha)
    cos_oh = np.clip(np.sum(wo * h, axis=1), 0.0, 1.0)
    fresnel = color + (1.0 - color) * ((1.0 - cos_oh) ** 5)[:, None]
    # f cos_i = F D G2 / (4 zo) with G2 = 2 zo zi / (ao zi + ai zo)
    f_cos = fresnel * (d * zi / np.maximum(2.0 * (ao * zi + ai * zo), _TINY))[:, None]
    # p = G1(wo) D / (4 zo) with G1(wo) = 2 zo / (zo + ao)
    pdf = d / np.maximum(2.0 * (zo + ao), _TINY)
    return f_cos, pdf


def _ggx_sample_vndf(wo: np.ndarray, alpha: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Sample a visible microfacet normal (Heitz 2018, listing 1)."""
    vh = np.stack([alpha * wo[:, 0], alpha * wo[:, 1], wo[:, 2]], axis=1)
    vh = vh / np.maximum(np.linalg.norm(vh, axis=1), _TINY)[:, None]
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
    ok = norm > _TINY
    ne = np.where(ok[:, None], ne / np.where(ok, norm, 1.0)[:, None], np.array([0.0, 0.0, 1.0]))
    return ne


def _lanes(m: np.ndarray):
    """An index for the lanes where ``m`` holds, or None if none: a slice when
    all do (a scene of one material kind, such as the Cornell box), which
    makes every ``a[i]`` a view and every ``a[i] = v`` a plain copy instead
    of a boolean gather or scatter (docs/performance.md)."""
    if m.all():
        return slice(None)
    idx = np.flatnonzero(m)
    return idx if idx.size else None


def _as_inputs(mats: Materials, mat, wo, other):
    mat = np.asarray(mat).reshape(-1)
    wo = np.asarray(wo, dtype=np.float64).reshape(-1, 3)
    kind = mats.kind[mat]
    color = mats.color[mat]
    alpha = np.maximum(mats.alpha[mat], ALPHA_MIN)
    return mat, wo, np.asarray(other, dtype=np.float64), kind, color, alpha


# --------------------------------------------------------------------------- API


def sample(mats: Materials, mat: np.ndarray, wo: np.ndarray, u: np.ndarray):
    """Sample an incident direction ``wi`` per shading point.

    Parameters
    ----------
    mats : Materials
        The material table.
    mat : numpy.ndarray
        ``(N,)`` integer material ids.
    wo : numpy.ndarray
        ``(N, 3)`` unit outgoing directions in the local frame, ``wo[:, 2] > 0``.
    u : numpy.ndarray
        ``(N, 2)`` uniform samples in ``[0, 1)``.

    Returns
    -------
    wi : numpy.ndarray
        ``(N, 3)`` unit sampled directions.
    weight : numpy.ndarray
        ``(N, 3)`` throughput weight :math:`f(\\omega_o,\\omega_i) |\\cos\\theta_i|
        / p(\\omega_i)` (for ``MIRROR``: the tint).
    pdf : numpy.ndarray
        ``(N,)`` solid-angle density of ``wi``, equal to ``evaluate(...)[1]``
        at ``wi``; 0 for delta lobes (read ``delta``).
    delta : numpy.ndarray
        ``(N,)`` bool, True for delta lobes (``MIRROR``).

    Notes
    -----
    Diffuse: Malley's method, :math:`p = \\cos\\theta_i/\\pi`, weight :math:`\\rho`.
    GGX: visible-normal sampling (Heitz 2018), :math:`p = G_1(\\omega_o) D(h) /
    (4\\cos\\theta_o)`, weight :math:`F\\, G_2 / G_1(\\omega_o)`. Samples with
    ``wi.z <= 0`` (or lanes with ``wo.z <= 0``) get weight 0 and pdf 0.
    """
    mat, wo, u, kind, color, alpha = _as_inputs(mats, mat, wo, u)
    u = u.reshape(-1, 2)
    n = wo.shape[0]
    wi = np.zeros((n, 3))
    wi[:, 2] = 1.0
    weight = np.zeros((n, 3))
    pdf = np.zeros(n)
    delta = kind == MIRROR
    valid = wo[:, 2] > 0.0

    m = _lanes((kind == DIFFUSE) & valid)
    if m is not None:
        x, y = concentric_disk(u[m]).T
        z = np.sqrt(np.maximum(0.0, 1.0 - x * x - y * y))
        d = np.stack([x, y, z], axis=1)
        wi[m] = d / np.linalg.norm(d, axis=1)[:, None]
        above = wi[m, 2] > 0.0
        weight[m] = np.where(above[:, None], color[m], 0.0)
        pdf[m] = np.where(above, wi[m, 2] / np.pi, 0.0)

    m = _lanes((kind == MIRROR) & valid)
    if m is not None:
        wi[m] = wo[m] * np.array([-1.0, -1.0, 1.0])
        weight[m] = color[m]

    m = _lanes((kind == GGX) & valid)
    if m is not None:
        wo_m, a_m = wo[m], alpha[m]
        h = _ggx_sample_vndf(wo_m, a_m, u[m])
        d = 2.0 * np.sum(wo_m * h, axis=1)[:, None] * h - wo_m
        d = d / np.maximum(np.linalg.norm(d, axis=1), _TINY)[:, None]
        above = d[:, 2] > 0.0
        f_cos, p = _ggx_eval(color[m], a_m, wo_m, np.where(above[:, None], d, np.array([0.0, 0.0, 1.0])))
        ok = above & (p > 0.0) & np.isfinite(p)
        wi[m] = d
        weight[m] = np.where(ok[:, None], f_cos / np.where(ok, p, 1.0)[:, None], 0.0)
        pdf[m] = np.where(ok, p, 0.0)

    return wi, weight, pdf, delta


def evaluate(mats: Materials, mat: np.ndarray, wo: np.ndarray, wi: np.ndarray):
    """Evaluate the BSDF times the cosine and the sampling density.

    Parameters
    ----------
    mats : Materials
        The material table.
    mat : numpy.ndarray
        ``(N,)`` integer material ids.
    wo, wi : numpy.ndarray
        ``(N, 3)`` unit directions in the local frame, ``wo[:, 2] > 0``.

    Returns
    -------
    f_cos : numpy.ndarray
        ``(N, 3)`` :math:`f(\\omega_o,\\omega_i) \\max(\\cos\\theta_i, 0)`.
    pdf : numpy.ndarray
        ``(N,)`` the solid-angle density with which :func:`sample` produces
        ``wi``.

    Both are 0 for delta lobes (``MIRROR``) and for ``wi`` at or below the
    surface (``wi.z <= 0``).
    """
    mat, wo, wi, kind, color, alpha = _as_inputs(mats, mat, wo, wi)
    wi = wi.reshape(-1, 3)
    n = wo.shape[0]
    f_cos = np.zeros((n, 3))
    pdf = np.zeros(n)
    valid = (wo[:, 2] > 0.0) & (wi[:, 2] > 0.0)

    m = _lanes((kind == DIFFUSE) & valid)
    if m is not None:
        c = wi[m, 2]
        f_cos[m] = color[m] * (c / np.pi)[:, None]
        pdf[m] = c / np.pi

    m = _lanes((kind == GGX) & valid)
    if m is not None:
        f_cos[m], pdf[m] = _ggx_eval(color[m], alpha[m], wo[m], wi[m])

    return f_cos, pdf
