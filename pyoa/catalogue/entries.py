"""The catalogue's base types: what every sampler entry is and declares.

A sampler of pyoa is one *entry* of the catalogue (:mod:`pyoa.catalogue`):
an instance of a :class:`Construction` subclass, registered once with
:func:`register`. The entry holds what every backend, test and error message
needs to know about the sampler before a single value is computed (its valid
sample counts and the parameters they mean, of its family's type in
:mod:`pyoa.catalogue.params`) and names its three implementations, which give the same
bits:

``reference``
    the pure-Python function of :mod:`pyoa.reference` (one value at a time);
``numpy``
    its vectorized mirror in :mod:`pyoa._numpy`;
``kernel``
    the name of its C function in the portable headers
    (``kernels/include/pyoa``), which the OpenCL kernels and the C API
    dispatch to by the entry's code (``PYOA_SAMPLER_<NAME>`` of
    ``pyoa/keys.h``, generated from the catalogue).

Each is called as ``function(i, j, *shape_args(params), *seed_args(...),
*options(offset, jitter))``. Registration, with its C function and a case in the
headers' dispatch, is all a new sampler needs: the
backends, the name lists and the conformance and
property suites (``tests/test_catalogue.py``) are built from the registry.

This module imports only the seed hashes below it (:mod:`pyoa.reference`,
:mod:`pyoa.hashes`); the entries (:mod:`pyoa.catalogue.constructions`,
:mod:`pyoa.catalogue.baselines`, :mod:`pyoa.catalogue.faure`) import it and
:mod:`pyoa.catalogue.params`, and :mod:`pyoa.catalogue` imports them, so the
dependencies run one way. Behaviour that depends on an entry's family is a
method of that family's class (:class:`Construction`); :data:`FAMILIES`
groups the entries for listing only.

Limits
------
``N <= 2**24`` samples per pixel: every integer that becomes a float (stratum,
sub-stratum, ``M``, ``s``) is then exact in float32, and every product the
constructions form (``s*s``, ``A_ik*s + A_ij + 1``, ``s**t``) stays below
``2**32``, so the uint32 arithmetic of docs/spec.md section 7 cannot overflow.
"""

from __future__ import annotations

import numbers
import os
import operator
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from ..hashes import pixel_seed as _numpy_pixel_seed
from ..reference.hashes import pixel_seed as _reference_pixel_seed
from ..reference.oa import OFFSETS

#: Kernel codes of the offset styles of docs/spec.md section 4 (OFFSETS,
#: defined with their mathematics in pyoa.reference.oa).
OFFSET_CODES = {name: code for code, name in enumerate(OFFSETS)}

#: Largest sample count per pixel (see the module docstring for why).
MAX_SPP = 2**24
#: Largest number of dimensions of one sampler (one row of values must fit in
#: a single OpenCL buffer even for the largest request).
MAX_DIMS = 2**20
#: Largest user seed, pixel index: both are uint32 (docs/spec.md section 3).
MAX_UINT32 = 2**32 - 1


def check_choice(value, env: str, valid, default: str | None) -> str | None:
    """The option that ``value`` names, else ``$env``, else ``default``: a
    str of ``valid``, checked and in lower case (TypeError for a non-str
    argument, ValueError naming the argument, or the variable, and the valid
    names). The one rule of pyoa's options that an environment variable may
    set (``backend``/``$PYOA_BACKEND``, ``shading``/``$PYOA_SHADING``)."""
    name = env.removeprefix("PYOA_").lower()
    if value is None:
        value = os.environ.get(env) or None
        origin, unset = f"${env}", "unset it"
    else:
        origin, unset = name, "None"
    if value is None:
        return default
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a str or None, got {type(value).__name__}")
    chosen = value.strip().lower()
    if chosen not in valid:
        suffix = f" (or {unset} for automatic)" if default is None else f" (or {unset} for {default})"
        raise ValueError(f"unknown {origin} {value.strip()!r}; valid: {', '.join(valid)}{suffix}")
    return chosen


