"""The orthogonal-array samplers in Dr.Jit operations: :mod:`pyoa._arrays.oa` bound to :mod:`.ops`.

Each sampler takes ``UInt32`` arrays of sample indices ``i``, dimensions
``j`` (any ``j >= 0``; blocks per docs/spec.md section 6) and array seeds
``p``; its shape (``s``, ``t``), offset style and jitter amount are Python
values fixed when the code is traced. Values are ``Float32`` arrays of the
same backend. ``located=(P, row)`` hands over the block rule's result for a
caller that keeps it per block (:func:`pyoa._arrays.oa.oa_value`, :mod:`pyoa.mitsuba`).
"""

from __future__ import annotations

from .._arrays import bind, oa
from . import ops

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
