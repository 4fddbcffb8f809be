"""A perfect mirror: specular reflection tinted by a colour.

.. math::

    \\omega_i = (-\\omega_{o,x}, -\\omega_{o,y}, \\omega_{o,z}), \\qquad
    \\frac{f \\cos\\theta_i}{p} = \\text{tint}.

A Dirac delta lobe (``DELTA``): it gets no light sample, :func:`sample`
flags its direction as ``delta`` and reports pdf 0 by convention, and
:func:`evaluate` and :func:`pdf` are 0 (no other strategy can hit a delta).

Scene keys: ``tint`` (RGB in [0, 1], default white).

References
----------
M. Pharr, W. Jakob, G. Humphreys, "Physically Based Rendering", 3rd ed.,
8.2 (specular reflection).
"""

from __future__ import annotations

import numpy as np

from .base import Key, scalar

NAME = "mirror"
KEYS = (Key("tint", (1.0, 1.0, 1.0), lo=0.0, hi=1.0),)
DELTA = True
LANES = False


def params(values: dict) -> tuple[float, ...]:
    """The material table's numbers: the tint (r, g, b)."""
    return values["tint"]


def sample(p: np.ndarray, wo: np.ndarray, u: np.ndarray, front: np.ndarray):
    """``(wi, weight, pdf, delta)``: the reflection of ``wo``, weight the
    tint, pdf 0, delta."""
    n = len(wo)
    return wo * np.array([-1.0, -1.0, 1.0]), p[:, :3].copy(), np.zeros(n), np.ones(n, dtype=bool)


def evaluate(p: np.ndarray, wo: np.ndarray, wi: np.ndarray, front: np.ndarray):
    """``(f_cos, pdf)``: 0 (a delta lobe)."""
    return np.zeros((len(wo), 3)), np.zeros(len(wo))


def pdf(p: np.ndarray, wo: np.ndarray, wi: np.ndarray, front: np.ndarray) -> np.ndarray:
    """0 (a delta lobe)."""
    return np.zeros(len(wo))


@scalar
def sample_point(m0, m1, m2, m3, front, ox, oy, oz, u0, u1):
    """:func:`sample` for one point: ``(wi x, y, z, weight r, g, b, pdf, delta)``."""
    return -ox, -oy, oz, m0, m1, m2, 0.0, True


@scalar
def evaluate_point(m0, m1, m2, m3, front, ox, oy, oz, ix, iy, iz):
    """:func:`evaluate` for one point: 0."""
    return 0.0, 0.0, 0.0, 0.0
