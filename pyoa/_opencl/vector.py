"""The vector path: orthogonal-array kernels specialized per request shape.

``kernels/vector.cl`` is built once per *shape* (construction parameters,
offset, number of dimensions and of sample positions), with the shape's
numbers as ``-D`` constants, so that every loop in it has a constant trip
count and unrolls, and its stores are generated for exactly that row length
(:func:`store_code`, :func:`group_code`). A shape is built on first use in
a process (about 0.3 s, plus PoCL's compilation of the kernels on their
first launch, which PoCL caches on disk across processes: docs/performance.md,
"The vector path"), then reused from :data:`_programs`. Where a dimension
lies past block 0, the shape includes the request's dimensions (each one's
block and column become build constants) and a third kernel,
``vector_rows``, computes the later blocks' rows once per (pixel, block,
sample) before the values.

Which requests take it (:func:`oa_shape`): the orthogonal-array samplers, any
offset, when

- a rectangle is whole pixels with at least 8 sample positions (the tables,
  32 bytes per pixel and dimension, are then no larger than the output),
- there are at most :data:`MAX_DIMS` dimensions (up to
  :data:`MAX_WHOLE_ROWS` the kernel holds one vector per dimension and
  stores whole rows; more are computed and stored in groups of 8; the padded
  2D samplers' kernel stops at :data:`MAX_WHOLE_ROWS`),
- a dimension past the first block reads its copy at its own rows
  (docs/spec.md section 6), from the records of every row of the array
  (:func:`row_records`), which must fit :data:`pyoa.catalogue.request.MAX_ARRAY_CELLS`
  words,
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

from ..catalogue import entries
from ..catalogue.params import OAParams, PointSetParams
from ..reference.hashes import walk_mask
from ..catalogue.request import MAX_ARRAY_CELLS, Rect, Request

#: Lanes per vector: 8 (AVX2's width; on AVX-512, 16 lanes measured slower).
LANES = 8
#: Most dimensions of a request on this path.
MAX_DIMS = 64
#: Most dimensions the kernel holds as one vector each and stores as whole
#: rows; more are computed in groups of 8 (kernels/vector.cl, VGROUPED).
MAX_WHOLE_ROWS = 16
#: Most rounds of a bounded walk (l = 17 in [0, 31] needs 16).
MAX_ROUNDS = 16

#: ``vector_rows`` walks the later blocks' rows in 16-bit lanes
#: (``pyoa_permute_round16`` of kernels/include/pyoa/hashes.h), so a request with a dimension
#: past block 0 takes the vector path only for arrays of fewer rows N = s M.
MAX_ROWS16 = 1 << 16
#: Words of the per-(pixel, dimension) table (kernels/vector.cl, vector_tables).
TABLE_WORDS = 8


def walk_rounds(n: int) -> int:
    """Rounds that always end a walk of Kensler's permute on ``[0, n)``."""
    return walk_mask(n) + 2 - n


