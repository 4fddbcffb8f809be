"""The NumPy backend: the CPU fallback used when no OpenCL device is usable.

Like the OpenCL backend it has two paths with the same bits: every value
from scratch (:func:`.oa.bose`, :func:`.oa.cmjnd`), or, for ``cmj`` and
``centered``, the permutations that do not depend on the sample computed once
per (pixel, dimension) as tables and gathered (a block past the first,
docs/spec.md section 6, at every row of its array and then gathered at the
pixel's rows: :meth:`NumpyBackend._tabled`).
"""

from __future__ import annotations

import numpy as np

from ..catalogue import host_tables
from ..reference.hashes import JITTER_KEY, STRATUM_KEY, SUBSTRATUM_KEY
from ..catalogue.request import Rect, Request
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
                # A rectangle's rows are (pixel, sample) in row-major order, so
                # a C-contiguous view is already its (pixels, samples, dims) cube.
                shape = (rect.n_pixels, rect.n_k, req.n_dims)
                cube = view.reshape(shape) if view.flags.c_contiguous else np.empty(shape, dtype=F32)
                self._tabled(req, rect, cube)
                if not view.flags.c_contiguous:
                    view[...] = cube.reshape(view.shape)
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
    def _tabled(req: Request, rect: Rect, out: np.ndarray) -> None:
        """Write the values of ``rect`` into ``out``, shape ``(pixels, samples,
        dims)``: the per-(pixel, dimension) permutations computed once
        (:meth:`_tables`), the cells once per block, then one gather per
        value (:meth:`_values_at`).

        Block 0 reads row ``i``, so its cells do not depend on the pixel
        (:func:`pyoa.catalogue.host_tables.cells`). A later block ``b`` reads its copy
        at row ``block_row(i, N, r_b)`` (docs/spec.md section 6), a
        different row per pixel. Where the rectangle holds at least ``N``
        samples per pixel, such a block is evaluated in row space: its values
        at every row ``0..N-1`` of the array, whose cells depend on the
        column only (:func:`pyoa.catalogue.host_tables.array_cells`), then gathered
        along the sample axis at each pixel's rows. That is block 0's work
        plus the rows and one gather, and never more values than the
        rectangle holds. A shorter run of samples (a subset of them, or the
        head or tail of a pixel split by a chunk) computes the cells at its
        own rows instead, per (pixel, sample, dimension), so that it
        evaluates no row it does not need.
        """
        prm = req.params
        N = prm.N
        blocks, which, seeds, orders = host_tables.block_seeds(req, rect.pix0, rect.pix1)
        col = req.dims % U32(prm.B)
        tables = NumpyBackend._tables(req, seeds[:, which] * (col + U32(1)))  # from the column keys
        i = req.samples[rect.k0 : rect.k1]
        first = int(blocks.size > 0 and blocks[0] == 0)  # the index of the first later block
        if blocks.size > first:
            # The rows of every later block, in one pair of permutes (a call
            # costs a cycle walk's loop whatever its size): (pixels, later
            # blocks, samples).
            rows = oa.block_row(i, N, orders[:, first:, None])
        # Samples are below N (spp is N), so every row a later block reads is
        # one of the N of row space; with at least N samples per pixel, row
        # space evaluates no more values than the rectangle holds.
        row_space = rect.n_k >= N and blocks.size > first
        if row_space:
            every = np.arange(N, dtype=U32)
            array_aij, array_u = host_tables.array_cells(req)  # (dims, N)
            # A (pixels * N, dims) view of a block's row-space values has the
            # values of (pixel, row r) in row pixel * N + r.
            base = np.arange(rect.n_pixels, dtype=np.intp)[:, None] * N
        for b, block in enumerate(blocks):
            d = np.flatnonzero(which == b)
            at = tuple(None if t is None else t[:, d] for t in tables)  # the block's dims' tables
            # A block's dimensions are usually a run of the request's; writing
            # a slice of out is several times faster than through an index
            # array (which dimensions interleaved across blocks need).
            run = slice(d[0], d[-1] + 1) if d[-1] - d[0] + 1 == d.size else d
            if block == 0:
                aij, u = host_tables.cells(req, rect.k0, rect.k1)
                out[..., run] = NumpyBackend._values_at(req, i, aij[d], u[d], at)
            elif row_space:
                vals = NumpyBackend._values_at(req, every, array_aij[d], array_u[d], at)
                # The gather copies whole rows of the block's dims. (The
                # indices are in range: mode="clip" spares a bounds check.)
                out[..., run] = np.take(vals.reshape(-1, d.size), base + rows[:, b - first], axis=0, mode="clip")
            else:
                r = rows[:, b - first, :, None]  # (pixels, samples, 1)
                aij, u = req.construction.cells(r, col[d], prm)  # (pixels, samples, the block's dims)
                out[..., run] = NumpyBackend._values_at(req, r, aij, u, at)

    @staticmethod
    def _tables(req: Request, q: np.ndarray) -> tuple[np.ndarray, np.ndarray | None, np.ndarray]:
        """What the table path computes once per (pixel, dimension).

        Parameters
        ----------
        req : Request
            The request (``cmj`` or ``centered``).
        q : numpy.ndarray
            The uint32 column keys ``P * (col + 1)``, shape ``(pixels, dims)``,
            ``P`` the seed of the dimension's block (docs/spec.md section 3.3).

        Returns
        -------
        strata : numpy.ndarray
            uint32 ``(pixels, dims, s)``: the stratum permutation of each column.
        subs : numpy.ndarray or None
            uint32 ``(pixels, dims, M)``: the sub-stratum permutation (``cmj``;
            None for ``centered``).
        jitter_keys : numpy.ndarray
            uint32 ``(pixels, dims)``: the jitter seed of each column.

        Notes
        -----
        Each table is one :func:`permute` call over every dimension of the
        request, whatever their blocks: its cycle walk loops over tiny arrays
        when the rectangle is small, so fewer calls cost less.
        """
        prm = req.params
        strata = permute(np.arange(prm.s, dtype=U32), prm.s, (q * U32(STRATUM_KEY))[..., None])
        subs = None
        if req.offset == "cmj":
            subs = permute(np.arange(prm.M, dtype=U32), prm.M, (q * U32(SUBSTRATUM_KEY))[..., None])
        return strata, subs, q * U32(JITTER_KEY)

    @staticmethod
    def _values_at(req: Request, rows: np.ndarray, aij: np.ndarray, u: np.ndarray, tables: tuple) -> np.ndarray:
        """The table path's values of some dimensions of a request at given rows.

        Parameters
        ----------
        req : Request
            The request (its offset, jitter and geometry; ``cmj`` or ``centered``).
        rows : numpy.ndarray
            The uint32 rows of the array the values read (docs/spec.md section
            6): either one run of rows shared by every pixel and dimension,
            shape ``(n_rows,)`` (block 0's samples, or every row ``0..N-1``
            of a later block in row space), or rows per (pixel, row, dimension)
            broadcastable to ``(pixels, n_rows, dims)`` (a later block's own
            rows).
        aij, u : numpy.ndarray
            The cells ``A_ij`` and sub-stratum indices of those rows in the
            dimensions' columns: shape ``(dims, n_rows)`` for a shared run of
            rows (:func:`pyoa.catalogue.host_tables.cells` and ``array_cells``' layout),
            else broadcastable to ``(pixels, n_rows, dims)``. ``u`` is unused
            for ``centered``.
        tables : tuple
            :meth:`_tables` of these dimensions.

        Returns
        -------
        numpy.ndarray
            C-contiguous float32 values of shape ``(pixels, n_rows, dims)``.

        Notes
        -----
        Every operand is laid out (pixels, rows, dims), dimensions fastest, so
        that the gathers and the float arithmetic run over memory in order
        and the result is C-contiguous (:meth:`_tabled` gathers rows of it).
        """
        prm = req.params
        strata, subs, jitter_keys = tables
        shared = rows.ndim == 1
        if shared:  # one run of rows: to (1, rows, 1), against the keys' (pixels, 1, dims)
            rows = rows[None, :, None]
        stratum = NumpyBackend._gather(strata, aij, shared)
        sub = F32((prm.M - 1) / 2) if subs is None else NumpyBackend._gather(subs, u, shared)
        jitter = jitter_value(randfloat(rows, jitter_keys[:, None, :]), F32(req.jitter))
        return np.ascontiguousarray(sample_value(stratum, sub, jitter, prm.M, prm.s))

    @staticmethod
    def _gather(table: np.ndarray, cell: np.ndarray, shared: bool) -> np.ndarray:
        """``table[pixel, d, cell]`` for every (pixel, row, dimension ``d``).

        Parameters
        ----------
        table : numpy.ndarray
            Per (pixel, dimension) tables, shape ``(pixels, dims, n)``.
        cell : numpy.ndarray
            Entries to read: shape ``(dims, rows)`` if ``shared``, else
            broadcastable to ``(pixels, rows, dims)``.
        shared : bool
            Whether every pixel reads the same entries (:meth:`_values_at`'s
            shared run of rows).

        Returns
        -------
        numpy.ndarray
            uint32 of shape ``(pixels, rows, dims)`` (C-contiguous if ``shared``).

        Notes
        -----
        Shared entries are one flat index per (row, dimension) into each
        pixel's tables, and a single ``np.take`` along that axis: several
        times faster than indexing with three broadcast index arrays, which
        NumPy walks per value.
        """
        n_p, n_d, n = table.shape
        if shared:
            at = cell.T + np.arange(n_d, dtype=np.intp) * n  # (rows, dims), intp
            return np.take(table.reshape(n_p, n_d * n), at, axis=1)
        return table[np.arange(n_p)[:, None, None], np.arange(n_d), cell]
