"""The OpenCL backend: launches of ``kernels/generate.cl`` in chunks."""

from __future__ import annotations

import threading

import numpy as np

from ..tables import gf
from ..catalogue.request import Rect, Request
from . import vector
from .choice import open_device
from .device import DeviceInfo

#: Work-items per group when an axis is split (see OpenCLBackend._launch_2d).
#: PoCL vectorizes across work-items only when it knows the group size, and
#: leaving it to PoCL halved throughput (docs/performance.md, lessons for PoCL).
GROUP_SIZE = 64
#: Upper bound on one launch's output buffer (OpenCL buffers may not exceed
#: 2 GiB, and CL_DEVICE_MAX_MEM_ALLOC_SIZE may be smaller still).
MAX_CHUNK_BYTES = 256 << 20
#: Longest first axis of a 2D launch that is one work-group (see
#: OpenCLBackend._launch_2d).
MAX_AXIS_GROUP = 1024
#: How the orthogonal-array samplers are computed (all give the same bits):
#: ``vector`` (kernels/vector.cl, specialized per shape, where
#: :func:`pyoa._opencl.vector.shape` accepts the request; else ``tables``),
#: ``tables`` (the table path of kernels/generate.cl where it pays off, else
#: ``direct``) or ``direct`` (one work-item per value, everything from
#: scratch). ``auto`` picks per device: ``vector`` on a CPU (PoCL: 2-3x the
#: table path, docs/performance.md) for requests of at least
#: :data:`VECTOR_MIN_VALUES` values, ``direct`` on a GPU (the H100 ran it at
#: 2.4-2.7 G values/s against 1.9 for the table path).
PATHS = ("auto", "vector", "tables", "direct")
#: Environment variable overriding the ``auto`` choice (one of :data:`PATHS`).
ENV_PATH = "PYOA_OPENCL_PATH"
#: Values of one shape (pixels x samples x dims, summed over this process's
#: requests of that shape) from which ``auto`` builds its vector program: a
#: new shape costs about a second to build once per process
#: (docs/performance.md, "First use of a shape"), and the vector path saves
#: about 2 ms per 2^20 values. Summed, not per request, because a render asks
#: for one batch of pixels after another (2^16 paths each, under 2^20 values
#: below 16 dimensions), and there the table path cost 1.3-2x the vector
#: path's time (Bose, 121 spp, 541 pixels a call, Intel Xeon 6/207).
VECTOR_MIN_VALUES = 1 << 20


