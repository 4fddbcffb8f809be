/* pyoa/baselines.h: the comparison samplers of docs/spec.md section 5.8
 * (pyoa/reference/baselines.py holds the mathematics, the references and
 * the reference values): random, jittered2d, cmj2d, sobol02, halton and
 * sobol, and the helpers zsobol.h and pmj02.h share. Values of random,
 * sobol02, halton and sobol are k * 2^-24 with k a 24-bit integer: exact in
 * float, no rounding. Each pyoa_sample_<name> is named by its catalogue
 * entry (pyoa/catalogue/baselines.py `kernel`). */
#ifndef PYOA_BASELINES_H
#define PYOA_BASELINES_H

#include "config.h"
#include "floats.h"
#include "hashes.h"
#include "keys.h"

/* 2^-24, written in decimal (hexadecimal float literals are not C++14). */
#define PYOA_2POW_M24 5.9604644775390625e-08f

/* The top 24 bits of h as a float in [0, 1). */
PYOA_FN float pyoa_unit24(pyoa_u32 h) { return PYOA_MUL(PYOA_U32_TO_F32(h >> 8), PYOA_2POW_M24); }

/* A seed derived from p and an index; seed 0 stays 0 (the canonical,
 * unscrambled point set, section 3.2). */
PYOA_FN pyoa_u32 pyoa_derived_seed(pyoa_u32 p, pyoa_u32 index, pyoa_u32 key)
{
    return p ? pyoa_hash_pair(p, index, key) : 0u;
}

PYOA_FN pyoa_u32 pyoa_reverse_bits(pyoa_u32 x)
{
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
}

/* Burley's Laine-Karras-style hash: even multipliers, so output bit k
 * depends only on input bits <= k. */
