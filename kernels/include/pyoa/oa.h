/* pyoa/oa.h: the orthogonal-array samplers of docs/spec.md sections 4-6
 * (pyoa/reference/oa.py is the reference, value for value).
 *
 * A value is three parts:
 * - the block rule (section 6, pyoa_oa_locate): dimension j reads column
 *   j % B of the copy j / B, with that copy's seed and its own order of the
 *   rows;
 * - a construction's cell of (row, column): the entry A_ij, the sub-stratum
 *   index u and the 'j' offset's cell key ck (the pyoa_<name>_cell
 *   functions, sections 5.3-5.7, the only part a construction supplies; the
 *   catalogue's entries name them, pyoa/catalogue/constructions.py `kernel`);
 * - the common tail (section 5.2, pyoa_oa_tail): the column's seeds, the
 *   permuted stratum, the offset's sub-stratum, the jitter and the float.
 * pyoa_oa_value puts the three together for a construction's catalogue code
 * (PYOA_SAMPLER_<NAME> of pyoa/keys.h).
 *
 * Every cell function has the same signature, whatever it reads:
 *   (row, col, s, t, M, gf, tabled, consts, &aij, &u, &ck)
 * with s the order, t the strength, M = N / s, gf/tabled the field of
 * pyoa/gf.h and consts the construction's constants (Addelman-Kempthorne's,
 * pyoa_ak_fill of pyoa/tables.h; unused otherwise). */
#ifndef PYOA_OA_H
#define PYOA_OA_H

#include "config.h"
#include "floats.h"
#include "gf.h"
#include "hashes.h"
#include "keys.h"

/* The block rule (section 6): dimension j of sample i reads column j % B of
 * copy j / B, with seed P = block_seed(p, j / B), at row
 * block_row(i, N, block_order_seed(P, j / B, N)): row i in block 0, the
 * copy's own order of the rows in later blocks. */
PYOA_FN void pyoa_oa_locate(pyoa_u32 p, pyoa_u32 i, pyoa_u32 j, pyoa_u32 B, pyoa_u32 N,
                            pyoa_u32 *P, pyoa_u32 *row, pyoa_u32 *col)
{
    pyoa_u32 block = j / B;
    *col = j % B;
    *P = pyoa_block_seed(p, block);
    *row = pyoa_block_row(i, N, pyoa_block_order_seed(*P, block, N));
}

/* s^e; every use stays below 2^24 (N <= 2^24, section 7.8). */
PYOA_FN pyoa_u32 pyoa_pow_u(pyoa_u32 s, pyoa_u32 e)
{
    pyoa_u32 r = 1u;
    for (pyoa_u32 k = 0u; k < e; ++k) r *= s;
    return r;
}

/* Bose over GF(s) (section 5.3): N = s^2 rows i = a0 s + a1, s + 1
 * columns; A_i0 = a0, A_i1 = a1, A_ij = a0 + (j - 1) a1 for j >= 2. u is
 * the partner column's entry A_ik (k = j ^ 1), and ck = u s + A_ij + 1.
 * The column-0/1/other choice is written with bit masks, not a ?: chain,
 * which LLVM turns into a switch that keeps PoCL from vectorizing
 * (docs/performance.md, lessons for PoCL); the multipliers of columns 0 and
 * 1 are clamped to 0 so that table lookups stay in range for the lanes the
 * masks discard. */
PYOA_FN void pyoa_bose_cell(pyoa_u32 row, pyoa_u32 col, pyoa_u32 s, pyoa_u32 t, pyoa_u32 M,
                            PYOA_GLOBAL const pyoa_u16 *gf, pyoa_u32 tabled, PYOA_GLOBAL const pyoa_u32 *consts,
                            pyoa_u32 *aij, pyoa_u32 *u, pyoa_u32 *ck)
{
    pyoa_u32 a0 = row / s, a1 = row % s;
    pyoa_u32 k = (col & 1u) ? col - 1u : col + 1u;
    pyoa_u32 m0 = 0u - (pyoa_u32)(col == 0u), m1 = 0u - (pyoa_u32)(col == 1u), mg = ~(m0 | m1);
    pyoa_u32 mj = ((col - 1u) & mg) % s, mk = ((k - 1u) & mg) % s;
    (void)t, (void)M, (void)consts;
    *aij = (a0 & m0) | (a1 & m1) | (pyoa_gf_add(a0, pyoa_gf_mul(mj, a1, s, gf, tabled), s, gf, tabled) & mg);
    *u = (a1 & m0) | (a0 & m1) | (pyoa_gf_add(a0, pyoa_gf_mul(mk, a1, s, gf, tabled), s, gf, tabled) & mg);
    *ck = *u * s + *aij + 1u;
}

/* Bush (section 5.4): N = s^t rows, s + 1 columns. Row i's polynomial
 * sum_l c_l x^l (c_l the base-s digits of i) at x = j in GF(s) for j < s,
 * its leading coefficient i / M for j == s; u = i / s for j < s, i % M for
 * j == s; ck = i + 1. */
