"""The wavefront path tracer of :mod:`pyoa.render.integrator`, compiled with
numba, Embree called from the compiled loop.

Same estimator, same dimension layout and the same guards as the NumPy
reference (read its docstring): camera rays (box or Gaussian filter, thin
lens, camera motion), emission seen by a ray with its MIS weight (power
heuristic), next-event estimation by emitter power, BSDF sampling, Russian
roulette from depth :data:`~pyoa.render.integrator.RR_DEPTH`.

A batch of camera paths is one call of :func:`render_paths`, which releases
the GIL and never returns to Python until the batch is done: it takes the
paths a wavefront of :data:`WAVEFRONT` lanes at a time (small enough for the
lanes' state to stay in the CPU's caches), makes their camera rays, and for
each bounce traces the closest hits (Embree packets), shades them
(:func:`~pyoa.render.compiled.shading.shade`: emission, the next-event candidate with its shadow ray, the
BSDF sample, roulette and the compaction of live lanes), traces the shadow
rays and adds what they carry. The renderer's worker threads run batches
side by side on every core; a lane's result depends only on its own row of
sampler values, so the image does not depend on the batch size, the
wavefront size, the packet width or the number of threads.

The scene, the camera, the path settings and the wavefront's state are
passed as named tuples (:class:`SceneData`, :class:`CameraData`,
:class:`PathSettings`, :class:`Wavefront`), which numba compiles to plain
structures.
"""

from __future__ import annotations

import ctypes
import time
from pathlib import Path
from typing import NamedTuple

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from ..._numba.hashes import hash_pair
from .. import embree
from .. import integrator as reference
from ..bsdfs import BSDFS
from ..camera import filter_offsets
from ..integrator import RR_KEY, Stats
from .cache import cache_dir
from .camera import SCRATCH as CAMERA_SCRATCH
from .camera import camera_rays
from .shading import CHUNK, SCRATCH, hit_data, shade

#: error_model="numpy": IEEE divisions, as the NumPy reference's (numba's
#: default checks every division for zero and raises).
_JIT = dict(nogil=True, cache=True, error_model="numpy")
_INLINE = dict(_JIT, inline="always")


class SceneData(NamedTuple):
    """The scene's arrays as the compiled loop reads them (built by
    :meth:`CompiledIntegrator.__init__` from :class:`pyoa.render.scene.Scene`,
    its :class:`~pyoa.render.emitters.Emitters` and
    :func:`~pyoa.render.integrator.triangle_reach`)."""

    verts: np.ndarray  # (T, 3, 3) float64 copies of the float32 vertices Embree traces
    normals: np.ndarray  # (T, 3) unit normals of the triangles as traced
    areas: np.ndarray  # (T,)
    emission: np.ndarray  # (T, 3) radiance emitted (front side)
    em: np.ndarray  # (E,) int64 emitting triangles (Emitters.index)
    em_cdf: np.ndarray  # (E,) their power CDF (Emitters.cdf)
    em_prob: np.ndarray  # (T,) probability of each triangle's choice (Emitters.prob)
    reach: np.ndarray  # (T,) triangle_reach: Embree's error grows with it ...
    growth: np.ndarray  # (T,) ... and, at a shadow segment's end, with its length times this
    hit_data: np.ndarray  # (T, HIT_FIELDS) what the shading reads of a hit triangle (shading.hit_data)
    kinds: np.ndarray  # (K,) bool per BSDF kind (pyoa.render.bsdfs.KINDS): a triangle's material has it


class CameraData(NamedTuple):
    """The camera (:class:`pyoa.render.camera.PerspectiveCamera`) for :func:`camera_rays`."""

    width: int
    height: int
    tan_x: float
    tan_y: float
    rot: np.ndarray  # (3, 3) camera to world
    pos: np.ndarray  # (3,)
    aperture: float
    focus: float
    motion: np.ndarray  # (3,)


class PathSettings(NamedTuple):
    """What a path does and which sampler columns feed it (:class:`pyoa.render.layout.Layout`)."""

    max_depth: int
    mis: bool
    rr_depth: int
    columns: np.ndarray  # (max_depth + 1, 4) int64: light u, v, bsdf u, v of each depth; -1 where none
    camera_columns: np.ndarray  # (5,) int64: pixel u, v, lens u, v, time; -1 where none
    seed: int  # the sampler's user seed, the Russian-roulette keys' first word


