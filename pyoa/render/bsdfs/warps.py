"""The warps that one-point forms share, in plain Python that numba compiles
(:func:`~pyoa.render.bsdfs.base.scalar`): the BSDFs' and, through
:mod:`pyoa.render.compiled.geometry`, the compiled camera's.

Each mirrors a vectorized form of :mod:`pyoa.render.geometry`; the sines and
cosines are polynomials (:func:`sin_cos`) instead of libm's, so the compiled
shading agrees with the NumPy reference to within 2 ulps there. All are
written with selects instead of branches, so that loops over lanes calling
them vectorize.
"""

from __future__ import annotations

import math

from .base import scalar

#: Taylor coefficients (-1)^k / (2k+1)! and (-1)^k / (2k)! of sin and cos,
#: to x^17 and x^18: on |x| <= pi/4 the first term left out is below 6e-17
#: of the result (half an ulp is 1.1e-16).
_SIN = tuple((-1) ** k / math.factorial(2 * k + 1) for k in range(9))
_COS = tuple((-1) ** k / math.factorial(2 * k) for k in range(10))


@scalar
def sin_cos(x):
    """``(sin x, cos x)`` for ``|x| <= pi/4``, as polynomials (Horner's
    scheme, within 2 ulps of libm's): the warps' angles all reduce to this
    range, and libm's ``sin`` and ``cos`` (about 18 ns each, one lane at a
    time) were most of a diffuse bounce's cost (docs/performance.md)."""
    z = x * x
    s = _SIN[8]
    for k in range(7, -1, -1):
        s = s * z + _SIN[k]
    c = _COS[9]
    for k in range(8, -1, -1):
        c = c * z + _COS[k]
    return x * s, c


@scalar
def cos_sin_turn(u):
    """``(cos 2 pi u, sin 2 pi u)`` for ``u`` in ``[0, 1]``: the nearest
    quarter turn ``k / 4`` is exact, the rest ``2 pi (u - k / 4)`` lies in
    ``[-pi/4, pi/4]`` (:func:`sin_cos`), and the quarter turns swap and
    negate. Written with selects, the quarter ``q = k mod 4`` kept a float
    (exact for whole numbers), so that a loop over lanes vectorizes (AVX2
    has no packed conversion of doubles to 64-bit integers)."""
    k = math.floor(4.0 * u + 0.5)
    s, c = sin_cos(2.0 * math.pi * (u - 0.25 * k))
    q = k - 4.0 * math.floor(0.25 * k)
    cq = c if q == 0.0 else (-s if q == 1.0 else (-c if q == 2.0 else s))
    sq = s if q == 0.0 else (c if q == 1.0 else (-s if q == 2.0 else -c))
    return cq, sq


@scalar
def concentric_disk(u0, u1):
    """Shirley and Chiu's concentric map of ``[0,1)^2`` onto the unit disk
    (the angle ``pi/2 - t`` of the second wedge as ``cos`` and ``sin`` of
    ``t`` swapped), written with selects instead of branches so that a loop
    over lanes vectorizes: the wedge picks the operands, each lane does the
    same operations as the branching form, so the same bits."""
    a = 2.0 * u0 - 1.0
    b = 2.0 * u1 - 1.0
    wide = abs(a) > abs(b)
    r = a if wide else b
    s, c = sin_cos((math.pi / 4) * ((b if wide else a) / r))
    x = r * (c if wide else s)
    y = r * (s if wide else c)
    centre = (a == 0.0) & (b == 0.0)
    return 0.0 if centre else x, 0.0 if centre else y
