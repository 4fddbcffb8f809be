"""The orthogonal-array entries of the catalogue: parameters and valid sizes.

Bose, Bush, CMJND (Jarosz et al.'s high-dimensional CMJ), Addelman-Kempthorne
and Bose-Bush: for each, which sample counts it accepts, which number of
strata ``s`` and strength ``t`` a count means, how many dimensions one
independently randomized block holds, and its three implementations (see
:mod:`pyoa.catalogue.entries`). The mathematics of each construction is in
``docs/spec.md`` section 5 and in the reference implementation
:mod:`pyoa.reference.oa`.
"""

from __future__ import annotations

import itertools
import math
from functools import lru_cache

import numpy as np

from ..tables import gf
from .._numpy import oa as _numpy_oa
from .entries import (
    MAX_SPP,
    OFFSET_CODES,
    OFFSETS,
    Claim,
    Construction,
    Launch,
    SppChoice,
    _Counts,
    nearest,
    register,
)
from .params import OAParams
from ..reference import oa as _reference_oa


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


def _power_candidates(spp: int, strengths, valid, choice) -> list[SppChoice]:
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
            out += [choice(s, t) for s in found]
    return out


class _OA(Construction):
    """The orthogonal arrays' family: their parameters (:class:`pyoa.catalogue.params.OAParams`),
    kernel arguments and offset styles, the cells the table paths gather with,
    and the properties they guarantee."""

    family = "oa"
    drjit_module = "oa"
    drjit_located = True
    offsets = OFFSETS
    default_offset = "cmj"
    jittered = True
    why_not_progressive = ("an orthogonal array is stratified only as a whole (all N samples): its first samples "
                           "are no smaller array (bose's first s samples share one stratum of dimension 0), so its "
                           "intermediate images would be poor")
    #: whether the array is computed in a Galois field (the backends then
    #: need pyoa.tables.gf's tables for prime-power orders); see field_order
    uses_field = False
    #: whether the 'j' offset's cell key is Bose's partner cell
    #: ``u * s + A_ij + 1`` rather than ``i + 1`` (docs/spec.md section 4)
    partner_cell_key = False
    #: ``(s, t) -> Geometry(N, B, s, M)``: the reference module's ``*_geometry``
    #: of the construction, the only definition of its shape (block size B
    #: included) that every implementation and this catalogue read
    geometry = None

    def params_for(self, s: int, t: int) -> OAParams:
        """The resolved parameters of the array with ``s`` symbols and strength ``t``."""
        g = self.geometry(s, t)
        return OAParams(N=g.N, B=g.B, s=s, M=g.M, t=t)

    def choice_for(self, s: int, t: int) -> SppChoice:
        """The sample count of the array with ``s`` symbols and strength ``t``, as a listed choice."""
        return self.choice(self.params_for(s, t))

    def choice(self, params):
        return SppChoice(params.N, params.s, params.t, params.B)

    def detail(self, params):
        return f"s={params.s}, strength={params.t}, block_dims={params.B}"

    def arguments(self, params):
        return {"strength": params.t}

    def spp_table(self, choices):
        return [f"{'spp':>9s} {'s':>5s} {'t':>3s} {'dims/block':>10s}",
                *(f"{c.spp:9d} {c.s:5d} {c.strength:3d} {c.block_dims:10d}" for c in choices)]

    def field_order(self, params: OAParams) -> int:
        """Order of the field the array is computed in (0: none)."""
        return params.s if self.uses_field else 0

    def shape_args(self, params):
        return (params.s, params.t)

    def options(self, offset, jitter):
        return (offset, jitter)

    def launch(self, params, offset, jitter):
        # kernels/generate.cl's generate: every OA through one kernel, dispatched by the code
        args = (self.code, params.s, params.t, params.B, params.N, params.M, OFFSET_CODES[offset])
        return Launch("generate", (*map(np.uint32, args), np.float32(jitter)), self.field_order(params))

    def cells(self, i, col, params: OAParams):
        """``(A_ij, u)`` of samples ``i`` in columns ``col < B``
        (NumPy arrays): the cell and its sub-stratum index, which do not depend
        on the pixel (the table paths of both backends compute them once per
        rectangle, :mod:`pyoa.catalogue.host_tables`)."""
        raise NotImplementedError

    def claims(self, params, offset):
        out = [Claim("oa", s=params.s, strength=params.t, block_dims=params.B)]
        if offset in ("cmj", "mj"):  # 1D Latin hypercubes at N (docs/spec.md section 4)
            out.append(Claim("latin", n=params.N))
        return out


