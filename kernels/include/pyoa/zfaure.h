/* pyoa/zfaure.h: zfaure, one Owen-scrambled Faure sequence handed out to
 * the pixels along a scrambled base-b Morton order of the image, so that
 * the error image is blue noise in every dimension of a block (docs/spec.md
 * section 5.12; pyoa/reference/zfaure.py holds the mathematics, why the
 * order is this one, and the references; this is the same computation,
 * operation for operation). */
#ifndef PYOA_ZFAURE_H
#define PYOA_ZFAURE_H

#include "baselines.h"
#include "config.h"
#include "faure.h"
#include "hashes.h"
#include "keys.h"

/* Most digits of an index T = z N + i: D = max(K, 2k + m), K <= 24, and
 * b^(2k) N = b^(2k+m) <= 2^64, so 2k + m <= 64 (an image side <= 2^16 keeps
 * it to 56, in base 2). */
#define PYOA_ZFAURE_MAX_DIGITS 64

/* The base-b digits of z, the position of pixel (x, y) on the scrambled
 * Morton order of the b^k x b^k grid (reference.zfaure.pixel_code), least
 * significant first, into z[0 .. 2k-1]. Level l (the most significant
 * first) takes the digits dx, dy of x and y; its b x b tile, named by t (a
 * hash of the seed and of every digit above), permutes its columns and its
 * rows and transposes at random; its child gy b + gx (gx b + gy when
 * transposed) is base-b^2 digit k-1-l of z. S is the sequence's seed
  * (hash_pair(seed, b, ZFAURE_ORDER_KEY)), never 0. */
PYOA_FN pyoa_u32 pyoa_zfaure_axis_permute(pyoa_u32 d, pyoa_u32 b, pyoa_u32 h)
{
    /* two permutations composed: one alone reaches few of the b! orders of a small b */
    return pyoa_permute(pyoa_permute(d, b, h), b, pyoa_mix32(h));
}

PYOA_FN void pyoa_zfaure_pixel_digits(pyoa_u32 x, pyoa_u32 y, pyoa_u32 b, pyoa_u32 k, pyoa_u32 S, pyoa_u32 *z)
{
    pyoa_u32 t = S, scale = 1u;
    for (pyoa_u32 level = 1u; level < k; level++) /* scale = b^(k-1) < max(width, height) <= 2^16 */
        scale *= b;
    for (pyoa_u32 level = 0u; level < k; level++, scale /= b) {
        pyoa_u32 dx = x / scale % b, dy = y / scale % b;
        pyoa_u32 gx = pyoa_zfaure_axis_permute(dx, b, pyoa_hash_pair(t, 0u, PYOA_ZFAURE_AXIS_KEY));
        pyoa_u32 gy = pyoa_zfaure_axis_permute(dy, b, pyoa_hash_pair(t, 1u, PYOA_ZFAURE_AXIS_KEY));
        pyoa_u32 swap = pyoa_hash_pair(t, 2u, PYOA_ZFAURE_AXIS_KEY) >> 31;
        t = pyoa_hash_pair(t, dy * b + dx, PYOA_ZFAURE_TILE_KEY);
        z[2u * (k - 1u - level)] = swap ? gy : gx;
        z[2u * (k - 1u - level) + 1u] = swap ? gx : gy;
    }
}

/* Sample i, dimension j of pixel `pixel` (row-major in an image `width`
 * wide) of zfaure in base b with N = b^m samples per pixel (m >= 2), k the
 * digits of the padded b^k x b^k grid, and the user seed `seed` (not the
 * pixel's seed: one sequence and one order for the whole image). The index
 * T = z N + i (below b^(2k) N <= 2^64) is read as its D = max(K, 2k + m)
 * lowest base-b digits, which need no 64-bit division: N = b^m puts i's m
 * digits below z's 2k, and the digits above 2k + m are 0. A copy (j >= b)
 * scrambles all D of them by a hash chain (reference.zfaure.
 * chained_scramble), which reorders its pixels and samples and keeps every
 * aligned block of b^r indices an aligned block. */
PYOA_FN float pyoa_sample_zfaure(pyoa_u32 i, pyoa_u32 j, pyoa_u32 N, pyoa_u32 b, pyoa_u32 k, pyoa_u32 width,
                                 pyoa_u32 pixel, pyoa_u32 seed)
{
    pyoa_u32 col = j % b, block = j / b;
    /* the sequence's seed, never 0: every user seed, 0 included, scrambles */
    pyoa_u32 S = pyoa_hash_pair(seed, b, PYOA_ZFAURE_ORDER_KEY);
    pyoa_u32 P = pyoa_block_seed(S, block);
    pyoa_u32 a[PYOA_ZFAURE_MAX_DIGITS];
    pyoa_u32 m = 0u, D, r;
    for (pyoa_u32 power = 1u; power < N; power *= b) /* N = b^m <= 2^24 */
        m++;
    D = PYOA_MAX(pyoa_faure_digits(b), 2u * k + m);
    for (r = 0u; r < m; r++, i /= b)
        a[r] = i % b;
    pyoa_zfaure_pixel_digits(pixel % width, pixel / width, b, k, S, a + m);
    for (r = 2u * k + m; r < D; r++)
        a[r] = 0u;
    if (block) {
        /* every copy past the first reads the sequence in its own nested
         * order of pixels and samples: digit r permuted by a hash chained
         * over the digits above it, from the most significant down */
        pyoa_u32 h = pyoa_hash_pair(P, b, PYOA_ZFAURE_INDEX_KEY);
        for (r = D; r-- > 0u;) {
            pyoa_u32 d = a[r];
            a[r] = pyoa_permute(d, b, h);
            h = pyoa_hash_pair(h, d, PYOA_ZFAURE_INDEX_KEY);
        }
    }
    return pyoa_faure_digits_value(a, D, b, col, pyoa_derived_seed(P, col, PYOA_FAURE_KEY));
}

#endif /* PYOA_ZFAURE_H */
