/* examples/c/integrate7d.c: pyoa's C API in a C99 program.
 *
 * Each pixel of a 32 x 32 image estimates the same 7-dimensional integral
 * with its own samples, as a renderer's pixels estimate their radiance; the
 * RMS error over the pixels measures the sampler. The integrand is Genz's
 * "Gaussian" test function with a_j = 1 and u_j = 1/2:
 *
 *     f(x) = exp(-sum_{j=1..7} (x_j - 1/2)^2),
 *     integral over [0, 1)^7 = (sqrt(pi) erf(1/2))^7 = 0.56881...
 *
 * (each factor integrates to sqrt(pi) erf(1/2)). f is a product of seven
 * smooth factors that each vary little (from e^-1/4 = 0.78 to 1), so almost
 * all of its variance lies in its 1D and 2D parts, which a sampler that
 * stratifies every 1D and 2D projection at once (an orthogonal array of
 * strength 2: bose) removes; independent random samples keep all of it.
 *
 * Build with nothing but pyoa's flags (docs/renderers.md):
 *     cc -std=c99 -O2 $(python -m pyoa.config --cflags) examples/c/integrate7d.c -o integrate7d-c -lm
 *     ./integrate7d-c [sampler [spp [seed]]]        (default: bose 49 0)
 * It prints the sampler's RMS error next to that of pyoa's `random` sampler
 * (independent uniform values) at the same spp. examples/cpp/integrate7d.cpp
 * computes the same numbers through the C++ class; tests/test_c_examples.py
 * builds and runs both. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <pyoa/sampler.h>

#define WIDTH 32u
#define HEIGHT 32u
#define DIMS 7u

static double integrand(const float x[DIMS])
{
    double sum = 0.0;
    unsigned j;
    for (j = 0; j < DIMS; ++j)
        sum += ((double)x[j] - 0.5) * ((double)x[j] - 0.5);
    return exp(-sum);
}

static double exact_integral(void)
{
    const double pi = 3.14159265358979323846;
    return pow(sqrt(pi) * erf(0.5), (double)DIMS);
}

/* Make sampler `name` with its table (if it needs one) in *table, which the
 * caller frees; print the C API's message and return 0 on error. */
static int make(pyoa_sampler *s, void **table, const char *name, pyoa_u32 spp, pyoa_u32 seed)
{
    char message[1024];
    size_t bytes;
    int code;
    pyoa_u32 sampler_code;
    /* the Python API's defaults, then what this program sets: pyoa.sampler(name, spp=spp, dims=7, seed=seed) */
    pyoa_options options = pyoa_options_default(name, spp);
    options.dims = DIMS;
    options.seed = seed;
    /* the image, for the samplers that take it (zsobol, zfaure; the others refuse one, as in Python) */
    if (pyoa_lookup(name, &sampler_code) == PYOA_OK && pyoa_needs_resolution(sampler_code)) {
        options.width = WIDTH;
        options.height = HEIGHT;
    }
    code = pyoa_sampler_make(s, &options, message, sizeof message);
    *table = NULL;
    if (code != PYOA_OK) {
        fprintf(stderr, "integrate7d: %s\n", message);
        return 0;
    }
    bytes = pyoa_sampler_table_bytes(s);
    if (bytes != 0) {
        *table = malloc(bytes); /* malloc's memory is aligned for any type: 8 bytes at least */
        if (*table == NULL) {
            fprintf(stderr, "integrate7d: no memory for the %s table (%lu bytes)\n", name, (unsigned long)bytes);
            return 0;
        }
        pyoa_sampler_fill_table(s, *table);
        pyoa_sampler_bind_table(s, *table);
    }
    return 1;
}

/* RMS over the pixels of (the pixel's estimate - the exact integral). */
static double rms_error(const pyoa_sampler *s, pyoa_u32 spp)
{
    double exact = exact_integral(), sum = 0.0;
    float x[DIMS];
    pyoa_u32 px, py, i, j;
    for (py = 0; py < HEIGHT; ++py)
        for (px = 0; px < WIDTH; ++px) {
            pyoa_u32 pixel = pyoa_pixel_index(px, py, WIDTH);
            double estimate = 0.0;
            for (i = 0; i < spp; ++i) {
                for (j = 0; j < DIMS; ++j)
                    x[j] = pyoa_sampler_value(s, pixel, i, j);
                estimate += integrand(x);
            }
            estimate /= (double)spp;
            sum += (estimate - exact) * (estimate - exact);
        }
    return sqrt(sum / (double)(WIDTH * HEIGHT));
}

static int parse_u32(const char *text, const char *what, pyoa_u32 *out)
{
    char *end;
    unsigned long v = strtoul(text, &end, 10);
    if (*text == '\0' || *text == '-' || *end != '\0' || v > 0xFFFFFFFFul) {
        fprintf(stderr, "integrate7d: %s must be an unsigned 32-bit integer, not '%s'\n", what, text);
        return 0;
    }
    *out = (pyoa_u32)v;
    return 1;
}

int main(int argc, char **argv)
{
    const char *name = argc > 1 ? argv[1] : "bose";
    pyoa_u32 spp = 49u, seed = 0u;
    pyoa_sampler s, r;
    void *table_s, *table_r;
    double err_s, err_r;
    if (argc > 4) {
        fprintf(stderr, "usage: %s [sampler [spp [seed]]]\n", argv[0]);
        return 2;
    }
    if ((argc > 2 && !parse_u32(argv[2], "spp", &spp)) || (argc > 3 && !parse_u32(argv[3], "seed", &seed)))
        return 2;
    if (!make(&s, &table_s, name, spp, seed))
        return 1;
    if (!make(&r, &table_r, "random", spp, seed)) {
        free(table_s);
        return 1;
    }
    err_s = rms_error(&s, spp);
    err_r = rms_error(&r, spp);
    printf("7D Genz Gaussian, exact integral %.6f; %u x %u pixels, %u spp, seed %u\n", exact_integral(), WIDTH,
           HEIGHT, spp, seed);
    printf("%-8s RMS error %.3e\n", name, err_s);
    printf("%-8s RMS error %.3e\n", "random", err_r);
    printf("random / %s: %.1f\n", name, err_r / err_s);
    free(table_s);
    free(table_r);
    return 0;
}
