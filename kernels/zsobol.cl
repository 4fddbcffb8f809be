/* zsobol: pbrt-v4's ZSobolSampler with pyoa's hashes (mirrors
 * pyoa/reference/zsobol.py, which holds the mathematics and references, and
 * pyoa/_numpy/zsobol.py). Uses hash_pair (pyoa/hashes.h) and unit24,
 * reverse_bits, owen_scramble (baselines.cl). Values are k * 2^-24 with k a
 * 24-bit integer: exact in float, no rounding. */

/* PYOA_ZSOBOL_KEY (pyoa/reference/zsobol.py) and PYOA_OWEN_KEY (baselines.py) come
 * from pyoa/keys.h, generated from those constants, their only definition. */

/* pbrt-v4's MixBits: a bijective avalanche hash of a ulong. */
ulong mix64(ulong v)
{
    v ^= v >> 31; v *= 0x7fb5d329728ea185ul;
    v ^= v >> 27; v *= 0x81dadef4bc2dd44dul;
    v ^= v >> 33;
    return v;
}

/* Bit t of a 16-bit value to bit 2t. */
uint morton_spread16(uint v)
{
    v &= 0x0000ffffu;
    v = (v | (v << 8)) & 0x00ff00ffu;
    v = (v | (v << 4)) & 0x0f0f0f0fu;
    v = (v | (v << 2)) & 0x33333333u;
    v = (v | (v << 1)) & 0x55555555u;
    return v;
}

/* pbrt's EncodeMorton2 for x, y < 2^16: x in the even bits, y in the odd. */
uint morton2(uint x, uint y) { return morton_spread16(x) | (morton_spread16(y) << 1); }

/* PERMS[p][digit] of pyoa/reference/zsobol.py (the 24 permutations of
 * {0,1,2,3} in lexicographic order) without a table in memory: permutation
 * p is the byte PERMS[p][0] | PERMS[p][1] << 2 | PERMS[p][2] << 4 |
 * PERMS[p][3] << 6, bytes 8 at a time in three ulong literals. */
uint zsobol_perm(uint p, uint digit)
{
    ulong w = p < 8u ? 0xb1e16c9c78d8b4e4ul : p < 16u ? 0x36c672d22d8d39c9ul : 0x1b4b278763931e4eul;
    return (uint)(w >> (8u * (p & 7u) + 2u * digit)) & 3u;
}

/* The low 32 bits of the permuted index g of sample i of `pixel` for the
 * pair with key q (pbrt's GetSampleIndex, the reference's permute_digits).
 * Digits at bit 32 and above are skipped (their bits are dropped), but every
 * hash reads the whole Morton index m < 2^56. */
uint zsobol_index(uint i, uint log2n, uint log2res, uint width, uint pixel, uint q)
{
    uint x = pixel % width, y = (pixel / width) & 0xffffu;
    ulong m = ((ulong)morton2(x, y) << log2n) | (ulong)i;
    ulong key = 0x55555555ul * (ulong)q;
    int odd = (int)(log2n & 1u);
    /* d = D-1 down to odd, D = log2res + ceil(log2n / 2); shift = 2d - odd < 32 <=> d <= 15 + odd */
    int top = min((int)(log2res + (log2n + 1u) / 2u) - 1, 15 + odd);
    uint g = 0u;
    for (int d = top; d >= odd; --d) {
        uint shift = (uint)(2 * d - odd);
        uint digit = (uint)(m >> shift) & 3u;
        ulong higher = m >> (shift + 2u);  /* the unpermuted digits above this one */
        uint p = (uint)((mix64(higher ^ key) >> 24) % 24ul);
        g |= zsobol_perm(p, digit) << shift;
    }
    if (odd) g |= ((uint)m & 1u) ^ ((uint)mix64((m >> 1) ^ key) & 1u);
    return g;
}

/* The first two Sobol' dimensions without a table: dimension 0's direction
 * numbers are v_k = 2^(31-k) (bit reversal), dimension 1's are
 * v_0 = 2^31, v_(k+1) = v_k ^ (v_k >> 1) (Pascal's triangle mod 2), the
 * rows 0 and 1 of pyoa.sequences.sobol_matrices(). */
uint zsobol_sobol_bits(uint g, uint c)
{
    if (c == 0u) return reverse_bits(g);
    uint x = 0u;
    for (uint v = 0x80000000u; g; g >>= 1, v ^= v >> 1)
        if (g & 1u) x ^= v;
    return x;
}

float sample_zsobol(uint i, uint j, uint log2n, uint log2res, uint width, uint pixel, uint seed)
{
    uint c = j & 1u;
    uint q = pyoa_hash_pair(seed, j >> 1, PYOA_ZSOBOL_KEY);
    uint g = zsobol_index(i, log2n, log2res, width, pixel, q);
    return unit24(owen_scramble(zsobol_sobol_bits(g, c), pyoa_hash_pair(q, 1u + c, PYOA_OWEN_KEY)));
}
