/* Bulk generation. A request is rows = (pixel, sample) pairs, each of n_dims
 * values, written row-major into out[(row - row0) * n_dims + d]; a launch
 * covers the rows [row0, row0 + n_values / n_dims). Global sizes are padded to
 * a multiple of the work-group size, hence the bounds checks.
 *
 * Row indices inside a launch are 32-bit and relative to the first pixel of
 * the launch (the host uploads only that launch's pixels): 64-bit divisions
 * made PoCL's cost model refuse to vectorize.
 *
 * Two paths, the same bits:
 * - generate: one work-item per value, everything from scratch (any offset);
 * - tables + generate_tabled_{bose,cmjnd} ('cmj' and 'centered'): the
 *   permutations that do not depend on the sample are computed once per
 *   (pixel, dimension) into a table, then a loop-free kernel that PoCL can
 *   vectorize reads them (POCL-NOTES.md: a cycle-walking loop in a kernel
 *   keeps PoCL scalar). Table entry layout per (pixel, dimension), E entries:
 *   [0, s) stratum permutation, [s, s + M) sub-stratum permutation ('cmj'
 *   only), [E - 1] the jitter seed P3. */

__kernel void generate(__global float *out,
                       __global const uint *pixels,
                       __global const uint *samples,
                       __global const uint *dims,
                       const uint n_samples,
                       const uint n_dims,
                       const uint row0,
                       const uint n_values,
                       const uint seed,
                       const uint construction,
                       const uint s,
                       const uint t,
                       const uint offset,
                       const float J,
                       __global const ushort *gf,
                       const uint gf_tabled,
                       __global const uint *consts)
{
    uint gid = (uint)get_global_id(0);
    if (gid >= n_values) return;
    uint row = row0 + gid / n_dims;
    uint dim = dims[gid % n_dims];
    uint i = samples[row % n_samples];
    uint p = pixel_seed(seed, pixels[row / n_samples]);
    float x;
    if (construction == CONSTRUCTION_BOSE)      x = bose(i, dim, s, p, offset, J, gf, gf_tabled);
    else if (construction == CONSTRUCTION_BUSH) x = bush(i, dim, s, t, p, offset, J, gf, gf_tabled);
    else if (construction == CONSTRUCTION_ADDELMAN_KEMPTHORNE)
        x = addelman_kempthorne(i, dim, s, p, offset, J, gf, gf_tabled, consts);
    else if (construction == CONSTRUCTION_BOSE_BUSH) x = bose_bush(i, dim, s, p, offset, J, gf, gf_tabled);
    else                                        x = cmjnd(i, dim, s, t, p, offset, J);
    out[gid] = x;
}

/* One work-item per table entry of the uploaded pixels. */
__kernel void tables(__global uint *tab,
                     __global const uint *pixels,
                     __global const uint *dims,
                     const uint n_entries,
                     const uint n_dims,
                     const uint E,
                     const uint seed,
                     const uint dmax,
                     const uint s,
                     const uint M)
{
    uint gid = (uint)get_global_id(0);
    if (gid >= n_entries) return;
    uint e = gid % E, pd = gid / E;
    uint q = column_key(pixel_seed(seed, pixels[pd / n_dims]), dims[pd % n_dims], dmax);
    tab[gid] = (e < s) ? permute(e, s, q * STRATUM_KEY)
             : (e + 1u < E) ? permute(e - s, M, q * SUBSTRATUM_KEY)
             : q * JITTER_KEY;
}

/* The table-driven value kernels; CELL computes aij and u (the sub-stratum
 * index) from i and the column col (CMJND reads s^col from `powers`). */
#define GENERATE_TABLED(NAME, CELL)                                                     \
__kernel void NAME(__global float *out,                                                 \
                   __global const uint *tab,                                            \
                   __global const uint *samples,                                        \
                   __global const uint *dims,                                           \
                   __global const uint *powers,                                         \
                   const uint n_samples,                                                \
                   const uint n_dims,                                                   \
                   const uint row0,                                                     \
                   const uint n_values,                                                 \
                   const uint E,                                                        \
                   const uint dmax,                                                     \
                   const uint s,                                                        \
                   const uint M,                                                        \
                   const uint t,                                                        \
                   const uint offset,                                                   \
                   const float J,                                                       \
                   __global const ushort *gf,                                           \
                   const uint gf_tabled,                                                \
                   __global const uint *consts)                                         \
{                                                                                       \
    uint gid = (uint)get_global_id(0);                                                  \
    if (gid >= n_values) return;                                                        \
    uint row = row0 + gid / n_dims;                                                     \
    uint d = gid % n_dims;                                                              \
    uint i = samples[row % n_samples];                                                  \
    uint base = ((row / n_samples) * n_dims + d) * E;                                   \
    uint col = dims[d] % dmax;                                                          \
    uint aij, u;                                                                        \
    CELL;                                                                               \
    /* 'centered' reads slot s (present in every table) and ignores it. */              \
    float sub = (offset == OFFSET_CMJ) ? convert_float(tab[base + s + (offset == OFFSET_CMJ ? u : 0u)]) \
                                       : 0.5f * convert_float(M - 1u);                  \
    out[gid] = oa_value(i, tab[base + aij], sub, tab[base + E - 1u], M, s, J);          \
}

GENERATE_TABLED(generate_tabled_bose, bose_cell(i, col, s, gf, gf_tabled, &aij, &u))
GENERATE_TABLED(generate_tabled_bush, bush_cell(i, col, s, t, M, gf, gf_tabled, &aij, &u))
GENERATE_TABLED(generate_tabled_cmjnd, cmjnd_cell(i, s, powers[col], &aij, &u))
GENERATE_TABLED(generate_tabled_addelman_kempthorne,
                addelman_kempthorne_cell(i, col, s, gf, gf_tabled, consts, &aij, &u))
GENERATE_TABLED(generate_tabled_bose_bush, bose_bush_cell(i, col, s, gf, gf_tabled, &aij, &u))

/* The comparison samplers: one kernel each, one work-item per value. a and b
 * are the sampler's shape arguments (Baseline.shape_args), `table` its
 * constants (Halton's primes, Sobol's direction numbers). */
#define GENERATE_BASELINE(NAME, EXPR)                                                   \
__kernel void generate_##NAME(__global float *out,                                      \
                              __global const uint *pixels,                              \
                              __global const uint *samples,                             \
                              __global const uint *dims,                                \
                              const uint n_samples,                                     \
                              const uint n_dims,                                        \
                              const uint row0,                                          \
                              const uint n_values,                                      \
                              const uint seed,                                          \
                              const uint a,                                             \
                              const uint b,                                             \
                              const float J,                                            \
                              __global const uint *table)                               \
{                                                                                       \
    uint gid = (uint)get_global_id(0);                                                  \
    if (gid >= n_values) return;                                                        \
    uint row = row0 + gid / n_dims;                                                     \
    uint j = dims[gid % n_dims];                                                        \
    uint i = samples[row % n_samples];                                                  \
    uint p = pixel_seed(seed, pixels[row / n_samples]);                                 \
    out[gid] = EXPR;                                                                    \
}

GENERATE_BASELINE(random, sample_random(i, j, p))
GENERATE_BASELINE(jittered2d, sample_jittered2d(i, j, a, b, p, J))
GENERATE_BASELINE(cmj2d, sample_cmj2d(i, j, a, b, p, J))
GENERATE_BASELINE(sobol02, sample_sobol02(i, j, a, p, table))
GENERATE_BASELINE(halton, sample_halton(i, j, p, table))
GENERATE_BASELINE(sobol, sample_sobol(i, j, p, table))
