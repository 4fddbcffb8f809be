#!/usr/bin/env python3
"""Render throughput: camera paths and rays per second on the bundled scenes.

What is measured
----------------
For each scene of ``--scenes`` (default: ``cornell``, ``dof7d``, ``bounce9d``
and ``deep``, each at its own max depth unless ``--max-depth`` is given),
``pyoa.render.render.render(scene, sampler=..., spp=..., width=W,
height=H)`` (the function behind ``pyoa render``) with each ``--shading``
(numba: compiled shading calling Embree, the default; numpy: the
reference) on the scene as bundled (robust tracing), and with the numba
shading also on its twin with ``integrator.robust_tracing`` false. Each
runs once as a warm-up on a 16 x 16 image (kernel build, numba's cache,
Embree and import costs); then ``--repeats`` **interleaved rounds** time
every row once each, beside, in the same round:

- **Mitsuba 3** (``cornell`` only: its own ``cornell_box()`` is the scene's
  twin), ``orthogonal`` sampler, LLVM backend, path integrator, if
  ``mitsuba`` is importable (otherwise the report says it was skipped), in
  both tracing modes (its ``embree_use_robust_intersections``; its default
  is false), one subprocess per round and mode;
- the **Embree floor** of each tracing mode: a 96 x 96 render's own rays
  replayed through the shipped tracing path (Embree packets called from
  numba) on two threads, each tracing its half of the wavefronts in one
  compiled call as a render's worker traces a batch, i.e. what the renderer
  would reach if shading were free.

The time covers sample generation, ray tracing and shading, not scene
loading or image writing. Reported: median, minimum and maximum seconds;
camera paths per second and rays per second (camera, continuation and
shadow rays) at the median; the ratios to Mitsuba and to the floor as
medians of per-round ratios (the machine drifts 15-40 % over minutes,
which rounds spread over every row alike); a separate single-threaded
profile of where the time goes (sampling, camera rays, Embree, shading,
host bookkeeping); and **peak memory** (``--memory``, on by default): a
fresh process renders the scene at the full size with each shading twice
and reports the second render's resident-set peak above the baseline
before it (the first render's one-time costs, such as PoCL compiling the
sampler's kernels for new call shapes, excluded; the heap it freed
returned to the OS first), against the stated bound of docs/performance.md.

Output: ``benchmarks/results/render.json`` and ``render.md`` (``--out``),
written atomically, then the docs' marked sections made from ``render.json``
(``update_docs.after``: README, docs/performance.md).

Usage::

    python benchmarks/bench_render.py                        # all four scenes, 256x256, bose 121 spp
    python benchmarks/bench_render.py --scenes cornell --max-depth 5 --shading numba
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as _dt
import json
import os
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))  # peers.py and common.py, shared with the other benchmarks

import numpy as np  # noqa: E402
import peers  # noqa: E402
from common import MEMORY_CHILD_HELPERS, loadavg, log, machine, machine_lines, write_text  # noqa: E402
import update_docs  # noqa: E402
from numba import njit  # noqa: E402

from pyoa.render import embree  # noqa: E402
from pyoa.render.render import BATCH_PATHS, batch_layout, render, values_ahead_bytes  # noqa: E402
from pyoa.render.scene import load  # noqa: E402

SCENES = ("cornell", "dof7d", "bounce9d", "deep")


_MITSUBA = """
import json, statistics, sys, time
import numpy as np
import mitsuba as mi
w, h, spp, depth, repeats, robust = map(int, sys.argv[1:7])
mi.set_variant("llvm_ad_rgb")
d = mi.cornell_box()
d["embree_use_robust_intersections"] = bool(robust)  # Mitsuba's default: False
d["sensor"]["sampler"] = {"type": "orthogonal", "sample_count": spp}
d["sensor"]["film"]["width"], d["sensor"]["film"]["height"] = w, h
d["integrator"] = {"type": "path", "max_depth": depth}
sc = mi.load_dict(d)
np.asarray(mi.render(sc, spp=spp))
times = []
for _ in range(repeats):
    t0 = time.perf_counter()
    np.asarray(mi.render(sc, spp=spp))
    times.append(time.perf_counter() - t0)
med = statistics.median(times)
print(json.dumps({"status": "ok", "version": mi.__version__, "times_s": times, "median_s": med,
                  "paths_per_s": w * h * spp / med}))
