"""pyoa's seed hashes over NumPy arrays: the public ones, for renderers and host code.

The integer hashes of docs/spec.md section 3, vectorized (arguments
broadcast; uint32 arithmetic wraps modulo ``2**32`` as the spec requires),
with the same bits as the pure-Python :mod:`pyoa.reference.hashes`. A
renderer derives its own decorrelated random streams from them (pyoa's path
tracer hashes Russian-roulette decisions with :func:`hash_pair`); the
samplers' backends use them for the pixel and block seeds.

Functions
---------
:func:`mix32`
    Wellons' ``lowbias32``: a bijective avalanche hash of a uint32.
:func:`hash_pair`
    ``mix32(b ^ mix32(a ^ key))``, never 0: a hash of two integers under a key.
:func:`pixel_seed`
    The point-set seed of one pixel (docs/spec.md section 3).
:func:`block_seed`
    The seed of one independently randomized copy of an array (section 6;
    the copy's order of the rows is keyed by it too).

Examples
--------
>>> from pyoa.hashes import hash_pair, pixel_seed
>>> int(pixel_seed(0, 1)) == int(hash_pair(0, 1, 0x5BD1E995))
True
"""

from __future__ import annotations

import numpy as np

from .reference.hashes import BLOCK_KEY, PIXEL_KEY

U32 = np.uint32


def _u32(x) -> np.ndarray:
    return np.asarray(x, dtype=U32)


def mix32(x) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.mix32` (Wellons' lowbias32)."""
    x = _u32(x).copy()
    x ^= x >> U32(16)
    x *= U32(0x7FEB352D)
    x ^= x >> U32(15)
    x *= U32(0x846CA68B)
    x ^= x >> U32(16)
    return x


def hash_pair(a, b, key: int) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.hashes.hash_pair` (never 0)."""
    h = mix32(_u32(b) ^ mix32(_u32(a) ^ U32(key)))
    return np.where(h == 0, U32(key), h)


def pixel_seed(seed, pixel) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.pixel_seed`."""
    return hash_pair(seed, pixel, PIXEL_KEY)


def block_seed(p, block) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.block_seed` (block 0 keeps ``p``)."""
    p, block = np.broadcast_arrays(_u32(p), _u32(block))
    return np.where(block == 0, p, hash_pair(p, block, BLOCK_KEY))
