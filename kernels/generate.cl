/* Bulk generation. A request is rows = (pixel, sample) pairs, each of n_dims
 * values, written row-major; each launch fills one rectangle of it (see
 * below) starting at out[out0]. The values are those of the portable
 * headers (include/pyoa: pyoa_oa_value of oa.h, pyoa_baseline_value of
 * values.h), which pyoa._opencl.program puts before this file.
 *
 * Two paths for the orthogonal arrays, the same bits:
 * - generate: one work-item per value, everything from scratch (any offset);
 * - tables + tables_finish + generate_cells ('cmj' and 'centered', every
 *   construction): the permutations that do not depend on the sample are
 *   computed once per (pixel, dimension) into a table, then a loop-free
 *   kernel that PoCL can vectorize reads them (docs/performance.md, lessons for PoCL: a cycle-walking
 *   loop in a kernel keeps PoCL scalar). Table entry layout per (pixel,
 *   dimension), E entries: [0, s) stratum permutation, [s, s + M)
 *   sub-stratum permutation ('cmj' only), [E - 1] the jitter seed P3.
 * The comparison samplers have one kernel each (generate_<name>, at the end
 * of this file). */

/* Every kernel runs over a rectangle of the request (whole pixels, or a run
 * of samples of one pixel) as a 2D NDRange: axis 0 is the sample position k
 * in [0, n_k) (`samples` holds the rectangle's sample indices), axis 1 is
 * pd = (pixel within the rectangle) * n_dims + d. Everything that depends on
 * (pixel, dimension) is then uniform along axis 0, where PoCL builds its
 * work-item loop; no work-item divides a flat index. The host launches
 * exactly n_k x n_pd work-items (no bounds checks: one makes loads
 * conditional, and PoCL then neither hoists nor vectorizes). */
#define RECT_ARGS                                                                       \
    __global float *restrict out, const uint out0,                                      \
    __global const uint *restrict pixels, __global const uint *restrict samples,        \
    __global const uint *restrict dims, const uint n_k, const uint n_dims

/* The index of value (k, pd) in `out`. Its stride along k is n_dims. Written
 * as k * n_dims, LLVM versions the work-item loop on "n_dims == 1" and runs
 * the scalar copy for every other n_dims (2x slower, docs/performance.md);
 * with the top bit set in the multiplier and masked off again it sees no
 * plain stride. The mask is exact: k * n_dims < 2^31 (a launch writes fewer
 * values). */
uint rect_index(uint out0, uint k, uint pl, uint d, uint n_k, uint n_dims)
{
    return out0 + pl * n_k * n_dims + ((k * (n_dims | 0x80000000u)) & 0x7fffffffu) + d;
}

#define RECT_PRELUDE                                                                    \
    uint k = (uint)get_global_id(0), pd = (uint)get_global_id(1);                       \
    uint d = pd % n_dims, pl = pd / n_dims;                                             \
    uint i = samples[k], j = dims[d], pixel = pixels[pl];                               \
    uint p = pyoa_pixel_seed(seed, pixel)

/* The direct path: any offset, everything from scratch (permute's cycle walk
 * keeps this kernel scalar on PoCL). */
__kernel void generate(RECT_ARGS,
                       const uint seed,
                       const uint construction,
                       const uint s,
                       const uint t,
                       const uint B,
                       const uint N,
                       const uint M,
                       const uint offset,
                       const float J,
                       __global const ushort *gf,
                       const uint gf_tabled,
                       __global const uint *consts)
{
    RECT_PRELUDE;
    out[rect_index(out0, k, pl, d, n_k, n_dims)] = pyoa_oa_value(construction, i, j, s, t, B, N, M, p, offset, J,
                                                                 gf, gf_tabled, consts);
}

/* The table path, in two launches over a rectangle of pixels x samples
 * (whole pixels, or a sample range of one pixel). Both use a 2D NDRange whose
 * second axis is pd = (pixel within the launch) * n_dims + d, so that
 * everything derived from (pixel, dimension) is uniform across the first
 * axis: PoCL hoists it out of its work-item loop and vectorizes that loop 8
 * wide (docs/performance.md: 77 -> 173 M values/s over a 1D range with a
 * division per work-item). The host launches exactly E (or n_k) x n_pd work-items, so
 * neither kernel has a bounds check: one makes the loads conditional, and
 * PoCL then neither hoists the uniform ones nor vectorizes. */

