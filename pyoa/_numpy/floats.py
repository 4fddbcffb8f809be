"""Float32 rules of SPEC section 7 over NumPy arrays (mirrors :mod:`pyoa.reference.floats`).

NumPy evaluates float32 array arithmetic one correctly rounded operation at a
time and never fuses a multiply and an add, which is what the spec asks.
"""

from __future__ import annotations

import numpy as np

from ..reference.floats import ONE_MINUS_ULP

F32 = np.float32
_ONE_MINUS_ULP = F32(ONE_MINUS_ULP)


def sample_value(stratum, sub, jitter, M: int, s: int) -> np.ndarray:
    """``(stratum + (sub + jitter) / M) / s`` in float32, clamped below 1."""
    x = (np.asarray(stratum).astype(F32) + (np.asarray(sub, dtype=F32) + jitter) / F32(M)) / F32(s)
    return np.minimum(x, _ONE_MINUS_ULP)


def jitter_value(r, amount: np.float32) -> np.ndarray:
    """``0.5 + J * (r - 0.5)`` in float32."""
    return F32(0.5) + F32(amount) * (r - F32(0.5))
