/* pyoa/fill.h: many values of one pixel at once, for CPU renderers that
 * take a pixel's (or a tile's) samples together: the values of
 * pyoa_sampler_value (pyoa/sampler.h), bit for bit, at a fraction of its
 * cost per value. Host only (PYOA_HOST_FN); no heap: the caller gives the
 * scratch memory, of a size pyoa_fill_scratch_bytes reports.
 *
 *     size_t bytes = pyoa_fill_scratch_bytes(&s, n_dims);    // once per sampler
 *     void *scratch = malloc(bytes);                          // one per thread
 *     float *v = malloc(sizeof(float) * spp * n_dims);
 *
 *     // one call per pixel (stateless: the scratch's contents do not matter)
 *     pyoa_sampler_fill(&s, pixel, 0, spp, 0, n_dims, v, scratch);
 *     // v[k * n_dims + d] == pyoa_sampler_value(&s, pixel, k, d)
 *
 *     // or: a render loop over many pixels with the same samples and dims
 *     pyoa_fill_prepare(&s, 0, spp, 0, n_dims, scratch);      // once
 *     for (each pixel) pyoa_fill_pixel(scratch, pixel, v);    // per pixel
 *
 * pyoa_sampler_fill(s, pixel, sample0, n_samples, dim0, n_dims, out,
 * scratch) writes out[k * n_dims + d] = pyoa_sampler_value(s, pixel,
 * sample0 + k, dim0 + d) for k < n_samples, d < n_dims (the layout of one
 * pixel of pyoa's generate). It is pyoa_fill_prepare followed by
 * pyoa_fill_pixel: prepare does the work that does not depend on the pixel,
 * pyoa_fill_pixel the rest, for any number of pixels. sample0 + n_samples
 * must not exceed spp (pyoa_sampler_value's own range).
 *
 * How (the table path of kernels/generate.cl, on a CPU). A value of an
 * orthogonal array (docs/spec.md sections 4-6) is
 *     stratum = permute(A_ij, s, q * STRATUM_KEY)         (section 5.2)
 *     sub     = permute(u, M, q * SUBSTRATUM_KEY)          ('cmj', section 4)
 *     jitter  = jitter_value(randfloat(row, q * JITTER_KEY), J)
 *     x       = sample_value(stratum, sub, jitter, M, s)  (section 7)
 * with q = P * (col + 1) the column key (section 3.3), P = block_seed(p,
 * j / B) and row the block's row of the sample (section 6). The value
 * function pays two cycle-walking permutations and about ten integer
 * divisions by run-time values per value. Here:
 * - the cells (A_ij, u) of each (row, column) come from the construction's
 *   cell function (pyoa_<name>_cell of oa.h, where the divisions are); they
 *   do not depend on the pixel, so pyoa_fill_prepare computes them once:
 *   for a block-0 column at the requested samples, for a later block's
 *   column at every row of the array (its rows differ from pixel to pixel);
 * - per pixel and dimension, the stratum permutation (s entries) and the
 *   'cmj' sub-stratum permutation (M entries) are computed once, as
 *   tables, and the rows of each later block once per (block, sample),
 *   shared by the block's columns; these permutations run three walk
 *   rounds branch-free over 16 lanes (most walks end there) and finish the
 *   few others one by one, as the OpenCL `tables` kernels do;
 * - each value is then two table reads, randfloat, jitter_value and
 *   sample_value (or centered_value): no integer division, no loop that
 *   depends on the data, in blocks of 16 lanes with a fixed trip count, so
 *   that compilers vectorize them (GCC already at -O2, whose very-cheap
 *   cost model takes only loops of a known multiple of the vector length;
 *   GCC 12 and Clang 15 vectorize every value loop and the walk rounds
 *   with -march=native, tests/test_c_fill.py and benchmarks/bench_openqmc.py
 *   report it; floats.h's clamp makes its two comparisons unconditionally
 *   for this).
 * pyoa_sampler_fill pays the cells (the divisions) for every pixel; a pixel
 * loop that prepares once pays them once (the prepared path is the fast
 * one: docs/performance.md has both against OpenQMC).
 *
 * What falls back, and how:
 * - the 'j' and 'mj' offsets (their sub-stratum permutation's seed changes
 *   from cell to cell, so no table), the comparison and progressive
 *   samplers, a code no construction has, and requests outside [0, spp):
 *   pyoa_sampler_value per value (correct, not faster);
 * - a stratum or sub-stratum table larger than PYOA_FILL_MAX_TABLE entries,
 *   or than 4 x n_samples (where building it costs more than it saves):
 *   that permutation per value, in a loop that does not vectorize;
 * - cells: a column whose rows do not fit PYOA_FILL_MAX_CELL_ROWS (block 0:
 *   n_samples; a later block: the array's N, also when N > 4 x n_samples)
 *   gets its cells computed per pixel, PYOA_FILL_CHUNK samples at a time.
 * The bounds change only the speed, never a value. The scratch is
 *     H + 4 x (5 x PYOA_FILL_CHUNK + n_dims x (16 + s' + M' + 2 R')) bytes,
 * H the plan's header (sizeof(pyoa_fill_plan) rounded up to 64), s' = s and
 * M' = M ('cmj' only) where they are at most PYOA_FILL_MAX_TABLE (4096) and
 * 0 above, R' = min(N, PYOA_FILL_MAX_CELL_ROWS (16384)), each rounded up to
 * 16: 1216 bytes per dimension for Bose at 121 spp, at most 163904 (160 KiB
 * + 64 bytes) for any sampler; H alone for the samplers that fall back. A
 * renderer may define the three macros before including this header (a
 * test build sets them tiny to exercise every fallback).
 *
 * Scratch: pyoa_fill_scratch_bytes(s, n_dims) bytes, aligned to 8 bytes
 * (malloc's), for any fill or prepare of that sampler with at most n_dims
 * dimensions. A thread uses its own. pyoa_fill_pixel reads what
 * pyoa_fill_prepare wrote there (a copy of the sampler, which must stay
 * bound to its table, the ranges and the cells) and overwrites the rest. */
