/* pyoa/pmj02_build.h: the pmj02 table builder (host only), bit for bit
 * pyoa.tables.pmj02.tables(): 16 progressive multi-jittered (0,2) sequences
 * of 2^16 points, coordinates 24-bit integers k (the value is k * 2^-24),
 * uint32 of shape (set, point, coordinate) = (16, 65536, 2), row-major.
 *
 * Algorithm (pyoa/reference/pmj02.py gives the full argument; build_set
 * there is the readable version, pyoa/tables/pmj02.py the numba one; this
 * file makes the same draws for the same choices):
 * - Christensen, Kensler and Kilpatrick's pmj02 (EGSR 2018): after n = 2^m
 *   points the set is a (0,m,2)-net; the next n points go into subquadrants
 *   (cells of the 2^q grid, q = m/2 + 1): for even m the subquadrant
 *   diagonally opposite point i's, for odd m the two remaining ones of
 *   point i's cell, in the "balanced" order (one random bit per pass: flip
 *   x first or y first, in every cell; S. Brown's and A. Helmer's rule).
 * - Pharr's product of strata (JCGT 2019): inside its subquadrant a point
 *   takes a uniform 1D stratum of width 2^-M (M = m + 1) among those whose
 *   elementary intervals 2^-u x 2^-(M-u), u = 0..M, are all empty, found by
 *   walking down a chain of intervals per axis, then uniform low 24 - M bits.
 *   The reference proves the chains never branch (one stratum or none); the
 *   walk here does not rely on it: it enumerates every valid stratum in
 *   ascending order (a depth-first walk with no stack: the path is the index
 *   itself), like the Python chain lists, so a uniform index among several
 *   would give the same bits as Python's.
 * - Randomness is counter-based: set s has seed
 *   hash_pair(PYOA_PMJ02_BUILD_SEED, s, PYOA_PMJ02_BUILD_KEY), and every
 *   random integer is draw(seed, index, purpose, attempt) (docs/spec.md
 *   section 3's hash_pair; pyoa.reference.pmj02.draw).
 *
 * Memory: no heap, no global state. The occupancy of the elementary
 * intervals of area 2^-M, (M + 1) * 2^M bits (at most 17 * 2^16 = 139,264
 * bytes), lives either in caller-provided scratch (pyoa_pmj02_fill_set,
 * which one thread per set may call concurrently) or, for
 * pyoa_pmj02_fill, in the top 8 bits of the table's own words: coordinates
 * are 24-bit, so the top byte of every word of an already built or not yet
 * built set is free; the builder clears it again, and the filled table has
 * only 24-bit words. pyoa_pmj02_fill needs no memory beyond the table's
 * 8 MiB; it takes about 0.4 s on one core (gcc -O2, an Intel Xeon VM; about
 * 130 million instructions per set, mostly the interval marks and the
 * walks' occupancy reads), the numba builder's time; a caller in a hurry
 * builds the 16 sets on several threads with pyoa_pmj02_fill_set.
 */
#ifndef PYOA_PMJ02_BUILD_H
#define PYOA_PMJ02_BUILD_H

#include "config.h"
#include "hashes.h"
#include "keys.h"
#include "pmj02.h" /* PYOA_PMJ02_SETS and PYOA_PMJ02_POINTS: the table's layout */

#if !defined(__OPENCL_VERSION__)

/* pyoa.reference.pmj02.BUILD_SEED (the year of the pmj paper): not a *_KEY,
 * so not in keys.h; tests/test_c_pmj02.py checks it equals the Python one. */
#define PYOA_PMJ02_BUILD_SEED 2018u
/* pyoa.reference.pmj02.POINTS_LOG2 (PYOA_PMJ02_POINTS = 2^16 is in
 * pmj02.h) and BITS (a coordinate is k * 2^-24). */
#define PYOA_PMJ02_POINTS_LOG2 16u
#define PYOA_PMJ02_BITS 24u
/* The purposes of a draw (pyoa.reference.pmj02: X_STRATUM, ..., SWAP). */
#define PYOA_PMJ02_X_STRATUM 0u
#define PYOA_PMJ02_Y_STRATUM 1u
#define PYOA_PMJ02_X_LOW 2u
#define PYOA_PMJ02_Y_LOW 3u
#define PYOA_PMJ02_SWAP 4u

/* Words of the whole table: 16 * 65536 * 2. */
PYOA_HOST_FN pyoa_u32 pyoa_pmj02_table_entries(void)
{
    return PYOA_PMJ02_SETS * PYOA_PMJ02_POINTS * 2u;
}

/* Occupancy bits of the last pass of a full set: (16 + 1) * 2^16. */
#define PYOA_PMJ02_OCC_BITS ((PYOA_PMJ02_POINTS_LOG2 + 1u) << PYOA_PMJ02_POINTS_LOG2)

