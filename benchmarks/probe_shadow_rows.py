#!/usr/bin/env python3
"""Probe: what tracing shadow rays straight from the shading's scratch would save.

The compiled renderer (``pyoa.render.compiled.integrator.render_paths``)
shades a bounce :data:`~pyoa.render.compiled.shading.CHUNK` lanes at a time;
each chunk's shadow rays are copied out of the scratch into the wavefront
(``shading.emit_shadows``: 11 values a ray), all the wavefront's shadow rays
are traced at once (``embree.occluded``, which loads its packets from those
copies), and ``add_visible`` adds what the unblocked ones carry. The
redesign that docs/performance.md weighs for issue 32 ("persistent
structure-of-arrays wavefronts") would trace each chunk's shadow rays from
the scratch rows themselves and add their contributions from there, with no
copy. This probe measures that one piece before anyone builds it: a compiled
driver runs the renderer's own steps (as ``benchmarks/probe_shading_stages.py``
does), with the shadow rays either as shipped or traced from the scratch
(:func:`shadows_from_rows`, here only), alternated in one process, one
thread, 64 x 64, Bose 121 spp. It checks that both give the renderer's image
bit for bit (each path adds its light in the same order) and prints ns per
camera path of each, min and median over the rounds.

Usage: python benchmarks/probe_shadow_rows.py [SCENE:R|F ...] [--rounds N]
(default: cornell:R dof7d:F bounce9d:F, 7 rounds)
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402
from numba import njit  # noqa: E402

from pyoa.render import embree  # noqa: E402
from pyoa.render.compiled import camera as ccam  # noqa: E402
from pyoa.render.compiled import integrator as ci  # noqa: E402
from pyoa.render.compiled import shading as sh  # noqa: E402
from pyoa.render.integrator import RR_KEY, U32, hash_pair  # noqa: E402
from pyoa.render.render import pixel_sums, plan, render  # noqa: E402
from pyoa.render.scene import load  # noqa: E402

SIZE, SPP = 64, 121
E = embree


@njit(nogil=True, error_model="numpy")
def shadows_from_rows(scene, fn, width, F, h, lanes, radiance, buf, bits, valid, idx):
    """The chunk's shadow rays (the lanes ``k < h`` with ``F[SH_OK + k]``) loaded
    into Embree packets straight from the scratch rows, traced, and the
    unblocked ones' contributions added to their paths. Returns how many."""
    j, rays = 0, 0
    for k in range(h + 1):
        last = k == h
        if not last and F[sh.SH_OK + k] != 0.0:
            # as embree._load: the ray in float32, tfar its segment's length
            buf[E.ORG_X * width + j] = F[sh.SH_OX + k]
            buf[E.ORG_Y * width + j] = F[sh.SH_OY + k]
            buf[E.ORG_Z * width + j] = F[sh.SH_OZ + k]
            buf[E.TNEAR * width + j] = 0.0
            buf[E.DIR_X * width + j] = F[sh.SH_DX + k]
            buf[E.DIR_Y * width + j] = F[sh.SH_DY + k]
            buf[E.DIR_Z * width + j] = F[sh.SH_DZ + k]
            buf[E.TIME * width + j] = 0.0
            buf[E.TFAR * width + j] = np.float32(F[sh.SH_SEG + k])
            bits[E.MASK * width + j] = 0xFFFFFFFF
            bits[E.ID * width + j] = 0
            bits[E.FLAGS * width + j] = 0
            idx[j] = k
            j += 1
        if j == width or (last and j > 0):
            for q in range(width):
                valid[q] = -1 if q < j else 0
            if width == 1:
                E._ccall3(fn, np.uint64(scene), np.uint64(buf.ctypes.data), np.uint64(0))
            else:
                E._ccall4(fn, np.uint64(valid.ctypes.data), np.uint64(scene), np.uint64(buf.ctypes.data),
                          np.uint64(0))
            for q in range(j):
                if buf[E.TFAR * width + q] >= 0.0:
                    k2 = idx[q]
                    li = lanes[k2]
                    radiance[li, 0] += F[sh.SH_R + k2]
                    radiance[li, 1] += F[sh.SH_G + k2]
                    radiance[li, 2] += F[sh.SH_B + k2]
            rays += j
            j = 0
    return rays


