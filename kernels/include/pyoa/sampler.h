/* pyoa/sampler.h: pyoa's samplers for a renderer written in C, C++ or CUDA.
 *
 * Make a sampler once on the host, from the same options as Python's
 * pyoa.Sampler; then every value is a stateless function of (pixel, sample,
 * dimension), on the host or in CUDA device code:
 *
 *     pyoa_options o = pyoa_options_default("bose", 121);
 *     o.seed = 7;
 *     pyoa_sampler s;
 *     char why[256];
 *     if (pyoa_sampler_make(&s, &o, why, sizeof why) != PYOA_OK) { puts(why); return 1; }
 *     void *table = NULL;
 *     if (pyoa_sampler_table_bytes(&s)) {             // prime-power fields, halton, sobol, pmj02
 *         table = aligned_alloc(8, pyoa_sampler_table_bytes(&s));
 *         pyoa_sampler_fill_table(&s, table);
 *         pyoa_sampler_bind_table(&s, table);        // or a device copy of it
 *     }
 *     float x = pyoa_sampler_value(&s, pyoa_pixel_index(px, py, width), i, dim);
 *
 * pyoa_sampler_value(&s, pixel, i, j) is, bit for bit, dimension j of
 * sample i of pixel index `pixel` of pyoa.Sampler(name, spp=..., dims=...,
 * seed=..., offset=..., jitter=..., strength=..., resolution=..., base=...)
 * (tests/test_c_sampler.py checks every catalogue sampler against the
 * reference and NumPy). A pyoa_sampler is a plain struct: copy it by value
 * into a kernel's arguments; it points at its table, which must stay alive
 * (and, for device code, live in device or managed memory).
 *
 * Pixel index: pyoa's values depend on a pixel only through one uint32
 * index (docs/spec.md section 3.1: the pixel's seed is a hash of the user
 * seed and that index). pyoa_pixel_index(x, y, width) = y * width + x over
 * the full image, so a crop or tile reproduces the full frame's values.
 * zsobol and zfaure read the position itself (their Morton orders): give
 * them the image size in the options and use the same index. For animations, give each
 * frame its own seed (docs/renderers.md has the recommended rule).
 *
 * Host-only functions are PYOA_HOST_FN; pyoa_sampler_value and
 * pyoa_pixel_index are PYOA_FN (also __host__ __device__ under nvcc). No
 * function allocates; the table's memory is the caller's. */
#ifndef PYOA_SAMPLER_H
#define PYOA_SAMPLER_H

#include "config.h"
#include "keys.h"
#include "values.h"

#if !defined(__OPENCL_VERSION__)
#include "counts.h"
#include "pmj02_build.h"
#include "tables.h"

/* What a sampler is made from: the keyword arguments of pyoa.Sampler.
 * Start from pyoa_options_default(name, spp), then change what you need. */
typedef struct pyoa_options {
    const char *name;   /* catalogue name or a pbrt/Mitsuba alias ("bose", "cmjnd", "zsobol", ...) */
    pyoa_u32 spp;       /* samples per pixel; an invalid count is refused with the nearest valid ones */
    pyoa_u32 dims;      /* dimensions the renderer reads; 0: not known (every dimension the sampler has) */
    pyoa_u32 seed;      /* the user seed (uint32) */
    const char *offset; /* the OAs' offset style: "cmj" (NULL: the default), "mj", "j" or "centered" */
    float jitter;       /* jitter amount in [0, 1] (1: the default; OAs, jittered2d and cmj2d only) */
    pyoa_u32 strength;  /* an OA's strength t; 0: the sampler's default */
    pyoa_u32 base;      /* faure's and zfaure's prime base; 0: its default */
    pyoa_u32 width;     /* the image, for zsobol and zfaure (0 x 0 for the others) */
    pyoa_u32 height;
} pyoa_options;

/* The defaults of pyoa.Sampler for sampler `name` at `spp` samples. */
PYOA_HOST_FN pyoa_options pyoa_options_default(const char *name, pyoa_u32 spp)
{
    pyoa_options o;
    o.name = name;
    o.spp = spp;
    o.dims = 0u;
    o.seed = 0u;
    o.offset = NULL;
    o.jitter = 1.0f;
    o.strength = 0u;
    o.base = 0u;
    o.width = 0u;
    o.height = 0u;
    return o;
}
#endif /* !__OPENCL_VERSION__ */

