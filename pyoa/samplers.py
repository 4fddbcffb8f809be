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
from collections.abc import Mapping, Sequence, Set
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from . import catalogue
from .backends import choose
from .catalogue.entries import MAX_DIMS, MAX_SPP, MAX_UINT32, check_int
from .catalogue.request import Request
from .util.units import format_bytes

ENV_MAX_BYTES = "PYOA_MAX_BYTES"
_UNITS = {"": 1, "k": 1 << 10, "m": 1 << 20, "g": 1 << 30, "t": 1 << 40}


#: The image given to a sampler that needs one (``zsobol``) where its pixels
#: are only independent trials (the analyses, plots, the qmc engine, ``pyoa
#: points`` without ``--resolution``): the largest, 65536 x 65536, so that
#: every uint32 pixel index is one of its pixels (row-major).
TRIAL_RESOLUTION = (1 << 16, 1 << 16)


def trial_options(name: str, options: dict) -> dict:
    """``options`` (keyword arguments of :func:`sampler`) with
    ``resolution=TRIAL_RESOLUTION`` added for a sampler that needs an image
    and was given none (:data:`TRIAL_RESOLUTION`)."""
    if options.get("resolution") is None and catalogue.get(name).needs_resolution:
        return {**options, "resolution": TRIAL_RESOLUTION}
    return options


def samplers() -> dict[str, str]:
    """The sampler names :func:`sampler` accepts, each with a one-line description; a sampler that
    pbrt-v4 or Mitsuba 3 users know by another name says so (``"also: independent (pbrt-v4, Mitsuba
    3)"``), and that name is accepted too (:data:`pyoa.catalogue.ALIASES`)."""
    out = {}
    for name, c in catalogue.SAMPLERS.items():
        also = [f"{a} ({catalogue.ALIASES[a][1]})" for a in catalogue.aliases_of(name)]
        out[name] = c.description + (f"; also: {', '.join(also)}" if also else "")
    return out


#: cgroup files that hold a container's memory limit (v2, then v1); "max" or
#: a huge number means none.
_CGROUP_LIMITS = ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes")


def _physical_memory() -> int:
    """The memory this process may use: the physical memory, or less where a
    container's cgroup limit or an address-space limit (``ulimit -v``,
    ``RLIMIT_AS``: what is left of it beyond the current ``VmSize``) says so.
    A default sized from the physical memory alone let a request pass the
    size check and then fail with ``MemoryError`` under such a limit."""
    try:
        found = [os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")]
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        found = [8 << 30]
    for path in _CGROUP_LIMITS:
        try:
            text = Path(path).read_text().strip()
        except OSError:
            continue
        if text.isdigit() and int(text) < 1 << 60:
            found.append(int(text))
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
        if soft != resource.RLIM_INFINITY:
            with open("/proc/self/status") as status:
                vm = next((int(line.split()[1]) * 1024 for line in status if line.startswith("VmSize:")), 0)
            found.append(max(soft - vm, 1 << 20))
    except (ImportError, OSError, ValueError):  # pragma: no cover - non-Linux
        pass
    return min(found)


#: What :func:`parse_bytes` accepts, for its error messages.
_BYTES_FORMS = ("an int of bytes (4000000000), a whole number string ('100', '1e9'), a size with a unit "
                "K, M, G or T, optionally followed by B or iB (powers of 1024: '4G', '512MiB', '1.5GB'), "
                "or a fraction of RAM in (0, 1] as a float or a string with a decimal point (0.25, '0.5')")
_SIZE = re.compile(
    r"\s*(?P<num>(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)\s*"
    r"(?:(?P<unit>[kKmMgGtT])(?:i?[bB])?|(?P<b>[bB]))?\s*"
)


def _fraction_of_ram(value: float, name: str, text) -> int:
    if not (math.isfinite(value) and 0 < value <= 1):
        raise ValueError(f"{name}={text!r}: a number with a decimal point (or a float) is a fraction of RAM and "
                         f"must be in (0, 1]; for a size in bytes write a whole number or a unit, e.g. '4G'")
    return _at_least_one_byte(int(value * _physical_memory()), name, text)


def _at_least_one_byte(nbytes: int, name: str, text) -> int:
    if nbytes < 1:
        raise ValueError(f"{name}={text!r} is less than one byte; give at least 1 (e.g. '1M')")
    return nbytes


def _parse_size(text: str, name: str) -> int:
    """A memory size string (see :func:`parse_bytes`) in bytes."""
    m = _SIZE.fullmatch(text)
    if not m:
        raise ValueError(f"cannot read a memory size from {name}={text!r}; valid: {_BYTES_FORMS}")
    value = float(m["num"])  # finite unless the exponent is absurd ('1e999')
    if not math.isfinite(value):
        raise ValueError(f"{name}={text!r} is not a finite size; valid: {_BYTES_FORMS}")
    if m["unit"] or m["b"]:
        nbytes = value * _UNITS[(m["unit"] or "").lower()]
        if not math.isfinite(nbytes):
            raise ValueError(f"{name}={text!r} is not a finite size; valid: {_BYTES_FORMS}")
        return _at_least_one_byte(int(nbytes), name, text)
    if "." in m["num"]:
        return _fraction_of_ram(value, name, text)
    if value != int(value):  # '5e-1': neither whole bytes nor written as a fraction
        raise ValueError(f"{name}={text!r} is not a whole number of bytes; valid: {_BYTES_FORMS}")
    return _at_least_one_byte(int(value), name, text)


def parse_bytes(value, name: str = "max_bytes") -> int:
    """A memory size in bytes, from the forms ``max_bytes=`` and ``$PYOA_MAX_BYTES`` accept.

    Parameters
    ----------
    value : int, float or str
        - an int: that many bytes (``4_000_000_000``);
        - a string of a whole number, optionally in exponent form: bytes
          (``"100"``, ``"1e9"``);
        - a string of a number with a unit ``K``, ``M``, ``G`` or ``T``
          (powers of 1024), optionally followed by ``B`` or ``iB``
          (``"4G"``, ``"512MiB"``, ``"1.5GB"``), or with ``B`` alone (``"100B"``);
        - a float, or a string with a decimal point: a fraction of the
          physical memory, in ``(0, 1]`` (``0.25``, ``"0.5"``, ``"1.0"``).
    name : str
        What the value is, for error messages (``"max_bytes"``,
        ``"$PYOA_MAX_BYTES"``).

    Returns
    -------
    int
        At least 1.

    Raises
    ------
    ValueError
        Anything else, with the valid forms: ``"1.01"`` (neither whole bytes
        nor a fraction), ``"e"``, ``"-1"``, non-finite values (``"1e999"``,
        ``float("inf")``), fractions outside ``(0, 1]``, sizes under one byte.
    TypeError
        A value that is neither an int, a float nor a str (bools included).
    """
    if isinstance(value, str):
        return _parse_size(value, name)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be an int, a float or a str, got {type(value).__name__} {value!r}; "
                        f"valid: {_BYTES_FORMS}")
    if isinstance(value, numbers.Integral):
        return _at_least_one_byte(int(value), name, value)
    return _fraction_of_ram(float(value), name, value)


