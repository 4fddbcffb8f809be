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

from .constructions import Construction, Params


@dataclass(frozen=True)
class Request:
    construction: Construction
    params: Params
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

    def tables_pay_off(self, row0: int, row1: int) -> bool:
        """Whether rows ``[row0, row1)`` should use the table path.

        The table path (``cmj`` and ``centered`` only) first computes
        :attr:`table_entries` values per (pixel, dimension) for every pixel the
        rows touch, then gathers. It pays off when that table is no larger than the
        chunk's output; the same bound keeps the table buffer within the
        chunk size limits the backends already respect.
        """
        if self.offset not in ("cmj", "centered") or row1 <= row0:
            return False
        n_s = len(self.samples)
        n_pixels = (row1 - 1) // n_s - row0 // n_s + 1
        return n_pixels * self.table_entries <= row1 - row0
