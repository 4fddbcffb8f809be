"""The wavefront path tracer of :mod:`pyoa.render.integrator`, its shading
compiled with numba and Embree called from the compiled loops.

Same estimator, same dimension layout and the same guards as the NumPy
reference (read its docstring): camera rays (box or Gaussian filter, thin
lens, camera motion), emission seen by a ray with its MIS weight (power
heuristic), next-event estimation by emitter power, BSDF sampling, Russian
roulette from depth :data:`~pyoa.render.integrator.RR_DEPTH`. Each bounce is
three compiled calls over the whole wavefront: closest hits (Embree packets),
``shade`` (emission, the next-event candidate with its shadow ray, the BSDF
sample, roulette and the compaction of live lanes), then the shadow rays
(Embree packets) and ``add_visible``. Every call releases the GIL, so the
renderer's worker threads keep both cores busy; a lane's result depends only
on its own row of sampler values, so the image does not depend on the batch
size, the packet width or the number of threads.
"""

from __future__ import annotations

import math
import time

import numpy as np
from numba import njit

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


@njit(**_JIT)
def shade(n, depth, max_depth, mis, rr_depth, reach, growth,
          verts, normals, areas, material, emission, kinds, colors, alphas, em, em_cdf, em_prob,
          x, light_u, light_v, bsdf_u, bsdf_v, sample_index, rr_key,
          lane, o, d, beta, prev_pdf, prev_delta, prim, t, radiance,
          sh_o, sh_d, sh_dist, sh_lane, sh_c):
    """One bounce of ``n`` live lanes whose closest hits are ``prim``/``t``.

    Adds the emission each ray sees (MIS-weighted) to ``radiance``; writes
    the next-event shadow rays and their contributions (``sh_*``); samples the
    BSDF, plays Russian roulette and compacts the surviving lanes, in place,
    to the front of ``lane, o, d, beta, prev_pdf, prev_delta`` with their new
    rays. Returns ``(live lanes, shadow rays)``. ``light_u`` and the other
    column indices are -1 where the layout has no such dimension. Hit points
    are moved onto their triangle's plane (:func:`to_plane`, ``normals``: the
    unit normals of the triangles as traced) and new rays leave them by
    :func:`offset_distance` (``reach``, ``growth``: as
    ``integrator.triangle_reach``).
    """
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
            dn = max(dist, 1e-12)
            wx, wy, wz = vx / dn, vy / dn, vz / dn
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
                sn = max(seg, 1e-12)
                wl = power_heuristic(pdf_l, pdf_b) if mis else 1.0
                f = wl / pdf_l
                sh_o[shadows, 0], sh_o[shadows, 1], sh_o[shadows, 2] = ax, ay, az
                sh_d[shadows, 0], sh_d[shadows, 1], sh_d[shadows, 2] = gx / sn, gy / sn, gz / sn
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
def add_visible(m, free, sh_lane, sh_c, radiance):
    """Add the contributions of the shadow rays that reached their emitter."""
    for k in range(m):
        if free[k]:
            li = sh_lane[k]
            radiance[li, 0] += sh_c[k, 0]
            radiance[li, 1] += sh_c[k, 1]
            radiance[li, 2] += sh_c[k, 2]


def packet_width() -> int:
    """Embree packet width for this CPU: 16 lanes with AVX-512, else 8
    (the native width of AVX2); see docs/performance.md for the measurements."""
    from ...hostcpu import host_cpu

    return 16 if host_cpu().isa == "AVX-512" else 8


