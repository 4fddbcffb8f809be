"""The catalogue's comparison samplers: the paper's baselines [1]_ and pbrt-v4's.

``random``, the padded ``jittered2d``, ``cmj2d`` and ``sobol02``, and the
high-dimensional ``halton`` and ``sobol`` of the paper's tables; pbrt-v4's
default ``zsobol`` [2]_ and the progressive multi-jittered ``pmj02`` [3]_:
their valid sample counts, their parameters and their implementations. Each
is evaluated statelessly per (pixel, sample, dimension) like the OA samplers;
the mathematics is in :mod:`pyoa.reference.baselines`,
:mod:`pyoa.reference.zsobol`, :mod:`pyoa.reference.pmj02` and
``docs/samplers.md``.

References
----------
.. [1] W. Jarosz, A. Enayet, A. Kensler, C. Kilpatrick, P. Christensen,
   "Orthogonal Array Sampling for Monte Carlo Rendering", EGSR 2019, Table 1.
.. [2] A. G. M. Ahmed, P. Wonka, "Screen-space blue-noise diffusion of Monte
   Carlo sampling error via hierarchical ordering of pixels", SIGGRAPH Asia
   2020; M. Pharr, W. Jakob, G. Humphreys, pbrt-v4, ``ZSobolSampler``.
.. [3] P. Christensen, A. Kensler, C. Kilpatrick, "Progressive Multi-Jittered
   Sample Sequences", EGSR 2018.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Sequence

from ..tables import pmj02 as pmj02_tables, sequences
from .._numpy import baselines as _numpy_baselines
from .._numpy import pmj02 as _numpy_pmj02
from .._numpy import zsobol as _numpy_zsobol
from .entries import MAX_SPP, Claim, CountRule, SppChoice, check_resolution, register
from .params import PointSetParams, SequenceParams
from ..reference import baselines as _reference_baselines
from ..reference import pmj02 as _reference_pmj02
from ..reference import zsobol as _reference_zsobol


#: The listed strata of the samplers of padded pairs, (s, strength, block_dims):
#: each pair of dimensions stratified on 2 x 2 cells and finer
PAIRS = (2, 2, 2)


class Baseline(CountRule):
    """The comparison samplers' family.

    A sequence (:class:`pyoa.catalogue.params.SequenceParams`) unless the entry is a
    padded 2D grid (:class:`PointSet`). What a listing shows of one
    (:meth:`choice`): its :attr:`strata` and, for the powers of two, the
    exponent. They have no offset styles; only the samplers with ``jittered
    = True`` take a jitter amount.
    """

    family = "baseline"
    drjit_module = "baselines"
    #: ``(s, strength, block_dims)`` as a listing shows them (SppChoice, the
    #: sampler's attributes): ``strength``-dimensional projections of each
    #: block of ``block_dims`` dimensions stratified into ``s`` strata per
    #: axis; None: ``(1, 0, max_dims)``, no stratification claimed
    strata: tuple[int, int, int] | None = None
    #: the vector kernel of kernels/vector.cl (VBASELINE) that computes it, or 0
    vector_kind = 0

    def params(self, spp, dims):
        return SequenceParams(N=spp, dims=dims or 0)

    def choice(self, params):
        s, strength, block_dims = self.strata or (1, 0, self.max_dims)
        return SppChoice(params.N, s, strength, block_dims, self.grid(params))

    def grid(self, params) -> str:
        """The listing's detail: ``"2^7"`` for the powers of two, else ``""``."""
        return f"2^{params.N.bit_length() - 1}" if self.counts == "pow2" else ""

    def detail(self, params):
        grid = self.grid(params)
        return f"grid {grid}" if grid else ""

    def spp_table(self, choices):
        # their grid (if any) instead of s and t
        return [f"{'spp':>9s} {'grid':>11s}", *(f"{c.spp:9d} {c.detail or '-':>11s}" for c in choices)]


class PointSet(Baseline):
    """The padded 2D grids (:class:`pyoa.catalogue.params.PointSetParams`): every pair of
    dimensions an ``a x c`` grid with one point per cell, stratified at the
    full count only. ``jitter`` scales the offset inside the cell."""

    jittered = True

    def choice(self, params):
        return SppChoice(params.N, params.a, 2, 2, self.grid(params))

    def grid(self, params):
        return f"{params.a}x{params.c}"


