"""The wavefront path tracer: camera rays, emitter sampling, and path
tracing with next-event estimation and multiple importance sampling.

Every lane is one camera path (pixel, sample). All random numbers of a path
come from one row of sampler values (:mod:`.layout` says which column feeds
what); rays are traced in bulk by Embree through ``embreex`` (float32 rays,
no ray start distance: origins are offset along the normal; its occlusion
answer is 0 for occluded and -1 for free); shading is vectorized NumPy in
float64. A lane's result depends only on its own row of sampler values, so
the image does not depend on how lanes are batched.

References
----------
.. [1] E. Veach, "Robust Monte Carlo Methods for Light Transport
   Simulation", PhD thesis, Stanford, 1997 (multiple importance sampling,
   power heuristic).
.. [2] M. Pharr, W. Jakob, G. Humphreys, "Physically Based Rendering", 4th
   ed., 2023, ch. 13 (path tracing) and 5.2 (thin-lens camera).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._numpy.hashes import U32, hash_pair
from . import bsdf
from .geometry import concentric_disk, dot, frame, normalize, to_local, to_world, triangle_point
from .layout import Layout

#: Russian roulette starts at this path depth (segments), as in Mitsuba 3.
RR_DEPTH = 5
#: Key of the Russian-roulette hash (not a sampler dimension, see layout).
RR_KEY = 0x7FEB352D


def _rotate(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``v @ R.T`` written out per element: BLAS could round differently for
    different batch sizes, and the image must not depend on them."""
    return v[:, :1] * R[:, 0] + v[:, 1:2] * R[:, 1] + v[:, 2:3] * R[:, 2]


def _compact(keep: np.ndarray, *arrays):
    """The rows of each array where ``keep`` holds (the arrays themselves when
    all do): one index computed once, instead of a boolean mask evaluated
    per array (docs/performance.md)."""
    if keep.all():
        return arrays
    idx = np.flatnonzero(keep)
    return tuple(a[idx] for a in arrays)


@dataclass
class Stats:
    """Counts of one render (summed over batches)."""

    paths: int = 0
    rays: int = 0  # every ray traced: camera, continuation and shadow rays

    def add(self, other: "Stats") -> None:
        self.paths += other.paths
        self.rays += other.rays