def bits(n: int) -> int:
    """Bits that hold every integer below ``n`` (0 for ``n <= 1``)."""
    return (n - 1).bit_length() if n > 1 else 0


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
                  "VSTORE_BLOCK": block, "VSTORE_TAIL": tail, "VSTORE_GROUPS": group_code(self.n_dims)}
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
    #: The request's dimensions when one of them lies past block 0 (docs/spec.md section 6), else ():
    #: each dimension's block and column are then build constants (:meth:`header`).
    dims: tuple = ()

    @property
    def later(self) -> bool:
        """Whether a dimension lies past block 0 and reads its block's own rows."""
        return any(j >= self.block_dims for j in self.dims)

    @property
    def slots(self) -> list[int]:
        """The distinct blocks of :attr:`dims`, in increasing order (kernels/vector.cl's slots)."""
        return sorted({j // self.block_dims for j in self.dims})

    @property
    def later_slots(self) -> int:
        """How many of :attr:`slots` lie past block 0 (each has its rows in vector_rows' table)."""
        return sum(1 for blk in self.slots if blk > 0)

    @property
    def a_bits(self) -> int:
        """Bits of a cell's ``A_ij`` (below s) in a row record (:func:`row_records`)."""
        return max(1, bits(self.s))

    @property
    def cell_bits(self) -> int:
        """Bits of one cell in a row record: ``A_ij``, then ``u`` (below M; none for 'centered')."""
        return self.a_bits + (bits(self.M) if self.sub else 0)

    @property
    def record_words(self) -> int:
        """32-bit words of a row's record: the cells of its ``block_dims`` columns, none split
        across two words."""
        return -(-self.block_dims // (32 // self.cell_bits))

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
            "VDMAX": f"{self.block_dims}u", "VOFFSET": entries.OFFSET_CODES[self.offset],
            "VS_PACKED": int(self.s_packed), "VS_ROUNDS": f"{walk_rounds(self.s)}u",
            "VSUB": self.sub, "VSUB_ROUNDS": f"{walk_rounds(self.M)}u", "VJKEY_BOSE": int(self.jkey_bose),
            "VN": f"{self.s * self.M}u", "VWN": f"{walk_mask(self.s * self.M)}u", "VLATER": int(self.later),
            "VNSLOT": f"{len(self.slots)}u", "VLATER0": f"{int(0 in self.slots)}u",
            "VRW": f"{self.record_words}u", "VCB": f"{self.cell_bits}u", "VCPW": f"{32 // self.cell_bits}u",
            "VAB": f"{self.a_bits}u", "VAMASK": f"{(1 << self.a_bits) - 1:#x}u",
            "VUMASK": f"{(1 << (self.cell_bits - self.a_bits)) - 1:#x}u",
            "VGROUPED": int(self.n_dims > MAX_WHOLE_ROWS),
        }) + self._slot_tables()

    def _slot_tables(self) -> str:
        """With later blocks, the ``__constant`` tables of kernels/vector.cl: each slot's first
        dimension (VSLOT_FIRST), each dimension's slot (VSLOT_OF) and column (VCOL_OF)."""
        if not self.later:
            return ""
        slot = {blk: k for k, blk in enumerate(self.slots)}
        of = [slot[j // self.block_dims] for j in self.dims]
        first = [of.index(k) for k in range(len(self.slots))]
        cols = [j % self.block_dims for j in self.dims]
        return "".join(f"__constant uint {name}[{len(v)}] = {{{', '.join(f'{x}u' for x in v)}}};\n"
                       for name, v in (("VSLOT_FIRST", first), ("VSLOT_OF", of), ("VCOL_OF", cols)))


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
    (other samplers, and the limits of :func:`oa_shape`)."""
    kind = req.construction.vector_kind  # its catalogue entry names the kernel (VBASELINE), or 0
    if not kind or rect.n_k != len(req.samples) or rect.n_k < LANES or not 1 <= req.n_dims <= MAX_WHOLE_ROWS:
        return None
    a, b = req.construction.shape_args(req.params)
    shp = BaselineShape(kind, a, b, req.n_dims, rect.n_k)
    walks = [shp.N, a] + ([b] if kind == 2 else [])
    return shp if max(walk_rounds(n) for n in walks) <= MAX_ROUNDS else None


def shape(req: Request, rect: Rect) -> Shape | BaselineShape | None:
    """The vector program for rectangle ``rect`` of ``req``, or None when the
    rectangle does not take the vector path: an orthogonal array's
    (:func:`oa_shape`), a padded 2D grid's (:func:`baseline_shape`), or none
    for the other samplers."""
    make = _SHAPES.get(type(req.params))
    return None if make is None else make(req, rect)


def oa_shape(req: Request, rect: Rect) -> Shape | None:
    """The vector program of an orthogonal array's rectangle ``rect`` of ``req``,
    or None when the rectangle does not take the vector path (module docstring)."""
    prm = req.params
    if rect.n_k != len(req.samples) or rect.n_k < LANES:
        return None
    if not 1 <= req.n_dims <= MAX_DIMS:
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
    dims = tuple(req.dims.tolist())
    shp = Shape(prm.s, prm.M, req.n_dims, rect.n_k, prm.B, req.offset, s_packed, sub,
                req.construction.partner_cell_key, dims if max(dims) >= prm.B else ())
    if shp.later and prm.N * shp.record_words > MAX_ARRAY_CELLS:
        return None  # the rows' records would not fit
    if shp.later and prm.N >= MAX_ROWS16:
        return None  # vector_rows walks in 16-bit lanes
    return shp


#: The vector program of each parameter type that has one (:func:`shape`).
_SHAPES = {OAParams: oa_shape, PointSetParams: baseline_shape}


def row_records(req: Request, shp: Shape) -> np.ndarray:
    """The record of every row ``0..N-1`` of the array, for the later blocks of
    kernels/vector.cl: a C-contiguous uint32 array of shape ``(N,
    shp.record_words)``.

    The cell of column ``c`` (docs/spec.md section 5: ``A_ij`` and ``u`` of
    the row, pyoa.catalogue.constructions' cell functions) is ``A_ij | u << a_bits``,
    ``cell_bits`` wide, at bit ``(c % per_word) * cell_bits`` of word ``c //
    per_word``, ``per_word = 32 // cell_bits``; ``u`` is left out for
    'centered'. A block's rows are a permutation of these rows per (pixel,
    block), so a later dimension gathers its row's record once per block and
    8 samples and takes its column's field from it, instead of gathering its
    own two cells per value."""
    prm = req.params
    N = prm.N
    rows = np.arange(N, dtype=np.uint32)[:, None]
    cols = np.arange(prm.B, dtype=np.uint32)[None, :]
    aij, u = (np.broadcast_to(c, (N, prm.B)).astype(np.uint32)
              for c in req.construction.cells(rows, cols, prm))
    cell = aij | (u << np.uint32(shp.a_bits)) if shp.sub else aij
    per_word, out = 32 // shp.cell_bits, np.zeros((N, shp.record_words), np.uint32)
    for c in range(prm.B):
        out[:, c // per_word] |= cell[:, c] << np.uint32((c % per_word) * shp.cell_bits)
    return out


def group_code(n_dims: int) -> str:
    """OpenCL statements computing and storing every whole group of 8 of
    ``n_dims`` dimensions (kernels/vector.cl, VGROUPED): ``V[e] =
    VALUE_V8(d)`` for the group's 8 dimensions ``d``, then ``store_group``.

    Written out rather than a loop over the groups: with every ``d`` a
    constant, a dimension's tables, block and column are found at build time,
    and no more than 8 vectors are live at once (so the program does not
    spill as a whole unrolled request does). A loop over the groups, with
    ``d`` only known at run time, ran 36 dimensions at 516-538 M values/s
    against 657-690 written out (Bose s = 11, 121 spp; Intel Xeon 6/207,
    2 cores, same process)."""
    groups = []
    for g in range(n_dims // LANES):
        values = " ".join(f"V[{e}] = VALUE_V8({LANES * g + e}u);" for e in range(LANES))
        groups.append(f"{values} store_group(o + {LANES * g}u, V, {LANES}u, rows);")
    return " ".join(groups) or ";"


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
    once per process, and ``vector_rows`` after them where a dimension lies
    past block 0; ``(vector_baseline,)`` for a :class:`BaselineShape`.

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
                        options=program.BUILD_OPTIONS)
            except cl.Error as exc:
                noise = "".join(printed)
                raise program.BuildError(info, "build", str(exc) + (f"\n{noise}" if noise.strip() else "")) from exc
            names = (("vector_baseline",) if isinstance(shp, BaselineShape) else
                     ("vector_tables", "vector_values") + (("vector_rows",) if shp.later else ()))
            _programs[key] = tuple(cl.Kernel(prg, name) for name in names)
        return _programs[key]


def cell_arrays(req: Request, shp: Shape) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(A_ij, u, sample indices)`` of every sample position, the cells laid
    out ``[d][k]`` and every row padded with zeros to whole blocks (the
    kernel's ``vload8`` reads whole blocks; padded lanes are never stored).
    A dimension past block 0 reads its cells from its block's row records
    (:func:`row_records`) instead, and its row here is never read."""
    from ..catalogue.host_tables import cells

    pad = shp.n_k_padded - shp.n_k
    samples = np.pad(req.samples, (0, pad))
    aij, u = cells(req, 0, shp.n_k)
    return (np.ascontiguousarray(np.pad(aij, ((0, 0), (0, pad)))),
            np.ascontiguousarray(np.pad(u, ((0, 0), (0, pad)))),
            np.ascontiguousarray(samples, dtype=np.uint32))
