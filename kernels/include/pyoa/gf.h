/* pyoa/gf.h: arithmetic in the Galois field GF(q) of docs/spec.md section
 * 5.1 (pyoa/gf.py is the reference): mod q for a prime q, else lookups in
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

#endif /* PYOA_GF_H */