#ifndef PYOA_FILL_H
#define PYOA_FILL_H

#include "config.h"
#include "sampler.h"

#if !defined(__OPENCL_VERSION__)

#ifndef PYOA_FILL_MAX_TABLE
#define PYOA_FILL_MAX_TABLE 4096u
#endif
#ifndef PYOA_FILL_MAX_CELL_ROWS
#define PYOA_FILL_MAX_CELL_ROWS 16384u
#endif
#ifndef PYOA_FILL_CHUNK
#define PYOA_FILL_CHUNK 256u
#endif

/* C99's restrict, which C++ spells __restrict (GCC, Clang, MSVC, nvcc). */
#if defined(__cplusplus) || !defined(__STDC_VERSION__) || __STDC_VERSION__ < 199901L
#if defined(__GNUC__) || defined(_MSC_VER)
#define PYOA_RESTRICT __restrict
#else
#define PYOA_RESTRICT
#endif
#else
#define PYOA_RESTRICT restrict
#endif

/* Lanes of the vectorizable loops: every loop over samples or table entries
 * runs in blocks of this many with a fixed inner trip count, over arrays
 * padded to it (padding lanes compute values nobody reads, from indices
 * kept valid). 16: one AVX-512 register of uint32, two of AVX2. */
#define PYOA_FILL_LANES 16u
#define PYOA_FILL_PAD(n) (((n) + (PYOA_FILL_LANES - 1u)) & ~(PYOA_FILL_LANES - 1u))
/* A walk that three rounds did not end (pyoa_fill_permute_lanes); the walk
 * state is <= w < 2^31 (l <= 2^31), so the bit is free. */
#define PYOA_FILL_PENDING 0x80000000u

/* What pyoa_fill_prepare leaves at the start of the scratch. */
typedef struct pyoa_fill_plan {
    pyoa_sampler s;       /* a copy of the sampler (pointing at its table) */
    pyoa_u32 sample0, n_samples, dim0, n_dims; /* the request */
    pyoa_u32 tabled;      /* 1: the table path; 0: pyoa_sampler_value per value */
    pyoa_u32 stab, mtab;  /* 1: a stratum (sub-stratum) table per dimension; 0: permute per value */
    pyoa_u32 stab_words, mtab_words, cell_words; /* the layout per dimension (pyoa_fill_words) */
    pyoa_u32 dim_words;   /* uint32 words per dimension */
    pyoa_u32 chunk;       /* samples per pass (PYOA_FILL_CHUNK, padded) */
} pyoa_fill_plan;

/* Per dimension, at the start of its words: the column, the block, how its
 * cells are held (below) and, during pyoa_fill_pixel, the column key q. */
