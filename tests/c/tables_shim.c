/* Entry points over pyoa/tables.h for tests/test_c_tables.py to load with
 * ctypes (the fill functions are static inline: a shared library needs a
 * symbol to call). Built as C99 and as C++14. */
#include <stddef.h>

#include <pyoa/tables.h>

#if defined(__cplusplus)
#define SHIM extern "C"
#else
#define SHIM
#endif

/* For each q[i]: p (0: not a prime power), r, is_supported, tabled, table entries, modulus code. */
SHIM void t_gf_info(size_t n, const pyoa_u32 *q, pyoa_u32 *out)
{
    for (size_t i = 0; i < n; ++i) {
        pyoa_u32 r;
        out[6 * i + 0] = pyoa_gf_prime_power(q[i], &r);
        out[6 * i + 1] = r;
        out[6 * i + 2] = (pyoa_u32)pyoa_gf_is_supported(q[i]);
        out[6 * i + 3] = pyoa_gf_tabled(q[i]);
        out[6 * i + 4] = pyoa_gf_table_entries(q[i]);
        out[6 * i + 5] = pyoa_gf_modulus(q[i]);
    }
}

SHIM pyoa_u32 t_gf_table_entries(pyoa_u32 q) { return pyoa_gf_table_entries(q); }
SHIM void t_gf_fill(pyoa_u32 q, pyoa_u16 *out) { pyoa_gf_fill(q, out); }
SHIM pyoa_u32 t_ak_entries(pyoa_u32 q) { return pyoa_ak_entries(q); }
SHIM void t_ak_fill(pyoa_u32 q, pyoa_u32 *out) { pyoa_ak_fill(q, out); }
SHIM pyoa_u32 t_halton_entries(void) { return pyoa_halton_entries(); }
SHIM void t_halton_fill(pyoa_u32 *out) { pyoa_halton_fill(out); }
SHIM pyoa_u32 t_sobol_entries(pyoa_u32 dims) { return pyoa_sobol_entries(dims); }
SHIM void t_sobol_fill(pyoa_u32 dims, pyoa_u32 *out) { pyoa_sobol_fill(dims, out); }
