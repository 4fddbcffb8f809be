/* pyoa/hashes.h: the integer hashes of docs/spec.md sections 2, 3 and 6
 * (pyoa/reference/hashes.py is the reference). All arithmetic is 32-bit
 * unsigned with wrap-around.
 *
 * Each function is written once, as a macro over its types, and
 * instantiated for scalars (pyoa_permute_round, ...): in every language.
 * OpenCL C also gets the 8- and 16-lane instances its kernels use
 * (kernels/vector.cl): the same operations in the same order, so every
 * instance gives the same bits. */
#ifndef PYOA_HASHES_H
#define PYOA_HASHES_H

#include "config.h"
#include "keys.h"

/* One pass of Kensler's bijection on [0, w] (spec 2.1: the body of the
 * cycle walk), lanes with their own seeds. */
#define PYOA_DEFINE_PERMUTE_ROUND(SFX, UT)                                              \
PYOA_FN UT pyoa_permute_round##SFX(UT i, UT p, pyoa_u32 w)                              \
{                                                                                       \
    i ^= p;             i *= 0xe170893du;                                               \
    i ^= p >> 16;                                                                       \
    i ^= (i & w) >> 4;                                                                  \
    i ^= p >> 8;        i *= 0x0929eb3fu;                                               \
    i ^= p >> 23;                                                                       \
    i ^= (i & w) >> 1;  i *= 1u | (p >> 27);                                            \
    i *= 0x6935fa69u;                                                                   \
    i ^= (i & w) >> 11; i *= 0x74dcb303u;                                               \
    i ^= (i & w) >> 2;  i *= 0x9e501cc3u;                                               \
    i ^= (i & w) >> 2;  i *= 0xc860a3dfu;                                               \
    i &= w;                                                                             \
    i ^= i >> 5;                                                                        \
    return i;                                                                           \
}

/* Kensler's randfloat (spec 2.2): a float in [0, 1); 0.5 for p == 0.
 * Without an early return (a select at the end), so that a compiler can
 * vectorize its callers. One seed for all lanes. */
#define PYOA_DEFINE_RANDFLOAT(SFX, UT, FT, CVT)                                         \
PYOA_FN FT pyoa_randfloat##SFX(UT i, pyoa_u32 p)                                        \
{                                                                                       \
    i ^= p;                                                                             \
    i ^= i >> 17;                                                                       \
    i ^= i >> 10;  i *= 0xb36534e5u;                                                    \
    i ^= i >> 12;                                                                       \
    i ^= i >> 21;  i *= 0x93fc4795u;                                                    \
    i ^= 0xdf6e307fu;                                                                   \
    i ^= i >> 17;  i *= 1u | (p >> 18);                                                 \
    FT r = PYOA_MUL(CVT(i), PYOA_AS_F32(0x2f7ffffeu));                                  \
    return p ? r : (FT)0.5f;                                                            \
}

/* Wellons' lowbias32, the pair hash and the seeds built on it (spec 3 and
 * 6). A lane's condition is written as a comparison: an OpenCL vector ?:
 * selects by each lane's top bit, not by its being nonzero.
 * pyoa_block_order_seed is the seed of block `block`'s sample order: 0 for
 * block 0 (permute with seed 0 is the identity), else never 0. */
#define PYOA_DEFINE_SEEDS(SFX, UT)                                                      \
PYOA_FN UT pyoa_mix32##SFX(UT x)                                                        \
{                                                                                       \
    x ^= x >> 16; x *= 0x7feb352du;                                                     \
    x ^= x >> 15; x *= 0x846ca68bu;                                                     \
    x ^= x >> 16;                                                                       \
    return x;                                                                           \
}                                                                                       \
PYOA_FN UT pyoa_hash_pair##SFX(UT a, UT b, pyoa_u32 key)                                \
{                                                                                       \
    UT h = pyoa_mix32##SFX(b ^ pyoa_mix32##SFX(a ^ key));                               \
    return (h != 0u) ? h : (UT)key;                                                     \
}                                                                                       \
PYOA_FN UT pyoa_pixel_seed##SFX(pyoa_u32 seed, UT pixel)                                \
{                                                                                       \
    return pyoa_hash_pair##SFX((UT)seed, pixel, PYOA_PIXEL_KEY);                        \
}                                                                                       \
PYOA_FN UT pyoa_block_seed##SFX(UT p, UT block)                                         \
{                                                                                       \
    return (block != 0u) ? pyoa_hash_pair##SFX(p, block, PYOA_BLOCK_KEY) : p;           \
}                                                                                       \
PYOA_FN UT pyoa_block_order_seed##SFX(UT P, UT block, pyoa_u32 N)                       \
{                                                                                       \
    return (block != 0u) ? pyoa_hash_pair##SFX(P, (UT)N, PYOA_BLOCK_ORDER_KEY) : (UT)0u; \
}