/* A made sampler: everything pyoa_sampler_value reads. Plain data, safe to
 * copy (by value into GPU kernels); read its fields, do not write them. */
typedef struct pyoa_sampler {
    pyoa_u32 code;        /* PYOA_SAMPLER_<NAME> (pyoa/keys.h) */
    pyoa_u32 spp;         /* samples per pixel */
    pyoa_u32 dims;        /* as given (0: not known) */
    pyoa_u32 seed;        /* the user seed */
    pyoa_u32 s, strength, block_dims, M; /* the resolved parameters (pyoa/counts.h pyoa_params) */
    pyoa_u32 a, b, c;     /* the shape arguments of the comparison and progressive samplers (pyoa_shape_args) */
    pyoa_u32 offset;      /* PYOA_OFFSET_<NAME>; PYOA_OFFSET_NONE for the others */
    float jitter;         /* J */
    pyoa_u32 field;       /* the order of the OA's Galois field (0: none) */
    pyoa_u32 gf_tabled;   /* 1: the field is a prime power and gf holds its tables */
    pyoa_u32 gf_entries;  /* uint16 entries of gf (0 when not tabled) */
    pyoa_u32 data_entries; /* uint32 entries of data (AK constants, or the sampler's table) */
    const pyoa_u16 *gf;   /* the field's addition and multiplication tables (bound) */
    const pyoa_u32 *data; /* AK's constants or halton/sobol/sobol02/pmj02's table (bound) */
} pyoa_sampler;

/* pyoa's pixel index of raster position (x, y) of an image `width` pixels
 * wide: row-major over the full image. */
PYOA_FN pyoa_u32 pyoa_pixel_index(pyoa_u32 x, pyoa_u32 y, pyoa_u32 width) { return y * width + x; }

/* Dimension j of sample i (i < spp) of pixel index `pixel`: the value in
 * [0, 1) that pyoa's Python API, NumPy and OpenCL give. Stateless and
 * thread-safe. Outside the sampler's ranges (i >= spp, j >= dims when dims
 * was given) the value is unspecified. */
PYOA_FN float pyoa_sampler_value(const pyoa_sampler *s, pyoa_u32 pixel, pyoa_u32 i, pyoa_u32 j)
{
    pyoa_u32 p = pyoa_pixel_seed(s->seed, pixel);
    if (s->code <= PYOA_SAMPLER_BOSE_BUSH) /* the orthogonal arrays: codes 0-4 (tests/test_c_sampler.py) */
        return pyoa_oa_value(s->code, i, j, s->s, s->strength, s->block_dims, s->spp, s->M, p, s->offset,
                             s->jitter, s->gf, s->gf_tabled, s->data);
    return pyoa_baseline_value(s->code, i, j, p, pixel, s->seed, s->a, s->b, s->c, s->jitter, s->data);
}

#if !defined(__OPENCL_VERSION__)

/* Bytes of the gf part of the table, rounded up to 8 so that the uint32
 * data after it stays aligned. */
PYOA_HOST_FN size_t pyoa_sampler_gf_bytes(const pyoa_sampler *s)
{
    return ((size_t)s->gf_entries * sizeof(pyoa_u16) + 7u) & ~(size_t)7u;
}

/* Make sampler `out` from `options`. Returns PYOA_OK, or the error code of
 * pyoa/counts.h (PYOA_ERROR_NAME, _SPP, _STRENGTH, _OFFSET, _RESOLUTION,
 * _DIMS, _BASE, _JITTER), with the message of Python's
 * ValueError in message[message_size] (truncated to fit; message may be
 * NULL): an invalid count names the nearest valid counts below and above.
 * `out` is written only on success. The sampler needs its table bound
 * before values are read when pyoa_sampler_table_bytes is not 0. */
