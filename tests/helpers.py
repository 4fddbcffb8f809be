"""Helpers shared by the test modules (importable as ``tests.helpers``)."""

from __future__ import annotations

import functools
import itertools
import subprocess
from pathlib import Path

import numpy as np

import pyoa

U32_MAX = 2**32 - 1
OFFSET_CODE = {"centered": 0, "j": 1, "mj": 2, "cmj": 3}
#: Keys of pyoa's documented seed hashes (pyoa/reference/hashes.py docstrings).
PIXEL_KEY = 0x5BD1E995
BLOCK_KEY = 0x1B873593


# --------------------------------------------------------------------------- C oracle

class SpecC:
    """Bulk queries to the compiled ``spec_hashes.c`` (one process per batch)."""

    def __init__(self, exe: Path):
        self.exe = Path(exe)

    def query(self, lines: list[str]) -> list[int]:
        if not lines:
            return []
        res = subprocess.run([str(self.exe)], input="\n".join(lines) + "\n", capture_output=True, text=True, check=True)
        out = res.stdout.split()
        assert len(out) == len(lines), (len(out), len(lines), res.stderr)
        return [int(v) for v in out]

    def permute(self, i, l, p) -> list[int]:
        return self.query([f"P {a} {b} {c}" for a, b, c in zip(i, l, p)])

    def randfloat_bits(self, i, p) -> list[int]:
        return self.query([f"R {a} {b}" for a, b in zip(i, p)])

    def mix32(self, x) -> list[int]:
        return self.query([f"X {a}" for a in x])

    def pixel_seed(self, seed, pixel) -> list[int]:
        return self.query([f"S {a} {b}" for a, b in zip(seed, pixel)])

    def block_seed(self, p, block) -> list[int]:
        return self.query([f"B {a} {b}" for a, b in zip(p, block)])

    def bose_bits(self, rows) -> list[int]:
        """rows: (i, j, s, p, offset, jitter) -> float32 bits."""
        return self.query([f"O {i} {j} {s} {p} {OFFSET_CODE[o]} {f32_bits(J)}" for i, j, s, p, o, J in rows])

    def cmjnd_bits(self, rows) -> list[int]:
        """rows: (i, j, s, t, p, offset, jitter) -> float32 bits."""
        return self.query([f"C {i} {j} {s} {t} {p} {OFFSET_CODE[o]} {f32_bits(J)}" for i, j, s, t, p, o, J in rows])


# --------------------------------------------------------------------------- float bits

def f32_bits(x: float) -> int:
    return int(np.float32(x).view(np.uint32))


def bits(a) -> np.ndarray:
    """uint32 view of a float32 array (refuses anything that is not float32)."""
    a = np.asarray(a)
    assert a.dtype == np.float32, a.dtype
    return a.view(np.uint32)


def assert_same_bits(got, want, what: str = "") -> None:
    """Bit-for-bit equality of two float32 arrays, with the first mismatch in the message."""
    got, want = np.asarray(got), np.asarray(want)
    assert got.shape == want.shape, f"{what}: shape {got.shape} != {want.shape}"
    gb, wb = bits(got), bits(want)
    bad = np.argwhere(gb != wb)
    if bad.size:
        idx = tuple(bad[0])
        raise AssertionError(
            f"{what}: {len(bad)} of {gb.size} values differ; first at index {idx}: "
            f"got {got[idx]!r} (0x{int(gb[idx]):08x}), want {want[idx]!r} (0x{int(wb[idx]):08x})"
        )


# --------------------------------------------------------------------------- reference blocks

def reference_block(smp, pixels, samples, dims) -> np.ndarray:
    """What ``smp.generate(pixels, samples, dims)`` must return, from the pure-Python
    reference function that the sampler's catalogue entry names (pixel seeds
    from ``pyoa.reference.pixel_seed``), one value at a time."""
    entry = smp._construction
    out = np.empty((len(pixels), len(samples), len(dims)), dtype=np.float32)
    for a, pix in enumerate(pixels):
        for b, i in enumerate(samples):
            for c, j in enumerate(dims):
                out[a, b, c] = entry.evaluate("reference", int(i), int(j), smp.params, smp.seed, int(pix),
                                              smp.offset, smp.jitter)
    return out