def check_int(name: str, value, lo: int | None = None, hi: int | None = None, why: str = "") -> int:
    """``value`` as a Python int in ``[lo, hi]``; bools and floats are refused
    (TypeError), out-of-range values too (ValueError), each naming ``name``;
    ``why`` (e.g. ``" (a uint32)"``) follows the range in the message."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__} {value!r}")
    value = int(value)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        rng = f"in [{lo}, {hi}]" if hi is not None else f">= {lo}"
        raise ValueError(f"{name} must be {rng}{why}, got {value}")
    return value


class SppChoice(NamedTuple):
    """One valid sample count of a construction.

    Attributes
    ----------
    spp : int
        Samples per pixel, N.
    s : int
        Coarse strata per axis.
    strength : int
        Strength t of the orthogonal array (every t-dimensional projection of
        one block is stratified into s**t cells).
    block_dims : int
        Dimensions per independently randomized block (docs/spec.md section 6).
    detail : str
        For the comparison samplers, their grid (``"11x11"``, ``"2^7"``) or ``""``.
    """

    spp: int
    s: int
    strength: int
    block_dims: int
    detail: str = ""

    def label(self) -> str:
        """Short text such as ``"121 (s=11)"``, ``"125 (s=5, t=3)"`` or ``"128 (2^7)"``."""
        shape = self.shape()
        return f"{self.spp} ({shape})" if shape else str(self.spp)

    def shape(self) -> str:
        """What :meth:`label` adds to the count: ``"s=11"``, ``"s=5, t=3"``, ``"2^7"`` or ``""``."""
        if self.detail or self.strength == 0:
            return self.detail
        if self.strength == 2:
            return f"s={self.s}"
        return f"s={self.s}, t={self.strength}"


class _Counts(Sequence):
    """The choices for every count ``first .. last``, made on demand (a list
    of all 16.7 million would take gigabytes and seconds)."""

    def __init__(self, first: int, last: int, make):
        self._first, self._len, self._make = first, last - first + 1, make

    def __len__(self):
        return self._len

    def __getitem__(self, k):
        if isinstance(k, slice):
            return [self._make(self._first + i) for i in range(*k.indices(self._len))]
        k = operator.index(k)
        if k < 0:
            k += self._len
        if not 0 <= k < self._len:
            raise IndexError(k)
        return self._make(self._first + k)

    def __eq__(self, other):
        return isinstance(other, Sequence) and len(other) == self._len and all(a == b for a, b in zip(self, other))


def check_resolution(name: str, resolution, largest: int, why: str) -> tuple[int, int]:
    """``resolution`` as ``(width, height)`` ints for sampler ``name``, which
    needs the image (``why`` says what for); TypeError or ValueError saying
    what is valid otherwise: each side in ``[1, largest]``."""
    if resolution is None:
        raise ValueError(f"{name} needs the image: resolution=(width, height), each in [1, {largest}] ({why}; "
                         "pixels are numbered row-major, y * width + x)")
    if isinstance(resolution, (str, bytes)) or not isinstance(resolution, Sequence) or len(resolution) != 2:
        raise TypeError(f"resolution must be a pair (width, height) of ints, got {resolution!r}")
    for what, v in zip(("width", "height"), resolution):
        if isinstance(v, bool) or not isinstance(v, numbers.Integral):
            raise TypeError(f"resolution {what} must be an int, got {type(v).__name__} {v!r}")
        if not 1 <= int(v) <= largest:
            raise ValueError(f"resolution {what} must be in [1, {largest}], got {v}")
    return int(resolution[0]), int(resolution[1])


def nearest(choices: list[SppChoice], spp: int) -> list[SppChoice]:
    """The choices nearest ``spp`` on both sides: those of the largest count
    below it, of ``spp`` itself, and of the smallest count above it (one side
    is empty past the ends), in increasing order of sample count.

    Both sides, not the two closest: the two closest can lie on one side
    (``bose-bush`` near 256 would say 32 and 128, hiding 512)."""
    below = max((c.spp for c in choices if c.spp < spp), default=None)
    above = min((c.spp for c in choices if c.spp > spp), default=None)
    return sorted((c for c in choices if c.spp in (below, spp, above)), key=lambda c: c.spp)


def _labels(choices: list[SppChoice]) -> str:
    return ", ".join(c.label() for c in choices)



class Claim(NamedTuple):
    """One stratification property an entry guarantees, for the property suite.

    ``kind`` names the check (``tests/test_catalogue.py`` implements each):

    ``"oa"``
        ``floor(x * s)`` of every ``strength``-subset of each block of
        ``block_dims`` dimensions is an orthogonal array (every cell equally
        often);
    ``"latin"``
        every dimension is stratified into ``n`` equal intervals, one point
        each;
    ``"grid"``
        every pair ``(2b, 2b + 1)`` has one point in each cell of an
        ``a x c`` grid (``a`` cells along the first axis);
    ``"net"``
        every pair is a (0, k, 2)-net in base 2, ``2**k == n`` (one point in
        each elementary interval of area ``1/n``); with ``prefixes`` every
        power-of-two prefix of the samples is one too.
    """

    kind: str
    n: int = 0
    s: int = 0
    strength: int = 0
    block_dims: int = 0
    a: int = 0
    c: int = 0
    prefixes: bool = False
    #: "net": how many leading pairs are nets (0: every pair)
    pairs: int = 0


class Launch(NamedTuple):
    """How the OpenCL backend computes a sampler value by value
    (``kernels/generate.cl``): the kernel, its arguments between the user
    seed and the sampler's constants, and the Galois field whose tables go
    between them (None: the kernel takes no field)."""

    kernel: str
    args: tuple
    field: int | None = None


class Construction:
    """Base class of the catalogue's entries (see the module docstring).

    Each family has its own subclass, which the entries derive from:
    :class:`pyoa.catalogue.constructions._OA` (the orthogonal arrays, family
    ``"oa"``), :class:`pyoa.catalogue.baselines.Baseline` (the comparison samplers,
    ``"baseline"``) and :class:`pyoa.catalogue.faure.Faure`
    (``"progressive"``). A family's subclass answers, as methods, every
    question whose answer depends on the family (the parameter type of
    :mod:`pyoa.catalogue.params` it resolves to, what a listing shows of it, its
    implementations' arguments, its OpenCL launch), so that no caller tests
    the family: :attr:`family` only groups the entries for listing.

    Entries define :meth:`choices` (every valid sample count),
    :meth:`solve` and :meth:`invalid` (the parameters for a requested count,
    or why there are none) and their implementations: ``reference`` and
    ``numpy`` (functions, as ``staticmethod``) and ``kernel``: the name of
    its C function in the portable headers (``kernels/include/pyoa``), which
    the OpenCL kernels and the C API call. For the orthogonal arrays it is
    the construction's cell (``pyoa_<name>_cell`` of ``pyoa/oa.h``, whose
    signature all cells share; the block rule and the common tail are
    shared, ``pyoa_oa_value``); for the comparison samplers the value
    function (``pyoa_sample_<name>``) that ``pyoa_baseline_value`` of
    ``pyoa/values.h`` calls. Each is dispatched by the entry's ``code``
    (``PYOA_SAMPLER_<NAME>`` in ``pyoa/keys.h``, generated from the
    catalogue).
    """

    name: str
    code: int
    description: str
    reference = None
    numpy = None
    kernel: str = ""
    #: the group the entry is listed in (:func:`pyoa.catalogue.names`):
    #: "oa", "baseline" or "progressive"; set by each family's class
    family: str
    #: the module of :mod:`pyoa._drjit` that may define the entry's Dr.Jit
    #: function (named :attr:`function`); named, not imported: Dr.Jit is optional
    drjit_module: str
    #: whether the Dr.Jit function takes ``located=(P, row)``, the block
    #: seed and row of dimension j (docs/spec.md section 6), which a caller
    #: drawing one dimension after another keeps per block (pyoa.mitsuba)
    drjit_located = False
    #: the offset styles the sampler takes (docs/spec.md section 4), and its default
    offsets: tuple[str, ...] = ()
    default_offset: str | None = None
    #: whether the sampler takes a jitter amount
    jittered = False
    #: whether a sampler needs the image resolution (``resolution=``): its
    #: values depend on where a pixel lies in the image
    needs_resolution = False
    #: whether every prefix of a pixel's samples keeps the sampler's
    #: stratification (its first n samples are as good as any n): a render
    #: may stop after any block of samples (``pyoa render --progressive``)
    progressive = False
    #: why a prefix is not stratified as the whole is, where it is not
    #: (the refusal of ``pyoa render --progressive``)
    why_not_progressive = ""
    #: whether a pixel's i-th sample is the same for every ``spp``: a stopped
    #: progressive render may continue to a larger count (``--resume``)
    spp_invariant = False
    #: whether the sampler has a digit base (``base=``; :meth:`with_base`)
    has_base = False

    def __setattr__(self, key, value):
        # One shared instance per sampler name serves every Sampler: changing
        # it would change every sampler of the process.
        raise AttributeError(f"cannot set {key!r}: the catalogue's constructions are immutable")

    def __delattr__(self, key):
        raise AttributeError(f"cannot delete {key!r}: the catalogue's constructions are immutable")

    def choice(self, params) -> SppChoice:
        """What a listing shows of ``params`` (:func:`pyoa.valid_spp`, the
        sampler's ``s``, ``strength`` and ``block_dims``)."""
        raise NotImplementedError

    def detail(self, params) -> str:
        """What a sampler's repr shows of ``params`` after its options
        (``"s=11, strength=2, block_dims=12"``, ``"grid 10x12"``), or ``""``."""
        return ""

    def spp_table(self, choices) -> list[str]:
        """The lines ``pyoa spp`` prints of ``choices`` (:meth:`choices`): a
        header, then a row per choice."""
        raise NotImplementedError

    def arguments(self, params) -> dict:
        """The keyword arguments of :func:`pyoa.sampler`, besides ``spp`` and
        ``dims``, that resolve to ``params`` again (a resolved strength, a
        default base, the image): a copy of a sampler cannot resolve others."""
        return {}

    def constants(self, params):
        """Per-sampler constants the kernels read (empty: none)."""
        return []

    def constants_key(self, params):
        """What :meth:`constants` depends on (a backend uploads them once per key)."""
        return (self.name, params)

    @property
    def function(self) -> str:
        """The entry's name as an identifier (kernel names, defines)."""
        return self.name.replace("-", "_")

    def shape_args(self, params) -> tuple[int, ...]:
        """The integer arguments that fix the shape of the computation."""
        raise NotImplementedError

    def seed_args(self, pixel_seed, seed, pixel) -> tuple:
        """The seed arguments of the implementations: by default the pixel's
        point-set seed ``pixel_seed(seed, pixel)`` (docs/spec.md section 3),
        with ``pixel_seed`` the implementation's own."""
        return (pixel_seed(seed, pixel),)

    def options(self, offset, jitter) -> tuple:
        """The arguments after the seeds (the offset style, the jitter amount, as the sampler takes them)."""
        raise NotImplementedError

    def launch(self, params, offset, jitter) -> Launch:
        """The OpenCL kernel that computes a value from scratch, and its arguments (:class:`Launch`)."""
        raise NotImplementedError

    def evaluate(self, impl: str, i, j, params, seed, pixel, offset, jitter):
        """Evaluate with implementation ``impl`` (``"reference"``: Python ints,
        one value; ``"numpy"``: broadcastable arrays)."""
        if impl not in ("reference", "numpy"):
            raise ValueError(f"implementation must be 'reference' or 'numpy', got {impl!r}")
        pixel_seed = _reference_pixel_seed if impl == "reference" else _numpy_pixel_seed
        f = getattr(type(self), impl)
        return f(i, j, *self.shape_args(params), *self.seed_args(pixel_seed, seed, pixel),
                 *self.options(offset, jitter))

    def with_resolution(self, params, resolution):
        """``params`` for an image of ``resolution = (width, height)``: None for
        the samplers that do not use it (they refuse one), required by those
        that do (:attr:`needs_resolution`)."""
        if resolution is not None:
            needing = [c.name for c in REGISTRY.values() if c.needs_resolution]
            raise ValueError(f"{self.name} takes no resolution (got resolution={resolution!r}); only "
                             f"{', '.join(needing)} {'depends' if len(needing) == 1 else 'depend'} on where a "
                             "pixel lies in the image")
        return params

    def with_base(self, params, base):
        """``params`` in the digit base ``base``: None for the samplers without
        one (they refuse one), a prime for those with one (``faure``)."""
        if base is not None:
            having = [c.name for c in REGISTRY.values() if c.has_base]
            raise ValueError(f"{self.name} takes no base (got base={base!r}); only {', '.join(having)} "
                             f"{'has' if len(having) == 1 else 'have'} a digit base")
        return params

    def pixel_count(self, params) -> int:
        """How many pixel indices are valid: ``width * height`` of the image of
        a sampler that needs one (:attr:`needs_resolution`), else ``2**32``."""
        if self.needs_resolution:
            width, height = params.resolution
            return width * height
        return MAX_UINT32 + 1

    def claims(self, params, offset: str | None) -> list[Claim]:
        """The stratification properties a sampler of these parameters
        guarantees for every pixel (checked by the property suite)."""
        return []

    def test_cases(self) -> list[dict]:
        """Sampler arguments (``spp``, ``dims`` and any others of
        :func:`pyoa.sampler`) that the catalogue's conformance and property
        suites run: the smallest and largest shapes and the edge cases of
        this entry. The suites add seeds, pixels, offsets and jitters."""
        raise NotImplementedError

    def choices(self, dims: int | None = None, strength: int | None = None) -> list[SppChoice]:
        raise NotImplementedError

    def solve(self, spp: int, dims: int | None, strength: int | None):
        """The parameters for ``spp`` samples (of the family's type,
        :mod:`pyoa.catalogue.params`), or None if it is not a valid count.

        Raises ValueError only for an invalid ``strength`` argument."""
        raise NotImplementedError

    def invalid(self, spp: int, dims: int | None, strength: int | None) -> str:
        """Why ``spp`` is not a valid count (the start of the error message)."""
        raise NotImplementedError

    def resolve(self, spp: int, dims: int | None, strength: int | None):
        """Like :meth:`solve`, but an invalid count raises a ValueError naming the
        nearest valid counts of this construction and the others that accept it."""
        prm = self.solve(spp, dims, strength)
        if prm is None:
            raise ValueError(
                f"{self.name}: {self.invalid(spp, dims, strength)}; nearest: "
                f"{_labels(self.nearest(spp, dims, strength))}{_elsewhere(self, spp, dims)}"
            )
        return prm

    def nearest(self, spp: int, dims: int | None = None, strength: int | None = None) -> list[SppChoice]:
        """The valid counts nearest ``spp`` on both sides, and ``spp`` itself if valid (:func:`nearest`)."""
        return nearest(self.choices(dims=dims, strength=strength), spp)


class CountRule(Construction):
    """Base of the entries whose valid counts are a rule of the count alone
    (every count, the powers of two or the squares, up to :attr:`max_spp`),
    which have no strength and no offset styles: the comparison samplers
    (:mod:`pyoa.catalogue.baselines`) and ``faure`` (:mod:`pyoa.catalogue.faure`).

    Their implementations are called as ``function(i, j, *shape_args(params),
    *seed_args(...)[, jitter])`` (a jitter amount only where :attr:`jittered`),
    in the OpenCL program by one ``generate_{function}`` kernel each."""

    #: largest number of dimensions
    max_dims = MAX_DIMS
    #: what a refusal of more dimensions than :attr:`max_dims` suggests
    more_dims_hint = ""
    #: sample counts: "any" (1 .. max_spp), "pow2" (powers of two) or "square"
    counts = "any"
    #: largest sample count
    max_spp = MAX_SPP
    why_not_progressive = "its grid is stratified only at the full count, not in its prefixes"

    def params(self, spp: int, dims: int | None):
        """The parameters of a valid ``spp`` (of the entry's type, :mod:`pyoa.catalogue.params`)."""
        raise NotImplementedError

    def _check(self, dims, strength):
        if strength is not None:
            raise ValueError(f"{self.name} has no strength parameter (got strength={strength}); "
                             "strength applies to the orthogonal-array samplers")
        if dims is not None and dims > self.max_dims:
            raise ValueError(f"{self.name} supports at most {self.max_dims} dimensions, got dims={dims}"
                             f"{self.more_dims_hint}")

    def _choice(self, spp: int, dims=None) -> SppChoice:
        return self.choice(self.params(spp, dims))

    def valid(self, spp: int) -> bool:
        if not 1 <= spp <= self.max_spp:
            return False
        return self.counts == "any" or spp & (spp - 1) == 0

    def choices(self, dims=None, strength=None):
        self._check(dims, strength)
        if self.counts == "any":  # every count 1 .. max_spp: listed lazily, not as 16.7 million tuples
            return _Counts(1, self.max_spp, lambda n: self._choice(n, dims))
        return [self._choice(1 << k, dims) for k in range(self.max_spp.bit_length())]

    def nearest(self, spp, dims=None, strength=None):
        self._check(dims, strength)
        if self.counts == "any":  # every count in [1, max_spp]: the neighbours, not 16.7 million choices
            near = min(max(int(spp), 0), self.max_spp + 1)
            return [self._choice(n, dims) for n in (near - 1, near, near + 1) if 1 <= n <= self.max_spp]
        return nearest(self.choices(dims), spp)

    def solve(self, spp, dims, strength):
        self._check(dims, strength)
        return self.params(spp, dims) if self.valid(spp) else None

    def invalid(self, spp, dims, strength):
        if self.counts == "pow2":
            return f"{spp} is not a power of two in [1, 2^{self.max_spp.bit_length() - 1}]"
        return f"{spp} is not in [1, 2^24]"

    def shape_args(self, params):
        return ()

    def options(self, offset, jitter):
        # no offset styles; a jitter amount only where the sampler has one
        return (jitter,) if self.jittered else ()

    def launch(self, params, offset, jitter):
        # the kernel's a, b, c: the shape arguments, zero-padded to three
        a, b, c = (*self.shape_args(params), 0, 0, 0)[:3]
        return Launch(f"generate_{self.function}", (np.uint32(a), np.uint32(b), np.uint32(c), np.float32(jitter)))

    def test_cases(self):
        # one sample, a few, the largest count (its last sample), many dimensions
        few = 12 if self.counts == "any" else 16
        return [dict(spp=1, dims=1), dict(spp=few, dims=5), dict(spp=self.max_spp, dims=3),
                dict(spp=4, dims=min(self.max_dims, 600))]


#: Every registered entry by name, in registration order; :mod:`pyoa.catalogue`
#: exposes them as ``SAMPLERS`` (the OA constructions first) once every
#: module of entries is imported.
REGISTRY: dict[str, Construction] = {}
#: The registered entries of each family (:attr:`Construction.family`), by name.
FAMILIES: dict[str, dict[str, Construction]] = {}


def register(cls: type[Construction]) -> type[Construction]:
    """Class decorator: add one instance of ``cls`` to :data:`REGISTRY`.

    Refuses an entry without implementations or whose name or kernel code is
    already taken, so two entries can never share a dispatch slot."""
    entry = cls()
    for attr in ("reference", "numpy"):
        if not callable(getattr(cls, attr, None)):
            raise TypeError(f"{cls.__name__} must name its {attr} implementation")
    if not entry.kernel:
        raise TypeError(f"{cls.__name__} must name its C function in the headers (kernel)")
    if entry.name in REGISTRY:
        raise ValueError(f"sampler name {entry.name!r} is registered twice")
    taken = {c.code: c.name for c in REGISTRY.values()}
    if entry.code in taken:
        raise ValueError(f"{entry.name}: kernel code {entry.code} is already {taken[entry.code]}'s")
    REGISTRY[entry.name] = entry
    FAMILIES.setdefault(entry.family, {})[entry.name] = entry
    return cls


def _elsewhere(this: Construction, spp: int, dims: int | None) -> str:
    """``"; 64 is valid for bush (s=4, t=3), cmjnd (s=8)"``: the other entries of
    ``this``'s family that accept ``spp``, or ``""``."""
    found = []
    for c in FAMILIES[this.family].values():
        if c is this:
            continue
        try:
            prm = c.solve(spp, dims, None)
        except ValueError:  # e.g. more dims than that sampler has
            continue
        if prm is None:
            continue
        shape = c.choice(prm).shape()
        found.append(f"{c.name} ({shape})" if shape else c.name)
    return f"; {spp} is valid for {', '.join(found)}" if found else ""
