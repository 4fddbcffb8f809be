"""The NumPy backend: the CPU fallback used when no OpenCL device is usable.

Like the OpenCL backend it has two paths with the same bits: every value
from scratch (:func:`.oa.bose`, :func:`.oa.cmjnd`), or, for ``cmj`` and
``centered``, the permutations that do not depend on the sample computed once
per (pixel, dimension) as tables and gathered.
"""

from __future__ import annotations

import numpy as np

from .. import host_tables
from ..reference.hashes import JITTER_KEY, STRATUM_KEY, SUBSTRATUM_KEY
from ..request import Rect, Request
from . import oa
from .floats import F32, jitter_value, sample_value
from .hashes import U32, permute, randfloat

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
        for rect in req.rectangles(row0, row1):
            view = out[rect.row0 - row0 : rect.row1 - row0]
            if req.tables_pay_off(rect):
                view[...] = self._tabled(req, rect).reshape(view.shape)
            else:
                self._direct(req, rect, view)

    @staticmethod
    def _direct(req: Request, rect: Rect, out: np.ndarray) -> None:
        rows = np.arange(rect.row0, rect.row1, dtype=np.int64)
        n_s = len(req.samples)
        i = req.samples[rows % n_s][:, None]
        pixel = req.pixels[rows // n_s][:, None]
        out[...] = req.construction.evaluate("numpy", i, req.dims[None, :], req.params, req.seed, pixel,
                                             req.offset, req.jitter)

    @staticmethod
    def _tabled(req: Request, rect: Rect) -> np.ndarray:
        """Values of ``rect`` as ``(pixels, samples, dims)``: the per-(pixel,
        dimension) permutations computed once, the cells once (block 0's do
        not depend on the pixel, :func:`pyoa.host_tables.cells`; a later
        block's are read at its own rows, docs/spec.md section 6), then one
        gather per value."""
        prm = req.params
        s, M, N = prm.s, prm.M, prm.s * prm.M
        blocks, which, seeds, orders = host_tables.block_seeds(req, rect.pix0, rect.pix1)
        col = req.dims % U32(prm.block_dims)
        q = seeds[:, which] * (col + U32(1))  # (pixels, dims): the column keys
        i = req.samples[rect.k0 : rect.k1]
        n_p, n_k = rect.n_pixels, rect.n_k
        rows = i[None, :, None]  # block 0: the samples themselves, for every pixel
        aij, u = (c.T[None] for c in host_tables.cells(req, rect.k0, rect.k1))
        if blocks.size and blocks[-1] != 0:  # a later block: its rows and cells depend on the pixel
            rows = np.broadcast_to(rows, (n_p, n_k, req.n_dims)).copy()
            aij, u = (np.broadcast_to(c, rows.shape).copy() for c in (aij, u))
        for b, block in enumerate(blocks):
            if block == 0:
                continue
            d = np.flatnonzero(which == b)
            r = oa.block_row(i[None, :], N, orders[:, b, None])[..., None]  # (pixels, samples, 1): the block's rows
            rows[..., d] = r
            aij[..., d], u[..., d] = req.construction.cells(r, col[d][None, None, :], prm)
        d = np.arange(req.n_dims)
        pl = np.arange(n_p)[:, None, None]
        strata = permute(np.arange(s, dtype=U32), s, (q * U32(STRATUM_KEY))[..., None])  # (pixels, dims, s)
        stratum = strata[pl, d, aij]
        if req.offset == "cmj":
            subs = permute(np.arange(M, dtype=U32), M, (q * U32(SUBSTRATUM_KEY))[..., None])
            sub = subs[pl, d, u]
        else:
            sub = F32((M - 1) / 2)
        return sample_value(stratum, sub, jitter_value(randfloat(rows, (q * U32(JITTER_KEY))[:, None, :]),
                                                       F32(req.jitter)), M, s)