class CompiledIntegrator(reference.Integrator):
    """The path tracer with compiled shading; same constructor and results as
    :class:`pyoa.render.integrator.Integrator` (up to floating-point rounding).

    ``packet`` is the Embree packet width (1, 4, 8 or 16; default by CPU,
    :func:`packet_width`). ``timings`` accumulates the seconds spent per
    stage over every :meth:`radiance` call (``camera``, ``embree``,
    ``shading``, ``host``).
    """

    def __init__(self, scene, layout, width, height, filter="box", packet=None):
        self.packet = packet_width() if packet is None else packet
        super().__init__(scene, layout, width, height, filter=filter)
        self._fn_hit, self._fn_occ = embree.query_addresses(self.packet)
        self._verts = np.ascontiguousarray(scene.triangles, dtype=np.float64)
        m = scene.materials
        self._mats = (np.ascontiguousarray(m.kind, dtype=np.int64), np.ascontiguousarray(m.color),
                      np.ascontiguousarray(m.alpha))
        self._emission = np.ascontiguousarray(scene.emission)
        self._normals = np.ascontiguousarray(scene.normals)
        self._areas = np.ascontiguousarray(scene.areas)
        self._material = np.ascontiguousarray(scene.material, dtype=np.int64)
        em = self.emitters
        self._em = (np.ascontiguousarray(em.index, dtype=np.int64), np.ascontiguousarray(em.cdf),
                    np.ascontiguousarray(em.prob))
        self.timings = {"camera": 0.0, "embree": 0.0, "shading": 0.0, "host": 0.0}

    def _build_tracer(self, scene):
        """The scene built with Embree's own calls, traced from the compiled loops
        (the reference's ``embreex`` scene is never built here)."""
        return embree.Scene(scene.triangles)

    def radiance(self, pixel, sample_index, x, seed: int = 0):
        """Radiance (RGB, float64) of the camera paths ``(pixel, sample)`` whose
        sampler rows are ``x`` (as :meth:`pyoa.render.integrator.Integrator.radiance`)."""
        L, n = self.layout, len(pixel)
        clock = time.perf_counter
        t0 = clock()
        stats = Stats(paths=n)
        x = np.ascontiguousarray(x)
        pixel = np.ascontiguousarray(pixel, dtype=np.int64)
        u = filter_offsets(x[:, list(L.pair("pixel"))].astype(np.float64), self.filter)
        cam = self.camera
        lens = x[:, list(L.pair("lens"))].astype(np.float64) if L.lens else np.zeros((0, 2))
        shutter = x[:, L.index("time")].astype(np.float64) if L.time else np.zeros(0)
        o, d = np.empty((n, 3)), np.empty((n, 3))
        t1 = clock()
        camera_rays(pixel, np.ascontiguousarray(u), lens, shutter, self.width, self.height, cam.tan_x, cam.tan_y,
                    cam.rot, cam.pos, cam.aperture, cam.focus_distance, cam.motion, o, d)
        t2 = clock()
        tm = self.timings
        tm["camera"] += t2 - t1
        radiance = np.zeros((n, 3))
        lane = np.arange(n, dtype=np.int64)
        beta = np.ones((n, 3))
        prev_pdf = np.zeros(n)
        prev_delta = np.ones(n, dtype=np.bool_)
        rr_key = reference.hash_pair(reference.U32(seed), pixel.astype(reference.U32), RR_KEY).astype(np.int64)
        sample_index = np.ascontiguousarray(sample_index, dtype=np.int64)
        prim, hit_t = np.empty(n, np.int64), np.empty(n)
        sh_o, sh_d, sh_dist = np.empty((n, 3)), np.empty((n, 3)), np.empty(n)
        sh_lane, sh_c, free = np.empty(n, np.int64), np.empty((n, 3)), np.empty(n, np.bool_)
        kinds, colors, alphas = self._mats
        live = n
        tm["host"] += clock() - t2 + (t1 - t0)
        for depth in range(1, L.max_depth + 1):
            if live == 0:
                break
            t0 = clock()
            embree.intersect(self._tracer.handle, self._fn_hit, self.packet, o[:live], d[:live], prim, hit_t)
            stats.rays += live
            t1 = clock()
            cols = [-1, -1, -1, -1]
            if depth < L.max_depth:
                cols[:2] = L.pair(f"light{depth}")
                if f"bsdf{depth}.u" in L:
                    cols[2:] = L.pair(f"bsdf{depth}")
            live, shadows = shade(live, depth, L.max_depth, L.mis, reference.RR_DEPTH, self.reach, self.growth,
                                  self._verts, self._normals, self._areas, self._material, self._emission,
                                  kinds, colors, alphas, *self._em,
                                  x, *cols, sample_index, rr_key,
                                  lane, o, d, beta, prev_pdf, prev_delta, prim, hit_t, radiance,
                                  sh_o, sh_d, sh_dist, sh_lane, sh_c)
            t2 = clock()
            if shadows:
                embree.occluded(self._tracer.handle, self._fn_occ, self.packet, sh_o[:shadows], sh_d[:shadows],
                                sh_dist[:shadows], free)
                stats.rays += shadows
            t3 = clock()
            add_visible(shadows, free, sh_lane, sh_c, radiance)
            t4 = clock()
            tm["embree"] += (t1 - t0) + (t3 - t2)
            tm["shading"] += (t2 - t1) + (t4 - t3)
        return radiance, stats
