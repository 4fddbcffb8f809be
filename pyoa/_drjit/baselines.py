"""Comparison samplers in Dr.Jit operations (mirrors :mod:`pyoa._numpy.baselines`).

Only ``random`` for now: the others (Sobol', Halton, PMJ02, ...) need
direction-number or point tables and are not ported; :mod:`pyoa._drjit.evaluate`
lists what is supported.
"""

from __future__ import annotations

import drjit as dr

from ..reference.baselines import RANDOM_KEY
from .hashes import hash_pair, mix32


def unit24(h):
    """``(h >> 8) * 2**-24`` as float32 (exact)."""
    F = dr.float32_array_t(type(h))
    return F(h >> 8) * F(2.0**-24)


def random(i, j, p):
    """:func:`pyoa.reference.baselines.random` over Dr.Jit arrays."""
    U = type(i)
    return unit24(mix32(U(i) ^ hash_pair(p, U(j), RANDOM_KEY)))
