"""The Owen-scrambled Faure sequence in Dr.Jit operations: :mod:`pyoa._arrays.faure` bound to :mod:`.ops`.

The dimension ``j`` is an array whose block may differ per lane (inside
Mitsuba it is the sampler's dimension counter), so every lane takes the
copies' path (all index digits, the index scramble; see the generic module).
"""

from __future__ import annotations

from .._arrays import bind, faure as generic
from . import ops

faure = bind(ops, generic.faure)
