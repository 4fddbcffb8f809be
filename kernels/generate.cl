/* Bulk generation: one work-item per value of a (pixel, sample, dimension)
 * request, written row-major into out[(pixel * n_samples + sample) * n_dims + dim].
 * One launch covers the rows [row0, row0 + n_rows) of the request; the
 * global size is padded to a multiple of the work-group size, hence the
 * bounds check. Construction codes CONSTRUCTION_* come from pyoa.constructions. */

__kernel void generate(__global float *out,
                       __global const uint *pixels,
                       __global const uint *samples,
                       __global const uint *dims,
                       const uint n_samples,
                       const uint n_dims,
                       const ulong row0,
                       const uint n_values,
                       const uint seed,
                       const uint construction,
                       const uint s,
                       const uint t,
                       const uint offset,
                       const float J)
{
    uint gid = (uint)get_global_id(0);
    if (gid >= n_values) return;
    ulong row = row0 + gid / n_dims;
    uint dim = dims[gid % n_dims];
    uint i = samples[(uint)(row % n_samples)];
    uint p = pixel_seed(seed, pixels[row / n_samples]);
    out[gid] = (construction == CONSTRUCTION_BOSE) ? bose(i, dim, s, p, offset, J)
                                                   : cmjnd(i, dim, s, t, p, offset, J);
}
