/* The vector path: the orthogonal-array samplers' kernels specialized per
 * request shape, built by pyoa/_opencl/vector.py after pyoa/hashes.h and
 * pyoa/floats.h with these -D constants (docs/performance.md, "The vector
 * path"):
 *
 *   VS, VM          s and M = N / s
 *   VWS, VWM        walk masks of s and M (walk_mask in pyoa/hashes.h)
 *   VND, VNK        dimensions and sample positions of the request
 *   VNKP            VNK rounded up to whole blocks of 8
 *   VDMAX           dimensions per block (docs/spec.md section 6)
 *   VN, VWN         rows N = s M of the array and the walk mask of N
 *   VLATER          1: some dimension lies past block 0 (its own rows); then also
 *   VNSLOT          the distinct blocks of the request's dimensions (slots)
 *   VLATER0         the first slot past block 0 (1 when block 0 is among them, else 0)
 *   VSLOT_FIRST, VSLOT_OF, VCOL_OF   __constant tables: the first dimension d of
 *                   each slot, and each d's slot and column (generated text)
 *   VRW             words of a row's record (the cells of every column of a row, packed)
 *   VCB, VCPW       bits of one packed cell and cells per record word
 *   VAB, VAMASK, VUMASK   bits of A_ij in a cell, then the masks of A_ij and of u
 *   VGROUPED        1: more than 16 dimensions, computed and stored in groups of 8
 *   VOFFSET         the offset's code (PYOA_OFFSET_* of pyoa/keys.h)
 *   VS_PACKED       1: the stratum permutation is tabled as 4-bit fields
 *                   (s <= 16); 0: each value walks it (VS_ROUNDS rounds)
 *   VSUB            0 none ('centered'), 1 tabled as 4-bit fields ('cmj',
 *                   M <= 16), 2 walked per value (VSUB_ROUNDS rounds)
 *   VJKEY_BOSE      1: the 'j' seed factor is Bose's u * s + A_ij + 1, else i + 1
 *   VSTORE_BLOCK, VSTORE_TAIL   the stores of one block (generated code)
 *   VSTORE_GROUPS   with VGROUPED, the values and stores of every whole group of 8 (generated code)
 *
 * Why this shape (each measured on PoCL, docs/performance.md): the values
 * kernel computes 8 sample positions of one pixel per work-item as explicit
 * 8-lane vectors, for every dimension, and stores them as whole rows:
 * across work-items, PoCL's own vectorization put the 8 lanes along the
 * samples, and the store, with a stride of VND floats, then cost 40 % of the
 * kernel; a (pixel, dimension)'s two permutations fit in 4-bit fields of
 * two 32-bit words, read with a variable shift instead of two gathers; the
 * walk of Kensler's permute is bounded (below), so no loop is left. */

/* Stores V[d] (lane r: sample position 8 b + r of dimension d) as output
 * rows of pixel pl: out + out0 + (pl * VNK + 8 b + r) * VND + d. The last
 * block of a pixel whose VNK is not a multiple of 8 stores only its valid
 * rows (VSTORE_TAIL, one value at a time); the condition is constant-folded
 * away when there is no tail. */
#define STORE_ROWS(V, b, pl)                                                            \
    do {                                                                                \
        __global float *o = out + out0 + ((pl) * VNK + 8u * (b)) * VND;                 \
        if ((VNK % 8u) != 0u && (b) + 1u == VNKP / 8u) { VSTORE_TAIL }                  \
        else { VSTORE_BLOCK }                                                           \
    } while (0)

/* A bounded walk: the cycle of permute_round through i < l reaches a value
 * below l after at most (w + 1 - l) values at or above l, so w + 2 - l
 * rounds always end it (and the host only builds this path when that is at
 * most MAX_ROUNDS of pyoa/_opencl/vector.py). Lanes that are done keep
 * their value. Then the final shift of permute (pyoa/hashes.h). Lanes with p == 0
 * are the identity. */
static inline __attribute__((always_inline)) uint8 permute_bounded_v8(uint8 i, uint8 p, uint l, uint w, uint rounds)
{
    uint8 x = pyoa_permute_round_v8(i, p, w);
    #pragma unroll
    for (uint r = 1u; r < rounds; ++r)  /* rounds is a build constant: unrolled */
        x = (x < l) ? x : pyoa_permute_round_v8(x, p, w);
    x += p % l;
    x = (x >= l) ? x - l : x;
    return (p != 0u) ? x : i;
}

