"""The integer hashes of docs/spec.md sections 2 and 3 and the block rule of
section 6 in Dr.Jit operations: :mod:`pyoa._arrays.hashes` and
:mod:`pyoa._arrays.blocks` bound to :mod:`.ops`.

Functions take ``UInt32`` arrays (Python ints broadcast with them); ``l``,
``N`` and ``B`` are Python ints, fixed when the code is traced.
"""

from __future__ import annotations

from .._arrays import bind, blocks, hashes
from . import ops

mix32 = bind(ops, hashes.mix32)
hash_pair = bind(ops, hashes.hash_pair)
pixel_seed = bind(ops, hashes.pixel_seed)
derived_seed = bind(ops, hashes.derived_seed)
permute = bind(ops, hashes.permute)
permutes = bind(ops, hashes.permutes)
randfloat = bind(ops, hashes.randfloat)

block_seed = bind(ops, blocks.block_seed)
block_order_seed = bind(ops, blocks.block_order_seed)
block_row = bind(ops, blocks.block_row)
locate_block = bind(ops, blocks.locate_block)
locate = bind(ops, blocks.locate)