/* tables: axis 0 is the entry e of (pixel, dimension) pd's table, whose E
 * entries start at pd * Es: Es is E rounded up to a multiple of 8, so that
 * the axis is whole 8-lane vectors (PoCL runs a remainder scalar; with E = 23
 * the 7 scalar lanes cost more than the 16 vector ones). The padding entries
 * are written with 0 and never read. keys holds
 * per pd the column key q and the final shifts q * PYOA_STRATUM_KEY % s and
 * q * PYOA_SUBSTRATUM_KEY % M (pyoa._numpy.oa.table_keys): computed on the host,
 * they cost PoCL more here than the cycle walks themselves, even as loop
 * invariants (docs/performance.md).
 *
 * pyoa_permute(i, l, p) = (walk(i) + p % l) % l with walk(i) < l, so the last %
 * is a subtraction. A loop keeps PoCL from vectorizing a kernel, so the walk
 * runs in two launches: `tables` takes 3 rounds for every entry
 * (straight-line, 8 lanes wide), which ends the walk of most entries, and
 * stores the others' walk state with WALK_PENDING set; `tables_finish`
 * walks those on to the end (a loop, but over few entries). The jitter-seed
 * slot walks from 0: a walk must start in [0, l), or it may never return. */
#define WALK_PENDING 0x80000000u

__attribute__((always_inline)) uint walk_step(uint x, uint l, uint p, uint w)
{
    uint y = pyoa_permute_round(x, p, w);
    return (x < l) ? x : y;
}

__kernel void tables(__global uint *restrict tab,
                     __global const uint *restrict keys,
                     const uint E,
                     const uint Es,
                     const uint s,
                     const uint M)
{
    uint e = (uint)get_global_id(0), pd = (uint)get_global_id(1);
    uint q = keys[3u * pd], cS = keys[3u * pd + 1u], cU = keys[3u * pd + 2u];
    uint wS = pyoa_walk_mask(s), wU = pyoa_walk_mask(M);
    uint stratum = e < s;
    uint l = stratum ? s : M, p = q * (stratum ? PYOA_STRATUM_KEY : PYOA_SUBSTRATUM_KEY), c = stratum ? cS : cU;
    uint w = stratum ? wS : wU;
    uint i = stratum ? e : (e + 1u >= E) ? 0u : e - s;
    /* 3 rounds, written out: a loop, even of constant trip count, is still
     * there when PoCL builds its work-item loop */
    uint x = walk_step(walk_step(pyoa_permute_round(i, p, w), l, p, w), l, p, w);
    uint v = x + c;
    v = (x >= l) ? (x | WALK_PENDING) : (v >= l) ? v - l : v;
    tab[pd * Es + e] = (e + 1u == E) ? q * PYOA_JITTER_KEY : (e >= E) ? 0u : p ? v : i;
}

/* Finishes the walks `tables` left pending (same launch shape). Entries
 * below l never have WALK_PENDING set (l <= 2^31), and the jitter slot is
 * skipped by position, so a finished entry is never touched again. */
__kernel void tables_finish(__global uint *restrict tab,
                            __global const uint *restrict keys,
                            const uint E,
                            const uint Es,
                            const uint s,
                            const uint M)
{
    uint e = (uint)get_global_id(0), pd = (uint)get_global_id(1);
    uint g = pd * Es + e, v = tab[g];
    if (!(v & WALK_PENDING) || e + 1u >= E) return;
    uint q = keys[3u * pd];
    uint stratum = e < s;
    uint l = stratum ? s : M, p = q * (stratum ? PYOA_STRATUM_KEY : PYOA_SUBSTRATUM_KEY);
    uint x = pyoa_permute_walk(v & ~WALK_PENDING, l, p, pyoa_walk_mask(l)) + keys[3u * pd + (stratum ? 1u : 2u)];
    tab[g] = (x >= l) ? x - l : x;
}

/* The values of the table path: axis 0 is the sample position k in [0, n_k),
 * axis 1 pd. Each value gathers its stratum (and 'cmj' sub-stratum) from its
 * (pixel, dimension)'s table at its cell, A_ij and u, from cell_a and
 * cell_u; LOCATE sets the cell's index c in them and the row the jitter
 * hashes (section 6), from the kernel's own arguments (__VA_ARGS__, between
 * the cells and n_k). Two instances:
 *
 * - generate_cells (every dimension in block 0): the cells do not depend on
 *   the pixel; the host computes them once per launch (pyoa.host_tables.cells),
 *   laid out [d][k], so that every construction shares these straight-line
 *   kernels and their loads along k are contiguous; isamp holds the sample
 *   indices (the rows of block 0).
 * - generate_rows (some dimension past block 0): a later block reads its copy
 *   at its own rows, so its cells depend on the pixel. `rows` holds the row
 *   of every sample position per slot: slot 0 (offset 0) the sample indices
 *   themselves (block 0, shared by every pixel), then one slot per (pixel,
 *   block >= 1) filled by block_rows; ro[pd] is the offset of (pixel,
 *   dimension) pd's slot. cell_a and cell_u hold the cells of every row of
 *   the array in each requested dimension's column ([d][row],
 *   pyoa.host_tables.array_cells), so one gather serves both. */
