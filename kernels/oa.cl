/* Orthogonal-array samplers of SPEC section 5 (mirrors pyoa/reference/oa.py).
 * Offset codes OFFSET_* come from pyoa.constructions as -D build options. */

float bose(uint i, uint j, uint s, uint p, uint offset, float J)
{
    uint block = j / (s + 1u);
    j = j % (s + 1u);
    p = block_seed(p, block);
    uint q = p * (j + 1u);
    uint P1 = q * STRATUM_KEY, P2 = q * SUBSTRATUM_KEY, P3 = q * JITTER_KEY;

    uint a0 = i / s, a1 = i % s;
    uint k = (j & 1u) ? j - 1u : j + 1u;
    uint aij = (j == 0u) ? a0 : (j == 1u) ? a1 : (a0 + (j - 1u) * a1) % s;
    uint aik = (j == 0u) ? a1 : (j == 1u) ? a0 : (a0 + ((k - 1u) % s) * a1) % s;

    uint stratum = permute(aij, s, P1);
    float sub;
    if (offset == OFFSET_CENTERED)  sub = 0.5f * convert_float(s - 1u);
    else if (offset == OFFSET_J)    sub = convert_float(permute(aik, s, (aik * s + aij + 1u) * P2));
    else if (offset == OFFSET_MJ)   sub = convert_float(permute(aik, s, (aij + 1u) * P2));
    else                            sub = convert_float(permute(aik, s, P2));
    return sample_value(stratum, sub, jitter_value(randfloat(i, P3), J), s, s);
}

/* pow_u(s, e) = s^e; every use stays below 2^24. */
uint pow_u(uint s, uint e)
{
    uint r = 1u;
    for (uint k = 0u; k < e; ++k) r *= s;
    return r;
}

float cmjnd(uint i, uint j, uint s, uint t, uint p, uint offset, float J)
{
    uint block = j / t;
    j = j % t;
    p = block_seed(p, block);
    uint q = p * (j + 1u);
    uint P1 = q * STRATUM_KEY, P2 = q * SUBSTRATUM_KEY, P3 = q * JITTER_KEY;

    uint M = pow_u(s, t - 1u);
    uint sj = pow_u(s, j);
    uint aij = (i / sj) % s;
    uint v = i % sj + (i / (sj * s)) * sj;

    uint stratum = permute(aij, s, P1);
    float sub;
    if (offset == OFFSET_CENTERED)  sub = 0.5f * convert_float(M - 1u);
    else if (offset == OFFSET_J)    sub = convert_float(permute(v, M, (i + 1u) * P2));
    else if (offset == OFFSET_MJ)   sub = convert_float(permute(v, M, (aij + 1u) * P2));
    else                            sub = convert_float(permute(v, M, P2));
    return sample_value(stratum, sub, jitter_value(randfloat(i, P3), J), M, s);
}