#ifndef VBASELINE  /* the orthogonal arrays' kernels */

/* Lanes r of t[idx.sr]: a gather of 8 table entries. */
static inline __attribute__((always_inline)) uint8 gather_v8(__global const uint *t, uint8 idx)
{
    return (uint8)(t[idx.s0], t[idx.s1], t[idx.s2], t[idx.s3], t[idx.s4], t[idx.s5], t[idx.s6], t[idx.s7]);
}

/* Entries a (< 16) of permutations stored as 4-bit fields: 0..7 in lo, 8..15 in hi. */
uint8 field4_v8(uint8 lo, uint8 hi, uint8 a) { return (((a < 8u) ? lo : hi) >> ((a & 7u) * 4u)) & 15u; }

/* The permutations of [0, l) with seeds p (l <= w + 1 <= 16), one per lane,
 * as 4-bit fields: permute_round of every x in [0, w] once (in 16-bit
 * lanes, permute_round16), then each
 * entry's bounded walk through that table (at most w + 1 - l steps, see
 * permute_bounded_v8), then the final shift. */
static inline __attribute__((always_inline)) void permutation_fields_v8(uint l, uint w, uint8 p, uint8 *lo_out, uint8 *hi_out)
{
    uint8 rlo = 0u, rhi = 0u;
    #pragma unroll
    for (uint x = 0u; x <= w; ++x) {  /* w and l are build constants: every loop unrolls */
        uint8 r = convert_uint8(pyoa_permute_round16_v8((ushort8)(ushort)x, p, (ushort)w)) << (4u * (x & 7u));
        if (x < 8u) rlo |= r; else rhi |= r;
    }
    uint8 sh = p % l, lo = 0u, hi = 0u;
    #pragma unroll
    for (uint i = 0u; i < l; ++i) {
        uint8 y = (((i < 8u) ? rlo : rhi) >> (4u * (i & 7u))) & 15u;
        /* a walk continues from y in [l, w] only: all in one word of fields
         * (w <= 7: rlo; else w = 15 and l > 8: rhi) */
        uint8 rout = (l > 8u) ? rhi : rlo;
        #pragma unroll
        for (uint st = 0u; st + l < w + 1u; ++st)
            y = (y < l) ? y : (rout >> ((y & 7u) * 4u)) & 15u;
        y += sh;
        y = (y >= l) ? y - l : y;
        y = ((p != 0u) ? y : (uint8)i) << (4u * (i & 7u));
        if (i < 8u) lo |= y; else hi |= y;
    }
    *lo_out = lo;
    *hi_out = hi;
}

/* Per (pixel, dimension) pd of the launch, 8 words at pk[8 pd]: [0, 1] the
 * stratum permutation as fields (VS_PACKED) or [0] its seed; [2, 3] the
 * sub-stratum permutation as fields (VSUB == 1) or [2] its seed; [4] the
 * jitter seed; [5] the seed of the block's order of the rows (0 in block 0,
 * docs/spec.md section 6). The keys come from the pixel and dimension
 * numbers here (docs/spec.md sections 3 and 6), not from the host. Each work-item does 8
 * consecutive pd as the lanes of 8-lane vectors (3.3x PoCL's own
 * vectorization of one pd per work-item); the host pads `pixels` and `pk`
 * so that the last work-item's extra lanes read and write in bounds. */
__kernel void vector_tables(__global uint *restrict pk,
                            __global const uint *restrict pixels,
                            __global const uint *restrict dims,
                            const uint seed)
{
    uint g = (uint)get_global_id(0);
    uint8 pd = 8u * g + (uint8)(0u, 1u, 2u, 3u, 4u, 5u, 6u, 7u), pix = pd / VND;
    uint8 j = gather_v8(dims, pd - pix * VND), block = j / VDMAX;
    uint8 P = pyoa_block_seed_v8(pyoa_pixel_seed_v8(seed, gather_v8(pixels, pix)), block);
    uint8 q = P * (j - block * VDMAX + 1u), os = pyoa_block_order_seed_v8(P, block, VN);
    uint8 w0 = q * PYOA_STRATUM_KEY, w1 = 0u, w2 = q * PYOA_SUBSTRATUM_KEY, w3 = 0u, w4 = q * PYOA_JITTER_KEY;
#if VS_PACKED
    permutation_fields_v8(VS, VWS, q * PYOA_STRATUM_KEY, &w0, &w1);
#endif
#if VSUB == 1
    permutation_fields_v8(VM, VWM, q * PYOA_SUBSTRATUM_KEY, &w2, &w3);
#endif
    __global uint *o = pk + 64u * g;
    #pragma unroll
    for (uint r = 0u; r < 8u; ++r) {
        o[8u * r + 0u] = w0[r]; o[8u * r + 1u] = w1[r]; o[8u * r + 2u] = w2[r];
        o[8u * r + 3u] = w3[r]; o[8u * r + 4u] = w4[r]; o[8u * r + 5u] = os[r];
    }
}

