"""``zfaure`` in Dr.Jit operations: :mod:`pyoa._arrays.zfaure` bound to :mod:`.ops`.

The pixel is the image's row-major index (``x = pixel % width``); inside
Mitsuba the plugin derives it from the lane and the film
(:mod:`pyoa.mitsuba`). As for :mod:`.faure`, the dimension is an array whose
block may differ per lane, so every lane takes the copies' path (the chained
index scramble, computed and selected away where the block is 0).
"""

from __future__ import annotations

from .._arrays import bind, zfaure as generic
from . import ops

zfaure = bind(ops, generic.zfaure)
