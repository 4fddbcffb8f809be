"""The catalogue of orthogonal-array constructions: parameters and valid sizes.

This module holds what every backend and every error message needs to know
about a construction *before* a single value is computed: which sample counts
it accepts, which number of strata ``s`` and strength ``t`` a count means, how
many dimensions one independently randomized block holds, and the integer codes
that the OpenCL kernels use for constructions and offset styles (passed to the
kernel build as ``-D`` defines, so those codes live here only).

The mathematics of each construction is in ``../shared/SPEC.md`` section 5 and
in the reference implementation :mod:`pyoa.reference`.

Limits
------
``N <= 2**24`` samples per pixel: every integer that becomes a float (stratum,
sub-stratum, ``M``, ``s``) is then exact in float32, and every product the
constructions form (``s*s``, ``A_ik*s + A_ij + 1``, ``s**t``) stays below
``2**32``, so the uint32 arithmetic of SPEC section 7 cannot overflow.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

#: Offset styles of SPEC section 4, in the order of their kernel codes.
OFFSETS = ("centered", "j", "mj", "cmj")
OFFSET_CODES = {name: code for code, name in enumerate(OFFSETS)}

#: Largest sample count per pixel (see the module docstring for why).
MAX_SPP = 2**24
#: Largest number of dimensions of one sampler (one row of values must fit in
#: a single OpenCL buffer even for the largest request).
MAX_DIMS = 2**20
#: Largest user seed, pixel index: both are uint32 (SPEC section 3).
MAX_UINT32 = 2**32 - 1


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
        Dimensions per independently randomized block (SPEC section 6).
    """

    spp: int
    s: int
    strength: int
    block_dims: int

    def label(self) -> str:
        """Short text such as ``"121 (s=11)"`` or ``"125 (s=5, t=3)"``."""
        if self.strength == 2:
            return f"{self.spp} (s={self.s})"
        return f"{self.spp} (s={self.s}, t={self.strength})"


@dataclass(frozen=True)
class Params:
    """Resolved parameters of one sampler.

    ``M = N / s`` is the number of fine sub-strata inside one coarse stratum.
    """

    s: int
    strength: int
    block_dims: int
    M: int


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


def _labels(choices: list[SppChoice]) -> str:
    return ", ".join(c.label() for c in choices)


class Construction:
    """Base class: one entry of the catalogue.

    Subclasses define :meth:`choices` (every valid sample count) and
    :meth:`resolve` (the parameters for a requested count).
    """

    name: str
    code: int
    description: str

    def choices(self, dims: int | None = None, strength: int | None = None) -> list[SppChoice]:
        raise NotImplementedError

    def resolve(self, spp: int, dims: int, strength: int | None) -> Params:
        raise NotImplementedError

    def nearest(self, spp: int, dims: int | None = None, strength: int | None = None) -> list[SppChoice]:
        """The two valid counts closest to ``spp``."""
        return nearest(self.choices(dims=dims, strength=strength), spp)


class Bose(Construction):
    """Bose (1938): strength 2, s prime, N = s**2, s+1 dimensions per block."""

    name = "bose"
    code = 0
    description = "Bose OA, strength 2: N = s^2 with s prime, s+1 dimensions per block"
    #: the largest prime with s**2 <= MAX_SPP
    max_s = max(p for p in range(math.isqrt(MAX_SPP), 1, -1) if is_prime(p))

    def choices(self, dims=None, strength=None):
        if strength not in (None, 2):
            return []
        return [SppChoice(s * s, s, 2, s + 1) for s in range(2, self.max_s + 1) if is_prime(s)]

    def resolve(self, spp, dims, strength):
        if strength not in (None, 2):
            raise ValueError(
                f"bose has strength 2 only (got strength={strength}); "
                "use 'cmjnd' for strength t >= 3 (N = s^t)"
            )
        s = math.isqrt(spp)
        if s * s != spp or not is_prime(s) or s > self.max_s:
            near = _labels(self.nearest(spp))
            raise ValueError(f"bose: {spp} is not s^2 with s prime (s <= {self.max_s}); nearest: {near}")
        return Params(s=s, strength=2, block_dims=s + 1, M=s)


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
        # Only the few s around spp**(1/t) of each strength can be nearest;
        # enumerating every count (16.7 million at t = 1) took half a minute.
        cands = []
        for t in self._strengths(dims, strength):
            root = int(round(max(spp, 1) ** (1.0 / t)))
            s_max = integer_root_floor(MAX_SPP, t)
            for s in {*range(max(2, root - 2), root + 3), s_max}:
                if 2 <= s <= s_max:
                    cands.append(SppChoice(s**t, s, t, t))
        return nearest(cands, spp)

    def choices(self, dims=None, strength=None):
        out = []
        for t in self._strengths(dims, strength):
            s = 2
            while s**t <= MAX_SPP:
                out.append(SppChoice(s**t, s, t, t))
                s += 1
        return sorted(out)

    def resolve(self, spp, dims, strength):
        if strength is not None:
            if not 1 <= strength <= self.max_strength:
                raise ValueError(f"cmjnd strength must be an integer in [1, {self.max_strength}], got {strength}")
            s = integer_root(spp, strength)
            if s is None or s < 2:
                near = _labels(self.nearest(spp, strength=strength))
                raise ValueError(f"cmjnd: {spp} is not s^{strength} with s >= 2; nearest: {near}")
            return Params(s=s, strength=strength, block_dims=strength, M=spp // s)
        # No strength given: the largest t <= dims (t >= 2 unless dims == 1)
        # such that spp = s^t: the most dimensions stratified jointly.
        for t in sorted(self._strengths(dims, None), reverse=True):
            s = integer_root(spp, t)
            if s is not None and s >= 2:
                return Params(s=s, strength=t, block_dims=t, M=spp // s)
        ts = self._strengths(dims, None)
        near = _labels(self.nearest(spp, dims=dims))
        raise ValueError(
            f"cmjnd: {spp} is not s^t with s >= 2 for any strength {ts[0]} <= t <= {ts[-1]} "
            f"(dims={dims}); nearest: {near}"
        )


CONSTRUCTIONS: dict[str, Construction] = {c.name: c for c in (Bose(), CMJND())}


def get(name: str) -> Construction:
    """Look up a construction by name, with an error that lists the valid ones."""
    if not isinstance(name, str):
        raise TypeError(f"sampler name must be a str, got {type(name).__name__}")
    try:
        return CONSTRUCTIONS[name.lower()]
    except KeyError:
        raise ValueError(f"unknown sampler {name!r}; valid: {', '.join(CONSTRUCTIONS)}") from None


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
    list of SppChoice
        ``(spp, s, strength, block_dims)`` tuples in increasing ``spp``.

    Examples
    --------
    >>> [c.label() for c in valid_spp("bose", near=120)]
    ['121 (s=11)', '169 (s=13)']
    """
    construction = get(name)
    if near is None:
        return construction.choices(dims=dims, strength=strength)
    return construction.nearest(int(near), dims=dims, strength=strength)
