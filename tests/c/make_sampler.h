/* The shims' common first step (tests/c/sampler_shim.c, fill_shim.c): a
 * sampler made from the Python API's keyword arguments, its table filled
 * and bound. offset "" means NULL (the default). Returns
 * pyoa_sampler_make's value, or -1 when the table's memory is not there.
 * The tables are kept for the library's life: pmj02's 8 MB one (the same for
 * every pmj02 sampler, a second to build) once, any other the last one,
 * while the sampler's parameters stay the same (GF(256)'s tables take
 * milliseconds, and the tests ask for many requests of one sampler in a
 * row). */
#ifndef TESTS_MAKE_SAMPLER_H
#define TESTS_MAKE_SAMPLER_H

#include <stdlib.h>
#include <string.h>

#include <pyoa/sampler.h>

static int make_sampler(pyoa_sampler *s, const char *name, pyoa_u32 spp, pyoa_u32 dims, pyoa_u32 seed,
                        const char *offset, float jitter, pyoa_u32 strength, pyoa_u32 base, pyoa_u32 width,
                        pyoa_u32 height, char *message, size_t message_size)
{
    static void *pmj02_table = NULL, *last = NULL;
    static pyoa_u32 key[6];
    pyoa_options o = pyoa_options_default(name, spp);
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
    rc = pyoa_sampler_make(s, &o, message, message_size);
    if (rc != PYOA_OK) return rc;
    bytes = pyoa_sampler_table_bytes(s);
    if (s->code == PYOA_SAMPLER_PMJ02) {
        if (!pmj02_table) {
            pmj02_table = malloc(bytes);
            if (!pmj02_table) return -1;
            pyoa_sampler_fill_table(s, pmj02_table);
        }
        pyoa_sampler_bind_table(s, pmj02_table);
    } else if (bytes) {
        pyoa_u32 now[6];
        now[0] = s->code, now[1] = s->spp, now[2] = s->s, now[3] = s->strength, now[4] = s->dims, now[5] = s->field;
        if (!last || memcmp(key, now, sizeof key) != 0) {
            free(last);
            last = malloc(bytes);
            if (!last) return -1;
            pyoa_sampler_fill_table(s, last);
            memcpy(key, now, sizeof key);
        }
        pyoa_sampler_bind_table(s, last);
    }
    return rc;
}

#endif /* TESTS_MAKE_SAMPLER_H */