PYOA_HOST_FN int pyoa_sampler_make(pyoa_sampler *out, const pyoa_options *o, char *message, size_t message_size)
{
    pyoa_params p;
    pyoa_u32 offset = PYOA_OFFSET_NONE;
    pyoa_sampler s;
    int rc = pyoa_resolve(o->name, o->spp, o->strength, o->dims, o->offset, o->jitter, o->base, o->width,
                          o->height, &p, &offset, message, message_size);
    if (rc != PYOA_OK) return rc;
    s.code = p.code;
    s.spp = p.spp;
    s.dims = o->dims;
    s.seed = o->seed;
    s.s = p.s;
    s.strength = p.strength;
    s.block_dims = p.block_dims;
    s.M = p.M;
    pyoa_shape_args(&p, &s.a, &s.b, &s.c);
    s.offset = offset;
    s.jitter = o->jitter;
    /* the Galois field (construction.field_order): bose-bush computes in GF(2s) */
    s.field = (p.code == PYOA_SAMPLER_CMJND || p.code > PYOA_SAMPLER_BOSE_BUSH) ? 0u
              : (p.code == PYOA_SAMPLER_BOSE_BUSH) ? 2u * p.s : p.s;
    s.gf_tabled = s.field ? pyoa_gf_tabled(s.field) : 0u;
    s.gf_entries = s.gf_tabled ? pyoa_gf_table_entries(s.field) : 0u;
    switch (p.code) {
    case PYOA_SAMPLER_ADDELMAN_KEMPTHORNE: s.data_entries = pyoa_ak_entries(p.s); break;
    case PYOA_SAMPLER_SOBOL02: s.data_entries = pyoa_sobol_entries(2u); break;
    case PYOA_SAMPLER_SOBOL: s.data_entries = pyoa_sobol_entries(o->dims); break;
    case PYOA_SAMPLER_HALTON: s.data_entries = pyoa_halton_entries(); break;
    case PYOA_SAMPLER_PMJ02: s.data_entries = pyoa_pmj02_table_entries(); break;
    default: s.data_entries = 0u; break;
    }
    s.gf = NULL;
    s.data = NULL;
    *out = s;
    return PYOA_OK;
}

/* Bytes of the table the sampler reads (0: none): the field's tables
 * (prime-power orders: 2 q^2 uint16), Addelman-Kempthorne's constants,
 * halton's primes (26 KB), sobol's direction numbers (128 bytes per
 * dimension; all 21201, 2.7 MB, when dims is 0), sobol02's two dimensions
 * or pmj02's point sets (8 MB). */
PYOA_HOST_FN size_t pyoa_sampler_table_bytes(const pyoa_sampler *s)
{
    size_t n = pyoa_sampler_gf_bytes(s) + (size_t)s->data_entries * sizeof(pyoa_u32);
    return n;
}

/* Fill `buffer` (host memory, pyoa_sampler_table_bytes(s) bytes, 8-byte
 * aligned) with the sampler's table. Deterministic: the same bytes on
 * every machine, so a renderer may fill it once and copy it anywhere.
 * pmj02's point sets are built here (a second or two); the others take
 * milliseconds. */
PYOA_HOST_FN void pyoa_sampler_fill_table(const pyoa_sampler *s, void *buffer)
{
    pyoa_u32 *data = (pyoa_u32 *)((char *)buffer + pyoa_sampler_gf_bytes(s));
    if (s->gf_entries) pyoa_gf_fill(s->field, (pyoa_u16 *)buffer);
    switch (s->code) {
    case PYOA_SAMPLER_ADDELMAN_KEMPTHORNE: pyoa_ak_fill(s->s, data); break;
    case PYOA_SAMPLER_SOBOL02: pyoa_sobol_fill(2u, data); break;
    case PYOA_SAMPLER_SOBOL: pyoa_sobol_fill(s->dims, data); break;
    case PYOA_SAMPLER_HALTON: pyoa_halton_fill(data); break;
    case PYOA_SAMPLER_PMJ02: (void)pyoa_pmj02_fill(data); break;
    default: break;
    }
}

/* Point the sampler at its filled table: `buffer` itself, or a copy of it
 * (the same bytes) in device or managed memory for GPU code. */
PYOA_HOST_FN void pyoa_sampler_bind_table(pyoa_sampler *s, const void *buffer)
{
    s->gf = s->gf_entries ? (const pyoa_u16 *)buffer : NULL;
    s->data = s->data_entries ? (const pyoa_u32 *)((const char *)buffer + pyoa_sampler_gf_bytes(s)) : NULL;
}

#endif /* !__OPENCL_VERSION__ */
#endif /* PYOA_SAMPLER_H */
