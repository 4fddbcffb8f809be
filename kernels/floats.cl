/* Float32 rules of docs/spec.md section 7 (mirrors pyoa/reference/floats.py).
 * FP_CONTRACT OFF forbids fusing a*b+c into an FMA; the program is built with
 * -cl-fp32-correctly-rounded-divide-sqrt so that '/' is correctly rounded. */
#pragma OPENCL FP_CONTRACT OFF

/* The smallest float32 >= c / n (0 <= c <= n <= 2^24, both exact as floats).
 * The correctly rounded quotient is that float or the one just below it; the
 * explicit fma is exact in sign (f * n - c is a multiple of f's unit in the
 * last place, far above the underflow range), so it tells which. */
float cell_floor(uint c, float nf)
{
    float cf = convert_float(c);
    float f = cf / nf;
    return (fma(f, nf, -cf) < 0.0f) ? as_float(as_uint(f) + 1u) : f;
}

/* x clamped into its cell [c/n, (c+1)/n): values inside keep their bits, a
 * value past an edge becomes the nearest float32 inside. Branch-free: PoCL
 * vectorizes it; it costs the table kernel about 3 % (docs/performance.md). */
float cell_clamp(float x, uint c, uint n)
{
    float nf = convert_float(n);
    float lo = cell_floor(c, nf), hi = as_float(as_uint(cell_floor(c + 1u, nf)) - 1u);
    return x < lo ? lo : (x > hi ? hi : x);
}

/* (stratum + (sub + jitter) / M) / s: four correctly rounded operations,
 * before the clamp. */
float formula_value(uint stratum, float sub, float jitter, uint M, uint s)
{
    return (convert_float(stratum) + (sub + jitter) / convert_float(M)) / convert_float(s);
}

/* The value of the integer sub-stratum sub, clamped into its fine cell
 * stratum * M + sub of N = s * M ('centered' is handled by oa_value). */
float sample_value(uint stratum, uint sub, float jitter, uint M, uint s)
{
    return cell_clamp(formula_value(stratum, convert_float(sub), jitter, M, s), stratum * M + sub, M * s);
}

/* The 'centered' offset: sub = (M-1)/2 (exact in float32). For odd M it is
 * an integer and the value is clamped into that fine cell; for even M it is
 * a half-integer between two fine cells, and the value is clamped into its
 * coarse stratum. */
float centered_value(uint stratum, float jitter, uint M, uint s)
{
    float x = formula_value(stratum, 0.5f * convert_float(M - 1u), jitter, M, s);
    uint odd = M & 1u;
    return cell_clamp(x, odd ? stratum * M + (M - 1u) / 2u : stratum, odd ? M * s : s);
}

float jitter_value(float r, float amount)
{
    return 0.5f + amount * (r - 0.5f);
}
