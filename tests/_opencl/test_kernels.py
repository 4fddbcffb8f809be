"""The header functions (kernels/include/pyoa) as OpenCL compiles them, called one by
one through a small test kernel built with pyoa's own source and build options,
against the C oracle. The orthogonal arrays are called through ``pyoa_oa_value`` (the block rule, the
construction's cell and the common tail), with each construction's B, N and
M written out here from docs/spec.md section 1.4."""

from __future__ import annotations

import numpy as np
import pytest

from pyoa._opencl import program as prog
from tests.helpers import U32_MAX, assert_same_bits, kernel_runner, permute_cases, randfloat_cases, seed_pair_cases

pytestmark = pytest.mark.opencl
U32 = np.uint32

TEST_KERNELS = r"""
__kernel void t_permute(__global const uint *i, __global const uint *l, __global const uint *p, __global uint *out)
{ size_t g = get_global_id(0); out[g] = pyoa_permute(i[g], l[g], p[g]); }

__kernel void t_randfloat(__global const uint *i, __global const uint *p, __global float *out)
{ size_t g = get_global_id(0); out[g] = pyoa_randfloat(i[g], p[g]); }

__kernel void t_seeds(__global const uint *a, __global const uint *b, __global uint *mix,
                      __global uint *pix, __global uint *blk)
{ size_t g = get_global_id(0); mix[g] = pyoa_mix32(a[g]); pix[g] = pyoa_pixel_seed(a[g], b[g]); blk[g] = pyoa_block_seed(a[g], b[g]); }

__kernel void t_sample_value(__global const uint *stratum, __global const uint *sub, __global const float *jit,
                             const uint M, const uint s, __global float *out)
{ size_t g = get_global_id(0); out[g] = pyoa_sample_value(stratum[g], sub[g], jit[g], M, s); }

__kernel void t_jitter_value(__global const float *r, const float J, __global float *out)
{ size_t g = get_global_id(0); out[g] = pyoa_jitter_value(r[g], J); }

__kernel void t_bose(__global const uint *i, __global const uint *j, const uint s, __global const uint *p,
                     const uint offset, const float J, __global float *out)
{ size_t g = get_global_id(0);
  /* prime s only (the C oracle's domain): tabled = 0, so the GF placeholder is never used */
  out[g] = pyoa_oa_value(PYOA_SAMPLER_BOSE, i[g], j[g], s, 2u, s + 1u, s * s, s, p[g], offset, J,
                       (__global const ushort *)p, 0u, p); }

__kernel void t_cmjnd(__global const uint *i, __global const uint *j, const uint s, const uint t,
                      __global const uint *p, const uint offset, const float J, __global float *out)
{ size_t g = get_global_id(0);
  out[g] = pyoa_oa_value(PYOA_SAMPLER_CMJND, i[g], j[g], s, t, t, pyoa_pow_u(s, t), pyoa_pow_u(s, t - 1u), p[g], offset, J,
                       (__global const ushort *)p, 0u, p); }

__kernel void t_gf(__global const uint *a, __global const uint *b, const uint q, __global const ushort *gf,
                   const uint tabled, __global uint *sum, __global uint *prod)
{ size_t g = get_global_id(0); sum[g] = pyoa_gf_add(a[g], b[g], q, gf, tabled); prod[g] = pyoa_gf_mul(a[g], b[g], q, gf, tabled); }

__kernel void t_bose_gf(__global const uint *i, __global const uint *j, const uint s, __global const uint *p,
                        const uint offset, const float J, __global const ushort *gf, const uint tabled,
                        __global float *out)
{ size_t g = get_global_id(0);
  out[g] = pyoa_oa_value(PYOA_SAMPLER_BOSE, i[g], j[g], s, 2u, s + 1u, s * s, s, p[g], offset, J, gf, tabled, p); }

__kernel void t_bush(__global const uint *i, __global const uint *j, const uint s, const uint t,
                     __global const uint *p, const uint offset, const float J, __global const ushort *gf,
                     const uint tabled, __global float *out)
{ size_t g = get_global_id(0);
  out[g] = pyoa_oa_value(PYOA_SAMPLER_BUSH, i[g], j[g], s, t, s + 1u, pyoa_pow_u(s, t), pyoa_pow_u(s, t - 1u), p[g], offset, J,
                       gf, tabled, p); }

__kernel void t_addelman_kempthorne(__global const uint *i, __global const uint *j, const uint s,
                                    __global const uint *p, const uint offset, const float J,
                                    __global const ushort *gf, const uint tabled, __global const uint *ak,
                                    __global float *out)
{ size_t g = get_global_id(0);
  out[g] = pyoa_oa_value(PYOA_SAMPLER_ADDELMAN_KEMPTHORNE, i[g], j[g], s, 2u, 2u * s + 1u, 2u * s * s, 2u * s, p[g],
                       offset, J, gf, tabled, ak); }

__kernel void t_bose_bush(__global const uint *i, __global const uint *j, const uint s, __global const uint *p,
                          const uint offset, const float J, __global const ushort *gf, const uint tabled,
                          __global float *out)
{ size_t g = get_global_id(0);
  out[g] = pyoa_oa_value(PYOA_SAMPLER_BOSE_BUSH, i[g], j[g], s, 2u, 2u * s + 1u, 2u * s * s, 2u * s, p[g], offset, J,
                       gf, tabled, p); }

__kernel void t_ak_cell(__global const uint *i, __global const uint *j, const uint q, __global const ushort *gf,
                        const uint tabled, __global const uint *ak, __global uint *aij, __global uint *u)
{ size_t g = get_global_id(0); uint a, b, ck; pyoa_addelman_kempthorne_cell(i[g], j[g], q, 2u, 2u * q, gf, tabled, ak, &a, &b, &ck);
  aij[g] = a; u[g] = b; }

__kernel void t_zfaure(__global const uint *i, __global const uint *j, const uint N, const uint b, const uint k,
                       const uint width, __global const uint *pixel, __global const uint *seed, __global float *out)
{ size_t g = get_global_id(0); out[g] = pyoa_sample_zfaure(i[g], j[g], N, b, k, width, pixel[g], seed[g]); }

__kernel void t_bb_cell(__global const uint *i, __global const uint *j, const uint s, __global const ushort *gf,
                        const uint tabled, __global uint *aij, __global uint *u)
{ size_t g = get_global_id(0); uint a, b, ck; pyoa_bose_bush_cell(i[g], j[g], s, 2u, 2u * s, gf, tabled, 0, &a, &b, &ck); aij[g] = a; u[g] = b; }
"""