@register
class Random(Baseline):
    """``random``: independent uniform values, the paper's "Random".

    Any ``spp`` in ``[1, 2**24]``, any number of dimensions. No
    stratification: the variance of an estimate falls as ``1/N``. Values are
    24-bit (``k * 2**-24``). Math: :func:`pyoa.reference.baselines.random`.

    >>> pyoa.sampler("random", spp=100, dims=7).generate().shape   # doctest: +SKIP
    (1, 100, 7)
    """

    name = "random"
    code = 5
    progressive = True
    spp_invariant = True
    reference = staticmethod(_reference_baselines.random)
    numpy = staticmethod(_numpy_baselines.random)
    kernel = "pyoa_sample_random"
    description = "independent uniform random values (no stratification): any N"

    strata = (1, 0, 1)


@register
class Jittered2D(PointSet):
    """``jittered2d``: padded 2D jittered sampling, the paper's "Jittered2D (pad)".

    ``spp = m**2``. Dimensions ``(0, 1), (2, 3), ...`` are independent pairs,
    each an ``m x m`` jittered grid with exactly one point per cell (its
    sample order shuffled per pair); with an odd ``dims`` the last dimension
    is a 1D jittered set of ``N`` strata. No 1D stratification beyond ``m``
    strata inside a pair. ``jitter`` scales the offset inside the cell
    (0: cell centres). Math: :func:`pyoa.reference.baselines.jittered2d`.
    """

    name = "jittered2d"
    code = 6
    counts = "square"
    vector_kind = 1
    reference = staticmethod(_reference_baselines.jittered2d)
    numpy = staticmethod(_numpy_baselines.jittered2d)
    kernel = "pyoa_sample_jittered2d"
    description = "padded 2D jittered: N = m^2, each pair of dimensions an m x m jittered grid"

    def valid(self, spp):
        return 1 <= spp <= MAX_SPP and math.isqrt(spp) ** 2 == spp

    def params(self, spp, dims):
        m = math.isqrt(spp)
        return PointSetParams(N=spp, a=m, c=m, dims=dims or 0)

    def choices(self, dims=None, strength=None):
        self._check(dims, strength)
        return [self._choice(m * m, dims) for m in range(1, math.isqrt(MAX_SPP) + 1)]

    def invalid(self, spp, dims, strength):
        return f"{spp} is not a square m^2 (m <= {math.isqrt(MAX_SPP)})"

    def shape_args(self, params):
        return (params.a, params.dims)

    def claims(self, params, offset):
        # each pair an m x m jittered grid, each dimension m strata of m points
        return [Claim("grid", a=params.a, c=params.c), Claim("latin", n=params.a)]

    def test_cases(self):
        # 1 x 1, an odd dims (a lone last dimension), 4096 x 4096
        return [dict(spp=1, dims=2), dict(spp=9, dims=5), dict(spp=121, dims=8), dict(spp=MAX_SPP, dims=3)]


