#!/usr/bin/env python3
"""Probe: the Bose s=11 cmj value computed without tables, with Kensler's
cycle walk unrolled to its bound (w + 2 - l = 6 rounds) as selects.

Checks the bits against the library and prints the kernel-only throughput
(65,536 pixels x 121 spp x 10 dims). Reading: docs/performance.md.
Usage: python benchmarks/probe_loopfree_kernel.py
"""
import statistics, time, numpy as np, pyopencl as cl, sys
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parent.parent))
from pyoa._opencl import program as prog
import pyoa
src = prog.source() + r'''
/* permute with the cycle walk unrolled to its bound: ROUNDS = w + 2 - l */
inline uint permute_u(uint i, uint l, uint w, uint p) {
    uint x = i, res = 0u, done = 0u;
    #pragma unroll
    for (uint r = 0u; r < ROUNDS; ++r) {
        x = permute_round(x, p, w);  /* kernels/hashes.cl */
        uint take = (done == 0u) & (x < l);
        res = take ? x : res;
        done |= take;
    }
    uint out = (res + p % l) % l;
    return p ? out : i;
}
__kernel void direct(__global float *out, const uint seed, const uint n_values)
{
    uint gid = (uint)get_global_id(0);
    if (gid >= n_values) return;
    uint row = gid / 10u;
    uint d = gid % 10u;
    uint i = row % 121u;
    uint pixel = row / 121u;
    uint q = column_key(pixel_seed(seed, pixel), d, 12u);
    uint a0 = i / 11u, a1 = i % 11u;
    uint kk = (d & 1u) ? d - 1u : d + 1u;
    uint mj = (d - 1u) % 11u, mk = (kk - 1u) % 11u;
    uint aij = d == 0u ? a0 : (d == 1u ? a1 : (a0 + mj * a1) % 11u);
    uint aik = d == 0u ? a1 : (d == 1u ? a0 : (a0 + mk * a1) % 11u);
    uint stratum = permute_u(aij, 11u, 15u, q * STRATUM_KEY);
    uint sub = permute_u(aik, 11u, 15u, q * SUBSTRATUM_KEY);
    out[gid] = oa_value(i, stratum, convert_float(sub), q * JITTER_KEY, 11u, 11u, 1.0f);
}
'''
plat = [p for p in cl.get_platforms() if "Portable" in p.name][0]
ctx = cl.Context([plat.get_devices()[0]]); q = cl.CommandQueue(ctx)
prg = cl.Program(ctx, src).build(options=prog.BUILD_OPTIONS + prog.defines() + ["-DROUNDS=6u"])
P = 65536; n = P * 1210
out = cl.Buffer(ctx, cl.mem_flags.WRITE_ONLY, size=n * 4)
k = cl.Kernel(prg, "direct")
ts = []
for _ in range(4):
    t = time.perf_counter(); k(q, (n,), (64,), out, np.uint32(0), np.uint32(n)); q.finish(); ts.append(time.perf_counter() - t)
print("direct loop-free", round(n / statistics.median(ts[1:]) / 1e6, 1), "M/s")
h = np.empty(n, np.float32); cl.enqueue_copy(q, h, out); q.finish()
ref = pyoa.sampler("bose", spp=121, dims=10, seed=0).generate(pixels=range(P)).ravel()
print("bits equal library:", np.array_equal(h.view(np.uint32), ref.view(np.uint32)))