@pytest.fixture(scope="module")
def harness(opencl):
    return kernel_runner(opencl, TEST_KERNELS)


def test_permute_matches_c_oracle(harness, spec_c):
    cases = permute_cases()
    i, l, p = (np.array(v, dtype=U32) for v in zip(*cases))
    got = harness("t_permute", [U32], i, l, p)
    assert got.tolist() == spec_c.permute(*zip(*cases))


@pytest.mark.parametrize("l", [3, 4093, 2**23])
def test_permute_bijection(harness, l):
    for p in (0x9E3779B9, U32_MAX, U32_MAX - (l - 1)):
        got = harness("t_permute", [U32], np.arange(l, dtype=U32), np.full(l, l, U32), np.full(l, p, U32))
        assert np.array_equal(np.sort(got), np.arange(l, dtype=U32)), (l, p)


def test_randfloat_bits_match_c_oracle(harness, spec_c):
    cases = randfloat_cases()
    i, p = (np.array(v, dtype=U32) for v in zip(*cases))
    got = harness("t_randfloat", [np.float32], i, p)
    assert got.view(U32).tolist() == spec_c.randfloat_bits(*zip(*cases))


def test_seed_hashes_match_c_oracle(harness, spec_c):
    cases = seed_pair_cases()
    a, b = (np.array(v, dtype=U32) for v in zip(*cases))
    mix, pix, blk = harness("t_seeds", [U32, U32, U32], a, b)
    A, B = zip(*cases)
    assert mix.tolist() == spec_c.mix32(A)
    assert pix.tolist() == spec_c.pixel_seed(A, B)
    assert blk.tolist() == spec_c.block_seed(A, B)


