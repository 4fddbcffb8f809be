"""The catalogue of orthogonal-array constructions: parameters and valid sizes.

This module holds what every backend and every error message needs to know
about a construction *before* a single value is computed: which sample counts
it accepts, which number of strata ``s`` and strength ``t`` a count means, how
many dimensions one independently randomized block holds, and the integer codes
that the OpenCL kernels use for constructions and offset styles (passed to the
kernel build as ``-D`` defines, so those codes live here only).

The mathematics of each construction is in ``docs/spec.md`` section 5 and
in the reference implementation :mod:`pyoa.reference`.

Limits
------
``N <= 2**24`` samples per pixel: every integer that becomes a float (stratum,
sub-stratum, ``M``, ``s``) is then exact in float32, and every product the
constructions form (``s*s``, ``A_ik*s + A_ij + 1``, ``s**t``) stays below
``2**32``, so the uint32 arithmetic of docs/spec.md section 7 cannot overflow.
"""

from __future__ import annotations

import importlib
import itertools
import math
import numbers
import operator
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import NamedTuple

from . import gf

#: Offset styles of docs/spec.md section 4, in the order of their kernel codes.
OFFSETS = ("centered", "j", "mj", "cmj")
OFFSET_CODES = {name: code for code, name in enumerate(OFFSETS)}

#: Largest sample count per pixel (see the module docstring for why).
MAX_SPP = 2**24
#: Largest number of dimensions of one sampler (one row of values must fit in
#: a single OpenCL buffer even for the largest request).
MAX_DIMS = 2**20
#: Largest user seed, pixel index: both are uint32 (docs/spec.md section 3).
MAX_UINT32 = 2**32 - 1


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


def is_prime(n: int) -> bool:
    """Deterministic primality test for the small integers used here."""
    if n < 2:
        return False
    if n % 2 == 0:
        return n == 2
    return all(n % d for d in range(3, math.isqrt(n) + 1, 2))


def integer_root(n: int, t: int) -> int | None:
    """Return s with ``s**t == n`` if such an integer exists, else None."""
    s = round(n ** (1.0 / t))
    for cand in (s - 1, s, s + 1):
        if cand >= 1 and cand**t == n:
            return cand
    return None


def integer_root_floor(n: int, t: int) -> int:
    """The largest s with ``s**t <= n``."""
    s = int(round(n ** (1.0 / t)))
    while s**t > n:
        s -= 1
    while (s + 1) ** t <= n:
        s += 1
    return s


def nearest(choices: list[SppChoice], spp: int, k: int = 2) -> list[SppChoice]:
    """The ``k`` choices closest to ``spp`` (ties broken towards fewer samples),
    returned in increasing order of sample count."""
    best = sorted(choices, key=lambda c: (abs(c.spp - spp), c.spp))[:k]
    return sorted(best, key=lambda c: c.spp)


def _power_candidates(spp: int, strengths, valid, block_dims) -> list[SppChoice]:
    """Counts ``s**t`` that can be among the two nearest to ``spp``: for each
    strength t, the two valid s at or below ``spp**(1/t)`` and the two above
    (``s**t <= MAX_SPP``). Searching outwards from the root instead of listing
    every count matters: at t = 1 there are 16.7 million counts."""
    out = []
    for t in strengths:
        s_max = integer_root_floor(MAX_SPP, t)
        root = min(max(int(round(max(spp, 1) ** (1.0 / t))), 2), s_max)
        for side in (range(root, 1, -1), range(root + 1, s_max + 1)):
            found = list(itertools.islice((s for s in side if valid(s, t)), 2))
            out += [SppChoice(s**t, s, t, block_dims(s, t)) for s in found]
    return out


def _labels(choices: list[SppChoice]) -> str:
    return ", ".join(c.label() for c in choices)


