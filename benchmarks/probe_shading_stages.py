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
def shadows_from_rows(scene, fn, width, F, h, lanes, radiance, buf, bits, valid, idx):
    """A piece of a redesign, measured before it is built (``probe_shadow_rows.py``):
    the chunk's shadow rays (the lanes ``k < h`` with ``F[SH_OK + k]``) loaded
    into Embree packets straight from the scratch rows, traced, and the
    unblocked ones' contributions added to their paths, instead of
    ``emit_shadows`` copying them into the wavefront for ``embree.occluded``
    and ``add_visible``. Each path adds its light in the same order, so the
    image is the same. Returns how many rays."""
    E = embree
    j, rays = 0, 0
    for k in range(h + 1):
        last = k == h
        if not last and F[sh.SH_OK + k] != 0.0:
            E._load_ray(buf, bits, width, j, F[sh.SH_OX + k], F[sh.SH_OY + k], F[sh.SH_OZ + k], F[sh.SH_DX + k],
                        F[sh.SH_DY + k], F[sh.SH_DZ + k], np.float32(F[sh.SH_SEG + k]))
            idx[j] = k
            j += 1
        if j == width or (last and j > 0):
            for q in range(width):
                valid[q] = -1 if q < j else 0
            E._query(scene, fn, width, buf, valid)
            for q in range(j):
                if buf[E.TFAR * width + q] >= 0.0:
                    li = lanes[idx[q]]
                    radiance[li, 0] += F[sh.SH_R + idx[q]]
                    radiance[li, 1] += F[sh.SH_G + idx[q]]
                    radiance[li, 2] += F[sh.SH_B + idx[q]]
            rays += j
            j = 0
    return rays


@njit(nogil=True, error_model="numpy")
def drive(tr, sc, cam, ps, pixel, sample_index, x, u, radiance, spent, clock, rr_key, size, rows=False):
    """``render_paths``' loop with ``shade``'s steps called one by one, the
    clock read between them (``spent``: seconds per step of :data:`STEPS`).
    ``rows``: the shadow rays traced from the scratch
    (:func:`shadows_from_rows`, timed as ``emit_shadows``) instead."""
    n = pixel.shape[0]
    w = ci.new_wavefront(size)
    F, lanes = np.empty(sh.SCRATCH), np.empty(sh.CHUNK, np.int64)
    cs = np.empty(ccam.SCRATCH)
    ts = np.zeros(2, np.int64)
    now = ci._now
    buf, bits = embree._packet_buffer(tr.packet)
    valid, idx = np.empty(tr.packet, np.int32), np.empty(tr.packet, np.int64)
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
                sh.other_kinds(h, extend, sc.kinds, F)
                t[6] = now(clock, ts)
                sh.shadow_rays(h, ps.mis, F)
                t[7] = now(clock, ts)
                if rows:
                    shadows_from_rows(tr.scene, tr.occluded, tr.packet, F, h, lanes, radiance, buf, bits, valid,
                                      idx)
                else:
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


def inputs(name: str, robust: bool):
    """The scene (``robust`` or fast tracing), ``render``'s own result at
    :data:`SIZE` x :data:`SIZE`, Bose :data:`SPP` spp, one thread (``want``:
    the image a driver must give, and its integrator), and the driver's
    arguments from ``pixel`` to ``rr_key`` (the sampler's values made once)."""
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
    return want, smp, pixel, sample, x, rr_key


def check_image(radiance, smp, want, what: str) -> None:
    """The driver's image is ``render``'s (its per-pixel sum), bit for bit."""
    s = pixel_sums(radiance, smp.spp)
    assert (s / smp.spp).astype(np.float32).tobytes() == want.image.reshape(-1, 3).tobytes(), \
        f"the probe's driver ({what}) no longer renders what render_paths does: update it"


def probe(name: str, robust: bool) -> str:
    want, smp, pixel, sample, x, rr_key = inputs(name, robust)
    integ = want.integrator[0]
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
    check_image(radiance, smp, want, "as shipped")
    seconds, spent = best
    paths = len(pixel)
    order = np.argsort(-spent)
    steps = ", ".join(f"{STEPS[i]} {spent[i] / paths * 1e9:.1f}" for i in order if spent[i] > 0)
    return (f"{name} {'robust' if robust else 'fast'}: {seconds / paths * 1e9:.0f} ns per path in all "
            f"(one thread, {SIZE} x {SIZE}, bose {smp.spp} spp); {steps}")


def main(argv: list[str]) -> int:
    from pyoa.util.hostcpu import host_cpu

    specs = argv or [f"{s}:F" for s in ("cornell", "dof7d", "bounce9d", "deep")]
    print(f"CPU: {host_cpu().describe()}")
    for spec in specs:
        name, _, mode = spec.partition(":")
        print(probe(name, mode.upper() != "F"), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