def test_sample_value_clamps_below_one(harness):
    """stratum s-1, sub M-1, jitter just below 1: the exact result rounds to 1.0 and
    must become 0x3f7fffff (docs/spec.md section 7)."""
    from pyoa.reference.floats import sample_value

    jit = np.float32(1) - np.float32(2**-24)  # 0x3f7fffff
    cases = [(3, 3), (7, 49), (13, 13), (2, 2**23), (4093, 4093)]
    for s, M in cases:
        got = harness("t_sample_value", [np.float32], np.array([s - 1], U32), np.array([M - 1], U32),
                      np.array([jit], np.float32), U32(M), U32(s))
        want = np.float32(sample_value(s - 1, M - 1, float(jit), M, s))
        assert got.view(U32)[0] == want.view(U32) == 0x3F7FFFFF, (s, M)


def test_jitter_value_has_no_fused_multiply_add(harness):
    """0.5 + J * (r - 0.5) with two roundings; an FMA would differ for some inputs."""
    from pyoa.reference.floats import jitter_value

    rng = np.random.default_rng(11)
    r = rng.random(20000).astype(np.float32)
    for J in (0.1, 0.3, 0.7, 0.9999):
        got = harness("t_jitter_value", [np.float32], r, np.float32(J))
        want = np.array([jitter_value(float(x), float(np.float32(J))) for x in r], np.float32)
        assert_same_bits(got, want, f"J={J}")
        fused = (np.float64(0.5) + np.float64(np.float32(J)) * (r - np.float32(0.5)).astype(np.float64)).astype(np.float32)
        assert np.any(fused.view(U32) != want.view(U32)), "inputs do not distinguish an FMA"


@pytest.mark.parametrize("offset", ["centered", "j", "mj", "cmj"])
def test_bose_and_cmjnd_match_c_oracle_including_seed_zero(harness, spec_c, offset):
    code = {"centered": 0, "j": 1, "mj": 2, "cmj": 3}[offset]
    rng = np.random.default_rng(code)
    for s in (2, 3, 13, 4093):
        n = 400
        i = rng.integers(0, s * s, n).astype(U32)
        j = rng.integers(0, 3 * (s + 1), n).astype(U32)
        p = rng.choice(np.array([0, 1, U32_MAX, 0x12345678, 0x9E3779B9], U32), n)
        J = 0.625
        got = harness("t_bose", [np.float32], i, j, U32(s), p, U32(code), np.float32(J))
        want = spec_c.bose_bits([(a, b, s, c, offset, J) for a, b, c in zip(i, j, p)])
        assert got.view(U32).tolist() == want, f"bose s={s}"
    for s, t in ((2, 1), (3, 4), (2, 24), (4096, 2), (5, 3)):
        n = 300
        i = rng.integers(0, s**t, n).astype(U32)
        j = rng.integers(0, 3 * t, n).astype(U32)
        p = rng.choice(np.array([0, 1, U32_MAX, 0x12345678], U32), n)
        got = harness("t_cmjnd", [np.float32], i, j, U32(s), U32(t), p, U32(code), np.float32(1.0))
        want = spec_c.cmjnd_bits([(a, b, s, t, c, offset, 1.0) for a, b, c in zip(i, j, p)])
        assert got.view(U32).tolist() == want, f"cmjnd s={s} t={t}"


def test_build_options_keep_floats_exact():
    opts = " ".join(prog.BUILD_OPTIONS)
    assert "-cl-fp32-correctly-rounded-divide-sqrt" in opts
    for bad in ("-cl-fast-relaxed-math", "-cl-mad-enable", "-cl-unsafe-math-optimizations"):
        assert bad not in opts
    assert "#pragma OPENCL FP_CONTRACT OFF" in prog.source()


