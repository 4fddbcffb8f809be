"""The vector path: orthogonal-array kernels specialized per request shape.

``kernels/vector.cl`` is built once per *shape* (construction parameters,
offset, number of dimensions and of sample positions), with the shape's
numbers as ``-D`` constants, so that every loop in it has a constant trip
count and unrolls, and its stores are generated for exactly that row length
(:func:`store_code`). A shape is built on first use in a process (about
0.3 s, plus PoCL's compilation of the two kernels on their first launch,
which PoCL caches on disk across processes: docs/performance.md, "The
vector path"), then reused from :data:`_programs`.

Which requests take it (:func:`shape`): the orthogonal-array samplers, any
offset, when

- a rectangle is whole pixels with at least 8 sample positions (the tables,
  32 bytes per pixel and dimension, are then no larger than the output),
- there are at most :data:`MAX_DIMS` dimensions (up to
  :data:`MAX_WHOLE_ROWS` the kernel holds one vector per dimension and
  stores whole rows; more are computed and stored in groups of 8; the padded
  2D samplers' kernel stops at :data:`MAX_WHOLE_ROWS`),
- a dimension past the first block finds the cells of every row of the
  array within :data:`pyoa.request.MAX_ARRAY_CELLS` (it reads its copy at its
  own rows, docs/spec.md section 6),
- the stratum permutation fits 4-bit fields (s <= 16) or its bounded walk
  takes at most :data:`MAX_ROUNDS` rounds, and the sub-stratum permutation
  likewise ('cmj' with M <= 16 is tabled; 'mj', 'j' and larger 'cmj' walk per
  value).

A walk of Kensler's permute on [0, l) in the domain [0, w] ends after at most
w + 2 - l rounds (the cycle through the start meets at most w + 1 - l values
outside [0, l) first), so the kernels run exactly that many rounds, without a
loop: l = 11 (w = 15) takes 6, l = 17 (w = 31) 16. Everything else takes the
table path or the direct path of ``kernels/generate.cl``, with the same bits.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

from .. import catalogue_types
from ..reference.hashes import walk_mask
from ..request import Rect, Request

#: Lanes per vector: 8 (AVX2's width; on AVX-512, 16 lanes measured slower).
LANES = 8
#: Most dimensions of a request on this path.
MAX_DIMS = 64
#: Most dimensions the kernel holds as one vector each and stores as whole
#: rows; more are computed in groups of 8 (kernels/vector.cl, VGROUPED).
MAX_WHOLE_ROWS = 16
#: Most rounds of a bounded walk (l = 17 in [0, 31] needs 16).
MAX_ROUNDS = 16
#: Words of the per-(pixel, dimension) table (kernels/vector.cl, vector_tables).
TABLE_WORDS = 8


def walk_rounds(n: int) -> int:
    """Rounds that always end a walk of Kensler's permute on ``[0, n)``."""
    return walk_mask(n) + 2 - n


