#!/usr/bin/env python3
"""Probe: which part of the Bose value kernel keeps PoCL from running fast.

Appends small kernels to pyoa's OpenCL program (so they use the same hash and
float helpers), each doing one more part of the value computation for Bose
s = 11, 121 spp, 10 dims with constant divisors, and prints the kernel-only
throughput for 65,536 pixels. Results and their reading: docs/performance.md
("What blocks the value kernel"). The values are not checked against the
library; this is a speed probe, not a sampler.

Usage: python benchmarks/probe_value_kernel.py
"""

import statistics
import sys
import time
from pathlib import Path

import numpy as np
import pyopencl as cl

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from pyoa._opencl import program as prog  # noqa: E402

base_src = prog.source()
head = r'''
__kernel void NAME(__global float *out, __global const uint *tab, const uint n_values)
{
    uint gid = (uint)get_global_id(0);
    if (gid >= n_values) return;
    uint row = gid / 10u;
    uint d = gid % 10u;
    uint i = row % 121u;
    uint base = ((row / 121u) * 10u + d) * 23u;
    uint a0 = i / 11u, a1 = i % 11u;
    uint aij = (a0 + d * a1) % 11u;
    uint aik = (a0 + (d + 1u) * a1) % 11u;
    BODY
}
'''
head_fast = head.replace("""    uint row = gid / 10u;
    uint d = gid % 10u;
    uint i = row % 121u;
    uint base = ((row / 121u) * 10u + d) * 23u;""", """    uint i = gid % 121u;
    uint t = gid / 121u;
    uint d = t % 10u;
    uint base = t * 23u;""")
bodies = {
  "nogather_nodiv": "out[gid] = (float)(aij * 11u + aik) * 0x1.0p-8f;",
  "gather_nodiv": "out[gid] = (float)(tab[base + aij] * 11u + tab[base + 11u + aik]) * 0x1.0p-8f + (float)tab[base + 22u];",
  "nogather_div": "out[gid] = ((float)aij + ((float)aik + 0.5f) / 11.0f) / 11.0f;",
  "nogather_randfloat": "out[gid] = randfloat(i, base * 0x9e3779b9u);",
  "nogather_samplevalue": "out[gid] = sample_value(aij, (float)aik, jitter_value(randfloat(i, base * 0x9e3779b9u), 1.0f), 11u, 11u);",
  "full": "out[gid] = sample_value(tab[base + aij], (float)tab[base + 11u + aik], jitter_value(randfloat(i, tab[base + 22u]), 1.0f), 11u, 11u);",
}
FULL = "out[gid] = sample_value(tab[base + aij], (float)tab[base + 11u + aik], jitter_value(randfloat(i, tab[base + 22u]), 1.0f), 11u, 11u);"
FULL_SCATTER = FULL.replace("out[gid]", "out[((t / 10u) * 121u + i) * 10u + d]")
src = base_src + "".join(head.replace("NAME", k).replace("BODY", v) for k, v in bodies.items())
src += head_fast.replace("NAME", "samplefast_full").replace("BODY", FULL)
src += head_fast.replace("NAME", "samplefast_full_scatter").replace("BODY", FULL_SCATTER)
bodies["samplefast_full"] = None
bodies["samplefast_full_scatter"] = None
plat = [p for p in cl.get_platforms() if "Portable" in p.name][0]
dev = plat.get_devices()[0]
ctx = cl.Context([dev]); q = cl.CommandQueue(ctx)
prg = cl.Program(ctx, src).build(options=prog.BUILD_OPTIONS + prog.defines())
P = 65536; n = P*1210
rng = np.random.default_rng(1)
tab = cl.Buffer(ctx, cl.mem_flags.READ_ONLY|cl.mem_flags.COPY_HOST_PTR, hostbuf=rng.integers(0, 11, P*10*23).astype(np.uint32))
out = cl.Buffer(ctx, cl.mem_flags.WRITE_ONLY, size=n*4)
for name in bodies:
    kern = cl.Kernel(prg, name)
    ts=[]
    for _ in range(4):
        t=time.perf_counter(); kern(q, (n,), (64,), out, tab, np.uint32(n)); q.finish(); ts.append(time.perf_counter()-t)
    print(f"{name:22s} {n/statistics.median(ts[1:])/1e6:8.1f} M/s")