# ----------------------------------------------------------------------------- GF(q), Bose over GF(q), Bush

@pytest.fixture(scope="module")
def field_args(opencl):
    """``q -> (gf buffer, tabled)``: the kernel arguments the backend passes for GF(q)."""
    import pyopencl as cl

    from pyoa._opencl.backend import _field_tables

    def args(q):
        tab, tabled = _field_tables(q)
        buf = cl.Buffer(opencl.context, cl.mem_flags.READ_ONLY | cl.mem_flags.COPY_HOST_PTR, hostbuf=tab)
        return buf, U32(tabled)

    return args


@pytest.mark.parametrize("q", [4, 8, 9, 27, 125, 256, 2, 13, 251, 4093])
def test_gf_add_mul_match_pyoa_gf(harness, field_args, q):
    """pyoa/gf.h: table lookups for prime powers, mod q for primes, on every pair
    (or many random ones), against pyoa.tables.gf's scalar definition."""
    from pyoa.tables import gf

    if q * q <= 70000:
        a, b = (x.astype(U32) for x in np.divmod(np.arange(q * q), q))
    else:
        rng = np.random.default_rng(q)
        a, b = (rng.integers(0, q, 5000).astype(U32) for _ in range(2))
    tab, tabled = field_args(q)
    assert bool(tabled) == (gf.prime_power(q)[1] > 1)
    sums, prods = harness("t_gf", [U32, U32], a, b, U32(q), tab, tabled)
    if tabled:
        add, mul = gf.tables(q)
        assert np.array_equal(sums, add[a * q + b]) and np.array_equal(prods, mul[a * q + b])
    else:
        assert np.array_equal(sums, (a.astype(np.int64) + b) % q)
        assert np.array_equal(prods, (a.astype(np.int64) * b) % q)
    for k in range(0, len(a), max(1, len(a) // 40)):  # spot checks against the scalar definition
        x, y = int(a[k]), int(b[k])
        assert sums[k] == gf.add(x, y, q) and prods[k] == gf.mul(x, y, q)


@pytest.mark.parametrize("offset", ["centered", "j", "mj", "cmj"])
def test_gf_bose_and_bush_match_reference_including_seed_zero(harness, field_args, offset):
    from pyoa import reference as ref

    code = {"centered": 0, "j": 1, "mj": 2, "cmj": 3}[offset]
    rng = np.random.default_rng(10 + code)
    seeds = np.array([0, 1, U32_MAX, 0x12345678], U32)
    for q in (4, 9, 16, 27, 256, 7):
        n = 200
        i = np.concatenate([[0, q * q - 1], rng.integers(0, q * q, n - 2)]).astype(U32)
        j = np.concatenate([[q, q + 1], rng.integers(0, 3 * (q + 1), n - 2)]).astype(U32)
        p = rng.choice(seeds, n)
        got = harness("t_bose_gf", [np.float32], i, j, U32(q), p, U32(code), np.float32(0.625), *field_args(q))
        want = np.array([ref.bose(int(a), int(b), q, int(c), offset, 0.625) for a, b, c in zip(i, j, p)], np.float32)
        assert_same_bits(got, want, f"bose q={q}")
    for s, t in ((2, 2), (3, 3), (4, 4), (5, 5), (8, 8), (9, 2), (16, 6), (256, 3), (4093, 2)):
        n = 150 if s < 4093 else 30
        N = s**t
        i = np.concatenate([[0, N - 1], rng.integers(0, N, n - 2)]).astype(U32)
        j = np.concatenate([[s, 2 * s + 1], rng.integers(0, 3 * (s + 1), n - 2)]).astype(U32)
        p = rng.choice(seeds, n)
        got = harness("t_bush", [np.float32], i, j, U32(s), U32(t), p, U32(code), np.float32(1.0), *field_args(s))
        want = np.array([ref.bush(int(a), int(b), s, t, int(c), offset, 1.0) for a, b, c in zip(i, j, p)], np.float32)
        assert_same_bits(got, want, f"bush s={s} t={t}")



# ----------------------------------------------------------------------------- index 2: Addelman-Kempthorne, Bose-Bush

@pytest.fixture(scope="module")
def ak_consts(opencl):
    """``q -> buffer`` of [kappa, b, k, c], as the backend uploads it (Construction.constants)."""
    import pyopencl as cl

    from pyoa import catalogue as constructions

    def buf(q):
        c = constructions.get("addelman-kempthorne")
        vals = np.array(c.constants(c.resolve(2 * q * q, None, None)), dtype=U32)
        return cl.Buffer(opencl.context, cl.mem_flags.READ_ONLY | cl.mem_flags.COPY_HOST_PTR, hostbuf=vals)

    return buf


def _index2_rows_cols(s, n, rng):
    """n (i, j) pairs: the edges (first/last sample, both halves, the last column
    j = 2s, the first column of the next block) then random ones over three blocks."""
    N, d = 2 * s * s, 2 * s + 1
    edge_i = [0, N - 1, s * s - 1, s * s, N - 1, 0, s * s]
    edge_j = [0, 2 * s, 2 * s, s, d, 3 * d - 1, s - 1]
    i = np.concatenate([edge_i, rng.integers(0, N, n - len(edge_i))]).astype(U32)
    j = np.concatenate([edge_j, rng.integers(0, 3 * d, n - len(edge_j))]).astype(U32)
    return i, j


@pytest.mark.parametrize("offset", ["centered", "j", "mj", "cmj"])
def test_index2_kernels_match_reference_including_seed_zero(harness, field_args, ak_consts, offset):
    """pyoa/oa.h addelman_kempthorne (GF(q) tables for 9, 27, 243; mod q for
    3, 7, 251, 2887) and bose_bush (GF(2s) tables, s = 2 .. 128), one value at a
    time, against the reference."""
    from pyoa import reference as ref

    code = {"centered": 0, "j": 1, "mj": 2, "cmj": 3}[offset]
    rng = np.random.default_rng(20 + code)
    seeds = np.array([0, 1, U32_MAX, 0x12345678], U32)
    for q in (3, 9, 27, 243, 7, 251, 2887):
        i, j = _index2_rows_cols(q, 150, rng)
        p = rng.choice(seeds, len(i))
        got = harness("t_addelman_kempthorne", [np.float32], i, j, U32(q), p, U32(code), np.float32(0.625),
                      *field_args(q), ak_consts(q))
        want = np.array([ref.addelman_kempthorne(int(a), int(b), q, int(c), offset, 0.625)
                         for a, b, c in zip(i, j, p)], np.float32)
        assert_same_bits(got, want, f"addelman-kempthorne q={q}")
    for s in (2, 4, 8, 16, 32, 64, 128):
        i, j = _index2_rows_cols(s, 150, rng)
        p = rng.choice(seeds, len(i))
        got = harness("t_bose_bush", [np.float32], i, j, U32(s), p, U32(code), np.float32(1.0), *field_args(2 * s))
        want = np.array([ref.bose_bush(int(a), int(b), s, int(c), offset, 1.0) for a, b, c in zip(i, j, p)],
                        np.float32)
        assert_same_bits(got, want, f"bose-bush s={s}")


@pytest.mark.parametrize("name, s", [("addelman-kempthorne", q) for q in (3, 5, 9, 25, 27, 243, 2887)]
                         + [("bose-bush", s) for s in (2, 8, 32, 128)])
def test_index2_cells_are_the_plain_arrays(harness, field_args, ak_consts, name, s):
    """addelman_kempthorne_cell / bose_bush_cell of the kernels over every entry of
    the array (N <= 2048) against the independent plain arrays; for the larger ones
    every column of sampled rows against NumPy's cells (themselves checked against
    the plain arrays in tests/_numpy/test_oa.py)."""
    from pyoa._numpy import oa as noa
    from tests.helpers import plain_index2_array

    N, d = 2 * s * s, 2 * s + 1
    if N <= 2048:
        i, j = (x.ravel().astype(U32) for x in np.meshgrid(np.arange(N), np.arange(d), indexing="ij"))
    else:
        rows = np.random.default_rng(s).integers(0, N, 40 if s < 2887 else 4).tolist() + [0, s * s - 1, s * s, N - 1]
        i, j = (x.ravel().astype(U32) for x in np.meshgrid(rows, np.arange(d), indexing="ij"))
    if name == "addelman-kempthorne":
        aij, u = harness("t_ak_cell", [U32, U32], i, j, U32(s), *field_args(s), ak_consts(s))
        want = noa.addelman_kempthorne_cell(i, j, s)
    else:
        aij, u = harness("t_bb_cell", [U32, U32], i, j, U32(s), *field_args(2 * s))
        want = noa.bose_bush_cell(i, j, s)
    if N <= 2048:
        A, U = plain_index2_array(name, s)
        assert np.array_equal(aij.reshape(N, d), A) and np.array_equal(u.reshape(N, d), U)
    assert np.array_equal(aij, want[0]) and np.array_equal(u, want[1])
    assert aij.max() < s and u.max() < 2 * s


#: zfaure's shapes (N, b, width, height): one pixel; a non-square image in base 5; base 2's most index
#: digits (k = 16, and 2^24 samples at k = 12: 48 digits); the largest base; the two closest to the
#: 64-bit limit, b^(2k) N = 0.98 * 2^64 (1621^2 at k = 2) and 0.92 * 2^64 (137^3 at k = 3).
ZFAURE_SHAPES = [(4, 2, 1, 1), (125, 5, 7, 3), (16, 2, 65536, 65536), (2**24, 2, 4096, 4096), (4093**2, 4093, 2, 2),
                 (1621**2, 1621, 1622, 1622), (137**3, 137, 18770, 18770)]


@pytest.mark.parametrize("N, b, width, height", ZFAURE_SHAPES)
def test_zfaure_matches_numpy_with_64_bit_indices(harness, N, b, width, height):
    """pyoa_sample_zfaure (zfaure.h: the order, the 64-bit index and its digits, the copies' hash chain,
    faure.h's shared digit tail) against NumPy on random pixels, samples, dimensions (three blocks) and
    seeds (0 among them), plus the image's corners at the first and last
    sample. Near the limit some indices T = z N + i pass 2^63 (the reference's pixel_code says so),
    so every bit of the uint64 arithmetic is exercised."""
    from pyoa._numpy.zfaure import zfaure as np_zfaure
    from pyoa.reference.zfaure import grid_digits, pixel_code, sequence_seed

    k = grid_digits(b, width, height)
    rng = np.random.default_rng(N + b + width)
    n = 3000
    i = rng.integers(0, N, n).astype(U32)
    j = rng.integers(0, 3 * b, n).astype(U32)
    pixel = rng.integers(0, width * height, n).astype(U32)
    seed = rng.integers(0, 2**32, n, dtype=np.uint64).astype(U32)
    seed[::7] = 0
    corners = [(x, y) for x in (0, width - 1) for y in (0, height - 1)]
    edge = [(y * width + x, smp, s) for x, y in corners for smp in (0, N - 1) for s in (0, 4, 9, U32_MAX)]
    pixel, i, seed = (np.concatenate([a, np.array(e, U32)]) for a, e in zip((pixel, i, seed), zip(*edge)))
    j = np.concatenate([j, np.arange(len(edge), dtype=U32) % (3 * b)])
    got = harness("t_zfaure", [np.float32], i, j, U32(N), U32(b), U32(k), U32(width), pixel, seed)
    assert_same_bits(got, np_zfaure(i, j, N, b, k, width, pixel, seed), f"zfaure N={N} b={b} {width}x{height}")
    if b ** (2 * k) * N > 2**63:
        top = max(pixel_code(int(p) % width, int(p) // width, b, k, sequence_seed(int(s), b)) * N + int(t)
                  for p, t, s in zip(pixel, i, seed))
        assert top >= 2**63
