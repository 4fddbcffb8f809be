"""Smooth glass: an interface between two dielectrics (Mitsuba's ``dielectric``).

A ray meeting the interface is reflected with the probability of the exact,
unpolarized Fresnel reflectance :math:`F` and refracted otherwise, as
Mitsuba 3's ``dielectric`` samples it. With :math:`\\eta` the relative index
of refraction across the interface in the direction of travel
(``int_ior / ext_ior`` for a ray arriving on the front, the side the
geometric normal points to, and its reciprocal for a ray arriving from
behind), :math:`\\cos\\theta_i` the cosine of ``wo`` (the side it lies on),
and Snell's law :math:`\\sin\\theta_t = \\sin\\theta_i / \\eta`:

.. math::

    \\cos\\theta_t = \\sqrt{1 - (1 - \\cos^2\\theta_i) / \\eta^2}, \\qquad
    r_s = \\frac{\\cos\\theta_i - \\eta \\cos\\theta_t}{\\cos\\theta_i + \\eta \\cos\\theta_t}, \\qquad
    r_p = \\frac{\\cos\\theta_t - \\eta \\cos\\theta_i}{\\cos\\theta_t + \\eta \\cos\\theta_i}, \\qquad
    F = \\frac{r_s^2 + r_p^2}{2},

with :math:`\\cos\\theta_t = 0` and so :math:`F = 1` where :math:`1 -
\\cos^2\\theta_i > \\eta^2` (total internal reflection). At normal incidence
:math:`F = ((\\eta - 1)/(\\eta + 1))^2`. The sample is

.. math::

    \\omega_i = (-\\omega_{o,x}, -\\omega_{o,y}, \\omega_{o,z}) \\text{ with weight } 1
    \\quad (u < F), \\qquad
    \\omega_i = (-\\omega_{o,x}/\\eta, -\\omega_{o,y}/\\eta, -\\cos\\theta_t)
    \\text{ with weight } 1/\\eta^2 \\quad (\\text{else}),

the factor :math:`1/\\eta^2` being the change of radiance across the
interface (the solid angle's compression; Veach 1997, 5.2), which Mitsuba
applies in its radiance mode too. Both lobes are Dirac deltas (``DELTA``):
the material gets no light sample (as Mitsuba's path integrator, whose
shadow rays stop at glass), :func:`sample` reports pdf 0 and ``delta``, and
:func:`evaluate` and :func:`pdf` are 0.

The side a ray arrives on is the geometric one: the renderer turns the
shading frame towards ``wo`` (every surface is two-sided, so ``wo.z > 0``
here) and passes ``front`` (whether ``wo`` lies on the side of the
triangle's geometric normal); a closed mesh with outward normals (the
``cube``) is a solid block of glass.

Scene keys, as Mitsuba's: ``int_ior`` (the index inside, behind the
normal; default 1.5046, Mitsuba's ``bk7``) and ``ext_ior`` (outside;
default 1.000277, Mitsuba's ``air``), numbers > 0.

References
----------
M. Born, E. Wolf, "Principles of Optics", 7th ed., 1.5.2 (Fresnel formulae).

E. Veach, "Robust Monte Carlo Methods for Light Transport Simulation", PhD
thesis, Stanford, 1997, 5.2 (non-symmetric scattering due to refraction).

W. Jakob et al., Mitsuba 3, ``src/bsdfs/dielectric.cpp`` and
``include/mitsuba/render/fresnel.h`` (the sampling and the Fresnel term
followed here).

M. Pharr, W. Jakob, G. Humphreys, "Physically Based Rendering", 3rd ed.,
8.2 (specular reflection and transmission).
"""

from __future__ import annotations

import math

import numpy as np

from .base import Key, scalar

NAME = "dielectric"
KEYS = (Key("int_ior", 1.5046, lo=0.0, lo_open=True), Key("ext_ior", 1.000277, lo=0.0, lo_open=True))
DELTA = True
LANES = True


def params(values: dict) -> tuple[float, ...]:
    """The material table's numbers: :math:`\\eta` = ``int_ior / ext_ior``."""
    return (values["int_ior"] / values["ext_ior"],)


# --------------------------------------------------------------------------- NumPy forms