# --------------------------------------------------------------------------- canonical arrays

def bose_symbol(i: int, j: int, s: int) -> int:
    """A_ij of the plain Bose array (docs/spec.md section 5)."""
    a0, a1 = divmod(i, s)
    if j == 0:
        return a0
    if j == 1:
        return a1
    return (a0 + (j - 1) * a1) % s


def bose_partner(j: int, s: int) -> int:
    """The partner column k of j (docs/spec.md section 5), as a column index whose symbol
    formula uses the multiplier (k-1) mod s."""
    if j == 0:
        return 1
    if j == 1:
        return 0
    return j - 1 if j % 2 else j + 1


def bose_partner_symbol(i: int, j: int, s: int) -> int:
    k = bose_partner(j, s)
    a0, a1 = divmod(i, s)
    if k == 0:
        return a0
    if k == 1:
        return a1
    return (a0 + ((k - 1) % s) * a1) % s


# --------------------------------------------------------------------------- an independent GF(q)

def factor_prime_power(q: int) -> tuple[int, int] | None:
    """``(p, r)`` with ``q == p**r``, p prime (trial division up to sqrt(q)), else None."""
    if q < 2:
        return None
    p = next((d for d in range(2, int(q**0.5) + 1) if q % d == 0), q)
    r, rest = 0, q
    while rest % p == 0:
        rest //= p
        r += 1
    return (p, r) if rest == 1 else None


#: Every prime power that is not a prime, up to 256 (pyoa.tables.gf's table limit).
GF_POWERS = [4, 8, 9, 16, 25, 27, 32, 49, 64, 81, 121, 125, 128, 169, 243, 256]

#: Moduli (coefficients, constant term first) of GF(q): the classic ones
#: x^2+x+1, x^3+x+1, x^4+x+1 and AES's x^8+x^4+x^3+x+1, and for 9, 25, 27 the
#: first monic irreducible by coefficient code (x^2+1, x^2+2, x^3+2x+1, checked
#: by hand: no roots).
KNOWN_MODULI = {
    4: (1, 1, 1),
    8: (1, 1, 0, 1),
    9: (1, 0, 1),
    16: (1, 1, 0, 0, 1),
    25: (2, 0, 1),
    27: (1, 2, 0, 1),
    256: (1, 1, 0, 1, 1, 0, 0, 0, 1),
}


def _trim(a: list[int]) -> list[int]:
    while a and a[-1] == 0:
        a = a[:-1]
    return a


def poly_rem(a: list[int], f: list[int], p: int) -> list[int]:
    """``a mod f`` over GF(p) (coefficient lists, constant first; any nonzero lead of f)."""
    a = _trim([x % p for x in a])
    f = _trim([x % p for x in f])
    inv = pow(f[-1], -1, p)
    while len(a) >= len(f):
        c = a[-1] * inv % p
        shift = len(a) - len(f)
        for k, y in enumerate(f):
            a[shift + k] = (a[shift + k] - c * y) % p
        a = _trim(a)
    return a


def poly_mul(a: list[int], b: list[int], p: int) -> list[int]:
    out = [0] * max(0, len(a) + len(b) - 1)
    for k, x in enumerate(a):
        for m, y in enumerate(b):
            out[k + m] = (out[k + m] + x * y) % p
    return _trim(out)


def poly_gcd(a: list[int], b: list[int], p: int) -> list[int]:
    a, b = _trim([x % p for x in a]), _trim([x % p for x in b])
    while b:
        a, b = b, poly_rem(a, b, p)
    return a


def poly_x_pow_p_pow(m: int, f: list[int], p: int) -> list[int]:
    """``x**(p**m) mod f`` over GF(p), by m Frobenius steps (square-and-multiply each)."""
    g = poly_rem([0, 1], f, p)
    for _ in range(m):
        result, base, e = [1], g, p
        while e:
            if e & 1:
                result = poly_rem(poly_mul(result, base, p), f, p)
            base = poly_rem(poly_mul(base, base, p), f, p)
            e >>= 1
        g = result
    return g