class Integrator:
    """Path tracer for one scene and layout.

    Parameters
    ----------
    scene : pyoa.render.scene.Scene
    layout : Layout
    width, height : int
        Film size in pixels.
    filter : {"box", "gaussian"}
        Pixel filter, importance-sampled: ``box`` spreads samples uniformly
        over the pixel (the paper's tables); ``gaussian`` draws the offset
        from the pixel centre from a Gaussian of standard deviation 0.5 pixel
        truncated at 2 pixels (Mitsuba's default filter), so every sample has
        weight 1.
    """

    def __init__(self, scene, layout: Layout, width: int, height: int, filter: str = "box"):
        from embreex import rtcore_scene as rtcs
        from embreex.mesh_construction import TriangleMesh

        if filter not in ("box", "gaussian"):
            raise ValueError(f"unknown pixel filter {filter!r}; valid: box, gaussian")
        self.scene, self.layout = scene, layout
        self.width, self.height, self.filter = width, height, filter
        self._embree = rtcs.EmbreeScene()
        TriangleMesh(self._embree, np.ascontiguousarray(scene.triangles, dtype=np.float32))
        # Emitter triangles chosen in proportion to their power (area x mean radiance).
        em = np.asarray(scene.emitters)
        power = scene.areas[em] * scene.emission[em].mean(axis=1)
        self._em = em
        self._em_cdf = np.cumsum(power) / power.sum()
        self._em_prob = np.zeros(len(scene.areas))
        self._em_prob[em] = power / power.sum()
        scale = float(np.abs(scene.triangles).max())
        self._eps = 1e-4 * max(1.0, scale)
        cam = scene.camera
        self._cam_rot = np.asarray(cam.to_world, dtype=np.float64)[:3, :3]
        self._cam_pos = np.asarray(cam.to_world, dtype=np.float64)[:3, 3]
        small = min(width, height)
        self._tan = math.tan(math.radians(cam.fov) / 2)
        self._tan_x = self._tan * width / small
        self._tan_y = self._tan * height / small

    # -- rays ---------------------------------------------------------------

    def _intersect(self, o, d):
        res = self._embree.run(o.astype(np.float32), d.astype(np.float32), output=1)
        return res["primID"], res["tfar"].astype(np.float64)

    def _visible(self, o, d, dist):
        """True where nothing blocks the segment (Embree: -1 = free)."""
        occ = self._embree.run(o.astype(np.float32), d.astype(np.float32),
                               dists=dist.astype(np.float32), query="OCCLUDED")
        return occ == -1

    def camera_rays(self, pixel: np.ndarray, x: np.ndarray):
        """Origins and directions of the camera rays of lanes with pixel index
        ``pixel`` and sampler rows ``x``."""
        L = self.layout
        u = x[:, L.pair("pixel")].astype(np.float64)
        if self.filter == "gaussian":
            from scipy.special import ndtr, ndtri

            lo, hi = ndtr(-4.0), ndtr(4.0)  # +-4 sigma = +-2 pixels
            u = 0.5 + 0.5 * ndtri(lo + u * (hi - lo))
        fx = ((pixel % self.width) + u[:, 0]) / self.width
        fy = ((pixel // self.width) + u[:, 1]) / self.height
        # Mitsuba's camera space: +z forward, +y up, +x towards the image's left.
        d = np.stack([(1.0 - 2.0 * fx) * self._tan_x, (1.0 - 2.0 * fy) * self._tan_y, np.ones_like(fx)], axis=1)
        o = np.zeros_like(d)
        cam = self.scene.camera
        if L.lens:
            lens = concentric_disk(x[:, L.pair("lens")].astype(np.float64)) * cam.aperture
            focus = d * cam.focus_distance  # d.z == 1: the point on the plane of focus
            o = np.concatenate([lens, np.zeros((len(d), 1))], axis=1)
            d = focus - o
        o = _rotate(self._cam_rot, o) + self._cam_pos
        if L.time:
            o = o + x[:, L.index("time")].astype(np.float64)[:, None] * np.asarray(cam.motion)[None, :]
        return o, normalize(_rotate(self._cam_rot, d))

    # -- emitters -------------------------------------------------------------

    def _sample_emitter(self, u):
        """A point on an emitter: triangle index, point, normal and the
        probability density per unit area. ``u[:, 0]`` picks the triangle
        and is then rescaled to [0, 1) so that it still places the point."""
        k = np.minimum(np.searchsorted(self._em_cdf, u[:, 0], side="right"), len(self._em) - 1)
        lo = np.where(k > 0, self._em_cdf[np.maximum(k - 1, 0)], 0.0)
        u0 = np.clip((u[:, 0] - lo) / (self._em_cdf[k] - lo), 0.0, np.nextafter(1.0, 0.0))
        tri = self._em[k]
        w = triangle_point(np.stack([u0, u[:, 1]], axis=1))
        v = self.scene.triangles[tri].astype(np.float64)
        p = np.einsum("ij,ijk->ik", w, v)
        return tri, p, self.scene.normals[tri], self._em_prob[tri] / self.scene.areas[tri]

    # -- paths ----------------------------------------------------------------

    def radiance(self, pixel: np.ndarray, sample: np.ndarray, x: np.ndarray, seed: int = 0):
        """Radiance (RGB, float64) of the camera paths ``(pixel, sample)`` whose
        sampler rows are ``x`` (float32, shape ``(lanes, layout.dims)``)."""
        sc, L = self.scene, self.layout
        n = len(pixel)
        stats = Stats(paths=n)
        radiance = np.zeros((n, 3))
        o, d = self.camera_rays(pixel, x)
        beta = np.ones((n, 3))
        lane = np.arange(n)
        prev_pdf = np.zeros(n)  # solid-angle pdf of the BSDF sample that made the ray
        prev_delta = np.ones(n, dtype=bool)  # camera rays count emission fully
        rr_key = hash_pair(U32(seed), pixel.astype(U32), RR_KEY)
        for depth in range(1, L.max_depth + 1):
            if len(lane) == 0:
                break
            tri, t = self._intersect(o, d)
            stats.rays += len(lane)
            hit = tri >= 0
            lane, o, d, beta, prev_pdf, prev_delta, tri, t = _compact(
                hit, lane, o, d, beta, prev_pdf, prev_delta, tri, t)
            if len(lane) == 0:
                break
            p = o + t[:, None] * d
            ng = sc.normals[tri]
            # emission seen by this ray (emitters are one-sided)
            cos_l = -dot(ng, d)
            le = np.where((cos_l > 0)[:, None], sc.emission[tri], 0.0)
            if np.any(le):
                if depth == 1:
                    w = np.ones(len(lane))
                elif L.mis:
                    pdf_light = self._em_prob[tri] / sc.areas[tri] * t**2 / np.maximum(cos_l, 1e-12)
                    w = np.where(prev_delta, 1.0, prev_pdf**2 / np.maximum(prev_pdf**2 + pdf_light**2, 1e-300))
                else:
                    w = prev_delta.astype(np.float64)  # without MIS only light sampling counts
                radiance[lane] += beta * le * w[:, None]  # lanes are distinct
            if depth == L.max_depth:
                break
            # shading frame facing the incoming ray (two-sided surfaces)
            ns = np.where((dot(ng, d) > 0)[:, None], -ng, ng)
            tb = frame(ns)
            wo = to_local(-d, *tb, ns)
            wo[:, 2] = np.maximum(wo[:, 2], 1e-9)
            mat = sc.material[tri]
            row = x[lane]
            # next-event estimation: one point on an emitter
            smooth = sc.materials.kind[mat] != bsdf.MIRROR
            if np.any(smooth):
                s = np.flatnonzero(smooth)
                sel = slice(None) if len(s) == len(smooth) else s  # a view when every lane is smooth
                etri, q, nq, pdf_area = self._sample_emitter(row[sel][:, L.pair(f"light{depth}")].astype(np.float64))
                to_q = q - p[sel]
                dist = np.linalg.norm(to_q, axis=1)
                wi = to_q / np.maximum(dist, 1e-12)[:, None]
                cos_q = -dot(nq, wi)
                f_cos, pdf_b = bsdf.evaluate(sc.materials, mat[sel], wo[sel],
                                             to_local(wi, tb[0][sel], tb[1][sel], ns[sel]))
                pdf_l = pdf_area * dist**2 / np.maximum(cos_q, 1e-12)
                ok = (cos_q > 0) & np.any(f_cos > 0, axis=1)
                if np.any(ok):
                    s, wi, f_cos, pdf_b, pdf_l, etri, q, nq = _compact(
                        ok, s, wi, f_cos, pdf_b, pdf_l, etri, q, nq)
                    # The shadow ray runs between the two points, each moved off its
                    # surface (towards the other): from p + eps n to q + eps n_q.
                    # Measuring it from p instead let it reach the light's own
                    # plane and count the light as its own occluder.
                    start = p[s] + self._eps * np.where((dot(wi, ns[s]) > 0)[:, None], ns[s], -ns[s])
                    seg = q + self._eps * nq - start
                    seg_len = np.linalg.norm(seg, axis=1)
                    vis = self._visible(start, seg / np.maximum(seg_len, 1e-12)[:, None], seg_len * (1 - 1e-4))
                    stats.rays += len(s)
                    w = pdf_l**2 / (pdf_l**2 + pdf_b**2) if L.mis else np.ones(len(s))
                    contrib = beta[s] * f_cos * sc.emission[etri] * (w / pdf_l)[:, None]
                    radiance[lane[s[vis]]] += contrib[vis]
            # continue the path with a BSDF sample
            if not (L.mis or depth < L.max_depth - 1):
                break
            wi, weight, pdf, delta = bsdf.sample(sc.materials, mat, wo, row[:, L.pair(f"bsdf{depth}")].astype(np.float64))
            beta = beta * weight
            alive = np.any(beta > 0, axis=1)
            if depth >= RR_DEPTH:
                q = np.minimum(beta.max(axis=1), 0.95)
                h = hash_pair(rr_key[lane], sample[lane].astype(U32) * U32(64) + U32(depth), RR_KEY)
                u = (h >> U32(8)).astype(np.float64) * 2.0**-24
                alive &= u < q
                beta = beta / np.where(alive, q, 1.0)[:, None]
            wd = to_world(wi, *tb, ns)
            off = self._eps * np.where((dot(wd, ns) > 0)[:, None], ns, -ns)
            lane, o, d, beta, prev_pdf, prev_delta = _compact(
                alive, lane, p + off, wd, beta, pdf, delta)
        return radiance, stats
