/* Batch entry points over pyoa's portable headers, for tests/test_c_headers.py
 * to load with ctypes: each applies one header function to n inputs. Built
 * as C (c99, gnu11 with -march=native -ffp-contract=fast: the flags under
 * which a compiler would contract float operations if the headers let it)
 * and as C++ (c++14), so every language mode is compared with the reference. */
#include <stddef.h>

#include <pyoa/floats.h>
#include <pyoa/hashes.h>

#if defined(__cplusplus)
#define SHIM extern "C"
#else
#define SHIM
#endif

SHIM void t_permute(size_t n, const pyoa_u32 *i, const pyoa_u32 *l, const pyoa_u32 *p, pyoa_u32 *out)
{
    for (size_t k = 0; k < n; ++k) out[k] = pyoa_permute(i[k], l[k], p[k]);
}

SHIM void t_block_row(size_t n, const pyoa_u32 *i, const pyoa_u32 *N, const pyoa_u32 *r, pyoa_u32 *out)
{
    for (size_t k = 0; k < n; ++k) out[k] = pyoa_block_row(i[k], N[k], r[k]);
}

SHIM void t_randfloat(size_t n, const pyoa_u32 *i, const pyoa_u32 *p, float *out)
{
    for (size_t k = 0; k < n; ++k) out[k] = pyoa_randfloat(i[k], p[k]);
}

/* seeds: out[5k..5k+4] = mix32(a), hash_pair(a, b, key), pixel_seed(a, b),
 * block_seed(a, b), frame_seed(a, b); block_order_seed(a, b, key) in out2[k] */
SHIM void t_seeds(size_t n, const pyoa_u32 *a, const pyoa_u32 *b, const pyoa_u32 *key, pyoa_u32 *out, pyoa_u32 *out2)
{
    for (size_t k = 0; k < n; ++k) {
        out[5 * k + 0] = pyoa_mix32(a[k]);
        out[5 * k + 1] = pyoa_hash_pair(a[k], b[k], key[k]);
        out[5 * k + 2] = pyoa_pixel_seed(a[k], b[k]);
        out[5 * k + 3] = pyoa_block_seed(a[k], b[k]);
        out[5 * k + 4] = pyoa_frame_seed(a[k], b[k]);
        out2[k] = pyoa_block_order_seed(a[k], b[k], key[k]);
    }
}

SHIM void t_sample_value(size_t n, const pyoa_u32 *stratum, const pyoa_u32 *sub, const float *jitter,
                         const pyoa_u32 *M, const pyoa_u32 *s, float *out)
{
    for (size_t k = 0; k < n; ++k) out[k] = pyoa_sample_value(stratum[k], sub[k], jitter[k], M[k], s[k]);
}

SHIM void t_centered_value(size_t n, const pyoa_u32 *stratum, const float *jitter, const pyoa_u32 *M,
                           const pyoa_u32 *s, float *out)
{
    for (size_t k = 0; k < n; ++k) out[k] = pyoa_centered_value(stratum[k], jitter[k], M[k], s[k]);
}

SHIM void t_jitter_value(size_t n, const float *r, const float *amount, float *out)
{
    for (size_t k = 0; k < n; ++k) out[k] = pyoa_jitter_value(r[k], amount[k]);
}