enum { PYOA_FILL_INFO_WORDS = 16 }; /* 4 used; 16 keep the tables 64-byte aligned */
enum { PYOA_FILL_CELLS_PER_PIXEL = 0, PYOA_FILL_CELLS_BY_SAMPLE = 1, PYOA_FILL_CELLS_BY_ROW = 2 };

/* The plan's header in uint32 words, rounded up to 64 bytes. */
PYOA_HOST_FN size_t pyoa_fill_header_words(void)
{
    return ((sizeof(pyoa_fill_plan) + 63u) / 64u) * 16u;
}

/* Whether sampler s has the table path: an orthogonal array (codes 0-4)
 * with the 'cmj' or 'centered' offset. */
PYOA_HOST_FN int pyoa_fill_has_tables(const pyoa_sampler *s)
{
    return s->code <= PYOA_SAMPLER_BOSE_BUSH &&
           (s->offset == PYOA_OFFSET_CMJ || s->offset == PYOA_OFFSET_CENTERED);
}

/* The words per dimension of sampler s's table path: the stratum table
 * (s entries when s <= PYOA_FILL_MAX_TABLE), the 'cmj' sub-stratum table
 * (M entries, likewise) and two cell arrays of min(N, PYOA_FILL_MAX_CELL_ROWS)
 * entries, each padded to PYOA_FILL_LANES. They depend on the sampler only,
 * so one scratch size serves every request. */
PYOA_HOST_FN void pyoa_fill_words(const pyoa_sampler *s, pyoa_u32 *stab, pyoa_u32 *mtab, pyoa_u32 *cells)
{
    *stab = (s->s <= PYOA_FILL_MAX_TABLE) ? PYOA_FILL_PAD(s->s) : 0u;
    *mtab = (s->offset == PYOA_OFFSET_CMJ && s->M <= PYOA_FILL_MAX_TABLE) ? PYOA_FILL_PAD(s->M) : 0u;
    *cells = PYOA_FILL_PAD(PYOA_MIN(s->spp, (pyoa_u32)PYOA_FILL_MAX_CELL_ROWS));
}

/* Bytes of scratch pyoa_sampler_fill and pyoa_fill_prepare need for sampler
 * s and up to n_dims dimensions (any samples). */
PYOA_HOST_FN size_t pyoa_fill_scratch_bytes(const pyoa_sampler *s, pyoa_u32 n_dims)
{
    pyoa_u32 stab, mtab, cells;
    size_t words = pyoa_fill_header_words();
    if (pyoa_fill_has_tables(s)) {
        pyoa_fill_words(s, &stab, &mtab, &cells);
        words += (size_t)n_dims * (PYOA_FILL_INFO_WORDS + stab + mtab + 2u * (size_t)cells) +
                 5u * (size_t)PYOA_FILL_PAD(PYOA_FILL_CHUNK);
    }
    return words * sizeof(pyoa_u32);
}

/* The scratch's parts: the words of dimension d, and the per-pass buffers
 * after the last dimension (rows, two cell arrays and two buffers of values
 * of one pass of `chunk` samples). */
PYOA_HOST_FN pyoa_u32 *pyoa_fill_dim(void *scratch, pyoa_u32 d)
{
    const pyoa_fill_plan *plan = (const pyoa_fill_plan *)scratch;
    return (pyoa_u32 *)scratch + pyoa_fill_header_words() + (size_t)d * plan->dim_words;
}

PYOA_HOST_FN pyoa_u32 *pyoa_fill_pass(void *scratch, pyoa_u32 part)
{
    const pyoa_fill_plan *plan = (const pyoa_fill_plan *)scratch;
    return pyoa_fill_dim(scratch, plan->n_dims) + (size_t)part * plan->chunk;
}

/* permute(i, l, p) (spec 2.1) for many i with one seed, in two passes.
 * permute(i, l, p) = (walk(i) + p % l) % l with walk(i) < l, so with
 * c = p % l hoisted the last % is one subtraction (the table path of
 * kernels/generate.cl does the same). pyoa_fill_rounds takes three walk
 * rounds branch-free in lanes (a walk ends at its first round below l; with
 * l > w / 2, three rounds end all but about (1/2)^3 of the walks, usually
 * far fewer) and marks the others PYOA_FILL_PENDING; pyoa_fill_finish walks
 * those on, one by one. A pixel's tables take their rounds first and their
 * finishes after, so that the rounds of all its tables (each a chain of 18
 * dependent multiplications) overlap in the CPU instead of waiting on the
 * finishing loop's branches. x[k], k < n (a multiple of PYOA_FILL_LANES):
 * the inputs (or, with x_iota, k itself); entries >= l are left as they
 * are (padding: a walk from them might never end). p must not be 0 (the
 * identity, permute's own rule: the callers skip it). */
