"""Float32 arithmetic one operation at a time (docs/spec.md section 7), in pure Python.

Each float32 operation is done in Python's double precision and then rounded
to float32 with ``struct`` (round to nearest even). For ``+ - * /`` of float32
operands this double rounding is exact: a double has 53 >= 2*24 + 2 bits, so
the result equals the correctly rounded float32 operation (Figueroa, "When is
double rounding innocuous?", SIGNUM Newsletter 30(3), 1995).
"""

from __future__ import annotations

import struct

_F = struct.Struct("<f")
_U = struct.Struct("<I")


def f32(x: float) -> float:
    """Round a Python number to the nearest float32 (ties to even)."""
    return _F.unpack(_F.pack(x))[0]


def from_bits(u: int) -> float:
    """The float32 whose IEEE-754 bits are ``u``."""
    return _F.unpack(_U.pack(u))[0]


def bits(x: float) -> int:
    """The IEEE-754 bits of ``x`` rounded to float32."""
    return _U.unpack(_F.pack(x))[0]


#: ``(1 - 2**-23) * 2**-32``: randfloat's scale, bits 0x2f7ffffe (docs/spec.md section 2).
UNIT_SCALE = from_bits(0x2F7FFFFE)
#: The largest float32 below 1 (bits 0x3f7fffff): the top of the last cell.
ONE_MINUS_ULP = from_bits(0x3F7FFFFF)


def cell_floor(c: int, n: int) -> float:
    """The smallest float32 ``>= c / n`` (``0 <= c <= n <= 2**24``).

    By definition, with exact comparisons: a float32 ``f`` times an integer
    ``n < 2**25`` has at most 49 significant bits, so ``f * n`` is exact in
    a Python float and ``f * n < c`` decides ``f < c/n`` exactly. The loops
    start from the nearest float32 to ``c/n`` and move at most one step (see
    :func:`pyoa._numpy.floats.cell_floor`, which takes that step without
    looping), so they end at once.
    """
    f = f32(c / n)
    while f * n < c:  # below c/n: up one float32
        f = from_bits(bits(f) + 1)
    while f > 0.0 and from_bits(bits(f) - 1) * n >= c:  # a smaller one is still >= c/n
        f = from_bits(bits(f) - 1)
    return f


def cell_clamp(x: float, c: int, n: int) -> float:
    """Clamp the float32 ``x`` into its cell ``[c/n, (c+1)/n)`` (docs/spec.md section 7).

    A value at or above ``(c+1)/n`` becomes the largest float32 below it (the
    float32 just before :func:`cell_floor` of ``c + 1``); a value below
    ``c/n`` becomes ``cell_floor(c, n)``; every other value keeps its bits.
    Each cell of width ``1/n >= 2**-24`` holds at least one float32 of
    ``[0, 1)``, so the result is always inside, and below 1.
    """
    lo = cell_floor(c, n)
    hi = from_bits(bits(cell_floor(c + 1, n)) - 1)
    return lo if x < lo else hi if x > hi else x


def sample_value(stratum: int, sub: float, jitter: float, M: int, s: int) -> float:
    """``(stratum + (sub + jitter) / M) / s`` in float32, clamped into its cell.

    Exactly four correctly rounded float32 operations in this order (SPEC
    sections 1 and 7), then :func:`cell_clamp` into the fine cell
    ``stratum * M + sub`` of ``N = s * M`` cells: float32 keeps 24 bits, so
    a jitter near 0 or 1 can round the value a few units in the last place
    across the cell's edge, which would break the Latin hypercube and, rarely,
    the coarse strata. ``sub`` is an integer, except for the ``centered``
    offset with even ``M`` (``(M-1)/2``, a half-integer), whose value is
    clamped into its coarse stratum ``[stratum/s, (stratum+1)/s)`` instead.
    """
    x = f32(f32(stratum) + f32(f32(sub + jitter) / M))
    x = f32(x / s)
    if sub == int(sub):
        return cell_clamp(x, stratum * M + int(sub), s * M)
    return cell_clamp(x, stratum, s)


def jitter_value(r: float, amount: float) -> float:
    """``0.5 + J * (r - 0.5)`` in float32, ``J`` the jitter amount (docs/spec.md section 3)."""
    return f32(0.5 + f32(amount * f32(r - 0.5)))
