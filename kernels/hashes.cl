/* Integer hashes of docs/spec.md sections 2 and 3 (mirrors pyoa/reference/hashes.py).
 * All arithmetic is uint with wrap-around. randfloat's float multiply must not
 * fuse with the subtraction in jitter_value once inlined (NVIDIA's compiler
 * did exactly that when this pragma came only later, in floats.cl), so the
 * pragma opens this file and program.source() puts it first in the program. */
#pragma OPENCL FP_CONTRACT OFF

/* STRATUM_KEY, SUBSTRATUM_KEY, JITTER_KEY, PIXEL_KEY, BLOCK_KEY and BLOCK_ORDER_KEY are not
 * defined here: pyoa/_opencl/program.py's defines() passes them as -D build
 * options (uint literals), generated from the constants of the same names in
 * pyoa/reference/hashes.py, their only definition. */
#ifndef STRATUM_KEY
#error "STRATUM_KEY undefined: build with pyoa._opencl.program.defines()"
#endif
#ifndef SUBSTRATUM_KEY
#error "SUBSTRATUM_KEY undefined: build with pyoa._opencl.program.defines()"
#endif
#ifndef JITTER_KEY
#error "JITTER_KEY undefined: build with pyoa._opencl.program.defines()"
#endif
#ifndef PIXEL_KEY
#error "PIXEL_KEY undefined: build with pyoa._opencl.program.defines()"
#endif
#ifndef BLOCK_KEY
#error "BLOCK_KEY undefined: build with pyoa._opencl.program.defines()"
#endif
#ifndef BLOCK_ORDER_KEY
#error "BLOCK_ORDER_KEY undefined: build with pyoa._opencl.program.defines()"
#endif

/* One pass of Kensler's bijection on [0, w] (the body of the cycle walk).
 * Defined once for scalars and once for 8-lane vectors (lanes with their own
 * seeds, vector.cl), as DEFINE_FLOATS in floats.cl. */
#define DEFINE_PERMUTE_ROUND(SFX, UT)                                                   \
UT permute_round##SFX(UT i, UT p, uint w)                                               \
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
DEFINE_PERMUTE_ROUND(, uint)
DEFINE_PERMUTE_ROUND(_v8, uint8)

/* permute_round in 16-bit lanes, for w < 2^16: every step of the round only
 * carries information upward (multiplications, xors, and right shifts of
 * i & w), so the low 16 bits of each intermediate are those of the 32-bit
 * round, and so is the result masked by w. Half the bits per lane: twice the
 * lanes per vector register, and a 16-bit multiply (vpmullw: one micro-op,
 * latency 5 on x86) where the 32-bit one takes two (latency 10). The seed
 * stays 32-bit: its parts (p, p >> 16, ...) are truncated after the shifts,
 * and the round's two consecutive multiplications, by 1 | p >> 27 and by
 * 0x6935fa69, are one by their product. Instances: 16 lanes with one seed
 * (the rows' walks), 8 lanes with their own seeds (the tables), as
 * DEFINE_PERMUTE_ROUND above. */
#define DEFINE_PERMUTE_ROUND16(SFX, HT, ST, CVT)                                        \
HT permute_round16##SFX(HT i, ST p, ushort w)                                           \
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
DEFINE_PERMUTE_ROUND16(_v16, ushort16, uint, (ushort))
DEFINE_PERMUTE_ROUND16(_v8, ushort8, uint8, convert_ushort8)

/* w = the all-ones mask just covering l - 1 (the walk's domain [0, w]). */
uint walk_mask(uint l)
{
    uint w = l - 1u;
    w |= w >> 1; w |= w >> 2; w |= w >> 4; w |= w >> 8; w |= w >> 16;
    return w;
}

/* The cycle walk: the first of round(i), round(round(i)), ... below l. */
uint permute_walk(uint i, uint l, uint p, uint w)
{
    do {
        i = permute_round(i, p, w);
    } while (i >= l);
    return i;
}

/* Kensler's permute with the wrap-safe final shift; 1 <= l <= 2^31. */
uint permute(uint i, uint l, uint p)
{
    if (p == 0u) return i;
    return (permute_walk(i, l, p, walk_mask(l)) + p % l) % l;
}

/* Kensler's randfloat: float in [0, 1); 0.5 for p == 0. Written without an
 * early return (a select at the end) so that PoCL can vectorize callers.
 * Scalar and 8-lane (one seed for all lanes) instances, as above. */
#define DEFINE_RANDFLOAT(SFX, UT, FT, CVT_RTE)                                          \
FT randfloat##SFX(UT i, uint p)                                                         \
{                                                                                       \
    i ^= p;                                                                             \
    i ^= i >> 17;                                                                       \
    i ^= i >> 10;  i *= 0xb36534e5u;                                                    \
    i ^= i >> 12;                                                                       \
    i ^= i >> 21;  i *= 0x93fc4795u;                                                    \
    i ^= 0xdf6e307fu;                                                                   \
    i ^= i >> 17;  i *= 1u | (p >> 18);                                                 \
    FT r = CVT_RTE(i) * as_float(0x2f7ffffeu);                                          \
    return p ? r : (FT)0.5f;                                                            \
}
DEFINE_RANDFLOAT(, uint, float, convert_float_rte)
DEFINE_RANDFLOAT(_v8, uint8, float8, convert_float8_rte)

/* Wellons' lowbias32, the pair hash and the seeds of docs/spec.md sections
 * 3 and 6 built on it. Scalar and 8-lane instances (lanes with their own
 * arguments: vector_tables derives 8 (pixel, dimension) pairs' seeds at
 * once), as above; a lane's condition is written as a comparison, since a
 * vector ?: selects by each lane's top bit, not by its being nonzero.
 * block_order_seed is the seed of block `block`'s sample order (section 6):
 * 0 for block 0 (permute with seed 0 is the identity), else never 0. */
#define DEFINE_SEEDS(SFX, UT)                                                           \
UT mix32##SFX(UT x)                                                                     \
{                                                                                       \
    x ^= x >> 16; x *= 0x7feb352du;                                                     \
    x ^= x >> 15; x *= 0x846ca68bu;                                                     \
    x ^= x >> 16;                                                                       \
    return x;                                                                           \
}                                                                                       \
UT hash_pair##SFX(UT a, UT b, uint key)                                                 \
{                                                                                       \
    UT h = mix32##SFX(b ^ mix32##SFX(a ^ key));                                         \
    return (h != 0u) ? h : (UT)key;                                                     \
}                                                                                       \
UT pixel_seed##SFX(uint seed, UT pixel) { return hash_pair##SFX((UT)seed, pixel, PIXEL_KEY); } \
UT block_seed##SFX(UT p, UT block)                                                      \
{                                                                                       \
    return (block != 0u) ? hash_pair##SFX(p, block, BLOCK_KEY) : p;                     \
}                                                                                       \
UT block_order_seed##SFX(UT P, UT block, uint N)                                        \
{                                                                                       \
    return (block != 0u) ? hash_pair##SFX(P, (UT)N, BLOCK_ORDER_KEY) : (UT)0u;          \
}
DEFINE_SEEDS(, uint)
DEFINE_SEEDS(_v8, uint8)

/* The row of sample i in a block whose order seed is r: two permutations
 * with independent seeds (pyoa.reference.hashes.block_row says why), the
 * identity for r = 0. */
uint block_row(uint i, uint N, uint r) { return permute(permute(i, N, r), N, mix32(r)); }
