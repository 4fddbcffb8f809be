"""The orthogonal-array samplers over NumPy arrays: :mod:`pyoa._arrays.oa`
and the block rule of :mod:`pyoa._arrays.blocks`, bound to :mod:`.ops`.

The pieces (block rule, cells, field) are public to this package because
the NumPy backend's table path (:mod:`.backend`) and the host tables
(:mod:`pyoa.catalogue.host_tables`) reuse them.
"""

from __future__ import annotations

from .._arrays import bind, blocks, oa
from . import ops

locate = bind(ops, blocks.locate)
block_row = bind(ops, blocks.block_row)
block_order_seed = bind(ops, blocks.block_order_seed)

Field = bind(ops, oa.Field)
field = bind(ops, oa.field)
bose_cell = bind(ops, oa.bose_cell)
bush_cell = bind(ops, oa.bush_cell)
cmjnd_cell = bind(ops, oa.cmjnd_cell)
addelman_kempthorne_cell = bind(ops, oa.addelman_kempthorne_cell)
bose_bush_cell = bind(ops, oa.bose_bush_cell)

bose = bind(ops, oa.bose)
bush = bind(ops, oa.bush)
cmjnd = bind(ops, oa.cmjnd)
addelman_kempthorne = bind(ops, oa.addelman_kempthorne)
bose_bush = bind(ops, oa.bose_bush)
