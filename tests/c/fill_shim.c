/* Entry points over pyoa/fill.h (the bulk path of the renderer API) for
 * tests/test_c_fill.py to load with ctypes: make a sampler from the Python
 * API's options, fill and bind its table, and evaluate one request
 * (samples sample0.., dimensions dim0..) of two pixels three ways: by
 * pyoa_sampler_fill, by pyoa_fill_pixel on the plan that fill left (the
 * other pixel, then the first again) and by pyoa_sampler_value per value.
 * Built as C99, C++14, with -O3 -march=native -ffp-contract=fast, and with
 * tiny PYOA_FILL_* bounds (every fallback of fill.h). */
#include <stdlib.h>
#include <string.h>

#include <pyoa/fill.h>

#include "make_sampler.h"

#if defined(__cplusplus)
#define SHIM extern "C"
#else
#define SHIM
#endif

/* Bytes after the scratch that must stay untouched, and their pattern. */
#define GUARD 256u
#define GUARD_BYTE 0xa5

/* pyoa_sampler_make's return value (or -1: out of memory). On success, for
 * n = n_samples * n_dims values per pixel:
 *   out[0 .. n)    pyoa_sampler_fill(pixel0)
 *   out[n .. 2n)   pyoa_fill_pixel(pixel1) right after it (the same plan)
 *   out[2n .. 3n)  pyoa_fill_pixel(pixel0) again
 *   want[0 .. 2n)  pyoa_sampler_value at pixel0, then pixel1
 * and info = {scratch bytes, tabled, stab, mtab, cell modes seen (bit m:
 * PYOA_FILL_CELLS_* m), guard intact, spp, s, block_dims, M}. The scratch
 * starts full of garbage (the fill must not read it). offset "" means NULL. */
SHIM int t_fill(const char *name, pyoa_u32 spp, pyoa_u32 dims, pyoa_u32 seed, const char *offset, float jitter,
                pyoa_u32 strength, pyoa_u32 base, pyoa_u32 width, pyoa_u32 height, pyoa_u32 pixel0,
                pyoa_u32 pixel1, pyoa_u32 sample0, pyoa_u32 n_samples, pyoa_u32 dim0, pyoa_u32 n_dims, float *out,
                float *want, pyoa_u32 *info, char *message, size_t message_size)
{
    pyoa_sampler s;
    unsigned char *scratch;
    size_t n = (size_t)n_samples * n_dims, k;
    pyoa_u32 i, d, modes = 0u, intact = 1u;
    int rc = make_sampler(&s, name, spp, dims, seed, offset, jitter, strength, base, width, height, message,
                          message_size);
    if (rc != PYOA_OK) return rc;
    info[0] = (pyoa_u32)pyoa_fill_scratch_bytes(&s, n_dims);
    scratch = (unsigned char *)malloc(info[0] + GUARD);
    if (!scratch) return -1;
    for (k = 0; k < info[0]; ++k) scratch[k] = (unsigned char)(k * 37u + 11u); /* garbage */
    memset(scratch + info[0], GUARD_BYTE, GUARD);

    pyoa_sampler_fill(&s, pixel0, sample0, n_samples, dim0, n_dims, out, scratch);
    {
        const pyoa_fill_plan *plan = (const pyoa_fill_plan *)(void *)scratch;
        info[1] = plan->tabled;
        info[2] = plan->tabled ? plan->stab : 0u;
        info[3] = plan->tabled ? plan->mtab : 0u;
        for (d = 0u; plan->tabled && d < n_dims; ++d) modes |= 1u << pyoa_fill_dim(scratch, d)[2];
    }
    pyoa_fill_pixel(scratch, pixel1, out + n);
    pyoa_fill_pixel(scratch, pixel0, out + 2 * n);
    for (k = 0; k < GUARD; ++k) intact &= (pyoa_u32)(scratch[info[0] + k] == GUARD_BYTE);
    for (i = 0u; i < n_samples; ++i)
        for (d = 0u; d < n_dims; ++d) {
            want[(size_t)i * n_dims + d] = pyoa_sampler_value(&s, pixel0, sample0 + i, dim0 + d);
            want[n + (size_t)i * n_dims + d] = pyoa_sampler_value(&s, pixel1, sample0 + i, dim0 + d);
        }
    info[4] = modes;
    info[5] = intact;
    info[6] = s.spp;
    info[7] = s.s;
    info[8] = s.block_dims;
    info[9] = s.M;
    free(scratch);
    return rc;
}

