"""The float32 rules of docs/spec.md section 7 over NumPy arrays:
:mod:`pyoa._arrays.floats` bound to :mod:`.ops`.
"""

from __future__ import annotations

import numpy as np

from .._arrays import bind, floats
from . import ops

F32 = np.float32

cell_floor = bind(ops, floats.cell_floor)
cell_clamp = bind(ops, floats.cell_clamp)
sample_value = bind(ops, floats.sample_value)
jitter_value = bind(ops, floats.jitter_value)
