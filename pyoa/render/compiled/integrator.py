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
(:func:`shade`: emission, the next-event candidate with its shadow ray, the
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
import math
import time
from typing import NamedTuple

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from .. import embree
from .. import integrator as reference
from ..bsdf import MIRROR
from ..camera import filter_offsets
from ..integrator import ORIGIN_ERROR, RR_KEY, TEST_ERROR, Stats
from .bsdf import evaluate, sample
from .camera import camera_rays
from .emitters import sample_emitter
from .geometry import frame

#: error_model="numpy": IEEE divisions, as the NumPy reference's (numba's
#: default checks every division for zero and raises).
_JIT = dict(nogil=True, cache=True, error_model="numpy")
_INLINE = dict(_JIT, inline="always")


@njit(**_INLINE)
def _mix32(x):
    """Wellons' lowbias32 on a uint32 held in an int64 (as pyoa.reference.mix32)."""
    x ^= x >> 16
    x = (x * 0x7FEB352D) & 0xFFFFFFFF
    x ^= x >> 15
    x = (x * 0x846CA68B) & 0xFFFFFFFF
    x ^= x >> 16
    return x


@njit(**_INLINE)
def hash_pair(a, b, key):
    """``mix32(b ^ mix32(a ^ key))``, never 0 (as pyoa.reference.hash_pair)."""
    h = _mix32((b & 0xFFFFFFFF) ^ _mix32((a & 0xFFFFFFFF) ^ key))
    return key if h == 0 else h


@njit(**_INLINE)
def power_heuristic(f_pdf, g_pdf):
    """Veach's power heuristic (beta = 2), as ``integrator.power_heuristic``."""
    return f_pdf * f_pdf / max(f_pdf * f_pdf + g_pdf * g_pdf, 1e-300)


@njit(**_INLINE)
def emission_weight(depth, mis, pdf_light, prev_pdf, prev_delta):
    """MIS weight of emission reached by a BSDF sample (as
    ``Integrator.emission_weight``)."""
    if depth == 1:
        return 1.0
    if not mis:
        return 1.0 if prev_delta else 0.0  # without MIS only light sampling counts
    return 1.0 if prev_delta else power_heuristic(prev_pdf, pdf_light)


@njit(**_INLINE)
def to_plane(px, py, pz, vx, vy, vz, mx, my, mz):
    """The point ``p`` moved along the unit normal ``m`` onto the plane through
    ``v``, as ``integrator.to_plane`` (the same operations in the same order,
    so the same bits), whose docstring says why."""
    h = (px - vx) * mx + (py - vy) * my + (pz - vz) * mz
    return px - h * mx, py - h * my, pz - h * mz


@njit(**_INLINE)
def offset_distance(px, py, pz, nx, ny, nz, extent):
    """How far along its unit normal ``n`` a ray leaves the surface point
    ``p``: ``d = sum_k |n_k| e_k`` with the float32 error bound ``e_k =
    ORIGIN_ERROR |p_k| + TEST_ERROR extent`` (pbrt-v4's offset of spawned ray
    origins, 6.8.6), as ``integrator.offset_distance``, whose docstring
    derives it; the same operations in the same order, so the same bits."""
    s = TEST_ERROR * extent
    return (abs(nx) * (ORIGIN_ERROR * abs(px) + s) + abs(ny) * (ORIGIN_ERROR * abs(py) + s)
            + abs(nz) * (ORIGIN_ERROR * abs(pz) + s))


@njit(**_INLINE)
def russian_roulette(br, bg, bb, key, sample_index, depth):
    """``(alive, beta r, g, b)``: survival with probability ``min(max beta,
    0.95)`` from a hash of the path (as ``integrator.russian_roulette``)."""
    q = min(max(br, bg, bb), 0.95)
    h = hash_pair(key, sample_index * 64 + depth, RR_KEY)
    if (h >> 8) * 2.0**-24 < q:
        return True, br / q, bg / q, bb / q
    return False, br, bg, bb


class SceneData(NamedTuple):
    """The scene's arrays as the compiled loop reads them (built by
    :meth:`CompiledIntegrator.__init__` from :class:`pyoa.render.scene.Scene`,
    its :class:`~pyoa.render.emitters.Emitters` and
    :func:`~pyoa.render.integrator.triangle_reach`)."""

    verts: np.ndarray  # (T, 3, 3) float64 copies of the float32 vertices Embree traces
    normals: np.ndarray  # (T, 3) unit normals of the triangles as traced
    areas: np.ndarray  # (T,)
    material: np.ndarray  # (T,) int64 material of each triangle
    emission: np.ndarray  # (T, 3) radiance emitted (front side)
    kinds: np.ndarray  # (M,) int64 BSDF kind of each material (pyoa.render.bsdf)
    colors: np.ndarray  # (M, 3)
    alphas: np.ndarray  # (M,) GGX roughness
    em: np.ndarray  # (E,) int64 emitting triangles (Emitters.index)
    em_cdf: np.ndarray  # (E,) their power CDF (Emitters.cdf)
    em_prob: np.ndarray  # (T,) probability of each triangle's choice (Emitters.prob)
    reach: np.ndarray  # (T,) triangle_reach: Embree's error grows with it ...
    growth: np.ndarray  # (T,) ... and, at a shadow segment's end, with its length times this


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
    beta: np.ndarray  # (W, 3) path throughput
    prev_pdf: np.ndarray  # (W,) solid-angle pdf of the BSDF sample that made the ray
    prev_delta: np.ndarray  # (W,) bool: that sample was a delta lobe (or the camera's)
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


@njit(**_JIT)
def shade(n, depth, sc, ps, x, sample_index, rr_key, w, radiance):
    """One bounce of the ``n`` live lanes of the wavefront ``w``, whose
    closest hits are ``w.prim``/``w.t``. The reference's formulas, with
    products by a reciprocal where it divides several numbers by one (the
    same values to rounding: divisions were a third of a bounce).

    Adds the emission each ray sees (MIS-weighted) to ``radiance``; writes
    the next-event shadow rays and their contributions (``w.sh_*``); samples
    the BSDF, plays Russian roulette and compacts the surviving lanes, in
    place, to the front of ``w.lane, o, d, beta, prev_pdf, prev_delta`` with
    their new rays. Returns ``(live lanes, shadow rays)``. The sampler
    columns of this depth are ``ps.columns[depth]`` (-1 where the layout has
    no such dimension). Hit points are moved onto their triangle's plane
    (:func:`to_plane`, ``sc.normals``: the unit normals of the triangles as
    traced) and new rays leave them by :func:`offset_distance` (``sc.reach``,
    ``sc.growth``: as ``integrator.triangle_reach``).
    """
    max_depth, mis, rr_depth = ps.max_depth, ps.mis, ps.rr_depth
    light_u, light_v = ps.columns[depth, 0], ps.columns[depth, 1]
    bsdf_u, bsdf_v = ps.columns[depth, 2], ps.columns[depth, 3]
    verts, normals, areas, material, emission = sc.verts, sc.normals, sc.areas, sc.material, sc.emission
    kinds, colors, alphas, em, em_cdf, em_prob = sc.kinds, sc.colors, sc.alphas, sc.em, sc.em_cdf, sc.em_prob
    reach, growth = sc.reach, sc.growth
    lane, o, d, beta, prev_pdf, prev_delta, prim, t = w.lane, w.o, w.d, w.beta, w.prev_pdf, w.prev_delta, w.prim, w.t
    sh_o, sh_d, sh_dist, sh_lane, sh_c = w.sh_o, w.sh_d, w.sh_dist, w.sh_lane, w.sh_c
    live, shadows = 0, 0
    for i in range(n):
        tri = prim[i]
        if tri < 0:
            continue  # the ray left the scene
        li = lane[i]
        dx, dy, dz = d[i, 0], d[i, 1], d[i, 2]
        ti = t[i]
        px, py, pz = to_plane(o[i, 0] + ti * dx, o[i, 1] + ti * dy, o[i, 2] + ti * dz,
                              verts[tri, 0, 0], verts[tri, 0, 1], verts[tri, 0, 2],
                              normals[tri, 0], normals[tri, 1], normals[tri, 2])
        nx, ny, nz = normals[tri, 0], normals[tri, 1], normals[tri, 2]
        br, bg, bb = beta[i, 0], beta[i, 1], beta[i, 2]
        # emission seen by this ray (emitters are one-sided)
        cos_l = -(nx * dx + ny * dy + nz * dz)
        er, eg, eb = emission[tri, 0], emission[tri, 1], emission[tri, 2]
        if cos_l > 0 and (er != 0.0 or eg != 0.0 or eb != 0.0):
            pdf_light = em_prob[tri] / areas[tri] * ti * ti / max(cos_l, 1e-12)
            w = emission_weight(depth, mis, pdf_light, prev_pdf[i], prev_delta[i])
            radiance[li, 0] += br * er * w
            radiance[li, 1] += bg * eg * w
            radiance[li, 2] += bb * eb * w
        if depth == max_depth:
            continue
        eps = offset_distance(px, py, pz, nx, ny, nz, reach[tri])  # new rays leave p this far
        # shading frame facing the incoming ray (two-sided surfaces)
        if nx * dx + ny * dy + nz * dz > 0:
            sx, sy, sz = -nx, -ny, -nz
        else:
            sx, sy, sz = nx, ny, nz
        (tx, ty, tz), (bx, by, bz) = frame(sx, sy, sz)
        wox, woy, woz = -(dx * tx + dy * ty + dz * tz), -(dx * bx + dy * by + dz * bz), -(dx * sx + dy * sy + dz * sz)
        woz = max(woz, 1e-9)
        mat = material[tri]
        kind, alpha = kinds[mat], alphas[mat]
        cr, cg, cb = colors[mat, 0], colors[mat, 1], colors[mat, 2]
        # next-event estimation: one point on an emitter
        if kind != MIRROR:
            etri, qx, qy, qz, mx, my, mz, pdf_area = sample_emitter(
                em, em_cdf, em_prob, verts, normals, areas,
                np.float64(x[li, light_u]), np.float64(x[li, light_v]))
            vx, vy, vz = qx - px, qy - py, qz - pz
            dist = math.sqrt(vx * vx + vy * vy + vz * vz)
            inv = 1.0 / max(dist, 1e-12)  # one division, three products (the reference divides thrice)
            wx, wy, wz = vx * inv, vy * inv, vz * inv
            cos_q = -(mx * wx + my * wy + mz * wz)
            fr, fg, fb, pdf_b = evaluate(kind, cr, cg, cb, alpha, wox, woy, woz,
                                         wx * tx + wy * ty + wz * tz, wx * bx + wy * by + wz * bz,
                                         wx * sx + wy * sy + wz * sz)
            pdf_l = pdf_area * dist * dist / max(cos_q, 1e-12)
            if cos_q > 0 and (fr > 0 or fg > 0 or fb > 0):
                # from p + eps n to q + eps_q n_q, each moved off its surface
                # by its own float32 error bound (q's: the end of a segment of
                # length dist), not shortened further (as the reference)
                side = eps if wx * sx + wy * sy + wz * sz > 0 else -eps
                ax, ay, az = px + side * sx, py + side * sy, pz + side * sz
                eq = offset_distance(qx, qy, qz, mx, my, mz, dist * growth[etri] + reach[etri])
                gx, gy, gz = qx + eq * mx - ax, qy + eq * my - ay, qz + eq * mz - az
                seg = math.sqrt(gx * gx + gy * gy + gz * gz)
                inv = 1.0 / max(seg, 1e-12)
                # power_heuristic(pdf_l, pdf_b) / pdf_l in one division
                f = pdf_l / max(pdf_l * pdf_l + pdf_b * pdf_b, 1e-300) if mis else 1.0 / pdf_l
                sh_o[shadows, 0], sh_o[shadows, 1], sh_o[shadows, 2] = ax, ay, az
                sh_d[shadows, 0], sh_d[shadows, 1], sh_d[shadows, 2] = gx * inv, gy * inv, gz * inv
                sh_dist[shadows] = seg
                sh_lane[shadows] = li
                sh_c[shadows, 0] = br * fr * emission[etri, 0] * f
                sh_c[shadows, 1] = bg * fg * emission[etri, 1] * f
                sh_c[shadows, 2] = bb * fb * emission[etri, 2] * f
                shadows += 1
        # continue the path with a BSDF sample
        if not (mis or depth < max_depth - 1):
            continue
        ix, iy, iz, wr, wg, wb, pdf, delta = sample(kind, cr, cg, cb, alpha, wox, woy, woz,
                                                    np.float64(x[li, bsdf_u]), np.float64(x[li, bsdf_v]))
        br, bg, bb = br * wr, bg * wg, bb * wb
        alive = br > 0 or bg > 0 or bb > 0
        if alive and depth >= rr_depth:
            alive, br, bg, bb = russian_roulette(br, bg, bb, rr_key[li], sample_index[li], depth)
        if not alive:
            continue
        ox_, oy_, oz_ = ix * tx + iy * bx + iz * sx, ix * ty + iy * by + iz * sy, ix * tz + iy * bz + iz * sz
        side = eps if ox_ * sx + oy_ * sy + oz_ * sz > 0 else -eps
        j = live
        lane[j] = li
        o[j, 0], o[j, 1], o[j, 2] = px + side * sx, py + side * sy, pz + side * sz
        d[j, 0], d[j, 1], d[j, 2] = ox_, oy_, oz_
        beta[j, 0], beta[j, 1], beta[j, 2] = br, bg, bb
        prev_pdf[j] = pdf
        prev_delta[j] = delta
        live += 1
    return live, shadows


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
    ts = np.zeros(2, np.int64)
    rays = 0
    t0 = _now(clock, ts)
    rr_key = np.empty(n, np.int64)
    for i in range(n):
        rr_key[i] = hash_pair(np.int64(ps.seed), pixel[i], RR_KEY)
    cc = ps.camera_columns
    uw = np.empty((size, 2))
    lens = np.empty((size if cc[2] >= 0 else 0, 2))
    shutter = np.empty(size if cc[4] >= 0 else 0)
    spent[0] += _now(clock, ts) - t0
    for start in range(0, n, size):
        m = min(size, n - start)
        stop = start + m
        t0 = _now(clock, ts)
        for j in range(m):
            i = start + j
            if u.shape[0]:
                uw[j, 0], uw[j, 1] = u[i, 0], u[i, 1]
            else:
                uw[j, 0], uw[j, 1] = np.float64(x[i, cc[0]]), np.float64(x[i, cc[1]])
            if lens.shape[0]:
                lens[j, 0], lens[j, 1] = np.float64(x[i, cc[2]]), np.float64(x[i, cc[3]])
            if shutter.shape[0]:
                shutter[j] = np.float64(x[i, cc[4]])
        camera_rays(pixel[start:stop], uw[:m], lens[:m], shutter[:m], cam.width, cam.height, cam.tan_x,
                    cam.tan_y, cam.rot, cam.pos, cam.aperture, cam.focus, cam.motion, w.o, w.d)
        for j in range(m):
            w.lane[j] = start + j
            w.beta[j, 0], w.beta[j, 1], w.beta[j, 2] = 1.0, 1.0, 1.0
            w.prev_pdf[j] = 0.0
            w.prev_delta[j] = True  # camera rays count emission fully
        t1 = _now(clock, ts)
        spent[0] += t1 - t0
        live = m
        for depth in range(1, ps.max_depth + 1):
            if live == 0:
                break
            embree.intersect(tr.scene, tr.hit, tr.packet, w.o[:live], w.d[:live], w.prim, w.t)
            rays += live
            t2 = _now(clock, ts)
            live, shadows = shade(live, depth, sc, ps, x, sample_index, rr_key, w, radiance)
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
        m, em = scene.materials, Emitters(scene)
        c = np.ascontiguousarray
        self._scene = SceneData(
            verts=c(scene.triangles, dtype=np.float64), normals=c(scene.normals), areas=c(scene.areas),
            material=c(scene.material, dtype=np.int64), emission=c(scene.emission),
            kinds=c(m.kind, dtype=np.int64), colors=c(m.color), alphas=c(m.alpha),
            em=c(em.index, dtype=np.int64), em_cdf=c(em.cdf), em_prob=c(em.prob), reach=c(reach), growth=c(growth))
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
