"""The catalogue's progressive orthogonal arrays: Owen-scrambled Faure (0, s)-sequences.

The orthogonal arrays of :mod:`pyoa.catalogue.constructions` are finite: ``bose`` is
stratified at ``N = s**2`` and nowhere else, and a render cannot continue
with more samples. A (0, s)-sequence in a prime base ``b`` (Faure 1982 [1]_)
removes both limits: every aligned block of ``b**m`` consecutive samples is
a (0, m, s)-net, so the first ``b**2`` samples are an orthogonal array of
strength 2 with ``b`` levels, the first ``b**3`` one of strength 3 that is
also stratified on the ``b**2 x b`` grids of every pair (a strong orthogonal
array), and every prefix of ``lam * b**m`` samples holds ``lam`` points in
each elementary box of volume ``b**-m``. Owen's nested scrambling [2]_, with
hash-based digit permutations, keeps all of it and makes each value a
stateless function of ``(pixel, i, j)``. The mathematics is in
:mod:`pyoa.reference.faure` and ``docs/samplers.md``.

References
----------
.. [1] H. Faure, "Discrépance de suites associées à un système de
   numération (en dimension s)", Acta Arithmetica 41, 1982.
.. [2] A. B. Owen, "Randomly permuted (t,m,s)-nets and (t,s)-sequences",
   Monte Carlo and Quasi-Monte Carlo Methods, 1995.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import numbers

import numpy as np

from .._numpy import faure as _numpy_faure
from .._numpy import zfaure as _numpy_zfaure
from .entries import MAX_SPP, Claim, CountRule, Launch, SppChoice, check_resolution, nearest, register
from .params import FaureParams
from ..reference import faure as _reference_faure
from ..reference import zfaure as _reference_zfaure

#: Largest base (the largest prime ``b`` with ``b**2 <= 2**24``).
MAX_BASE = _reference_faure.MAX_BASE


#: Every valid base, in increasing order.
BASES = _reference_faure.bases()


def default_base(spp: int, dims: int | None = None) -> int:
    """The base ``faure`` uses when none is given (the rule of :class:`Faure`).

    The largest prime ``b_max`` with ``b_max**2 <= spp`` (strength 2 at
    ``spp``, as many dimensions per block as that allows; 2 below 4 samples),
    lowered to the smallest prime ``>= dims`` when that already holds every
    dimension in one block (the same strength 2 and finer strata: more
    digits fit in ``spp``).

    >>> default_base(121), default_base(1000), default_base(1000, dims=5), default_base(3)
    (11, 31, 5, 2)
    """
    root = math.isqrt(max(int(spp), 1))
    b_max = max((b for b in BASES if b <= root), default=2)
    if dims:
        fits = next((b for b in BASES if b >= dims), None)
        if fits is not None and fits <= b_max:
            return fits
    return b_max


def _levels(b: int, spp: int) -> int:
    """The largest ``m`` with ``b**m <= spp``: the prefix's first full net."""
    m, power = 0, b
    while power <= spp:
        m, power = m + 1, power * b
    return m