class Tracer(NamedTuple):
    """An Embree scene and its queries, as integers (:mod:`pyoa.render.embree`)."""

    scene: int  # RTCScene
    hit: int  # address of rtcIntersect<packet>
    occluded: int  # address of rtcOccluded<packet>
    packet: int


class Wavefront(NamedTuple):
    """The state of up to ``len(lane)`` live paths, compacted to the front
    after every bounce, and the shadow rays of the current bounce."""

    lane: np.ndarray  # (W,) int64 path (row of x) of each live entry
    o: np.ndarray  # (W, 3) ray origins
    d: np.ndarray  # (W, 3) unit ray directions
    beta: np.ndarray  # (W, 3) path throughput (from depth 2: shading.path_state)
    prev_pdf: np.ndarray  # (W,) solid-angle pdf of the BSDF sample that made the ray (from depth 2)
    prev_delta: np.ndarray  # (W,) bool: that sample was a delta lobe (from depth 2)
    prim: np.ndarray  # (W,) int64 closest hit (-1: none)
    t: np.ndarray  # (W,) its distance
    sh_o: np.ndarray  # (W, 3) shadow rays
    sh_d: np.ndarray
    sh_dist: np.ndarray
    sh_lane: np.ndarray  # (W,) int64 path each shadow ray belongs to
    sh_c: np.ndarray  # (W, 3) what it carries if it reaches its emitter
    free: np.ndarray  # (W,) bool: nothing blocks it


@njit(**_JIT)
def new_wavefront(size):
    """Empty wavefront buffers for ``size`` lanes."""
    return Wavefront(np.empty(size, np.int64), np.empty((size, 3)), np.empty((size, 3)), np.empty((size, 3)),
                     np.empty(size), np.empty(size, np.bool_), np.empty(size, np.int64), np.empty(size),
                     np.empty((size, 3)), np.empty((size, 3)), np.empty(size), np.empty(size, np.int64),
                     np.empty((size, 3)), np.empty(size, np.bool_))


@njit(**_INLINE)
def start_paths(cam, ps, pixel, x, u, start, m, scratch, w):
    """The first ``m`` entries of ``w`` become the paths ``start .. start +
    m - 1`` of the batch (``pixel``, sampler rows ``x``, filter offsets
    ``u``: as :func:`render_paths`) at their camera rays (:func:`camera_rays`,
    ``scratch`` its :data:`~pyoa.render.compiled.camera.SCRATCH` values).
    Their throughput and previous sample are not stored: the shading takes
    a camera ray's from :func:`~pyoa.render.compiled.shading.path_state`
    (storing them took 3-4 ns a path)."""
    stop = start + m
    camera_rays(pixel[start:stop], x[start:stop], u[start:stop], ps.camera_columns, cam.width, cam.height,
                cam.tan_x, cam.tan_y, cam.rot, cam.pos, cam.aperture, cam.focus, cam.motion, scratch, w.o, w.d)
    for j in range(m):
        w.lane[j] = start + j


@njit(**_JIT)
def add_visible(m, w, radiance):
    """Add the contributions of the shadow rays that reached their emitter."""
    for k in range(m):
        if w.free[k]:
            li = w.sh_lane[k]
            radiance[li, 0] += w.sh_c[k, 0]
            radiance[li, 1] += w.sh_c[k, 1]
            radiance[li, 2] += w.sh_c[k, 2]


#: Lanes of a wavefront: the paths of a batch are traced this many at a time,
#: so that their state (about 300 bytes a lane) stays in the CPU's caches
#: (docs/performance.md, "Rendering": 128 to 1,024 lanes were 5-15 % faster than
#: 4,096 to 65,536).
WAVEFRONT = 512
#: Stages :func:`render_paths` times (its ``spent`` array, in this order).
STAGES = ("camera", "embree", "shading")
_CLOCK_MONOTONIC = 1


@intrinsic
def _clock_gettime(typingctx, fn, clock, ts):
    """``((int (*)(int, void *)) fn)(clock, ts)``: the C library's ``clock_gettime``."""
    sig = types.int32(types.uint64, types.int32, types.uint64)

    def codegen(context, builder, signature, args):
        i32, ptr = ir.IntType(32), ir.IntType(8).as_pointer()
        fnty = ir.FunctionType(i32, [i32, ptr])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(f, [args[1], builder.inttoptr(args[2], ptr)])

    return sig, codegen


def clock_address() -> int:
    """Address of the C library's ``clock_gettime`` (passed as an integer,
    so that numba's on-disk cache stays valid across processes)."""
    return ctypes.cast(ctypes.CDLL(None).clock_gettime, ctypes.c_void_p).value


