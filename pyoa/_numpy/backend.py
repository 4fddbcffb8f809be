"""The NumPy backend: the CPU fallback used when no OpenCL device is usable."""

from __future__ import annotations

import numpy as np

from ..request import Request
from . import oa
from .hashes import pixel_seed

#: Values per chunk: bounds the temporaries (about 20 arrays of this size).
CHUNK_VALUES = 1 << 20


class NumpyBackend:
    """Vectorized evaluation of :mod:`pyoa._numpy.oa`; stateless, so thread-safe."""

    name = "numpy"

    def describe(self) -> str:
        return f"NumPy {np.__version__} on the CPU"

    def rows_per_chunk(self, n_dims: int) -> int:
        return max(1, CHUNK_VALUES // max(1, n_dims))

    def fill(self, req: Request, row0: int, row1: int, out: np.ndarray) -> None:
        """Write rows ``[row0, row1)`` of ``req`` into ``out`` (shape ``(row1-row0, n_dims)``)."""
        rows = np.arange(row0, row1, dtype=np.int64)
        n_s = len(req.samples)
        p = pixel_seed(req.seed, req.pixels[rows // n_s])[:, None]
        i = req.samples[rows % n_s][:, None]
        j = req.dims[None, :]
        prm = req.params
        if req.construction.name == "bose":
            out[...] = oa.bose(i, j, prm.s, p, req.offset, req.jitter)
        else:
            out[...] = oa.cmjnd(i, j, prm.s, prm.strength, p, req.offset, req.jitter)
