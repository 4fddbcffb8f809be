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

# One implementation: the generic hashes of pyoa._arrays, bound to NumPy.
from ._numpy.hashes import U32, block_seed, hash_pair, mix32, pixel_seed  # noqa: F401
