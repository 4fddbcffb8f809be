/* Float32 rules of docs/spec.md section 7 (mirrors pyoa/reference/floats.py).
 * FP_CONTRACT OFF forbids fusing a*b+c into an FMA; the program is built with
 * -cl-fp32-correctly-rounded-divide-sqrt so that '/' is correctly rounded.
 *
 * Each function is defined once, by a macro over its types, and instantiated
 * for scalars (cell_floor, ...) and for the 8-lane vectors of the kernels in
 * vector.cl (cell_floor_v8, ...): elementwise, the same operations in the
 * same order, so both give the same bits. UT/FT are the uint/float types,
 * CVT converts UT to FT, ASF/ASU reinterpret bits. */
#pragma OPENCL FP_CONTRACT OFF

#define DEFINE_FLOATS(SFX, UT, FT, CVT, ASF, ASU)                                       \
/* The smallest float32 >= c / n (0 <= c <= n <= 2^24, both exact as floats).       \
 * The correctly rounded quotient is that float or the one just below it; the       \
 * explicit fma is exact in sign (f * n - c is a multiple of f's unit in the        \
 * last place, far above the underflow range), so it tells which. */                \
FT cell_floor##SFX(UT c, float nf)                                                      \
{                                                                                       \
    FT cf = CVT(c);                                                                     \
    FT f = cf / nf;                                                                     \
    return (fma(f, (FT)nf, -cf) < 0.0f) ? ASF(ASU(f) + 1u) : f;                         \
}                                                                                       \
                                                                                        \
/* x clamped into its cell [c/n, (c+1)/n): values inside keep their bits, a         \
 * value past an edge becomes the nearest float32 inside. Branch-free: PoCL         \
 * vectorizes it; it costs the table kernel about 3 % (docs/performance.md). */     \
FT cell_clamp##SFX(FT x, UT c, uint n)                                                  \
{                                                                                       \
    float nf = convert_float(n);                                                        \
    FT lo = cell_floor##SFX(c, nf), hi = ASF(ASU(cell_floor##SFX(c + 1u, nf)) - 1u);    \
    return x < lo ? lo : (x > hi ? hi : x);                                             \
}                                                                                       \
                                                                                        \
/* (stratum + (sub + jitter) / M) / s: four correctly rounded operations,           \
 * before the clamp. */                                                             \
FT formula_value##SFX(UT stratum, FT sub, FT jitter, uint M, uint s)                    \
{                                                                                       \
    return (CVT(stratum) + (sub + jitter) / convert_float(M)) / convert_float(s);       \
}                                                                                       \
                                                                                        \
/* The value of the integer sub-stratum sub, clamped into its fine cell             \
 * stratum * M + sub of N = s * M ('centered' is handled by oa_value). */           \
FT sample_value##SFX(UT stratum, UT sub, FT jitter, uint M, uint s)                     \
{                                                                                       \
    return cell_clamp##SFX(formula_value##SFX(stratum, CVT(sub), jitter, M, s),         \
                           stratum * M + sub, M * s);                                   \
}                                                                                       \
                                                                                        \
/* The 'centered' offset: sub = (M-1)/2 (exact in float32). For odd M it is an      \
 * integer and the value is clamped into that fine cell; for even M it is a         \
 * half-integer between two fine cells, and the value is clamped into its           \
 * coarse stratum. */                                                               \
FT centered_value##SFX(UT stratum, FT jitter, uint M, uint s)                           \
{                                                                                       \
    FT x = formula_value##SFX(stratum, (FT)(0.5f * convert_float(M - 1u)), jitter, M, s); \
    uint odd = M & 1u;                                                                  \
    return cell_clamp##SFX(x, odd ? stratum * M + (M - 1u) / 2u : stratum, odd ? M * s : s); \
}                                                                                       \
                                                                                        \
FT jitter_value##SFX(FT r, float amount)                                                \
{                                                                                       \
    return 0.5f + amount * (r - 0.5f);                                                  \
}

DEFINE_FLOATS(, uint, float, convert_float, as_float, as_uint)
DEFINE_FLOATS(_v8, uint8, float8, convert_float8, as_float8, as_uint8)
