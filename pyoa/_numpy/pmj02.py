"""pmj02 over NumPy arrays (mirrors :func:`pyoa.reference.pmj02.pmj02`
operation for operation, and ``kernels/pmj02.cl``).

Arguments broadcast: sample indices ``i``, dimensions ``j`` and seeds ``p``
are uint32 arrays; parameters assumed valid (``i < 2**log2n <= 2**16``).
"""

from __future__ import annotations

import numpy as np

from ..reference.pmj02 import PMJ02_KEY, PMJ02_SHIFT_KEY
from .baselines import derived_seed
from .floats import F32
from .hashes import U32

_UNIT24 = F32(2.0**-24)


def pmj02(i, j, log2n: int, p) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.pmj02.pmj02`: float32 values ``k * 2**-24``.

    ``h = derived_seed(p, j >> 1, PMJ02_KEY)`` picks the set ``h >> 28`` of
    :func:`pyoa.pmj02_tables.tables` and seeds the 24-bit digital shift
    ``derived_seed(h, 1 + (j & 1), PMJ02_SHIFT_KEY) >> 8`` of coordinate
    ``j & 1``; the sample index is not shuffled, so ``log2n`` (the caller's
    bound on ``i``) does not enter the values.
    """
    from ..pmj02_tables import tables

    i, j, p = np.broadcast_arrays(np.asarray(i, dtype=U32), np.asarray(j, dtype=U32), np.asarray(p, dtype=U32))
    c = j & U32(1)
    h = derived_seed(p, j >> U32(1), PMJ02_KEY)
    shift = derived_seed(h, U32(1) + c, PMJ02_SHIFT_KEY) >> U32(8)
    k = tables()[h >> U32(28), i, c]
    return np.asarray((k ^ shift).astype(F32) * _UNIT24)
