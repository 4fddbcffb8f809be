"""The user-facing sampler: parameters, validation and bulk generation.

A :class:`Sampler` is a pure function ``x(pixel, i, j)`` (pixel index, sample
index, dimension) to float32 values in ``[0, 1)``, in the style of pbrt-v4's
stateless samplers: any value can be computed alone, in any order, by any
backend, with the same bits. Each pixel's point set is an independently
randomized orthogonal array with seed ``pixel_seed(seed, pixel)``.

References
----------
.. [1] W. Jarosz, A. Enayet, A. Kensler, C. Kilpatrick, P. Christensen,
   "Orthogonal Array Sampling for Monte Carlo Rendering", EGSR 2019.
"""

from __future__ import annotations

import math
import numbers
import os
import re
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from . import constructions, reference
from .backends import choose
from .constructions import MAX_DIMS, MAX_SPP, MAX_UINT32, OFFSETS
from .request import Request

ENV_MAX_BYTES = "PYOA_MAX_BYTES"
_UNITS = {"": 1, "k": 1 << 10, "m": 1 << 20, "g": 1 << 30, "t": 1 << 40}


def samplers() -> dict[str, str]:
    """The sampler names :func:`sampler` accepts, each with a one-line description."""
    return {name: c.description for name, c in constructions.SAMPLERS.items()}


def _physical_memory() -> int:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return 8 << 30


def parse_bytes(text: str) -> int:
    """Parse ``"4G"``, ``"512MiB"``, ``"1e9"`` or ``"0.25"`` (a fraction of RAM) into bytes."""
    m = re.fullmatch(r"\s*([0-9.eE+]+)\s*([kKmMgGtT]?)(i?[bB])?\s*", text)
    if not m:
        raise ValueError(f"cannot read a memory size from {text!r}; examples: 4G, 512MiB, 0.25 (of RAM)")
    value = float(m[1])
    if not m[2] and not m[3] and 0 < value <= 1:
        return int(value * _physical_memory())
    return int(value * _UNITS[m[2].lower()])


def default_max_bytes() -> int:
    """``$PYOA_MAX_BYTES`` if set, else half of the physical memory."""
    env = os.environ.get(ENV_MAX_BYTES)
    return parse_bytes(env) if env else _physical_memory() // 2


