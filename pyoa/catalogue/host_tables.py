"""Host-side tables of the orthogonal arrays' table paths, shared by the backends.

The table paths (NumPy's and the OpenCL kernels' ``generate_cells`` and
vector path) split an OA value into what depends on the sample only (its cell
``A_ij`` and sub-stratum index ``u``, :func:`cells`), on the (pixel,
dimension) only (the column key and the permutation shifts,
:func:`column_keys`, :func:`table_keys`), and one gather per value. Both are
computed here, on the host, once per rectangle of a request
(:meth:`pyoa.catalogue.request.Request.rectangles`).
"""

from __future__ import annotations

import numpy as np

from .._numpy.oa import block_order_seed
from ..hashes import U32, block_seed, pixel_seed
from ..reference.hashes import STRATUM_KEY, SUBSTRATUM_KEY


def cells(req, k0: int, k1: int) -> tuple[np.ndarray, np.ndarray]:
    """``(A_ij, u)`` of sample positions ``[k0, k1)`` of request ``req`` in each
    of its dimensions, read at row ``i`` (the rows of block 0; later blocks
    read their own rows, docs/spec.md section 6, and their cells come from
    :func:`array_cells`): two C-contiguous uint32 arrays of shape
    ``(n_dims, k1 - k0)``.

    A block-0 cell depends on the sample and the column only, not on the pixel, so the
    table path computes it once per rectangle of pixels x samples and gathers
    the pixel's permutations with it (both backends; the OpenCL kernel
    ``generate_cells`` reads exactly these arrays, and the vector path of
    :mod:`pyoa._opencl.vector` the same, padded), from the entry's NumPy
    cell function (:meth:`pyoa.catalogue.constructions._OA.cells`). ``u`` is 0 for the
    ``centered`` offset, which has no sub-stratum.
    """
    return _cells_at(req, req.samples[k0:k1])


def array_cells(req) -> tuple[np.ndarray, np.ndarray]:
    """``(A_ij, u)`` of every row ``0..N-1`` of the array in each requested
    dimension's column: two C-contiguous uint32 arrays of shape
    ``(n_dims, N)``, laid out ``[d][row]``. The table paths gather from them
    at a later block's own rows (docs/spec.md section 6). ``u`` is 0 for the
    ``centered`` offset."""
    return _cells_at(req, np.arange(req.params.N, dtype=U32))


def _cells_at(req, rows) -> tuple[np.ndarray, np.ndarray]:
    """``(A_ij, u)`` of ``rows`` in each requested dimension's column, shape
    ``(n_dims, len(rows))``, C-contiguous uint32; ``u`` is 0 for ``centered``."""
    col = (req.dims % U32(req.params.B))[:, None]
    aij, u = req.construction.cells(np.asarray(rows, dtype=U32)[None, :], col, req.params)
    shape = (req.n_dims, len(rows))
    aij = np.ascontiguousarray(np.broadcast_to(aij, shape), dtype=U32)
    if req.offset == "centered":
        return aij, np.zeros(shape, U32)
    return aij, np.ascontiguousarray(np.broadcast_to(u, shape), dtype=U32)


def block_seeds(req, pix0: int, pix1: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The block rule's per-pixel part (docs/spec.md section 6) for pixels
    ``[pix0, pix1)`` of request ``req``: ``(blocks, which, seeds, orders)``.

    ``blocks`` are the distinct blocks the request's dimensions fall in
    (sorted), ``which[d]`` the index into ``blocks`` of dimension ``d``;
    ``seeds`` and ``orders``, shape ``(pixels, len(blocks))``, are each
    block's array seed ``block_seed(p, b)`` and the seed of its sample order
    ``block_order_seed(P, b, N)`` (0 for block 0). They are hashed once per
    pixel and distinct block, not per (pixel, dimension): requests have few
    blocks and many dimensions per block."""
    prm = req.params
    p = pixel_seed(req.seed, req.pixels[pix0:pix1])
    blocks, which = np.unique(req.dims // U32(prm.B), return_inverse=True)
    seeds = np.empty((len(p), len(blocks)), dtype=U32)  # (pixels, distinct blocks); none for no dims
    for k, b in enumerate(blocks):
        seeds[:, k] = block_seed(p, b)
    orders = block_order_seed(seeds, blocks[None, :], prm.N)
    return blocks, which.ravel(), seeds, orders


def column_keys(req, pix0: int, pix1: int) -> np.ndarray:
    """The column key ``q = P * (col + 1)`` of every (pixel, dimension) of
    pixels ``[pix0, pix1)`` of request ``req``, shape ``(pixels, n_dims)``:
    times STRATUM_KEY, SUBSTRATUM_KEY and JITTER_KEY it gives the column's
    three seeds (docs/spec.md section 3.3; ``P`` from :func:`block_seeds`)."""
    if pix1 == pix0 or req.n_dims == 0:
        return np.empty((pix1 - pix0, req.n_dims), dtype=U32)
    _, which, seeds, _ = block_seeds(req, pix0, pix1)
    return seeds[:, which] * (req.dims % U32(req.params.B) + U32(1))


def table_keys(req, pix0: int, pix1: int) -> np.ndarray:
    """Per (pixel, dimension) of pixels ``[pix0, pix1)``: the column key ``q``
    (:func:`column_keys`) and the final shifts ``q * STRATUM_KEY % s`` and
    ``q * SUBSTRATUM_KEY % M`` of its two permutations, as a C-contiguous
    uint32 array of shape ``(pixels, n_dims, 3)`` (the OpenCL ``tables``
    kernel reads it)."""
    prm = req.params
    q = column_keys(req, pix0, pix1)
    out = np.empty((*q.shape, 3), dtype=U32)
    out[..., 0] = q
    np.remainder(q * U32(STRATUM_KEY), U32(prm.s), out=out[..., 1])
    np.remainder(q * U32(SUBSTRATUM_KEY), U32(prm.M), out=out[..., 2])
    return out
