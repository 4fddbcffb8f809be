"""Lambertian diffuse reflection (Mitsuba's ``diffuse``).

.. math::

    f(\\omega_o, \\omega_i) = \\frac{\\rho}{\\pi}, \\qquad
    p(\\omega_i) = \\frac{\\cos\\theta_i}{\\pi}, \\qquad
    \\frac{f \\cos\\theta_i}{p} = \\rho,

sampled with Malley's method: Shirley and Chiu's concentric disk mapping
lifted to the hemisphere, so every sample's weight is exactly the
reflectance :math:`\\rho`. Zero below the surface (:math:`\\cos\\theta_i \\le 0`).

Scene keys: ``reflectance`` (RGB in [0, 1], default 0.5 grey). It is the
registry's first kind (id 0): the compiled shading runs its one-point forms
on every lane in its own vectorized loops, and other kinds overwrite their
lanes (:mod:`pyoa.render.compiled.shading`).

References
----------
M. Pharr, W. Jakob, G. Humphreys, "Physically Based Rendering", 3rd ed.,
13.6.2-13.6.3 (concentric disk and cosine-weighted hemisphere sampling).

P. Shirley, K. Chiu, "A Low Distortion Map Between Disk and Square",
Journal of Graphics Tools 2(3), 1997.
"""

from __future__ import annotations

import math

import numpy as np

from ..geometry import concentric_disk as concentric_disk_lanes
from .base import Key, scalar
from .warps import concentric_disk

NAME = "diffuse"
KEYS = (Key("reflectance", (0.5, 0.5, 0.5), lo=0.0, hi=1.0),)
DELTA = False
LANES = True


def params(values: dict) -> tuple[float, ...]:
    """The material table's numbers: the reflectance (r, g, b)."""
    return values["reflectance"]


def sample(p: np.ndarray, wo: np.ndarray, u: np.ndarray, front: np.ndarray):
    """``(wi, weight, pdf, delta)`` for ``(n, 2)`` uniform ``u`` (Malley's
    method): weight :math:`\\rho`, pdf :math:`\\cos\\theta_i / \\pi`, both 0
    where ``wi`` ends on the horizon. ``p``: the ``(n, PARAMS)`` material
    numbers; ``wo``: ``(n, 3)`` with ``wo.z > 0``; ``front`` unused."""
    x, y = concentric_disk_lanes(u).T
    z = np.sqrt(np.maximum(0.0, 1.0 - x * x - y * y))
    d = np.stack([x, y, z], axis=1)
    wi = d / np.linalg.norm(d, axis=1)[:, None]
    above = wi[:, 2] > 0.0
    weight = np.where(above[:, None], p[:, :3], 0.0)
    pdf = np.where(above, wi[:, 2] / np.pi, 0.0)
    return wi, weight, pdf, np.zeros(len(wi), dtype=bool)


def evaluate(p: np.ndarray, wo: np.ndarray, wi: np.ndarray, front: np.ndarray):
    """``(f_cos, pdf)``: :math:`\\rho \\cos\\theta_i / \\pi` and
    :math:`\\cos\\theta_i / \\pi`, 0 where ``wi.z <= 0``."""
    up = wi[:, 2] > 0.0
    c = wi[:, 2] / np.pi
    return np.where(up[:, None], p[:, :3] * c[:, None], 0.0), np.where(up, c, 0.0)


def pdf(p: np.ndarray, wo: np.ndarray, wi: np.ndarray, front: np.ndarray) -> np.ndarray:
    """The density of :func:`sample`'s ``wi``: :math:`\\cos\\theta_i / \\pi` above the surface."""
    return np.where(wi[:, 2] > 0.0, wi[:, 2] / np.pi, 0.0)


@scalar
def sample_point(m0, m1, m2, m3, front, ox, oy, oz, u0, u1):
    """:func:`sample` for one point, free of branches: ``(wi x, y, z, weight
    r, g, b, pdf, delta)``. It normalizes ``wi`` by one reciprocal (the NumPy
    form divides thrice): the same to rounding."""
    x, y = concentric_disk(u0, u1)
    z = math.sqrt(max(0.0, 1.0 - x * x - y * y))
    inv = 1.0 / math.sqrt(x * x + y * y + z * z)
    x, y, z = x * inv, y * inv, z * inv
    up = z > 0.0
    return (x, y, z, m0 if up else 0.0, m1 if up else 0.0, m2 if up else 0.0, z / math.pi if up else 0.0, False)


@scalar
def evaluate_point(m0, m1, m2, m3, front, ox, oy, oz, ix, iy, iz):
    """:func:`evaluate` for one point, free of branches: ``(f_cos r, g, b,
    pdf)``, 0 unless both ``wo`` and ``wi`` lie above the surface."""
    c = iz / math.pi
    lit = oz > 0.0 and iz > 0.0
    return m0 * c if lit else 0.0, m1 * c if lit else 0.0, m2 * c if lit else 0.0, c if lit else 0.0