PYOA_DEFINE_PERMUTE_ROUND(, pyoa_u32)
PYOA_DEFINE_RANDFLOAT(, pyoa_u32, float, PYOA_U32_TO_F32)
PYOA_DEFINE_SEEDS(, pyoa_u32)

/* The user seed of frame `frame` of an animation rendered with user seed
 * `seed` (spec 3.5): the seed itself for frame 0 (a still image keeps its
 * values), else hash_pair(seed, frame, FRAME_KEY), an independent
 * randomization per frame. */
PYOA_FN pyoa_u32 pyoa_frame_seed(pyoa_u32 seed, pyoa_u32 frame)
{
    return frame ? pyoa_hash_pair(seed, frame, PYOA_FRAME_KEY) : seed;
}

/* w = the all-ones mask just covering l - 1 (the walk's domain [0, w]). */
PYOA_FN pyoa_u32 pyoa_walk_mask(pyoa_u32 l)
{
    pyoa_u32 w = l - 1u;
    w |= w >> 1; w |= w >> 2; w |= w >> 4; w |= w >> 8; w |= w >> 16;
    return w;
}

/* The cycle walk: the first of round(i), round(round(i)), ... below l. */
PYOA_FN pyoa_u32 pyoa_permute_walk(pyoa_u32 i, pyoa_u32 l, pyoa_u32 p, pyoa_u32 w)
{
    do {
        i = pyoa_permute_round(i, p, w);
    } while (i >= l);
    return i;
}

/* Kensler's permute (spec 2.1) with the wrap-safe final shift:
 * element i of the p-th permutation of 0..l-1; 1 <= l <= 2^31, i < l. */
PYOA_FN pyoa_u32 pyoa_permute(pyoa_u32 i, pyoa_u32 l, pyoa_u32 p)
{
    if (p == 0u) return i;
    return (pyoa_permute_walk(i, l, p, pyoa_walk_mask(l)) + p % l) % l;
}

/* The row of sample i in a block whose order seed is r (spec 6): two
 * permutations with independent seeds, the identity for r = 0. */
PYOA_FN pyoa_u32 pyoa_block_row(pyoa_u32 i, pyoa_u32 N, pyoa_u32 r)
{
    return pyoa_permute(pyoa_permute(i, N, r), N, pyoa_mix32(r));
}

#if defined(__OPENCL_VERSION__)
PYOA_DEFINE_PERMUTE_ROUND(_v8, uint8)
PYOA_DEFINE_RANDFLOAT(_v8, uint8, float8, convert_float8_rte)
PYOA_DEFINE_SEEDS(_v8, uint8)

/* pyoa_permute_round in 16-bit lanes, for w < 2^16 (OpenCL only: C's
 * integer promotion would make a uint16 product a signed int): every step
 * of the round only carries information upward (multiplications, xors,
 * right shifts of i & w), so the low 16 bits of each intermediate are those
 * of the 32-bit round, and so is the result masked by w. Twice the lanes
 * per register, and a 16-bit multiply (one micro-op, latency 5 on x86)
 * where the 32-bit one takes two (latency 10). The seed stays 32-bit: its
 * parts are truncated after the shifts, and the round's two consecutive
 * multiplications, by 1 | p >> 27 and by 0x6935fa69, are one by their
 * product. 16 lanes with one seed, 8 lanes with their own. */
#define PYOA_DEFINE_PERMUTE_ROUND16(SFX, HT, ST, CVT)                                   \
PYOA_FN HT pyoa_permute_round16##SFX(HT i, ST p, ushort w)                              \
{                                                                                       \
    i ^= CVT(p);        i *= (ushort)0xe170893du;                                       \
    i ^= CVT(p >> 16);                                                                  \
    i ^= (i & w) >> 4;                                                                  \
    i ^= CVT(p >> 8);   i *= (ushort)0x0929eb3fu;                                       \
    i ^= CVT(p >> 23);                                                                  \
    i ^= (i & w) >> 1;  i *= CVT((1u | (p >> 27)) * 0x6935fa69u);                       \
    i ^= (i & w) >> 11; i *= (ushort)0x74dcb303u;                                       \
    i ^= (i & w) >> 2;  i *= (ushort)0x9e501cc3u;                                       \
    i ^= (i & w) >> 2;  i *= (ushort)0xc860a3dfu;                                       \
    i &= w;                                                                             \
    i ^= i >> 5;                                                                        \
    return i;                                                                           \
}
PYOA_DEFINE_PERMUTE_ROUND16(_v16, ushort16, uint, (ushort))
PYOA_DEFINE_PERMUTE_ROUND16(_v8, ushort8, uint8, convert_ushort8)
#endif

#endif /* PYOA_HASHES_H */
