"""Galois fields GF(q), q = p**r, for the orthogonal-array constructions.

Elements are integer *codes*: the base-p digits of a polynomial's
coefficients, least significant digit = constant term (docs/spec.md section 5), so
over a prime field (r = 1) the code is the residue itself and the arithmetic
is plain mod-p arithmetic. Multiplication reduces modulo a fixed monic
irreducible polynomial of degree r: for each q, the *first* one in the order
of its coefficient codes (its code below ``q`` plus the leading ``x**r``);
:func:`modulus` returns it and the README lists them.

The scalar functions here (:func:`add`, :func:`mul`) are the definition, used
by the pure-Python reference; :func:`tables` turns them into ``q x q`` lookup
tables, built once per q and shared by the NumPy backend and the OpenCL kernels.

Limits
------
Prime q: any prime the samplers accept (arithmetic mod q, no tables). Prime
powers that are not prime: q <= 256 (:data:`MAX_TABLE_Q`), so that each table
has at most 65,536 entries (128 KiB as uint16) and fits in any OpenCL device's
memory and cache; larger composite q are refused with the nearest valid counts.

References
----------
.. [1] R. Lidl and H. Niederreiter, "Finite Fields", Cambridge University
   Press, 1997, ch. 1-3.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

MAX_TABLE_Q = 256


@lru_cache(maxsize=None)
def prime_power(q: int) -> tuple[int, int] | None:
    """``(p, r)`` with ``q == p**r`` and p prime, or None if q is not a prime power."""
    if q < 2:
        return None
    p = next(d for d in range(2, q + 1) if q % d == 0)  # smallest factor: prime
    r = 0
    while q % p == 0:
        q //= p
        r += 1
    return (p, r) if q == 1 else None


def is_supported(q: int) -> bool:
    """Whether pyoa has GF(q): q prime, or a prime power up to :data:`MAX_TABLE_Q`."""
    pr = prime_power(q)
    return pr is not None and (pr[1] == 1 or q <= MAX_TABLE_Q)


def _digits(code: int, p: int, r: int) -> list[int]:
    return [(code // p**k) % p for k in range(r)]


def _code(digits: list[int], p: int) -> int:
    return sum(d * p**k for k, d in enumerate(digits))


def _polymod_is_zero(a: list[int], b: list[int], p: int) -> bool:
    """Whether polynomial ``b`` (monic, coefficient lists low->high) divides ``a`` over GF(p)."""
    a = a[:]
    db = len(b) - 1
    for k in range(len(a) - 1, db - 1, -1):
        c = a[k] % p
        if c:
            for m in range(db + 1):
                a[k - db + m] = (a[k - db + m] - c * b[m]) % p
    return not any(x % p for x in a[:db])


@lru_cache(maxsize=None)
def modulus(q: int) -> tuple[int, ...]:
    """Coefficients (constant term first, leading 1 last) of GF(q)'s modulus.

    The first monic irreducible polynomial of degree r over GF(p), ordered by
    the code of its lower coefficients; ``(0, 1)`` (the polynomial x) for prime q.
    """
    pr = prime_power(q)
    if pr is None:
        raise ValueError(f"{q} is not a prime power")
    p, r = pr
    if r == 1:
        return (0, 1)
    for low in range(q):
        f = _digits(low, p, r) + [1]
        if f[0] == 0:
            continue  # divisible by x
        # irreducible iff no monic factor of degree 1..r//2
        if not any(
            _polymod_is_zero(f, _digits(g, p, d) + [1], p)
            for d in range(1, r // 2 + 1)
            for g in range(p**d)
        ):
            return tuple(f)
    raise AssertionError(f"no irreducible polynomial of degree {r} over GF({p})")  # pragma: no cover


def add(a: int, b: int, q: int) -> int:
    """``a + b`` in GF(q): digit-wise addition mod p."""
    p, r = prime_power(q)
    if r == 1:
        return (a + b) % q
    return _code([(x + y) % p for x, y in zip(_digits(a, p, r), _digits(b, p, r))], p)


def mul(a: int, b: int, q: int) -> int:
    """``a * b`` in GF(q): polynomial product reduced by :func:`modulus`."""
    p, r = prime_power(q)
    if r == 1:
        return (a * b) % q
    da, db = _digits(a, p, r), _digits(b, p, r)
    prod = [0] * (2 * r - 1)
    for k, x in enumerate(da):
        for m, y in enumerate(db):
            prod[k + m] = (prod[k + m] + x * y) % p
    f = modulus(q)
    for k in range(2 * r - 2, r - 1, -1):  # x**k = x**(k-r) * (x**r) = -x**(k-r) * (f - x**r)
        c = prod[k]
        if c:
            prod[k] = 0
            for m in range(r):
                prod[k - r + m] = (prod[k - r + m] - c * f[m]) % p
    return _code(prod[:r], p)


@lru_cache(maxsize=None)
def tables(q: int) -> tuple[np.ndarray, np.ndarray]:
    """``(add, mul)``: read-only ``q x q`` uint16 tables of GF(q), flattened row-major.

    ``add[a * q + b] == add(a, b, q)``; built once per q and cached.
    """
    if not is_supported(q) or (prime_power(q)[1] == 1 and q > MAX_TABLE_Q):
        raise ValueError(f"no GF({q}) tables: q must be a prime power <= {MAX_TABLE_Q}")
    a, b = np.divmod(np.arange(q * q), q)
    add_t = np.array([add(int(x), int(y), q) for x, y in zip(a, b)], dtype=np.uint16)
    mul_t = np.array([mul(int(x), int(y), q) for x, y in zip(a, b)], dtype=np.uint16)
    add_t.flags.writeable = False
    mul_t.flags.writeable = False
    return add_t, mul_t


def inverse(a: int, q: int) -> int:
    """The multiplicative inverse of ``a != 0`` in GF(q): ``a**(q-2)``, since
    the multiplicative group has order q - 1 (square-and-multiply)."""
    if a == 0:
        raise ZeroDivisionError("0 has no inverse")
    result, base, e = 1, a, q - 2
    while e:
        if e & 1:
            result = mul(result, base, q)
        base = mul(base, base, q)
        e >>= 1
    return result


def neg(a: int, q: int) -> int:
    """``-a`` in GF(q): each base-p digit negated mod p."""
    p, r = prime_power(q)
    return _code([(-d) % p for d in _digits(a, p, r)], p)


@lru_cache(maxsize=None)
def ak_constants(q: int) -> tuple[int, tuple[int, ...], tuple[int, ...], tuple[int, ...]]:
    """Constants of the Addelman-Kempthorne construction over GF(q), q odd.

    Returns ``(kappa, b, k, c)`` with ``kappa`` the smallest non-square of
    GF(q) (by code) and, for ``m = 1 .. q-1`` (index 0 unused, 0):
    ``b[m] = (kappa - 1) / (4 kappa m)``, ``k[m] = kappa m`` and
    ``c[m] = m**2 (kappa - 1) / 4``, the values of Addelman and Kempthorne
    (1961) as tabulated in Hedayat, Sloane and Stufken, "Orthogonal Arrays"
    (1999), section 3.4.
    """
    pr = prime_power(q)
    if pr is None or pr[0] == 2:
        raise ValueError(f"Addelman-Kempthorne needs q an odd prime power, got {q}")
    p = pr[0]
    squares = {mul(x, x, q) for x in range(q)}
    kappa = next(x for x in range(1, q) if x not in squares)
    four = 4 % p  # the field element 4 = 1 + 1 + 1 + 1 (1 when p = 3)
    num = add(kappa, neg(1, q), q)  # kappa - 1
    b, k, c = [0] * q, [0] * q, [0] * q
    for m in range(1, q):
        b[m] = mul(num, inverse(mul(mul(kappa, four, q), m, q), q), q)
        k[m] = mul(kappa, m, q)
        c[m] = mul(mul(mul(m, m, q), num, q), inverse(four, q), q)
    return kappa, tuple(b), tuple(k), tuple(c)