@register
class Bose(_OA):
    """Bose (1938): strength 2, s a prime power, N = s**2, s+1 dimensions per block."""

    name = "bose"
    code = 0
    uses_field = True
    partner_cell_key = True
    reference = staticmethod(_reference_oa.bose)
    geometry = staticmethod(_reference_oa.bose_geometry)
    numpy = staticmethod(_numpy_oa.bose)
    kernel = "pyoa_bose_cell"
    description = "Bose OA, strength 2: N = s^2 with s a prime power, s+1 dimensions per block"
    #: the largest prime with s**2 <= MAX_SPP
    max_s = max(p for p in range(math.isqrt(MAX_SPP), 1, -1) if is_prime(p))

    def shape_args(self, params):
        return (params.s,)

    def cells(self, i, col, params):
        return _numpy_oa.bose_cell(i, col, params.s)

    def test_cases(self):
        # s = 2, GF(4), two blocks of a prime, GF(9), GF(256), the largest prime
        return [dict(spp=4, dims=3), dict(spp=16, dims=5), dict(spp=49, dims=9), dict(spp=81, dims=10),
                dict(spp=256 * 256, dims=4), dict(spp=self.max_s**2, dims=3)]

    def choices(self, dims=None, strength=None):
        if strength not in (None, 2):
            return []
        return [self.choice_for(s, 2) for s in range(2, self.max_s + 1) if gf.is_supported(s)]

    def solve(self, spp, dims, strength):
        if strength not in (None, 2):
            raise ValueError(
                f"bose has strength 2 only (got strength={strength}); "
                "use 'bush' or 'cmjnd' for strength t >= 3 (N = s^t)"
            )
        s = math.isqrt(spp)
        if s * s != spp or not gf.is_supported(s) or s > self.max_s:
            return None
        return self.params_for(s, 2)

    def invalid(self, spp, dims, strength):
        return f"{spp} is not s^2 with s a prime (<= {self.max_s}) or a prime power (<= {gf.MAX_TABLE_Q})"


@register
class Bush(_OA):
    """Bush (1952): strength t, s a prime power, t <= s, N = s**t, s+1 dimensions per block."""

    name = "bush"
    code = 2
    uses_field = True
    reference = staticmethod(_reference_oa.bush)
    geometry = staticmethod(_reference_oa.bush_geometry)
    numpy = staticmethod(_numpy_oa.bush)
    kernel = "pyoa_bush_cell"
    #: t <= s and s**t <= 2**24 allow t <= 8 (8**8 = 2**24; 9**9 is too large)
    max_strength = 8
    description = "Bush OA, strength t: N = s^t with s a prime power and t <= s, s+1 dimensions per block"

    def _strengths(self, dims, strength):
        if strength is not None:
            return [strength]
        return list(range(2, max(2, min(dims or self.max_strength, self.max_strength)) + 1))

    def cells(self, i, col, params):
        return _numpy_oa.bush_cell(i, col, params.s, params.t)

    def test_cases(self):
        # s = t = 2, t = 3 over GF(4) (two blocks), s = 5 t = 4, the largest: s = t = 8
        return [dict(spp=4, dims=2, strength=2), dict(spp=64, dims=7, strength=3),
                dict(spp=625, dims=4, strength=4), dict(spp=8**8, dims=9, strength=8)]

    def choices(self, dims=None, strength=None):
        out = []
        for t in self._strengths(dims, strength):
            s = max(2, t)
            while s**t <= MAX_SPP:
                if gf.is_supported(s):
                    out.append(self.choice_for(s, t))
                s += 1
        return sorted(out)

    def nearest(self, spp, dims=None, strength=None):
        return nearest(_power_candidates(spp, self._strengths(dims, strength),
                                         lambda s, t: s >= t and gf.is_supported(s), self.choice_for), spp)

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
                return self.params_for(s, t)
        return None

    def invalid(self, spp, dims, strength):
        ts = self._strengths(dims, strength)
        what = f"s^{strength}" if strength is not None else f"s^t for any strength 2 <= t <= {ts[-1]}"
        return (f"{spp} is not {what} with s >= t a prime, or a prime power <= {gf.MAX_TABLE_Q}")


@register
class CMJND(_OA):
    """Jarosz et al. (2019) high-dimensional CMJ: any s >= 2, N = s**t, t dimensions per block."""

    name = "cmjnd"
    code = 1
    reference = staticmethod(_reference_oa.cmjnd)
    geometry = staticmethod(_reference_oa.cmjnd_geometry)
    numpy = staticmethod(_numpy_oa.cmjnd)
    kernel = "pyoa_cmjnd_cell"
    description = "N-dimensional correlated multi-jittered OA: N = s^t for any s >= 2, t dimensions per block"
    max_strength = 24  # 2**24 = MAX_SPP

    def cells(self, i, col, params):
        return _numpy_oa.cmjnd_cell(i, col, params.s)

    def test_cases(self):
        # strength 1 (any N), s = 2, t = 3 (two blocks), s = 6 t = 4, the largest s at t = 2 and t = 24
        return [dict(spp=7, dims=1), dict(spp=4, dims=2), dict(spp=27, dims=7, strength=3),
                dict(spp=1296, dims=4, strength=4), dict(spp=4096**2, dims=3, strength=2),
                dict(spp=2**24, dims=25, strength=24)]

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
                                         lambda s, t: s >= 2, self.choice_for), spp)

    def choices(self, dims=None, strength=None):
        strengths = self._strengths(dims, strength)
        if strengths == [1]:  # every count 2 .. 2**24: listed lazily, not as 16.7 million tuples
            return _Counts(2, MAX_SPP, lambda n: self.choice_for(n, 1))
        out = []
        for t in strengths:
            s = 2
            while s**t <= MAX_SPP:
                out.append(self.choice_for(s, t))
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
                return self.params_for(s, t)
        return None

    def invalid(self, spp, dims, strength):
        if strength is not None:
            return f"{spp} is not s^{strength} with s >= 2"
        ts = self._strengths(dims, None)
        return f"{spp} is not s^t with s >= 2 for any strength {ts[0]} <= t <= {ts[-1]} (dims={dims})"


