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

/* Bose over GF(s): A_ij of column j (< s+1) and A_ik of its partner column
 * k. The column-0/1/other choice is written with bit masks, not a ?: chain,
 * which LLVM turns into a switch that keeps PoCL from vectorizing
 * (POCL-NOTES.md); multipliers of columns 0 and 1 are clamped to 0 so that
 * table lookups stay in range for the lanes the masks discard. */
void bose_cell(uint i, uint j, uint s, __global const ushort *gf, uint tabled, uint *aij, uint *aik)
{
    uint a0 = i / s, a1 = i % s;
    uint k = (j & 1u) ? j - 1u : j + 1u;
    uint m0 = 0u - (uint)(j == 0u), m1 = 0u - (uint)(j == 1u), mg = ~(m0 | m1);
    uint mj = ((j - 1u) & mg) % s, mk = ((k - 1u) & mg) % s;
    *aij = (a0 & m0) | (a1 & m1) | (gf_add(a0, gf_mul(mj, a1, s, gf, tabled), s, gf, tabled) & mg);
    *aik = (a1 & m0) | (a0 & m1) | (gf_add(a0, gf_mul(mk, a1, s, gf, tabled), s, gf, tabled) & mg);
}

/* Bush: the row polynomial sum_l c_l x^l (c_l = base-s digits of i) at
 * x = j in GF(s) for j < s, its leading coefficient for j == s; and u, the
 * sub-stratum index: i / s for j < s, i % M for j == s (see reference.bush). */
void bush_cell(uint i, uint j, uint s, uint t, uint M, __global const ushort *gf, uint tabled, uint *aij, uint *u)
{
    uint x = min(j, s - 1u), acc = 0u, pw = M;
    for (uint l = 0u; l < t; ++l) {  /* Horner from c_{t-1} down to c_0 */
        acc = gf_add(gf_mul(acc, x, s, gf, tabled), (i / pw) % s, s, gf, tabled);
        pw /= s;
    }
    *aij = (j == s) ? i / M : acc;
    *u = (j == s) ? i % M : i / s;
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

float bose(uint i, uint j, uint s, uint p, uint offset, float J, __global const ushort *gf, uint tabled)
{
    uint q = column_key(p, j, s + 1u);
    uint aij, aik;
    bose_cell(i, j % (s + 1u), s, gf, tabled, &aij, &aik);
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

float bush(uint i, uint j, uint s, uint t, uint p, uint offset, float J, __global const ushort *gf, uint tabled)
{
    uint q = column_key(p, j, s + 1u);
    uint M = pow_u(s, t - 1u);
    uint aij, u;
    bush_cell(i, j % (s + 1u), s, t, M, gf, tabled, &aij, &u);
    uint stratum = permute(aij, s, q * STRATUM_KEY);
    float sub = offset_sub(offset, u, M, i + 1u, aij, q * SUBSTRATUM_KEY);
    return oa_value(i, stratum, sub, q * JITTER_KEY, M, s, J);
}
