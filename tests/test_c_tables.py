"""pyoa/tables.h and pyoa/sobol_data.h: the host-side table builders of the
portable C headers give, bit for bit, the arrays pyoa's OpenCL backend
uploads (docs/spec.md sections 5.1, 5.6 and 5.8):

- GF(q): ``pyoa._opencl.backend._field_tables(q)`` (addition then
  multiplication table, or the 1-entry placeholder) for every composite prime
  power q <= 256, the primes, q = 0 and q that are not prime powers;
- Addelman-Kempthorne: ``AddelmanKempthorne.constants`` for every q
  ``AddelmanKempthorne.levels()`` allows (426 of them). The prime powers,
  the primes below 300 and the largest ones are compared with
  ``pyoa.tables.gf.ak_constants`` itself; every q with a vectorized NumPy
  evaluation of the same definition (pyoa.tables.gf's scalar loop over all 426 would
  take ten seconds), which on the first set must then agree with pyoa.tables.gf too;
- Halton: ``pyoa.tables.sequences.primes()``, whole;
- Sobol: ``pyoa.tables.sequences.sobol_matrices()[:dims]`` for 1, 2, 1000 and all
  21201 dimensions, from the generated ``sobol_data.h`` (which must equal
  ``pyoa.c_data.sobol_data_header()``).

The shim (tests/c/tables_shim.c) is built as C99 and as C++14, -O2, with
warnings as errors; each fill writes into a buffer with guard entries after
its size, which must stay untouched. That each header compiles alone (C99,
C++14, C++17, nvcc) is tests/test_c_headers.py's test_every_header_compiles_*,
which globs every header. Set ``PYOA_REQUIRE_C=1`` to fail instead of skip
without gcc/g++.
"""

from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pyoa import c_data, c_headers
from pyoa.tables import gf, sequences
from pyoa._opencl.backend import _field_tables
from pyoa.catalogue.constructions import AddelmanKempthorne
from tests.helpers import GF_POWERS, factor_prime_power
from tests.test_c_headers import WARN, compile_, need

INCLUDE = Path(c_headers.get_include())
SHIM = Path(__file__).parent / "c" / "tables_shim.c"
GUARD = 16  # entries after each table that a fill must not touch
BUILDS = {
    "c99-O2": ("gcc", ".c", ["-std=c99", "-O2", *WARN]),
    "c++14-O2": ("g++", ".cpp", ["-std=c++14", "-O2", *WARN]),
}
AK_LEVELS = AddelmanKempthorne.levels()
#: Addelman-Kempthorne q compared with pyoa.tables.gf.ak_constants itself: every odd
#: composite prime power, the primes below 300, every 20th level and the three largest.
AK_DIRECT = sorted({q for q in AK_LEVELS if factor_prime_power(q)[1] > 1 or q < 300}
                   | set(AK_LEVELS[::20]) | set(AK_LEVELS[-3:]))


@pytest.fixture(scope="module", params=list(BUILDS))
def lib(request, tmp_path_factory):
    """tests/c/tables_shim.c built as a shared library in one mode, loaded with ctypes."""
    compiler, suffix, flags = BUILDS[request.param]
    need(compiler, "PYOA_REQUIRE_C")
    d = tmp_path_factory.mktemp(request.param)
    src = d / f"tables_shim{suffix}"
    src.write_text(SHIM.read_text())
    so = d / "tables_shim.so"
    compile_(compiler, [*flags, "-shared", "-fPIC", f"-I{INCLUDE}", str(src), "-o", str(so)], d)
    lib = ctypes.CDLL(str(so))
    for name in ("t_gf_table_entries", "t_ak_entries", "t_halton_entries", "t_sobol_entries"):
        getattr(lib, name).restype = ctypes.c_uint32
    return lib