class _Rows:
    """What every vector program shares: ``n_dims`` dimensions and ``n_k``
    sample positions per pixel, computed in blocks of :data:`LANES`."""

    n_dims: int
    n_k: int

    @property
    def n_blocks(self) -> int:
        return -(-self.n_k // LANES)

    @property
    def n_k_padded(self) -> int:
        return self.n_blocks * LANES

    def _header(self, consts: dict) -> str:
        """``#define`` lines of ``consts`` and the row constants. The
        generated stores do not fit ``-D`` options, which the driver splits
        at spaces, so the constants open the program text instead."""
        # whole-row stores, for up to MAX_WHOLE_ROWS dimensions (more go in groups, without them)
        block, tail = store_code(self.n_dims, self.n_k % LANES) if self.n_dims <= MAX_WHOLE_ROWS else (";", ";")
        consts = {**consts, "VND": f"{self.n_dims}u", "VNK": f"{self.n_k}u", "VNKP": f"{self.n_k_padded}u",
                  "VSTORE_BLOCK": block, "VSTORE_TAIL": tail}
        return "".join(f"#define {name} {value}\n" for name, value in consts.items())


@dataclass(frozen=True)
class Shape(_Rows):
    """The build constants of one vector program (see kernels/vector.cl)."""

    s: int
    M: int
    n_dims: int
    n_k: int
    block_dims: int
    offset: str
    s_packed: bool
    sub: int  # 0 none, 1 tabled as fields, 2 walked per value
    jkey_bose: bool
    #: bit d set: requested dimension d lies past block 0 (docs/spec.md section 6), so it reads its own rows
    later_mask: int = 0

    @property
    def later(self) -> bool:
        return self.later_mask != 0

    @property
    def tabled(self) -> bool:
        """Whether no value walks a permutation (both are 4-bit fields).

        For 'cmj' and 'centered' a walked permutation is slower than the
        table path of kernels/generate.cl, which tables it whatever its size
        (Bush s = 5 t = 3 'cmj', M = 25: 277 against about 460 M values/s,
        docs/performance.md), so ``auto`` takes the vector path for them only
        when this holds."""
        return self.s_packed and self.sub != 2

    def header(self) -> str:
        """The ``#define`` lines that open the program text."""
        return self._header({
            "VS": f"{self.s}u", "VM": f"{self.M}u", "VWS": f"{walk_mask(self.s)}u", "VWM": f"{walk_mask(self.M)}u",
            "VDMAX": f"{self.block_dims}u", "VOFFSET": catalogue_types.OFFSET_CODES[self.offset],
            "VS_PACKED": int(self.s_packed), "VS_ROUNDS": f"{walk_rounds(self.s)}u",
            "VSUB": self.sub, "VSUB_ROUNDS": f"{walk_rounds(self.M)}u", "VJKEY_BOSE": int(self.jkey_bose),
            "VN": f"{self.s * self.M}u", "VWN": f"{walk_mask(self.s * self.M)}u", "VLATER": int(self.later),
            "VLATER_MASK": f"{self.later_mask:#x}ul",
            "VGROUPED": int(self.n_dims > MAX_WHOLE_ROWS),
        })


@dataclass(frozen=True)
class BaselineShape(_Rows):
    """The build constants of one vector program of a padded 2D comparison
    sampler (``jittered2d``: kind 1, grid a x a, b = the sampler's dims;
    ``cmj2d``: kind 2, grid a x b). See kernels/vector.cl, vector_baseline."""

    kind: int
    a: int
    b: int
    n_dims: int
    n_k: int

    @property
    def N(self) -> int:
        return self.a * (self.a if self.kind == 1 else self.b)

    def header(self) -> str:
        """The ``#define`` lines that open the program text."""
        return self._header({
            "VBASELINE": self.kind, "VBA": f"{self.a}u", "VBB": f"{self.b}u", "VBN": f"{self.N}u",
            "VBN_ROUNDS": f"{walk_rounds(self.N)}u", "VBA_ROUNDS": f"{walk_rounds(self.a)}u",
            "VBB_ROUNDS": f"{walk_rounds(self.b) if self.kind == 2 else 0}u",
        })


def baseline_shape(req: Request, rect: Rect) -> BaselineShape | None:
    """The vector program of a ``jittered2d`` or ``cmj2d`` rectangle, or None
    (other samplers, and the limits of :func:`shape`)."""
    kind = req.construction.vector_kind  # its catalogue entry names the kernel (VBASELINE), or 0
    if not kind or rect.n_k != len(req.samples) or rect.n_k < LANES or not 1 <= req.n_dims <= MAX_WHOLE_ROWS:
        return None
    a, b = req.construction.shape_args(req.params)
    shp = BaselineShape(kind, a, b, req.n_dims, rect.n_k)
    walks = [shp.N, a] + ([b] if kind == 2 else [])
    return shp if max(walk_rounds(n) for n in walks) <= MAX_ROUNDS else None


def shape(req: Request, rect: Rect) -> Shape | None:
    """The vector program for rectangle ``rect`` of ``req``, or None when the
    rectangle does not take the vector path (module docstring)."""
    prm = req.params
    if req.construction.family != "oa" or rect.n_k != len(req.samples) or rect.n_k < LANES:
        return None
    if not 1 <= req.n_dims <= MAX_DIMS or not req.array_cells_fit:
        return None
    s_packed = prm.s <= 16
    if not s_packed and walk_rounds(prm.s) > MAX_ROUNDS:
        return None
    if req.offset == "centered":
        sub = 0
    elif req.offset == "cmj" and prm.M <= 16:
        sub = 1
    elif walk_rounds(prm.M) <= MAX_ROUNDS:
        sub = 2
    else:
        return None
    return Shape(prm.s, prm.M, req.n_dims, rect.n_k, prm.block_dims, req.offset, s_packed, sub,
                 req.construction.partner_cell_key,
                 sum(1 << d for d, j in enumerate(req.dims.tolist()) if j >= prm.block_dims))


def store_code(n_dims: int, tail: int) -> tuple[str, str]:
    """OpenCL statements storing ``float8 V[n_dims]`` (V[d] lane r is sample
    8 b + r of dimension d) at ``o``, row after row (``o[r * n_dims + d]``).

    The full block is ``n_dims`` contiguous ``vstore8`` of the rows in order:
    elements gathered from the V[d] by constant indices, which LLVM turns
    into shuffles. The tail block (``tail`` valid rows, 0 = none) stores its
    ``tail * n_dims`` values one by one."""
    def elem(m: int) -> str:
        r, d = divmod(m, n_dims)
        return f"V[{d}].s{r}"

    block = " ".join(
        f"vstore8((float8)({', '.join(elem(v * LANES + e) for e in range(LANES))}), {v}, o);"
        for v in range(n_dims)
    )
    tail_code = " ".join(f"o[{m}] = {elem(m)};" for m in range(tail * n_dims)) or ";"
    return block, tail_code


_lock = threading.Lock()
#: (context, Shape) -> built program with its two kernels.
_programs: dict[tuple, tuple] = {}


def built(context, shp: Shape | BaselineShape) -> bool:
    """Whether :func:`kernels` has built ``shp`` in ``context`` already."""
    with _lock:
        return (context.int_ptr, shp) in _programs


def kernels(context, info, shp: Shape | BaselineShape) -> tuple:
    """``(vector_tables, vector_values)`` built for ``shp`` in ``context``,
    once per process; ``(vector_baseline,)`` for a :class:`BaselineShape`.

    Raises
    ------
    pyoa._opencl.program.BuildError
        If the device's compiler rejects the program (it carries the log).
    """
    import pyopencl as cl

    from .. import kernels as kernel_sources
    from . import program

    key = (context.int_ptr, shp)
    with _lock:
        if key not in _programs:
            printed: list[str] = []
            try:
                with program._captured_stderr() as printed:
                    prg = cl.Program(context, shp.header() + program.source(kernel_sources.VECTOR_SOURCES)).build(
                        options=program.BUILD_OPTIONS + program.defines())
            except cl.Error as exc:
                noise = "".join(printed)
                raise program.BuildError(info, "build", str(exc) + (f"\n{noise}" if noise.strip() else "")) from exc
            names = ("vector_baseline",) if isinstance(shp, BaselineShape) else ("vector_tables", "vector_values")
            _programs[key] = tuple(cl.Kernel(prg, name) for name in names)
        return _programs[key]


def cell_arrays(req: Request, shp: Shape) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(A_ij, u, sample indices)`` of every sample position, the cells laid
    out ``[d][k]`` and every row padded with zeros to whole blocks (the
    kernel's ``vload8`` reads whole blocks; padded lanes are never stored)."""
    from ..host_tables import cells

    aij, u = cells(req, 0, shp.n_k)
    pad = shp.n_k_padded - shp.n_k
    samples = np.pad(req.samples, (0, pad))
    return (np.ascontiguousarray(np.pad(aij, ((0, 0), (0, pad)))),
            np.ascontiguousarray(np.pad(u, ((0, 0), (0, pad)))),
            np.ascontiguousarray(samples, dtype=np.uint32))