PYOA_HOST_FN void pyoa_fill_rounds(pyoa_u32 *PYOA_RESTRICT x, int x_iota, pyoa_u32 n, pyoa_u32 l, pyoa_u32 p)
{
    const pyoa_u32 w = pyoa_walk_mask(l), c = p % l;
    pyoa_u32 k0, m;
    for (k0 = 0u; k0 < n; k0 += PYOA_FILL_LANES) {
        /* a block's base pointer and a 0..15 index: a uint32 index k0 + m
         * may wrap, which GCC's data-reference analysis cannot vectorize */
        pyoa_u32 *PYOA_RESTRICT xb = x + k0;
        for (m = 0u; m < PYOA_FILL_LANES; ++m) { /* fixed trip count: vectorizes */
            pyoa_u32 i = x_iota ? k0 + m : xb[m];
            pyoa_u32 y = pyoa_permute_round(i, p, w);
            pyoa_u32 y2 = pyoa_permute_round(y, p, w);
            pyoa_u32 y3, v, pending;
            y = (y < l) ? y : y2;
            y3 = pyoa_permute_round(y, p, w);
            y = (y < l) ? y : y3;
            /* flat selects: a nested ?: on y < l and i >= l became jumps
             * that GCC's if-conversion gave up on ("control flow in loop") */
            pending = (pyoa_u32)(y >= l) << 31;
            v = y + c;
            v -= (v >= l) ? l : 0u;
            v = (y < l) ? v : y;
            xb[m] = (i < l) ? (v | pending) : i;
        }
    }
}

PYOA_HOST_FN void pyoa_fill_finish(pyoa_u32 *PYOA_RESTRICT x, pyoa_u32 n, pyoa_u32 l, pyoa_u32 p)
{
    pyoa_u32 k;
    for (k = 0u; k < n; ++k)
        if (x[k] & PYOA_FILL_PENDING) { /* rare: continue the walk where it stands (>= l) */
            pyoa_u32 v = pyoa_permute_walk(x[k] & ~PYOA_FILL_PENDING, l, p, pyoa_walk_mask(l)) + p % l;
            x[k] = (v >= l) ? v - l : v;
        }
}

/* x[k] = permute(x[k], l, p) for k < n (a multiple of PYOA_FILL_LANES). */
PYOA_HOST_FN void pyoa_fill_permute_lanes(pyoa_u32 *PYOA_RESTRICT x, pyoa_u32 n, pyoa_u32 l, pyoa_u32 p)
{
    if (p == 0u) return;
    pyoa_fill_rounds(x, 0, n, l, p);
    pyoa_fill_finish(x, n, l, p);
}

/* The two passes of table[e] = permute(e, l, p), e < l; the padding up to
 * PYOA_FILL_PAD(l) holds e (never read). */
PYOA_HOST_FN void pyoa_fill_table_rounds(pyoa_u32 *PYOA_RESTRICT table, pyoa_u32 l, pyoa_u32 p)
{
    pyoa_u32 e;
    if (p != 0u)
        pyoa_fill_rounds(table, 1, PYOA_FILL_PAD(l), l, p);
    else
        for (e = 0u; e < PYOA_FILL_PAD(l); ++e) table[e] = e;
}

PYOA_HOST_FN void pyoa_fill_table_finish(pyoa_u32 *PYOA_RESTRICT table, pyoa_u32 l, pyoa_u32 p)
{
    if (p != 0u) pyoa_fill_finish(table, PYOA_FILL_PAD(l), l, p);
}

/* The cells (A_ij, u) of rows[k] in column col, k < n, from the
 * construction's cell function (oa.h); 0 for an unknown code (never
 * reached: pyoa_fill_prepare sends those to the per-value path). */