PYOA_FN pyoa_u32 pyoa_laine_karras(pyoa_u32 x, pyoa_u32 seed)
{
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

/* Hash-based Owen scrambling of a 32-bit fraction (Burley 2020); seed 0 is
 * the identity. */
PYOA_FN pyoa_u32 pyoa_owen_scramble(pyoa_u32 x, pyoa_u32 seed)
{
    pyoa_u32 y = pyoa_reverse_bits(pyoa_laine_karras(pyoa_reverse_bits(x), seed));
    return seed ? y : x;
}

/* XOR of one dimension's 32 direction numbers v over the set bits of g. */
PYOA_FN pyoa_u32 pyoa_sobol_bits(pyoa_u32 g, PYOA_GLOBAL const pyoa_u32 *v)
{
    pyoa_u32 x = 0u;
    for (pyoa_u32 k = 0u; g; ++k, g >>= 1)
        if (g & 1u) x ^= v[k];
    return x;
}

/* random: value j of sample i, a hash of (i, j, p). */
PYOA_FN float pyoa_sample_random(pyoa_u32 i, pyoa_u32 j, pyoa_u32 p)
{
    return pyoa_unit24(pyoa_mix32(i ^ pyoa_hash_pair(p, j, PYOA_RANDOM_KEY)));
}

/* jittered2d: pairs of dimensions padded from m x m jittered grids, each
 * pair's N = m^2 samples in their own shuffled order; with an odd number of
 * dimensions `dims`, the lone last one is N strata (dims = 0: no lone
 * dimension). */
PYOA_FN float pyoa_sample_jittered2d(pyoa_u32 i, pyoa_u32 j, pyoa_u32 m, pyoa_u32 dims, pyoa_u32 p, float J)
{
    pyoa_u32 q = pyoa_derived_seed(p, j >> 1, PYOA_PAD_KEY);
    pyoa_u32 N = m * m;
    pyoa_u32 k = pyoa_permute(i, N, q * PYOA_SHUFFLE_KEY);
    int even = (j & 1u) == 0u;
    float jit = pyoa_jitter_value(pyoa_randfloat(k, q * (even ? PYOA_JITX_KEY : PYOA_JITY_KEY)), J);
    if (even && j + 1u == dims) return pyoa_sample_value(k, 0u, jit, 1u, N); /* a lone last dimension */
    return pyoa_sample_value(even ? k % m : k / m, 0u, jit, 1u, m);
}

/* cmj2d: pairs padded from Kensler's correlated multi-jittered m x n
 * grids. */
PYOA_FN float pyoa_sample_cmj2d(pyoa_u32 i, pyoa_u32 j, pyoa_u32 m, pyoa_u32 n, pyoa_u32 p, float J)
{
    pyoa_u32 q = pyoa_derived_seed(p, j >> 1, PYOA_PAD_KEY);
    pyoa_u32 k = pyoa_permute(i, m * n, q * PYOA_SHUFFLE_KEY);
    pyoa_u32 sx = pyoa_permute(k % m, m, q * PYOA_SUBX_KEY);
    if ((j & 1u) == 0u) {
        pyoa_u32 sy = pyoa_permute(k / m, n, q * PYOA_SUBY_KEY);
        return pyoa_sample_value(k % m, sy, pyoa_jitter_value(pyoa_randfloat(k, q * PYOA_JITX_KEY), J), n, m);
    }
    return pyoa_sample_value(k / m, sx, pyoa_jitter_value(pyoa_randfloat(k, q * PYOA_JITY_KEY), J), m, n);
}

/* sobol02: pairs padded from Owen-scrambled (0,2)-sequences of 2^log2n
 * points; `directions` = Sobol' dimensions 0 and 1 (64 words). The scramble
 * seeds are hashed: Burley's top levels depend on a seed's low bits only. */
PYOA_FN float pyoa_sample_sobol02(pyoa_u32 i, pyoa_u32 j, pyoa_u32 log2n, pyoa_u32 p,
                                  PYOA_GLOBAL const pyoa_u32 *directions)
{
    pyoa_u32 q = pyoa_derived_seed(p, j >> 1, PYOA_PAD_KEY);
    pyoa_u32 g = pyoa_owen_scramble(i, pyoa_derived_seed(q, 0u, PYOA_OWEN_KEY)) & ((1u << log2n) - 1u);
    pyoa_u32 c = j & 1u;
    return pyoa_unit24(pyoa_owen_scramble(pyoa_sobol_bits(g, directions + 32u * c),
                                          pyoa_derived_seed(q, 1u + c, PYOA_OWEN_KEY)));
}

/* halton: dimension j in base primes[j] (primes: pyoa_halton_fill of
 * pyoa/tables.h), digits randomly permuted per prefix (nested). */
PYOA_FN float pyoa_sample_halton(pyoa_u32 i, pyoa_u32 j, pyoa_u32 p, PYOA_GLOBAL const pyoa_u32 *primes)
{
    pyoa_u32 b = primes[j];
    pyoa_u32 q = pyoa_derived_seed(p, j, PYOA_HALTON_KEY);
    pyoa_u32 rest = i, prefix = 0u;
    pyoa_u64 numer = 0u, power = 1u; /* power = b^(k-1) */
    while (power < 0x1000000u) {
        pyoa_u32 d = rest % b;
        pyoa_u32 dd;
        rest /= b;
        dd = q ? pyoa_permute(d, b, pyoa_hash_pair(q, (pyoa_u32)power + prefix, PYOA_DIGIT_KEY)) : d;
        numer = numer * b + dd;
        prefix += d * (pyoa_u32)power;
        power *= b;
    }
    return PYOA_MUL(PYOA_U32_TO_F32((pyoa_u32)((numer << 24) / power)), PYOA_2POW_M24);
}

/* sobol: dimension j of the Owen-scrambled Sobol' sequence in Gray-code
 * order; `directions` = 32 words per dimension (pyoa_sobol_fill). */
PYOA_FN float pyoa_sample_sobol(pyoa_u32 i, pyoa_u32 j, pyoa_u32 p, PYOA_GLOBAL const pyoa_u32 *directions)
{
    pyoa_u32 x = pyoa_sobol_bits(i ^ (i >> 1), directions + 32u * j);
    return pyoa_unit24(pyoa_owen_scramble(x, pyoa_derived_seed(p, j, PYOA_SOBOL_KEY)));
}

#endif /* PYOA_BASELINES_H */
