/* pmj02: padded progressive multi-jittered (0,2) sequences (mirrors
 * pyoa/reference/pmj02.py, which holds the mathematics and references).
 * Values are k * 2^-24 with k a 24-bit integer: exact in float, no rounding.
 * Uses hash_pair (pyoa/hashes.h) and derived_seed (baselines.cl). */

/* PYOA_PMJ02_KEY and PYOA_PMJ02_SHIFT_KEY come from pyoa/keys.h, generated from
 * pyoa/reference/pmj02.py, their only definition. */

/* The table layout, pyoa.pmj02_tables.SETS and .POINTS (tests/test_pmj02.py
 * checks that these literals equal them): SETS = 16 because h >> 28 picks
 * the set. */
#define PMJ02_SETS 16u
#define PMJ02_POINTS 65536u

/* Value j of sample i (i < PMJ02_POINTS) of the point set with seed p;
 * table: the (PMJ02_SETS, PMJ02_POINTS, 2) uint array of
 * pyoa.pmj02_tables.tables(), flat. The pair b = j >> 1 reads set h >> 28
 * in its own nested-scrambled order (prefixes map onto aligned blocks, which
 * are nets), digitally shifted (XOR of the 24-bit fraction: elementary
 * intervals map onto elementary intervals); p == 0 reads set 0 unshifted in
 * its own order. */
float sample_pmj02(uint i, uint j, uint p, __global const uint *table)
{
    uint c = j & 1u;
    uint h = derived_seed(p, j >> 1, PYOA_PMJ02_KEY);
    uint shift = derived_seed(h, 1u + c, PYOA_PMJ02_SHIFT_KEY) >> 8;
    uint g = owen_scramble(i, derived_seed(h, 0u, PYOA_PMJ02_SHIFT_KEY)) & (PMJ02_POINTS - 1u);
    uint k = table[((h >> 28) * PMJ02_POINTS + g) * 2u + c];
    return convert_float(k ^ shift) * 0x1.0p-24f;
}