PYOA_HOST_FN void pyoa_fill_cells(const pyoa_sampler *sp, pyoa_u32 col, const pyoa_u32 *PYOA_RESTRICT rows,
                                  pyoa_u32 n, pyoa_u32 *PYOA_RESTRICT A, pyoa_u32 *PYOA_RESTRICT U)
{
    const pyoa_u32 s = sp->s, t = sp->strength, M = sp->M, tabled = sp->gf_tabled;
    const pyoa_u16 *gf = sp->gf;
    const pyoa_u32 *consts = sp->data;
    pyoa_u32 k, a, u, ck;
#define PYOA_FILL_CELLS(CELL)                                                           \
    for (k = 0u; k < n; ++k) {                                                          \
        CELL(rows[k], col, s, t, M, gf, tabled, consts, &a, &u, &ck);                   \
        A[k] = a;                                                                       \
        U[k] = u;                                                                       \
    }                                                                                   \
    break;
    switch (sp->code) {
    case PYOA_SAMPLER_BOSE: PYOA_FILL_CELLS(pyoa_bose_cell)
    case PYOA_SAMPLER_BUSH: PYOA_FILL_CELLS(pyoa_bush_cell)
    case PYOA_SAMPLER_CMJND: PYOA_FILL_CELLS(pyoa_cmjnd_cell)
    case PYOA_SAMPLER_ADDELMAN_KEMPTHORNE: PYOA_FILL_CELLS(pyoa_addelman_kempthorne_cell)
    case PYOA_SAMPLER_BOSE_BUSH: PYOA_FILL_CELLS(pyoa_bose_bush_cell)
    default:
        for (k = 0u; k < n; ++k) A[k] = U[k] = 0u;
        break;
    }
#undef PYOA_FILL_CELLS
}

/* rows[k] = first + k for k < PYOA_FILL_PAD(n); the padding repeats `first`
 * (a valid row for the cell arrays and permutations that read it). */
PYOA_HOST_FN void pyoa_fill_iota(pyoa_u32 *rows, pyoa_u32 first, pyoa_u32 n)
{
    pyoa_u32 k;
    for (k = 0u; k < PYOA_FILL_PAD(n); ++k) rows[k] = (k < n) ? first + k : first;
}

/* Write the request (sample0 + k, dim0 + d), k < n_samples, d < n_dims, of
 * sampler s into the scratch, and the work of pyoa_sampler_fill that does
 * not depend on the pixel: which tables pay, and the cells. */
PYOA_HOST_FN void pyoa_fill_prepare(const pyoa_sampler *s, pyoa_u32 sample0, pyoa_u32 n_samples, pyoa_u32 dim0,
                                    pyoa_u32 n_dims, void *scratch)
{
    pyoa_fill_plan *plan = (pyoa_fill_plan *)scratch;
    pyoa_u32 N = s->spp, d, c0;
    plan->s = *s;
    plan->sample0 = sample0;
    plan->n_samples = n_samples;
    plan->dim0 = dim0;
    plan->n_dims = n_dims;
    plan->chunk = PYOA_FILL_PAD(PYOA_FILL_CHUNK);
    /* the table path needs its cells' and tables' indices in range: the
     * samples inside [0, N) (written so that sample0 + n_samples cannot wrap) */
    plan->tabled = (pyoa_u32)(pyoa_fill_has_tables(s) && n_samples > 0u && n_dims > 0u && sample0 < N &&
                              n_samples <= N - sample0);
    if (!plan->tabled) {
        plan->dim_words = 0u;
        return;
    }
    pyoa_fill_words(s, &plan->stab_words, &plan->mtab_words, &plan->cell_words);
    plan->dim_words = PYOA_FILL_INFO_WORDS + plan->stab_words + plan->mtab_words + 2u * plan->cell_words;
    /* a table of l entries costs about l cycle walks per pixel and dimension
     * and saves one per value: it pays when l <= 4 n (and it fits) */
    plan->stab = (pyoa_u32)(plan->stab_words && s->s / 4u <= n_samples);
    plan->mtab = (pyoa_u32)(plan->mtab_words && s->M / 4u <= n_samples);
    for (d = 0u; d < n_dims; ++d) {
        pyoa_u32 *info = pyoa_fill_dim(scratch, d);
        pyoa_u32 *A = info + PYOA_FILL_INFO_WORDS + plan->stab_words + plan->mtab_words, *U = A + plan->cell_words;
        pyoa_u32 *rows = pyoa_fill_pass(scratch, 0u);
        pyoa_u32 j = dim0 + d, block = j / s->block_dims, col = j % s->block_dims, rows_held, first;
        info[0] = col;
        info[1] = block;
        /* block 0 reads row i = the sample: cells of the requested samples;
         * a later block reads its own order of all N rows (section 6): cells
         * of every row, when they fit and cost at most 4 per value */
        if (block == 0u && n_samples <= PYOA_FILL_MAX_CELL_ROWS) {
            info[2] = PYOA_FILL_CELLS_BY_SAMPLE;
            rows_held = n_samples;
            first = sample0;
        } else if (block != 0u && N <= PYOA_FILL_MAX_CELL_ROWS && N / 4u <= n_samples) {
            info[2] = PYOA_FILL_CELLS_BY_ROW;
            rows_held = N;
            first = 0u;
        } else {
            info[2] = PYOA_FILL_CELLS_PER_PIXEL;
            continue;
        }
        for (c0 = 0u; c0 < rows_held; c0 += plan->chunk) {
            pyoa_u32 cn = PYOA_MIN(plan->chunk, rows_held - c0);
            pyoa_fill_iota(rows, first + c0, cn);
            pyoa_fill_cells(s, col, rows, cn, A + c0, U + c0);
        }
        /* the padding after the held rows: cell (0, 0), in every table's range */
        for (c0 = rows_held; c0 < PYOA_FILL_PAD(rows_held); ++c0) A[c0] = U[c0] = 0u;
    }
}

