"""The catalogue's base types: what every sampler entry is and declares.

A sampler of pyoa is one *entry* of the catalogue (:mod:`pyoa.catalogue`):
an instance of a :class:`Construction` subclass, registered once with
:func:`register`. The entry holds what every backend, test and error message
needs to know about the sampler before a single value is computed (its valid
sample counts and the parameters they mean) and names its three
implementations, which give the same bits:

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
:mod:`pyoa.hashes`); the entries
(:mod:`pyoa.constructions`, :mod:`pyoa.baselines`) import it, and
:mod:`pyoa.catalogue` imports them, so the dependencies run one way.

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
from dataclasses import dataclass
from typing import NamedTuple

from .hashes import pixel_seed as _numpy_pixel_seed
from .reference.hashes import pixel_seed as _reference_pixel_seed
from .reference.oa import OFFSETS

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
        if self.detail or self.strength == 0:
            return f"{self.spp} ({self.detail})" if self.detail else str(self.spp)
        if self.strength == 2:
            return f"{self.spp} (s={self.s})"
        return f"{self.spp} (s={self.s}, t={self.strength})"


@dataclass(frozen=True)
class Params:
    """Resolved parameters of one sampler.

    ``M = N / s`` is the number of fine sub-strata inside one coarse stratum.
    ``dims`` is the sampler's number of dimensions (0 where unknown, as in
    :func:`valid_spp`); only some comparison samplers depend on it. For the
    comparison samplers (:mod:`pyoa.baselines`) ``s``, ``strength`` and ``M``
    describe their grids as documented there.
    """

    s: int
    strength: int
    block_dims: int
    M: int
    dims: int = 0
    #: the image (width, height) of a sampler whose values depend on where a
    #: pixel lies in it (``zsobol``); None for the others
    resolution: tuple[int, int] | None = None


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


class Construction:
    """Base class of the catalogue's entries (see the module docstring).

    Subclasses define :meth:`choices` (every valid sample count),
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
    #: "oa" for the orthogonal arrays, "baseline" for the comparison samplers
    family = "oa"
    #: whether the integer array is computed in a Galois field (the backends
    #: then need pyoa.gf's tables for prime-power orders); see field_order
    uses_field = False
    #: whether a sampler needs the image resolution (``resolution=``): its
    #: values depend on where a pixel lies in the image
    needs_resolution = False
    #: whether every prefix of a pixel's samples keeps the sampler's
    #: stratification (its first n samples are as good as any n): a render
    #: may stop after any block of samples (``pyoa render --progressive``)
    progressive = False
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

    def field_order(self, params: Params) -> int:
        """Order of the field the array is computed in (0: none)."""
        return params.s if self.uses_field else 0

    def constants(self, params: Params):
        """Per-sampler constants the kernels read (empty: none)."""
        return []

    def constants_key(self, params: Params):
        """What :meth:`constants` depends on (a backend uploads them once per key)."""
        return (self.name, params)

    @property
    def function(self) -> str:
        """The entry's name as an identifier (kernel names, defines)."""
        return self.name.replace("-", "_")

    def shape_args(self, params: Params) -> tuple[int, ...]:
        return (params.s, params.strength)

    def seed_args(self, pixel_seed, seed, pixel) -> tuple:
        """The seed arguments of the implementations: by default the pixel's
        point-set seed ``pixel_seed(seed, pixel)`` (docs/spec.md section 3),
        with ``pixel_seed`` the implementation's own."""
        return (pixel_seed(seed, pixel),)

    def options(self, offset, jitter) -> tuple:
        """The arguments after the seeds: offset and jitter for the OAs."""
        return (offset, jitter)

    def evaluate(self, impl: str, i, j, params: Params, seed, pixel, offset, jitter):
        """Evaluate with implementation ``impl`` (``"reference"``: Python ints,
        one value; ``"numpy"``: broadcastable arrays)."""
        if impl not in ("reference", "numpy"):
            raise ValueError(f"implementation must be 'reference' or 'numpy', got {impl!r}")
        pixel_seed = _reference_pixel_seed if impl == "reference" else _numpy_pixel_seed
        f = getattr(type(self), impl)
        return f(i, j, *self.shape_args(params), *self.seed_args(pixel_seed, seed, pixel),
                 *self.options(offset, jitter))

    def with_resolution(self, params: Params, resolution) -> Params:
        """``params`` for an image of ``resolution = (width, height)``: None for
        the samplers that do not use it (they refuse one), required by those
        that do (:attr:`needs_resolution`)."""
        if resolution is not None:
            needing = [c.name for c in REGISTRY.values() if c.needs_resolution]
            raise ValueError(f"{self.name} takes no resolution (got resolution={resolution!r}); only "
                             f"{', '.join(needing)} {'depends' if len(needing) == 1 else 'depend'} on where a "
                             "pixel lies in the image")
        return params

    def with_base(self, params: Params, base) -> Params:
        """``params`` in the digit base ``base``: None for the samplers without
        one (they refuse one), a prime for those with one (``faure``)."""
        if base is not None:
            having = [c.name for c in REGISTRY.values() if c.has_base]
            raise ValueError(f"{self.name} takes no base (got base={base!r}); only {', '.join(having)} "
                             f"{'has' if len(having) == 1 else 'have'} a digit base")
        return params

    def pixel_count(self, params: Params) -> int:
        """How many pixel indices are valid: ``2**32`` unless the sampler has an image."""
        return MAX_UINT32 + 1

    def claims(self, params: Params, offset: str | None) -> list[Claim]:
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

    def solve(self, spp: int, dims: int | None, strength: int | None) -> Params | None:
        """The parameters for ``spp`` samples, or None if it is not a valid count.

        Raises ValueError only for an invalid ``strength`` argument."""
        raise NotImplementedError

    def invalid(self, spp: int, dims: int | None, strength: int | None) -> str:
        """Why ``spp`` is not a valid count (the start of the error message)."""
        raise NotImplementedError

    def resolve(self, spp: int, dims: int | None, strength: int | None) -> Params:
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


#: Every registered entry by name, in registration order (the OA
#: constructions, then the comparison samplers); :mod:`pyoa.catalogue`
#: exposes it as ``SAMPLERS`` once both modules of entries are imported.
REGISTRY: dict[str, Construction] = {}


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
    return cls


def _elsewhere(this: Construction, spp: int, dims: int | None) -> str:
    """``"; 64 is valid for bush (s=4, t=3), cmjnd (s=8)"``, or ``""``."""
    found = []
    for c in REGISTRY.values():
        if c is this or c.family != this.family:
            continue
        try:
            prm = c.solve(spp, dims, None)
        except ValueError:  # e.g. more dims than that sampler has
            continue
        if prm is None:
            continue
        label = SppChoice(spp, prm.s, prm.strength, prm.block_dims, getattr(c, "detail", lambda _: "")(prm)).label()
        found.append(f"{c.name} ({label[len(str(spp)) + 2:-1]})" if label != str(spp) else c.name)
    return f"; {spp} is valid for {', '.join(found)}" if found else ""
