/* Entry points over pyoa/pmj02_build.h for tests/test_c_pmj02.py to load
 * with ctypes: the whole table, one set with caller scratch, the constants,
 * and the builder's parts (draw, uniform index, Pharr's strata walk) for
 * comparison with pyoa.reference.pmj02. Built as C99 and as C++14. */
#include <stddef.h>

#include <pyoa/pmj02_build.h>

#if defined(__cplusplus)
#define SHIM extern "C"
#else
#define SHIM
#endif

SHIM pyoa_u32 t_pmj02_table_entries(void) { return pyoa_pmj02_table_entries(); }
SHIM size_t t_pmj02_scratch_bytes(void) { return pyoa_pmj02_scratch_bytes(); }
SHIM int t_pmj02_fill(pyoa_u32 *out) { return pyoa_pmj02_fill(out); }

SHIM int t_pmj02_fill_set(pyoa_u32 set, pyoa_u32 points, pyoa_u32 *out, void *scratch)
{
    return pyoa_pmj02_fill_set(set, points, out, scratch);
}

/* constants: BUILD_SEED, SETS, POINTS_LOG2, POINTS, BITS, then the
 * purposes X_STRATUM, Y_STRATUM, X_LOW, Y_LOW, SWAP */
SHIM void t_pmj02_constants(pyoa_u32 *out)
{
    out[0] = PYOA_PMJ02_BUILD_SEED;
    out[1] = PYOA_PMJ02_SETS;
    out[2] = PYOA_PMJ02_POINTS_LOG2;
    out[3] = PYOA_PMJ02_POINTS;
    out[4] = PYOA_PMJ02_BITS;
    out[5] = PYOA_PMJ02_X_STRATUM;
    out[6] = PYOA_PMJ02_Y_STRATUM;
    out[7] = PYOA_PMJ02_X_LOW;
    out[8] = PYOA_PMJ02_Y_LOW;
    out[9] = PYOA_PMJ02_SWAP;
}

SHIM void t_pmj02_set_seed(size_t n, const pyoa_u32 *s, pyoa_u32 *out)
{
    for (size_t k = 0; k < n; ++k) out[k] = pyoa_pmj02_set_seed(s[k]);
}

SHIM void t_pmj02_draw(size_t n, const pyoa_u32 *seed, const pyoa_u32 *index, const pyoa_u32 *purpose,
                       const pyoa_u32 *attempt, pyoa_u32 *out)
{
    for (size_t k = 0; k < n; ++k) out[k] = pyoa_pmj02_draw(seed[k], index[k], purpose[k], attempt[k]);
}

SHIM void t_pmj02_uniform_index(size_t n, const pyoa_u32 *seed, const pyoa_u32 *index, const pyoa_u32 *purpose,
                                const pyoa_u32 *count, pyoa_u32 *out)
{
    for (size_t k = 0; k < n; ++k) out[k] = pyoa_pmj02_uniform_index(seed[k], index[k], purpose[k], count[k]);
}

/* Every valid stratum of the walk, in order, into out (count words, at most
 * 2^M); returns the count. bits: the occupancy as packed bits (scratch
 * layout), bit (u << M) | i for interval i of shape (u, M - u). */
SHIM pyoa_u32 t_pmj02_strata(pyoa_u32 *bits, pyoa_u32 M, pyoa_u32 q, pyoa_u32 qa, pyoa_u32 qb, pyoa_u32 axis,
                             pyoa_u32 *out)
{
    pyoa_pmj02_occ o;
    pyoa_u32 count, r;
    o.w = bits;
    o.lg = 5u;
    o.base = 0u;
    count = pyoa_pmj02_strata(&o, M, q, qa, qb, axis, 0xffffffffu, out);
    for (r = 0u; r < count; ++r) pyoa_pmj02_strata(&o, M, q, qa, qb, axis, r, out + r);
    return count;
}