/* The values of one column over one pass (as pyoa_fill_column_tabled below)
 * where a permutation has no table (too large to pay) or the jitter seed is
 * 0: the stratum from stab or permute, the sub-stratum from mtab or permute
 * (pyoa_oa_tail's seeds), per value, in a loop that does not vectorize. */
PYOA_HOST_FN void pyoa_fill_column_permute(float *PYOA_RESTRICT vals, pyoa_u32 n,
                                           const pyoa_u32 *PYOA_RESTRICT rows, const pyoa_u32 *PYOA_RESTRICT ca,
                                           const pyoa_u32 *PYOA_RESTRICT cu, int by_row,
                                           const pyoa_u32 *PYOA_RESTRICT stab, const pyoa_u32 *PYOA_RESTRICT mtab,
                                           pyoa_u32 q, float J, pyoa_u32 S, pyoa_u32 M, int centered)
{
    pyoa_u32 k;
    for (k = 0u; k < n; ++k) {
        pyoa_u32 row = rows[k], c = by_row ? row : k;
        pyoa_u32 stratum = stab ? stab[ca[c]] : pyoa_permute(ca[c], S, q * PYOA_STRATUM_KEY);
        float jit = pyoa_jitter_value(pyoa_randfloat(row, q * PYOA_JITTER_KEY), J);
        pyoa_u32 sub = (centered || mtab) ? (mtab ? mtab[cu[c]] : 0u) : pyoa_permute(cu[c], M, q * PYOA_SUBSTRATUM_KEY);
        vals[k] = centered ? pyoa_centered_value(stratum, jit, M, S) : pyoa_sample_value(stratum, sub, jit, M, S);
    }
}

/* The values of one column over one pass: vals[k] for k < PYOA_FILL_PAD(n)
 * from rows[k], the cells (A: at k, or at the row for a later block's
 * held cells), the tables and the column key q. One loop per case, each
 * with a fixed-count inner loop over PYOA_FILL_LANES lanes and nothing but
 * inlined arithmetic and table reads in it: the vectorizable core. */
#define PYOA_FILL_VALUES(A, VALUE)                                                      \
    for (k0 = 0u; k0 < n; k0 += PYOA_FILL_LANES) {                                      \
        const pyoa_u32 *PYOA_RESTRICT rb = rows + k0;                                   \
        float *PYOA_RESTRICT vb = vals + k0;                                            \
        for (m = 0u; m < PYOA_FILL_LANES; ++m) {                                        \
            pyoa_u32 row = rb[m];                                                       \
            pyoa_u32 stratum = stab[A];                                                 \
            float jit = pyoa_jitter_value(pyoa_randfloat(row, pj), J);                  \
            vb[m] = VALUE;                                                              \
        }                                                                               \
    }