def fill(lib, name: str, entries: int, dtype, *args) -> np.ndarray:
    """lib.name(*args, out) into ``entries`` plus GUARD sentinel entries; the
    table, after checking that the sentinels survived."""
    sentinel = np.iinfo(dtype).max - 0x21
    buf = np.full(entries + GUARD, sentinel, dtype)
    getattr(lib, name)(*(ctypes.c_uint32(a) for a in args), buf.ctypes.data_as(ctypes.c_void_p))
    assert (buf[entries:] == sentinel).all(), f"{name}{args} wrote past its {entries} entries"
    return buf[:entries]


def gf_info(lib, qs) -> np.ndarray:
    """Rows (p, r, is_supported, tabled, table_entries, modulus code) for each q."""
    q = np.ascontiguousarray(qs, dtype=np.uint32)
    out = np.zeros((len(q), 6), np.uint32)
    lib.t_gf_info(ctypes.c_size_t(len(q)), q.ctypes.data_as(ctypes.c_void_p), out.ctypes.data_as(ctypes.c_void_p))
    return out


def expected_info(q: int, pr) -> tuple:
    """What gf_info must say of q, from the prime-power factorization pr (None: not a prime power)."""
    p, r = pr or (0, 0)
    supported = pr is not None and (r == 1 or q <= gf.MAX_TABLE_Q)
    tabled = supported and r > 1
    code = sum(c * p**k for k, c in enumerate(gf.modulus(q)[:-1])) if r > 1 else 0
    return (p, r, int(supported), int(tabled), 2 * q * q if tabled else 1, code)


# ----------------------------------------------------------------------------- GF(q)

def test_gf_info_matches_pyoa_gf_up_to_4096(lib):
    """prime_power, is_supported, tabled, the table size and the modulus (of
    every q = p^r with r >= 2: the first monic irreducible polynomial,
    pyoa.tables.gf.modulus) for every q <= 4096 as pyoa.tables.gf says, and large q up to
    the edge of uint32."""
    qs = list(range(0, 4097))
    got = gf_info(lib, qs)
    for q, row in zip(qs, got):
        assert tuple(row) == expected_info(q, gf.prime_power(q)), q
    # three moduli by hand (docs/spec.md section 5.1): x^2 + x + 1, x^2 + 1, x^8 + x^4 + x^3 + x + 1
    assert gf_info(lib, [4, 9, 256])[:, 5].tolist() == [1 + 2, 1, 1 + 2 + 8 + 16]
    big = {65521: (65521, 1), 65536: (2, 16), 65537: (65537, 1), 2**31 - 1: (2**31 - 1, 1), 2**31: (2, 31),
           3**20: (3, 20), 65521**2: (65521, 2), 4294967291: (4294967291, 1), 2**32 - 1: None, 65521 * 65537: None}
    for (q, pr), row in zip(big.items(), gf_info(lib, list(big))):
        p, r = pr or (0, 0)
        assert tuple(row[:5]) == (p, r, int(pr is not None and r == 1), 0, 1), q


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(0, 2**32 - 1), min_size=1, max_size=8))
def test_gf_prime_power_of_random_uint32(lib, qs):
    """Any uint32: p and r as trial division finds them (0, 0: not a prime power)."""
    for q, row in zip(qs, gf_info(lib, qs)):
        p, r = factor_prime_power(q) or (0, 0)
        assert tuple(row[:2]) == (p, r), q
        assert row[2] == int(p != 0 and (r == 1 or q <= 256)), q


@pytest.mark.parametrize("q", GF_POWERS)
def test_gf_tables_equal_the_uploaded_ones(lib, q):
    """Addition then multiplication table, 2 q^2 uint16: exactly the buffer
    pyoa/_opencl/backend.py uploads (gf.tables(q), concatenated)."""
    want, tabled = _field_tables(q)
    assert tabled
    n = lib.t_gf_table_entries(q)
    assert n == want.size == 2 * q * q
    got = fill(lib, "t_gf_fill", n, np.uint16, q)
    assert np.array_equal(got, want), (q, np.flatnonzero(got != want)[:5])