PYOA_FN void pyoa_bush_cell(pyoa_u32 row, pyoa_u32 col, pyoa_u32 s, pyoa_u32 t, pyoa_u32 M,
                            PYOA_GLOBAL const pyoa_u16 *gf, pyoa_u32 tabled, PYOA_GLOBAL const pyoa_u32 *consts,
                            pyoa_u32 *aij, pyoa_u32 *u, pyoa_u32 *ck)
{
    pyoa_u32 x = PYOA_MIN(col, s - 1u), acc = 0u, pw = M;
    (void)consts;
    for (pyoa_u32 l = 0u; l < t; ++l) { /* Horner from c_{t-1} down to c_0 */
        acc = pyoa_gf_add(pyoa_gf_mul(acc, x, s, gf, tabled), (row / pw) % s, s, gf, tabled);
        pw /= s;
    }
    *aij = (col == s) ? row / M : acc;
    *u = (col == s) ? row % M : row / s;
    *ck = row + 1u;
}

/* CMJND (section 5.5): N = s^t rows, t columns, any s >= 2: A_ij is digit j
 * of i in base s, u the number formed by the other digits; ck = i + 1. */
PYOA_FN void pyoa_cmjnd_cell(pyoa_u32 row, pyoa_u32 col, pyoa_u32 s, pyoa_u32 t, pyoa_u32 M,
                             PYOA_GLOBAL const pyoa_u16 *gf, pyoa_u32 tabled, PYOA_GLOBAL const pyoa_u32 *consts,
                             pyoa_u32 *aij, pyoa_u32 *u, pyoa_u32 *ck)
{
    pyoa_u32 sj = pyoa_pow_u(s, col);
    (void)t, (void)M, (void)gf, (void)tabled, (void)consts;
    *aij = (row / sj) % s;
    *u = row % sj + (row / (sj * s)) * sj;
    *ck = row + 1u;
}

/* Addelman-Kempthorne (section 5.6): N = 2q^2 rows i = h q^2 + x q + y,
 * 2q + 1 columns over GF(q), q odd. consts = [kappa, b[0..q), k[0..q),
 * c[0..q)] (pyoa_ak_fill). Columns 1..q-1 use m = j, columns q..2q-1 use
 * m = j - q (k[0] = c[0] = 0 makes m = 0 column q); the multipliers of
 * other columns are clamped to 0 so that every lookup stays in range;
 * ck = i + 1. */
PYOA_FN void pyoa_addelman_kempthorne_cell(pyoa_u32 row, pyoa_u32 col, pyoa_u32 s, pyoa_u32 t, pyoa_u32 M,
                                           PYOA_GLOBAL const pyoa_u16 *gf, pyoa_u32 tabled,
                                           PYOA_GLOBAL const pyoa_u32 *consts,
                                           pyoa_u32 *aij, pyoa_u32 *u, pyoa_u32 *ck)
{
    pyoa_u32 q = s;
    pyoa_u32 h = row / (q * q), x = (row / q) % q, y = row % q;
    pyoa_u32 x2 = pyoa_gf_mul(x, x, q, gf, tabled);
    pyoa_u32 kappa = consts[0];
    pyoa_u32 mA = (col >= 1u && col < q) ? col : 0u;
    pyoa_u32 mB = (col >= q && col < 2u * q) ? col - q : 0u;
    pyoa_u32 colA = pyoa_gf_add(pyoa_gf_add(x, pyoa_gf_mul(mA, y, q, gf, tabled), q, gf, tabled),
                                h ? consts[1u + mA] : 0u, q, gf, tabled);
    pyoa_u32 kx = pyoa_gf_mul(h ? consts[1u + q + mB] : mB, x, q, gf, tabled);
    pyoa_u32 sq = h ? pyoa_gf_mul(kappa, x2, q, gf, tabled) : x2;
    pyoa_u32 colB = pyoa_gf_add(pyoa_gf_add(pyoa_gf_add(y, kx, q, gf, tabled), sq, q, gf, tabled),
                                h ? consts[1u + 2u * q + mB] : 0u, q, gf, tabled);
    (void)t, (void)M;
    *aij = (col == 0u) ? y : (col < q) ? colA : (col < 2u * q) ? colB : x;
    *u = h * q + ((col == 0u || (col >= q && col < 2u * q)) ? x : y);
    *ck = row + 1u;
}

/* Bose-Bush (section 5.7): N = 2s^2 rows i = x s + k, 2s + 1 columns, in
 * GF(2s): column j < 2s is low_r(x * j) XOR k, column 2s is x mod s;
 * ck = i + 1. */