class _Index2(_OA):
    """Shared parts of the strength-2, index-2 constructions: N = 2 s**2,
    2s + 1 dimensions per block, M = 2s sub-strata."""

    uses_field = True

    def shape_args(self, params):
        return (params.s,)

    def cells(self, i, col, params):
        return self.cell(i, col, params.s)

    def levels(self):  # pragma: no cover - abstract
        raise NotImplementedError

    def choices(self, dims=None, strength=None):
        if strength not in (None, 2):
            return []
        return [self.choice_for(s, 2) for s in self.levels()]

    def solve(self, spp, dims, strength):
        if strength not in (None, 2):
            raise ValueError(f"{self.name} has strength 2 only (got strength={strength})")
        s = math.isqrt(spp // 2)
        if spp % 2 or 2 * s * s != spp or s not in self.levels():
            return None
        return self.params_for(s, 2)


@register
class AddelmanKempthorne(_Index2):
    """Addelman and Kempthorne (1961): strength 2, index 2, q an odd prime power,
    N = 2 q**2, 2q + 1 dimensions per block."""

    name = "addelman-kempthorne"
    code = 3
    reference = staticmethod(_reference_oa.addelman_kempthorne)
    geometry = staticmethod(_reference_oa.addelman_kempthorne_geometry)
    numpy = staticmethod(_numpy_oa.addelman_kempthorne)
    cell = staticmethod(_numpy_oa.addelman_kempthorne_cell)
    kernel = "pyoa_addelman_kempthorne_cell"
    description = ("Addelman-Kempthorne OA, strength 2, index 2: N = 2q^2 with q an odd prime power, "
                   "2q+1 dimensions per block")

    @staticmethod
    @lru_cache(maxsize=None)
    def levels():
        top = math.isqrt(MAX_SPP // 2)
        return tuple(q for q in range(3, top + 1, 2) if gf.is_supported(q))

    def test_cases(self):
        # q = 3 (two blocks), GF(9), GF(27), the largest prime q = 2887
        return [dict(spp=18, dims=9), dict(spp=162, dims=19), dict(spp=2 * 27**2, dims=5),
                dict(spp=2 * self.levels()[-1] ** 2, dims=3)]

    def constants(self, params):
        kappa, b, k, c = gf.ak_constants(params.s)
        return [kappa, *b, *k, *c]

    def invalid(self, spp, dims, strength):
        return (f"{spp} is not 2q^2 with q an odd prime (<= {self.levels()[-1]}) "
                f"or odd prime power (<= {gf.MAX_TABLE_Q})")


@register
class BoseBush(_Index2):
    """Bose and Bush (1952): strength 2, index 2, s a power of two,
    N = 2 s**2, 2s + 1 dimensions per block, computed in GF(2s)."""

    name = "bose-bush"
    code = 4
    reference = staticmethod(_reference_oa.bose_bush)
    geometry = staticmethod(_reference_oa.bose_bush_geometry)
    numpy = staticmethod(_numpy_oa.bose_bush)
    cell = staticmethod(_numpy_oa.bose_bush_cell)
    kernel = "pyoa_bose_bush_cell"
    description = "Bose-Bush OA, strength 2, index 2: N = 2s^2 with s a power of two, 2s+1 dimensions per block"

    @staticmethod
    def levels():
        return tuple(2**r for r in range(1, 8))  # GF(2s) tables up to 256

    def field_order(self, params):
        return 2 * params.s

    def test_cases(self):
        # s = 2 (two blocks), 4, 16, the largest s = 128 (GF(256))
        return [dict(spp=8, dims=7), dict(spp=32, dims=9), dict(spp=512, dims=4), dict(spp=2 * 128**2, dims=3)]

    def invalid(self, spp, dims, strength):
        return f"{spp} is not 2s^2 with s a power of two (<= {self.levels()[-1]}, GF(2s) tables up to {gf.MAX_TABLE_Q})"
