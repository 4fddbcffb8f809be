"""The integer hashes of docs/spec.md sections 2 and 3 over NumPy uint32 arrays:
:mod:`pyoa._arrays.hashes` (and the block seed of :mod:`pyoa._arrays.blocks`)
bound to :mod:`.ops`. Arguments broadcast.
"""

from __future__ import annotations

import numpy as np

from .._arrays import bind, blocks, hashes
from . import ops

U32 = np.uint32

mix32 = bind(ops, hashes.mix32)
hash_pair = bind(ops, hashes.hash_pair)
pixel_seed = bind(ops, hashes.pixel_seed)
derived_seed = bind(ops, hashes.derived_seed)
dimension_seeds = bind(ops, hashes.dimension_seeds)
permute_round = bind(ops, hashes.permute_round)
permute = bind(ops, hashes.permute)
randfloat = bind(ops, hashes.randfloat)
block_seed = bind(ops, blocks.block_seed)