/* Bytes of the scratch pyoa_pmj02_fill_set needs (139,264), 4-byte aligned. */
PYOA_HOST_FN size_t pyoa_pmj02_scratch_bytes(void)
{
    return (size_t)(PYOA_PMJ02_OCC_BITS / 8u);
}

/* Seed of set s: hash_pair(BUILD_SEED, s, PMJ02_BUILD_KEY). */
PYOA_HOST_FN pyoa_u32 pyoa_pmj02_set_seed(pyoa_u32 s)
{
    return pyoa_hash_pair(PYOA_PMJ02_BUILD_SEED, s, PYOA_PMJ02_BUILD_KEY);
}

/* The build's random number `attempt` for `purpose` at point (or pass)
 * `index`: hash_pair(hash_pair(seed, index, K), attempt << 3 | purpose, K),
 * K = PMJ02_DRAW_KEY (Python masks the shift to 32 bits, as C wraps). */
PYOA_HOST_FN pyoa_u32 pyoa_pmj02_draw(pyoa_u32 seed, pyoa_u32 index, pyoa_u32 purpose, pyoa_u32 attempt)
{
    return pyoa_hash_pair(pyoa_hash_pair(seed, index, PYOA_PMJ02_DRAW_KEY), (attempt << 3) | purpose,
                          PYOA_PMJ02_DRAW_KEY);
}

/* A uniform integer in [0, n), n >= 1: the draw's low bits under the least
 * all-ones mask covering n - 1, redrawn with the next attempt while >= n.
 * For n == 1 every draw gives 0, so none is made. */
PYOA_HOST_FN pyoa_u32 pyoa_pmj02_uniform_index(pyoa_u32 seed, pyoa_u32 index, pyoa_u32 purpose, pyoa_u32 n)
{
    pyoa_u32 mask = 0u, attempt = 0u, r;
    if (n <= 1u) return 0u;
    while (mask < n - 1u) mask = 2u * mask + 1u;
    for (;;) {
        r = pyoa_pmj02_draw(seed, index, purpose, attempt) & mask;
        if (r < n) return r;
        ++attempt;
    }
}

/* The occupancy bits: bit k is bit `base + (k & (2^lg - 1))` of word
 * w[k >> lg]; the other bits of each word are left alone. lg = 5, base = 0:
 * plain packed bits (scratch); lg = 3, base = 24: the top byte of table
 * words. Bit (u << M) | i is interval i of shape (u, M - u), i = (a << (M -
 * u)) | c for [a 2^-u, (a+1) 2^-u) x [c 2^-(M-u), (c+1) 2^-(M-u)). */
typedef struct pyoa_pmj02_occ {
    pyoa_u32 *w;
    pyoa_u32 lg;
    pyoa_u32 base;
} pyoa_pmj02_occ;

PYOA_HOST_FN int pyoa_pmj02_occ_get(const pyoa_pmj02_occ *o, pyoa_u32 k)
{
    return (int)((o->w[k >> o->lg] >> (o->base + (k & ((1u << o->lg) - 1u)))) & 1u);
}

/* Clear the bits [0, nbits) (whole words: the storage is sized for 17 *
 * 2^16 bits, so the words covering any level's bits are all ours). */
PYOA_HOST_FN void pyoa_pmj02_occ_clear(const pyoa_pmj02_occ *o, pyoa_u32 nbits)
{
    pyoa_u32 per = 1u << o->lg, words = (nbits + per - 1u) >> o->lg, k;
    pyoa_u32 keep = (per == 32u) ? 0u : ~(((1u << per) - 1u) << o->base);
    for (k = 0u; k < words; ++k) o->w[k] &= keep;
}

/* Mark every interval of area 2^-M holding the point (x, y) (24-bit). */
PYOA_HOST_FN void pyoa_pmj02_mark(const pyoa_pmj02_occ *o, pyoa_u32 M, pyoa_u32 x, pyoa_u32 y)
{
    /* locals: a store through w could alias o's fields, which the compiler
     * would otherwise reload at every step */
    pyoa_u32 *w = o->w, lg = o->lg, base = o->base, low = (1u << lg) - 1u, u;
    for (u = 0u; u <= M; ++u) {
        pyoa_u32 v = M - u;
        pyoa_u32 k = (u << M) | ((x >> (PYOA_PMJ02_BITS - u)) << v) | (y >> (PYOA_PMJ02_BITS - v));
        w[k >> lg] |= 1u << (base + (k & low));
    }
}

/* Whether the chain node (t, a) of Pharr's walk along `axis` is empty: the
 * interval with t bits a along the axis and the top M - t bits of the
 * subquadrant's other index qb (q bits) along the other axis. */
