"""The float32 rules of docs/spec.md section 7 over an array namespace
(:mod:`pyoa._arrays`): :mod:`pyoa.reference.floats` on float32 arrays, and
``kernels/include/pyoa/floats.h``.

NumPy and Dr.Jit evaluate float32 arithmetic one correctly rounded operation
at a time and never fuse a multiply and an add (Dr.Jit only on ``dr.fma``),
which is what the spec asks; divisions go through ``xp.divide``.
"""

from __future__ import annotations

import numbers

from ..reference.floats import f32

#: Unit roundoff of float32.
UNIT_ROUNDOFF = 2.0**-24


def cell_floor(xp, c, n: int):
    """The smallest float32 ``>= c / n`` for uint32 ``0 <= c <= n <= 2**24`` (a Python int ``n``).

    ``f = c / n`` correctly rounded is the float32 nearest to ``c/n``, so it
    is either that smallest float32 or the one just below it: one step up
    when ``f < c/n``. The test ``f * n < c`` is exact in float64 (a float32
    times an integer below ``2**25`` has at most 49 significant bits); the
    kernels take the sign of the exactly rounded ``fma(f, n, -c)`` instead.
    """
    f = xp.divide(xp.f32(c), n)
    below = xp.f64(f) * n < xp.f64(c)
    return xp.from_bits(xp.bits(f) + xp.u32(below))


def cell_clamp(xp, x, c, n: int):
    """Float32 ``x`` clamped into its cell ``[c/n, (c+1)/n)``
    (:func:`pyoa.reference.floats.cell_clamp`); values inside keep their bits."""
    lo = cell_floor(xp, c, n)
    hi = xp.from_bits(xp.bits(cell_floor(xp, c + 1, n)) - 1)
    return xp.select(x < lo, lo, xp.select(x > hi, hi, x))


def sample_value(xp, stratum, sub, jitter, M: int, s: int):
    """``(stratum + (sub + jitter) / M) / s`` in float32, clamped into its cell
    (:func:`pyoa.reference.floats.sample_value`).

    ``sub`` is a uint32 array (the fine cell is ``stratum * M + sub`` of
    ``N = s * M``) or the number ``(M-1)/2`` of ``centered``: an integer for
    odd ``M``, else a half-integer, whose values are clamped into their
    coarse stratum ``stratum`` of ``s``.

    Notes
    -----
    The clamp moves a few values in a million, and a backend that can skip
    work (NumPy, ``xp.where_needed``) examines only the values that can
    have crossed an edge. Four correctly rounded operations give ``x = t (1
    + e)`` with ``|e| <= (1 + u)**4 - 1 < 4.0001 u`` (``u = 2**-24``) for
    the exact ``t < 1`` of the same float32 inputs, so ``|x - t| < 4.0001
    u``; and ``t N = c + jitter``, so ``t`` lies ``min(jitter, 1 - jitter) /
    N`` from its cell's nearer edge. A value can leave its cell only if
    ``min(jitter, 1 - jitter) < 4.0001 u N``: outside that band (with a
    margin, ``5 u N``) the value is inside and keeps its bits. Of the others,
    ``floor(float64(x) * N)`` (exact) tells those outside, and
    :func:`cell_clamp` moves them. The kernels and Dr.Jit clamp every value
    instead (no branch); the conformance tests check that they agree bit for bit.
    """
    N = s * M
    if not isinstance(sub, numbers.Real):  # a uint32 array
        x = _formula(xp, stratum, xp.f32(sub), jitter, M, s)
        return _into_cell(xp, x, N, lambda st, sb: st * M + sb, (stratum, sub), _near_edges(jitter, N))
    half = float(sub)
    x = _formula(xp, stratum, half, jitter, M, s)
    if half.is_integer():
        return _into_cell(xp, x, N, lambda st: st * M + int(half), (stratum,), _near_edges(jitter, N))
    # a half-integer sub: every value is examined, against its coarse stratum
    return _into_cell(xp, x, s, lambda st: st, (stratum,), None)


def _formula(xp, stratum, sub, jitter, M: int, s: int):
    """``(stratum + (sub + jitter) / M) / s``: four correctly rounded float32 operations."""
    return xp.divide(xp.f32(stratum) + xp.divide(sub + jitter, M), s)


def _near_edges(jitter, n: int):
    """The lanes whose value can have left its cell of ``n`` (the band of
    :func:`sample_value`'s notes), or None: every lane (the band covers all
    jitters when ``n`` nears ``2**24``)."""
    band = 5 * UNIT_ROUNDOFF * n
    return (jitter < band) | (jitter > 1 - band) if band < 0.5 else None


def _into_cell(xp, x, n: int, cell, parts: tuple, near):
    """``x`` clamped into cell ``cell(*parts)`` of ``n``, the cell's index
    computed, and the clamp applied, only where needed: in lanes ``near``, for
    the values found outside."""
    def clamp(x, *parts):
        c = cell(*parts)
        outside = xp.u32(xp.f64(x) * n) != c  # float64 -> uint32 truncates: floor(x n), exact
        return xp.where_needed(outside, lambda x, c: cell_clamp(xp, x, c, n), x, c)

    return xp.where_needed(near, clamp, x, *parts)


def jitter_value(xp, r, amount: float):
    """``0.5 + J * (r - 0.5)`` in float32, ``J`` the amount rounded to float32 (docs/spec.md section 3.4)."""
    return 0.5 + f32(amount) * (r - 0.5)