PYOA_HOST_FN void pyoa_fill_column_tabled(float *PYOA_RESTRICT vals, pyoa_u32 n,
                                          const pyoa_u32 *PYOA_RESTRICT rows, const pyoa_u32 *PYOA_RESTRICT ca,
                                          const pyoa_u32 *PYOA_RESTRICT cu, int by_row,
                                          const pyoa_u32 *PYOA_RESTRICT stab, const pyoa_u32 *PYOA_RESTRICT mtab,
                                          pyoa_u32 q, float J, pyoa_u32 S, pyoa_u32 M, int centered)
{
    const pyoa_u32 pj = q * PYOA_JITTER_KEY;
    pyoa_u32 k0, m;
    if (pj == 0u) { /* randfloat's seed-0 rule (0.5) as a select kept GCC's loops scalar; below, pj != 0 */
        pyoa_fill_column_permute(vals, n, rows, ca, cu, by_row, stab, mtab, q, J, S, M, centered);
        return;
    }
    n = PYOA_FILL_PAD(n);
    if (centered) {
        /* pyoa_centered_value with its cell (pyoa_centered_cell) hoisted out of the loop */
        const float mid = PYOA_MUL(0.5f, PYOA_U32_TO_F32(M - 1u));
        pyoa_u32 cm, ch, cn;
        pyoa_centered_cell(M, S, &cm, &ch, &cn);
        if (by_row)
            PYOA_FILL_VALUES(ca[row], pyoa_cell_clamp(pyoa_formula_value(stratum, mid, jit, M, S), stratum * cm + ch, cn))
        else
            PYOA_FILL_VALUES((ca + k0)[m],
                             pyoa_cell_clamp(pyoa_formula_value(stratum, mid, jit, M, S), stratum * cm + ch, cn))
    } else {
        if (by_row) PYOA_FILL_VALUES(ca[row], pyoa_sample_value(stratum, mtab[cu[row]], jit, M, S))
        else PYOA_FILL_VALUES((ca + k0)[m], pyoa_sample_value(stratum, mtab[(cu + k0)[m]], jit, M, S))
    }
}
#undef PYOA_FILL_VALUES

/* out[(c0 + k) * nd + d] = v[k], k < n: one column of a pass into the
 * pixel's values. */
PYOA_HOST_FN void pyoa_fill_store(float *PYOA_RESTRICT out, pyoa_u32 nd, pyoa_u32 d, pyoa_u32 c0, pyoa_u32 n,
                                  const float *PYOA_RESTRICT v)
{
    float *o = out + (size_t)c0 * nd + d;
    pyoa_u32 k;
    for (k = 0u; k < n; ++k, o += nd) *o = v[k];
}

/* The values of pixel `pixel` for the request of the last pyoa_fill_prepare
 * on `scratch`: out[k * n_dims + d] = pyoa_sampler_value(s, pixel, sample0 + k,
 * dim0 + d), bit for bit. */
