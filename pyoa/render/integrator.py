"""The wavefront path tracer: camera rays, emitter sampling, and path
tracing with next-event estimation and multiple importance sampling.

Every lane is one camera path (pixel, sample). All random numbers of a path
come from one row of sampler values (:mod:`.layout` says which column feeds
what); rays are traced in bulk by Embree through ``embreex`` (float32 rays,
no ray start distance: origins are offset along the normal by a bound on the
float32 error at each point, :func:`offset_distance`; its occlusion answer is
0 for occluded and -1 for free); shading is vectorized NumPy in float64.
A lane's result depends only on its own row of sampler values, so the image
does not depend on how lanes are batched.

References
----------
.. [1] E. Veach, "Robust Monte Carlo Methods for Light Transport
   Simulation", PhD thesis, Stanford, 1997 (multiple importance sampling,
   power heuristic).
.. [2] M. Pharr, W. Jakob, G. Humphreys, "Physically Based Rendering", 4th
   ed., 2023, ch. 13 (path tracing), 5.2 (thin-lens camera) and 6.8
   (managing rounding error; 6.8.6, robust spawned ray origins).
.. [3] C. Wächter, N. Binder, "A Fast and Robust Method for Avoiding
   Self-Intersection", Ray Tracing Gems, ch. 6, 2019.
.. [4] Intel Embree, tutorials/pathtracer: ``dg.eps = 32 * FLT_EPSILON *
   max(|P.x|, |P.y|, |P.z|, ray.tfar)``, the ray start distance of every
   secondary ray.
.. [5] Intel Embree 4, kernels/geometry/triangle_intersector_pluecker.h:
   the vertices shifted to the ray origin, the normal from their edges, the
   hit distance from the normal and the first shifted vertex.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..hashes import U32, hash_pair
from . import bsdfs
from .camera import PerspectiveCamera, check_filter, filter_offsets
from .emitters import Emitters
from .geometry import dot, frame, to_local, to_world
from .layout import Layout

#: Russian roulette starts at this path depth (segments), as in Mitsuba 3.
RR_DEPTH = 5
#: Key of the Russian-roulette hash (not a sampler dimension, see layout).
RR_KEY = 0x7FEB352D
#: Version of what a render computes, bumped whenever the images of the same
#: settings change (the estimator, ray offsets, scene loading): progressive
#: and reference states and studies record it, and work of another version is
#: never mixed into theirs. 2 (issue 33): ray offsets follow each hit point's
#: own float32 error and Embree's error on its triangle, normals come from the
#: float32 vertices, shadow rays are not shortened, triangles flat in float32
#: are dropped; 1: offsets of 1e-4 of the scene's largest coordinate.
RENDERER_VERSION = 2
# The two factors below are checked by benchmarks/offset_stress.py (results:
# benchmarks/results/offset-stress.md), a stress test of Embree's answers
# through pyoa.render.embree with this module's own offset functions (robust
# mode, as embreex and pyoa.render.embree build their scenes; embreex gives
# the same counts): new rays leaving random points of one triangle (counted
# when they hit it), and shadow rays from points in front of a light triangle
# to random points of it (counted when occluded, the light alone in the
# scene); triangles 1e-3 to 1e5 across at 0 to 1e7 from the origin (within
# the loader's limits), axis-aligned, tilted by 1e-6 or 1e-3 radian or in
# random orientations, well shaped, needles and caps (all three edges long)
# of heights 1e-2 to 1e-6 of their length; shadow rays 1e-3 to 1e2 times the
# light's size; half the rays within 0.1 radian of grazing: 4.66e7 new rays
# and 3.38e7 shadow rays in all (2026-11-27, Intel Xeon 6/207).

#: Bound, relative to a coordinate, on the float32 rounding of ray origins
#: (:func:`offset_distance`): half an ulp is at most 2^-24 of it. In the
#: stress test 1 * 2^-24 is the smallest factor without self-intersections or
#: false occlusion (0.5 * 2^-24 lets 24 % of the new rays round back onto
#: axis-aligned planes), so 4 * 2^-24 leaves a margin of 4.
ORIGIN_ERROR = 4 * 2.0**-24
#: Bound on the error, along the normal, of Embree's float32 ray-triangle
#: test, relative to the reach of the triangle (:func:`triangle_reach`) and,
#: for the light end of a shadow ray, to the segment's length times the
#: triangle's growth (:func:`offset_distance`). In the stress test 4 * 2^-24
#: is the smallest factor without self-intersections (2 * 2^-24 left 9 of the
#: 4.66e7 new rays, all in one cap 1e-6 high) or false occlusion (2 * 2^-24
#: left 378 of the 3.38e7 shadow rays), so 16 * 2^-24 leaves a margin of 4.
#: With the origin's rounding alone (and the reach's last term) 2.1 % of the
#: new rays hit the triangle they left, in tilted triangles; with the longest
#: edge as the reach (before issue 33's review) 0.38 %, all from caps, and
#: 14 034 shadow rays were occluded by their light even with the segment
#: shortened by 1e-4.
TEST_ERROR = 16 * 2.0**-24


def triangle_reach(triangles: np.ndarray, normals: np.ndarray, areas: np.ndarray):
    """``(reach, growth)``, both ``(T,)`` float64: how the error of Embree's
    float32 test of the ``(T, 3, 3)`` triangles (as stored: the float32
    vertices Embree traces; ``normals`` and ``areas`` those of the scene,
    computed from them) grows with the triangle, along its normal.

    Embree's robust test moves the vertices to coordinates relative to the
    ray origin ``o``, rounds them to float32 and computes the normal from
    them and the origin's height above the plane [5]_. For an origin on the
    triangle each coordinate ``v_k - o_k`` is at most the triangle's extent
    ``w_k`` along axis ``k`` and is rounded by ``2^-24`` of it; a rounding
    within the plane moves nothing, so only ``|n_k| w_k`` counts. The
    float32 normal's own error, relative to its length (twice the area,
    ``|N|``), is a product of two edge components for each of its components;
    across the triangle it makes ``w_x w_y w_z / |N|``. So::

        reach = |n_x| w_x + |n_y| w_y + |n_z| w_z + w_x w_y w_z / |N| + 2^-24 max_k w_k

    which is 0 but for the last term for a triangle in an axis plane (its
    coordinates along the normal are all equal, and its float32 normal points
    exactly along that axis), about its size in a random orientation, and
    ``L^2 / h`` for a cap (all edges about ``L``, height ``h``), whose
    float32 normal turns by ``2^-24 L / h``. The last term keeps the offset
    above 0 for a triangle in a plane through the origin (``x = 0``), where
    the others vanish.

    For the end of a shadow segment ``s`` away, the coordinates relative to
    its start are up to ``s`` in every axis, and the normal's error turns
    that into ``growth * s``, ``growth = 1 + (w_x w_y + w_y w_z + w_z w_x) /
    |N|``.
    """
    lo = triangles.min(axis=1).astype(np.float64)
    w = triangles.max(axis=1).astype(np.float64)
    w -= lo  # in float64, where differences of float32 coordinates are exact or nearly
    del lo
    twice_area = 2.0 * areas
    wx, wy, wz = w[:, 0], w[:, 1], w[:, 2]
    reach = np.abs(normals[:, 0]) * wx + np.abs(normals[:, 1]) * wy + np.abs(normals[:, 2]) * wz
    reach += wx * wy * wz / twice_area
    reach += 2.0**-24 * w.max(axis=1)
    growth = 1.0 + (wx * wy + wy * wz + wz * wx) / twice_area
    return reach, growth


def to_plane(p: np.ndarray, v0: np.ndarray, m: np.ndarray) -> np.ndarray:
    """The points ``p`` moved along the unit normals ``m`` onto the planes
    through ``v0`` (all ``(N, 3)``).

    A hit point ``o + t d`` carries the float32 error of ``t`` and of the ray
    origin, which grows with the ray's length and the origin's coordinates;
    on the plane of its triangle (its vertex ``v0`` and unit normal ``m``,
    ``Scene.normals``: float64 arithmetic on the float32 vertices Embree
    traces) it has none along the normal, the only direction that
    matters for leaving the surface. pbrt-v4 [2]_ (6.8.5) recomputes hit
    points from barycentrics for the same reason.
    """
    # term by term, in the order of the compiled mirror (same bits)
    h = (p[:, 0] - v0[:, 0]) * m[:, 0] + (p[:, 1] - v0[:, 1]) * m[:, 1] + (p[:, 2] - v0[:, 2]) * m[:, 2]
    return p - h[:, None] * m


def offset_distance(p: np.ndarray, n: np.ndarray, extent: np.ndarray) -> np.ndarray:
    """How far along its unit normal ``n`` a ray must leave the surface point
    ``p`` (``(N, 3)``) for Embree's float32 test not to find that surface
    again. ``p`` lies on its triangle's plane (:func:`to_plane`, or a point
    sampled on a light), and ``extent`` is the length that Embree's error
    there grows with (:func:`triangle_reach`): the triangle's reach, plus,
    for a light sample at the end of a shadow segment, the segment's length
    times the triangle's growth.

    The offset is pbrt-v4's [2]_ ``d = dot(|n|, e)`` (6.8.6, robust spawned
    ray origins) for a per-component bound ``e`` of what float32 rounds::

        e_k = ORIGIN_ERROR |p_k| + TEST_ERROR extent
        d   = |n_x| e_x + |n_y| e_y + |n_z| e_z

    The first term bounds the rounding of the ray origin to float32, half an
    ulp (at most ``2^-24 |p_k|``); only the coordinates along the normal
    count (a wall at ``x = 1e5`` needs 1e5's rounding, the floor beside it
    does not). The second bounds the error of Embree's test along the
    normal, which grows with the vertices' coordinates relative to the ray
    origin (:func:`triangle_reach`): 0 but for ``2^-24`` of the triangle for
    a triangle in an axis plane (a floor 1e5 wide leaves at 2.4e-7 at
    ``y = -1``, not at 0.135 as with its longest edge), about its size in
    a random orientation; and for a shadow segment also its float32
    direction and length. So the offset follows the point and its
    triangle, not the largest coordinate of the scene nor the length of the
    ray that found it: it is the same fraction of the geometry at every
    scale, and grows with the distance from the origin only as float32's
    spacing does, up to the limits that the scene loader checks
    (``pyoa.render.scene._check_float32_precision``). Embree's own path
    tracer [4]_ starts secondary rays at ``64 * 2^-24 max(|p|, t)``; Wächter
    and Binder [3]_ move float32 hit points by 256 ulps of each coordinate.
    Returns ``(N,)`` float64 distances.
    """
    s = TEST_ERROR * extent
    a, b = np.abs(n), ORIGIN_ERROR * np.abs(p)
    # term by term, in the order of the compiled mirror (same bits)
    return a[:, 0] * (b[:, 0] + s) + a[:, 1] * (b[:, 1] + s) + a[:, 2] * (b[:, 2] + s)


def _compact(keep: np.ndarray, *arrays):
    """The rows of each array where ``keep`` holds (the arrays themselves when
    all do): one index computed once, instead of a boolean mask evaluated
    per array (docs/performance.md)."""
    if keep.all():
        return arrays
    idx = np.flatnonzero(keep)
    return tuple(a[idx] for a in arrays)


def power_heuristic(f_pdf: np.ndarray, g_pdf: np.ndarray) -> np.ndarray:
    """Veach's power heuristic (beta = 2): the weight of the strategy of
    density ``f_pdf`` against one of density ``g_pdf``, ``f^2 / (f^2 + g^2)``
    (guarded against 0 / 0) [1]_."""
    return f_pdf**2 / np.maximum(f_pdf**2 + g_pdf**2, 1e-300)


def russian_roulette(beta: np.ndarray, rr_key: np.ndarray, sample: np.ndarray, depth: int):
    """``(alive, beta)``: each path survives with probability ``q = min(max
    throughput, 0.95)`` and its throughput is divided by ``q`` (unbiased). The
    uniform number is a hash of the path (pixel key, sample index, depth),
    not a sampler dimension, so the layout does not depend on path length."""
    q = np.minimum(beta.max(axis=1), 0.95)
    h = hash_pair(rr_key, sample.astype(U32) * U32(64) + U32(depth), RR_KEY)
    u = (h >> U32(8)).astype(np.float64) * 2.0**-24
    alive = u < q
    return alive, beta / np.where(alive, q, 1.0)[:, None]


@dataclass
class Stats:
    """Counts of one render (summed over batches)."""

    paths: int = 0
    rays: int = 0  # every ray traced: camera, continuation and shadow rays

    def add(self, other: "Stats") -> None:
        self.paths += other.paths
        self.rays += other.rays


@functools.lru_cache(maxsize=1)
def _embreex_device():
    """The process's ``embreex`` device, on which every reference integrator
    builds its scene: made once and kept. ``embreex`` would otherwise make
    and release a device per scene, and releasing an Embree device while
    another lives left a TBB worker spinning through the next compiled
    render (see :func:`pyoa.render.embree.device`, which keeps the compiled
    path's device for the same reason)."""
    from embreex import rtcore

    return rtcore.EmbreeDevice()


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
        check_filter(filter)
        self.scene, self.layout = scene, layout
        self.width, self.height, self.filter = width, height, filter
        #: Reach and growth of each triangle as traced (float32), for
        #: :func:`offset_distance` (its plane for :func:`to_plane` is
        #: ``scene.normals``); computed before Embree's build, so that their
        #: temporaries do not add to its peak.
        self.reach, self.growth = triangle_reach(scene.triangles, scene.normals, scene.areas)
        self._tracer = self._build_tracer(scene)
        self.camera = PerspectiveCamera(scene.camera, width, height)
        self.emitters = Emitters(scene)

    # -- rays ---------------------------------------------------------------

    def _build_tracer(self, scene):
        """The scene as ``embreex`` traces it (one Python call per wavefront)."""
        from embreex import rtcore_scene as rtcs
        from embreex.mesh_construction import TriangleMesh

        tracer = rtcs.EmbreeScene(_embreex_device())
        TriangleMesh(tracer, np.ascontiguousarray(scene.triangles, dtype=np.float32))
        return tracer

    def _intersect(self, o, d):
        res = self._tracer.run(o.astype(np.float32), d.astype(np.float32), output=1)
        return res["primID"], res["tfar"].astype(np.float64)

    def _visible(self, o, d, dist):
        """True where nothing blocks the segment (Embree: -1 = free)."""
        occ = self._tracer.run(o.astype(np.float32), d.astype(np.float32),
                               dists=dist.astype(np.float32), query="OCCLUDED")
        return occ == -1

    def camera_rays(self, pixel: np.ndarray, x: np.ndarray):
        """Origins and directions of the camera rays of lanes with pixel index
        ``pixel`` and sampler rows ``x``."""
        L = self.layout
        offset = filter_offsets(x[:, L.pair("pixel")].astype(np.float64), self.filter)
        lens = x[:, L.pair("lens")].astype(np.float64) if L.lens else None
        shutter = x[:, L.index("time")].astype(np.float64) if L.time else None
        return self.camera.rays(pixel, offset, lens, shutter)

    # -- the steps of a bounce ------------------------------------------------

    def emitted(self, tri, d):
        """``(Le, cos)``: the radiance each ray sees at its hit (emitters are
        one-sided) and the cosine at the emitter."""
        cos_l = -dot(self.scene.normals[tri], d)
        return np.where((cos_l > 0)[:, None], self.scene.emission[tri], 0.0), cos_l

    def emission_weight(self, depth, tri, t, cos_l, prev_pdf, prev_delta):
        """MIS weight of emission reached by a BSDF sample, against light
        sampling of the same point: 1 for camera rays and delta lobes; without
        MIS only light sampling counts emission after the first segment."""
        if depth == 1:
            return np.ones(len(tri))
        if not self.layout.mis:
            return prev_delta.astype(np.float64)
        pdf_light = self.emitters.pdf_area(tri) * t**2 / np.maximum(cos_l, 1e-12)
        return np.where(prev_delta, 1.0, power_heuristic(prev_pdf, pdf_light))

    def next_event(self, p, off, ns, tb, wo, front, mat, beta, u):
        """Next-event estimation at the smooth lanes: one point on an emitter
        per lane (``u``: its two numbers), the BSDF (``front``: which side of
        the geometric normal ``wo`` lies on) and the MIS weight (power
        heuristic against BSDF sampling), and a shadow ray between the two
        points, the one at ``p`` moved ``off`` (:func:`offset_distance`) off
        its surface. Returns ``(lanes, contributions)`` of the unoccluded
        samples, and the number of shadow rays traced."""
        sc = self.scene
        etri, q, nq, pdf_area = self.emitters.sample(u)
        to_q = q - p
        dist = np.linalg.norm(to_q, axis=1)
        wi = to_q / np.maximum(dist, 1e-12)[:, None]
        cos_q = -dot(nq, wi)
        f_cos, pdf_b = bsdfs.evaluate(sc.materials, mat, wo, to_local(wi, tb[0], tb[1], ns), front)
        pdf_l = pdf_area * dist**2 / np.maximum(cos_q, 1e-12)
        s = np.flatnonzero((cos_q > 0) & np.any(f_cos > 0, axis=1))
        if len(s) == 0:
            return s, np.zeros((0, 3)), 0
        if len(s) < len(cos_q):
            wi, f_cos, pdf_b, pdf_l, etri, q, nq, dist = (
                a[s] for a in (wi, f_cos, pdf_b, pdf_l, etri, q, nq, dist))
        # The shadow ray runs between the two points, each moved off its
        # surface (towards the other) by its own float32 error bound: from
        # p + off n to q + off_q n_q, off_q that of the end of a segment of
        # length dist. Measuring it from p instead let it reach the
        # light's own plane and count the light as its own occluder. The
        # segment is not shortened further: off_q alone keeps the light out
        # (stress test, TEST_ERROR), and a shorter one missed occluders
        # within 1e-4 of its length from the light.
        start = p[s] + off[s][:, None] * np.where((dot(wi, ns[s]) > 0)[:, None], ns[s], -ns[s])
        seg = q + offset_distance(q, nq, dist * self.growth[etri] + self.reach[etri])[:, None] * nq - start
        seg_len = np.linalg.norm(seg, axis=1)
        vis = self._visible(start, seg / np.maximum(seg_len, 1e-12)[:, None], seg_len)
        w = power_heuristic(pdf_l, pdf_b) if self.layout.mis else np.ones(len(s))
        contrib = beta[s] * f_cos * sc.emission[etri] * (w / pdf_l)[:, None]
        return s[vis], contrib[vis], len(s)

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
            lane, o, d, beta, prev_pdf, prev_delta, tri, t = _compact(
                tri >= 0, lane, o, d, beta, prev_pdf, prev_delta, tri, t)
            if len(lane) == 0:
                break
            p = to_plane(o + t[:, None] * d, sc.triangles[tri, 0].astype(np.float64), sc.normals[tri])
            le, cos_l = self.emitted(tri, d)
            if np.any(le):
                w = self.emission_weight(depth, tri, t, cos_l, prev_pdf, prev_delta)
                radiance[lane] += beta * le * w[:, None]  # lanes are distinct
            if depth == L.max_depth:
                break
            # shading frame facing the incoming ray (two-sided surfaces); front: the ray came from the side the
            # geometric normal points to (glass refracts into the other side by its own index)
            ng = sc.normals[tri]
            back = dot(ng, d) > 0
            front = ~back
            ns = np.where(back[:, None], -ng, ng)
            off = offset_distance(p, ng, self.reach[tri])  # new rays leave p this far along ns
            tb = frame(ns)
            wo = to_local(-d, *tb, ns)
            wo[:, 2] = np.maximum(wo[:, 2], 1e-9)
            mat = sc.material[tri]
            row = x[lane]
            smooth = ~bsdfs.DELTA[sc.materials.kind[mat]]  # delta lobes get no light sample
            if np.any(smooth):
                s = np.flatnonzero(smooth)
                sel = slice(None) if len(s) == len(smooth) else s  # a view when every lane is smooth
                hit, contrib, shadows = self.next_event(
                    p[sel], off[sel], ns[sel], (tb[0][sel], tb[1][sel]), wo[sel], front[sel], mat[sel], beta[sel],
                    row[sel][:, L.pair(f"light{depth}")].astype(np.float64))
                stats.rays += shadows
                radiance[lane[s[hit]]] += contrib
            # continue the path with a BSDF sample
            if not (L.mis or depth < L.max_depth - 1):
                break
            u = row[:, L.pair(f"bsdf{depth}")].astype(np.float64)
            wi, weight, pdf, delta = bsdfs.sample(sc.materials, mat, wo, u, front)
            beta = beta * weight
            alive = np.any(beta > 0, axis=1)
            if depth >= RR_DEPTH:
                survive, beta = russian_roulette(beta, rr_key[lane], sample[lane], depth)
                alive &= survive
            wd = to_world(wi, *tb, ns)
            o = p + off[:, None] * np.where((dot(wd, ns) > 0)[:, None], ns, -ns)
            lane, o, d, beta, prev_pdf, prev_delta = _compact(alive, lane, o, wd, beta, pdf, delta)
        return radiance, stats
