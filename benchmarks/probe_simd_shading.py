#!/usr/bin/env python3
"""Probe: would SIMD shading pay? Does numba (LLVM) vectorize the next-event
arithmetic of a diffuse lane (direction to the light sample, cosines, pdfs,
the MIS weight) written as a structure-of-arrays loop over a 512-lane
wavefront, and what does it cost per lane in float64 and float32, against the
same arithmetic in the array-of-structures layout that the compiled
shading used one lane at a time before it was vectorized
(``pyoa.render.compiled.shading`` is the result)?

Prints ns per lane (Python's call overhead of ~1 ns per lane included) and
counts the packed (``vdivp``, ``vsqrtp``, ``ymm``/``zmm``) instructions in the
structure-of-arrays loop's assembly, so the vectorization is read off the
generated code rather than assumed. This is a speed probe of the arithmetic
alone (no emitter choice, BSDF or roulette), not a shading. Results and
their reading: docs/performance.md ("Rendering").

Usage: python benchmarks/probe_simd_shading.py
"""
import math
import re
import time

import numpy as np
from numba import njit

LANES = 512  # the renderer's wavefront (pyoa.render.compiled.integrator.WAVEFRONT)
REPEATS = 20_000


def kernels(dtype):
    """The two layouts of the same arithmetic, compiled for ``dtype``."""
    one, tiny, zero, inv_pi, floor = dtype(1.0), dtype(1e-12), dtype(0.0), dtype(1 / math.pi), dtype(1e-30)

    @njit(nogil=True, error_model="numpy")
    def soa(n, p, s, q, m, pdf_area, pdf_b_out, f_out, d_out, seg_out):
        for i in range(n):
            vx, vy, vz = q[0, i] - p[0, i], q[1, i] - p[1, i], q[2, i] - p[2, i]
            dist = math.sqrt(vx * vx + vy * vy + vz * vz)
            inv = one / max(dist, tiny)
            wx, wy, wz = vx * inv, vy * inv, vz * inv
            cos_q = -(m[0, i] * wx + m[1, i] * wy + m[2, i] * wz)
            pdf_b = max(s[0, i] * wx + s[1, i] * wy + s[2, i] * wz, zero) * inv_pi
            pdf_l = pdf_area[i] * dist * dist / max(cos_q, tiny)
            f = pdf_l / max(pdf_l * pdf_l + pdf_b * pdf_b, floor)
            pdf_b_out[i] = pdf_b
            f_out[i] = f if cos_q > 0 else zero
            d_out[0, i], d_out[1, i], d_out[2, i] = wx, wy, wz
            seg_out[i] = dist

    @njit(nogil=True, error_model="numpy")
    def aos(n, p, s, q, m, pdf_area, pdf_b_out, f_out, d_out, seg_out):
        for i in range(n):
            vx, vy, vz = q[i, 0] - p[i, 0], q[i, 1] - p[i, 1], q[i, 2] - p[i, 2]
            dist = math.sqrt(vx * vx + vy * vy + vz * vz)
            inv = one / max(dist, tiny)
            wx, wy, wz = vx * inv, vy * inv, vz * inv
            cos_q = -(m[i, 0] * wx + m[i, 1] * wy + m[i, 2] * wz)
            pdf_b = max(s[i, 0] * wx + s[i, 1] * wy + s[i, 2] * wz, zero) * inv_pi
            pdf_l = pdf_area[i] * dist * dist / max(cos_q, tiny)
            f = pdf_l / max(pdf_l * pdf_l + pdf_b * pdf_b, floor)
            pdf_b_out[i] = pdf_b
            f_out[i] = f if cos_q > 0 else zero
            d_out[i, 0], d_out[i, 1], d_out[i, 2] = wx, wy, wz
            seg_out[i] = dist

    return soa, aos


def ns_per_lane(fn, args) -> float:
    fn(LANES, *args)  # compile
    best = math.inf
    for _ in range(3):
        t0 = time.perf_counter()
        for _ in range(REPEATS):
            fn(LANES, *args)
        best = min(best, time.perf_counter() - t0)
    return best / REPEATS / LANES * 1e9


def main() -> None:
    rng = np.random.default_rng(0)
    for dtype in (np.float64, np.float32):
        soa, aos = kernels(dtype)
        p, s, q, m = (rng.normal(size=(3, LANES)).astype(dtype) for _ in range(4))
        pdf_area = np.abs(rng.normal(size=LANES)).astype(dtype)
        out_soa = (np.empty(LANES, dtype), np.empty(LANES, dtype), np.empty((3, LANES), dtype), np.empty(LANES, dtype))
        out_aos = (np.empty(LANES, dtype), np.empty(LANES, dtype), np.empty((LANES, 3), dtype), np.empty(LANES, dtype))
        rows = tuple(np.ascontiguousarray(a.T) for a in (p, s, q, m))
        t_soa = ns_per_lane(soa, (p, s, q, m, pdf_area, *out_soa))
        t_aos = ns_per_lane(aos, (*rows, pdf_area, *out_aos))
        asm = soa.inspect_asm(soa.signatures[0])
        packed = {k: len(re.findall(k, asm)) for k in ("vdivp[sd]", "vsqrtp[sd]", "ymm", "zmm")}
        name = np.dtype(dtype).name
        print(f"{name}: structure of arrays {t_soa:.2f} ns/lane, one lane at a time (AoS) {t_aos:.2f} ns/lane "
              f"({t_aos / t_soa:.1f}x); packed instructions in the SoA loop: {packed}")


if __name__ == "__main__":
    main()
