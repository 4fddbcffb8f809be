"""What a backend is asked to compute: one validated bulk request.

A request is the product pixels x samples x dims, laid out row-major as
``rows = len(pixels) * len(samples)`` rows of ``len(dims)`` values; row ``r``
is pixel ``pixels[r // len(samples)]``, sample ``samples[r % len(samples)]``.
Backends fill any range of rows, so the same request can be produced in
chunks (OpenCL buffers are limited to 2 GiB) and the chunks concatenate to
the whole.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .entries import Construction
from .params import FaureParams, OAParams, PointSetParams, SequenceParams

#: Most cells (entries per array, each of 4 bytes, twice) the OpenCL table
#: path uploads for dimensions past the first block (:attr:`Request.array_cells_fit`).
MAX_ARRAY_CELLS = 1 << 22


@dataclass(frozen=True)
class Request:
    """One bulk request. The table paths' properties (:attr:`table_entries`
    and the others that read ``s``, ``M``, ``N`` or ``B``) are asked of the
    orthogonal arrays only: :meth:`tables_pay_off` is False without an
    offset style."""

    construction: Construction
    params: OAParams | PointSetParams | SequenceParams | FaureParams
    seed: int
    offset: str
    jitter: float
    pixels: np.ndarray  # uint32
    samples: np.ndarray  # uint32
    dims: np.ndarray  # uint32

    @property
    def n_rows(self) -> int:
        return len(self.pixels) * len(self.samples)

    @property
    def n_dims(self) -> int:
        return len(self.dims)

    @property
    def table_entries(self) -> int:
        """Entries per (pixel, dimension) of the table path: ``s`` stratum
        permutation entries, ``M`` sub-stratum entries (``cmj`` only) and the
        jitter seed (the layout of ``kernels/generate.cl``)."""
        return self.params.s + (self.params.M if self.offset == "cmj" else 0) + 1

    def rectangles(self, row0: int, row1: int) -> list["Rect"]:
        """Rows ``[row0, row1)`` as rectangles of pixels x sample positions.

        A rectangle is either whole pixels (all sample positions) or a run of
        sample positions inside one pixel, so a chunk boundary that falls inside
        a pixel gives at most a head and a tail rectangle around the whole
        pixels. The table path works per rectangle: its kernels index by
        (sample position, pixel and dimension) instead of dividing a flat row
        index (docs/performance.md).
        """
        n_s = len(self.samples)
        rects = []
        r = row0
        while r < row1:
            pix, k = divmod(r, n_s)
            if k or row1 - r < n_s:  # part of one pixel
                r1 = min(row1, (pix + 1) * n_s)
                rects.append(Rect(r, r1, pix, pix + 1, k, k + r1 - r))
            else:
                r1 = r + (row1 - r) // n_s * n_s
                rects.append(Rect(r, r1, pix, r1 // n_s, 0, n_s))
            r = r1
        return rects

    @property
    def past_block0(self) -> bool:
        """Whether a dimension lies past the first block (docs/spec.md section
        6): such a dimension reads its copy at its own rows, which depend on
        the pixel, so the table paths gather its cells at those rows."""
        return self.n_dims > 0 and int(self.dims.max()) >= self.params.B

    @property
    def array_cells_fit(self) -> bool:
        """Whether the OpenCL table path may hold the cells of every row of
        the array in each dimension's column (:func:`pyoa.catalogue.host_tables.array_cells`),
        which it needs for dimensions past the first block: at most
        :data:`MAX_ARRAY_CELLS` entries. Larger requests take the direct path."""
        return not self.past_block0 or self.n_dims * self.params.N <= MAX_ARRAY_CELLS

    @property
    def table_stride(self) -> int:
        """:attr:`table_entries` rounded up to a multiple of 8: the OpenCL
        kernels lay tables out with this stride so that a table is whole
        8-lane vectors (``kernels/generate.cl``)."""
        return -(-self.table_entries // 8) * 8

    def tables_pay_off(self, rect: "Rect") -> bool:
        """Whether rectangle ``rect`` should use the table path.

        The table path (``cmj`` and ``centered`` only) first computes
        :attr:`table_entries` values per (pixel, dimension), then gathers one
        per value. It pays off when a table (with its padding,
        :attr:`table_stride`) is no longer than the rectangle's run of
        samples, i.e. the tables are no larger than the output; the same bound
        keeps the table buffer within the chunk size limits the backends
        already respect.
        """
        return self.offset in ("cmj", "centered") and self.table_stride <= rect.n_k


@dataclass(frozen=True)
class Rect:
    """Rows ``[row0, row1)`` of a request: pixels ``[pix0, pix1)`` x sample
    positions ``[k0, k1)`` (see :meth:`Request.rectangles`)."""

    row0: int
    row1: int
    pix0: int
    pix1: int
    k0: int
    k1: int

    @property
    def n_k(self) -> int:
        return self.k1 - self.k0

    @property
    def n_pixels(self) -> int:
        return self.pix1 - self.pix0
