/* pyoa/gf.h: arithmetic in the Galois field GF(q) of docs/spec.md section
 * 5.1 (pyoa/tables/gf.py is the reference): mod q for a prime q, else lookups in
 * the tables of pyoa/tables.h (pyoa_gf_fill), one buffer `gf` holding the
 * q*q addition table followed by the q*q multiplication table (uint16),
 * with `tabled` = 1. For a prime q, `gf` may be a 1-element placeholder and
 * tabled = 0: the index is clamped to 0 then, so no lane ever reads past it
 * (a GPU or vector lane evaluates both sides of the select). */
#ifndef PYOA_GF_H
#define PYOA_GF_H

#include "config.h"

/* a + b in GF(q), for a, b < q. */
PYOA_FN pyoa_u32 pyoa_gf_add(pyoa_u32 a, pyoa_u32 b, pyoa_u32 q, PYOA_GLOBAL const pyoa_u16 *gf, pyoa_u32 tabled)
{
    pyoa_u32 k = tabled ? a * q + b : 0u;
    return tabled ? (pyoa_u32)gf[k] : (a + b) % q;
}

/* a * b in GF(q), for a, b < q (a * b < 2^16 for the tabled q <= 256, and
 * below 2^32 for every prime pyoa allows). */
PYOA_FN pyoa_u32 pyoa_gf_mul(pyoa_u32 a, pyoa_u32 b, pyoa_u32 q, PYOA_GLOBAL const pyoa_u16 *gf, pyoa_u32 tabled)
{
    pyoa_u32 k = tabled ? q * q + a * q + b : 0u;
    return tabled ? (pyoa_u32)gf[k] : (a * b) % q;
}

#if !defined(__OPENCL_VERSION__)
/* Which orders pyoa has a field for, on the host (making a sampler,
 * filling its tables: pyoa/counts.h, pyoa/tables.h). */

/* The largest composite prime power with GF tables (pyoa.tables.gf.MAX_TABLE_Q). */
#define PYOA_GF_MAX_TABLE_Q 256u

/* The smallest prime factor p of q >= 2 and the exponent r with q = p^r;
 * returns p, or 0 (r = 0) when q is not a prime power (q < 2 included).
 * pyoa.tables.gf.prime_power. Trial division up to sqrt(q) < 2^16. */
PYOA_HOST_FN pyoa_u32 pyoa_gf_prime_power(pyoa_u32 q, pyoa_u32 *r)
{
    pyoa_u32 p = q, d, e = 0;
    *r = 0;
    if (q < 2) return 0;
    for (d = 2; d <= q / d; ++d) {
        if (q % d == 0) {
            p = d;
            break;
        }
    }
    while (q % p == 0) {
        q /= p;
        ++e;
    }
    if (q != 1) return 0;
    *r = e;
    return p;
}

/* Whether pyoa has GF(q): q prime, or a prime power up to 256
 * (pyoa.tables.gf.is_supported). */
PYOA_HOST_FN int pyoa_gf_is_supported(pyoa_u32 q)
{
    pyoa_u32 r;
    return pyoa_gf_prime_power(q, &r) != 0 && (r == 1 || q <= PYOA_GF_MAX_TABLE_Q);
}

/* Whether n is a prime (constructions.is_prime). */
PYOA_HOST_FN int pyoa_is_prime(pyoa_u32 n)
{
    pyoa_u32 r;
    return pyoa_gf_prime_power(n, &r) != 0 && r == 1;
}
#endif /* !__OPENCL_VERSION__ */

#endif /* PYOA_GF_H */
