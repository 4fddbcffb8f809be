/* Entry points over pyoa/sampler.h (the renderer API) for
 * tests/test_c_sampler.py to load with ctypes: make a sampler from the
 * Python API's options, fill and bind its table, and evaluate it at n
 * (pixel, sample, dimension) triples. Built as C99 and as C++14. */
#include <stdlib.h>

#include <pyoa/sampler.h>

#if defined(__cplusplus)
#define SHIM extern "C"
#else
#define SHIM
#endif

/* pyoa_sampler_make's return value; on success out[k] = value(pixel[k],
 * sample[k], dim[k]) and info = {table bytes, code, spp, s, strength,
 * block_dims, M}. offset "" means NULL (the default). */
SHIM int t_values(const char *name, pyoa_u32 spp, pyoa_u32 dims, pyoa_u32 seed, const char *offset, float jitter,
                  pyoa_u32 strength, pyoa_u32 base, pyoa_u32 width, pyoa_u32 height, size_t n,
                  const pyoa_u32 *pixel, const pyoa_u32 *sample, const pyoa_u32 *dim, float *out, pyoa_u32 *info,
                  char *message, size_t message_size)
{
    pyoa_options o = pyoa_options_default(name, spp);
    pyoa_sampler s;
    void *table = NULL;
    size_t bytes;
    int rc;
    o.dims = dims;
    o.seed = seed;
    o.offset = (offset && offset[0]) ? offset : NULL;
    o.jitter = jitter;
    o.strength = strength;
    o.base = base;
    o.width = width;
    o.height = height;
    rc = pyoa_sampler_make(&s, &o, message, message_size);
    if (rc != PYOA_OK) return rc;
    bytes = pyoa_sampler_table_bytes(&s);
    if (s.code == PYOA_SAMPLER_PMJ02) {
        /* pmj02's 8 MB table is the same for every pmj02 sampler: filled
         * once per library (a second), compared byte for byte by
         * tests/test_c_pmj02.py */
        static void *pmj02_table = NULL;
        if (!pmj02_table) {
            pmj02_table = malloc(bytes);
            if (!pmj02_table) return -1;
            pyoa_sampler_fill_table(&s, pmj02_table);
        }
        pyoa_sampler_bind_table(&s, pmj02_table);
    } else if (bytes) {
        table = malloc(bytes);
        if (!table) return -1;
        pyoa_sampler_fill_table(&s, table);
        pyoa_sampler_bind_table(&s, table);
    }
    for (size_t k = 0; k < n; ++k) {
        /* a copy per value, as a GPU kernel receives it by value */
        pyoa_sampler copy = s;
        out[k] = pyoa_sampler_value(&copy, pixel[k], sample[k], dim[k]);
    }
    info[0] = (pyoa_u32)bytes;
    info[1] = s.code;
    info[2] = s.spp;
    info[3] = s.s;
    info[4] = s.strength;
    info[5] = s.block_dims;
    info[6] = s.M;
    free(table);
    return rc;
}
