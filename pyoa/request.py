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