/* The value of dimension d (index into the request's dims) at sample
 * positions [8 b, 8 b + 8) of pixel pl: lanes r of the result. i holds the
 * sample indices. cell_a and cell_u are the cells of docs/spec.md section 5
 * at the sample indices, laid out [d][k] with rows of VNKP
 * (pyoa.host_tables.cells, padded).
 *
 * A request with a dimension past block 0 (VLATER) reads each block's copy at
 * that block's own rows (docs/spec.md section 6), which depend on (pixel,
 * block, sample) only: vector_rows computes them beforehand, and
 * vector_values loads them once per work-item and block (slot), before any
 * value, with the records of those rows (rows, rec: see locate_slots). A
 * later dimension then takes its cell from its column's field of its block's
 * record, two shifts and masks, and a block-0 dimension loads it from
 * cell_a and cell_u as without VLATER (a gather of block 0's records cost
 * the 36-dimension request about 3 % of its values kernel); the code that
 * computes values is the same straight line for every dimension. (Before, a later dimension walked
 * its block's rows inside this kernel, once per block and 8 samples, and
 * gathered its own two cells per value: 36 dimensions ran at 0.57-0.62x the
 * values/s of 12, docs/performance.md.) */
static inline __attribute__((always_inline)) float8 value_v8(
    uint d, uint b, uint pl, uint8 i, float J,
    __global const uint *restrict pk, __global const uint *restrict cell_a, __global const uint *restrict cell_u,
    const uint8 *rows, const uint8 *rec)
{
    __global const uint *w = pk + 8u * (pl * VND + d);
    uint8 row = i;
    uint8 aij = vload8(b, cell_a + d * VNKP);
#if VSUB != 0
    uint8 u = vload8(b, cell_u + d * VNKP);
#endif
#if VLATER
    uint slot = VSLOT_OF[d], col = VCOL_OF[d];  /* constants: d is after unrolling */
    if (slot >= VLATER0) {  /* past block 0; block 0's cells are the request's, as without VLATER */
        row = rows[slot];
        uint8 field = rec[slot * VRW + col / VCPW] >> ((col % VCPW) * VCB);
        aij = field & VAMASK;
#if VSUB != 0
        u = (field >> VAB) & VUMASK;
#endif
    }
#endif
#if VS_PACKED
    uint8 stratum = field4_v8((uint8)w[0], (uint8)w[1], aij);
#else
    uint8 stratum = permute_bounded_v8(aij, (uint8)w[0], VS, VWS, VS_ROUNDS);
#endif
    float8 jit = pyoa_jitter_value_v8(pyoa_randfloat_v8(row, w[4]), J);
#if VSUB == 0
    return pyoa_centered_value_v8(stratum, jit, VM, VS);
#else
#if VSUB == 1
    uint8 sub = field4_v8((uint8)w[2], (uint8)w[3], u);
#else
#if VOFFSET == PYOA_OFFSET_J
#if VJKEY_BOSE
    uint8 seed = (u * VS + aij + 1u) * w[2];
#else
    uint8 seed = (row + 1u) * w[2];
#endif
#elif VOFFSET == PYOA_OFFSET_MJ
    uint8 seed = (aij + 1u) * w[2];
#else
    uint8 seed = (uint8)w[2];
#endif
    uint8 sub = permute_bounded_v8(u, seed, VM, VWM, VSUB_ROUNDS);
#endif
    return pyoa_sample_value_v8(stratum, sub, jit, VM, VS);
#endif
}

#if VLATER
/* vector_rows walks the rows of the VNKP sample positions in chunks of this
 * many 16-lane vectors. */
#define WALK_VECTORS 8u