#define GENERATE_TABLED(NAME, LOCATE, VALUE, ...)                                       \
__kernel void NAME(__global float *restrict out,                                        \
                   const uint out0,                                                     \
                   __global const uint *restrict tab,                                   \
                   __global const uint *restrict cell_a,                                \
                   __global const uint *restrict cell_u,                                \
                   __VA_ARGS__,                                                         \
                   const uint n_k,                                                      \
                   const uint n_dims,                                                   \
                   const uint E,                                                        \
                   const uint Es,                                                       \
                   const uint s,                                                        \
                   const uint M,                                                        \
                   const float J)                                                       \
{                                                                                       \
    uint k = (uint)get_global_id(0), pd = (uint)get_global_id(1);                      \
    uint d = pd % n_dims, pl = pd / n_dims, base = pd * Es;                             \
    LOCATE                                                                              \
    uint stratum = tab[base + cell_a[c]];                                               \
    float jit = pyoa_jitter_value(pyoa_randfloat(row, tab[base + E - 1u]), J);                    \
    out[rect_index(out0, k, pl, d, n_k, n_dims)] = VALUE;                               \
}

#define CELLS_BY_SAMPLE uint c = d * n_k + k, row = isamp[k];
#define CELLS_BY_ROW uint row = rows[ro[pd] + k], c = d * N + row;
#define CMJ_VALUE pyoa_sample_value(stratum, tab[base + s + cell_u[c]], jit, M, s)
#define CENTERED_VALUE pyoa_centered_value(stratum, jit, M, s)

/* One kernel per offset of the table path rather than one with an offset
 * argument: a select between the two value paths, even on that uniform
 * argument, kept PoCL from vectorizing (0.20 instead of 0.55 G values/s,
 * docs/performance.md). 'centered' passes cell_u = 0 and never reads it. */
GENERATE_TABLED(generate_cells, CELLS_BY_SAMPLE, CMJ_VALUE, __global const uint *restrict isamp)
GENERATE_TABLED(generate_cells_centered, CELLS_BY_SAMPLE, CENTERED_VALUE, __global const uint *restrict isamp)
GENERATE_TABLED(generate_rows, CELLS_BY_ROW, CMJ_VALUE,
                __global const uint *restrict rows, __global const uint *restrict ro, const uint N)
GENERATE_TABLED(generate_rows_centered, CELLS_BY_ROW, CENTERED_VALUE,
                __global const uint *restrict rows, __global const uint *restrict ro, const uint N)

/* The rows of the later blocks' slots: axis 0 the sample position k, axis 1
 * the slot m - 1 (slot m = 1 + pixel * blocks + block index), whose order
 * seed is orders[m - 1] (never 0). permute's cycle walk keeps this kernel
 * scalar on PoCL, but it runs once per (pixel, block, sample), not per value. */
__kernel void block_rows(__global uint *restrict rows,
                         __global const uint *restrict orders,
                         const uint n_k,
                         const uint N)
{
    uint k = (uint)get_global_id(0), m = (uint)get_global_id(1) + 1u;
    rows[m * n_k + k] = pyoa_block_row(rows[k], N, orders[m - 1u]);
}

/* The comparison samplers: one kernel each, one work-item per value, over a
 * rectangle like `generate`. a, b and c are the sampler's shape arguments
 * (its catalogue entry's shape_args, zero-padded), `table` its constants
 * (Halton's primes, Sobol's direction numbers, pmj02's point sets). One
 * kernel per sampler rather than one with a code argument: with the code a
 * constant, pyoa_baseline_value's switch folds away and each kernel is
 * compiled for its sampler alone. tests/test_catalogue.py checks that every
 * comparison sampler of the catalogue has its kernel here. */
#define GENERATE_BASELINE(NAME, CODE)                                                   \
__kernel void generate_##NAME(RECT_ARGS,                                                \
                              const uint seed,                                          \
                              const uint a,                                             \
                              const uint b,                                             \
                              const uint c,                                             \
                              const float J,                                            \
                              __global const uint *table)                               \
{                                                                                       \
    RECT_PRELUDE;                                                                       \
    out[rect_index(out0, k, pl, d, n_k, n_dims)] =                                      \
        pyoa_baseline_value(CODE, i, j, p, pixel, seed, a, b, c, J, table);             \
}

GENERATE_BASELINE(random, PYOA_SAMPLER_RANDOM)
GENERATE_BASELINE(jittered2d, PYOA_SAMPLER_JITTERED2D)
GENERATE_BASELINE(cmj2d, PYOA_SAMPLER_CMJ2D)
GENERATE_BASELINE(sobol02, PYOA_SAMPLER_SOBOL02)
GENERATE_BASELINE(halton, PYOA_SAMPLER_HALTON)
GENERATE_BASELINE(sobol, PYOA_SAMPLER_SOBOL)
GENERATE_BASELINE(zsobol, PYOA_SAMPLER_ZSOBOL)
GENERATE_BASELINE(pmj02, PYOA_SAMPLER_PMJ02)
GENERATE_BASELINE(faure, PYOA_SAMPLER_FAURE)
GENERATE_BASELINE(zfaure, PYOA_SAMPLER_ZFAURE)
