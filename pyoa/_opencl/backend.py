"""The OpenCL backend: launches of ``kernels/generate.cl`` in chunks."""

from __future__ import annotations

import threading

import numpy as np

from .. import constructions, gf
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
    #: Launches are serialized by a lock; the device parallelizes inside one.
    parallel_chunks = False

    def __init__(self, selector: str | None = None):
        self.info: DeviceInfo = select_device(selector)
        self.context, self.queue, self.program = build(self.info)
        self._lock = threading.Lock()
        # Kernel objects are fetched once (each retrieval builds a new one);
        # their arguments are set under self._lock.
        self._kernels = {k.function_name: k for k in self.program.all_kernels()}
        self._fields: dict[int, tuple] = {}
        self._consts: dict[tuple, object] = {}
        self._scratch_bufs: dict[str, object] = {}
        limit = min(MAX_CHUNK_BYTES, int(self.info.device.max_mem_alloc_size), 2**31 - 1)
        self.max_chunk_values = limit // 4

    def describe(self) -> str:
        return self.info.describe()

    def _constants(self, req: Request):
        """Buffer of the sampler's constants (Addelman-Kempthorne's, Halton's
        primes, Sobol's direction numbers), uploaded once per (sampler,
        parameters); a 1-element placeholder when there are none. Called with
        self._lock held."""
        key = (req.construction.name, req.params)
        if key not in self._consts:
            import pyopencl as cl

            values = np.ascontiguousarray(req.construction.constants(req.params), dtype=np.uint32).ravel()
            if values.size == 0:
                values = np.zeros(1, np.uint32)
            self._consts[key] = cl.Buffer(self.context, cl.mem_flags.READ_ONLY | cl.mem_flags.COPY_HOST_PTR,
                                          hostbuf=values)
        return self._consts[key]

    def _field(self, q: int) -> tuple:
        """Kernel arguments ``(gf buffer, tabled)`` for GF(q), uploaded once per q.
        Called with self._lock held."""
        if q not in self._fields:
            import pyopencl as cl

            tab, tabled = _field_tables(q)
            buf = cl.Buffer(self.context, cl.mem_flags.READ_ONLY | cl.mem_flags.COPY_HOST_PTR, hostbuf=tab)
            self._fields[q] = (buf, np.uint32(tabled))
        return self._fields[q]

    def _scratch(self, name: str, nbytes: int):
        """A device buffer of at least ``nbytes``, kept for the next launch.

        Allocating a fresh output and table buffer per chunk cost PoCL about a
        third of a Bose ``generate`` call (the pages are faulted in again
        every time), so each kind of scratch buffer is reused, and grown only
        when a launch needs more. Called with self._lock held."""
        import pyopencl as cl

        buf = self._scratch_bufs.get(name)
        if buf is None or buf.size < nbytes:
            buf = self._scratch_bufs[name] = cl.Buffer(self.context, cl.mem_flags.READ_WRITE, size=max(nbytes, 4))
        return buf

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
        prm = req.params
        n_s = len(req.samples)
        with self._lock:
            samples = cl.Buffer(self.context, ro, hostbuf=req.samples)
            dims = cl.Buffer(self.context, ro, hostbuf=req.dims)
            buf = self._scratch("out", n_values * 4)
            # Only the pixels of these rows travel to the device.
            pix0, pix1 = row0 // n_s, (row1 - 1) // n_s + 1
            pixels = cl.Buffer(self.context, ro, hostbuf=np.ascontiguousarray(req.pixels[pix0:pix1]))
            if req.construction.family == "baseline":
                a, b = (*req.construction.shape_args(prm), 0, 0)[:2]
                self._kernels[f"generate_{req.construction.function}"](
                    self.queue, (_padded(n_values),), (GROUP_SIZE,),
                    buf, pixels, samples, dims,
                    np.uint32(n_s), np.uint32(req.n_dims), np.uint32(row0 - pix0 * n_s), np.uint32(n_values),
                    np.uint32(req.seed), np.uint32(a), np.uint32(b), np.float32(req.jitter), self._constants(req),
                )
                cl.enqueue_copy(self.queue, out, buf)
                self.queue.finish()
                return
            gf_args = (*self._field(req.construction.field_order(prm)), self._constants(req))
            if req.tables_pay_off(row0, row1):
                E = req.table_entries
                n_entries = (pix1 - pix0) * req.n_dims * E
                tab = self._scratch("tables", n_entries * 4)
                self._kernels["tables"](
                    self.queue, (_padded(n_entries),), (GROUP_SIZE,),
                    tab, pixels, dims, np.uint32(n_entries), np.uint32(req.n_dims), np.uint32(E),
                    np.uint32(req.seed), np.uint32(prm.block_dims), np.uint32(prm.s), np.uint32(prm.M),
                )
                kernel = self._kernels[f"generate_tabled_{req.construction.function}"]
                # s^col of each CMJND column (all below 2**24); unused otherwise
                pw = [prm.s**k for k in range(prm.block_dims)] if req.construction.name == "cmjnd" else [1]
                powers = cl.Buffer(self.context, ro, hostbuf=np.array(pw, dtype=np.uint32))
                kernel(
                    self.queue, (_padded(n_values),), (GROUP_SIZE,),
                    buf, tab, samples, dims, powers, np.uint32(n_s), np.uint32(req.n_dims),
                    np.uint32(row0 - pix0 * n_s), np.uint32(n_values), np.uint32(E),
                    np.uint32(prm.block_dims), np.uint32(prm.s), np.uint32(prm.M), np.uint32(prm.strength),
                    np.uint32(constructions.OFFSET_CODES[req.offset]), np.float32(req.jitter), *gf_args,
                )
            else:
                self._kernels["generate"](
                    self.queue, (_padded(n_values),), (GROUP_SIZE,),
                    buf, pixels, samples, dims,
                    np.uint32(n_s), np.uint32(req.n_dims), np.uint32(row0 - pix0 * n_s), np.uint32(n_values),
                    np.uint32(req.seed), np.uint32(req.construction.code),
                    np.uint32(prm.s), np.uint32(prm.strength),
                    np.uint32(constructions.OFFSET_CODES[req.offset]), np.float32(req.jitter), *gf_args,
                )
            cl.enqueue_copy(self.queue, out, buf)
            self.queue.finish()


def _field_tables(q: int) -> tuple[np.ndarray, bool]:
    """GF(q) as the kernels read it: addition then multiplication table, or a
    1-element placeholder (and tabled = False) for prime q and for q = 0 (a
    construction without a field)."""
    if q == 0 or gf.prime_power(q)[1] == 1:
        return np.zeros(1, np.uint16), False
    add, mul = gf.tables(q)
    return np.concatenate([add, mul]), True


def _padded(n: int) -> int:
    """``n`` rounded up to a multiple of :data:`GROUP_SIZE`."""
    return -(-n // GROUP_SIZE) * GROUP_SIZE