class Construction:
    """Base class: one entry of the catalogue.

    Subclasses define :meth:`choices` (every valid sample count) and
    :meth:`resolve` (the parameters for a requested count). ``function`` names
    the sampler function, the same in :mod:`pyoa.reference` and
    :mod:`pyoa._numpy.oa`, called as ``function(i, j, *shape_args(params), p,
    offset, jitter)``.
    """

    name: str
    code: int
    description: str
    #: "oa" for the orthogonal arrays, "baseline" for the comparison samplers
    family = "oa"
    #: the module of pyoa.reference and pyoa._numpy holding `function`
    module = "oa"
    #: whether the integer array is computed in a Galois field (the backends
    #: then need pyoa.gf's tables for prime-power orders); see field_order
    uses_field = False

    def __setattr__(self, key, value):
        # One shared instance per sampler name serves every Sampler: changing
        # it would change every sampler of the process.
        raise AttributeError(f"cannot set {key!r}: the catalogue's constructions are immutable")

    def __delattr__(self, key):
        raise AttributeError(f"cannot delete {key!r}: the catalogue's constructions are immutable")

    def field_order(self, params: Params) -> int:
        """Order of the field the array is computed in (0: none)."""
        return params.s if self.uses_field else 0

    def constants(self, params: Params) -> list[int]:
        """Per-construction constants the kernels read (empty: none)."""
        return []

    @property
    def function(self) -> str:
        return self.name.replace("-", "_")

    def shape_args(self, params: Params) -> tuple[int, ...]:
        return (params.s, params.strength)

    def options(self, offset, jitter) -> tuple:
        """The arguments after ``p`` of ``function``: offset and jitter for the OAs."""
        return (offset, jitter)

    def call(self, package: str, i, j, params: Params, p, offset, jitter):
        """Evaluate with the implementation in ``package`` (``"pyoa.reference"``
        or ``"pyoa._numpy"``): ``function(i, j, *shape_args(params), p, *options(offset, jitter))``."""
        f = getattr(importlib.import_module(f"{package}.{self.module}"), self.function)
        return f(i, j, *self.shape_args(params), p, *self.options(offset, jitter))

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
        """The two valid counts closest to ``spp``."""
        return nearest(self.choices(dims=dims, strength=strength), spp)


class Bose(Construction):
    """Bose (1938): strength 2, s a prime power, N = s**2, s+1 dimensions per block."""

    name = "bose"
    code = 0
    uses_field = True
    description = "Bose OA, strength 2: N = s^2 with s a prime power, s+1 dimensions per block"
    #: the largest prime with s**2 <= MAX_SPP
    max_s = max(p for p in range(math.isqrt(MAX_SPP), 1, -1) if is_prime(p))

    def shape_args(self, params):
        return (params.s,)

    def choices(self, dims=None, strength=None):
        if strength not in (None, 2):
            return []
        return [SppChoice(s * s, s, 2, s + 1) for s in range(2, self.max_s + 1) if gf.is_supported(s)]

    def solve(self, spp, dims, strength):
        if strength not in (None, 2):
            raise ValueError(
                f"bose has strength 2 only (got strength={strength}); "
                "use 'bush' or 'cmjnd' for strength t >= 3 (N = s^t)"
            )
        s = math.isqrt(spp)
        if s * s != spp or not gf.is_supported(s) or s > self.max_s:
            return None
        return Params(s=s, strength=2, block_dims=s + 1, M=s)

    def invalid(self, spp, dims, strength):
        return f"{spp} is not s^2 with s a prime (<= {self.max_s}) or a prime power (<= {gf.MAX_TABLE_Q})"