@njit(nogil=True, error_model="numpy")
def drive(tr, sc, cam, ps, pixel, sample_index, x, u, radiance, rr_key, size, rows):
    """render_paths' loop with shade's steps called one by one; ``rows``: the
    shadow rays traced from the scratch (:func:`shadows_from_rows`) instead of
    copied into the wavefront and traced per wavefront."""
    n = pixel.shape[0]
    w = ci.new_wavefront(size)
    F, lanes = np.empty(sh.SCRATCH), np.empty(sh.CHUNK, np.int64)
    cs = np.empty(ccam.SCRATCH)
    buf, bits = E._packet_buffer(tr.packet)
    valid, idx = np.empty(tr.packet, np.int32), np.empty(tr.packet, np.int64)
    for start in range(0, n, size):
        m = min(size, n - start)
        ci.start_paths(cam, ps, pixel, x, u, start, m, cs, w)
        live = m
        for depth in range(1, ps.max_depth + 1):
            if live == 0:
                break
            E.intersect(tr.scene, tr.hit, tr.packet, w.o[:live], w.d[:live], w.prim, w.t)
            if depth == ps.max_depth:
                sh.emission_only(live, depth, ps.mis, sc, w, radiance)
                break
            nn, live, shadows = live, 0, 0
            extend = ps.mis or depth < ps.max_depth - 1
            for s0 in range(0, nn, sh.CHUNK):
                h = sh.gather(s0, min(s0 + sh.CHUNK, nn), depth, sc, ps, x, w, F, lanes)
                sh.head(h, depth, ps.mis, F)
                sh.emit_and_choose(h, sc, F, lanes, radiance)
                sh.light_directions(h, F)
                if extend:
                    sh.sample_lobes(h, F)
                sh.other_kinds(h, extend, F)
                sh.shadow_rays(h, ps.mis, F)
                if rows:
                    shadows_from_rows(tr.scene, tr.occluded, tr.packet, F, h, lanes, radiance, buf, bits, valid,
                                      idx)
                else:
                    shadows = sh.emit_shadows(h, F, lanes, w, shadows)
                if extend:
                    sh.new_rays(h, F)
                    live = sh.survivors(h, depth, ps.rr_depth, F, lanes, sample_index, rr_key, w, live)
            if not rows:
                if shadows:
                    E.occluded(tr.scene, tr.occluded, tr.packet, w.sh_o[:shadows], w.sh_d[:shadows],
                               w.sh_dist[:shadows], w.free)
                ci.add_visible(shadows, w, radiance)


def probe(name: str, robust: bool, rounds: int) -> str:
    scene = load(name)
    if not robust:
        scene = dataclasses.replace(scene, robust_tracing=False)
    kw = dict(sampler="bose", spp=SPP, width=SIZE, height=SIZE)
    want = render(scene, **kw, threads=1)
    integ = want.integrator[0]
    if integ.filter != "box":
        raise SystemExit("the probe renders with the box filter only")
    smp = plan(scene, **kw).sampler
    n_pix = SIZE * SIZE
    x = np.ascontiguousarray(smp.generate(pixels=range(n_pix)).reshape(n_pix * smp.spp, -1))
    pixel = np.repeat(np.arange(n_pix), smp.spp).astype(np.int64)
    sample = np.tile(np.arange(smp.spp), n_pix).astype(np.int64)
    rr_key = hash_pair(U32(smp.seed), pixel.astype(U32), RR_KEY).astype(np.int64)
    radiance = np.zeros((len(pixel), 3))  # one array, zeroed in place (probe_shading_stages.py says why)
    args = (integ._tracer, integ._scene, integ._camera, integ._settings, pixel, sample, x, np.zeros((0, 2)))
    times = {False: [], True: []}
    for r in range(rounds + 1):
        for rows in ((False, True) if r % 2 == 0 else (True, False)):
            radiance.fill(0.0)
            t0 = time.perf_counter()
            drive(*args, radiance, rr_key, integ.wavefront, rows)
            if r:  # round 0 compiles and warms
                times[rows].append(time.perf_counter() - t0)
            img = (pixel_sums(radiance, smp.spp) / smp.spp).astype(np.float32)
            assert img.tobytes() == want.image.reshape(-1, 3).tobytes(), \
                f"the driver ({'rows' if rows else 'shipped'}) no longer renders what render_paths does"
    paths = len(pixel)
    ns = {k: np.array(v) / paths * 1e9 for k, v in times.items()}
    gain = np.median(ns[False]) - np.median(ns[True])
    return (f"{name} {'robust' if robust else 'fast'}: shipped {ns[False].min():.1f}-{np.median(ns[False]):.1f}, "
            f"from the scratch {ns[True].min():.1f}-{np.median(ns[True]):.1f} ns per path (min-median of {rounds} "
            f"alternated rounds; the same image): {gain:.1f} ns a path less, "
            f"{gain / np.median(ns[False]):.1%} of the path")


def main(argv: list[str]) -> int:
    from pyoa.hostcpu import host_cpu

    rounds = 7
    if "--rounds" in argv:
        i = argv.index("--rounds")
        rounds = int(argv[i + 1])
        argv = argv[:i] + argv[i + 2:]
    specs = argv or ["cornell:R", "dof7d:F", "bounce9d:F"]
    print(f"CPU: {host_cpu().describe()}")
    for spec in specs:
        name, _, mode = spec.partition(":")
        print(probe(name, mode.upper() != "F", rounds), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