@register
class Faure(CountRule):
    """``faure``: Owen-scrambled Faure (0, s)-sequence, progressive orthogonal arrays.

    Any ``spp`` in ``[1, 2**24]``. ``base=b``, a prime in ``[2, 4093]``:
    dimensions ``0 .. b-1`` are one (0, b)-sequence in base ``b``, so every
    aligned block of ``b**m`` samples of a pixel is a (0, m, b)-net: at
    ``N = b**2`` an orthogonal array of strength 2 (``b x b`` cells of every
    pair, as ``bose``), at ``N = b**3`` every triple is stratified into
    ``b x b x b`` cells and every pair into ``b**2 x b`` and ``b x b**2``
    cells, and a prefix of ``lam * b**m`` samples puts ``lam`` in each box.
    Dimensions past ``b`` come from independently scrambled copies (as the
    OA samplers' blocks), each reading the sequence in its own nested order
    of the samples, so that no dimension is a function of another. Each digit is Owen-scrambled by hashes of the
    pixel's seed, the dimension and the digits above it.

    **Progressive**: a pixel's ``i``-th sample does not depend on ``spp``
    (for a given ``base``), so a render can stop at any count and continue.

    **Default base** (``base=None``): the largest prime ``b`` with
    ``b**2 <= spp`` (strength 2 at ``spp`` with as many dimensions per block
    as that allows, as ``bose`` chooses ``s``; 2 below 4 samples), or the
    smallest prime ``>= dims`` when that is smaller (every dimension in one
    block, finer strata). E.g. ``spp=1000, dims=40`` gives ``b=31`` (961
    samples a strength-2 array of 31 dimensions per block); ``spp=1000,
    dims=8`` gives ``b=11``; ``spp=1000, dims=5`` gives ``b=5`` (625 samples
    a (0,4,5)-net: every 4-dimensional projection stratified). The default depends on ``spp``: give ``base`` to continue a
    sequence at another count. Math: :func:`pyoa.reference.faure.faure`.

    >>> pyoa.sampler("faure", spp=121, dims=8).base   # doctest: +SKIP
    11
    """

    name = "faure"
    code = 13
    family = "progressive"
    drjit_module = "faure"
    has_base = True
    progressive = True
    spp_invariant = True
    reference = staticmethod(_reference_faure.faure)
    numpy = staticmethod(_numpy_faure.faure)
    kernel = "pyoa_sample_faure"
    description = (f"Owen-scrambled Faure (0,s)-sequence in a prime base b <= {MAX_BASE} (base=): any N, every "
                   "b^m block a (0,m,b)-net, progressive")

    def params(self, spp, dims):
        b = default_base(spp, dims)
        return FaureParams(N=spp, b=b, m=_levels(b, spp))

    def choice(self, params):
        # s: the base's b strata per axis of a full net; strength: its full nets, b^m <= N
        return SppChoice(params.N, params.b, params.m, params.b, f"b={params.b}")

    def arguments(self, params):
        return {"base": params.b}

    def spp_table(self, choices):
        # any count; the base of each (given or default) and its full nets b^m (aligned blocks of b^m samples are nets)
        return [f"{'spp':>9s} {'base':>5s} {'full nets':>10s} {'dims/block':>10s}",
                *(f"{c.spp:9d} {c.s:5d} {f'{c.s}^{c.strength}':>10s} {c.block_dims:10d}" for c in choices)]

    def with_base(self, params, base):
        if base is None:
            return params
        if isinstance(base, bool) or not isinstance(base, numbers.Integral):
            raise TypeError(f"base must be an int (a prime in [2, {MAX_BASE}]), got {type(base).__name__} {base!r}")
        base = int(base)
        if base not in BASES:
            near = sorted(BASES, key=lambda b: (abs(b - base), b))[:2]
            raise ValueError(f"{self.name}: base must be a prime in [2, {MAX_BASE}], got {base}; nearest: "
                             f"{', '.join(map(str, sorted(near)))}")
        return FaureParams(N=params.N, b=base, m=_levels(base, params.N))

    def shape_args(self, params):
        return (params.b, _reference_faure.index_digits(params.b, params.N))

    def claims(self, params, offset):
        return [Claim("faure", n=params.N, s=params.b, strength=min(3, max(params.m, 1)), block_dims=params.b)]

    def test_cases(self):
        # one sample; a prime count over two blocks; b^2 at base 7; the largest
        # count in base 2 (24 digits) and at the default (largest) base 4093;
        # many blocks of base 31; a count just past a full net
        return [dict(spp=1, dims=1), dict(spp=13, dims=7), dict(spp=49, dims=8, base=7),
                dict(spp=MAX_SPP, dims=3, base=2), dict(spp=MAX_SPP, dims=3),
                dict(spp=4, dims=600, base=31), dict(spp=28, dims=3, base=3)]


@functools.cache
def zfaure_counts() -> dict[int, tuple[int, int]]:
    """Every count ``zfaure`` takes, ``N = b**m`` (``b`` a prime, ``m >= 2``,
    ``N <= 2**24``), mapped to its ``(b, m)``, in increasing order of ``N``."""
    counts = {}
    for b in BASES:
        power, m = b * b, 2
        while power <= MAX_SPP:
            counts[power] = (b, m)
            power, m = power * b, m + 1
    return dict(sorted(counts.items()))


