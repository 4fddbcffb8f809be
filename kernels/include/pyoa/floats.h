/* pyoa/floats.h: the float32 rules of docs/spec.md section 7
 * (pyoa/reference/floats.py is the reference). Every operation the spec
 * rounds is a PYOA_ADD, PYOA_SUB, PYOA_MUL or PYOA_DIV, never contracted
 * into an FMA (pyoa/config.h); the one FMA is explicit and exact in sign.
 *
 * Each function is written once, as a macro over its types (UT/FT the
 * uint/float types, CVT converting UT to FT with ties to even, ASF/ASU
 * reinterpreting bits), instantiated for scalars in every language and, in
 * OpenCL C, for the 8-lane vectors of kernels/vector.cl. */
#ifndef PYOA_FLOATS_H
#define PYOA_FLOATS_H

#include "config.h"

#define PYOA_DEFINE_FLOATS(SFX, UT, FT, CVT, ASF, ASU)                                  \
/* The smallest float32 >= c / n (0 <= c <= n <= 2^24, both exact as floats).       \
 * The correctly rounded quotient is that float or the one just below it; the       \
 * explicit fma is exact in sign (f * n - c is a multiple of f's unit in the        \
 * last place, far above the underflow range), so it tells which. */                \
PYOA_FN FT pyoa_cell_floor##SFX(UT c, float nf)                                         \
{                                                                                       \
    FT cf = CVT(c);                                                                     \
    FT f = PYOA_DIV(cf, (FT)nf);                                                        \
    return (PYOA_FMA(f, (FT)nf, -cf) < 0.0f) ? ASF(ASU(f) + 1u) : f;                    \
}                                                                                       \
                                                                                        \
/* x clamped into its cell [c/n, (c+1)/n) (spec 7.4): values inside keep their      \
 * bits, a value past an edge becomes the nearest float32 inside. Branch-free,      \
 * so that callers vectorize: both comparisons are made unconditionally (a         \
 * nested ?: compares x > hi only where x >= lo, and under GCC's default           \
 * -ftrapping-math a comparison that may trap is then not evaluated                \
 * speculatively: the loop keeps a branch). lo <= hi (spec 7.5), so the order      \
 * of the two selects does not matter. */                                           \
PYOA_FN FT pyoa_cell_clamp##SFX(FT x, UT c, pyoa_u32 n)                                 \
{                                                                                       \
    float nf = PYOA_U32_TO_F32(n);                                                      \
    FT lo = pyoa_cell_floor##SFX(c, nf);                                                \
    FT hi = ASF(ASU(pyoa_cell_floor##SFX(c + 1u, nf)) - 1u);                            \
    FT below_hi = x > hi ? hi : x;                                                      \
    return x < lo ? lo : below_hi;                                                      \
}                                                                                       \
                                                                                        \
/* (stratum + (sub + jitter) / M) / s (spec 1.2): four correctly rounded            \
 * operations, before the clamp. */                                                 \
PYOA_FN FT pyoa_formula_value##SFX(UT stratum, FT sub, FT jitter, pyoa_u32 M, pyoa_u32 s) \
{                                                                                       \
    FT inner = PYOA_DIV(PYOA_ADD(sub, jitter), (FT)PYOA_U32_TO_F32(M));                 \
    return PYOA_DIV(PYOA_ADD(CVT(stratum), inner), (FT)PYOA_U32_TO_F32(s));             \
}                                                                                       \
                                                                                        \
/* The value of the integer sub-stratum sub, clamped into its fine cell             \
 * stratum * M + sub of N = s * M ('centered' has centered_value). */               \
PYOA_FN FT pyoa_sample_value##SFX(UT stratum, UT sub, FT jitter, pyoa_u32 M, pyoa_u32 s) \
{                                                                                       \
    return pyoa_cell_clamp##SFX(pyoa_formula_value##SFX(stratum, CVT(sub), jitter, M, s), \
                                stratum * M + sub, M * s);                              \
}                                                                                       \
                                                                                        \
/* The 'centered' offset: sub = (M-1)/2 (exact in float32). For odd M it is an      \
 * integer and the value is clamped into that fine cell; for even M it is a         \
 * half-integer between two fine cells, and the value is clamped into its           \
 * coarse stratum. */                                                               \
PYOA_FN FT pyoa_centered_value##SFX(UT stratum, FT jitter, pyoa_u32 M, pyoa_u32 s)      \
{                                                                                       \
    FT mid = (FT)PYOA_MUL(0.5f, PYOA_U32_TO_F32(M - 1u)); /* not "half": an OpenCL type */ \
    FT x = pyoa_formula_value##SFX(stratum, mid, jitter, M, s);                         \
    pyoa_u32 cm, ch, n;                                                                 \
    pyoa_centered_cell(M, s, &cm, &ch, &n);                                             \
    return pyoa_cell_clamp##SFX(x, stratum * cm + ch, n);                               \
}                                                                                       \
                                                                                        \
/* The jitter of spec 1.2: 0.5 + amount (r - 0.5), two rounded operations and a     \
 * product (an FMA here changed bits on NVIDIA's compiler). */                      \
PYOA_FN FT pyoa_jitter_value##SFX(FT r, float amount)                                   \
{                                                                                       \
    return PYOA_ADD((FT)0.5f, PYOA_MUL((FT)amount, PYOA_SUB(r, (FT)0.5f)));             \
}

/* The cell the 'centered' value of a stratum is clamped into (spec 4,
 * 7.4): cell stratum * cm + ch of n. For odd M, sub = (M-1)/2 is an
 * integer: the fine cell stratum * M + (M-1)/2 of n = M s; for even M it
 * is a half-integer between two fine cells: the coarse stratum of n = s.
 * It depends on M and s alone, so a loop over strata hoists it (a select
 * per lane kept GCC from vectorizing pyoa/fill.h's loops). */
PYOA_FN void pyoa_centered_cell(pyoa_u32 M, pyoa_u32 s, pyoa_u32 *cm, pyoa_u32 *ch, pyoa_u32 *n)
{
    pyoa_u32 odd = M & 1u;
    *cm = odd ? M : 1u;
    *ch = odd ? (M - 1u) / 2u : 0u;
    *n = odd ? M * s : s;
}

PYOA_DEFINE_FLOATS(, pyoa_u32, float, PYOA_U32_TO_F32, PYOA_AS_F32, PYOA_AS_U32)
#if defined(__OPENCL_VERSION__)
PYOA_DEFINE_FLOATS(_v8, uint8, float8, convert_float8, as_float8, as_uint8)
#endif

#endif /* PYOA_FLOATS_H */
