"""Float32 rules of docs/spec.md section 7 in Dr.Jit operations (mirrors
``kernels/include/pyoa/floats.h``: every value is clamped into its cell, branch-free).

Dr.Jit emits one correctly rounded IEEE operation per ``+``, ``*`` and
``/`` on ``Float32`` and never contracts a multiply and an add into an FMA
unless ``dr.fma`` is called, which is what the spec asks, with one
exception: it turns a division by a *literal* into a multiplication by its
rounded reciprocal, which changes about half of the quotients by 7 (measured).
Every divisor here is therefore an opaque array (:func:`divide`). The tests
check the rest where it matters: against the NumPy backend, bit for bit.
"""

from __future__ import annotations

from functools import cache

import drjit as dr


@cache
def _opaque(F, n: float):
    return dr.opaque(F, n)


def divide(x, n: int):
    """``x / n`` correctly rounded: ``n`` as an opaque array, never a literal
    (Dr.Jit rewrites ``x / literal`` as ``x * (1 / literal)``)."""
    return x / _opaque(type(x), float(n))


def _types(u):
    return dr.float32_array_t(u), dr.float64_array_t(u)


def cell_floor(c, n: int):
    """The smallest float32 ``>= c / n`` for ``0 <= c <= n <= 2**24`` (``n`` a Python int).

    ``f = c / n`` correctly rounded is that float or the one just below it;
    ``f * n < c`` in float64 is exact (at most 49 significant bits) and says which.
    """
    U = type(c)
    F, D = _types(U)
    f = divide(F(c), n)
    below = D(f) * float(n) < D(c)
    return dr.reinterpret_array(F, dr.reinterpret_array(U, f) + dr.select(below, U(1), U(0)))


def cell_clamp(x, c, n: int):
    """``x`` clamped into its cell ``[c/n, (c+1)/n)``; values inside keep their bits."""
    U = type(c)
    F = dr.float32_array_t(U)
    lo = cell_floor(c, n)
    hi = dr.reinterpret_array(F, dr.reinterpret_array(U, cell_floor(c + 1, n)) - 1)
    return dr.select(x < lo, lo, dr.select(x > hi, hi, x))


def formula_value(stratum, sub, jitter, M: int, s: int):
    """``(stratum + (sub + jitter) / M) / s``: four correctly rounded float32 operations."""
    F = type(jitter)
    return divide(F(stratum) + divide(sub + jitter, M), s)


def sample_value(stratum, sub, jitter, M: int, s: int):
    """The value of the integer sub-stratum ``sub``, clamped into its fine cell ``stratum * M + sub`` of ``s * M``."""
    F = type(jitter)
    return cell_clamp(formula_value(stratum, F(sub), jitter, M, s), stratum * M + sub, M * s)


def centered_value(stratum, jitter, M: int, s: int):
    """The ``centered`` offset: ``sub = (M - 1) / 2``; for odd ``M`` clamped into
    that fine cell, for even ``M`` (a half-integer) into the coarse stratum."""
    F = type(jitter)
    x = formula_value(stratum, F(0.5 * (M - 1)), jitter, M, s)
    if M % 2:
        return cell_clamp(x, stratum * M + (M - 1) // 2, M * s)
    return cell_clamp(x, stratum, s)


def jitter_value(r, amount: float):
    """``0.5 + J * (r - 0.5)`` in float32 (``J`` rounded to float32 first)."""
    import numpy as np

    F = type(r)
    return F(0.5) + F(float(np.float32(amount))) * (r - F(0.5))