def default_max_bytes() -> int:
    """``$PYOA_MAX_BYTES`` if set (see :func:`parse_bytes`), else half of the
    memory this process may use (the physical memory, or a cgroup or
    ``RLIMIT_AS`` limit below it)."""
    env = os.environ.get(ENV_MAX_BYTES)
    return parse_bytes(env, f"${ENV_MAX_BYTES}") if env else _physical_memory() // 2


_int = check_int  # the checker of every count argument (pyoa.analysis uses it too)


#: Bytes per index of a request: pixels, samples and dims are held as uint32.
INDEX_BYTES = 4

#: Most chunks of one :meth:`Sampler.to_dask` array. Its graph is one lazy
#: layer whatever the count, but Dask itself keeps every chunk's size and
#: offset (about 60 bytes a chunk: 3 s and 0.5 GB at 10**7 chunks), and
#: computing the whole array makes a task of about 1 KB per chunk on the
#: scheduler; a million chunks (about 0.5 s and 64 MB to build) is far more
#: than any useful chunking of the values and far less than a machine's
#: memory.
MAX_DASK_CHUNKS = 10**6
#: The axes of a :meth:`Sampler.generate` result, as error messages name them.
_AXES = ("pixels", "samples", "dims")
_CHUNK_FORMS = ("valid chunks: 'auto', a size such as '64MiB', an int >= 1 for every axis, or one entry per axis "
                "(pixels, samples, dims) as a 3-tuple or a dict {axis number: entry}, each entry an int >= 1, -1 or "
                "None (the whole axis), 'auto', or a tuple of chunk sizes (ints >= 1) adding up to the axis length")


def _index_kind_error(name: str, value) -> TypeError:
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        hint = f"e.g. [{value}] or range({value})" if value >= 0 else "e.g. [3] or range(4)"
    else:
        hint = "e.g. [3] or range(4)"
    why = " (a set or dict has no order)" if isinstance(value, (Set, Mapping)) else ""
    return TypeError(f"{name} must be a range or a sequence of ints (a list, a tuple or a 1-D integer array), "
                     f"{hint}; got {type(value).__name__}{why}")


def _index_length(name: str, value, size: int) -> int:
    """How many indices ``value`` names, after checking its kind (and a range's
    bounds), without building anything: requests are size-checked first."""
    if isinstance(value, range):
        # Check the end points, not len(): len() of a range with 2**63 or
        # more elements raises OverflowError. In-bounds end points bound the
        # length by `size`.
        if value and not (0 <= min(value[0], value[-1]) and max(value[0], value[-1]) < size):
            raise ValueError(f"{name} must lie in [0, {size}), got {value}")
        return len(value)
    if isinstance(value, np.ndarray):
        if value.ndim == 0:
            raise _index_kind_error(name, value[()])
        if value.ndim != 1:
            raise ValueError(f"{name} must be one-dimensional, got an array of shape {value.shape}")
        return len(value)
    if isinstance(value, (str, bytes, bytearray)) or not isinstance(value, Sequence):
        if hasattr(value, "__array__") and not np.isscalar(value):  # array-likes: pandas, xarray...
            return _index_length(name, np.asarray(value), size)
        raise _index_kind_error(name, value)
    return len(value)


def _checked_items(name: str, items) -> None:
    """Raise for the first entry of a flat sequence that is not an integer."""
    if all(type(v) is int for v in items):  # the common case, fast
        return
    for k, v in enumerate(items):
        if isinstance(v, (Sequence, np.ndarray)) and not isinstance(v, (str, bytes)):
            raise ValueError(f"{name} must be one-dimensional (a flat sequence of ints), "
                             f"got a {type(v).__name__} at position {k}")
        # NumPy registers timedelta64 as an integer type; it is a duration, not an index
        if isinstance(v, (bool, np.bool_, np.timedelta64)) or not isinstance(v, numbers.Integral):
            raise TypeError(f"{name} must hold integers, got {type(v).__name__} {v!r} at position {k}")


