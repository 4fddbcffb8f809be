/* Float32 rules of SPEC section 7 (mirrors pyoa/reference/floats.py).
 * FP_CONTRACT OFF forbids fusing a*b+c into an FMA; the program is built with
 * -cl-fp32-correctly-rounded-divide-sqrt so that '/' is correctly rounded. */
#pragma OPENCL FP_CONTRACT OFF

#define ONE_MINUS_ULP as_float(0x3f7fffffu)

float sample_value(uint stratum, float sub, float jitter, uint M, uint s)
{
    float x = (convert_float(stratum) + (sub + jitter) / convert_float(M)) / convert_float(s);
    return x < 1.0f ? x : ONE_MINUS_ULP;
}

float jitter_value(float r, float amount)
{
    return 0.5f + amount * (r - 0.5f);
}