PYOA_HOST_FN int pyoa_pmj02_node_empty(const pyoa_pmj02_occ *o, pyoa_u32 M, pyoa_u32 q, pyoa_u32 qb,
                                       pyoa_u32 axis, pyoa_u32 t, pyoa_u32 a)
{
    pyoa_u32 cb = qb >> (q - (M - t)); /* M - t <= q */
    pyoa_u32 k = (axis == 0u) ? ((t << M) | (a << (M - t)) | cb) : (((M - t) << M) | (cb << t) | a);
    return !pyoa_pmj02_occ_get(o, k);
}

/* Pharr's chain walk (pyoa.reference.pmj02.Occupancy.strata): the 1D
 * strata of width 2^-M along `axis` (0: x, 1: y) where a point of the
 * subquadrant (qa along the axis, qb along the other) of the 2^q grid meets
 * only empty intervals. Depth first, children in order, so the strata come
 * in ascending order as in Python's breadth-first lists: returns their
 * count and stores the one of rank `want` (if any) in *pick. The node
 * (t, a) of level t has a's top t - q bits below the root qa as its path. */
PYOA_HOST_FN pyoa_u32 pyoa_pmj02_strata(const pyoa_pmj02_occ *o, pyoa_u32 M, pyoa_u32 q, pyoa_u32 qa,
                                        pyoa_u32 qb, pyoa_u32 axis, pyoa_u32 want, pyoa_u32 *pick)
{
    pyoa_u32 t = q, a = qa, count = 0u;
    for (;;) {
        int next = 1;
        if (pyoa_pmj02_node_empty(o, M, q, qb, axis, t, a)) {
            if (t == M) {
                if (count == want) *pick = a;
                ++count;
            } else { /* descend to the first child */
                ++t;
                a <<= 1;
                next = 0;
            }
        }
        if (next) { /* the next node in order: a right sibling, else up */
            for (;;) {
                if (t == q) return count;
                if ((a & 1u) == 0u) {
                    a |= 1u;
                    break;
                }
                a >>= 1;
                --t;
            }
        }
    }
}

/* Place point `index` in subquadrant (qx, qy) of the 2^q grid at level M:
 * a uniform valid stratum per axis, uniform low bits; marks it. 0 at a dead
 * end (no valid stratum on an axis). */
PYOA_HOST_FN int pyoa_pmj02_place(const pyoa_pmj02_occ *o, pyoa_u32 M, pyoa_u32 q, pyoa_u32 qx, pyoa_u32 qy,
                                  pyoa_u32 seed, pyoa_u32 index, pyoa_u32 *out)
{
    pyoa_u32 x = 0u, y = 0u, nx, ny, r;
    pyoa_u32 low = (1u << (PYOA_PMJ02_BITS - M)) - 1u;
    nx = pyoa_pmj02_strata(o, M, q, qx, qy, 0u, 0u, &x);
    if (nx == 0u) return 0;
    ny = pyoa_pmj02_strata(o, M, q, qy, qx, 1u, 0u, &y);
    if (ny == 0u) return 0;
    if (nx > 1u) { /* never for pmj02 (the chains do not branch); kept general */
        r = pyoa_pmj02_uniform_index(seed, index, PYOA_PMJ02_X_STRATUM, nx);
        pyoa_pmj02_strata(o, M, q, qx, qy, 0u, r, &x);
    }
    if (ny > 1u) {
        r = pyoa_pmj02_uniform_index(seed, index, PYOA_PMJ02_Y_STRATUM, ny);
        pyoa_pmj02_strata(o, M, q, qy, qx, 1u, r, &y);
    }
    x = (x << (PYOA_PMJ02_BITS - M)) | (pyoa_pmj02_draw(seed, index, PYOA_PMJ02_X_LOW, 0u) & low);
    y = (y << (PYOA_PMJ02_BITS - M)) | (pyoa_pmj02_draw(seed, index, PYOA_PMJ02_Y_LOW, 0u) & low);
    out[2u * index] = x;
    out[2u * index + 1u] = y;
    pyoa_pmj02_mark(o, M, x, y);
    return 1;
}

/* Clear the occupancy of level M and mark the first n points of out. */
PYOA_HOST_FN void pyoa_pmj02_remark(const pyoa_pmj02_occ *o, pyoa_u32 M, pyoa_u32 n, const pyoa_u32 *out)
{
    pyoa_u32 i;
    pyoa_pmj02_occ_clear(o, (M + 1u) << M);
    for (i = 0u; i < n; ++i) pyoa_pmj02_mark(o, M, out[2u * i], out[2u * i + 1u]);
}

/* The first `points` points of the set with seed `seed` into out[2 i + c]
 * (pyoa.reference.pmj02.build_set): 0, or 1 + the index of the point that
 * met a dead end. */
