"""pyoa.tables.gf: the Galois fields GF(q) behind Bose over prime powers and Bush.

Checked against field axioms on the lookup tables (every prime power q <= 256
that is not a prime; prime q use plain mod-q arithmetic), and against an
independent polynomial implementation (tests.helpers.PolyField, Rabin's
irreducibility test) for the moduli and the element codes of docs/spec.md section 5.
"""

from __future__ import annotations

import numpy as np
import pytest

from pyoa.tables import gf
from tests.helpers import (
    GF_POWERS,
    KNOWN_MODULI,
    PolyField,
    factor_prime_power,
    is_irreducible,
)

PRIMES_256 = [q for q in range(2, 257) if factor_prime_power(q) == (q, 1)]


def _tables(q):
    add, mul = gf.tables(q)
    return add.reshape(q, q).astype(np.int64), mul.reshape(q, q).astype(np.int64)


def _triples(q, n=20000, seed=0):
    """Every triple for small q, else n random ones."""
    if q**3 <= 40000:
        a, b, c = np.meshgrid(np.arange(q), np.arange(q), np.arange(q), indexing="ij")
        return a.ravel(), b.ravel(), c.ravel()
    rng = np.random.default_rng(seed + q)
    return tuple(rng.integers(0, q, n) for _ in range(3))


# ----------------------------------------------------------------------------- prime_power, is_supported

@pytest.mark.parametrize("q, want, supported", [
    (-4, None, False), (0, None, False), (1, None, False), (2, (2, 1), True), (3, (3, 1), True),
    (4, (2, 2), True), (6, None, False), (12, None, False), (100, None, False), (243, (3, 5), True),
    (256, (2, 8), True), (257, (257, 1), True), (289, (17, 2), False), (512, (2, 9), False),
    (4093, (4093, 1), True), (4096, (2, 12), False), (4097, None, False), (65521, (65521, 1), True),
])
def test_prime_power_and_is_supported_edges(q, want, supported):
    assert gf.prime_power(q) == want
    assert gf.is_supported(q) is supported


def test_prime_power_agrees_with_trial_division_up_to_4096():
    for q in range(-2, 4097):
        assert gf.prime_power(q) == factor_prime_power(q), q
        pr = factor_prime_power(q)
        assert gf.is_supported(q) == (pr is not None and (pr[1] == 1 or q <= gf.MAX_TABLE_Q)), q


def test_supported_prime_powers_up_to_256():
    assert gf.MAX_TABLE_Q == 256
    composite = [q for q in range(2, 257) if gf.prime_power(q) and gf.prime_power(q)[1] > 1]
    assert composite == GF_POWERS
    assert all(gf.is_supported(q) for q in composite + PRIMES_256)


# ----------------------------------------------------------------------------- moduli

@pytest.mark.parametrize("q", sorted(KNOWN_MODULI))
def test_known_moduli(q):
    assert gf.modulus(q) == KNOWN_MODULI[q]