"""


def mitsuba_figure(scene: str, width: int, height: int, spp: int, depth: int, repeats: int, robust: bool) -> dict:
    """Mitsuba 3's ``orthogonal`` sampler on its own ``cornell_box()``, in a
    subprocess (a Dr.Jit/LLVM failure must not take this benchmark down;
    ``peers.run_json_script``), tracing with Embree's robust mode or without
    it (Mitsuba's default; its scene property ``embree_use_robust_intersections``)."""
    if not peers.mitsuba_available():
        return {"status": "skipped", "reason": "mitsuba is not installed (pip install mitsuba)"}
    if scene != "cornell":
        return {"status": "skipped", "reason": "only the cornell scene has a Mitsuba twin"}
    res = peers.run_json_script(_MITSUBA, [width, height, spp, depth, repeats, int(robust)], env=peers.mitsuba_env())
    res["libllvm"] = peers.drjit_llvm()
    return res


def _wrap(cls, name, spent, part, originals, lock=None):
    """Time every call of ``cls.name`` into ``spent[part]`` (``part`` None:
    no timing), holding ``lock`` (if given) for the call."""
    real = getattr(cls, name)
    originals.append((cls, name, real))
    held = lock if lock is not None else contextlib.nullcontext()

    def timed(*a, **kw):
        with held:
            t0 = time.perf_counter()
            try:
                return real(*a, **kw)
            finally:
                if part is not None:
                    spent[part] += time.perf_counter() - t0

    setattr(cls, name, timed)


def profile_parts(scene, args, shading: str) -> dict:
    """Where one render's time goes, from a separate single-threaded render of
    the same image (one thread, so the parts add up to the wall time). The
    renderer samples on a thread of its own, ahead of its worker: here a
    lock held by each sampler call and each batch's tracing keeps the two
    from overlapping, so that the parts are one thread's time.

    ``sampling`` is ``Sampler.generate`` (the OA values of each batch). With
    ``numpy`` shading, ``intersection`` is Embree through embreex (closest
    hits and shadow rays) and ``shading`` everything else (NumPy camera rays,
    BSDFs, emitter sampling, MIS, lane bookkeeping). With ``numba`` shading
    the compiled integrator times its own stages (``camera``, ``embree``:
    packets of closest hits and shadow rays, ``shading``: the compiled bounce
    and the shadow-ray contributions, ``host``: the Python between them) and
    ``other`` is the rest (per-pixel means, the batch loop). The headline
    figures come from the timed runs, not from this one."""
    from pyoa.render.compiled.integrator import CompiledIntegrator
    from pyoa.render.integrator import Integrator
    from pyoa.samplers import Sampler

    spent = {"sampling": 0.0}
    originals = []
    one_at_a_time = threading.Lock()
    _wrap(Sampler, "generate", spent, "sampling", originals, one_at_a_time)
    _wrap(CompiledIntegrator if shading == "numba" else Integrator, "radiance", spent, None, originals, one_at_a_time)
    if shading == "numpy":
        spent["intersection"] = 0.0
        _wrap(Integrator, "_intersect", spent, "intersection", originals)
        _wrap(Integrator, "_visible", spent, "intersection", originals)
    try:
        w, h = args.size
        res = render(scene, sampler=args.sampler, spp=args.spp, width=w, height=h, max_depth=args.max_depth,
                     threads=1, shading=shading)
    finally:
        for cls, name, real in originals:
            setattr(cls, name, real)
    if shading == "numpy":
        parts = dict(spent, shading=res.seconds - sum(spent.values()))
    else:
        parts = dict(spent, **res.timings)
        parts["other"] = res.seconds - sum(parts.values())
    return {"threads": 1, "seconds": res.seconds, "paths_per_s": res.paths_per_second,
            "rays_per_s": res.rays_per_second, "parts_s": parts,
            "shares": {k: v / res.seconds for k, v in parts.items()}}


def record_rays(scene, args, size) -> tuple[list, int]:
    """The rays of a ``size`` render of ``scene`` with the compiled shading:
    ``(wavefronts, paths)``, ``wavefronts`` a list of each wavefront's calls
    in the order they are traced, ``("hit", o, d, None)`` for closest hits
    and ``("occ", o, d, dist)`` for shadow rays. The
    render runs the compiled integrator's own stages (camera rays,
    ``shading.shade``, ``add_visible``) one wavefront at a time from Python, as
    ``render_paths`` runs them in one compiled call, and copies each
    wavefront's rays before tracing them."""
    from pyoa.render.camera import filter_offsets
    from pyoa.render.compiled import camera as ccam
    from pyoa.render.compiled import integrator as ci
    from pyoa.render.compiled import shading as csh
    from pyoa.render.integrator import RR_KEY, U32, hash_pair

    res = render(scene, sampler=args.sampler, spp=args.spp, width=size[0], height=size[1],
                 max_depth=args.max_depth, threads=1, shading="numba", pixels=range(0, 1))
    integ = res.integrator[0]
    smp_kw = dict(sampler=args.sampler, spp=args.spp, width=size[0], height=size[1], max_depth=args.max_depth)
    from pyoa.render.render import plan

    p = plan(scene, **smp_kw)
    L, n_pix = integ.layout, size[0] * size[1]
    x = np.ascontiguousarray(p.sampler.generate(pixels=range(n_pix)).reshape(n_pix * p.sampler.spp, -1))
    pixel = np.repeat(np.arange(n_pix), p.sampler.spp)
    sample = np.tile(np.arange(p.sampler.spp), n_pix).astype(np.int64)
    u = np.ascontiguousarray(filter_offsets(x[:, list(L.pair("pixel"))].astype(np.float64), integ.filter))
    rr_key = hash_pair(U32(p.sampler.seed), pixel.astype(U32), RR_KEY).astype(np.int64)
    radiance = np.zeros((len(pixel), 3))
    tr, sc, cam, ps = integ._tracer, integ._scene, integ._camera, integ._settings
    wavefronts = []
    size_w = integ.wavefront
    w = ci.new_wavefront(size_w)
    scratch, lanes = np.empty(csh.SCRATCH), np.empty(csh.CHUNK, np.int64)
    cam_scratch = np.empty(ccam.SCRATCH)
    for start in range(0, len(pixel), size_w):
        m = min(size_w, len(pixel) - start)
        ci.start_paths(cam, ps, pixel, x, u, start, m, cam_scratch, w)
        calls = []
        wavefronts.append(calls)
        live = m
        for depth in range(1, ps.max_depth + 1):
            if live == 0:
                break
            calls.append(("hit", w.o[:live].copy(), w.d[:live].copy(), None))
            embree.intersect(tr.scene, tr.hit, tr.packet, w.o[:live], w.d[:live], w.prim, w.t)
            live, shadows = csh.shade(live, depth, sc, ps, x, sample, rr_key, w, radiance, scratch, lanes)
            if shadows:
                calls.append(("occ", w.sh_o[:shadows].copy(), w.sh_d[:shadows].copy(), w.sh_dist[:shadows].copy()))
                embree.occluded(tr.scene, tr.occluded, tr.packet, w.sh_o[:shadows], w.sh_d[:shadows],
                                w.sh_dist[:shadows], w.free)
            ci.add_visible(shadows, w, radiance)
    return wavefronts, len(pixel)


@njit(nogil=True)
def replay_wavefronts(scene, hit, occluded, width, kinds, offsets, o, d, dist):
    """Trace the wavefronts ``offsets[c] .. offsets[c + 1]`` of the rays
    ``o``, ``d`` (closest hits where ``kinds[c]`` is 0, shadow rays of
    length ``dist`` where it is 1) through ``embree.intersect`` and
    ``embree.occluded``, all in one compiled call that releases the GIL, as
    ``render_paths`` traces a batch's."""
    most = 1
    for c in range(kinds.shape[0]):
        most = max(most, offsets[c + 1] - offsets[c])
    prim, t, free = np.empty(most, np.int64), np.empty(most), np.empty(most, np.bool_)
    for c in range(kinds.shape[0]):
        a, b = offsets[c], offsets[c + 1]
        if kinds[c] == 0:
            embree.intersect(scene, hit, width, o[a:b], d[a:b], prim, t)
        else:
            embree.occluded(scene, occluded, width, o[a:b], d[a:b], dist[a:b], free)


def pack_calls(calls: list) -> tuple:
    """``(kinds, offsets, o, d, dist)``: the calls ``calls`` (of
    :func:`record_rays`' wavefronts) as contiguous arrays for
    :func:`replay_wavefronts`."""
    kinds = np.array([0 if kind == "hit" else 1 for kind, *_ in calls], np.int64)
    offsets = np.zeros(len(calls) + 1, np.int64)
    offsets[1:] = np.cumsum([len(o) for _, o, _, _ in calls])
    o = np.ascontiguousarray(np.concatenate([o for _, o, _, _ in calls]))
    d = np.ascontiguousarray(np.concatenate([d for _, _, d, _ in calls]))
    dist = np.concatenate([np.zeros(len(o)) if dist is None else dist for _, o, _, dist in calls])
    return kinds, offsets, o, d, dist


class EmbreeFloor:
    """The tracing path pyoa ships (Embree packets called from numba, the
    scene built as the renderer builds it) alone: the rays of a ``size``
    render of the same scene, sampler, spp and depth (:func:`record_rays`),
    replayed on two threads by :meth:`run`: each takes every other
    wavefront, its closest hits and shadow rays, and traces them in one
    compiled call that releases the GIL (:func:`replay_wavefronts`), as a
    render's worker traces a batch's: no Python runs between two
    wavefronts. Two earlier versions understated it (docs/performance.md,
    "What the floor is"): until commit fdffe45 the threads called
    ``embree.intersect`` / ``occluded`` from Python once per wavefront and
    queued for the GIL between calls; before commit 32ec017 they took every
    other *call*, and as the calls alternate closest hits and shadow rays,
    one thread traced nearly all the closest hits and the other the shadow
    rays.
    Its ``paths_per_s`` is the rate at the render's own rays per path: what
    the renderer would reach if shading, sampling and bookkeeping were free."""

    def __init__(self, scene, args, size=(96, 96)):
        from pyoa.render.compiled import integrator as ci

        wavefronts, paths = record_rays(scene, args, size)
        self.size, self.packet, self.mode = list(size), ci.packet_width(), tracing(scene)
        self.rtc = embree.Scene(scene.triangles, robust=scene.robust_tracing)
        self.fns = embree.query_addresses(self.packet)
        self.rays = sum(len(c[1]) for wf in wavefronts for c in wf)
        self.rays_per_path = self.rays / paths
        self.parts = [pack_calls([c for wf in wavefronts[k::2] for c in wf]) for k in (0, 1)]
        self.times = []
        self._trace(pack_calls(wavefronts[0] + wavefronts[1]))  # compile and warm

    def _trace(self, part):
        replay_wavefronts(self.rtc.handle, self.fns[0], self.fns[1], self.packet, *part)

    def run(self) -> float:
        """One timed replay on two threads; returns its M paths/s equivalent's rate (paths/s)."""
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(2) as pool:
            t0 = time.perf_counter()
            list(pool.map(self._trace, self.parts))
            self.times.append(time.perf_counter() - t0)
        return self.rays / self.times[-1] / self.rays_per_path

    def summary(self) -> dict:
        med = statistics.median(self.times)
        return {"size": self.size, "rays": self.rays, "packet": self.packet, "threads": 2, "times_s": self.times,
                "rays_per_s": self.rays / med, "rays_per_path": self.rays_per_path,
                "paths_per_s": self.rays / med / self.rays_per_path, "replay": "compiled, one call per thread"}


def _render(scene, args, shading: str, **kw):
    w, h = args.size
    return render(scene, sampler=args.sampler, spp=args.spp, width=kw.pop("width", w), height=kw.pop("height", h),
                  max_depth=args.max_depth, shading=shading, **kw)


def tracing(scene) -> str:
    """``"robust"`` or ``"fast"``: how the compiled shading traces ``scene``
    (its ``integrator.robust_tracing``; the NumPy shading is always robust)."""
    return "robust" if scene.robust_tracing else "fast"


def fast_twin(scene):
    """``scene`` loaded again with ``integrator.robust_tracing`` false."""
    import dataclasses

    return dataclasses.replace(scene, robust_tracing=False)


def _row(scene, shading: str, times: list, res) -> dict:
    """A pyoa row from its timed renders (paths and rays are the same in
    every run: the image is deterministic); rates at the median."""
    med = statistics.median(times)
    mode = tracing(scene) if shading == "numba" else "robust"
    log(f"  {scene.name} {shading} {mode}: {res.stats.paths / med / 1e6:.3f} M paths/s, "
        f"{res.stats.rays / med / 1e6:.2f} M rays/s")
    return {"shading": shading, "tracing": mode, "times_s": times, "median_s": med, "min_s": min(times),
            "max_s": max(times), "paths_per_s": res.stats.paths / med, "rays_per_s": res.stats.rays / med,
            "rays_per_path": res.stats.rays / res.stats.paths, "dims": res.dims}


# ---------------------------------------------------------------------------
# peak memory, in a fresh process per render

_MEMORY_CHILD = MEMORY_CHILD_HELPERS + r"""
import ctypes, gc, json, sys
from pyoa.render.render import render
from pyoa.render.scene import load

name, sampler, shading = sys.argv[1:4]
spp, w, h, depth, batch = (int(v) if v != "None" else None for v in sys.argv[4:9])
scene = load(name)
# Warm-up: the same render first, so that the peak measured is the render's working set, not the one-time
# costs of a process's first render of this shape (PoCL compiles a kernel per sampler call shape, LLVM's
# memory with it; numba's and Embree's set-up); then the heap the warm-up freed goes back to the OS
# (malloc_trim), so that the measured render cannot hide its arrays in memory counted in the baseline.
render(scene, sampler=sampler, spp=spp, width=w, height=h, max_depth=depth, shading=shading, batch_paths=batch)
gc.collect()
ctypes.CDLL("libc.so.6").malloc_trim(0)
base = status_kib("VmRSS")
if not reset_peak():  # VmHWM := VmRSS: the peak is the render's own
    raise SystemExit("cannot reset VmHWM (/proc/self/clear_refs): no peak of the render alone")
res = render(scene, sampler=sampler, spp=spp, width=w, height=h, max_depth=depth, shading=shading, batch_paths=batch)
print(json.dumps({"status": "ok", "baseline_kib": base, "peak_kib": status_kib("VmHWM"), "dims": res.dims,
                  "shading": res.shading}))
"""


#: glibc's mmap threshold in the memory children (``MALLOC_MMAP_THRESHOLD_``).
MMAP_THRESHOLD = 128 * 1024
#: Bytes per camera path in flight of docs/performance.md's stated bound
#: ("Render memory"), by shading.
STATED_PATH_BYTES = {"numba": 512, "numpy": 1536}


def peak_memory(scene_name: str, args, shading: str, size: tuple[int, int], batch_paths: int) -> dict:
    """The render's resident-set peak above its warmed-up baseline, in a fresh
    process, beside the image's own bytes, the batch working set this implies
    per camera path (``threads x batch_paths`` paths are in flight), and the
    stated bound: ``B`` bytes per path in flight (:data:`STATED_PATH_BYTES`),
    the float32 sampler values made ahead of the workers
    (:func:`pyoa.render.render.values_ahead_bytes`) and the image."""
    argv = [scene_name, args.sampler, shading, args.spp, *size, args.max_depth, batch_paths]
    # glibc's mmap threshold fixed (it grows with every large free by default): every array above 128 KiB is
    # its own mapping, returned to the OS when freed, so the baseline holds no freed arrays a render could reuse
    env = dict(os.environ, MALLOC_MMAP_THRESHOLD_=str(MMAP_THRESHOLD))
    proc = subprocess.run([sys.executable, "-c", _MEMORY_CHILD, *map(str, argv)], capture_output=True, text=True,
                          timeout=1800, env=env)
    entry = {"scene": scene_name, "shading": shading, "size": list(size), "batch_paths": batch_paths}
    if proc.returncode != 0:
        return {**entry, "status": "failed", "reason": (proc.stderr.strip().splitlines() or ["?"])[-1]}
    res = json.loads(proc.stdout.strip().splitlines()[-1])
    threads = os.cpu_count() or 1
    pixels, batches, workers = batch_layout(size[0] * size[1], args.spp, batch_paths=batch_paths, threads=threads)
    per_batch = pixels * args.spp  # paths: whole pixels
    in_flight = workers * per_batch
    above = (res["peak_kib"] - res["baseline_kib"]) * 1024
    image = 12 * size[0] * size[1]
    ahead = values_ahead_bytes(batches, per_batch, res["dims"], workers)
    bound = in_flight * STATED_PATH_BYTES[res["shading"]] + ahead + image
    entry.update(status="ok", threads=threads, baseline_bytes=res["baseline_kib"] * 1024, above_bytes=above,
                 image_bytes=image, paths_in_flight=in_flight,
                 bytes_per_path=(above - image) / in_flight, samples_ahead_bytes=ahead, bound_bytes=bound)
    log(f"  memory {scene_name} {shading} {size[0]}x{size[1]} batch {batch_paths}: "
        f"{above / 2**20:.1f} MiB above baseline ({entry['bytes_per_path']:.0f} B per path in flight; "
        f"stated bound {bound / 2**20:.1f} MiB)")
    return entry


def memory_rows(scene_names: list[str], args, shadings: list[str]) -> list[dict]:
    """Peak memory of the full-size render of each scene and shading, and, for
    the first scene, at twice the width and height (the image grows 4x: the
    peak must not, beyond the image's own bytes) and at a quarter of the batch
    (the peak must shrink): the working set is bounded by the batch size."""
    w, h = args.size
    rows = []
    for name in scene_names:
        for sh in shadings:
            rows.append(peak_memory(name, args, sh, (w, h), BATCH_PATHS))
    first = scene_names[0]
    for sh in shadings:
        rows.append(peak_memory(first, args, sh, (2 * w, 2 * h), BATCH_PATHS))
        rows.append(peak_memory(first, args, sh, (w, h), BATCH_PATHS // 4))
    return rows


def bench_scene(name: str, args, shadings: list[str]) -> dict:
    """Every shading on the scene as bundled (robust tracing), the compiled
    shading also without robust mode, Mitsuba in both tracing modes and the
    Embree floor of each mode, **interleaved**: ``--repeats`` rounds, each
    timing every one of them once, so that the machine's drift (15-40 %
    over minutes) falls on all alike; the ratios are medians of the
    per-round ratios (each pyoa render against Mitsuba and the floor of its
    own round and tracing mode). Then a single-threaded profile per row."""
    scene = load(name)
    assert scene.robust_tracing, "the bundled scenes trace robustly"
    w, h = args.size
    depth = args.max_depth or scene.max_depth
    log(f"{name}: {w} x {h}, {args.sampler} {args.spp} spp, max depth {depth}")
    variants = [(scene, sh) for sh in shadings]
    if "numba" in shadings:
        variants.append((fast_twin(scene), "numba"))
    modes = ("robust", "fast") if "numba" in shadings else ("robust",)
    floors = {m: EmbreeFloor(sc, args) for m, sc in (("robust", scene), ("fast", fast_twin(scene))) if m in modes
              and "numba" in shadings}
    for sc, sh in variants:  # warm-up: kernel builds, numba's cache, Embree and imports
        _render(sc, args, sh, width=16, height=16)
    times, last = [[] for _ in variants], [None] * len(variants)
    mit = {m: {"status": "skipped", "reason": "only the cornell scene has a Mitsuba twin"} for m in modes}
    mit_rounds = {m: [] for m in modes}
    floor_rounds = {m: [] for m in floors}
    for r in range(args.repeats):
        for i, (sc, sh) in enumerate(variants):
            t0 = time.perf_counter()
            last[i] = _render(sc, args, sh)
            times[i].append(time.perf_counter() - t0)
            log(f"  round {r + 1}/{args.repeats}: {name} {sh} {tracing(sc) if sh == 'numba' else 'robust'}: "
                f"{times[i][-1]:.3f} s")
        for m in modes:
            res = mitsuba_figure(name, w, h, args.spp, depth, 1, m == "robust")
            if res.get("status") == "ok":
                mit_rounds[m].append(res["paths_per_s"])
                prev = mit[m] if mit[m].get("status") == "ok" else {**res, "times_s": []}
                prev["times_s"] = prev["times_s"] + res["times_s"]
                mit[m] = prev
                log(f"  round {r + 1}/{args.repeats}: Mitsuba {m}: {res['times_s'][0]:.3f} s")
            else:
                mit[m] = res
        for m, fl in floors.items():
            floor_rounds[m].append(fl.run())
    for m, res in mit.items():
        if res.get("status") == "ok":
            med = statistics.median(res["times_s"])
            res.update(median_s=med, paths_per_s=w * h * args.spp / med)
            if len(floor_rounds.get(m, ())) == len(mit_rounds[m]):
                # Mitsuba's share of the same floor, round by round: what a production renderer reaches of it
                res["vs_floor"] = statistics.median(a / b for a, b in zip(mit_rounds[m], floor_rounds[m]))
    rows = []
    for i, (sc, sh) in enumerate(variants):
        row = _row(sc, sh, times[i], last[i])
        paths = last[i].stats.paths
        rates = [paths / t for t in times[i]]
        if sh == "numba":
            m = row["tracing"]
            if len(mit_rounds[m]) == len(rates):
                row["vs_mitsuba"] = statistics.median(a / b for a, b in zip(rates, mit_rounds[m]))
            if m in floor_rounds:
                row["vs_floor"] = statistics.median(a / b for a, b in zip(rates, floor_rounds[m]))
        row["profile"] = profile_parts(sc, args, sh)
        rows.append(row)
    return {"scene": name, "max_depth": depth, "results": rows, "mitsuba": mit,
            "embree_floor": {m: fl.summary() for m, fl in floors.items()}}


def _csv(text: str, valid: tuple[str, ...], what: str) -> list[str]:
    items = [v.strip() for v in text.split(",") if v.strip()]
    bad = [v for v in items if v not in valid]
    if bad or not items:
        raise argparse.ArgumentTypeError(f"{what} takes a comma-separated subset of {', '.join(valid)}; got {text!r}")
    return items


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    ap.add_argument("--scenes", type=lambda t: _csv(t, SCENES, "--scenes"), default=list(SCENES),
                    help=f"comma-separated bundled scenes (default {','.join(SCENES)})")
    ap.add_argument("--sampler", default="bose")
    ap.add_argument("--spp", type=int, default=121)
    ap.add_argument("--size", type=int, nargs=2, default=(256, 256), metavar=("W", "H"))
    ap.add_argument("--max-depth", type=int, default=None, help="default: each scene's own")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--shading", type=lambda t: _csv(t, ("numba", "numpy"), "--shading"), default=["numba", "numpy"],
                    help="comma-separated shadings to time (default numba,numpy)")
    ap.add_argument("--no-memory", dest="memory", action="store_false", help="skip the peak-memory renders")
    ap.add_argument("--out", default=str(REPO / "benchmarks" / "results" / "render.json"))
    args = ap.parse_args(argv)
    if args.repeats < 1 or args.spp < 1 or min(args.size) < 1:
        ap.error("--repeats, --spp and --size must be positive")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    meta = machine()
    log(f"pyoa {meta['pyoa']} (git {meta['git_commit'] or 'unknown'}) on {meta['cpu']}")
    meta["loadavg_start"] = loadavg()
    scenes = [bench_scene(name, args, args.shading) for name in args.scenes]
    memory = memory_rows(args.scenes, args, args.shading) if args.memory else []
    meta["loadavg_end"] = loadavg()
    report = {
        "date_utc": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "machine": meta,
        "config": {"scenes": args.scenes, "sampler": args.sampler, "spp": args.spp, "size": list(args.size),
                   "max_depth": args.max_depth, "repeats": args.repeats, "shadings": args.shading,
                   "batch_paths": BATCH_PATHS},
        "scenes": scenes, "memory": memory,
    }
    write_text(out, json.dumps(report, indent=2) + "\n")
    md = markdown(report, time.perf_counter() - t_start)
    write_text(out.with_suffix(".md"), md)
    print(md)
    for page in update_docs.after(out):  # the docs' sections made from this file
        print(f"wrote {page}")
    return 0


def _rate(mit: dict):
    return mit.get("paths_per_s") if mit.get("status") == "ok" else None


def scene_markdown(cfg: dict, sc: dict) -> list[str]:
    """A scene's table: each pyoa row beside Mitsuba with the same tracing
    mode (robust or fast), then the Embree floor of each mode."""
    w, h = cfg["size"]
    mit, floors = sc["mitsuba"], sc["embree_floor"]
    lines = [f"## `{sc['scene']}`", "",
             f"{w} x {h}, max depth {sc['max_depth']}, {cfg['sampler']} {cfg['spp']} spp "
             f"({sc['results'][0]['dims']} dims), {cfg['repeats']} interleaved rounds after a warm-up (each round "
             "times every row and the floors once), all CPUs. Tracing: `robust` is Embree's robust mode (pyoa's "
             "default, watertight at shared edges), `fast` without it (Mitsuba's default). The ratios are medians "
             "of per-round ratios, each pyoa render against Mitsuba and the Embree floor of the same round and "
             "tracing mode (Mitsuba's own row: its share of that floor, at pyoa's rays per path).", "",
             "| renderer | tracing | median s | min s | max s | M paths/s | M rays/s | rays/path | / Mitsuba, same tracing | / Embree floor |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in sc["results"]:
        ratio = f"{r['vs_mitsuba']:.2f}x" if "vs_mitsuba" in r else ""
        share = f"{r['vs_floor']:.0%}" if "vs_floor" in r else ""
        lines.append(f"| pyoa, {r['shading']} shading | {r['tracing']} | {r['median_s']:.2f} | {r['min_s']:.2f} | "
                     f"{r['max_s']:.2f} | {r['paths_per_s'] / 1e6:.3f} | {r['rays_per_s'] / 1e6:.2f} | "
                     f"{r['rays_per_path']:.2f} | {ratio} | {share} |")
    for mode, m in mit.items():
        if _rate(m):
            lines.append(f"| Mitsuba {m['version']} `orthogonal` (LLVM, {m.get('libllvm') or 'default libLLVM'}), "
                         f"its own `cornell_box()` | {mode} | {m['median_s']:.2f} | {min(m['times_s']):.2f} | "
                         f"{max(m['times_s']):.2f} | {m['paths_per_s'] / 1e6:.3f} | | | 1.00x | "
                         f"{format(m['vs_floor'], '.0%') if 'vs_floor' in m else ''} |")
        else:
            lines.append(f"| Mitsuba | {mode} | {m['status']}: {m.get('reason')} | | | | | | | |")
    for mode, floor in floors.items():
        rate = _rate(mit.get(mode, {}))
        ratio = f" = {floor['paths_per_s'] / rate:.2f}x Mitsuba ({mode})" if rate else ""
        lines += ["", f"Embree floor, {mode} tracing (the rays of a {floor['size'][0]} x {floor['size'][1]} render "
                      f"of the same scene replayed through the shipped tracing path: {floor['packet']}-wide packets "
                      f"from numba, {floor['threads']} threads, each tracing its wavefronts in one compiled "
                      f"call; median of the rounds): "
                      f"{floor['rays_per_s'] / 1e6:.2f} M rays/s = {floor['paths_per_s'] / 1e6:.3f} M paths/s at "
                      f"{floor['rays_per_path']:.2f} rays/path{ratio}."]
    profs = [r for r in sc["results"]]
    parts = list(dict.fromkeys(k for r in profs for k in r["profile"]["parts_s"]))
    lines += ["", "Where the time goes (a separate render on 1 thread; seconds and share of it):", "",
              "| part | " + " | ".join(f"{r['shading']}, {r['tracing']}" for r in profs) + " |",
              "|---|" + "---:|" * len(profs)]
    for k in parts:
        cells = [(f"{r['profile']['parts_s'][k]:.2f} s ({100 * r['profile']['shares'][k]:.0f} %)"
                  if k in r["profile"]["parts_s"] else "") for r in profs]
        lines.append(f"| {k} | " + " | ".join(cells) + " |")
    lines.append("| **total** (M paths/s) | " + " | ".join(
        f"{r['profile']['seconds']:.2f} s ({r['profile']['paths_per_s'] / 1e6:.3f})" for r in profs) + " |")
    return lines


def memory_markdown(rows: list[dict]) -> list[str]:
    lines = ["## Peak memory", "",
             "Resident-set peak of the render above the process warmed up by the same render (a fresh process per "
             "row, glibc's mmap threshold fixed at 128 KiB; the warm-up's freed heap returned with malloc_trim, "
             "then `/proc/self/status` VmHWM reset: the "
             "working set, without a process's one-time costs such as PoCL compiling kernels for new call shapes), "
             "the image's own bytes (float32 RGB) and the rest per "
             "camera path in flight (threads x batch paths), and the stated bound of docs/performance.md "
             "(\"Render memory\"): B per path in flight (512 B compiled, 1.5 KiB NumPy), the float32 sampler values "
             "made ahead of the workers (at most that many batches' worth) and the image:", "",
             "| scene | shading | size | batch paths | paths in flight | peak above baseline | image "
             "| per path in flight | sampler values made ahead, at most | stated bound | within |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        if r["status"] != "ok":
            lines.append(f"| {r['scene']} | {r['shading']} | {r['size'][0]} x {r['size'][1]} | {r['batch_paths']:,} | "
                         f"failed: {r['reason']} | | | | | | |")
            continue
        lines.append(f"| {r['scene']} | {r['shading']} | {r['size'][0]} x {r['size'][1]} | {r['batch_paths']:,} | "
                     f"{r['paths_in_flight']:,} | {r['above_bytes'] / 2**20:.1f} MiB | {r['image_bytes'] / 2**20:.2f} MiB "
                     f"| {r['bytes_per_path']:,.0f} B | {r['samples_ahead_bytes'] / 2**20:.1f} MiB "
                     f"| {r['bound_bytes'] / 2**20:.1f} MiB "
                     f"| {'yes' if r['above_bytes'] <= r['bound_bytes'] else '**no**'} |")
    return lines


def markdown(report: dict, total_s: float) -> str:
    cfg = report["config"]
    lines = ["# pyoa render benchmark", "",
             f"{report['date_utc']}; CPU: {report['machine'].get('cpu')}. Mitsuba and the Embree floor in the same run; "
             "ratios compare rows of this run only (this machine kind drifts 15-40 % between processes).", ""]
    for sc in report["scenes"]:
        lines += [*scene_markdown(cfg, sc), ""]
    if report["memory"]:
        lines += [*memory_markdown(report["memory"]), ""]
    lines += machine_lines(report["machine"], total_s, {})
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main())