PYOA_FN void pyoa_bose_bush_cell(pyoa_u32 row, pyoa_u32 col, pyoa_u32 s, pyoa_u32 t, pyoa_u32 M,
                                 PYOA_GLOBAL const pyoa_u16 *gf, pyoa_u32 tabled, PYOA_GLOBAL const pyoa_u32 *consts,
                                 pyoa_u32 *aij, pyoa_u32 *u, pyoa_u32 *ck)
{
    pyoa_u32 x = row / s, k = row % s;
    pyoa_u32 a = (pyoa_gf_mul(x, PYOA_MIN(col, 2u * s - 1u), 2u * s, gf, tabled) % s) ^ k;
    (void)t, (void)M, (void)consts;
    *aij = (col < 2u * s) ? a : x % s;
    *u = (col < 2u * s) ? x : (x / s) * s + k;
    *ck = row + 1u;
}

/* The sub-stratum of the offset styles (section 4) that hash per cell
 * ('j': seed ck * P2), per stratum ('mj': (A_ij + 1) * P2) or per column
 * ('cmj': P2); 'centered' does not use it (pyoa_centered_value). */
PYOA_FN pyoa_u32 pyoa_offset_sub(pyoa_u32 offset, pyoa_u32 u, pyoa_u32 M, pyoa_u32 ck, pyoa_u32 aij, pyoa_u32 P2)
{
    pyoa_u32 seed;
    if (offset == PYOA_OFFSET_CENTERED) return 0u; /* skip the cycle walk it would discard */
    seed = (offset == PYOA_OFFSET_J) ? ck * P2 : (offset == PYOA_OFFSET_MJ) ? (aij + 1u) * P2 : P2;
    return pyoa_permute(u, M, seed);
}

/* The common tail (section 5.2): x of row `row` in column `col` of the copy
 * with seed P, from the cell (A_ij, u, ck): the column's seeds q * KEY
 * (section 3.3), the permuted stratum, the offset's sub-stratum, the jitter
 * of section 3.4 (its randfloat index is the row) and section 7's float. */
PYOA_FN float pyoa_oa_tail(pyoa_u32 row, pyoa_u32 col, pyoa_u32 P, pyoa_u32 aij, pyoa_u32 u, pyoa_u32 ck,
                           pyoa_u32 s, pyoa_u32 M, pyoa_u32 offset, float J)
{
    pyoa_u32 q = P * (col + 1u);
    pyoa_u32 stratum = pyoa_permute(aij, s, q * PYOA_STRATUM_KEY);
    pyoa_u32 sub = pyoa_offset_sub(offset, u, M, ck, aij, q * PYOA_SUBSTRATUM_KEY);
    float jit = pyoa_jitter_value(pyoa_randfloat(row, q * PYOA_JITTER_KEY), J);
    return (offset == PYOA_OFFSET_CENTERED) ? pyoa_centered_value(stratum, jit, M, s)
                                            : pyoa_sample_value(stratum, sub, jit, M, s);
}

/* Dimension j of sample i (i < N) of the array with seed p (the pixel's
 * seed, section 3.1) of construction `code` (PYOA_SAMPLER_<NAME>), order s,
 * strength t, B columns per block, N rows, M = N / s, an offset code
 * (PYOA_OFFSET_<NAME>) and jitter amount J in [0, 1]. A code that is not an
 * orthogonal array gives NaN, never another construction's value. */
PYOA_FN float pyoa_oa_value(pyoa_u32 code, pyoa_u32 i, pyoa_u32 j, pyoa_u32 s, pyoa_u32 t, pyoa_u32 B, pyoa_u32 N,
                            pyoa_u32 M, pyoa_u32 p, pyoa_u32 offset, float J, PYOA_GLOBAL const pyoa_u16 *gf,
                            pyoa_u32 tabled, PYOA_GLOBAL const pyoa_u32 *consts)
{
    pyoa_u32 P, row, col, aij = 0u, u = 0u, ck = 0u;
    pyoa_oa_locate(p, i, j, B, N, &P, &row, &col);
    switch (code) {
    case PYOA_SAMPLER_BOSE: pyoa_bose_cell(row, col, s, t, M, gf, tabled, consts, &aij, &u, &ck); break;
    case PYOA_SAMPLER_BUSH: pyoa_bush_cell(row, col, s, t, M, gf, tabled, consts, &aij, &u, &ck); break;
    case PYOA_SAMPLER_CMJND: pyoa_cmjnd_cell(row, col, s, t, M, gf, tabled, consts, &aij, &u, &ck); break;
    case PYOA_SAMPLER_ADDELMAN_KEMPTHORNE:
        pyoa_addelman_kempthorne_cell(row, col, s, t, M, gf, tabled, consts, &aij, &u, &ck); break;
    case PYOA_SAMPLER_BOSE_BUSH: pyoa_bose_bush_cell(row, col, s, t, M, gf, tabled, consts, &aij, &u, &ck); break;
    default: return PYOA_AS_F32(0x7fc00000u); /* not an orthogonal array: NaN */
    }
    return pyoa_oa_tail(row, col, P, aij, u, ck, s, M, offset, J);
}

#endif /* PYOA_OA_H */