def _in_bounds(name: str, lo: int, hi: int, size: int) -> None:
    if lo < 0 or hi >= size:
        raise ValueError(f"{name} must lie in [0, {size}), got {lo if lo < 0 else hi}")


def _range_indices(value: range) -> np.ndarray:
    """A checked range as uint32, built in place (no int64 temporary: a large
    pixel range would need twice the memory the size check allowed for)."""
    n = len(value)
    out = np.arange(n, dtype=np.uint32)
    if value.step > 0:  # every start + k * step is a valid uint32, so no step wraps
        out *= np.uint32(value.step)
        out += np.uint32(value.start)
    elif n:
        out *= np.uint32(-value.step)
        np.subtract(np.uint32(value.start), out, out=out)
    return out


def _indices(name: str, value, size: int) -> np.ndarray:
    """Validate a range or a flat sequence of ints in ``[0, size)``; returns uint32.

    Raises TypeError for anything that is not a range or a sequence of
    integers (bools, floats, strings, sets, dicts, datetime values, a bare
    int) and ValueError for nested sequences and out-of-range entries, each
    naming ``name``.
    """
    _index_length(name, value, size)
    if isinstance(value, range):
        return _range_indices(value)
    if not isinstance(value, np.ndarray) and not isinstance(value, Sequence):
        value = np.asarray(value)  # an array-like (see _index_length)
    if isinstance(value, np.ndarray) and value.dtype != object:
        if value.dtype.kind not in "iu":  # "m" (timedelta64) is an integer subtype to NumPy
            raise TypeError(f"{name} must hold integers, got an array of dtype {value.dtype}")
        if value.size == 0:
            return np.zeros(0, np.uint32)
        _in_bounds(name, int(value.min()), int(value.max()), size)
        return value.astype(np.uint32)
    items = value.tolist() if isinstance(value, np.ndarray) else value
    if len(items) == 0:
        return np.zeros(0, np.uint32)
    _checked_items(name, items)
    _in_bounds(name, int(min(items)), int(max(items)), size)
    return np.fromiter(items, dtype=np.uint32, count=len(items))