@pytest.mark.parametrize("q", [0, 2, 3, 5, 7, 251, 257, 2887, 4093, 65521])
def test_gf_placeholder_for_primes_and_no_field(lib, q):
    """Prime q (and q = 0, a construction without a field): a 1-entry
    placeholder 0 and tabled = 0, as _field_tables."""
    want, tabled = _field_tables(q)
    assert not tabled and gf_info(lib, [q])[0, 3] == 0
    assert lib.t_gf_table_entries(q) == want.size == 1
    assert fill(lib, "t_gf_fill", 1, np.uint16, q).tolist() == want.tolist() == [0]


@pytest.mark.parametrize("q", [1, 6, 289, 512, 4096])
def test_gf_placeholder_for_unsupported_q(lib, q):
    """Not a prime power, or a composite prime power above 256: no tables either."""
    assert not gf.is_supported(q)
    assert lib.t_gf_table_entries(q) == 1
    assert fill(lib, "t_gf_fill", 1, np.uint16, q).tolist() == [0]


# ----------------------------------------------------------------------------- Addelman-Kempthorne

def ak_fast(q: int) -> list[int]:
    """[kappa, b..., k..., c...] for prime q, vectorized: kappa the smallest
    code outside the squares, inverses x**(q-2) by square and multiply on an
    int64 array (products < 2**24), b[m] = (kappa - 1) inv(4 kappa m),
    k[m] = kappa m, c[m] = m**2 (kappa - 1) inv(4) (docs/spec.md section 5.6)."""
    assert factor_prime_power(q) == (q, 1)
    x = np.arange(q, dtype=np.int64)
    squares = np.zeros(q, bool)
    squares[x * x % q] = True
    kappa = int(np.flatnonzero(~squares)[0])
    inv, base, e = np.ones(q, np.int64), x.copy(), q - 2
    while e:
        if e & 1:
            inv = inv * base % q
        base = base * base % q
        e >>= 1
    m = x[1:]
    num = (kappa - 1) % q
    four = 4 % q
    out = np.zeros((3, q), np.int64)
    out[0, 1:] = num * inv[four * kappa * m % q] % q
    out[1, 1:] = kappa * m % q
    out[2, 1:] = m * m % q * num % q * inv[four] % q
    return [kappa, *out.ravel().tolist()]


def test_ak_levels_are_what_this_file_expects():
    assert len(AK_LEVELS) == 426 and AK_LEVELS[:4] == (3, 5, 7, 9) and AK_LEVELS[-1] == 2887
    assert {q for q in AK_LEVELS if factor_prime_power(q)[1] > 1} == {9, 25, 27, 49, 81, 121, 125, 169, 243}


def ak_upload(q: int) -> np.ndarray:
    """The uint32 array the OpenCL backend uploads for Addelman-Kempthorne at q."""
    ak = AddelmanKempthorne()
    return np.ascontiguousarray(ak.constants(ak.params_for(q, 2)), dtype=np.uint32).ravel()


@pytest.mark.parametrize("q", AK_DIRECT)
def test_ak_constants_equal_pyoa_gf(lib, q):
    n = lib.t_ak_entries(q)
    assert n == 1 + 3 * q
    got = fill(lib, "t_ak_fill", n, np.uint32, q)
    want = ak_upload(q)
    assert np.array_equal(got, want), (q, np.flatnonzero(got != want)[:5])
    if factor_prime_power(q)[1] == 1:
        assert ak_fast(q) == want.tolist(), q  # the fast oracle of the next test is pyoa.tables.gf's


def test_ak_constants_of_every_level(lib):
    """All 426 q of AddelmanKempthorne.levels(): the composite prime powers
    against pyoa.tables.gf (cached by the test above), the primes against ak_fast."""
    for q in AK_LEVELS:
        got = fill(lib, "t_ak_fill", lib.t_ak_entries(q), np.uint32, q)
        want = ak_upload(q) if factor_prime_power(q)[1] > 1 else ak_fast(q)
        assert got.tolist() == list(want), q