@register
class CMJ2D(PointSet):
    """``cmj2d``: padded correlated multi-jittered 2D (Kensler 2013), the paper's "CMJ2D (pad)".

    Any ``spp``, split into the most nearly square grid ``m x n`` (``m`` the
    largest divisor of N not above its square root: 120 = 10 x 12, a prime
    N is 1 x N). Each pair of dimensions has one point per cell of the
    ``m x n`` grid, and both of its coordinates are 1D Latin hypercubes of
    ``N`` strata; pairs are independent (their own seed and sample order).
    ``jitter`` as for :class:`Jittered2D`. Math:
    :func:`pyoa.reference.baselines.cmj2d`.
    """

    name = "cmj2d"
    code = 7
    vector_kind = 2
    reference = staticmethod(_reference_baselines.cmj2d)
    numpy = staticmethod(_numpy_baselines.cmj2d)
    kernel = "pyoa_sample_cmj2d"
    description = "padded 2D correlated multi-jittered (Kensler): any N = m x n, the most nearly square grid"

    def params(self, spp, dims):
        m = max(d for d in range(1, math.isqrt(spp) + 1) if spp % d == 0)
        return PointSetParams(N=spp, a=m, c=spp // m, dims=dims or 0)

    def shape_args(self, params):
        return (params.a, params.c)

    def claims(self, params, offset):
        return [Claim("grid", a=params.a, c=params.c), Claim("latin", n=params.N)]

    def test_cases(self):
        # a prime (1 x N), 10 x 12, a square, the largest prime below 2^24 and 4093 x 4099
        return [dict(spp=7, dims=3), dict(spp=120, dims=4), dict(spp=256, dims=6),
                dict(spp=16777213, dims=2), dict(spp=4093 * 4099, dims=3)]


@register
class Sobol02(Baseline):
    """``sobol02``: padded (0,2)-sequence, the paper's "(0,2)-seq. (pad)".

    ``spp = 2**k``. Each pair of dimensions is the first two Sobol
    dimensions, Owen-scrambled (Burley 2020) with its own seed and its
    sample order shuffled by a nested scramble of the index, so every
    power-of-two prefix of every pair has exactly one point in every
    elementary interval ``2**-u x 2**-v`` with ``u + v = k``. Math:
    :func:`pyoa.reference.baselines.sobol02`.
    """

    name = "sobol02"
    strata = PAIRS
    code = 8
    progressive = True
    counts = "pow2"
    reference = staticmethod(_reference_baselines.sobol02)
    numpy = staticmethod(_numpy_baselines.sobol02)
    kernel = "pyoa_sample_sobol02"
    description = "padded (0,2)-sequence, Owen-scrambled and shuffled per pair: N a power of two"

    def shape_args(self, params):
        return (params.N.bit_length() - 1,)

    def constants(self, params):
        return sequences.sobol_matrices()[:2]

    def constants_key(self, params):
        return self.name  # the same two dimensions for every count

    def claims(self, params, offset):
        return [Claim("net", n=params.N, prefixes=True), Claim("latin", n=params.N)]


@register
class Halton(Baseline):
    """``halton``: Owen-scrambled Halton sequence, the paper's "Halton".

    Any ``spp``; dimension ``j`` is the radical inverse in the ``j``-th prime
    (2, 3, 5, ...), up to 6542 dimensions (the primes below ``2**16``), each
    digit permuted by a hash of the digits before it (Owen's nested
    scrambling), per dimension and pixel. The first ``b**k`` samples of a
    base-``b`` dimension fall one in each of ``b**k`` intervals. Math:
    :func:`pyoa.reference.baselines.halton`.
    """

    name = "halton"
    code = 9
    progressive = True
    spp_invariant = True
    reference = staticmethod(_reference_baselines.halton)
    numpy = staticmethod(_numpy_baselines.halton)
    kernel = "pyoa_sample_halton"
    max_dims = sequences.HALTON_MAX_DIMS
    more_dims_hint = " (one prime base below 2^16 each); use sobol (21201) or a padded sampler for more"
    description = f"Owen-scrambled Halton: any N, up to {sequences.HALTON_MAX_DIMS} dimensions"

    def constants(self, params):
        return sequences.primes()

    def constants_key(self, params):
        return self.name


@register
class Sobol(Baseline):
    """``sobol``: Owen-scrambled Sobol sequence, the paper's "Sobol".

    ``spp = 2**k``, up to 21201 dimensions with the Joe-Kuo direction
    numbers SciPy ships (:mod:`pyoa.tables.sequences`), in SciPy's Gray-code order,
    each dimension Owen-scrambled (Burley 2020) per pixel. Every power-of-two
    prefix is a (t,m,s)-net: each dimension stratified into ``2**k``
    intervals, dimensions 0 and 1 a (0,k,2)-net. Unscrambled (``p = 0``
    through :mod:`pyoa.reference.baselines`) it equals
    ``scipy.stats.qmc.Sobol(d, scramble=False)``. Math:
    :func:`pyoa.reference.baselines.sobol`.
    """

    name = "sobol"
    code = 10
    progressive = True
    spp_invariant = True
    counts = "pow2"
    reference = staticmethod(_reference_baselines.sobol)
    numpy = staticmethod(_numpy_baselines.sobol)
    kernel = "pyoa_sample_sobol"
    max_dims = sequences.SOBOL_MAX_DIMS
    more_dims_hint = " (the Joe-Kuo table); use a padded sampler for more"
    description = (f"Owen-scrambled Sobol (Joe-Kuo directions): N a power of two, "
                   f"up to {sequences.SOBOL_MAX_DIMS} dimensions")

    def constants(self, params):
        V = sequences.sobol_matrices()
        return V[: params.dims] if params.dims else V

    def claims(self, params, offset):
        # every dimension a (0,1)-sequence; dimensions 0 and 1 a (0,2)-sequence
        return [Claim("net", n=params.N, prefixes=True, pairs=1), Claim("latin", n=params.N)]


@register
class ZSobol(Baseline):
    """``zsobol``: pbrt-v4's default sampler (Ahmed and Wonka 2020).

    ``spp = 2**k``; needs the image: ``resolution=(width, height)``, each at
    most ``2**16``, pixels numbered row-major (``pixel = y * width + x``, as
    pyoa's renderer numbers them). Every pixel takes its own consecutive block
    of ``N`` indices of one Owen-scrambled (0,2)-sequence per pair of
    dimensions, handed out along a Morton (Z) curve of the image whose base-4
    digits are permuted by hashes of the digits above them: each pixel's
    samples of each pair are a (0,k,2)-net, and neighbouring pixels' blocks
    together form larger nets, so the per-pixel errors are negatively
    correlated (blue noise in screen space). Pairs ``(2b, 2b+1)`` are
    scrambled independently (padding). Math and the differences from pbrt:
    :func:`pyoa.reference.zsobol.zsobol`.
    """

    name = "zsobol"
    strata = PAIRS
    code = 11
    progressive = True
    counts = "pow2"
    needs_resolution = True
    reference = staticmethod(_reference_zsobol.zsobol)
    numpy = staticmethod(_numpy_zsobol.zsobol)
    kernel = "pyoa_sample_zsobol"
    description = ("pbrt-v4's Z-order Sobol (Ahmed-Wonka): N a power of two, blue-noise error across pixels; "
                   "needs resolution=(width, height)")

    def with_resolution(self, params, resolution):
        resolution = check_resolution(self.name, resolution, 1 << _reference_zsobol.MAX_LOG2RES,
                                      "its Z-order curve spans the image")
        return dataclasses.replace(params, resolution=resolution)

    def arguments(self, params):
        return {"resolution": params.resolution}

    def shape_args(self, params):
        width, height = params.resolution
        return (params.N.bit_length() - 1, _reference_zsobol.resolution_log2(width, height), width)

    def seed_args(self, pixel_seed, seed, pixel):
        return (pixel, seed)  # the Morton curve needs the pixel itself; the seed keys the pairs

    def claims(self, params, offset):
        return [Claim("net", n=params.N), Claim("latin", n=params.N)]

    def test_cases(self):
        # one pixel, a non-power-of-two image at an odd k, full HD, the largest image and count
        return [dict(spp=1, dims=2, resolution=(1, 1)), dict(spp=32, dims=5, resolution=(5, 3)),
                dict(spp=16, dims=4, resolution=(1920, 1080)), dict(spp=256, dims=3, resolution=(64, 64)),
                dict(spp=MAX_SPP, dims=3, resolution=(65536, 65536))]


@register
class PMJ02(Baseline):
    """``pmj02``: progressive multi-jittered (0,2) sequences (Christensen et al. 2018).

    ``spp = 2**k`` up to ``2**16``. Each pair of dimensions reads one of 16
    precomputed pmj02 sequences of ``2**16`` points (built once by pyoa's own
    implementation of the paper's algorithm, cached: :mod:`pyoa.tables.pmj02`),
    chosen per (pixel, pair) by a hash and digitally shifted (XOR) by
    another: every power-of-two prefix of every pair is a (0,k,2)-net and each
    coordinate of it is stratified into ``2**k`` intervals, so the first ``n``
    samples of a pixel are as good as any ``n``. Each pair reads its set in
    its own nested-scrambled order, which maps every prefix onto an aligned
    block of the set (a net too), so pairs are independent and the sequence
    stays progressive. Math: :func:`pyoa.reference.pmj02.pmj02`.
    """

    name = "pmj02"
    strata = PAIRS
    code = 12
    progressive = True
    spp_invariant = True  # log2n only bounds i: the index scramble covers all 2**16
    counts = "pow2"
    max_spp = _reference_pmj02.POINTS
    reference = staticmethod(_reference_pmj02.pmj02)
    numpy = staticmethod(_numpy_pmj02.pmj02)
    kernel = "pyoa_sample_pmj02"
    description = (f"progressive multi-jittered (0,2) (Christensen et al.): N a power of two up to "
                   f"2^{_reference_pmj02.POINTS_LOG2}, every power-of-two prefix a (0,2)-net")

    def shape_args(self, params):
        return (params.N.bit_length() - 1,)

    def constants(self, params):
        return pmj02_tables.tables()

    def constants_key(self, params):
        return self.name  # one table for every count

    def claims(self, params, offset):
        return [Claim("net", n=params.N, prefixes=True), Claim("latin", n=params.N)]