def is_irreducible(f: list[int], p: int) -> bool:
    """Rabin's test: monic f of degree r is irreducible over GF(p) iff
    ``x**(p**r) == x mod f`` and ``gcd(x**(p**(r/k)) - x, f) == 1`` for every prime k | r."""
    r = len(f) - 1
    if poly_x_pow_p_pow(r, f, p) != poly_rem([0, 1], f, p):
        return False
    for k in {k for k in range(2, r + 1) if r % k == 0 and factor_prime_power(k) == (k, 1)}:
        h = poly_x_pow_p_pow(r // k, f, p) + [0, 0]
        h[1] = (h[1] - 1) % p  # x**(p**(r/k)) - x
        h = _trim(h)
        if not h or len(poly_gcd(f, h, p)) != 1:  # f divides it, or a nonconstant common factor
            return False
    return True


class PolyField:
    """GF(p**r) written independently of pyoa.tables.gf: elements are codes whose base-p
    digits are polynomial coefficients (constant term least significant, SPEC
    section 5), multiplied as polynomials and reduced by the monic modulus ``f``."""

    def __init__(self, q: int, f):
        self.q = q
        self.p, self.r = factor_prime_power(q)
        self.f = list(f)
        assert len(self.f) == self.r + 1 and self.f[-1] == 1

    def digits(self, a: int) -> list[int]:
        return [(a // self.p**k) % self.p for k in range(self.r)]

    def code(self, coeffs: list[int]) -> int:
        return sum((c % self.p) * self.p**k for k, c in enumerate(coeffs))

    def add(self, a: int, b: int) -> int:
        return self.code([x + y for x, y in zip(self.digits(a), self.digits(b))])

    def mul(self, a: int, b: int) -> int:
        return self.code(poly_rem(poly_mul(self.digits(a), self.digits(b), self.p), self.f, self.p))

    def poly_at(self, coeffs: list[int], x: int) -> int:
        """``sum_l coeffs[l] * x**l`` in the field, term by term (not Horner)."""
        acc, xp = 0, 1
        for c in coeffs:
            acc = self.add(acc, self.mul(c, xp))
            xp = self.mul(xp, x)
        return acc


def prime_field(q: int) -> PolyField:
    return PolyField(q, (0, 1))


def field_for(q: int) -> PolyField:
    """GF(q) for prime q (mod q); else over the modulus of :data:`KNOWN_MODULI`, or
    for the other q pyoa.tables.gf's modulus (tests/test_gf.py checks it is the first
    monic irreducible polynomial, independently)."""
    if factor_prime_power(q)[1] == 1:
        return prime_field(q)
    from pyoa.tables import gf

    return PolyField(q, KNOWN_MODULI.get(q) or gf.modulus(q))


def gf_bose_symbol(i: int, j: int, F: PolyField) -> int:
    """A_ij of the plain Bose array over GF(q): a0 + (j-1) a1 for 2 <= j <= q."""
    a0, a1 = divmod(i, F.q)
    if j == 0:
        return a0
    if j == 1:
        return a1
    return F.add(a0, F.mul(j - 1, a1))


def gf_bose_partner_symbol(i: int, j: int, F: PolyField) -> int:
    k = bose_partner(j, F.q)
    a0, a1 = divmod(i, F.q)
    if k == 0:
        return a0
    if k == 1:
        return a1
    return F.add(a0, F.mul((k - 1) % F.q, a1))


def bush_symbol(i: int, j: int, t: int, F: PolyField) -> int:
    """A_ij of the plain Bush array: the row polynomial (base-s digits of i,
    constant term = least significant digit) at x = j < s; its leading coefficient for j = s."""
    s = F.q
    c = [(i // s**l) % s for l in range(t)]
    return c[t - 1] if j == s else F.poly_at(c, j)


@functools.cache
def field_tables(q: int) -> tuple[np.ndarray, np.ndarray]:
    """(add, mul) q x q tables of :func:`field_for` (independent of pyoa.tables.gf), cached."""
    F = field_for(q)
    add = np.array([[F.add(a, b) for b in range(q)] for a in range(q)], dtype=np.int64)
    mul = np.array([[F.mul(a, b) for b in range(q)] for a in range(q)], dtype=np.int64)
    return add, mul


@functools.cache
def plain_bush_array(s: int, t: int) -> np.ndarray:
    """The whole plain Bush array (N, s+1) of :func:`bush_symbol`, vectorized over
    :func:`field_tables`, term by term; read-only and cached."""
    add, mul = field_tables(s)
    i = np.arange(s**t)
    c = [(i // s**l) % s for l in range(t)]
    A = np.empty((s**t, s + 1), dtype=np.int64)
    for x in range(s):
        acc, xp = np.zeros_like(i), 1
        for l in range(t):
            acc = add[acc, mul[c[l], xp]]
            xp = int(mul[xp, x])
        A[:, x] = acc
    A[:, s] = c[t - 1]
    A.flags.writeable = False
    return A


@functools.cache
def plain_gf_bose_array(q: int) -> tuple[np.ndarray, np.ndarray]:
    """``(A, A_partner)``, each (q^2, q+1), of :func:`gf_bose_symbol`; read-only, cached."""
    F = field_for(q)
    A = np.array([[gf_bose_symbol(i, j, F) for j in range(q + 1)] for i in range(q * q)])
    Ak = np.array([[gf_bose_partner_symbol(i, j, F) for j in range(q + 1)] for i in range(q * q)])
    A.flags.writeable = Ak.flags.writeable = False
    return A, Ak


def bush_sub_index(i: int, j: int, s: int, t: int) -> int:
    """The sub-stratum index u of pyoa's Bush (reference.oa.bush): i // s in
    columns j < s, i mod s**(t-1) in column s (the documented deviation from SPEC)."""
    return i % s ** (t - 1) if j == s else i // s


# --------------------------------------------------------------------------- index-2 arrays (AK, Bose-Bush)

#: Addelman-Kempthorne q (odd prime powers) and Bose-Bush s (powers of two) of the
#: property tests; every 2s+1 columns of the arrays are checked pair by pair.
AK_Q = [3, 5, 7, 9, 11, 13, 25, 27]
BB_S = [2, 4, 8, 16, 32]


def index2_levels(name: str) -> list[int]:
    """Every s of an index-2 sampler, enumerated independently of pyoa.catalogue.constructions:
    Addelman-Kempthorne q odd, a prime or a prime power <= 256, 2q^2 <= 2^24;
    Bose-Bush s = 2^r with 2s <= 256 (GF(2s) tables)."""
    if name == "bose-bush":
        return [2**r for r in range(1, 8)]
    out = []
    for q in range(3, 2**12, 2):
        pr = factor_prime_power(q)
        if pr and 2 * q * q <= 2**24 and (pr[1] == 1 or q <= 256):
            out.append(q)
    return out


@functools.cache
def field_inverses(q: int) -> tuple[int, ...]:
    """``inv[a]`` (``inv[0] = 0``) in :func:`field_for` GF(q), from the powers of a
    primitive element (``inv(g^e) = g^(q-1-e)``): no Fermat exponentiation, no tables
    of pyoa.tables.gf."""
    F = field_for(q)
    for g in range(2, q) if q > 2 else [1]:
        powers, x = [1], g
        while x != 1:
            powers.append(x)
            x = F.mul(x, g)
        if len(powers) == q - 1:
            break
    else:  # pragma: no cover - every finite field has a primitive element
        raise AssertionError(f"no primitive element of GF({q})")
    inv = [0] * q
    for e, a in enumerate(powers):
        inv[a] = powers[(q - 1 - e) % (q - 1)]
    return tuple(inv)


@functools.cache
def ak_constants_independent(q: int, kappa: int | None = None) -> tuple[int, tuple, tuple, tuple]:
    """``(kappa, b, k, c)`` of Addelman-Kempthorne (1961) / Hedayat-Sloane-Stufken 3.4
    as pyoa documents them (kappa the smallest non-square by code; b[m] =
    (kappa-1)/(4 kappa m), k[m] = kappa m, c[m] = m^2 (kappa-1)/4, index 0 unused = 0),
    computed with :class:`PolyField`: 4 = 1+1+1+1, -1 found by search, inverses
    from :func:`field_inverses`. ``kappa`` given: the same formulas with that
    element instead (for tests that need another, or a wrong, kappa)."""
    F = field_for(q)
    if kappa is None:
        squares = {F.mul(x, x) for x in range(q)}
        kappa = min(x for x in range(q) if x not in squares)
    four = F.add(F.add(F.add(1, 1), 1), 1)
    minus_one = next(e for e in range(q) if F.add(e, 1) == 0)
    num = F.add(kappa, minus_one)  # kappa - 1
    inv = field_inverses(q)
    b, k, c = [0] * q, [0] * q, [0] * q
    for m in range(1, q):
        b[m] = F.mul(num, inv[F.mul(F.mul(four, kappa), m)])
        k[m] = F.mul(kappa, m)
        c[m] = F.mul(F.mul(F.mul(m, m), num), inv[four])
    return kappa, tuple(b), tuple(k), tuple(c)


def ak_symbol(i: int, j: int, q: int) -> tuple[int, int]:
    """``(A_ij, u)`` of the plain Addelman-Kempthorne array, column ``j < 2q+1``,
    written from the table of reference.addelman_kempthorne's docstring with the
    independent field: row ``i = h q^2 + x q + y``; ``u = h q + x`` in the columns
    where a stratum fixes y (0 and q..2q-1), ``u = h q + y`` in the others."""
    F = field_for(q)
    kappa, b, k, c = ak_constants_independent(q)
    h, rest = divmod(i, q * q)
    x, y = divmod(rest, q)
    x2 = F.mul(x, x)
    if j == 0:
        a = y
    elif j < q:  # x + m y (+ b_m)
        a = F.add(x, F.mul(j, y))
        if h:
            a = F.add(a, b[j])
    elif j < 2 * q:  # y + m x + x^2, or y + k_m x + kappa x^2 + c_m (m = 0: column q, k_0 = c_0 = 0)
        m = j - q
        if h:
            a = F.add(F.add(F.add(y, F.mul(k[m], x)), F.mul(kappa, x2)), c[m])
        else:
            a = F.add(F.add(y, F.mul(m, x)), x2)
    else:
        a = x
    u = h * q + (x if j == 0 or q <= j < 2 * q else y)
    return a, u


@functools.cache
def plain_ak_array(q: int, kappa: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(A, U)``, each (2q^2, 2q+1): :func:`ak_symbol` over the whole array,
    vectorized over :func:`field_tables` (independent of pyoa.tables.gf); read-only, cached.
    ``kappa``: see :func:`ak_constants_independent`."""
    add, mul = field_tables(q)
    kappa, b, k, c = (np.asarray(v) for v in ak_constants_independent(q, kappa))
    i = np.arange(2 * q * q)
    h, x, y = i // (q * q), (i // q) % q, i % q
    x2 = mul[x, x]
    A = np.empty((2 * q * q, 2 * q + 1), dtype=np.int64)
    U = np.empty_like(A)
    A[:, 0], U[:, 0] = y, h * q + x
    for m in range(1, q):
        A[:, m] = add[add[x, mul[m, y]], np.where(h == 1, b[m], 0)]
        U[:, m] = h * q + y
    for m in range(q):
        first = add[add[y, mul[m, x]], x2]
        second = add[add[add[y, mul[k[m], x]], mul[kappa, x2]], c[m]]
        A[:, q + m] = np.where(h == 1, second, first)
        U[:, q + m] = h * q + x
    A[:, 2 * q], U[:, 2 * q] = x, h * q + y
    A.flags.writeable = U.flags.writeable = False
    return A, U


def bose_bush_symbol(i: int, j: int, s: int) -> tuple[int, int]:
    """``(A_ij, u)`` of the plain Bose-Bush array (Bose and Bush 1952, HSS 3.5),
    column ``j < 2s+1``: in GF(2s) (independent field), the low r bits of x*j (the
    class of the product modulo the additive subgroup of multiples of x^r) plus k,
    for row ``i = x s + k``; column 2s is the class x mod s of x. ``u = x``, and in
    column 2s ``u = (x // s) s + k``."""
    F = field_for(2 * s)
    x, k = divmod(i, s)
    if j < 2 * s:
        return F.add(F.mul(x, j) % s, k), x
    return x % s, (x // s) * s + k


@functools.cache
def plain_bose_bush_array(s: int) -> tuple[np.ndarray, np.ndarray]:
    """``(A, U)``, each (2s^2, 2s+1), of :func:`bose_bush_symbol`, vectorized over
    :func:`field_tables` of GF(2s); read-only, cached."""
    add, mul = field_tables(2 * s)
    i = np.arange(2 * s * s)
    x, k = i // s, i % s
    A = np.empty((2 * s * s, 2 * s + 1), dtype=np.int64)
    U = np.empty_like(A)
    for j in range(2 * s):
        A[:, j] = add[mul[x, j] % s, k]
        U[:, j] = x
    A[:, 2 * s], U[:, 2 * s] = x % s, (x // s) * s + k
    A.flags.writeable = U.flags.writeable = False
    return A, U


def plain_index2_array(name: str, s: int) -> tuple[np.ndarray, np.ndarray]:
    return plain_ak_array(s) if name == "addelman-kempthorne" else plain_bose_bush_array(s)


def index2_symbol(name: str, i: int, j: int, s: int) -> tuple[int, int]:
    return ak_symbol(i, j, s) if name == "addelman-kempthorne" else bose_bush_symbol(i, j, s)


# --------------------------------------------------------------------------- OA / LH checks

def strata_exact(x: np.ndarray, s: int) -> np.ndarray:
    """``floor(x*s)``: the stratum of each value among ``s`` (exact in float64 for
    float32 values and ``s <= 2**24``; values are clamped into their cells, so
    this is the stratum the construction chose, at any jitter amount)."""
    return np.floor(np.asarray(x, np.float64) * s).astype(np.int64)


def assert_oa(strata: np.ndarray, s: int, t: int, cols=None, what: str = "") -> None:
    """Every t-subset of columns of every array holds each of the s^t cells equally often.

    strata: integer array (..., N, d) of symbols in [0, s).
    """
    strata = np.asarray(strata)
    N, d = strata.shape[-2:]
    assert strata.min() >= 0 and strata.max() < s, f"{what}: symbols outside [0, {s})"
    lam, rem = divmod(N, s**t)
    assert rem == 0
    cols = range(d) if cols is None else cols
    arrays = strata.reshape(-1, N, d)
    n = len(arrays)
    base = (np.arange(n, dtype=np.int64) * s**t)[:, None]  # one run of s^t cells per array
    for sub in itertools.combinations(cols, t):
        code = np.zeros((n, N), dtype=np.int64)
        for c in sub:
            code = code * s + arrays[:, :, c]
        counts = np.bincount((code + base).ravel(), minlength=n * s**t).reshape(n, s**t)
        ok = np.all(counts == lam, axis=-1)
        assert np.all(ok), f"{what}: columns {sub} are not an OA(strength {t}) in {np.size(ok) - np.count_nonzero(ok)} arrays"


def assert_latin_exact(x: np.ndarray, N: int, what: str = "") -> None:
    """floor(x*N) is a permutation of 0..N-1 in every column (exact: see
    :func:`strata_exact`; any jitter amount)."""
    cells = np.sort(np.floor(np.asarray(x, np.float64) * N).astype(np.int64), axis=-2)
    want = np.arange(N).reshape((N, 1))
    ok = np.all(cells == want, axis=-2)
    assert np.all(ok), f"{what}: {np.size(ok) - np.count_nonzero(ok)} columns are not Latin hypercubes at {N} cells"


def in_unit_interval(x) -> bool:
    x = np.asarray(x)
    return bool(np.all(x >= 0) and np.all(x < 1) and np.all(np.isfinite(x)))


def make(name: str, spp: int, dims: int, **kw):
    return pyoa.sampler(name, spp=spp, dims=dims, **kw)


# --------------------------------------------------------------------------- hash test inputs

BOSE_PRIMES = [p for p in range(2, 4094) if all(p % d for d in range(2, int(p**0.5) + 1))]


def permute_cases(n_random: int = 3000, seed: int = 20190710) -> list[tuple[int, int, int]]:
    """(i, l, p) triples: random ones, l = 1, powers of two and one off, the Bose
    primes and CMJND sub-strata counts M = s^(t-1), seeds 0, 1, near 2^32 and with
    high bits set, i = 0 and l - 1."""
    rng = np.random.default_rng(seed)
    ls = [1, 2, 3, 4093, 4096, 2**23, 2**31, 2**31 - 1]
    for k in range(1, 32):
        ls += [2**k - 1, 2**k, 2**k + 1]
    ls += BOSE_PRIMES[-5:] + [7, 11, 13]
    ls += [s ** (t - 1) for s, t in [(2, 24), (3, 15), (5, 10), (6, 4), (16, 6), (4096, 2), (255, 3)]]
    ls = sorted({l for l in ls if 1 <= l <= 2**31})
    ps = [0, 1, 2, 3, 0x80000000, 0x7FFFFFFF, 0xF8000000, U32_MAX] + [U32_MAX - k for k in range(1, 70)]
    out = []
    for l in ls:
        for p in ps[:8] + [int(v) for v in rng.choice(ps[8:], 3)] + [int(v) for v in rng.integers(0, 2**32, 3)]:
            for i in {0, l - 1, int(rng.integers(0, l))}:
                out.append((i, l, p))
    for _ in range(n_random):
        l = int(rng.integers(1, 2**31 + 1)) if rng.random() < 0.5 else int(rng.integers(1, 5000))
        i = int(rng.integers(0, l))
        p = int(rng.integers(0, 2**32)) if rng.random() < 0.8 else U32_MAX - int(rng.integers(0, l))
        out.append((i, l, p))
    return out


def randfloat_cases(n_random: int = 4000, seed: int = 20130101) -> list[tuple[int, int]]:
    rng = np.random.default_rng(seed)
    specials = [0, 1, 2, 0x3FFFF, 0x40000, 0x7FFFFFFF, 0x80000000, U32_MAX - 1, U32_MAX]
    out = [(i, p) for i in specials for p in specials]
    out += [(int(i), int(p)) for i, p in rng.integers(0, 2**32, (n_random, 2))]
    out += [(int(i), int(p)) for i, p in zip(rng.integers(0, 2**32, 500), rng.integers(0, 2**18, 500))]
    return out


def seed_pair_cases(n_random: int = 2000, seed: int = 7) -> list[tuple[int, int]]:
    rng = np.random.default_rng(seed)
    specials = [0, 1, 2, 0x5BD1E995, 0x1B873593, U32_MAX - 1, U32_MAX]
    out = [(a, b) for a in specials for b in specials]
    out += [(int(a), int(b)) for a, b in rng.integers(0, 2**32, (n_random, 2))]
    out += [(int(a), int(b)) for a, b in zip(rng.integers(0, 2**32, 300), rng.integers(0, 64, 300))]
    return out


# --------------------------------------------------------------------------- inverting randfloat's hash

def _unxorshift(y: int, k: int) -> int:
    """Inverse of x -> x ^ (x >> k) on uint32."""
    x = y
    for _ in range(32 // k + 1):
        x = y ^ (x >> k)
    return x & U32_MAX


def randfloat_preimage(h: int, p: int) -> int:
    """The i for which randfloat's integer hash (docs/spec.md section 2, before the float
    conversion) of (i, p) equals h; p != 0. Every step of the hash is a bijection."""
    M = 2**32
    x = (h * pow(1 | (p >> 18), -1, M)) % M
    x = _unxorshift(x, 17)
    x ^= 0xDF6E307F
    x = (x * pow(0x93FC4795, -1, M)) % M
    x = _unxorshift(x, 21)
    x = _unxorshift(x, 12)
    x = (x * pow(0xB36534E5, -1, M)) % M
    x = _unxorshift(x, 10)
    x = _unxorshift(x, 17)
    return x ^ p


def run_cli(args, capsys):
    """Run ``pyoa ARGS`` in-process: (exit status, stdout, stderr)."""
    from pyoa import commands

    try:
        code = commands.main([str(a) for a in args])
    except SystemExit as exc:
        code = exc.code
    out = capsys.readouterr()
    return code, out.out, out.err


def kernel_runner(backend, test_kernels: str):
    """Build ``test_kernels`` after pyoa's own program source (same build
    options) on ``backend``'s OpenCL device, and return
    ``run(name, outs, *args, n=None)``: it uploads the ndarray arguments,
    passes the others as they are, appends one output buffer per dtype in
    ``outs``, launches ``n`` work-items (default: the common size of the
    array arguments) and returns the outputs (one array, or a list)."""
    import pyopencl as cl

    from pyoa._opencl import program as prog

    ctx, queue = backend.context, backend.queue
    program = cl.Program(ctx, prog.source() + "\n" + test_kernels).build(options=prog.BUILD_OPTIONS)
    kernels = {}

    def run(name, outs, *args, n=None):
        mf = cl.mem_flags
        arrays = [a for a in args if isinstance(a, np.ndarray)]
        if n is None:
            n = arrays[0].size
            assert all(a.size == n for a in arrays), "array arguments of different sizes need n="
        kargs = [cl.Buffer(ctx, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=np.ascontiguousarray(a).ravel())
                 if isinstance(a, np.ndarray) else a for a in args]
        results = [np.empty(n, dtype=dt) for dt in outs]
        bufs = [cl.Buffer(ctx, mf.WRITE_ONLY, size=max(4, r.nbytes)) for r in results]
        if name not in kernels:
            kernels[name] = cl.Kernel(program, name)
        kernels[name](queue, (n,), None, *kargs, *bufs)
        for r, b in zip(results, bufs):
            cl.enqueue_copy(queue, r, b)
        queue.finish()
        return results if len(results) > 1 else results[0]

    return run


def compositions(m: int, k: int):
    """Every way to split ``m`` digits among ``k`` dimensions (``e_1 + ... + e_k = m``, each >= 0)."""
    if k == 1:
        yield (m,)
        return
    for e in range(m + 1):
        for rest in compositions(m - e, k - 1):
            yield (e, *rest)


def net_failures(x: np.ndarray, b: int, m: int, block_dims: int, max_k: int = 3, subsets=None) -> list[str]:
    """Where the aligned blocks of ``b**m`` samples of ``x`` (pixels, N,
    dims) are not (0, m, s)-nets in base ``b``: for every projection onto
    ``k <= min(m, max_k)`` dimensions of one block of ``block_dims``
    dimensions (or the given ``subsets``), and every split of the ``m``
    digits among them, each elementary box must hold exactly one point of
    every aligned block. Exact: ``floor(x * b**e)`` of a float32 is exact in
    float64. Returns the failures (empty: every net holds)."""
    P, N, D = x.shape
    size = b**m
    nblk = N // size
    if nblk == 0:
        return []
    xs = np.asarray(x[:, :nblk * size], np.float64)
    owner = (np.arange(P)[:, None] * nblk + np.arange(nblk * size)[None, :] // size)  # (pixel, block) id
    if subsets is None:
        subsets = [sub for b0 in range(0, D, block_dims)
                   for k in range(1, min(m, max_k, min(D, b0 + block_dims) - b0) + 1)
                   for sub in itertools.combinations(range(b0, min(D, b0 + block_dims)), k)]
    fails = []
    for sub in subsets:
        for split in compositions(m, len(sub)):
            code = owner * size  # box index within the block: sum of stratum * b**(digits after it)
            for t, (c, e) in enumerate(zip(sub, split)):
                code = code + np.floor(xs[:, :, c] * b**e).astype(np.int64) * b ** (m - sum(split[:t + 1]))
            counts = np.bincount(code.ravel(), minlength=P * nblk * size)
            if not (counts == 1).all():
                fails.append(f"dims {sub} split {split}")
    return fails