class Bush(Construction):
    """Bush (1952): strength t, s a prime power, t <= s, N = s**t, s+1 dimensions per block."""

    name = "bush"
    code = 2
    uses_field = True
    #: t <= s and s**t <= 2**24 allow t <= 8 (8**8 = 2**24; 9**9 is too large)
    max_strength = 8
    description = "Bush OA, strength t: N = s^t with s a prime power and t <= s, s+1 dimensions per block"

    def _strengths(self, dims, strength):
        if strength is not None:
            return [strength]
        return list(range(2, max(2, min(dims or self.max_strength, self.max_strength)) + 1))

    def choices(self, dims=None, strength=None):
        out = []
        for t in self._strengths(dims, strength):
            s = max(2, t)
            while s**t <= MAX_SPP:
                if gf.is_supported(s):
                    out.append(SppChoice(s**t, s, t, s + 1))
                s += 1
        return sorted(out)

    def nearest(self, spp, dims=None, strength=None):
        return nearest(_power_candidates(spp, self._strengths(dims, strength),
                                         lambda s, t: s >= t and gf.is_supported(s), lambda s, t: s + 1), spp)

    def solve(self, spp, dims, strength):
        if strength is not None and not 2 <= strength <= self.max_strength:
            raise ValueError(
                f"bush strength must be an integer in [2, {self.max_strength}] (t <= s and s^t <= 2^24), "
                f"got {strength}; use 'cmjnd' for higher strengths"
            )
        # The largest t <= dims (t >= 2): the most dimensions stratified jointly.
        for t in sorted(self._strengths(dims, strength), reverse=True):
            s = integer_root(spp, t)
            if s is not None and s >= t and gf.is_supported(s):
                return Params(s=s, strength=t, block_dims=s + 1, M=spp // s)
        return None

    def invalid(self, spp, dims, strength):
        ts = self._strengths(dims, strength)
        what = f"s^{strength}" if strength is not None else f"s^t for any strength 2 <= t <= {ts[-1]}"
        return (f"{spp} is not {what} with s >= t a prime, or a prime power <= {gf.MAX_TABLE_Q}")


class CMJND(Construction):
    """Jarosz et al. (2019) high-dimensional CMJ: any s >= 2, N = s**t, t dimensions per block."""

    name = "cmjnd"
    code = 1
    description = "N-dimensional correlated multi-jittered OA: N = s^t for any s >= 2, t dimensions per block"
    max_strength = 24  # 2**24 = MAX_SPP

    def _strengths(self, dims, strength):
        if strength is not None:
            return [strength]
        if dims is None:
            return list(range(2, self.max_strength + 1))
        if dims == 1:
            return [1]
        return list(range(2, min(dims, self.max_strength) + 1))

    def nearest(self, spp, dims=None, strength=None):
        return nearest(_power_candidates(spp, self._strengths(dims, strength),
                                         lambda s, t: s >= 2, lambda s, t: t), spp)

    def choices(self, dims=None, strength=None):
        strengths = self._strengths(dims, strength)
        if strengths == [1]:  # every count 2 .. 2**24: listed lazily, not as 16.7 million tuples
            return _Counts(2, MAX_SPP, lambda n: SppChoice(n, n, 1, 1))
        out = []
        for t in strengths:
            s = 2
            while s**t <= MAX_SPP:
                out.append(SppChoice(s**t, s, t, t))
                s += 1
        return sorted(out)

    def solve(self, spp, dims, strength):
        if strength is not None and not 1 <= strength <= self.max_strength:
            raise ValueError(f"cmjnd strength must be an integer in [1, {self.max_strength}], got {strength}")
        # No strength given: the largest t <= dims (t >= 2 unless dims == 1)
        # such that spp = s^t: the most dimensions stratified jointly.
        for t in sorted(self._strengths(dims, strength), reverse=True):
            s = integer_root(spp, t)
            if s is not None and s >= 2:
                return Params(s=s, strength=t, block_dims=t, M=spp // s)
        return None

    def invalid(self, spp, dims, strength):
        if strength is not None:
            return f"{spp} is not s^{strength} with s >= 2"
        ts = self._strengths(dims, None)
        return f"{spp} is not s^t with s >= 2 for any strength {ts[0]} <= t <= {ts[-1]} (dims={dims})"


class _Index2(Construction):
    """Shared parts of the strength-2, index-2 constructions: N = 2 s**2,
    2s + 1 dimensions per block, M = 2s sub-strata."""

    uses_field = True

    def shape_args(self, params):
        return (params.s,)

    def levels(self):  # pragma: no cover - abstract
        raise NotImplementedError

    def choices(self, dims=None, strength=None):
        if strength not in (None, 2):
            return []
        return [SppChoice(2 * s * s, s, 2, 2 * s + 1) for s in self.levels()]

    def solve(self, spp, dims, strength):
        if strength not in (None, 2):
            raise ValueError(f"{self.name} has strength 2 only (got strength={strength})")
        s = math.isqrt(spp // 2)
        if spp % 2 or 2 * s * s != spp or s not in self.levels():
            return None
        return Params(s=s, strength=2, block_dims=2 * s + 1, M=2 * s)


class AddelmanKempthorne(_Index2):
    """Addelman and Kempthorne (1961): strength 2, index 2, q an odd prime power,
    N = 2 q**2, 2q + 1 dimensions per block."""

    name = "addelman-kempthorne"
    code = 3
    description = ("Addelman-Kempthorne OA, strength 2, index 2: N = 2q^2 with q an odd prime power, "
                   "2q+1 dimensions per block")

    @staticmethod
    @lru_cache(maxsize=None)
    def levels():
        top = math.isqrt(MAX_SPP // 2)
        return tuple(q for q in range(3, top + 1, 2) if gf.is_supported(q))

    def constants(self, params):
        kappa, b, k, c = gf.ak_constants(params.s)
        return [kappa, *b, *k, *c]

    def invalid(self, spp, dims, strength):
        return (f"{spp} is not 2q^2 with q an odd prime (<= {self.levels()[-1]}) "
                f"or odd prime power (<= {gf.MAX_TABLE_Q})")


class BoseBush(_Index2):
    """Bose and Bush (1952): strength 2, index 2, s a power of two,
    N = 2 s**2, 2s + 1 dimensions per block, computed in GF(2s)."""

    name = "bose-bush"
    code = 4
    description = "Bose-Bush OA, strength 2, index 2: N = 2s^2 with s a power of two, 2s+1 dimensions per block"

    @staticmethod
    def levels():
        return tuple(2**r for r in range(1, 8))  # GF(2s) tables up to 256

    def field_order(self, params):
        return 2 * params.s

    def invalid(self, spp, dims, strength):
        return f"{spp} is not 2s^2 with s a power of two (<= {self.levels()[-1]}, GF(2s) tables up to {gf.MAX_TABLE_Q})"


#: The orthogonal-array constructions.
CONSTRUCTIONS: dict[str, Construction] = {
    c.name: c for c in (Bose(), Bush(), CMJND(), AddelmanKempthorne(), BoseBush())
}

# The comparison samplers subclass Construction, hence the import down here.
from .baselines import BASELINES  # noqa: E402

#: Every sampler: the OA constructions, then the comparison samplers.
SAMPLERS: dict[str, Construction] = {**CONSTRUCTIONS, **BASELINES}


def _elsewhere(this: Construction, spp: int, dims: int | None) -> str:
    """``"; 64 is valid for bush (s=4, t=3), cmjnd (s=8)"``, or ``""``."""
    found = []
    for c in SAMPLERS.values():
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


def get(name: str) -> Construction:
    """Look up a construction by name, with an error that lists the valid ones."""
    if not isinstance(name, str):
        raise TypeError(f"sampler name must be a str, got {type(name).__name__}")
    try:
        return SAMPLERS[name.lower()]
    except KeyError:
        raise ValueError(f"unknown sampler {name!r}; valid: {', '.join(SAMPLERS)}") from None


def valid_spp(name: str, near: int | None = None, dims: int | None = None, strength: int | None = None) -> list[SppChoice]:
    """List the valid sample counts of a sampler.

    Parameters
    ----------
    name : str
        Sampler name, see :func:`pyoa.samplers`.
    near : int, optional
        If given, only the two counts closest to ``near`` (or ``near`` itself
        and its closest neighbour if it is valid).
    dims : int, optional
        Number of dimensions the sampler will be asked for; for ``cmjnd``
        without ``strength`` it bounds the strengths considered (2..dims).
    strength : int, optional
        Restrict to one strength t.

    Returns
    -------
    sequence of SppChoice
        ``(spp, s, strength, block_dims, detail)`` tuples in increasing
        ``spp``. For ``random``, ``cmj2d`` and ``halton``, which accept every
        count in ``[1, 2**24]``, a lazy sequence of all 16.7 million.

    Examples
    --------
    >>> [c.label() for c in valid_spp("bose", near=120)]
    ['81 (s=9)', '121 (s=11)']
    >>> [c.label() for c in valid_spp("sobol", near=120)]
    ['64 (2^6)', '128 (2^7)']

    Raises
    ------
    ValueError
        An unknown sampler; a negative ``near``; ``dims`` outside
        ``[1, 2**20]``; a ``strength`` the sampler does not have (as
        :func:`pyoa.sampler` refuses it: ``bose`` has strength 2 only,
        ``bush`` 2..8...), rather than an empty list.
    TypeError
        A name that is not a str, or a count that is not an int.
    """
    construction = get(name)
    near = None if near is None else check_int("near", near, 0)
    dims = None if dims is None else check_int("dims", dims, 1, MAX_DIMS)
    strength = None if strength is None else check_int("strength", strength, 1)
    construction.solve(1, dims, strength)  # raises for a strength (or dims) this sampler cannot have
    return _listing(construction, near, dims, strength)


def _listing(construction: Construction, near: int | None, dims: int | None, strength: int | None):
    """:func:`valid_spp` of arguments already checked (or to be taken as they are)."""
    if near is None:
        return construction.choices(dims=dims, strength=strength)
    return construction.nearest(int(near), dims=dims, strength=strength)


def nearest_spp(name: str, spp: int, dims: int | None = None, strength: int | None = None) -> int | None:
    """The valid sample count of ``name`` closest to ``spp`` (``spp`` itself if
    valid; ties go to fewer samples), or None if there is none for these
    ``dims`` and ``strength``. Used wherever a requested count is replaced by
    a sampler's nearest one (``pyoa compare``, convergence studies, the qmc
    engine's default)."""
    # Unlike valid_spp, a strength the sampler cannot have means "none" here
    # (convergence studies skip such a sampler instead of failing).
    choices = _listing(get(name), spp, dims, strength)
    return min((c.spp for c in choices), key=lambda n: (abs(n - spp), n)) if choices else None