@pytest.mark.parametrize("q", [0, 1, 2, 4, 8, 15, 256])
def test_ak_zeros_for_q_without_constants(lib, q):
    """q not an odd prime power (pyoa.tables.gf.ak_constants raises): 1 + 3q zeros."""
    with pytest.raises(ValueError):
        gf.ak_constants(q)
    assert lib.t_ak_entries(q) == 1 + 3 * q
    assert not fill(lib, "t_ak_fill", 1 + 3 * q, np.uint32, q).any()


# ----------------------------------------------------------------------------- Halton

def test_halton_primes(lib):
    n = lib.t_halton_entries()
    assert n == sequences.HALTON_MAX_DIMS == 6542
    got = fill(lib, "t_halton_fill", n, np.uint32)
    assert np.array_equal(got, sequences.primes())
    assert got[-1] == 65521


# ----------------------------------------------------------------------------- Sobol

def test_sobol_data_header_is_generated():
    """sobol_data.h is pyoa.c_data's output for SciPy's table; a table or
    layout change not regenerated here (python -m pyoa.c_headers) fails."""
    assert (INCLUDE / "pyoa" / c_data.SOBOL_DATA_FILE).read_text() == c_data.sobol_data_header()


def test_sobol_packing_round_trips():
    """The packed stream, read back in Python, is SciPy's vinit (the layout
    that tables.h decodes, checked without C)."""
    poly, words, bits = c_data.sobol_packed()
    _, vinit = sequences._joe_kuo()
    stream = int.from_bytes(np.asarray(words, "<u4").tobytes(), "little")
    assert stream >> bits == 0 and len(words) == -(-bits // 32)
    pos = 0
    for d in range(1, len(poly)):
        s = poly[d].bit_length() - 1
        if d in (1, 2, 3, 100, 1111, 21200):  # spot dimensions (the offsets of all the others count)
            got = [2 * ((stream >> (pos + (k - 1) * (k - 2) // 2)) & ((1 << (k - 1)) - 1)) + 1 for k in range(1, s + 1)]
            assert got == vinit[d, :s].tolist(), d
        pos += s * (s - 1) // 2
    assert pos == bits


def test_sobol_generator_refuses_a_table_it_cannot_pack(monkeypatch):
    poly, vinit = sequences._joe_kuo()
    bad = vinit.copy()
    bad[5, 1] = 2  # even: not a direction number
    monkeypatch.setattr(sequences, "_joe_kuo", lambda: (poly, bad))
    with pytest.raises(ValueError, match="dimension 5: m_2"):
        c_data.sobol_packed()


@pytest.fixture(scope="module")
def sobol_all(lib):
    n = lib.t_sobol_entries(sequences.SOBOL_MAX_DIMS)
    assert n == 32 * 21201
    return fill(lib, "t_sobol_fill", n, np.uint32, sequences.SOBOL_MAX_DIMS).reshape(-1, 32)


def test_sobol_all_dimensions(sobol_all):
    assert np.array_equal(sobol_all, sequences.sobol_matrices())


@pytest.mark.parametrize("dims", [1, 2, 1000])
def test_sobol_prefixes(lib, sobol_all, dims):
    """A fill of ``dims`` writes exactly sobol_matrices()[:dims] (what Sobol.constants uploads)."""
    n = lib.t_sobol_entries(dims)
    assert n == 32 * dims
    got = fill(lib, "t_sobol_fill", n, np.uint32, dims).reshape(dims, 32)
    assert np.array_equal(got, sequences.sobol_matrices()[:dims])
    if dims == 2:  # sobol02's table: van der Corput, then m = 1, 3, 5, 15, ...
        assert got[0, :3].tolist() == [2**31, 2**30, 2**29] and got[1, :3].tolist() == [2**31, 3 << 30, 5 << 29]


@pytest.mark.parametrize("dims", [0, 21202, 2**32 - 1])
def test_sobol_dims_zero_or_too_many_mean_all(lib, sobol_all, dims):
    """As Python's V[:dims] (and Sobol.constants for dims = 0): the whole table."""
    assert lib.t_sobol_entries(dims) == 32 * 21201
    got = fill(lib, "t_sobol_fill", 32 * 21201, np.uint32, dims)
    assert np.array_equal(got, sobol_all.ravel())
