#!/usr/bin/env python3
"""Probe: where a compiled render's time goes, function by function.

``pyoa.render.compiled.integrator.render_paths`` times three stages
(camera, Embree, shading). This probe runs the same loop, a wavefront of
:data:`~pyoa.render.compiled.integrator.WAVEFRONT` paths at a time, as a
compiled driver of its own that calls the renderer's own functions
(``start_paths``: the camera rays, ``embree.intersect``/``occluded``, every step of
``shading.shade``: ``gather``, ``head``, ``emit_and_choose``, ...,
``survivors``, ``emission_only``) with a monotonic clock read between
them, so no Python runs between the steps and each number is the step
itself (plus about 20 ns per clock read, per chunk of
:data:`~pyoa.render.compiled.shading.CHUNK` lanes). The sampler's values are
generated once, before the timing. One thread.

Prints, per scene and tracing mode, ns per camera path of each step, the
largest first. The driver copies ``render_paths``' and ``shade``'s control
flow: if those change, change it too (the probe checks that its image is the
renderer's, bit for bit).

Usage: python benchmarks/probe_shading_stages.py [SCENE:R|F ...]   (default: the four scenes, fast tracing)
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

STEPS = ("camera rays", "closest hits", "gather", "head", "emit_and_choose", "light_directions",
         "sample_lobes", "other_kinds", "shadow_rays", "emit_shadows", "new_rays", "survivors",
         "shadow rays (Embree)", "add_visible", "emission_only")
SIZE, SPP = 64, 121


@njit(nogil=True, error_model="numpy")
def drive(tr, sc, cam, ps, pixel, sample_index, x, u, radiance, spent, clock, rr_key, size):
    n = pixel.shape[0]
    w = ci.new_wavefront(size)
    F, lanes = np.empty(sh.SCRATCH), np.empty(sh.CHUNK, np.int64)
    cs = np.empty(ccam.SCRATCH)
    ts = np.zeros(2, np.int64)
    now = ci._now
    for start in range(0, n, size):
        m = min(size, n - start)
        a = now(clock, ts)
        ci.start_paths(cam, ps, pixel, x, u, start, m, cs, w)
        spent[0] += now(clock, ts) - a
        live = m
        for depth in range(1, ps.max_depth + 1):
            if live == 0:
                break
            a = now(clock, ts)
            embree.intersect(tr.scene, tr.hit, tr.packet, w.o[:live], w.d[:live], w.prim, w.t)
            b = now(clock, ts)
            spent[1] += b - a
            if depth == ps.max_depth:
                sh.emission_only(live, depth, ps.mis, sc, w, radiance)
                spent[14] += now(clock, ts) - b
                break
            nn, live, shadows = live, 0, 0
            extend = ps.mis or depth < ps.max_depth - 1
            for s0 in range(0, nn, sh.CHUNK):
                t = np.empty(12)
                t[0] = now(clock, ts)
                h = sh.gather(s0, min(s0 + sh.CHUNK, nn), depth, sc, ps, x, w, F, lanes)
                t[1] = now(clock, ts)
                sh.head(h, depth, ps.mis, F)
                t[2] = now(clock, ts)
                sh.emit_and_choose(h, sc, F, lanes, radiance)
                t[3] = now(clock, ts)
                sh.light_directions(h, F)
                t[4] = now(clock, ts)
                if extend:
                    sh.sample_lobes(h, F)
                t[5] = now(clock, ts)
                sh.other_kinds(h, extend, F)
                t[6] = now(clock, ts)
                sh.shadow_rays(h, ps.mis, F)
                t[7] = now(clock, ts)
                shadows = sh.emit_shadows(h, F, lanes, w, shadows)
                t[8] = now(clock, ts)
                if extend:
                    sh.new_rays(h, F)
                    t[9] = now(clock, ts)
                    live = sh.survivors(h, depth, ps.rr_depth, F, lanes, sample_index, rr_key, w, live)
                else:
                    t[9] = t[8]
                t[10] = now(clock, ts)
                for k in range(10):
                    spent[2 + k] += t[k + 1] - t[k]
            a = now(clock, ts)
            if shadows:
                embree.occluded(tr.scene, tr.occluded, tr.packet, w.sh_o[:shadows], w.sh_d[:shadows],
                                w.sh_dist[:shadows], w.free)
            b = now(clock, ts)
            spent[12] += b - a
            ci.add_visible(shadows, w, radiance)
            spent[13] += now(clock, ts) - b


def probe(name: str, robust: bool) -> str:
    scene = load(name)
    if not robust:
        scene = dataclasses.replace(scene, robust_tracing=False)
    kw = dict(sampler="bose", spp=SPP, width=SIZE, height=SIZE)
    want = render(scene, **kw, threads=1)
    integ = want.integrator[0]
    smp = plan(scene, **kw).sampler
    n_pix = SIZE * SIZE
    x = np.ascontiguousarray(smp.generate(pixels=range(n_pix)).reshape(n_pix * smp.spp, -1))
    pixel = np.repeat(np.arange(n_pix), smp.spp).astype(np.int64)
    sample = np.tile(np.arange(smp.spp), n_pix).astype(np.int64)
    rr_key = hash_pair(U32(smp.seed), pixel.astype(U32), RR_KEY).astype(np.int64)
    if integ.filter != "box":
        raise SystemExit("the probe renders with the box filter only")
    best = None
    # one radiance array, zeroed in place: a fresh np.zeros per round maps new pages, and the first write to
    # each (in add_visible or emit_and_choose) would time the kernel's page faults, which the renderer, whose
    # batches reuse freed heap memory, mostly does not pay
    radiance = np.zeros((len(pixel), 3))
    for _ in range(3):
        spent = np.zeros(len(STEPS))
        radiance.fill(0.0)
        t0 = time.perf_counter()
        drive(integ._tracer, integ._scene, integ._camera, integ._settings, pixel, sample, x, np.zeros((0, 2)),
              radiance, spent, integ._clock, rr_key, integ.wavefront)
        seconds = time.perf_counter() - t0
        if best is None or seconds < best[0]:
            best = (seconds, spent)
    # the driver's image is the renderer's (render()'s per-pixel sum)
    s = pixel_sums(radiance, smp.spp)
    assert (s / smp.spp).astype(np.float32).tobytes() == want.image.reshape(-1, 3).tobytes(), \
        "the probe's driver no longer renders what render_paths does: update it"
    seconds, spent = best
    paths = len(pixel)
    order = np.argsort(-spent)
    steps = ", ".join(f"{STEPS[i]} {spent[i] / paths * 1e9:.1f}" for i in order if spent[i] > 0)
    return (f"{name} {'robust' if robust else 'fast'}: {seconds / paths * 1e9:.0f} ns per path in all "
            f"(one thread, {SIZE} x {SIZE}, bose {smp.spp} spp); {steps}")


def main(argv: list[str]) -> int:
    from pyoa.hostcpu import host_cpu

    specs = argv or [f"{s}:F" for s in ("cornell", "dof7d", "bounce9d", "deep")]
    print(f"CPU: {host_cpu().describe()}")
    for spec in specs:
        name, _, mode = spec.partition(":")
        print(probe(name, mode.upper() != "F"), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