@njit(**_INLINE)
def _now(clock, ts):
    """Monotonic seconds (``ts``: an int64[2] timespec buffer)."""
    _clock_gettime(clock, np.int32(_CLOCK_MONOTONIC), np.uint64(ts.ctypes.data))
    return ts[0] + ts[1] * 1e-9


@njit(**_JIT)
def render_paths(tr, sc, cam, ps, pixel, sample_index, x, u, radiance, spent, clock, wavefront):
    """Radiance of the camera paths ``(pixel[i], sample_index[i])`` whose
    sampler rows are ``x[i]``, added into ``radiance`` (``(n, 3)`` float64,
    zeros on entry), ``wavefront`` paths at a time (:data:`WAVEFRONT`):
    camera rays, then every bounce's closest hits, shading, shadow rays and
    their contributions. The camera's samples are read from ``x``
    (``ps.camera_columns``); ``u`` are the pixel-filter offsets of a
    Gaussian filter (:func:`~pyoa.render.camera.filter_offsets`, which
    needs SciPy), empty for the box filter, whose offsets are the samples
    themselves. Each path's Russian-roulette key is ``hash_pair(ps.seed,
    pixel, RR_KEY)``. Adds the seconds of each stage
    (:data:`STAGES`) to ``spent`` (``clock``: :func:`clock_address`).
    Returns the number of rays traced."""
    n = pixel.shape[0]
    size = max(1, min(wavefront, n))
    w = new_wavefront(size)
    scratch, lanes = np.empty(SCRATCH), np.empty(CHUNK, np.int64)
    ts = np.zeros(2, np.int64)
    rays = 0
    t0 = _now(clock, ts)
    # roulette keys only where a path can reach roulette: a new ray is made at depths below max_depth, and
    # roulette plays from rr_depth (of the bundled scenes only deep's paths are that long)
    rr_key = np.empty(n if ps.rr_depth < ps.max_depth else 0, np.int64)
    last, key = -1, 0
    for i in range(rr_key.shape[0]):
        if pixel[i] != last:  # a pixel's samples are consecutive: one hash per pixel
            last = pixel[i]
            key = hash_pair(np.int64(ps.seed), last, RR_KEY)
        rr_key[i] = key
    cam_scratch = np.empty(CAMERA_SCRATCH)
    spent[0] += _now(clock, ts) - t0
    for start in range(0, n, size):
        m = min(size, n - start)
        t0 = _now(clock, ts)
        start_paths(cam, ps, pixel, x, u, start, m, cam_scratch, w)
        t1 = _now(clock, ts)
        spent[0] += t1 - t0
        live = m
        for depth in range(1, ps.max_depth + 1):
            if live == 0:
                break
            embree.intersect(tr.scene, tr.hit, tr.packet, w.o[:live], w.d[:live], w.prim, w.t)
            rays += live
            t2 = _now(clock, ts)
            live, shadows = shade(live, depth, sc, ps, x, sample_index, rr_key, w, radiance, scratch, lanes)
            t3 = _now(clock, ts)
            if shadows:
                embree.occluded(tr.scene, tr.occluded, tr.packet, w.sh_o[:shadows], w.sh_d[:shadows],
                                w.sh_dist[:shadows], w.free)
                rays += shadows
            t4 = _now(clock, ts)
            add_visible(shadows, w, radiance)
            t5 = _now(clock, ts)
            spent[1] += (t2 - t1) + (t4 - t3)
            spent[2] += (t3 - t2) + (t5 - t4)
            t1 = t5
    return rays


def packet_width() -> int:
    """Embree packet width: 8 lanes on every CPU. On the Intel Xeon of family
    6 model 207 (AVX-512) whole renders ran 5-15 % faster with 8 than with
    16 (robust tracing; 1, 4, 8 and 16 measured in one process), on the AMD
    EPYC Zen 4 the two were within 2 % (docs/performance.md, "Rendering");
    every width gives the same hits (tested), so the choice changes speed
    only."""
    return 8


