/* Entry points over pyoa/sampler.h (the renderer API) for
 * tests/test_c_sampler.py to load with ctypes: make a sampler from the
 * Python API's options, fill and bind its table, and evaluate it at n
 * (pixel, sample, dimension) triples. Built as C99 and as C++14. */
#include <pyoa/sampler.h>

#include "make_sampler.h"

#if defined(__cplusplus)
#define SHIM extern "C"
#else
#define SHIM
#endif

/* make_sampler's return value; on success out[k] = value(pixel[k],
 * sample[k], dim[k]) and info = {table bytes, code, spp, s, strength,
 * block_dims, M}. */
SHIM int t_values(const char *name, pyoa_u32 spp, pyoa_u32 dims, pyoa_u32 seed, const char *offset, float jitter,
                  pyoa_u32 strength, pyoa_u32 base, pyoa_u32 width, pyoa_u32 height, size_t n,
                  const pyoa_u32 *pixel, const pyoa_u32 *sample, const pyoa_u32 *dim, float *out, pyoa_u32 *info,
                  char *message, size_t message_size)
{
    pyoa_sampler s;
    int rc = make_sampler(&s, name, spp, dims, seed, offset, jitter, strength, base, width, height, message,
                          message_size);
    if (rc != PYOA_OK) return rc;
    for (size_t k = 0; k < n; ++k) {
        /* a copy per value, as a GPU kernel receives it by value */
        pyoa_sampler copy = s;
        out[k] = pyoa_sampler_value(&copy, pixel[k], sample[k], dim[k]);
    }
    info[0] = (pyoa_u32)pyoa_sampler_table_bytes(&s);
    info[1] = s.code;
    info[2] = s.spp;
    info[3] = s.s;
    info[4] = s.strength;
    info[5] = s.block_dims;
    info[6] = s.M;
    return rc;
}
