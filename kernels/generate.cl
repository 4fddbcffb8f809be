/* Bulk generation. A request is rows = (pixel, sample) pairs, each of n_dims
 * values, written row-major into out[out0 + (row - row0) * n_dims + d]; a
 * launch covers the rows [row0, row0 + n_values / n_dims). Global sizes are padded to
 * a multiple of the work-group size, hence the bounds checks.
 *
 * Row indices inside a launch are 32-bit and relative to the first pixel of
 * the launch (the host uploads only that launch's pixels): 64-bit divisions
 * made PoCL's cost model refuse to vectorize.
 *
 * Two paths, the same bits:
 * - generate: one work-item per value, everything from scratch (any offset);
 * - tables + generate_cells ('cmj' and 'centered', every construction): the
 *   permutations that do not depend on the sample are computed once per
 *   (pixel, dimension) into a table, then a loop-free kernel that PoCL can
 *   vectorize reads them (POCL-NOTES.md: a cycle-walking loop in a kernel
 *   keeps PoCL scalar). Table entry layout per (pixel, dimension), E entries:
 *   [0, s) stratum permutation, [s, s + M) sub-stratum permutation ('cmj'
 *   only), [E - 1] the jitter seed P3. */

__kernel void generate(__global float *out,
                       const uint out0,
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
    out[out0 + gid] = x;
}

/* The table path, in two launches over a rectangle of pixels x samples
 * (whole pixels, or a sample range of one pixel). Both use a 2D NDRange whose
 * second axis is pd = (pixel within the launch) * n_dims + d, so that
 * everything derived from (pixel, dimension) is uniform across the first
 * axis: PoCL hoists it out of its work-item loop and vectorizes that loop 8
 * wide (docs/performance.md measured 3x over a 1D range with a division per
 * work-item). The host launches exactly E (or n_k) x n_pd work-items, so
 * neither kernel has a bounds check: one makes the loads conditional, and
 * PoCL then neither hoists the uniform ones nor vectorizes. */

/* tables: axis 0 is the entry e of (pixel, dimension) pd's table. keys holds
 * per pd the column key q and the final shifts q * STRATUM_KEY % s and
 * q * SUBSTRATUM_KEY % M (pyoa._numpy.oa.table_keys): computed on the host,
 * they cost PoCL more here than the cycle walks themselves, even as loop
 * invariants (docs/performance.md). */
__kernel void tables(__global uint *tab,
                     __global const uint *keys,
                     const uint E,
                     const uint s,
                     const uint M)
{
    uint e = (uint)get_global_id(0), pd = (uint)get_global_id(1);
    uint q = keys[3u * pd], cS = keys[3u * pd + 1u], cU = keys[3u * pd + 2u];
    /* permute(i, l, p) = (walk(i) + p % l) % l with walk(i) < l, so the last
     * % is a subtraction. The jitter-seed slot walks from 0: a walk must
     * start in [0, l), or it may never return there. */
    uint stratum = e < s;
    uint l = stratum ? s : M, p = q * (stratum ? STRATUM_KEY : SUBSTRATUM_KEY), c = stratum ? cS : cU;
    uint i = stratum ? e : (e + 1u == E) ? 0u : e - s;
    uint x = permute_walk(i, l, p, walk_mask(l)) + c;
    x = (x >= l) ? x - l : x;
    tab[pd * E + e] = (e + 1u == E) ? q * JITTER_KEY : p ? x : i;
}

/* generate_cells: axis 0 is the sample position k in [0, n_k). The cells
 * (A_ij and the sub-stratum index u of every requested dimension and sample)
 * do not depend on the pixel; the host computes them once per launch
 * (pyoa._numpy.oa.cells), laid out [d][k], so that every construction shares
 * this one straight-line kernel and its loads along k are contiguous.
 * 'centered' passes cell_u = 0 and reads (and ignores) slot s. */
__kernel void generate_cells(__global float *out,
                             const uint out0,
                             __global const uint *tab,
                             __global const uint *cell_a,
                             __global const uint *cell_u,
                             __global const uint *isamp,
                             const uint n_k,
                             const uint n_dims,
                             const uint E,
                             const uint s,
                             const uint M,
                             const uint offset,
                             const float J)
{
    uint k = (uint)get_global_id(0), pd = (uint)get_global_id(1);
    uint d = pd % n_dims, pl = pd / n_dims, base = pd * E;
    uint c = d * n_k + k;
    float sub = (offset == OFFSET_CMJ) ? convert_float(tab[base + s + cell_u[c]]) : 0.5f * convert_float(M - 1u);
    out[out0 + (pl * n_k + k) * n_dims + d] = oa_value(isamp[k], tab[base + cell_a[c]], sub, tab[base + E - 1u], M, s, J);
}

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
