/* The comparison samplers (mirrors pyoa/reference/baselines.py, which holds
 * the mathematics and references). Values of random, sobol02, halton and
 * sobol are k * 2^-24 with k a 24-bit integer: exact in float, no rounding. */

/* The PYOA_*_KEY constants come from pyoa/keys.h (kernels/include), generated
 * from the constants of pyoa/reference/baselines.py, their only definition. */

float unit24(uint h) { return convert_float(h >> 8) * 0x1.0p-24f; }

uint derived_seed(uint p, uint index, uint key) { return p ? pyoa_hash_pair(p, index, key) : 0u; }

uint reverse_bits(uint x)
{
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
}

/* Burley's Laine-Karras-style hash: even multipliers, so output bit k
 * depends only on input bits <= k. */
uint laine_karras(uint x, uint seed)
{
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

/* Hash-based Owen scrambling of a 32-bit fraction; seed 0 = identity. */
uint owen_scramble(uint x, uint seed)
{
    uint y = reverse_bits(laine_karras(reverse_bits(x), seed));
    return seed ? y : x;
}

/* XOR of one dimension's 32 direction numbers over the set bits of g. */
uint sobol_bits(uint g, __global const uint *v)
{
    uint x = 0u;
    for (uint k = 0u; g; ++k, g >>= 1)
        if (g & 1u) x ^= v[k];
    return x;
}

float sample_random(uint i, uint j, uint p)
{
    return unit24(pyoa_mix32(i ^ pyoa_hash_pair(p, j, PYOA_RANDOM_KEY)));
}

float sample_jittered2d(uint i, uint j, uint m, uint dims, uint p, float J)
{
    uint q = derived_seed(p, j >> 1, PYOA_PAD_KEY);
    uint N = m * m;
    uint k = pyoa_permute(i, N, q * PYOA_SHUFFLE_KEY);
    bool even = (j & 1u) == 0u;
    float jit = pyoa_jitter_value(pyoa_randfloat(k, q * (even ? PYOA_JITX_KEY : PYOA_JITY_KEY)), J);
    if (even && j + 1u == dims) return pyoa_sample_value(k, 0u, jit, 1u, N);  /* a lone last dimension */
    return pyoa_sample_value(even ? k % m : k / m, 0u, jit, 1u, m);
}

float sample_cmj2d(uint i, uint j, uint m, uint n, uint p, float J)
{
    uint q = derived_seed(p, j >> 1, PYOA_PAD_KEY);
    uint k = pyoa_permute(i, m * n, q * PYOA_SHUFFLE_KEY);
    uint sx = pyoa_permute(k % m, m, q * PYOA_SUBX_KEY);
    if ((j & 1u) == 0u) {
        uint sy = pyoa_permute(k / m, n, q * PYOA_SUBY_KEY);
        return pyoa_sample_value(k % m, sy, pyoa_jitter_value(pyoa_randfloat(k, q * PYOA_JITX_KEY), J), n, m);
    }
    return pyoa_sample_value(k / m, sx, pyoa_jitter_value(pyoa_randfloat(k, q * PYOA_JITY_KEY), J), m, n);
}

float sample_sobol02(uint i, uint j, uint log2n, uint p, __global const uint *directions)
{
    uint q = derived_seed(p, j >> 1, PYOA_PAD_KEY);
    /* hashed scramble seeds: Burley's top levels depend on a seed's low bits only */
    uint g = owen_scramble(i, derived_seed(q, 0u, PYOA_OWEN_KEY)) & ((1u << log2n) - 1u);
    uint c = j & 1u;
    return unit24(owen_scramble(sobol_bits(g, directions + 32u * c), derived_seed(q, 1u + c, PYOA_OWEN_KEY)));
}

float sample_halton(uint i, uint j, uint p, __global const uint *primes)
{
    uint b = primes[j];
    uint q = derived_seed(p, j, PYOA_HALTON_KEY);
    uint rest = i, prefix = 0u;
    ulong numer = 0ul, power = 1ul;  /* power = b^(k-1) */
    while (power < 0x1000000ul) {
        uint d = rest % b;
        rest /= b;
        uint dd = q ? pyoa_permute(d, b, pyoa_hash_pair(q, (uint)power + prefix, PYOA_DIGIT_KEY)) : d;
        numer = numer * b + dd;
        prefix += d * (uint)power;
        power *= b;
    }
    return convert_float((uint)((numer << 24) / power)) * 0x1.0p-24f;
}

float sample_sobol(uint i, uint j, uint p, __global const uint *directions)
{
    uint x = sobol_bits(i ^ (i >> 1), directions + 32u * j);
    return unit24(owen_scramble(x, derived_seed(p, j, PYOA_SOBOL_KEY)));
}