/* Kensler's permute on [0, VN) with seed p != 0 of WALK_VECTORS vectors x at
 * once, the final shift included, in 16-bit lanes (permute_round16: the
 * host builds this kernel only for N <= 2^16).
 *
 * Where the walk's domain [0, VWN] has at most 16 values at or above VN
 * (VNOUT = VWN + 1 - VN <= 16: N = 121, 125, 25, 49, ...), a walk is one
 * round and a lookup: the round of x < VN lands either below VN (the walk
 * ends) or on one of the VNOUT out values y, and from y the walk goes on
 * exactly as a walk started at y would, to a fixed W(y) < VN. So the VNOUT
 * results W are walked first, once per seed, and each x then takes its
 * round, then W of it where the round left [0, VN) (a select per out value:
 * PoCL scalarizes shuffle). The same bits as permute_walk, at one round per
 * sample instead of about two: a loop until every lane is in ran a second
 * round almost always (each lane leaves with probability VNOUT / (VWN + 1),
 * 0.05 for N = 121, so one of 64 lanes did 95 % of the time).
 *
 * Otherwise one cycle walk for all vectors (a loop until every lane of every
 * vector is below VN): a walk is a chain of dependent multiplications
 * repeated until its slowest lane lands; independent chains in one loop
 * overlap and share that wait. */
#define VNOUT (VWN + 1u - VN)
static inline __attribute__((always_inline)) void permute_walks(ushort16 *x, uint p)
{
    const ushort n = (ushort)VN, w = (ushort)VWN;
#if VNOUT <= 16u
    /* W(y) of y = VN + lane (lanes past VWN repeat VWN and are never read).
     * A y on a cycle of out values only is never reached from below VN (the
     * walk from x < VN stays on x's own cycle) and its walk would not end:
     * from any other y, at most VNOUT rounds lead below VN. */
    ushort16 wo = min((ushort16)n + (ushort16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15), (ushort16)w);
    wo = pyoa_permute_round16_v16(wo, p, w);
    for (uint r = 1u; r < VNOUT && any(wo >= n); ++r)
        wo = (wo < n) ? wo : pyoa_permute_round16_v16(wo, p, w);
    #pragma unroll
    for (uint c = 0u; c < WALK_VECTORS; ++c) {
        ushort16 y = pyoa_permute_round16_v16(x[c], p, w), z = y;
        #pragma unroll
        for (uint o = 0u; o < VNOUT; ++o)
            z = (y == (ushort)(VN + o)) ? (ushort16)wo[o] : z;
        x[c] = z;
    }
#else
    #pragma unroll
    for (uint c = 0u; c < WALK_VECTORS; ++c)
        x[c] = pyoa_permute_round16_v16(x[c], p, w);
    for (;;) {
        short16 out = 0;
        #pragma unroll
        for (uint c = 0u; c < WALK_VECTORS; ++c)
            out |= x[c] >= n;
        if (!any(out))
            break;
        #pragma unroll
        for (uint c = 0u; c < WALK_VECTORS; ++c)
            x[c] = (x[c] < n) ? x[c] : pyoa_permute_round16_v16(x[c], p, w);
    }
#endif
    /* (x + p % N) mod N without leaving 16 bits: x + sh reaches 2 N - 2,
     * past 65535 for N > 32768, so the lanes at or above N - sh subtract
     * N - sh instead of adding sh */
    const ushort sh = (ushort)(p % VN), back = (ushort)(VN - p % VN);
    #pragma unroll
    for (uint c = 0u; c < WALK_VECTORS; ++c)
        x[c] = (x[c] >= back) ? x[c] - back : x[c] + sh;
}

/* The rows of a later block (docs/spec.md section 6: block_row, two
 * permutations with the block's order seed) at every sample position of the
 * request, per pixel: rowtab[((pl (VNSLOT - VLATER0) + k) VNKP + s] for later
 * slot k (axis 0) and pixel pl (axis 1). They depend on (pixel, block,
 * sample) only, so they are computed here once, not inside vector_values
 * (there, a walk per block and 8 samples ran one chain of rounds at a time:
 * about a fifth of a 36-dimension request's time, docs/performance.md).
 * WALK_VECTORS vectors of 16 at a time (permute_walks). */
