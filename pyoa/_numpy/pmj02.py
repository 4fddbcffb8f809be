"""pmj02 over NumPy arrays (mirrors :func:`pyoa.reference.pmj02.pmj02`
operation for operation, and ``kernels/include/pyoa/pmj02.h``).

Arguments broadcast: sample indices ``i``, dimensions ``j`` and seeds ``p``
are uint32 arrays; parameters assumed valid (``i < 2**log2n <= 2**16``).
"""

from __future__ import annotations

import numpy as np

from ..reference.pmj02 import PMJ02_KEY, PMJ02_SHIFT_KEY, POINTS
from .baselines import derived_seed, owen_scramble
from .floats import F32
from .hashes import U32

_UNIT24 = F32(2.0**-24)


def pmj02(i, j, log2n: int, p) -> np.ndarray:
    """Vectorized :func:`pyoa.reference.pmj02.pmj02`: float32 values ``k * 2**-24``.

    ``h = derived_seed(p, j >> 1, PMJ02_KEY)`` picks the set ``h >> 28`` of
    :func:`pyoa.tables.pmj02.tables` and seeds the 24-bit digital shift
    ``derived_seed(h, 1 + (j & 1), PMJ02_SHIFT_KEY) >> 8`` of coordinate
    ``j & 1``; the sample index is Owen-scrambled within the whole set (seed
    ``derived_seed(h, 0, PMJ02_SHIFT_KEY)``), not within ``N``, so ``log2n``
    (the caller's bound on ``i``) does not enter the values.
    """
    from ..tables.pmj02 import tables

    # at least 1-D: NumPy's uint32 scalars warn on the wrap-around the hashes rely on
    i, j, p = np.broadcast_arrays(np.asarray(i, dtype=U32), np.asarray(j, dtype=U32), np.asarray(p, dtype=U32))
    shape = i.shape
    i, j, p = (np.atleast_1d(a) for a in (i, j, p))
    c = j & U32(1)
    h = derived_seed(p, j >> U32(1), PMJ02_KEY)
    shift = derived_seed(h, U32(1) + c, PMJ02_SHIFT_KEY) >> U32(8)
    g = owen_scramble(i, derived_seed(h, U32(0), PMJ02_SHIFT_KEY)) & U32(POINTS - 1)
    k = tables()[h >> U32(28), g, c]
    return np.asarray((k ^ shift).astype(F32) * _UNIT24).reshape(shape)
