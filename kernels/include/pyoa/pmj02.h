/* pyoa/pmj02.h: pmj02, padded progressive multi-jittered (0,2) sequences
 * (docs/spec.md section 5.8; pyoa/reference/pmj02.py holds the mathematics
 * and references). Values are k * 2^-24 with k a 24-bit integer: exact in
 * float, no rounding. The table is pyoa.tables.pmj02.tables(), built in C by
 * pyoa/pmj02_build.h. */
#ifndef PYOA_PMJ02_H
#define PYOA_PMJ02_H

#include "baselines.h"
#include "config.h"
#include "hashes.h"
#include "keys.h"

/* The table's layout, pyoa.tables.pmj02.SETS and .POINTS (tests check that
 * these equal them): 16 sets because h >> 28 picks the set. */
#define PYOA_PMJ02_SETS 16u
#define PYOA_PMJ02_POINTS 65536u

/* Value j of sample i (i < PYOA_PMJ02_POINTS) of the point set with seed p;
 * table: the (SETS, POINTS, 2) uint32 array, flat. The pair b = j >> 1
 * reads set h >> 28 in its own nested-scrambled order (prefixes map onto
 * aligned blocks, which are nets), digitally shifted (XOR of the 24-bit
 * fraction: elementary intervals map onto elementary intervals); p == 0
 * reads set 0 unshifted in its own order. */
PYOA_FN float pyoa_sample_pmj02(pyoa_u32 i, pyoa_u32 j, pyoa_u32 p, PYOA_GLOBAL const pyoa_u32 *table)
{
    pyoa_u32 c = j & 1u;
    pyoa_u32 h = pyoa_derived_seed(p, j >> 1, PYOA_PMJ02_KEY);
    pyoa_u32 shift = pyoa_derived_seed(h, 1u + c, PYOA_PMJ02_SHIFT_KEY) >> 8;
    pyoa_u32 g = pyoa_owen_scramble(i, pyoa_derived_seed(h, 0u, PYOA_PMJ02_SHIFT_KEY)) & (PYOA_PMJ02_POINTS - 1u);
    pyoa_u32 k = table[((h >> 28) * PYOA_PMJ02_POINTS + g) * 2u + c];
    return PYOA_MUL(PYOA_U32_TO_F32(k ^ shift), PYOA_2POW_M24);
}

#endif /* PYOA_PMJ02_H */
