"""Small vectorized vector helpers: orthonormal frames and sampling warps."""

from __future__ import annotations

import numpy as np


def normalize(v: np.ndarray) -> np.ndarray:
    """Rows of ``v`` scaled to unit length (rows of zeros stay zero)."""
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 0, n, 1.0)


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot product."""
    return np.einsum("ij,ij->i", a, b)


def frame(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tangents ``(t, b)`` completing unit normals ``n`` to orthonormal frames.

    The branch-free construction of Duff et al., "Building an Orthonormal
    Basis, Revisited", JCGT 6(1), 2017.
    """
    sign = np.where(n[:, 2] >= 0, 1.0, -1.0)
    a = -1.0 / (sign + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t = np.stack([1.0 + sign * n[:, 0] ** 2 * a, sign * b, -sign * n[:, 0]], axis=1)
    bt = np.stack([b, sign + n[:, 1] ** 2 * a, -n[:, 1]], axis=1)
    return t, bt


def to_local(v, t, b, n) -> np.ndarray:
    """World vectors ``v`` in the frames ``(t, b, n)``."""
    return np.stack([dot(v, t), dot(v, b), dot(v, n)], axis=1)


def to_world(v, t, b, n) -> np.ndarray:
    """Local vectors ``v`` of the frames ``(t, b, n)`` in world space."""
    return v[:, :1] * t + v[:, 1:2] * b + v[:, 2:3] * n


def concentric_disk(u: np.ndarray) -> np.ndarray:
    """Shirley and Chiu's concentric map of ``[0,1)^2`` onto the unit disk
    (area-preserving and continuous, so stratification carries over)."""
    a = 2.0 * u[:, 0] - 1.0
    b = 2.0 * u[:, 1] - 1.0
    first = np.abs(a) > np.abs(b)
    safe_a = np.where(a == 0, 1.0, a)
    safe_b = np.where(b == 0, 1.0, b)
    r = np.where(first, a, b)
    phi = np.where(first, (np.pi / 4) * (b / safe_a), np.pi / 2 - (np.pi / 4) * (a / safe_b))
    phi = np.where((a == 0) & (b == 0), 0.0, phi)
    return np.stack([r * np.cos(phi), r * np.sin(phi)], axis=1)


def triangle_point(u: np.ndarray) -> np.ndarray:
    """Barycentric weights ``(w0, w1, w2)`` of a uniform point in a triangle
    from ``u`` in ``[0,1)^2`` (the square-root warp, PBR book 13.6.4)."""
    su = np.sqrt(u[:, 0])
    w1 = u[:, 1] * su
    w0 = 1.0 - su
    return np.stack([w0, w1, 1.0 - w0 - w1], axis=1)