@pytest.mark.parametrize("q", GF_POWERS)
def test_modulus_is_the_first_monic_irreducible(q):
    """Monic of degree r, irreducible (Rabin's test, independent of pyoa's trial
    division), and the first one by the code of its lower coefficients (the
    documented rule, so the element codes are reproducible)."""
    p, r = factor_prime_power(q)
    f = gf.modulus(q)
    assert isinstance(f, tuple) and len(f) == r + 1 and f[-1] == 1
    assert all(isinstance(c, int) and 0 <= c < p for c in f)
    assert is_irreducible(list(f), p)
    if r <= 3:  # irreducible <=> no root in GF(p)
        assert all(sum(c * x**k for k, c in enumerate(f)) % p for x in range(p))
    code = sum(c * p**k for k, c in enumerate(f[:-1]))
    for low in range(code):
        g = [(low // p**k) % p for k in range(r)] + [1]
        assert not is_irreducible(g, p), f"{g} (code {low}) is irreducible and comes before {f}"


def test_rabin_oracle_counts_irreducibles():
    """The independent irreducibility test itself: it finds exactly the number of
    monic irreducible polynomials Gauss's formula gives (30 of degree 8 over GF(2),
    48 of degree 5 over GF(3), 3 of degree 2 over GF(3))."""
    for p, r, want in [(2, 8, 30), (3, 5, 48), (3, 2, 3), (2, 4, 3), (5, 2, 10)]:
        n = sum(is_irreducible([(c // p**k) % p for k in range(r)] + [1], p) for c in range(p**r))
        assert n == want, (p, r)


@pytest.mark.parametrize("q", [2, 3, 5, 251, 257, 4093])
def test_modulus_of_a_prime_is_x(q):
    assert gf.modulus(q) == (0, 1)


@pytest.mark.parametrize("q", [1, 6, 12, 100])
def test_modulus_refuses_non_prime_powers(q):
    with pytest.raises(ValueError, match=str(q)):
        gf.modulus(q)


# ----------------------------------------------------------------------------- field axioms on the tables

@pytest.fixture(scope="module", params=GF_POWERS, ids=[f"GF{q}" for q in GF_POWERS])
def field(request):
    q = request.param
    return q, *_tables(q)


def test_tables_layout(field):
    q, A, M = field
    add, mul = gf.tables(q)
    assert gf.tables(q)[0] is add and gf.tables(q)[1] is mul  # cached
    for t in (add, mul):
        assert t.dtype == np.uint16 and t.shape == (q * q,) and not t.flags.writeable
        with pytest.raises(ValueError):
            t[0] = 1


def test_addition_is_an_abelian_group(field):
    q, A, _ = field
    full = np.arange(q)
    assert np.array_equal(np.sort(A, axis=1), np.broadcast_to(full, (q, q))), "rows are not permutations"
    assert np.array_equal(np.sort(A, axis=0), np.broadcast_to(full[:, None], (q, q))), "columns are not permutations"
    assert np.array_equal(A[0], full) and np.array_equal(A[:, 0], full), "0 is not the identity"
    assert np.array_equal(A, A.T), "not commutative"
    assert np.all((A == 0).sum(axis=1) == 1), "additive inverses"
    a, b, c = _triples(q)
    assert np.array_equal(A[A[a, b], c], A[a, A[b, c]]), "not associative"


def test_addition_is_digitwise_mod_p(field):
    """The element codes of docs/spec.md section 5: addition adds the base-p digits mod p,
    so the characteristic is p (p copies of anything sum to 0)."""
    q, A, _ = field
    p, r = factor_prime_power(q)
    a, b = np.divmod(np.arange(q * q), q)
    want = sum(((a // p**k + b // p**k) % p) * p**k for k in range(r))
    assert np.array_equal(A.ravel(), want)
    acc = np.zeros(q, dtype=np.int64)
    for _ in range(p):
        acc = A[acc, np.arange(q)]
    assert not acc.any()


def test_multiplication_of_nonzero_elements_is_a_group(field):
    q, _, M = field
    full = np.arange(q)
    assert not M[0].any() and not M[:, 0].any(), "0 does not annihilate"
    assert np.array_equal(M[1], full) and np.array_equal(M[:, 1], full), "1 is not the identity"
    assert np.array_equal(M, M.T), "not commutative"
    nz = M[1:, 1:]
    assert np.array_equal(np.sort(nz, axis=1), np.broadcast_to(full[1:], (q - 1, q - 1))), \
        "a row of a nonzero element is not a permutation of 1..q-1 (zero divisor)"
    inv = np.argmax(M == 1, axis=1)
    assert np.all(M[full[1:], inv[1:]] == 1), "a nonzero element without an inverse"
    a, b, c = _triples(q, seed=1)
    assert np.array_equal(M[M[a, b], c], M[a, M[b, c]]), "not associative"


def test_distributivity(field):
    q, A, M = field
    a, b, c = _triples(q, seed=2)
    assert np.array_equal(M[a, A[b, c]], A[M[a, b], M[a, c]])


def test_multiplicative_group_is_cyclic_of_order_q_minus_1(field):
    """a**(q-1) == 1 for every nonzero a (so a**q == a: x**q - x splits), and some
    element has order exactly q-1 (a primitive element exists, as in any field)."""
    q, _, M = field
    nz = np.arange(1, q)
    pw = np.ones(q - 1, dtype=np.int64)
    order = np.zeros(q - 1, dtype=np.int64)
    for k in range(1, q):
        pw = M[pw, nz]
        order[(pw == 1) & (order == 0)] = k
    assert np.all(pw == 1), "a**(q-1) != 1"
    assert np.all((q - 1) % order == 0)
    assert (order == q - 1).any(), "no primitive element"


def test_tables_equal_independent_polynomial_arithmetic(field):
    """The tables against tests.helpers.PolyField built on the modulus: checks the
    code convention (constant term least significant) and the reduction."""
    q, A, M = field
    F = PolyField(q, gf.modulus(q))
    rng = np.random.default_rng(q)
    pairs = [(a, b) for a in range(q) for b in range(q)] if q <= 32 else \
        [(int(a), int(b)) for a, b in rng.integers(0, q, (1500, 2))] + [(q - 1, q - 1), (q - 1, 1), (2, q - 1)]
    for a, b in pairs:
        assert A[a, b] == F.add(a, b), (a, b)
        assert M[a, b] == F.mul(a, b), (a, b)


def test_scalar_functions_equal_tables(field):
    q, A, M = field
    rng = np.random.default_rng(q + 1)
    for a, b in [(0, 0), (q - 1, q - 1), (1, q - 1)] + [tuple(map(int, v)) for v in rng.integers(0, q, (300, 2))]:
        assert gf.add(a, b, q) == A[a, b]
        assert gf.mul(a, b, q) == M[a, b]


@pytest.mark.parametrize("q", [4, 8, 16, 256])
def test_characteristic_two_known_products(q):
    """Spot values: in GF(2^r) with the classic moduli, x * x**(r-1) = x**r = the
    modulus' lower part; in GF(256) (AES) 0x57 * 0x83 = 0xC1 and 0x53 * 0xCA = 1."""
    r = q.bit_length() - 1
    low = sum(c << k for k, c in enumerate(KNOWN_MODULI[q][:-1]))
    assert gf.mul(2, 1 << (r - 1), q) == low
    assert gf.add(q - 1, q - 1, q) == 0
    if q == 256:
        assert gf.mul(0x57, 0x83, q) == 0xC1
        assert gf.mul(0x53, 0xCA, q) == 0x01
        assert gf.mul(0x57, 0x13, q) == 0xFE


def test_gf9_is_gaussian_integers_mod_3():
    """GF(9) = GF(3)[i], i**2 = -1 (modulus x^2 + 1): code a + 3b is a + b i."""
    for a in range(9):
        for b in range(9):
            (a0, a1), (b0, b1) = divmod(a, 3)[::-1], divmod(b, 3)[::-1]
            re_, im = (a0 * b0 - a1 * b1) % 3, (a0 * b1 + a1 * b0) % 3
            assert gf.mul(a, b, 9) == re_ + 3 * im


# ----------------------------------------------------------------------------- prime fields

@pytest.mark.parametrize("q", PRIMES_256 + [257, 4091, 4093])
def test_prime_field_is_mod_q(q):
    rng = np.random.default_rng(q)
    pairs = [(0, 0), (q - 1, q - 1), (1, q - 1), (q - 1, 2)] + [tuple(map(int, v)) for v in rng.integers(0, q, (40, 2))]
    for a, b in pairs:
        assert gf.add(a, b, q) == (a + b) % q
        assert gf.mul(a, b, q) == (a * b) % q


@pytest.mark.parametrize("q", [2, 3, 5, 7, 11, 13, 31, 53])
def test_prime_tables_are_mod_q(q):
    A, M = _tables(q)
    a, b = np.divmod(np.arange(q * q), q)
    assert np.array_equal(A.ravel(), (a + b) % q)
    assert np.array_equal(M.ravel(), (a * b) % q)


@pytest.mark.parametrize("q", [1, 6, 12, 257, 289, 512, 4093, 4096])
def test_tables_refused(q):
    with pytest.raises(ValueError, match=f"GF\\({q}\\)"):
        gf.tables(q)


def test_numpy_field_uses_tables_only_for_prime_powers():
    from pyoa._numpy.oa import Field

    U32 = np.uint32
    for q in (7, 257, 4093):
        F = Field(q)
        assert not F.tabled
        a = np.array([0, 1, q - 1, q - 2], U32)
        assert np.array_equal(F.add(a, a[::-1]), (a.astype(np.int64) + a[::-1]) % q)
        assert np.array_equal(F.mul(a, a[::-1]), (a.astype(np.int64) * a[::-1]) % q)
    for q in (4, 27, 256):
        F = Field(q)
        assert F.tabled
        A, M = _tables(q)
        a, b = (x.astype(U32) for x in np.divmod(np.arange(q * q), q))
        assert np.array_equal(F.add(a, b), A.ravel())
        assert np.array_equal(F.mul(a, b), M.ravel())


def test_documented_moduli_table_matches():
    """docs/galois-fields.md lists every modulus; it must be the one pyoa uses."""
    import re
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[1] / "docs" / "galois-fields.md").read_text()
    rows = re.findall(r"^\|\s*(\d+)\s*\|\s*(\d+)\s*\|\s*(\d+)\s*\|\s*([^|]+?)\s*\|$", doc, flags=re.M)
    assert [int(q) for q, *_ in rows] == GF_POWERS
    for q, p, r, text in rows:
        q, p, r = int(q), int(p), int(r)
        assert factor_prime_power(q) == (p, r)
        coeffs = [0] * (r + 1)
        for term in text.replace(" ", "").split("+"):
            m = re.fullmatch(r"(\d*)(x(?:\^(\d+))?)?", term)
            assert m, term
            c = int(m[1]) if m[1] else 1
            k = (int(m[3]) if m[3] else 1) if m[2] else 0
            coeffs[k] = c
        assert tuple(coeffs) == gf.modulus(q), (q, text)


# ----------------------------------------------------------------------------- Addelman-Kempthorne constants

#: Every odd prime power q <= 256 that is not a prime, small primes, and the largest
#: Addelman-Kempthorne prime (2 * 2887^2 <= 2^24).
AK_CONST_Q = [9, 25, 27, 49, 81, 121, 125, 169, 243, 3, 5, 7, 11, 13, 251, 2887]


@pytest.mark.parametrize("q", AK_CONST_Q)
def test_ak_constants_satisfy_their_definitions(q):
    """pyoa.tables.gf.ak_constants(q) = (kappa, b, k, c): kappa is a non-square of GF(q)
    and the smallest one by code; for m = 1..q-1, b[m] * 4 kappa m = kappa - 1,
    k[m] = kappa m and 4 c[m] = m^2 (kappa - 1), checked by multiplication only
    in the independent field (4 = 1+1+1+1, which is 1 in characteristic 3);
    index 0 is unused and 0. The same constants as the independent computation of
    tests.helpers (inverses from a primitive element)."""
    from tests.helpers import ak_constants_independent, field_for

    F = field_for(q)
    kappa, b, k, c = gf.ak_constants(q)
    assert gf.ak_constants(q) is gf.ak_constants(q), "not cached"
    assert all(isinstance(v, tuple) and len(v) == q and v[0] == 0 for v in (b, k, c))
    squares = {F.mul(x, x) for x in range(q)}
    assert len(squares) == (q + 1) // 2  # 0 and the (q-1)/2 nonzero squares
    assert 0 < kappa < q and kappa not in squares
    assert all(a in squares for a in range(kappa)), "kappa is not the smallest non-square"
    p = factor_prime_power(q)[0]
    if q == p:  # Euler's criterion, another test of non-squareness for prime q
        assert pow(kappa, (q - 1) // 2, q) == q - 1
    four = F.add(F.add(F.add(1, 1), 1), 1)
    assert four == 4 % p
    kappa_minus_1 = next(e for e in range(q) if F.add(e, 1) == kappa)
    for m in range(1, q):
        assert 0 <= b[m] < q and 0 <= k[m] < q and 0 <= c[m] < q
        assert F.mul(b[m], F.mul(F.mul(four, kappa), m)) == kappa_minus_1, ("b", m)
        assert k[m] == F.mul(kappa, m), ("k", m)
        assert F.mul(four, c[m]) == F.mul(F.mul(m, m), kappa_minus_1), ("c", m)
    assert (kappa, b, k, c) == ak_constants_independent(q)


@pytest.mark.parametrize("q, kappa", [(3, 2), (5, 2), (7, 3), (11, 2), (13, 2), (17, 3), (23, 5), (2887, 3),
                                      (9, 4), (25, 5)])
def test_ak_smallest_non_squares(q, kappa):
    """kappa by hand. Primes: the squares mod 7 are 1, 2, 4; mod 17 they include 1, 2,
    4 but not 3; mod 23 they include 1, 2, 3, 4 but not 5; 2887 = 7 mod 8 makes 2 a
    square, and 2887 = 3 mod 4, 2887 = 1 mod 3 make 3 a non-square (quadratic
    reciprocity). GF(9) = GF(3)[i], i^2 = -1 (code a + 3b = a + b i): 1, 2 = i^2 and
    3 = i = (1 + 2i)^2 are squares, 4 = 1 + i is not ((1 + i)^4 = -1). GF(25) with
    modulus x^2 + 2: every element of GF(5) is a square in GF(25), and 5 = x has
    order 8 (x^2 = 3 has order 4), which does not divide 24/2, so it is not."""
    assert gf.ak_constants(q)[0] == kappa


@pytest.mark.parametrize("q", [2, 4, 8, 16, 256])
def test_ak_constants_refuse_even_q(q):
    with pytest.raises(ValueError, match=f"odd.*{q}"):
        gf.ak_constants(q)


@pytest.mark.parametrize("q", [0, 1, 15, 45, 2889])
def test_ak_constants_refuse_non_prime_powers(q):
    """Like modulus() and tables(), a q that is no prime power is a ValueError that
    names q, not an internal TypeError."""
    with pytest.raises(ValueError, match=str(q)):
        gf.ak_constants(q)