PYOA_HOST_FN int pyoa_pmj02_build(pyoa_u32 seed, pyoa_u32 points, pyoa_u32 *out, const pyoa_pmj02_occ *o)
{
    const pyoa_u32 B = PYOA_PMJ02_BITS;
    pyoa_u32 n = 1u, m = 0u, i;
    pyoa_pmj02_remark(o, 0u, 0u, out);
    if (!pyoa_pmj02_place(o, 0u, 0u, 0u, 0u, seed, 0u, out)) return 1; /* anywhere in the square */
    while (n < points) {                                                 /* n = 2^m points: a (0,m,2)-net */
        pyoa_u32 M = m + 1u, q = m / 2u + 1u;                            /* subquadrants: the 2^q grid */
        pyoa_pmj02_remark(o, M, n, out);
        if (m % 2u == 0u) { /* n = 4^k: the diagonally opposite subquadrant of each point */
            for (i = 0u; i < n; ++i) {
                pyoa_u32 sx = out[2u * i] >> (B - q), sy = out[2u * i + 1u] >> (B - q);
                if (!pyoa_pmj02_place(o, M, q, sx ^ 1u, sy ^ 1u, seed, n + i, out)) return (int)(n + i + 1u);
            }
        } else { /* n = 2 * 4^k: the two remaining subquadrants of each cell, balanced */
            pyoa_u32 h = n / 2u, fx = pyoa_pmj02_draw(seed, n, PYOA_PMJ02_SWAP, 0u) & 1u;
            for (i = 0u; i < h; ++i) {
                pyoa_u32 sx = out[2u * i] >> (B - q), sy = out[2u * i + 1u] >> (B - q);
                if (!pyoa_pmj02_place(o, M, q, sx ^ fx, sy ^ (1u - fx), seed, n + i, out)) return (int)(n + i + 1u);
            }
            for (i = 0u; i < h; ++i) {
                pyoa_u32 sx = out[2u * i] >> (B - q), sy = out[2u * i + 1u] >> (B - q);
                if (!pyoa_pmj02_place(o, M, q, sx ^ (1u - fx), sy ^ fx, seed, n + h + i, out))
                    return (int)(n + h + i + 1u);
            }
        }
        n *= 2u;
        ++m;
    }
    return 0;
}

/* Set `set` (any uint32; the table holds 0..15), its first `points` points
 * (a power of two in [1, 2^16]: prefixes of the full set) into out[2 i + c],
 * 2 * points words. scratch: pyoa_pmj02_scratch_bytes() bytes, 4-byte
 * aligned, contents ignored; one per thread, so threads may build different
 * sets at once. Returns 0; -1 for a bad `points`; 1 + i when point i met a
 * subquadrant with no valid position (never for the table's sets, nor for
 * any set tried: pyoa/reference/pmj02.py). */
PYOA_HOST_FN int pyoa_pmj02_fill_set(pyoa_u32 set, pyoa_u32 points, pyoa_u32 *out, void *scratch)
{
    pyoa_pmj02_occ o;
    if (points == 0u || points > PYOA_PMJ02_POINTS || (points & (points - 1u)) != 0u) return -1;
    o.w = (pyoa_u32 *)scratch;
    o.lg = 5u;
    o.base = 0u;
    return pyoa_pmj02_build(pyoa_pmj02_set_seed(set), points, out, &o);
}

/* The whole table, pyoa.tables.pmj02.tables(), into out
 * (pyoa_pmj02_table_entries() words, row-major set, point, coordinate), with
 * no other memory: set s keeps its occupancy in the top bytes of the first
 * 17 * 2^16 / 8 words of set 8 (s < 8) or of set 0 (s >= 8), never its own
 * words, and clears them after. Returns 0, else 1 + the first set that met
 * a dead end (never). */
PYOA_HOST_FN int pyoa_pmj02_fill(pyoa_u32 *out)
{
    const pyoa_u32 per_set = 2u * PYOA_PMJ02_POINTS, words = PYOA_PMJ02_OCC_BITS / 8u;
    pyoa_u32 s, k;
    pyoa_pmj02_occ o;
    o.lg = 3u;
    o.base = 24u;
    for (s = 0u; s < PYOA_PMJ02_SETS; ++s) {
        int rc;
        o.w = out + (s < PYOA_PMJ02_SETS / 2u ? PYOA_PMJ02_SETS / 2u : 0u) * per_set;
        rc = pyoa_pmj02_build(pyoa_pmj02_set_seed(s), PYOA_PMJ02_POINTS, out + s * per_set, &o);
        for (k = 0u; k < words; ++k) o.w[k] &= 0x00ffffffu; /* 24-bit words again */
        if (rc != 0) return (int)(s + 1u);
    }
    return 0;
}

#endif /* !__OPENCL_VERSION__ */
#endif /* PYOA_PMJ02_BUILD_H */