class Sampler:
    """A sampler: ``x(pixel, i, j)`` for every pixel, sample and dimension.

    Orthogonal-array samplers (``bose``, ``bush``, ``cmjnd``,
    ``addelman-kempthorne``, ``bose-bush``), the paper's comparison
    samplers (``random``, ``jittered2d``, ``cmj2d``, ``sobol02``, ``halton``,
    ``sobol``) and pbrt-v4's ``zsobol`` (Z-order Sobol, blue-noise error
    across pixels; needs ``resolution``) and ``pmj02`` (progressive
    multi-jittered (0,2)), pyoa's progressive ``faure`` (Owen-scrambled
    Faure (0,s)-sequences: orthogonal arrays at every ``b**m``, any count)
    and ``zfaure`` (one Faure sequence ordered across the image: blue-noise
    error in every dimension of a block; needs ``resolution``) share this class, its API and its bit-exactness guarantees.

    Create one with :func:`sampler`. Immutable (setting or deleting an
    attribute raises AttributeError: make a new sampler instead) and safe to
    share between threads. It pickles and deep-copies as its parameters: the
    copy, in this process or a worker, opens its own backend (the same
    backend name and device selector) and gives the same bits.

    Attributes
    ----------
    name : str
        Sampler name (``"bose"``, ``"sobol"``...; see :func:`samplers`).
    spp : int
        Samples per pixel, N.
    dims : int
        Number of dimensions.
    s : int
        Coarse strata per axis (comparison samplers: see :mod:`pyoa.catalogue.baselines`).
    strength : int
        Strength t: every t-dimensional projection of a block is stratified
        (2 for the padded comparison samplers, 0 for random, halton and sobol).
    block_dims : int
        Dimensions per independently randomized block (s+1 for Bose, t for CMJND,
        2 for padded samplers); dimensions past it come from re-randomized copies
        (docs/spec.md section 6).
    offset : str or None
        Offset style of an OA sampler: ``"cmj"`` (default), ``"mj"``, ``"j"`` or
        ``"centered"``; None for the comparison samplers.
    jitter : float
        Jitter amount in [0, 1] (as float32); 1 for samplers without one.
    seed : int
        User seed (uint32).
    resolution : tuple of int or None
        ``(width, height)`` of the image for the samplers whose values depend
        on where a pixel lies in it (``zsobol``, ``zfaure``), else None.
    base : int or None
        The prime digit base of ``faure`` or ``zfaure`` (given or its default), else None.
    n_pixels : int
        How many pixel indices are valid: ``width * height`` with a
        resolution (pixel ``y * width + x``), else ``2**32``.
    backend : str
        ``"opencl"`` or ``"numpy"``; ``device`` describes what it runs on.
    max_bytes : int
        Largest request :meth:`generate` accepts, in bytes: its float32
        values plus its uint32 index arrays.
    """

    def __init__(self, name, *, spp, dims, seed=0, offset=None, jitter=1.0, strength=None, resolution=None,
                 base=None, backend=None, device=None, max_bytes=None):
        construction = catalogue.get(name)
        spp = _int("spp", spp, 1, MAX_SPP)
        dims = _int("dims", dims, 1, MAX_DIMS)
        seed = _int("seed", seed, 0, MAX_UINT32)
        if strength is not None:
            strength = _int("strength", strength, 1)
        offset = _offset(construction, offset)
        jitter = _jitter(construction, jitter)
        params = construction.with_resolution(construction.resolve(spp, dims, strength), resolution)
        params = construction.with_base(params, base)
        max_bytes = default_max_bytes() if max_bytes is None else parse_bytes(max_bytes, "max_bytes")
        impl = choose(backend, device)
        shown = construction.choice(params)
        # the keywords that give these parameters again: a resolved strength, base or image
        resolved = construction.arguments(params)
        # Every attribute is set here and never again (see __setattr__).
        fields = dict(
            _construction=construction, name=construction.name, spp=spp, dims=dims, seed=seed, offset=offset,
            jitter=jitter, params=params, s=shown.s, strength=shown.strength, block_dims=shown.block_dims,
            resolution=resolved.get("resolution"), n_pixels=construction.pixel_count(params),
            base=resolved.get("base"), _resolved=resolved,
            max_bytes=max_bytes, _backend=impl, _device_selector=device, backend=impl.name,
            device=impl.describe(),
        )
        for key, value in fields.items():
            object.__setattr__(self, key, value)

    def __setattr__(self, key, value):
        raise AttributeError(f"cannot set {key!r}: samplers are immutable; make a new one with "
                             f"pyoa.sampler(...)")

    def __delattr__(self, key):
        raise AttributeError(f"cannot delete {key!r}: samplers are immutable; make a new one with "
                             f"pyoa.sampler(...)")

    def _arguments(self) -> dict:
        """The keyword arguments of :func:`sampler` that make this sampler again."""
        return dict(
            spp=self.spp, dims=self.dims, seed=self.seed, offset=self.offset, jitter=self.jitter,
            # the resolved strength, base and image, so the copy cannot resolve others
            **{"strength": None, "resolution": None, "base": None, **self._resolved},
            backend=self.backend, device=self._device_selector, max_bytes=self.max_bytes,
        )

    def __reduce__(self):
        # An OpenCL backend holds a context, queue and program that cannot be
        # pickled: a sampler travels as its parameters, and the other side
        # (a worker process) opens its own device. The backend is named
        # explicitly, so the copy never silently falls back to another one.
        return (_rebuild, (self.name, self._arguments()))

    def __repr__(self) -> str:
        detail = self._construction.detail(self.params)
        return (
            f"Sampler({self.name!r}, spp={self.spp}, dims={self.dims}, seed={self.seed}"
            f"{f', offset={self.offset!r}' if self.offset is not None else ''}"
            f"{f', jitter={self.jitter:g}' if self._construction.jittered else ''}"
            f"{f', resolution={self.resolution}' if self.resolution else ''}"
            f"{f', base={self.base}' if self.base else ''}{f'; {detail}' if detail else ''}; "
            f"backend={self.backend!r} on {self.device})"
        )

    def _request(self, pixels, samples, dims) -> Request:
        pixels, samples, dims = self._checked_size(pixels, samples, dims)
        return Request(
            construction=self._construction,
            params=self.params,
            seed=self.seed,
            offset=self.offset,
            jitter=self.jitter,
            pixels=_indices("pixels", pixels, self.n_pixels),
            samples=_indices("samples", samples, self.spp),
            dims=_indices("dims", dims, self.dims),
        )

    def _checked_size(self, pixels, samples, dims) -> tuple:
        """The index arguments with their defaults, once the whole request (its
        float32 values and its uint32 index arrays) is known to fit in
        ``max_bytes``: checked before anything is built, so a huge range is
        refused at once instead of filling memory first."""
        pixels = [0] if pixels is None else pixels
        samples = range(self.spp) if samples is None else samples
        dims = range(self.dims) if dims is None else dims
        n_p = _index_length("pixels", pixels, self.n_pixels)
        n_s = _index_length("samples", samples, self.spp)
        n_d = _index_length("dims", dims, self.dims)
        nbytes = 4 * n_p * n_s * n_d + INDEX_BYTES * (n_p + n_s + n_d)
        if nbytes > self.max_bytes:
            raise ValueError(
                f"request of {n_p} x {n_s} x {n_d} float32 values needs {format_bytes(nbytes)} (with its "
                f"index arrays), over the memory limit of {format_bytes(self.max_bytes)}; ask for fewer pixels "
                f"at a time, or raise the limit with max_bytes= or ${ENV_MAX_BYTES}"
            )
        return pixels, samples, dims

    def generate(self, pixels=None, samples=None, dims=None, *, out: np.ndarray | None = None,
                 progress: bool = False) -> np.ndarray:
        """Generate a block of values in bulk.

        Parameters
        ----------
        pixels : range or sequence of int, optional
            Pixel indices in ``[0, 2**32)`` (``[0, width * height)`` for a
            sampler with a ``resolution``, row-major); default ``[0]``.
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
            An index out of range, a nested sequence, a request larger than
            ``max_bytes`` (its values, 4 bytes each, plus its index arrays, 4
            bytes per index; checked before anything is allocated), or an
            ``out`` of the wrong shape.
        TypeError
            An argument that is not a range or a sequence of ints (a bare int
            such as ``4``: write ``[4]`` or ``range(4)``; a set; floats, bools,
            datetime values), or an ``out`` that is not a writeable
            C-contiguous float32 ndarray.
        """
        req = self._request(pixels, samples, dims)
        shape = (len(req.pixels), len(req.samples), req.n_dims)
        out = _output(out, shape)
        rows = out.reshape(req.n_rows, req.n_dims)
        step = self._backend.rows_per_chunk(req.n_dims)
        chunks = [(r0, min(r0 + step, req.n_rows)) for r0 in range(0, req.n_rows, step)]
        bar = None
        if progress and len(chunks) > 1:
            from .util.progress import bar as progress_bar

            bar = progress_bar(total=len(chunks), desc=f"pyoa {self.name}", unit="chunk")

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

    def to_dask(self, pixels=None, *, samples=None, dims=None, chunks="auto"):
        """The values of :meth:`generate` as a lazy Dask array, one :meth:`generate` call per chunk.

        For point sets larger than memory, or wanted where they are used: the
        array can be written straight to disk (``arr.to_zarr(...)``), kept in
        a Dask cluster's memory (``arr.persist()``), or reduced chunk by
        chunk. Each chunk is computed where it is needed, by the worker that
        needs it: the graph is one lazy layer (a chunk's task is made only
        when a computation needs that chunk) and one key holding the
        sampler's parameters (it pickles as them, see :class:`Sampler`) and
        the index arguments, never sample values shipped from the client.
        A worker process rebuilds the
        sampler with the same backend name and device selector, so an
        OpenCL sampler needs OpenCL on the workers.

        Parameters
        ----------
        pixels : range or sequence of int, optional
            Pixel indices, as in :meth:`generate`; default ``[0]``.
        samples : range or sequence of int, optional
            Sample indices in ``[0, spp)``; default every sample.
        dims : range or sequence of int, optional
            Dimensions in ``[0, dims)``; default every dimension.
        chunks : int, str, tuple or dict
            Chunk sizes over the three axes ``(pixels, samples, dims)``, in
            the forms :func:`dask.array.core.normalize_chunks` reads: an int
            ``>= 1`` for every axis; a size in bytes (``"64MiB"``); or one
            entry per axis as a 3-tuple, or a dict ``{axis number: entry}``
            (the others whole), each entry an int ``>= 1``, ``-1`` or None
            (the whole axis), ``"auto"``, or a tuple of chunk sizes (ints
            ``>= 1``) adding up to the axis length. At most
            :data:`MAX_DASK_CHUNKS` chunks in all. ``"auto"`` (default): chunks of about Dask's
            ``array.chunk-size`` (128 MiB unless configured; at most half of
            ``max_bytes``), each whole ``samples x dims`` rows of a run of
            pixels where one row fits, else split along samples, then dims.

        Returns
        -------
        dask.array.Array
            float32 of shape ``(len(pixels), len(samples), len(dims))``; every
            chunk has the bits :meth:`generate` gives for the same indices,
            whatever the chunking.

        Raises
        ------
        ValueError, TypeError
            At once, not at compute time: the errors :meth:`generate` raises
            for its index arguments; chunks in none of the forms above (a
            chunk size of 0 or below other than -1, a float, sizes that do
            not add up to the axis length, an axis number other than 0, 1,
            2), each message naming the axis and the valid forms; more than
            :data:`MAX_DASK_CHUNKS` chunks (counted before any is listed;
            the message suggests a chunking that fits); or a chunk larger
            than ``max_bytes`` (the limit is per chunk; the whole array may
            be larger).
        ImportError
            Dask is not installed.

        Examples
        --------
        >>> import numpy as np
        >>> import pyoa
        >>> smp = pyoa.sampler("bose", spp=49, dims=8, seed=7, backend="numpy")
        >>> arr = smp.to_dask(pixels=range(10), chunks=(4, 20, -1))
        >>> arr.shape, arr.dtype, arr.numblocks
        ((10, 49, 8), dtype('float32'), (3, 3, 1))
        >>> bool(np.array_equal(arr.compute(), smp.generate(pixels=range(10))))
        True

        A billion pixels (196 GB), computed only where a chunk is used; each
        chunk holds whole ``samples x dims`` rows:

        >>> big = smp.to_dask(pixels=range(10**9))
        >>> big.shape, big.chunksize[1:]
        ((1000000000, 49, 8), (49, 8))
        >>> bool(np.array_equal(big[10**9 - 3:].compute(), smp.generate(pixels=range(10**9 - 3, 10**9))))
        True
        """
        try:
            import dask
            import dask.array as da
            from dask.base import tokenize
            from dask.utils import parse_bytes as dask_bytes
        except ImportError as exc:
            raise ImportError('Sampler.to_dask needs Dask: pip install "dask[distributed]"') from exc

        # generate's defaults and index checks, now and in its order (every
        # argument's kind, then the entries); a range stays a range (a task
        # gets its slice of it), anything else becomes checked uint32
        checks = (("pixels", [0] if pixels is None else pixels, self.n_pixels),
                  ("samples", range(self.spp) if samples is None else samples, self.spp),
                  ("dims", range(self.dims) if dims is None else dims, self.dims))
        shape = tuple(_index_length(axis, value, size) for axis, value, size in checks)
        axes = [value if isinstance(value, range) else _indices(axis, value, size) for axis, value, size in checks]

        auto_limit = min(dask_bytes(dask.config.get("array.chunk-size")), max(self.max_bytes // 2, 1))
        if isinstance(chunks, str) and chunks == "auto":
            row = 4 * shape[1] * shape[2]
            if 0 in shape:  # nothing to split (and Dask's "auto" divides by the row size)
                spec = (-1, -1, -1)
            elif row <= auto_limit:
                spec = ("auto", -1, -1)
            else:
                spec = (1, "auto", -1) if 4 * shape[2] <= auto_limit else (1, 1, "auto")
            chunks = _dask_chunks(spec, shape, auto_limit, self.max_bytes, auto_limit, given="auto")
        else:
            chunks = _dask_chunks(chunks, shape, None, self.max_bytes, auto_limit)
        largest = [max(c, default=0) for c in chunks]
        nbytes = 4 * math.prod(largest) + INDEX_BYTES * sum(largest)
        if nbytes > self.max_bytes:
            raise ValueError(
                f"a chunk of {' x '.join(map(str, largest))} float32 values needs {format_bytes(nbytes)} (with its "
                f"index arrays), over the memory limit of {format_bytes(self.max_bytes)}; ask for smaller chunks, "
                f"or raise the limit with max_bytes= or ${ENV_MAX_BYTES}"
            )

        # One lazy (Blockwise) layer whose task for block (i, j, k) is made
        # only when a computation needs it: a graph of one task per chunk
        # built here took 0.5 GB at a million chunks. The sampler, the index
        # arguments and each axis's chunk offsets are one separate key that
        # every task reads (as dask's from_array holds its array), so a
        # worker receives them once, not once per task.
        name = f"pyoa-{self.name}-" + tokenize(self.name, self._arguments(), *axes, chunks)
        starts = tuple(np.concatenate(([0], np.cumsum(c, dtype=np.int64))) for c in chunks)
        state = dask.delayed((self, tuple(axes), starts), pure=True, traverse=False, name=f"{name}-indices")
        return da.map_blocks(_dask_block, state, chunks=chunks, dtype=np.float32, name=name,
                             meta=np.empty((0, 0, 0), np.float32))

    def value(self, pixel: int, i: int, j: int) -> float:
        """One value, computed by the pure-Python reference.

        Returns the float32 value ``x(pixel, i, j)`` as a Python float; it has
        the same bits as the corresponding entry of :meth:`generate`.
        """
        pixel = _int("pixel", pixel, 0, self.n_pixels - 1)
        i = _int("i", i, 0, self.spp - 1)
        j = _int("j", j, 0, self.dims - 1)
        return float(self._construction.evaluate("reference", i, j, self.params, self.seed, pixel, self.offset,
                                                 self.jitter))


def _rebuild(name: str, arguments: dict) -> Sampler:
    """Unpickle a :class:`Sampler` (see ``Sampler.__reduce__``)."""
    return Sampler(name, **arguments)


def _dask_block(state: tuple, block_id: tuple[int, int, int] | None = None) -> np.ndarray:
    """One chunk of :meth:`Sampler.to_dask`, a task of its graph: ``state``
    is ``(sampler, (pixels, samples, dims), starts)`` (each axis's chunk
    offsets), ``block_id`` the chunk's position (given by Dask)."""
    smp, axes, starts = state
    return smp.generate(*(value[int(s[b]):int(s[b + 1])] for value, s, b in zip(axes, starts, block_id)))


def _chunk_entries(chunks) -> tuple:
    """``chunks`` of :meth:`Sampler.to_dask` as one entry per axis (a dict
    or a 3-sequence entry by entry; anything else is every axis's entry)."""
    if isinstance(chunks, Mapping):
        for key in chunks:
            if isinstance(key, bool) or not isinstance(key, numbers.Integral) or not 0 <= key < len(_AXES):
                raise ValueError(f"chunks {{axis: entry}} needs axis 0 (pixels), 1 (samples) or 2 (dims), got "
                                 f"{key!r}; {_CHUNK_FORMS}")
        return tuple(chunks.get(axis) for axis in range(len(_AXES)))
    if isinstance(chunks, (tuple, list)):
        if len(chunks) != len(_AXES):
            raise ValueError(f"chunks has {len(chunks)} entries, the array 3 axes (pixels, samples, dims); "
                             f"{_CHUNK_FORMS}")
        return tuple(chunks)
    return (chunks,) * len(_AXES)


def _chunk_count(axis: str, entry, n: int) -> int | None:
    """How many chunks ``entry`` makes of an axis of length ``n``, known
    before Dask lists them (None for "auto" or a size in bytes: Dask picks);
    an entry of a kind or value Dask would misread (``0`` divides by zero,
    ``2.5`` is truncated, ``True`` is 1) is refused here."""
    if entry is None:
        return 1
    if isinstance(entry, str):
        return None
    if isinstance(entry, bool) or not isinstance(entry, (numbers.Integral, tuple, list)):
        raise TypeError(f"chunks for the {axis} axis must be an int, None, 'auto' or a tuple of ints, got "
                        f"{type(entry).__name__} {entry!r}; {_CHUNK_FORMS}")
    if isinstance(entry, numbers.Integral):
        if entry == -1:
            return 1
        if entry < 1:
            raise ValueError(f"chunks for the {axis} axis must be >= 1, or -1 for the whole axis, got {entry}; "
                             f"{_CHUNK_FORMS}")
        return max(1, -(-n // int(entry)))
    for size in entry:
        if isinstance(size, bool) or not isinstance(size, numbers.Integral):
            raise TypeError(f"chunk sizes of the {axis} axis must be ints, got {type(size).__name__} {size!r}; "
                            f"{_CHUNK_FORMS}")
    return len(entry)


def _dask_chunks(chunks, shape: tuple[int, int, int], limit: int | None, max_bytes: int, auto_limit: int,
                 given=None) -> tuple[tuple[int, ...], ...]:
    """``chunks`` of :meth:`Sampler.to_dask` as Dask's chunks of ``shape``.

    Dask's own :func:`dask.array.core.normalize_chunks` reads the forms; what
    it lets through is then checked: every chunk an int >= 1 (``(0,)`` for an
    empty axis) and each axis's chunks adding up to its length (Dask keeps
    ``(5, -3, 8)`` as given). The chunks are counted before Dask lists them
    (a list of 4 billion one-pixel chunks would fill the memory): more than
    :data:`MAX_DASK_CHUNKS` is refused with a chunking that fits. ``limit``
    is the size of an "auto" chunk (None: Dask's ``array.chunk-size``),
    ``auto_limit`` that of ``chunks="auto"`` (for the suggestion), ``given``
    what the user wrote (for messages; default ``chunks``).
    """
    import reprlib

    import dask
    from dask.array.core import normalize_chunks
    from dask.utils import parse_bytes as dask_bytes

    given = chunks if given is None else given
    entries = _chunk_entries(chunks)
    counts = [_chunk_count(axis, entry, n) for axis, entry, n in zip(_AXES, entries, shape)]
    if None in counts:  # "auto" chunks of about `limit` bytes each (a size in bytes sets the limit)
        sizes = [e for e in entries if isinstance(e, str) and e != "auto"]
        try:
            size = dask_bytes(sizes[0]) if sizes else limit or dask_bytes(dask.config.get("array.chunk-size"))
        except ValueError as exc:
            raise ValueError(f"chunks={reprlib.repr(given)}: {exc}; {_CHUNK_FORMS}") from None
        if size < 1:
            raise ValueError(f"chunks={reprlib.repr(given)}: a chunk size must be at least 1 byte; {_CHUNK_FORMS}")
        fixed = math.prod(c for c in counts if c is not None)
        _check_chunk_count(max(fixed, -(-4 * math.prod(shape) // size)), given, shape, max_bytes, auto_limit,
                           about=True)
    else:
        _check_chunk_count(math.prod(counts), given, shape, max_bytes, auto_limit)
    try:
        normalized = normalize_chunks(entries, shape, limit=limit, dtype=np.float32)
    except (ValueError, TypeError, ZeroDivisionError) as exc:
        raise ValueError(f"chunks={reprlib.repr(given)}: {str(exc).splitlines()[0]}; {_CHUNK_FORMS}") from None
    for axis, sizes, n in zip(_AXES, normalized, shape):
        if sum(sizes) != n or (n and min(sizes) < 1):
            raise ValueError(f"chunks of the {axis} axis must be ints >= 1 adding up to its length {n}, got "
                             f"{reprlib.repr(sizes)}; {_CHUNK_FORMS}")
    _check_chunk_count(math.prod(map(len, normalized)), given, shape, max_bytes, auto_limit)
    return normalized


def _check_chunk_count(count: int, given, shape: tuple[int, int, int], max_bytes: int, auto_limit: int,
                       about: bool = False) -> None:
    """Refuse more than :data:`MAX_DASK_CHUNKS` chunks (``count``, an
    estimate where ``about``), suggesting a chunking within it: whole
    ``samples x dims`` rows of enough pixels where such a chunk fits
    ``max_bytes``, else ``"auto"`` where it makes few enough."""
    if count <= MAX_DASK_CHUNKS:
        return
    import reprlib

    n_p, n_s, n_d = shape
    per = -(-n_p // MAX_DASK_CHUNKS)
    nbytes = 4 * per * n_s * n_d + INDEX_BYTES * (per + n_s + n_d)
    if nbytes <= max_bytes:
        hint = f"use larger chunks, e.g. chunks=({per}, -1, -1) ({format_bytes(nbytes)} each)"
    elif -(-4 * math.prod(shape) // auto_limit) <= MAX_DASK_CHUNKS:
        hint = f"use larger chunks, e.g. chunks='auto' (about {format_bytes(auto_limit)} each)"
    else:
        hint = (f"ask for fewer values per array (this one has {n_p} x {n_s} x {n_d}), or raise the memory limit "
                f"of a chunk with max_bytes= or ${ENV_MAX_BYTES} (now {format_bytes(max_bytes)})")
    raise ValueError(f"chunks={reprlib.repr(given)} makes {'about ' if about else ''}{count:,} chunks of the "
                     f"{n_p} x {n_s} x {n_d} array, over the {MAX_DASK_CHUNKS:,} that Sampler.to_dask allows (Dask "
                     f"keeps every chunk's size and offset, and makes a task of each chunk computed); {hint}")


def _offset(construction, offset):
    """The checked offset style: the sampler's default (``"cmj"`` for the OA
    samplers, None for the others) when not given."""
    if offset is None:
        return construction.default_offset
    if not construction.offsets:
        raise ValueError(f"offset applies to the orthogonal-array samplers only; {construction.name} has none "
                         f"(got offset={offset!r})")
    if not isinstance(offset, str) or offset not in construction.offsets:
        raise ValueError(f"unknown offset {offset!r}; valid: {', '.join(construction.offsets)} "
                         f"(default {construction.default_offset!r})")
    return offset


def _jitter(construction, jitter) -> float:
    """The checked jitter amount, rounded to float32 as the kernels use it."""
    if isinstance(jitter, bool) or not isinstance(jitter, numbers.Real):
        raise TypeError(f"jitter must be a real number in [0, 1], got {type(jitter).__name__}")
    if not 0.0 <= float(jitter) <= 1.0:  # NaN fails too
        raise ValueError(f"jitter must be in [0, 1] (1 = full jitter, 0 = cell centres), got {jitter}")
    if not construction.jittered and float(jitter) != 1.0:
        raise ValueError(f"{construction.name} has no jitter amount (got jitter={jitter}); it applies to the "
                         "orthogonal-array samplers, jittered2d and cmj2d")
    return float(np.float32(jitter))


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
            strength: int | None = None, resolution: tuple[int, int] | None = None, base: int | None = None,
            backend: str | None = None, device: str | None = None,
            max_bytes: int | float | str | None = None) -> Sampler:
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
        (high-dimensional, Owen-scrambled), and pbrt-v4's ``"zsobol"``
        (``spp = 2**k``; every pixel's samples of a pair a (0,k,2)-net,
        blue-noise error across the image; needs `resolution`) and
        ``"pmj02"`` (progressive multi-jittered (0,2), ``spp = 2**k`` up to
        ``2**16``, from a table built once and cached). pyoa's progressive
        orthogonal arrays: ``"faure"`` (Owen-scrambled Faure (0,s)-sequence
        in a prime base, any ``spp``: every aligned block of ``b**m`` samples
        a (0,m,b)-net, so ``b**2`` samples are a strength-2 array and a
        render can stop and continue at any count) and ``"zfaure"`` (one
        such sequence handed out along a scrambled Morton order of the image,
        ``spp = b**m`` with ``m >= 2``: each pixel a (0,m,b)-net, each tile of
        ``b x b`` pixels a (0,m+2,b)-net, so the error is blue noise in every
        dimension of a block; needs `resolution`). See :func:`samplers`,
        :func:`valid_spp` and ``docs/samplers.md``.
    spp : int
        Samples per pixel. An invalid count raises a ValueError naming the
        nearest valid ones.
    dims : int
        Number of dimensions, ``1 <= dims <= 2**20``. Dimensions past one
        block come from independently randomized copies of the array, each
        read in its own random order of the rows (docs/spec.md section 6).
    seed : int
        User seed in ``[0, 2**32)``; out-of-range seeds are refused, not reduced.
        Pixel ``k`` uses the array seed ``pyoa.reference.pixel_seed(seed, k)``.
    offset : {"cmj", "mj", "j", "centered"}, optional
        OA samplers only (default ``"cmj"``; the comparison samplers refuse
        it). Where points go inside their coarse strata (docs/spec.md section 4): ``cmj``
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
    resolution : (int, int), optional
        ``(width, height)`` of the image, required by the samplers whose
        values depend on where a pixel lies in the image (``zsobol``,
        ``zfaure``: their Morton orders span the image) and refused by the
        others. Pixels are
        then numbered row-major, ``pixel = y * width + x`` (as pyoa's
        renderer numbers them), and must be below ``width * height``.
    base : int, optional
        ``faure`` and ``zfaure`` only (the others refuse it): the digit base,
        a prime in ``[2, 4093]``; ``b`` dimensions per block, every ``b**m``
        samples a net. ``faure``'s default: the largest prime ``b`` with
        ``b**2 <= spp``, or the smallest prime ``>= dims`` if smaller (see
        :class:`pyoa.catalogue.faure.Faure`); a pixel's samples do not depend
        on ``spp`` for a given base: give it to continue a sequence at another
        count. ``zfaure``'s count ``b**m`` fixes it.
    backend : {"opencl", "numpy"}, optional
        Default: ``$PYOA_BACKEND``, else OpenCL if usable, else NumPy with a
        warning (see :mod:`pyoa.backends`).
    device : str, optional
        OpenCL device selector, a str: ``"P:D"`` (device D of platform P, as
        ``pyoa backends`` lists them), ``"P"`` (device 0 of platform P),
        ``"gpu"``, ``"cpu"``, ``"accelerator"``, or text found in the
        platform or device name (``"nvidia"``); see :mod:`pyoa._opencl.device`.
        Default ``$PYOA_OPENCL_DEVICE`` (same forms), else the first of PoCL's
        CPU device and the others that builds pyoa's kernels.
    max_bytes : int, float or str, optional
        Largest request :meth:`Sampler.generate` accepts (its float32 values
        plus its index arrays): an int of bytes, a string with a unit
        (``"4G"``, ``"512MiB"``), or a fraction of RAM in (0, 1] (``0.25``,
        ``"0.25"``); see :func:`parse_bytes`. Default ``$PYOA_MAX_BYTES``
        (same forms), else half the memory the process may use.

    Examples
    --------
    >>> import pyoa
    >>> smp = pyoa.sampler("bose", spp=121, dims=8, seed=7, backend="numpy")
    >>> x = smp.generate(pixels=range(4))
    >>> x.shape, x.dtype
    ((4, 121, 8), dtype('float32'))

    Every value has the bits of the pure-Python reference:

    >>> bool(smp.value(pixel=3, i=17, j=5) == x[3, 17, 5])
    True
    """
    return Sampler(name, spp=spp, dims=dims, seed=seed, offset=offset, jitter=jitter, strength=strength,
                   resolution=resolution, base=base, backend=backend, device=device, max_bytes=max_bytes)