__kernel void vector_rows(__global uint *restrict rowtab,
                          __global const uint *restrict pk,
                          __global const uint *restrict isamp)
{
    uint k = (uint)get_global_id(0), pl = (uint)get_global_id(1);
    uint order = pk[8u * (pl * VND + VSLOT_FIRST[VLATER0 + k]) + 5u];  /* never 0 past block 0 */
    __global uint *o = rowtab + (pl * (VNSLOT - VLATER0) + k) * VNKP;
    #define VNV16 ((VNKP + 15u) / 16u)  /* 16-lane vectors of sample positions */
    for (uint c0 = 0u; c0 < VNV16; c0 += WALK_VECTORS) {
        ushort16 x[WALK_VECTORS];
        #pragma unroll
        for (uint c = 0u; c < WALK_VECTORS; ++c) {  /* past the last vector: repeat it (not stored) */
            uint v = min(c0 + c, VNV16 - 1u);
            x[c] = convert_ushort16((uint16)(vload8(min(2u * v, VNKP / 8u - 1u), isamp),
                                             vload8(min(2u * v + 1u, VNKP / 8u - 1u), isamp)));
        }
        permute_walks(x, order);
        permute_walks(x, pyoa_mix32(order));
        #pragma unroll
        for (uint c = 0u; c < WALK_VECTORS; ++c) {
            uint16 r = convert_uint16(x[c]);
            if (2u * (c0 + c) < VNKP / 8u)
                vstore8(r.lo, 2u * (c0 + c), o);
            if (2u * (c0 + c) + 1u < VNKP / 8u)
                vstore8(r.hi, 2u * (c0 + c) + 1u, o);
        }
    }
}

/* The rows of samples i (8 lanes) in every later block of the request (slot
 * k >= VLATER0: rows[k], from vector_rows; block 0's rows are i, and its
 * cells the request's cell_a and cell_u) and their records (rec[k VRW + word]: pyoa._opencl.vector.row_records, the cells of
 * every column of a row, packed), for pixel pl. */
static inline __attribute__((always_inline)) void locate_slots(
    uint b, uint pl, uint8 i, __global const uint *restrict rowtab, __global const uint *restrict records,
    uint8 *rows, uint8 *rec)
{
    #pragma unroll
    for (uint k = 0u; k < VNSLOT; ++k) {
        if (k >= VLATER0) {  /* block 0 (slot 0 where VLATER0) reads the request's cells instead */
            uint8 r = vload8(b, rowtab + (pl * (VNSLOT - VLATER0) + k - VLATER0) * VNKP);
            rows[k] = r;
            #pragma unroll
            for (uint q = 0u; q < VRW; ++q)
                rec[k * VRW + q] = gather_v8(records + q, r * VRW);
        }
    }
}
#define SLOT_STATE uint8 slot_rows[VNSLOT], slot_rec[VNSLOT * VRW]; \
    locate_slots(b, pl, i, rowtab, records, slot_rows, slot_rec)
#else
#define SLOT_STATE const uint8 *slot_rows = 0, *slot_rec = 0
#endif

#define VALUE_V8(d) value_v8((d), b, pl, i, J, pk, cell_a, cell_u, slot_rows, slot_rec)

#if VGROUPED
/* n (<= 8) dimensions from d0 of the 8 rows at o (row stride VND), `rows`
 * of them valid: each row's n values are contiguous in the output, so a row
 * of a full group is one vstore8 of a transposed lane (constant indices
 * after unrolling: shuffles). */
static inline __attribute__((always_inline)) void store_group(__global float *o, float8 *V, uint n, uint rows)
{
    #pragma unroll
    for (uint r = 0u; r < 8u; ++r) {
        if (r < rows) {
            if (n == 8u) {
                vstore8((float8)(((float *)&V[0])[r], ((float *)&V[1])[r], ((float *)&V[2])[r], ((float *)&V[3])[r],
                                 ((float *)&V[4])[r], ((float *)&V[5])[r], ((float *)&V[6])[r], ((float *)&V[7])[r]),
                        0, o + r * VND);
            } else {
                #pragma unroll
                for (uint e = 0u; e < 8u; ++e)
                    if (e < n) o[r * VND + e] = ((float *)&V[e])[r];
            }
        }
    }
}
#endif

/* Values of sample positions [8 b, 8 b + 8) of pixel pl (axis 0: b, axis 1:
 * pl), every dimension, written at out + out0 + (pl * VNK + 8 b) * VND (see
 * value_v8 for the arguments). Up to 16 dimensions (VGROUPED 0) the kernel
 * holds one vector per dimension and stores whole rows (STORE_ROWS); more
 * (VGROUPED 1) go in groups of 8 in a loop that is not unrolled, each
 * stored as 8 row segments, so that no more than 8 vectors are live and the
 * program stays the size of an 8-dimension one (a 46-dimension request,
 * unrolled, took PoCL 9 s to compile and spilled). */