class OpenCLBackend:
    """One OpenCL device with pyoa's program built on it.

    ``selector`` names the device (see :mod:`pyoa._opencl.device`); without
    one, the first candidate device that builds the program is used
    (:func:`pyoa._opencl.choice.open_device`).

    A lock serializes launches, so one backend (and every Sampler using it)
    is safe to call from several threads.
    """

    name = "opencl"
    #: Launches are serialized by a lock; the device parallelizes inside one.
    parallel_chunks = False

    def __init__(self, selector: str | None = None, *, path: str | None = None):
        import os

        import pyopencl as cl

        path = path or os.environ.get(ENV_PATH) or "auto"
        if path not in PATHS:
            raise ValueError(f"OpenCL path {path!r} is not one of {', '.join(PATHS)} (argument path= or ${ENV_PATH})")

        self.info: DeviceInfo
        self.info, (self.context, self.queue, self.program) = open_device(selector)
        self._lock = threading.Lock()
        # Kernel objects are fetched once (each retrieval builds a new one);
        # their arguments are set under self._lock.
        self._kernels = {k.function_name: k for k in self.program.all_kernels()}
        self._fields: dict[int, tuple] = {}
        self._consts: dict[tuple, object] = {}
        self._scratch_bufs: dict[str, object] = {}
        #: name -> (key, device buffers) of the last upload of each kind (_kept_upload)
        self._uploads: dict[str, tuple] = {}
        limit = min(MAX_CHUNK_BYTES, int(self.info.device.max_mem_alloc_size), 2**31 - 1)
        self.max_chunk_values = limit // 4
        #: A CPU device (PoCL) writes straight into the caller's array
        #: (USE_HOST_PTR): no device buffer, no copy back. A GPU writes into
        #: a reused device buffer that is then copied.
        self.zero_copy = self.info.kind == "cpu"
        #: The orthogonal arrays' path on this device (see :data:`PATHS`).
        self.path = path if path != "auto" else "vector" if self.info.kind == "cpu" else "direct"
        #: Whether the path was asked for (then the vector path takes requests
        #: of any size) rather than chosen by ``auto``.
        self.path_forced = path != "auto"
        #: Values requested so far of each vector shape not yet built (see
        #: :data:`VECTOR_MIN_VALUES`).
        self._shape_values: dict = {}
        self._axis_limit = min(
            [MAX_AXIS_GROUP]
            + [self._kernels[k].get_work_group_info(cl.kernel_work_group_info.WORK_GROUP_SIZE, self.info.device)
               for k in self._kernels]
        )

    def describe(self) -> str:
        return self.info.describe()

    def _constants(self, req: Request):
        """Buffer of the sampler's constants (Addelman-Kempthorne's, Halton's
        primes, Sobol's direction numbers), uploaded once per (sampler,
        parameters); a 1-element placeholder when there are none. Called with
        self._lock held."""
        key = req.construction.constants_key(req.params)
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

    def _launch_2d(self, name: str, n: int, n_pd: int, *args) -> None:
        """Launch 2D kernel ``name`` over exactly ``n`` x ``n_pd`` work-items.

        The kernels have no bounds check: one would make their loads
        conditional, and PoCL then neither hoists the per-(pixel, dimension)
        loads out of its work-item loop nor vectorizes it
        (docs/performance.md). So no axis is padded: along the first axis one
        work-group spans it when it fits, else groups of :data:`GROUP_SIZE`
        cover the largest multiple and a second launch, at a global offset,
        the rest; a short first axis takes several rows of the second per
        group (about GROUP_SIZE work-items a group), with the rows that do
        not fill a group in a launch of their own. Called with self._lock
        held."""
        self._launch_2d_kernel(self._kernels[name], n, n_pd, *args)

    def _launch_2d_kernel(self, kernel, n: int, n_pd: int, *args) -> None:
        """:meth:`_launch_2d` of a kernel object (the vector path's are not in
        the main program). Called with self._lock held."""
        if n > self._axis_limit:
            main = n // GROUP_SIZE * GROUP_SIZE
            parts = [((0, 0), (main, n_pd), (GROUP_SIZE, 1))]
            if main < n:
                parts.append(((main, 0), (n - main, n_pd), (n - main, 1)))
        else:
            rows = max(1, min(GROUP_SIZE // n, n_pd))
            main = n_pd // rows * rows
            parts = [((0, 0), (n, main), (n, rows))]
            if main < n_pd:
                parts.append(((0, main), (n, n_pd - main), (n, 1)))
        for offset, size, local in parts:
            kernel(self.queue, size, local, *args, global_offset=offset if any(offset) else None)

    def rows_per_chunk(self, n_dims: int) -> int:
        return max(1, self.max_chunk_values // max(1, n_dims))

    def fill(self, req: Request, row0: int, row1: int, out: np.ndarray) -> None:
        """Write rows ``[row0, row1)`` of ``req`` into ``out`` (C-contiguous float32)."""
        import pyopencl as cl

        n_values = (row1 - row0) * req.n_dims
        if n_values == 0:
            return
        ro = cl.mem_flags.READ_ONLY | cl.mem_flags.COPY_HOST_PTR
        prm = req.params
        with self._lock:
            if self.zero_copy:
                buf = cl.Buffer(self.context, cl.mem_flags.WRITE_ONLY | cl.mem_flags.USE_HOST_PTR, hostbuf=out)
            else:
                buf = self._scratch("out", n_values * 4)
            dims = cl.Buffer(self.context, ro, hostbuf=req.dims)
            # the kernel that computes a value from scratch: the OAs' generate or a comparison sampler's own
            launch = req.construction.launch(prm, req.offset, req.jitter)
            field = () if launch.field is None else self._field(launch.field)
            extra = (np.uint32(req.seed), *launch.args, *field, self._constants(req))
            use_vector = self.path == "vector"
            for rect in req.rectangles(row0, row1):
                # each rectangle's values are a contiguous part of the chunk
                at = np.uint32((rect.row0 - row0) * req.n_dims)
                shp = vector.shape(req, rect) if use_vector else None
                if shp is not None and not self.path_forced and req.tables_pay_off(rect) and not shp.tabled:
                    shp = None  # a walked permutation: the table path is faster ('cmj', 'centered')
                if shp is not None and self._vector_pays(shp, rect, req.n_dims):
                    launch_vector = (self._launch_vector_baseline if isinstance(shp, vector.BaselineShape)
                                     else self._launch_vector)
                    launch_vector(req, rect, shp, buf, at, dims)
                    continue
                if self.path != "direct" and req.tables_pay_off(rect) and req.array_cells_fit:
                    self._launch_tabled(req, rect, buf, at)
                    continue
                # only the rectangle's pixels and samples travel to the device
                pixels = cl.Buffer(self.context, ro, hostbuf=np.ascontiguousarray(req.pixels[rect.pix0 : rect.pix1]))
                samples = cl.Buffer(self.context, ro, hostbuf=np.ascontiguousarray(req.samples[rect.k0 : rect.k1]))
                self._launch_2d(launch.kernel, rect.n_k, rect.n_pixels * req.n_dims,
                                buf, at, pixels, samples, dims, np.uint32(rect.n_k), np.uint32(req.n_dims), *extra)
            if self.zero_copy:
                # mapping makes the kernels' writes visible in `out` (where the
                # runtime could not use the pointer itself, it copies here)
                mapped, _ = cl.enqueue_map_buffer(self.queue, buf, cl.map_flags.READ, 0, out.shape, out.dtype)
                mapped.base.release(self.queue)
            else:
                cl.enqueue_copy(self.queue, out, buf)
            self.queue.finish()

    def _vector_pays(self, shp, rect: Rect, n_dims: int) -> bool:
        """Whether ``rect`` takes the vector program of ``shp``: always when
        the path was forced, else once this process has asked for
        :data:`VECTOR_MIN_VALUES` values of that shape (this rectangle's
        included), so that a small request alone does not pay a build.
        Called with self._lock held."""
        if self.path_forced or vector.built(self.context, shp):
            return True
        total = self._shape_values.get(shp, 0) + rect.n_pixels * rect.n_k * n_dims
        if total >= VECTOR_MIN_VALUES:
            self._shape_values.pop(shp, None)
            return True
        self._shape_values[shp] = total
        return False

    def _launch_1d(self, kernel, n: int, *args) -> None:
        """Launch 1D ``kernel`` over exactly ``n`` work-items: groups of
        :data:`GROUP_SIZE`, the remainder in a launch of its own (no bounds
        checks in the kernels, see :meth:`_launch_2d`). Called with self._lock held."""
        main = n // GROUP_SIZE * GROUP_SIZE
        if main:
            kernel(self.queue, (main,), (GROUP_SIZE,), *args)
        if main < n:
            kernel(self.queue, (n - main,), (n - main,), *args, global_offset=(main,))

    def _launch_vector(self, req: Request, rect: Rect, shp: vector.Shape, buf, at: int, dims) -> None:
        """The vector path over one rectangle of whole pixels: ``vector_tables``
        then ``vector_values`` (kernels/vector.cl), writing values ``[at, at +
        rect values)`` of ``buf``. Called with self._lock held."""
        import pyopencl as cl

        ro = cl.mem_flags.READ_ONLY | cl.mem_flags.COPY_HOST_PTR
        k_tables, k_values, *k_rows = vector.kernels(self.context, self.info, shp)
        n_pd = rect.n_pixels * req.n_dims
        groups = -(-n_pd // vector.LANES)  # vector_tables does 8 (pixel, dimension) pairs per work-item
        pk = self._scratch("vector", groups * vector.LANES * vector.TABLE_WORDS * 4)
        # padded so that the last work-item's extra lanes read a pixel (and write padding)
        pixels = np.zeros(-(-groups * vector.LANES // req.n_dims), np.uint32)
        pixels[: rect.n_pixels] = req.pixels[rect.pix0 : rect.pix1]
        pixels = cl.Buffer(self.context, ro, hostbuf=pixels)
        self._launch_1d(k_tables, groups, pk, pixels, dims, np.uint32(req.seed))
        aij, u, samples = (cl.Buffer(self.context, ro, hostbuf=a) for a in vector.cell_arrays(req, shp))
        records = rowtab = samples  # placeholders where no dimension lies past block 0
        if shp.later:
            # every row's record, and the later blocks' rows of every (pixel, sample position)
            records = self._row_records(req, shp)
            rowtab = self._scratch("rows", rect.n_pixels * shp.later_slots * shp.n_k_padded * 4)
            self._launch_2d_kernel(k_rows[0], shp.later_slots, rect.n_pixels, rowtab, pk, samples)
        self._launch_2d_kernel(k_values, shp.n_blocks, rect.n_pixels,
                               buf, np.uint32(at), pk, aij, u, samples, rowtab, records, np.float32(req.jitter))

    def _launch_vector_baseline(self, req: Request, rect: Rect, shp: vector.BaselineShape, buf, at: int,
                                dims) -> None:
        """``vector_baseline`` (kernels/vector.cl) over one rectangle of whole
        pixels of a padded 2D comparison sampler. Called with self._lock held."""
        import pyopencl as cl

        ro = cl.mem_flags.READ_ONLY | cl.mem_flags.COPY_HOST_PTR
        (kernel,) = vector.kernels(self.context, self.info, shp)
        pixels = cl.Buffer(self.context, ro, hostbuf=np.ascontiguousarray(req.pixels[rect.pix0 : rect.pix1]))
        samples = cl.Buffer(self.context, ro, hostbuf=np.pad(req.samples, (0, shp.n_k_padded - shp.n_k)))
        self._launch_2d_kernel(kernel, shp.n_blocks, rect.n_pixels, buf, np.uint32(at), pixels, dims, samples,
                               np.uint32(req.seed), np.float32(req.jitter))

    def _launch_tabled(self, req: Request, rect: Rect, buf, at: int) -> None:
        """The table path over one rectangle: ``tables`` then ``generate_cells``
        (every dimension in block 0) or ``block_rows`` and ``generate_rows``
        (later blocks read their own rows, docs/spec.md section 6), writing
        values ``[at, at + rect values)`` of ``buf``. Called with self._lock held."""
        import pyopencl as cl

        from ..catalogue.host_tables import block_seeds, cells, table_keys

        ro = cl.mem_flags.READ_ONLY | cl.mem_flags.COPY_HOST_PTR
        prm = req.params
        E, n_k, n_pd = req.table_entries, rect.n_k, rect.n_pixels * req.n_dims
        keys = cl.Buffer(self.context, ro, hostbuf=table_keys(req, rect.pix0, rect.pix1))
        Es = req.table_stride  # E padded to whole vectors (kernels/generate.cl)
        tab = self._scratch("tables", n_pd * Es * 4)
        for name in ("tables", "tables_finish"):
            self._launch_2d(name, Es, n_pd, tab, keys, np.uint32(E), np.uint32(Es), np.uint32(prm.s), np.uint32(prm.M))
        samples = np.ascontiguousarray(req.samples[rect.k0 : rect.k1])
        centered = req.offset == "centered"
        if not req.past_block0:
            aij, u = cells(req, rect.k0, rect.k1)
            self._launch_2d(
                "generate_cells_centered" if centered else "generate_cells", n_k, n_pd,
                buf, np.uint32(at), tab,
                cl.Buffer(self.context, ro, hostbuf=aij), cl.Buffer(self.context, ro, hostbuf=u),
                cl.Buffer(self.context, ro, hostbuf=samples),
                np.uint32(n_k), np.uint32(req.n_dims), np.uint32(E), np.uint32(Es), np.uint32(prm.s), np.uint32(prm.M),
                np.float32(req.jitter),
            )
            return
        # later blocks: one slot of rows per (pixel, block >= 1) after block 0's (the samples)
        blocks, which, _, orders = block_seeds(req, rect.pix0, rect.pix1)
        later = blocks != 0
        n_later = int(later.sum())
        slot = np.zeros(len(blocks), np.int64)
        slot[later] = 1 + np.arange(n_later)
        offsets = (slot[which][None, :] + np.where(later[which], n_later, 0)[None, :]
                   * np.arange(rect.n_pixels)[:, None]) * n_k  # (pixels, dims)
        rows = self._scratch("rows", (1 + rect.n_pixels * n_later) * n_k * 4)
        cl.enqueue_copy(self.queue, rows, samples)
        order_seeds = np.ascontiguousarray(orders[:, later], dtype=np.uint32)
        self._launch_2d("block_rows", n_k, rect.n_pixels * n_later, rows,
                        cl.Buffer(self.context, ro, hostbuf=order_seeds), np.uint32(n_k), np.uint32(prm.N))
        aij, u = self._array_cells(req)
        self._launch_2d(
            "generate_rows_centered" if centered else "generate_rows", n_k, n_pd,
            buf, np.uint32(at), tab, aij, u, rows,
            cl.Buffer(self.context, ro, hostbuf=np.ascontiguousarray(offsets, dtype=np.uint32)), np.uint32(prm.N),
            np.uint32(n_k), np.uint32(req.n_dims), np.uint32(E), np.uint32(Es), np.uint32(prm.s), np.uint32(prm.M),
            np.float32(req.jitter),
        )

    def _kept_upload(self, name: str, key, arrays) -> tuple:
        """Read-only device buffers of the host arrays ``arrays()``, uploaded
        once per ``key`` and kept under ``name`` until another key comes (a
        render asks for the same shape batch after batch). Called with
        self._lock held."""
        import pyopencl as cl

        kept = self._uploads.get(name)
        if kept is None or kept[0] != key:
            ro = cl.mem_flags.READ_ONLY | cl.mem_flags.COPY_HOST_PTR
            kept = self._uploads[name] = (key, tuple(cl.Buffer(self.context, ro, hostbuf=a) for a in arrays()))
        return kept[1]

    def _array_cells(self, req: Request) -> tuple:
        """Device buffers of :func:`pyoa.catalogue.host_tables.array_cells` of ``req``,
        uploaded once per request shape. Called with self._lock held."""
        from ..catalogue.host_tables import array_cells

        return self._kept_upload("cells", (req.construction.name, req.params, req.offset, req.dims.tobytes()),
                                 lambda: array_cells(req))

    def _row_records(self, req: Request, shp: vector.Shape):
        """The device buffer of :func:`pyoa._opencl.vector.row_records` of
        ``req``, uploaded once per array and record layout. Called with
        self._lock held."""
        return self._kept_upload("records", (req.construction.name, req.params, shp.cell_bits),
                                 lambda: (vector.row_records(req, shp),))[0]

def _field_tables(q: int) -> tuple[np.ndarray, bool]:
    """GF(q) as the kernels read it: addition then multiplication table, or a
    1-element placeholder (and tabled = False) for prime q and for q = 0 (a
    construction without a field)."""
    if q == 0 or gf.prime_power(q)[1] == 1:
        return np.zeros(1, np.uint16), False
    add, mul = gf.tables(q)
    return np.concatenate([add, mul]), True


