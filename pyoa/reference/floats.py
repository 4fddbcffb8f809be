"""Float32 arithmetic one operation at a time (SPEC section 7), in pure Python.

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


#: ``(1 - 2**-23) * 2**-32``: randfloat's scale, bits 0x2f7ffffe (SPEC section 2).
UNIT_SCALE = from_bits(0x2F7FFFFE)
#: The largest float32 below 1 (bits 0x3f7fffff), the value that replaces 1.0.
ONE_MINUS_ULP = from_bits(0x3F7FFFFF)


def sample_value(stratum: int, sub: float, jitter: float, M: int, s: int) -> float:
    """``(stratum + (sub + jitter) / M) / s`` in float32, clamped below 1.

    Exactly four correctly rounded float32 operations in this order (SPEC
    sections 1 and 7); a result that rounds to 1.0 becomes the largest
    float32 below 1.
    """
    x = f32(f32(stratum) + f32(f32(sub + jitter) / M))
    x = f32(x / s)
    return ONE_MINUS_ULP if x >= 1.0 else x


def jitter_value(r: float, amount: float) -> float:
    """``0.5 + J * (r - 0.5)`` in float32, ``J`` the jitter amount (SPEC section 3)."""
    return f32(0.5 + f32(amount * f32(r - 0.5)))