PYOA_HOST_FN void pyoa_fill_pixel(void *scratch, pyoa_u32 pixel, float *out)
{
    pyoa_fill_plan *plan = (pyoa_fill_plan *)scratch;
    const pyoa_sampler *s = &plan->s;
    const pyoa_u32 n = plan->n_samples, nd = plan->n_dims, N = s->spp, S = s->s, M = s->M;
    const int centered = s->offset == PYOA_OFFSET_CENTERED;
    pyoa_u32 p, d, d1, c0, k, P = 0u, block = 0u, held = 0u, held_d = 0u, held_c0 = 0u, held_n = 0u;
    pyoa_u32 *rows, *chunk_a, *chunk_u;
    float *vals, *v, *held_v = NULL;
    if (!plan->tabled) { /* the per-value path */
        for (k = 0u; k < n; ++k)
            for (d = 0u; d < nd; ++d)
                out[(size_t)k * nd + d] = pyoa_sampler_value(s, pixel, plan->sample0 + k, plan->dim0 + d);
        return;
    }
    rows = pyoa_fill_pass(scratch, 0u);
    chunk_a = pyoa_fill_pass(scratch, 1u);
    chunk_u = pyoa_fill_pass(scratch, 2u);
    vals = v = (float *)(void *)pyoa_fill_pass(scratch, 3u); /* two buffers of `chunk` values */
    p = pyoa_pixel_seed(s->seed, pixel);
    /* per dimension: the column key q = P (col + 1) (section 3.3) and the
     * permutation tables of this pixel */
    for (d = 0u; d < nd; ++d) {
        pyoa_u32 *info = pyoa_fill_dim(scratch, d), q;
        if (d == 0u || info[1] != block) {
            block = info[1];
            P = pyoa_block_seed(p, block);
        }
        info[3] = q = P * (info[0] + 1u);
        if (plan->stab) pyoa_fill_table_rounds(info + PYOA_FILL_INFO_WORDS, S, q * PYOA_STRATUM_KEY);
        if (plan->mtab)
            pyoa_fill_table_rounds(info + PYOA_FILL_INFO_WORDS + plan->stab_words, M, q * PYOA_SUBSTRATUM_KEY);
    }
    for (d = 0u; d < nd; ++d) { /* after all the rounds (pyoa_fill_rounds says why) */
        pyoa_u32 *info = pyoa_fill_dim(scratch, d), q = info[3];
        if (plan->stab) pyoa_fill_table_finish(info + PYOA_FILL_INFO_WORDS, S, q * PYOA_STRATUM_KEY);
        if (plan->mtab)
            pyoa_fill_table_finish(info + PYOA_FILL_INFO_WORDS + plan->stab_words, M, q * PYOA_SUBSTRATUM_KEY);
    }
    /* passes over the samples; in each, the dimensions block by block: a
     * block's rows once, then its columns */
    for (c0 = 0u; c0 < n; c0 += plan->chunk) {
        const pyoa_u32 cn = PYOA_MIN(plan->chunk, n - c0);
        for (d = 0u; d < nd; d = d1) {
            block = pyoa_fill_dim(scratch, d)[1];
            for (d1 = d + 1u; d1 < nd && pyoa_fill_dim(scratch, d1)[1] == block; ++d1) {
            }
            /* the rows of this block (section 6): row = i in block 0, else
             * block_row(i, N, r) = permute(permute(i, N, r), N, mix32(r)) */
            pyoa_fill_iota(rows, plan->sample0 + c0, cn);
            if (block != 0u) {
                pyoa_u32 r = pyoa_block_order_seed(pyoa_block_seed(p, block), block, N);
                pyoa_fill_permute_lanes(rows, PYOA_FILL_PAD(cn), N, r);
                pyoa_fill_permute_lanes(rows, PYOA_FILL_PAD(cn), N, pyoa_mix32(r));
            }
            for (; d < d1; ++d) {
                pyoa_u32 *info = pyoa_fill_dim(scratch, d);
                const pyoa_u32 *stab = plan->stab ? info + PYOA_FILL_INFO_WORDS : NULL;
                const pyoa_u32 *mtab = plan->mtab ? info + PYOA_FILL_INFO_WORDS + plan->stab_words : NULL;
                const pyoa_u32 *ca = info + PYOA_FILL_INFO_WORDS + plan->stab_words + plan->mtab_words;
                const pyoa_u32 *cu = ca + plan->cell_words;
                const pyoa_u32 q = info[3];
                const int by_row = info[2] == PYOA_FILL_CELLS_BY_ROW;
                if (info[2] == PYOA_FILL_CELLS_BY_SAMPLE) {
                    ca += c0;
                    cu += c0;
                } else if (info[2] == PYOA_FILL_CELLS_PER_PIXEL) {
                    pyoa_fill_cells(s, info[0], rows, PYOA_FILL_PAD(cn), chunk_a, chunk_u);
                    ca = chunk_a;
                    cu = chunk_u;
                }
                if (stab && (mtab || centered))
                    pyoa_fill_column_tabled(v, cn, rows, ca, cu, by_row, stab, mtab, q, s->jitter, S, M, centered);
                else
                    pyoa_fill_column_permute(v, cn, rows, ca, cu, by_row, stab, mtab, q, s->jitter, S, M, centered);
                /* store the previous column now that this one is computed:
                 * read right after the vector stores that wrote them, the
                 * values' scalar loads waited on store forwarding (3 ns per
                 * value, half the path's time, GCC 12 with AVX-512) */
                if (held) pyoa_fill_store(out, nd, held_d, held_c0, held_n, held_v);
                held = 1, held_d = d, held_c0 = c0, held_n = cn, held_v = v;
                v = (v == vals) ? vals + plan->chunk : vals;
            }
        }
    }
    if (held) pyoa_fill_store(out, nd, held_d, held_c0, held_n, held_v);
}

/* out[k * n_dims + d] = pyoa_sampler_value(s, pixel, sample0 + k, dim0 + d)
 * for k < n_samples, d < n_dims, bit for bit; scratch holds
 * pyoa_fill_scratch_bytes(s, n_dims) bytes or more (its contents on entry
 * do not matter). pyoa_fill_prepare then pyoa_fill_pixel. */
PYOA_HOST_FN void pyoa_sampler_fill(const pyoa_sampler *s, pyoa_u32 pixel, pyoa_u32 sample0, pyoa_u32 n_samples,
                                    pyoa_u32 dim0, pyoa_u32 n_dims, float *out, void *scratch)
{
    pyoa_fill_prepare(s, sample0, n_samples, dim0, n_dims, scratch);
    pyoa_fill_pixel(scratch, pixel, out);
}

#endif /* !__OPENCL_VERSION__ */
#endif /* PYOA_FILL_H */
