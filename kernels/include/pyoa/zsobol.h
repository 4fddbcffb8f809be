/* pyoa/zsobol.h: zsobol, pbrt-v4's ZSobolSampler (Ahmed and Wonka 2020)
 * with pyoa's hashes (docs/spec.md section 5.8; pyoa/reference/zsobol.py
 * holds the mathematics and references). Values are k * 2^-24 with k a
 * 24-bit integer: exact in float, no rounding. */
#ifndef PYOA_ZSOBOL_H
#define PYOA_ZSOBOL_H

#include "baselines.h"
#include "config.h"
#include "hashes.h"
#include "keys.h"

/* pbrt-v4's MixBits: a bijective avalanche hash of a 64-bit word. */
PYOA_FN pyoa_u64 pyoa_mix64(pyoa_u64 v)
{
    v ^= v >> 31;
    v *= (pyoa_u64)0x7fb5d329728ea185u;
    v ^= v >> 27;
    v *= (pyoa_u64)0x81dadef4bc2dd44du;
    v ^= v >> 33;
    return v;
}

/* Bit t of a 16-bit value to bit 2t. */
PYOA_FN pyoa_u32 pyoa_morton_spread16(pyoa_u32 v)
{
    v &= 0x0000ffffu;
    v = (v | (v << 8)) & 0x00ff00ffu;
    v = (v | (v << 4)) & 0x0f0f0f0fu;
    v = (v | (v << 2)) & 0x33333333u;
    v = (v | (v << 1)) & 0x55555555u;
    return v;
}

/* pbrt's EncodeMorton2 for x, y < 2^16: x in the even bits, y in the odd. */
PYOA_FN pyoa_u32 pyoa_morton2(pyoa_u32 x, pyoa_u32 y)
{
    return pyoa_morton_spread16(x) | (pyoa_morton_spread16(y) << 1);
}

/* PERMS[p][digit] of pyoa/reference/zsobol.py (the 24 permutations of
 * {0,1,2,3} in lexicographic order) without a table in memory: permutation
 * p is the byte PERMS[p][0] | PERMS[p][1] << 2 | PERMS[p][2] << 4 |
 * PERMS[p][3] << 6, bytes 8 at a time in three 64-bit literals. */
PYOA_FN pyoa_u32 pyoa_zsobol_perm(pyoa_u32 p, pyoa_u32 digit)
{
    pyoa_u64 w = p < 8u    ? (pyoa_u64)0xb1e16c9c78d8b4e4u
                 : p < 16u ? (pyoa_u64)0x36c672d22d8d39c9u
                           : (pyoa_u64)0x1b4b278763931e4eu;
    return (pyoa_u32)(w >> (8u * (p & 7u) + 2u * digit)) & 3u;
}

/* The low 32 bits of the permuted index g of sample i of `pixel` (in an
 * image `width` wide) for the pair with key q (pbrt's GetSampleIndex, the
 * reference's permute_digits). Digits at bit 32 and above are skipped (their
 * bits are dropped), but every hash reads the whole Morton index m < 2^56. */
PYOA_FN pyoa_u32 pyoa_zsobol_index(pyoa_u32 i, pyoa_u32 log2n, pyoa_u32 log2res, pyoa_u32 width, pyoa_u32 pixel,
                                   pyoa_u32 q)
{
    pyoa_u32 x = pixel % width, y = (pixel / width) & 0xffffu;
    pyoa_u64 m = ((pyoa_u64)pyoa_morton2(x, y) << log2n) | (pyoa_u64)i;
    pyoa_u64 key = (pyoa_u64)0x55555555u * (pyoa_u64)q;
    int odd = (int)(log2n & 1u);
    /* d = D-1 down to odd, D = log2res + ceil(log2n / 2); shift = 2d - odd < 32 <=> d <= 15 + odd */
    int top0 = (int)(log2res + (log2n + 1u) / 2u) - 1, top1 = 15 + odd;
    int top = top0 < top1 ? top0 : top1;
    pyoa_u32 g = 0u;
    for (int d = top; d >= odd; --d) {
        pyoa_u32 shift = (pyoa_u32)(2 * d - odd);
        pyoa_u32 digit = (pyoa_u32)(m >> shift) & 3u;
        pyoa_u64 higher = m >> (shift + 2u); /* the unpermuted digits above this one */
        pyoa_u32 p = (pyoa_u32)((pyoa_mix64(higher ^ key) >> 24) % 24u);
        g |= pyoa_zsobol_perm(p, digit) << shift;
    }
    if (odd) g |= ((pyoa_u32)m & 1u) ^ ((pyoa_u32)pyoa_mix64((m >> 1) ^ key) & 1u);
    return g;
}

/* The first two Sobol' dimensions without a table: dimension 0's direction
 * numbers are v_k = 2^(31-k) (bit reversal), dimension 1's are
 * v_0 = 2^31, v_(k+1) = v_k ^ (v_k >> 1) (Pascal's triangle mod 2): rows 0
 * and 1 of pyoa.tables.sequences.sobol_matrices(). */
PYOA_FN pyoa_u32 pyoa_zsobol_sobol_bits(pyoa_u32 g, pyoa_u32 c)
{
    pyoa_u32 x = 0u;
    if (c == 0u) return pyoa_reverse_bits(g);
    for (pyoa_u32 v = 0x80000000u; g; g >>= 1, v ^= v >> 1)
        if (g & 1u) x ^= v;
    return x;
}

/* Value j of sample i (i < 2^log2n) of `pixel` in an image `width` wide,
 * log2res = ceil(log2(max(width, height))), with the user seed `seed` (not
 * the pixel's seed: the pixel enters through its Morton index). */
PYOA_FN float pyoa_sample_zsobol(pyoa_u32 i, pyoa_u32 j, pyoa_u32 log2n, pyoa_u32 log2res, pyoa_u32 width,
                                 pyoa_u32 pixel, pyoa_u32 seed)
{
    pyoa_u32 c = j & 1u;
    pyoa_u32 q = pyoa_hash_pair(seed, j >> 1, PYOA_ZSOBOL_KEY);
    pyoa_u32 g = pyoa_zsobol_index(i, log2n, log2res, width, pixel, q);
    return pyoa_unit24(pyoa_owen_scramble(pyoa_zsobol_sobol_bits(g, c), pyoa_hash_pair(q, 1u + c, PYOA_OWEN_KEY)));
}

#endif /* PYOA_ZSOBOL_H */
