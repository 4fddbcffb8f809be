"""Helpers shared by the test modules (importable as ``tests.helpers``)."""

from __future__ import annotations

import itertools
import subprocess
from pathlib import Path

import numpy as np

import pyoa
from pyoa import reference as ref

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
    reference functions (pixel seeds from ``pyoa.reference.pixel_seed``)."""
    out = np.empty((len(pixels), len(samples), len(dims)), dtype=np.float32)
    for a, pix in enumerate(pixels):
        p = ref.pixel_seed(smp.seed, int(pix))
        for b, i in enumerate(samples):
            for c, j in enumerate(dims):
                if smp.name == "bose":
                    out[a, b, c] = ref.bose(int(i), int(j), smp.s, p, smp.offset, smp.jitter)
                else:
                    out[a, b, c] = ref.cmjnd(int(i), int(j), smp.s, smp.strength, p, smp.offset, smp.jitter)
    return out


# --------------------------------------------------------------------------- canonical arrays

def bose_symbol(i: int, j: int, s: int) -> int:
    """A_ij of the plain Bose array (SPEC section 5)."""
    a0, a1 = divmod(i, s)
    if j == 0:
        return a0
    if j == 1:
        return a1
    return (a0 + (j - 1) * a1) % s


def bose_partner(j: int, s: int) -> int:
    """The partner column k of j (SPEC section 5), as a column index whose symbol
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


# --------------------------------------------------------------------------- OA / LH checks

def strata_exact(x: np.ndarray, s: int) -> np.ndarray:
    """Coarse strata of values generated with jitter 0 (points at fine-cell centres,
    far from every boundary, so floor is exact)."""
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
    for sub in itertools.combinations(cols, t):
        code = np.zeros(strata.shape[:-1], dtype=np.int64)
        for c in sub:
            code = code * s + strata[..., c]
        counts = np.sort(code, axis=-1)
        want = np.repeat(np.arange(s**t), lam)
        ok = np.all(counts == want, axis=-1)
        assert np.all(ok), f"{what}: columns {sub} are not an OA(strength {t}) in {np.size(ok) - np.count_nonzero(ok)} arrays"


def assert_latin_exact(x: np.ndarray, N: int, what: str = "") -> None:
    """floor(x*N) is a permutation of 0..N-1 in every column (jitter 0 values)."""
    cells = np.sort(np.floor(np.asarray(x, np.float64) * N).astype(np.int64), axis=-2)
    want = np.arange(N).reshape((N, 1))
    ok = np.all(cells == want, axis=-2)
    assert np.all(ok), f"{what}: {np.size(ok) - np.count_nonzero(ok)} columns are not Latin hypercubes at {N} cells"


def assert_latin_closed(x: np.ndarray, N: int, what: str = "") -> None:
    """1D Latin hypercube up to float32 rounding: the k-th smallest value of every
    column lies in the closed cell [k/N, (k+1)/N] (a jittered value may round
    onto the upper boundary of its cell), within a few float32 ulps."""
    xs = np.sort(np.asarray(x, np.float64), axis=-2) * N
    k = np.arange(N).reshape((N, 1))
    tol = 4 * N * 2.0**-24
    dev = np.maximum(k - xs, xs - (k + 1))
    assert dev.max() <= tol, f"{what}: a sorted value is {dev.max():.3g} cells outside its Latin-hypercube cell"


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
    """The i for which randfloat's integer hash (SPEC section 2, before the float
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
