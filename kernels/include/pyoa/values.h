/* pyoa/values.h: the value of every sampler of pyoa's catalogue, chosen by
 * its code (PYOA_SAMPLER_<NAME> of pyoa/keys.h): the orthogonal arrays
 * (pyoa/oa.h) and the comparison and progressive samplers (baselines.h,
 * zsobol.h, pmj02.h, faure.h, zfaure.h). These are what the OpenCL kernels
 * call; a renderer calls pyoa_sampler_value of pyoa/sampler.h, which
 * resolves the arguments below once. */
#ifndef PYOA_VALUES_H
#define PYOA_VALUES_H

#include "baselines.h"
#include "config.h"
#include "faure.h"
#include "keys.h"
#include "oa.h"
#include "pmj02.h"
#include "zfaure.h"
#include "zsobol.h"

/* Value j of sample i of a comparison or progressive sampler `code`:
 * p is the pixel's seed (pyoa_pixel_seed(seed, pixel), section 3.1), pixel
 * and seed the pixel index and user seed (zsobol and zfaure read them), a,
 * b and c the sampler's shape arguments (pyoa/counts.h pyoa_shape_args; the
 * catalogue's shape_args, zero-padded; zfaure's four, (N, b, k, width), as
 * the three words (N, b | k << 16, width) of its launch), J the jitter
 * amount, table its table (halton's primes, sobol's and sobol02's direction
 * numbers, pmj02's point sets; unused otherwise). A code that is not one of these gives
 * NaN. */
PYOA_FN float pyoa_baseline_value(pyoa_u32 code, pyoa_u32 i, pyoa_u32 j, pyoa_u32 p, pyoa_u32 pixel, pyoa_u32 seed,
                                  pyoa_u32 a, pyoa_u32 b, pyoa_u32 c, float J, PYOA_GLOBAL const pyoa_u32 *table)
{
    switch (code) {
    case PYOA_SAMPLER_RANDOM: return pyoa_sample_random(i, j, p);
    case PYOA_SAMPLER_JITTERED2D: return pyoa_sample_jittered2d(i, j, a, b, p, J);
    case PYOA_SAMPLER_CMJ2D: return pyoa_sample_cmj2d(i, j, a, b, p, J);
    case PYOA_SAMPLER_SOBOL02: return pyoa_sample_sobol02(i, j, a, p, table);
    case PYOA_SAMPLER_HALTON: return pyoa_sample_halton(i, j, p, table);
    case PYOA_SAMPLER_SOBOL: return pyoa_sample_sobol(i, j, p, table);
    case PYOA_SAMPLER_ZSOBOL: return pyoa_sample_zsobol(i, j, a, b, c, pixel, seed);
    case PYOA_SAMPLER_PMJ02: return pyoa_sample_pmj02(i, j, p, table);
    case PYOA_SAMPLER_FAURE: return pyoa_sample_faure(i, j, a, b, p);
    case PYOA_SAMPLER_ZFAURE: return pyoa_sample_zfaure(i, j, a, b & 0xffffu, b >> 16, c, pixel, seed);
    default: return PYOA_AS_F32(0x7fc00000u); /* not one of these: NaN */
    }
}

#endif /* PYOA_VALUES_H */