@register
class ZFaure(Faure):
    """``zfaure``: one Faure sequence handed out along a scrambled Morton order
    of the image, blue-noise error in every dimension of a block.

    Needs the image: ``resolution=(width, height)``, each at most ``2**16``,
    pixels row-major (``pixel = y * width + x``). Pixel ``(x, y)`` takes
    the samples ``z(x, y) * spp + i`` of one Owen-scrambled Faure
    (0, b)-sequence per block of ``b`` dimensions, ``z`` its position on a
    base-``b`` Morton order of the image whose tiles permute their rows and
    columns and transpose at random (nested, from the seed). Each pixel's
    ``b**m`` samples are a (0,m,b)-net (an orthogonal array of strength 2 and
    more), each row of ``b`` pixels of a tile a (0,m+1,b)-net, each ``b x b``
    tile a (0,m+2,b)-net: neighbouring pixels' errors cancel in
    every dimension of the block, and the error image is blue noise (little
    low-frequency power), where ``zsobol``'s is blue only in its first pair.

    **Counts**: ``spp = b**m``, a power of a prime ``b`` with ``m >= 2``
    (4, 8, 9, 16, 25, 27, 32, 49, 64, 81, 121, 125, 128, ...): each pixel's
    samples are then one aligned block of the sequence, a (0,m,b)-net, so its
    error is ``faure``'s at the same count and base, and each tile's samples
    an aligned block too. The count fixes the base (``base=``, if given, must
    be it): every dimension of a 4D integrand shares one block from ``b = 5``
    (25, 125, 625 samples). Not progressive: a pixel's samples sit at
    ``z * spp``, so the count is part of every value. Math:
    :func:`pyoa.reference.zfaure.zfaure` and docs/spec.md section 5.12.

    >>> pyoa.sampler("zfaure", spp=125, dims=4, resolution=(64, 64)).base   # doctest: +SKIP
    5
    """

    name = "zfaure"
    code = 14
    drjit_module = "zfaure"
    progressive = False
    why_not_progressive = ("a pixel's samples are indices z * spp + i of one sequence, so the count is part of "
                           "every value: render all of it at once")
    spp_invariant = False
    needs_resolution = True
    reference = staticmethod(_reference_zfaure.zfaure)
    numpy = staticmethod(_numpy_zfaure.zfaure)
    kernel = "pyoa_sample_zfaure"
    description = ("Faure sequence ordered along a scrambled base-b Morton curve of the image: N = b^m (a prime "
                   "power, m >= 2), blue-noise error in every dimension; needs resolution=(width, height)")

    def params(self, spp, dims):
        b, m = zfaure_counts()[spp]
        return FaureParams(N=spp, b=b, m=m)

    def valid(self, spp):
        return spp in zfaure_counts()

    def invalid(self, spp, dims, strength):
        return f"{spp} is not a power b^m of a prime b with m >= 2 (4, 8, 9, 16, 25, 27, 32, ...) up to 2^24"

    def choices(self, dims=None, strength=None):
        self._check(dims, strength)
        return [self._choice(n, dims) for n in zfaure_counts()]

    def nearest(self, spp, dims=None, strength=None):
        return nearest(self.choices(dims, strength), spp)

    def with_resolution(self, params, resolution):
        resolution = check_resolution(self.name, resolution, _reference_zfaure.MAX_RESOLUTION,
                                      "its Morton order spans the image")
        _reference_zfaure.check_shape(params.N, params.b, *resolution)
        return dataclasses.replace(params, resolution=resolution)

    def with_base(self, params, base):
        if base is None or super().with_base(params, base).b == params.b:
            return params
        powers = [n for n, (b, _) in zfaure_counts().items() if b == base]
        raise ValueError(f"zfaure: {params.N} samples are {params.b}^{params.m}, base {params.b}; base {base} takes "
                         f"{', '.join(map(str, powers[:6]))}{', ...' if len(powers) > 6 else ''} (the count fixes "
                         "the base: give one of these counts, or no base)")

    def arguments(self, params):
        return {"base": params.b, "resolution": params.resolution}

    def grid(self, params) -> int:
        """``k``: the digits of the padded ``b**k x b**k`` grid of the image."""
        return _reference_zfaure.grid_digits(params.b, *params.resolution)

    def shape_args(self, params):
        return (params.N, params.b, self.grid(params), params.resolution[0])

    def seed_args(self, pixel_seed, seed, pixel):
        return (pixel, seed)  # the order needs the pixel itself; the seed keys the one sequence

    def launch(self, params, offset, jitter):
        # the kernel's three shape words: N, the base with k in its high half, the width
        N, b, k, width = self.shape_args(params)
        return Launch(f"generate_{self.function}", (np.uint32(N), np.uint32(b | k << 16), np.uint32(width),
                                                    np.float32(jitter)))

    def claims(self, params, offset):
        return [Claim("faure", n=params.N, s=params.b, strength=min(3, max(params.m, 1)), block_dims=params.b)]

    def test_cases(self):
        # one pixel at the smallest count; base 5 on a non-square image not a power of 5, over two
        # blocks; base 2 at full HD at 4096 spp (T past 2**32); base 7 past a block; the largest
        # count at a large image in base 2; the largest base
        return [dict(spp=4, dims=1, resolution=(1, 1)), dict(spp=125, dims=7, resolution=(7, 3), base=5),
                dict(spp=4096, dims=3, resolution=(1920, 1080)), dict(spp=49, dims=9, resolution=(16, 16)),
                dict(spp=MAX_SPP, dims=3, resolution=(4096, 4096)), dict(spp=4093**2, dims=2, resolution=(2, 2))]