/* floats.h's clamp as it was written before it made its two comparisons
 * unconditionally (for fill.h's loops to vectorize), and the values built
 * on it: t_floats counts the inputs, of `count`, where today's
 * pyoa_sample_value and pyoa_centered_value differ from these. */
static float old_clamp(float x, pyoa_u32 c, pyoa_u32 n)
{
    float nf = PYOA_U32_TO_F32(n);
    float lo = pyoa_cell_floor(c, nf);
    float hi = PYOA_AS_F32(PYOA_AS_U32(pyoa_cell_floor(c + 1u, nf)) - 1u);
    return x < lo ? lo : (x > hi ? hi : x);
}

SHIM pyoa_u32 t_floats(pyoa_u32 seed, pyoa_u32 count)
{
    pyoa_u32 k, bad = 0u;
    for (k = 0u; k < count; ++k) {
        pyoa_u32 h1 = pyoa_hash_pair(seed, k, 1u), h2 = pyoa_hash_pair(seed, k, 2u), h3 = pyoa_hash_pair(seed, k, 3u);
        pyoa_u32 s = 1u + (h1 & 4095u), M = 1u + ((h1 >> 12) & 4095u);
        pyoa_u32 stratum = h2 % s, sub = (h2 >> 8) % M, odd = M & 1u;
        float jit, mid = PYOA_MUL(0.5f, PYOA_U32_TO_F32(M - 1u));
        switch (h3 & 3u) {
        case 0u: jit = 0.0f; break;
        case 1u: jit = 0.99999994f; break;
        case 2u: jit = PYOA_AS_F32(0x3f000000u + ((h3 >> 2) & 63u) - 32u); break;
        default: jit = pyoa_randfloat(h3, seed | 1u); break;
        }
        if (s * M > 16777216u) continue;
        bad += (pyoa_u32)(PYOA_AS_U32(pyoa_sample_value(stratum, sub, jit, M, s)) !=
                          PYOA_AS_U32(old_clamp(pyoa_formula_value(stratum, PYOA_U32_TO_F32(sub), jit, M, s),
                                                stratum * M + sub, M * s)));
        bad += (pyoa_u32)(PYOA_AS_U32(pyoa_centered_value(stratum, jit, M, s)) !=
                          PYOA_AS_U32(old_clamp(pyoa_formula_value(stratum, mid, jit, M, s),
                                                odd ? stratum * M + (M - 1u) / 2u : stratum, odd ? M * s : s)));
    }
    return bad;
}

/* How many inputs, of `count`, the clamp changes: pyoa_sample_value differs
 * from the unclamped formula (spec 7.3), so that t_floats is known to reach
 * the clamp. */
SHIM pyoa_u32 t_clamped(pyoa_u32 seed, pyoa_u32 count)
{
    pyoa_u32 k, n = 0u;
    for (k = 0u; k < count; ++k) {
        pyoa_u32 h1 = pyoa_hash_pair(seed, k, 1u), h2 = pyoa_hash_pair(seed, k, 2u);
        pyoa_u32 s = 1u + (h1 & 4095u), M = 1u + ((h1 >> 12) & 4095u), stratum = h2 % s, sub = (h2 >> 8) % M;
        if (s * M > 16777216u) continue;
        n += (pyoa_u32)(PYOA_AS_U32(pyoa_sample_value(stratum, sub, 0.99999994f, M, s)) !=
                        PYOA_AS_U32(pyoa_formula_value(stratum, PYOA_U32_TO_F32(sub), 0.99999994f, M, s)));
    }
    return n;
}