def etas(eta: np.ndarray, front: np.ndarray):
    """``(eta_it, eta_ti)``: the relative index across the interface in the
    direction of travel, ``eta`` from the front and ``1 / eta`` from behind,
    and its reciprocal."""
    inv = 1.0 / eta
    return np.where(front, eta, inv), np.where(front, inv, eta)


def fresnel(cos_i: np.ndarray, eta_it: np.ndarray, eta_ti: np.ndarray):
    """``(F, cos_t)``: the unpolarized Fresnel reflectance for ``cos_i > 0``
    and the cosine of the refracted direction (0 at total internal
    reflection, where ``F`` is 1). ``F`` is exactly 0 where the indices
    match (``eta_it == 1``), as Mitsuba's (the formula's rounding would leave
    about 1e-32)."""
    ct = np.sqrt(np.maximum(1.0 - (1.0 - cos_i * cos_i) * (eta_ti * eta_ti), 0.0))
    a_s = (cos_i - eta_it * ct) / (cos_i + eta_it * ct)
    a_p = (ct - eta_it * cos_i) / (ct + eta_it * cos_i)
    return np.where(eta_it == 1.0, 0.0, 0.5 * (a_s * a_s + a_p * a_p)), ct


def sample(p: np.ndarray, wo: np.ndarray, u: np.ndarray, front: np.ndarray):
    """``(wi, weight, pdf, delta)``: reflection where ``u[:, 0] < F`` (weight
    1), else refraction (weight ``eta_ti^2``); pdf 0 and delta (two Dirac
    lobes). ``p[:, 0]``: ``int_ior / ext_ior``; ``wo.z > 0``; ``front``:
    whether ``wo`` lies on the side of the geometric normal."""
    eta_it, eta_ti = etas(p[:, 0], front)
    f, ct = fresnel(wo[:, 2], eta_it, eta_ti)
    r = u[:, 0] < f
    refracted = np.stack([-eta_ti * wo[:, 0], -eta_ti * wo[:, 1], -ct], axis=1)
    wi = np.where(r[:, None], wo * np.array([-1.0, -1.0, 1.0]), refracted)
    weight = np.repeat(np.where(r, 1.0, eta_ti * eta_ti)[:, None], 3, axis=1)
    return wi, weight, np.zeros(len(wo)), np.ones(len(wo), dtype=bool)


def evaluate(p: np.ndarray, wo: np.ndarray, wi: np.ndarray, front: np.ndarray):
    """``(f_cos, pdf)``: 0 (two delta lobes)."""
    return np.zeros((len(wo), 3)), np.zeros(len(wo))


def pdf(p: np.ndarray, wo: np.ndarray, wi: np.ndarray, front: np.ndarray) -> np.ndarray:
    """0 (two delta lobes)."""
    return np.zeros(len(wo))


# --------------------------------------------------------------------------- one-point forms


@scalar
def fresnel_point(cos_i, eta_it, eta_ti):
    """:func:`fresnel` for one point: ``(F, cos_t)``, the same operations."""
    ct = math.sqrt(max(1.0 - (1.0 - cos_i * cos_i) * (eta_ti * eta_ti), 0.0))
    a_s = (cos_i - eta_it * ct) / (cos_i + eta_it * ct)
    a_p = (ct - eta_it * cos_i) / (ct + eta_it * cos_i)
    return 0.0 if eta_it == 1.0 else 0.5 * (a_s * a_s + a_p * a_p), ct


@scalar
def sample_point(m0, m1, m2, m3, front, ox, oy, oz, u0, u1):
    """:func:`sample` for one point, free of branches: ``(wi x, y, z, weight
    r, g, b, pdf, delta)``, the same operations (so the same bits)."""
    inv = 1.0 / m0
    eta_it = m0 if front else inv
    eta_ti = inv if front else m0
    f, ct = fresnel_point(oz, eta_it, eta_ti)
    r = u0 < f
    t = eta_ti * eta_ti
    w = 1.0 if r else t
    return -ox if r else -eta_ti * ox, -oy if r else -eta_ti * oy, oz if r else -ct, w, w, w, 0.0, True


@scalar
def evaluate_point(m0, m1, m2, m3, front, ox, oy, oz, ix, iy, iz):
    """:func:`evaluate` for one point: 0."""
    return 0.0, 0.0, 0.0, 0.0