__kernel void vector_values(__global float *restrict out,
                            const uint out0,
                            __global const uint *restrict pk,
                            __global const uint *restrict cell_a,
                            __global const uint *restrict cell_u,
                            __global const uint *restrict isamp,
                            __global const uint *restrict rowtab,
                            __global const uint *restrict records,
                            const float J)
{
    uint b = (uint)get_global_id(0), pl = (uint)get_global_id(1);
    uint8 i = vload8(b, isamp);
    SLOT_STATE;
#if VGROUPED
    __global float *o = out + out0 + (pl * VNK + 8u * b) * VND;
    uint rows = ((VNK % 8u) != 0u && b + 1u == VNKP / 8u) ? VNK % 8u : 8u;
    float8 V[8];
    VSTORE_GROUPS  /* each whole group of 8: its 8 values, then store_group (generated, every d a constant) */
#if VND % 8u
    #pragma unroll
    for (uint e = 0u; e < VND % 8u; ++e)
        V[e] = VALUE_V8(VND - VND % 8u + e);
    store_group(o + (VND - VND % 8u), V, VND % 8u, rows);
#endif
#else
    float8 V[VND];
    #pragma unroll
    for (uint d = 0u; d < VND; ++d)  /* VND is a build constant: unrolled */
        V[d] = VALUE_V8(d);
    STORE_ROWS(V, b, pl);
#endif
}

#endif  /* VBASELINE */

#ifdef VBASELINE
/* The padded 2D comparison samplers (pyoa/baselines.h), VBASELINE 1 =
 * jittered2d (grid VBA x VBA; VBB is the request's dims, for the lone last
 * dimension), 2 = cmj2d (grid VBA x VBB). Each permute of pyoa/baselines.h is a
 * bounded walk here (VBN_ROUNDS for the sample order on [0, VBN), VBA_ROUNDS
 * and VBB_ROUNDS for the sub-strata); the rest as in vector_values. */
__kernel void vector_baseline(__global float *restrict out,
                              const uint out0,
                              __global const uint *restrict pixels,
                              __global const uint *restrict dims,
                              __global const uint *restrict isamp,
                              const uint seed,
                              const float J)
{
    uint b = (uint)get_global_id(0), pl = (uint)get_global_id(1);
    uint8 i = vload8(b, isamp);
    uint p = pyoa_pixel_seed(seed, pixels[pl]);
    float8 V[VND];
    #pragma unroll
    for (uint d = 0u; d < VND; ++d) {
        uint j = dims[d];
        uint q = pyoa_derived_seed(p, j >> 1, PYOA_PAD_KEY);
        uint8 k = permute_bounded_v8(i, (uint8)(q * PYOA_SHUFFLE_KEY), VBN, pyoa_walk_mask(VBN), VBN_ROUNDS);
        bool even = (j & 1u) == 0u;
#if VBASELINE == 1
        float8 jit = pyoa_jitter_value_v8(pyoa_randfloat_v8(k, q * (even ? PYOA_JITX_KEY : PYOA_JITY_KEY)), J);
        if (even && j + 1u == VBB)  /* a lone last dimension */
            V[d] = pyoa_sample_value_v8(k, (uint8)0u, jit, 1u, VBN);
        else
            V[d] = pyoa_sample_value_v8(even ? k % VBA : k / VBA, (uint8)0u, jit, 1u, VBA);
#else
        if (even) {
            uint8 sy = permute_bounded_v8(k / VBA, (uint8)(q * PYOA_SUBY_KEY), VBB, pyoa_walk_mask(VBB), VBB_ROUNDS);
            V[d] = pyoa_sample_value_v8(k % VBA, sy, pyoa_jitter_value_v8(pyoa_randfloat_v8(k, q * PYOA_JITX_KEY), J), VBB, VBA);
        } else {
            uint8 sx = permute_bounded_v8(k % VBA, (uint8)(q * PYOA_SUBX_KEY), VBA, pyoa_walk_mask(VBA), VBA_ROUNDS);
            V[d] = pyoa_sample_value_v8(k / VBA, sx, pyoa_jitter_value_v8(pyoa_randfloat_v8(k, q * PYOA_JITY_KEY), J), VBA, VBB);
        }
#endif
    }
    STORE_ROWS(V, b, pl);
}
#endif  /* VBASELINE */