def _fmt_bytes(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if n < 1024 or unit == "TiB":
            return f"{n:.1f} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1024
    return f"{n} B"  # pragma: no cover


def _int(name: str, value, lo: int | None = None, hi: int | None = None) -> int:
    """``value`` as a Python int in ``[lo, hi]``; bools and floats are refused."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__} {value!r}")
    value = int(value)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        rng = f"in [{lo}, {hi}]" if hi is not None else f">= {lo}"
        raise ValueError(f"{name} must be {rng}, got {value}")
    return value


def _indices(name: str, value, size: int, default) -> np.ndarray:
    """Validate a range or a sequence of ints in ``[0, size)``; returns uint32."""
    if value is None:
        value = default
    if isinstance(value, range):
        # Check the end points, not len(): len() of a range with 2**63 or
        # more elements raises OverflowError. In-bounds end points bound the
        # length by `size`.
        if value and not (0 <= min(value[0], value[-1]) and max(value[0], value[-1]) < size):
            raise ValueError(f"{name} must lie in [0, {size}), got {value}")
        return np.arange(value.start, value.stop, value.step, dtype=np.int64).astype(np.uint32)
    if isinstance(value, (str, bytes)) or np.isscalar(value) or not hasattr(value, "__len__"):
        raise TypeError(f"{name} must be a range or a sequence of ints, e.g. [3] or range(4); got {type(value).__name__}")
    arr = np.asarray(value)
    if arr.size == 0:
        return np.zeros(0, np.uint32)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional, got shape {arr.shape}")
    if arr.dtype == bool or not np.issubdtype(arr.dtype, np.integer):
        if arr.dtype == object and all(isinstance(v, numbers.Integral) and not isinstance(v, bool) for v in arr):
            arr = np.array([int(v) for v in arr], dtype=object)
        else:
            raise TypeError(f"{name} must hold integers, got dtype {arr.dtype}")
    lo, hi = int(arr.min()), int(arr.max())
    if lo < 0 or hi >= size:
        bad = lo if lo < 0 else hi
        raise ValueError(f"{name} must lie in [0, {size}), got {bad}")
    return arr.astype(np.uint32)


class Sampler:
    """A sampler: ``x(pixel, i, j)`` for every pixel, sample and dimension.

    Orthogonal-array samplers (``bose``, ``bush``, ``cmjnd``,
    ``addelman-kempthorne``, ``bose-bush``) and the paper's comparison
    samplers (``random``, ``jittered2d``, ``cmj2d``, ``sobol02``, ``halton``,
    ``sobol``) share this class, its API and its bit-exactness guarantees.

    Create one with :func:`sampler`. Immutable and safe to share between threads.

    Attributes
    ----------
    name : str
        Sampler name (``"bose"``, ``"sobol"``...; see :func:`samplers`).
    spp : int
        Samples per pixel, N.
    dims : int
        Number of dimensions.
    s : int
        Coarse strata per axis (comparison samplers: see :mod:`pyoa.baselines`).
    strength : int
        Strength t: every t-dimensional projection of a block is stratified
        (2 for the padded comparison samplers, 0 for random, halton and sobol).
    block_dims : int
        Dimensions per independently randomized block (s+1 for Bose, t for CMJND,
        2 for padded samplers); dimensions past it come from re-randomized copies
        (SPEC section 6).
    offset : str or None
        Offset style of an OA sampler: ``"cmj"`` (default), ``"mj"``, ``"j"`` or
        ``"centered"``; None for the comparison samplers.
    jitter : float
        Jitter amount in [0, 1] (as float32); 1 for samplers without one.
    seed : int
        User seed (uint32).
    backend : str
        ``"opencl"`` or ``"numpy"``; ``device`` describes what it runs on.
    max_bytes : int
        Largest array :meth:`generate` will allocate.
    """

    def __init__(self, name, *, spp, dims, seed=0, offset=None, jitter=1.0, strength=None,
                 backend=None, device=None, max_bytes=None):
        self._construction = constructions.get(name)
        self.name = self._construction.name
        self.spp = _int("spp", spp, 1, MAX_SPP)
        self.dims = _int("dims", dims, 1, MAX_DIMS)
        self.seed = _int("seed", seed, 0, MAX_UINT32)
        if strength is not None:
            strength = _int("strength", strength, 1)
        is_oa = self._construction.family == "oa"
        if offset is None:
            offset = "cmj" if is_oa else None
        elif not is_oa:
            raise ValueError(f"offset applies to the orthogonal-array samplers only; {self.name} has none "
                             f"(got offset={offset!r})")
        elif not isinstance(offset, str) or offset not in OFFSETS:
            raise ValueError(f"unknown offset {offset!r}; valid: {', '.join(OFFSETS)} (default 'cmj')")
        self.offset = offset
        if isinstance(jitter, bool) or not isinstance(jitter, numbers.Real):
            raise TypeError(f"jitter must be a real number in [0, 1], got {type(jitter).__name__}")
        if not 0.0 <= float(jitter) <= 1.0:  # NaN fails too
            raise ValueError(f"jitter must be in [0, 1] (1 = full jitter, 0 = cell centres), got {jitter}")
        if not (is_oa or self._construction.jittered) and float(jitter) != 1.0:
            raise ValueError(f"{self.name} has no jitter amount (got jitter={jitter}); it applies to the "
                             "orthogonal-array samplers, jittered2d and cmj2d")
        self.jitter = float(np.float32(jitter))
        self.params = self._construction.resolve(self.spp, self.dims, strength)
        self.s, self.strength, self.block_dims = self.params.s, self.params.strength, self.params.block_dims
        if max_bytes is None:
            max_bytes = default_max_bytes()
        elif isinstance(max_bytes, str):
            max_bytes = parse_bytes(max_bytes)
        self.max_bytes = _int("max_bytes", max_bytes, 1)
        self._backend = choose(backend, device)
        self.backend = self._backend.name
        self.device = self._backend.describe()

    def __repr__(self) -> str:
        if self._construction.family != "oa":
            c = self._construction
            grid = c.detail(self.params)
            return (
                f"Sampler({self.name!r}, spp={self.spp}, dims={self.dims}, seed={self.seed}"
                f"{f', jitter={self.jitter:g}' if c.jittered else ''}{f'; grid {grid}' if grid else ''}; "
                f"backend={self.backend!r} on {self.device})"
            )
        return (
            f"Sampler({self.name!r}, spp={self.spp}, dims={self.dims}, seed={self.seed}, "
            f"offset={self.offset!r}, jitter={self.jitter:g}; s={self.s}, strength={self.strength}, "
            f"block_dims={self.block_dims}; backend={self.backend!r} on {self.device})"
        )

    def _request(self, pixels, samples, dims) -> Request:
        return Request(
            construction=self._construction,
            params=self.params,
            seed=self.seed,
            offset=self.offset,
            jitter=self.jitter,
            pixels=_indices("pixels", pixels, MAX_UINT32 + 1, [0]),
            samples=_indices("samples", samples, self.spp, range(self.spp)),
            dims=_indices("dims", dims, self.dims, range(self.dims)),
        )

    def generate(self, pixels=None, samples=None, dims=None, *, out: np.ndarray | None = None,
                 progress: bool = False) -> np.ndarray:
        """Generate a block of values in bulk.

        Parameters
        ----------
        pixels : range or sequence of int, optional
            Pixel indices in ``[0, 2**32)``; default ``[0]``.
        samples : range or sequence of int, optional
            Sample indices in ``[0, spp)``; default every sample.
        dims : range or sequence of int, optional
            Dimensions in ``[0, dims)``; default every dimension.
        out : numpy.ndarray, optional
            Where to write the result, as NumPy's ``out=``: a C-contiguous,
            writeable float32 array of the result's shape. Reusing one array
            across calls saves allocating (and the kernel faulting in) fresh
            pages every time (``docs/performance.md``).
        progress : bool
            Show a tqdm progress bar over the chunks of a large request.

        Returns
        -------
        numpy.ndarray
            C-contiguous float32 of shape ``(len(pixels), len(samples), len(dims))``
            (``out`` itself when given);
            ``result[a, b, c] == x(pixels[a], samples[b], dims[c])``, bit for bit
            whatever the backend or the way the request is split.

        Raises
        ------
        ValueError
            An index out of range, a request larger than ``max_bytes``, or an
            ``out`` of the wrong shape.
        TypeError
            An argument that is not a range or a sequence of ints, or an
            ``out`` that is not a writeable C-contiguous float32 ndarray.
        """
        req = self._request(pixels, samples, dims)
        shape = (len(req.pixels), len(req.samples), req.n_dims)
        nbytes = 4 * math.prod(shape)
        if nbytes > self.max_bytes:
            raise ValueError(
                f"request of {shape[0]} x {shape[1]} x {shape[2]} float32 values needs {_fmt_bytes(nbytes)}, "
                f"over the memory limit of {_fmt_bytes(self.max_bytes)}; ask for fewer pixels at a time, "
                f"or raise the limit with max_bytes= or ${ENV_MAX_BYTES}"
            )
        out = _output(out, shape)
        rows = out.reshape(req.n_rows, req.n_dims)
        step = self._backend.rows_per_chunk(req.n_dims)
        chunks = [(r0, min(r0 + step, req.n_rows)) for r0 in range(0, req.n_rows, step)]
        bar = None
        if progress and len(chunks) > 1:
            from tqdm.auto import tqdm

            bar = tqdm(total=len(chunks), desc=f"pyoa {self.name}", unit="chunk")

        def fill(chunk):
            r0, r1 = chunk
            self._backend.fill(req, r0, r1, rows[r0:r1])
            if bar is not None:
                bar.update()

        # Backends whose fill runs on the host without a lock (NumPy releases
        # the GIL inside its ufuncs) fill chunks on every core; chunks write
        # disjoint rows of `out`, so no further synchronisation is needed.
        workers = min(len(chunks), os.cpu_count() or 1) if self._backend.parallel_chunks else 1
        try:
            if workers > 1:
                with ThreadPoolExecutor(workers) as pool:
                    list(pool.map(fill, chunks))
            else:
                for chunk in chunks:
                    fill(chunk)
        finally:
            if bar is not None:
                bar.close()
        return out

    def value(self, pixel: int, i: int, j: int) -> float:
        """One value, computed by the pure-Python reference.

        Returns the float32 value ``x(pixel, i, j)`` as a Python float; it has
        the same bits as the corresponding entry of :meth:`generate`.
        """
        pixel = _int("pixel", pixel, 0, MAX_UINT32)
        i = _int("i", i, 0, self.spp - 1)
        j = _int("j", j, 0, self.dims - 1)
        p = reference.pixel_seed(self.seed, pixel)
        return float(self._construction.call("pyoa.reference", i, j, self.params, p, self.offset, self.jitter))


def _output(out, shape: tuple[int, ...]) -> np.ndarray:
    """``out`` checked as the destination of a result of ``shape``, or a new array."""
    if out is None:
        return np.empty(shape, dtype=np.float32)
    if not isinstance(out, np.ndarray):
        raise TypeError(f"out must be a numpy.ndarray, got {type(out).__name__}")
    if out.dtype != np.float32 or not out.flags.c_contiguous or not out.flags.writeable:
        raise TypeError(
            f"out must be a writeable C-contiguous float32 array, got dtype={out.dtype}, "
            f"C-contiguous={out.flags.c_contiguous}, writeable={out.flags.writeable}"
        )
    if out.shape != shape:
        raise ValueError(f"out has shape {out.shape}; this request needs {shape} (pixels, samples, dims)")
    return out


def sampler(name: str, *, spp: int, dims: int, seed: int = 0, offset: str | None = None, jitter: float = 1.0,
            strength: int | None = None, backend: str | None = None, device: str | None = None,
            max_bytes: int | str | None = None) -> Sampler:
    """Create a sampler: an orthogonal array or one of the paper's comparison samplers.

    Parameters
    ----------
    name : str
        Orthogonal arrays: ``"bose"`` (strength 2, ``spp = s**2``, s+1
        dimensions per block), ``"bush"`` (strength t, ``spp = s**t``),
        ``"cmjnd"`` (``spp = s**t`` for any ``s >= 2``, t dimensions per
        block), ``"addelman-kempthorne"``, ``"bose-bush"`` (``spp = 2 s**2``).
        Comparison samplers: ``"random"``, ``"jittered2d"``, ``"cmj2d"``,
        ``"sobol02"`` (padded pairs), ``"halton"`` and ``"sobol"``
        (high-dimensional, Owen-scrambled). See :func:`samplers`,
        :func:`valid_spp` and ``docs/samplers.md``.
    spp : int
        Samples per pixel. An invalid count raises a ValueError naming the
        nearest valid ones.
    dims : int
        Number of dimensions, ``1 <= dims <= 2**20``. Dimensions past one
        block come from independently randomized copies of the array.
    seed : int
        User seed in ``[0, 2**32)``; out-of-range seeds are refused, not reduced.
        Pixel ``k`` uses the array seed ``pyoa.reference.pixel_seed(seed, k)``.
    offset : {"cmj", "mj", "j", "centered"}, optional
        OA samplers only (default ``"cmj"``; the comparison samplers refuse
        it). Where points go inside their coarse strata (SPEC section 4): ``cmj``
        (correlated multi-jittered, the paper's "Ours") and ``mj`` are 1D Latin
        hypercubes; ``j`` jitters each coarse cell independently; ``centered``
        puts every point at the centre of its coarse stratum (up to jitter).
    jitter : float
        Jitter amount in [0, 1]: 1 = uniform in the fine cell, 0 = its centre.
        OA samplers, ``jittered2d`` and ``cmj2d`` only (the others refuse
        anything but 1).
    strength : int, optional
        ``bush`` and ``cmjnd``: t, so ``spp = s**t``. Default: the largest
        ``t <= dims`` (``t >= 2``) for which ``spp`` is a perfect t-th power.
    backend : {"opencl", "numpy"}, optional
        Default: ``$PYOA_BACKEND``, else OpenCL if usable, else NumPy with a
        warning (see :mod:`pyoa.backends`).
    device : str, optional
        OpenCL device selector (``"gpu"``, ``"1:0"``, ``"nvidia"``...); default
        ``$PYOA_OPENCL_DEVICE``, else PoCL's CPU device.
    max_bytes : int or str, optional
        Largest array :meth:`Sampler.generate` may return (``"4G"``, ``0.25``
        of RAM...); default ``$PYOA_MAX_BYTES``, else half the physical memory.

    Examples
    --------
    >>> import pyoa
    >>> smp = pyoa.sampler("bose", spp=121, dims=8, seed=7)
    >>> x = smp.generate(pixels=range(4))
    >>> x.shape, x.dtype
    ((4, 121, 8), dtype('float32'))
    >>> smp.value(pixel=3, i=17, j=5) == x[3, 17, 5]
    True
    """
    return Sampler(name, spp=spp, dims=dims, seed=seed, offset=offset, jitter=jitter, strength=strength,
                   backend=backend, device=device, max_bytes=max_bytes)
