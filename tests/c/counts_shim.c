/* Entry points over pyoa/counts.h for tests/test_c_counts.py to load with
 * ctypes (the header's functions are static inline: this file gives them
 * linkage). Built as C99 and as C++14, both compared with the Python API. */
#include <stddef.h>

#include <pyoa/counts.h>

#if defined(__cplusplus)
#define SHIM extern "C"
#else
#define SHIM
#endif

/* The 9 fields of pyoa_params, then pyoa_shape_args' a, b, c. */
#define T_FIELDS 12u

static void t_store(const pyoa_params *p, pyoa_u32 *out)
{
    out[0] = p->code;
    out[1] = p->spp;
    out[2] = p->s;
    out[3] = p->strength;
    out[4] = p->block_dims;
    out[5] = p->M;
    out[6] = p->dims;
    out[7] = p->width;
    out[8] = p->height;
    pyoa_shape_args(p, &out[9], &out[10], &out[11]);
}

/* n requests: pyoa_solve where base is 0 (the API the lead's sampler uses),
 * else pyoa_solve_base. rc[k], params[T_FIELDS k ...] (untouched on error,
 * the caller fills them with a marker to see that), messages[stride k ...]. */
SHIM void t_solve(size_t n, const pyoa_u32 *code, const pyoa_u32 *spp, const pyoa_u32 *strength, const pyoa_u32 *dims,
                  const pyoa_u32 *base, const pyoa_u32 *width, const pyoa_u32 *height, int *rc, pyoa_u32 *params,
                  char *messages, size_t stride)
{
    size_t k;
    for (k = 0; k < n; ++k) {
        pyoa_params p;
        char *msg = messages + k * stride;
        if (base[k] == 0u)
            rc[k] = pyoa_solve(code[k], spp[k], strength[k], dims[k], width[k], height[k], &p, msg, stride);
        else
            rc[k] = pyoa_solve_base(code[k], spp[k], strength[k], dims[k], base[k], width[k], height[k], &p, msg,
                                    stride);
        if (rc[k] == PYOA_OK)
            t_store(&p, params + T_FIELDS * k);
    }
}

SHIM int t_resolve(const char *name, pyoa_u32 spp, pyoa_u32 strength, pyoa_u32 dims, const char *offset,
                   pyoa_u32 base, pyoa_u32 width, pyoa_u32 height, pyoa_u32 *params, pyoa_u32 *offset_code,
                   char *message, size_t size)
{
    pyoa_params p;
    int rc = pyoa_resolve(name, spp, strength, dims, offset, 1.0f, base, width, height, &p, offset_code, message, size);
    if (rc == PYOA_OK)
        t_store(&p, params);
    return rc;
}

SHIM int t_lookup(const char *name, pyoa_u32 *code)
{
    return pyoa_lookup(name, code);
}

SHIM size_t t_name_error(const char *name, char *message, size_t size)
{
    return pyoa_name_error(name, message, size);
}

SHIM const char *t_sampler_name(pyoa_u32 code)
{
    return pyoa_sampler_name(code);
}

SHIM int t_needs_resolution(pyoa_u32 code)
{
    return pyoa_needs_resolution(code);
}

SHIM int t_offset_code(const char *offset, pyoa_u32 *code)
{
    return pyoa_offset_code(offset, code);
}

SHIM int t_sampler_offset(pyoa_u32 sampler, const char *offset, pyoa_u32 *code, char *message, size_t size)
{
    return pyoa_sampler_offset(sampler, offset, code, message, size);
}

/* pyoa_nearest for n requests: counts[k] choices (up to max each) at
 * out[T_FIELDS (max k + i) ...]; nearest_spp[k]. */
SHIM void t_nearest(size_t n, const pyoa_u32 *code, const pyoa_u32 *spp, const pyoa_u32 *dims,
                    const pyoa_u32 *strength, size_t max, pyoa_u32 *counts, pyoa_u32 *out, pyoa_u32 *nearest_spp)
{
    size_t k, i;
    for (k = 0; k < n; ++k) {
        pyoa_params c[PYOA_NEAREST_MAX];
        size_t got = pyoa_nearest(code[k], spp[k], dims[k], strength[k], c, max < PYOA_NEAREST_MAX ? max : PYOA_NEAREST_MAX);
        counts[k] = (pyoa_u32)got;
        for (i = 0; i < got && i < max; ++i)
            t_store(&c[i], out + T_FIELDS * (max * k + i));
        nearest_spp[k] = pyoa_nearest_spp(code[k], spp[k], dims[k], strength[k]);
    }
}

/* The header's exact rounded root, for the test of its boundaries. */
SHIM void t_root_round(size_t n, const pyoa_u32 *value, const pyoa_u32 *t, pyoa_u32 *out)
{
    size_t k;
    for (k = 0; k < n; ++k)
        out[k] = (pyoa_u32)pyoa_counts_root_round(value[k], t[k]);
}

SHIM size_t t_nearest_max(void)
{
    return PYOA_NEAREST_MAX;
}