class CompiledIntegrator:
    """The path tracer with compiled shading: the estimator of
    :class:`pyoa.render.integrator.Integrator` (same constructor; the same
    image up to floating-point rounding, checked against it within the
    noise both predict), a batch of paths per compiled call
    (:func:`render_paths`).

    ``packet`` is the Embree packet width (1, 4, 8 or 16; default by CPU,
    :func:`packet_width`). ``timings`` accumulates the seconds spent per
    stage over every :meth:`radiance` call: ``camera``, ``embree`` and
    ``shading`` inside the compiled loop (summed over the threads that ran
    it), ``host`` the Python around it (the filter's warp, the arrays of a
    batch).
    """

    def __init__(self, scene, layout, width, height, filter="box", packet=None):
        from ..camera import PerspectiveCamera, check_filter
        from ..emitters import Emitters

        check_filter(filter)
        self.scene, self.layout = scene, layout
        self.width, self.height, self.filter = width, height, filter
        self.packet = packet_width() if packet is None else packet
        # reach and growth before Embree's build, so that their temporaries
        # do not add to its peak (as the reference)
        reach, growth = reference.triangle_reach(scene.triangles, scene.normals, scene.areas)
        self._rtc = embree.Scene(scene.triangles, robust=getattr(scene, "robust_tracing", True))
        hit, occ = embree.query_addresses(self.packet)
        self._tracer = Tracer(self._rtc.handle, hit, occ, self.packet)
        em = Emitters(scene)
        c = np.ascontiguousarray
        self._scene = SceneData(
            verts=c(scene.triangles, dtype=np.float64), normals=c(scene.normals), areas=c(scene.areas),
            emission=c(scene.emission), em=c(em.index, dtype=np.int64), em_cdf=c(em.cdf), em_prob=c(em.prob),
            reach=c(reach), growth=c(growth), hit_data=hit_data(scene, em.prob, reach),
            kinds=np.isin(np.arange(len(BSDFS)), np.asarray(scene.materials.kind)[np.asarray(scene.material)]))
        cam = PerspectiveCamera(scene.camera, width, height)
        self._camera = CameraData(width, height, cam.tan_x, cam.tan_y, c(cam.rot), c(cam.pos), cam.aperture,
                                  cam.focus_distance, c(cam.motion))
        L = layout
        columns = np.full((L.max_depth + 1, 4), -1, np.int64)
        for depth in range(1, L.max_depth):
            columns[depth, :2] = L.pair(f"light{depth}")
            if f"bsdf{depth}.u" in L:
                columns[depth, 2:] = L.pair(f"bsdf{depth}")
        camera = np.array([*L.pair("pixel"), *(L.pair("lens") if L.lens else (-1, -1)),
                           L.index("time") if L.time else -1], np.int64)
        self._settings = PathSettings(L.max_depth, bool(L.mis), reference.RR_DEPTH, columns, camera, 0)
        self._clock = clock_address()
        #: paths traced together (:data:`WAVEFRONT`; any size gives the same image)
        self.wavefront = WAVEFRONT
        self.timings = {"camera": 0.0, "embree": 0.0, "shading": 0.0, "host": 0.0}

    @staticmethod
    def needs_compiling() -> bool:
        """Whether numba's on-disk cache holds no compiled :func:`render_paths` for these sources
        (:func:`pyoa.render.compiled.cache_dir`): the first render after an install or an update
        then compiles the renderer (15-60 s) before its first path."""
        return not any(Path(cache_dir()).glob("*/integrator.render_paths-*.nbi"))

    def radiance(self, pixel, sample_index, x, seed: int = 0):
        """Radiance (RGB, float64) of the camera paths ``(pixel, sample)`` whose
        sampler rows are ``x`` (as :meth:`pyoa.render.integrator.Integrator.radiance`)."""
        L, n = self.layout, len(pixel)
        t0 = time.perf_counter()
        x = np.ascontiguousarray(x)
        pixel = np.ascontiguousarray(pixel, dtype=np.int64)
        sample_index = np.ascontiguousarray(sample_index, dtype=np.int64)
        u = (np.zeros((0, 2)) if self.filter == "box" else np.ascontiguousarray(
            filter_offsets(x[:, list(L.pair("pixel"))].astype(np.float64), self.filter)))
        radiance = np.zeros((n, 3))
        spent = np.zeros(len(STAGES))
        settings = self._settings._replace(seed=int(seed))
        t1 = time.perf_counter()
        rays = render_paths(self._tracer, self._scene, self._camera, settings, pixel, sample_index, x, u, radiance,
                            spent, self._clock, self.wavefront)
        t2 = time.perf_counter()
        tm = self.timings
        for name, sec in zip(STAGES, spent):
            tm[name] += float(sec)
        tm["host"] += (t1 - t0) + max(0.0, (t2 - t1) - spent.sum())
        return radiance, Stats(paths=n, rays=int(rays))
