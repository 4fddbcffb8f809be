"""The pure-Python reference of pyoa: the oracle every backend is tested against.

Scalar, one value at a time, written to be read next to ``docs/spec.md``. It is
slow by design; use :func:`pyoa.sampler` for bulk generation.

Public functions: :func:`permute`, :func:`randfloat`, :func:`pixel_seed`,
:func:`block_seed`, :func:`bose`, :func:`bush`, :func:`cmjnd`,
:func:`addelman_kempthorne`, :func:`bose_bush`; the comparison samplers are
in :mod:`pyoa.reference.baselines`.
"""

from .hashes import block_seed, dimension_seeds, mix32, permute, pixel_seed, randfloat
from .oa import addelman_kempthorne, bose, bose_bush, bush, cmjnd

__all__ = ["permute", "randfloat", "pixel_seed", "block_seed", "dimension_seeds", "mix32", "bose", "bush", "cmjnd", "addelman_kempthorne", "bose_bush"]
