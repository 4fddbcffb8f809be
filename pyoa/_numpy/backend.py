"""The NumPy backend: the CPU fallback used when no OpenCL device is usable.

Like the OpenCL backend it has two paths with the same bits: every value
from scratch (:func:`.oa.bose`, :func:`.oa.cmjnd`), or, for ``cmj`` and
``centered``, the permutations that do not depend on the sample computed once
per (pixel, dimension) as tables and gathered.
"""

from __future__ import annotations

import numpy as np

from ..reference.hashes import JITTER_KEY, STRATUM_KEY, SUBSTRATUM_KEY
from ..request import Request
from . import oa
from .floats import F32
from .hashes import U32, permute, pixel_seed

#: Values per chunk: bounds the temporaries (about 20 arrays of this size).
CHUNK_VALUES = 1 << 20


class NumpyBackend:
    """Vectorized evaluation of :mod:`pyoa._numpy.oa`; stateless, so thread-safe."""

    name = "numpy"
    #: Sampler.generate may call fill on several chunks at once (one per core).
    parallel_chunks = True

    def describe(self) -> str:
        return f"NumPy {np.__version__} on the CPU"

    def rows_per_chunk(self, n_dims: int) -> int:
        return max(1, CHUNK_VALUES // max(1, n_dims))

    def fill(self, req: Request, row0: int, row1: int, out: np.ndarray) -> None:
        """Write rows ``[row0, row1)`` of ``req`` into ``out`` (shape ``(row1-row0, n_dims)``)."""
        rows = np.arange(row0, row1, dtype=np.int64)
        n_s = len(req.samples)
        prm = req.params
        i = req.samples[rows % n_s][:, None]
        if req.tables_pay_off(row0, row1):
            out[...] = self._tabled(req, rows, i)
            return
        p = pixel_seed(req.seed, req.pixels[rows // n_s])[:, None]
        out[...] = req.construction.call("pyoa._numpy", i, req.dims[None, :], prm, p, req.offset, req.jitter)

    @staticmethod
    def _tabled(req: Request, rows: np.ndarray, i: np.ndarray) -> np.ndarray:
        prm = req.params
        s, M, dmax = prm.s, prm.M, prm.block_dims
        n_s = len(req.samples)
        pix0 = rows[0] // n_s
        local = (rows // n_s - pix0)[:, None]  # pixel of each row, within this chunk
        q = oa.column_key(pixel_seed(req.seed, req.pixels[pix0 : rows[-1] // n_s + 1])[:, None], req.dims[None, :], dmax)
        strata = permute(np.arange(s, dtype=U32), s, (q * U32(STRATUM_KEY))[..., None])
        col = (req.dims % U32(dmax))[None, :]
        d = np.arange(req.n_dims)[None, :]
        aij, u = {
            "bose": lambda: oa.bose_cell(i, col, s),
            "bush": lambda: oa.bush_cell(i, col, s, prm.strength),
            "cmjnd": lambda: oa.cmjnd_cell(i, col, s),
            "addelman-kempthorne": lambda: oa.addelman_kempthorne_cell(i, col, s),
            "bose-bush": lambda: oa.bose_bush_cell(i, col, s),
        }[req.construction.name]()
        if req.offset == "cmj":
            subs = permute(np.arange(M, dtype=U32), M, (q * U32(SUBSTRATUM_KEY))[..., None])
            sub = subs[local, d, u].astype(F32)
        else:
            sub = F32((M - 1) / 2)
        return oa.oa_value(i, strata[local, d, aij], sub, (q * U32(JITTER_KEY))[local, d], M, s, req.jitter)
