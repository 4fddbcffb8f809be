/* Orthogonal-array samplers of docs/spec.md section 5 (mirrors pyoa/reference/oa.py).
 * Offset codes OFFSET_* come from pyoa.constructions as -D build options.
 *
 * A value is the block rule (oa_locate: the copy's seed, the row and the
 * column), a construction's cell of (row, column) (the *_cell functions,
 * the only part a construction supplies) and one shared tail (oa_tail).
 * oa_dispatch, generated from the catalogue after generate.cl
 * (pyoa._opencl.program.dispatch_source), puts the three together. */

/* The block rule (docs/spec.md section 6): dimension j of sample i reads
 * column j % B of copy j / B, with seed P = pyoa_block_seed(p, j / B), at row
 * pyoa_block_row(i, N, pyoa_block_order_seed(P, j / B, N)): row i in block 0, the
 * copy's own order of the rows in later blocks. */
void oa_locate(uint p, uint i, uint j, uint B, uint N, uint *P, uint *row, uint *col)
{
    uint block = j / B;
    *col = j % B;
    *P = pyoa_block_seed(p, block);
    *row = pyoa_block_row(i, N, pyoa_block_order_seed(*P, block, N));
}

/* Bose over GF(s): A_ij of column j (< s+1) and A_ik of its partner column
 * k. The column-0/1/other choice is written with bit masks, not a ?: chain,
 * which LLVM turns into a switch that keeps PoCL from vectorizing
 * (docs/performance.md, lessons for PoCL); multipliers of columns 0 and 1 are clamped to 0 so that
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

/* x from the stratum, the integer sub-stratum and the jitter seed (row: the
 * jitter's randfloat index). */
float oa_value(uint i, uint stratum, uint sub, uint P3, uint M, uint s, float J, uint offset)
{
    float jit = pyoa_jitter_value(pyoa_randfloat(i, P3), J);
    return (offset == OFFSET_CENTERED) ? pyoa_centered_value(stratum, jit, M, s) : pyoa_sample_value(stratum, sub, jit, M, s);
}

/* sub-stratum of the offset styles that hash per cell ('j', 'mj') or per
 * column ('cmj'); 'centered' does not use it (see centered_value). cell_key
 * is the 'j' seed factor. */
uint offset_sub(uint offset, uint u, uint M, uint cell_key, uint aij, uint P2)
{
    if (offset == OFFSET_CENTERED) return 0u;  /* skip the cycle walk it would discard */
    uint seed = (offset == OFFSET_J) ? cell_key * P2 : (offset == OFFSET_MJ) ? (aij + 1u) * P2 : P2;
    return pyoa_permute(u, M, seed);
}

/* pow_u(s, e) = s^e; every use stays below 2^24. */
uint pow_u(uint s, uint e)
{
    uint r = 1u;
    for (uint k = 0u; k < e; ++k) r *= s;
    return r;
}

/* Addelman-Kempthorne: A_ij of column j < 2q+1 and the sub-stratum index u
 * (see reference.addelman_kempthorne). ak = [kappa, b[0..q), k[0..q), c[0..q)]
 * from pyoa.gf.ak_constants. Columns 1..q-1 use m = j, columns q..2q-1 use
 * m = j - q (k[0] = c[0] = 0 makes m = 0 column q); multipliers of other
 * columns are clamped to 0 so every lookup stays in range. */
void addelman_kempthorne_cell(uint i, uint j, uint q, __global const ushort *gf, uint tabled,
                              __global const uint *ak, uint *aij, uint *u)
{
    uint h = i / (q * q), x = (i / q) % q, y = i % q;
    uint x2 = gf_mul(x, x, q, gf, tabled);
    uint kappa = ak[0];
    uint mA = (j >= 1u && j < q) ? j : 0u;
    uint mB = (j >= q && j < 2u * q) ? j - q : 0u;
    uint colA = gf_add(gf_add(x, gf_mul(mA, y, q, gf, tabled), q, gf, tabled), h ? ak[1u + mA] : 0u, q, gf, tabled);
    uint kx = gf_mul(h ? ak[1u + q + mB] : mB, x, q, gf, tabled);
    uint sq = h ? gf_mul(kappa, x2, q, gf, tabled) : x2;
    uint colB = gf_add(gf_add(gf_add(y, kx, q, gf, tabled), sq, q, gf, tabled), h ? ak[1u + 2u * q + mB] : 0u, q, gf, tabled);
    *aij = (j == 0u) ? y : (j < q) ? colA : (j < 2u * q) ? colB : x;
    *u = h * q + ((j == 0u || (j >= q && j < 2u * q)) ? x : y);
}

/* Bose-Bush in GF(2s): column j < 2s is low_r(x * j) XOR k, column 2s is
 * x mod s, for row i = x s + k (see reference.bose_bush). */
void bose_bush_cell(uint i, uint j, uint s, __global const ushort *gf, uint tabled, uint *aij, uint *u)
{
    uint x = i / s, k = i % s;
    uint a = (gf_mul(x, min(j, 2u * s - 1u), 2u * s, gf, tabled) % s) ^ k;
    *aij = (j < 2u * s) ? a : x % s;
    *u = (j < 2u * s) ? x : (x / s) * s + k;
}

/* The common tail (docs/spec.md section 5.2): x of row `row` in column `col`
 * of the copy with seed P, from the construction's cell (A_ij, u) and the
 * 'j' offset's cell key. */
float oa_tail(uint row, uint col, uint P, uint aij, uint u, uint cell_key, uint s, uint M, uint offset, float J)
{
    uint q = P * (col + 1u);  /* times the three keys: the column's seeds (section 3.3) */
    uint stratum = pyoa_permute(aij, s, q * PYOA_STRATUM_KEY);
    uint sub = offset_sub(offset, u, M, cell_key, aij, q * PYOA_SUBSTRATUM_KEY);
    return oa_value(row, stratum, sub, q * PYOA_JITTER_KEY, M, s, J, offset);
}
