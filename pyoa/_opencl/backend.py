"""The OpenCL backend: launches of ``kernels/generate.cl`` in chunks."""

from __future__ import annotations

import threading

import numpy as np

from .. import constructions
from ..request import Request
from .device import DeviceInfo, select_device
from .program import build

#: Work-group size. PoCL vectorizes across work-items only when it knows the
#: group size, and leaving it to PoCL halved throughput (POCL-NOTES.md), so the
#: global size is padded to a multiple of this and the kernel bounds-checks.
GROUP_SIZE = 64
#: Upper bound on one launch's output buffer (OpenCL buffers may not exceed
#: 2 GiB, and CL_DEVICE_MAX_MEM_ALLOC_SIZE may be smaller still).
MAX_CHUNK_BYTES = 256 << 20


class OpenCLBackend:
    """One OpenCL device with pyoa's program built on it.

    A lock serializes launches, so one backend (and every Sampler using it)
    is safe to call from several threads.
    """

    name = "opencl"

    def __init__(self, selector: str | None = None):
        self.info: DeviceInfo = select_device(selector)
        self.context, self.queue, self.program = build(self.info)
        self._kernel = self.program.generate
        self._lock = threading.Lock()
        limit = min(MAX_CHUNK_BYTES, int(self.info.device.max_mem_alloc_size), 2**31 - 1)
        self.max_chunk_values = limit // 4

    def describe(self) -> str:
        return self.info.describe()

    def rows_per_chunk(self, n_dims: int) -> int:
        return max(1, self.max_chunk_values // max(1, n_dims))

    def fill(self, req: Request, row0: int, row1: int, out: np.ndarray) -> None:
        """Write rows ``[row0, row1)`` of ``req`` into ``out`` (C-contiguous float32)."""
        import pyopencl as cl

        n_values = (row1 - row0) * req.n_dims
        if n_values == 0:
            return
        mf = cl.mem_flags
        ro = mf.READ_ONLY | mf.COPY_HOST_PTR
        global_size = -(-n_values // GROUP_SIZE) * GROUP_SIZE
        with self._lock:
            pixels = cl.Buffer(self.context, ro, hostbuf=req.pixels if len(req.pixels) else np.zeros(1, np.uint32))
            samples = cl.Buffer(self.context, ro, hostbuf=req.samples)
            dims = cl.Buffer(self.context, ro, hostbuf=req.dims)
            buf = cl.Buffer(self.context, mf.WRITE_ONLY, size=n_values * 4)
            self._kernel(
                self.queue, (global_size,), (GROUP_SIZE,),
                buf, pixels, samples, dims,
                np.uint32(len(req.samples)), np.uint32(req.n_dims), np.uint64(row0), np.uint32(n_values),
                np.uint32(req.seed), np.uint32(req.construction.code),
                np.uint32(req.params.s), np.uint32(req.params.strength),
                np.uint32(constructions.OFFSET_CODES[req.offset]), np.float32(req.jitter),
            )
            cl.enqueue_copy(self.queue, out, buf)
            self.queue.finish()
