/* Orthogonal-array samplers of SPEC section 5 (mirrors pyoa/reference/oa.py).
 * Offset codes OFFSET_* come from pyoa.constructions as -D build options.
 *
 * Each sampler is split into the pieces the bulk kernels of generate.cl
 * reuse: the column key (block seed times column + 1, SPEC sections 3 and 6),
 * the integer cell of the array, and the final value. */

/* q = block_seed(p, j / dmax) * (j % dmax + 1): the three dimension seeds are
 * q * STRATUM_KEY, q * SUBSTRATUM_KEY and q * JITTER_KEY. */
uint column_key(uint p, uint j, uint dmax)
{
    return block_seed(p, j / dmax) * (j % dmax + 1u);
}

/* Bose: A_ij of column j (< s+1) and A_ik of its partner column k. The
 * column-0/1/other choice is written with bit masks, not a ?: chain, which
 * LLVM turns into a switch that keeps PoCL from vectorizing (POCL-NOTES.md). */
void bose_cell(uint i, uint j, uint s, uint *aij, uint *aik)
{
    uint a0 = i / s, a1 = i % s;
    uint k = (j & 1u) ? j - 1u : j + 1u;
    uint m0 = 0u - (uint)(j == 0u), m1 = 0u - (uint)(j == 1u), mg = ~(m0 | m1);
    *aij = (a0 & m0) | (a1 & m1) | (((a0 + (j - 1u) * a1) % s) & mg);
    *aik = (a1 & m0) | (a0 & m1) | (((a0 + ((k - 1u) % s) * a1) % s) & mg);
}

/* CMJND: digit j of i in base s (sj = s^j), and v = the other digits. */
void cmjnd_cell(uint i, uint s, uint sj, uint *aij, uint *v)
{
    *aij = (i / sj) % s;
    *v = i % sj + (i / (sj * s)) * sj;
}

/* x from the stratum, the sub-stratum (as float) and the jitter seed. */
float oa_value(uint i, uint stratum, float sub, uint P3, uint M, uint s, float J)
{
    return sample_value(stratum, sub, jitter_value(randfloat(i, P3), J), M, s);
}

/* sub-stratum of the offset styles that hash per cell ('j', 'mj') or per
 * column ('cmj'); 'centered' is (M-1)/2. cell_key is the 'j' seed factor. */
float offset_sub(uint offset, uint u, uint M, uint cell_key, uint aij, uint P2)
{
    if (offset == OFFSET_CENTERED) return 0.5f * convert_float(M - 1u);
    uint seed = (offset == OFFSET_J) ? cell_key * P2 : (offset == OFFSET_MJ) ? (aij + 1u) * P2 : P2;
    return convert_float(permute(u, M, seed));
}

float bose(uint i, uint j, uint s, uint p, uint offset, float J)
{
    uint q = column_key(p, j, s + 1u);
    uint aij, aik;
    bose_cell(i, j % (s + 1u), s, &aij, &aik);
    uint stratum = permute(aij, s, q * STRATUM_KEY);
    float sub = offset_sub(offset, aik, s, aik * s + aij + 1u, aij, q * SUBSTRATUM_KEY);
    return oa_value(i, stratum, sub, q * JITTER_KEY, s, s, J);
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
    uint q = column_key(p, j, t);
    uint M = pow_u(s, t - 1u);
    uint aij, v;
    cmjnd_cell(i, s, pow_u(s, j % t), &aij, &v);
    uint stratum = permute(aij, s, q * STRATUM_KEY);
    float sub = offset_sub(offset, v, M, i + 1u, aij, q * SUBSTRATUM_KEY);
    return oa_value(i, stratum, sub, q * JITTER_KEY, M, s, J);
}
