"""One bounce of a wavefront, shaded in lanes (structure of arrays) so that
the compiler vectorizes it.

:func:`shade` takes the live entries of a wavefront :data:`CHUNK` at a time.
For each chunk it

1. gathers the entries whose ray hit something into a scratch array, one row
   per quantity (:func:`gather`, a scalar loop: the triangle's and the
   material's data are indexed by the hit, which a vector loop would read
   with slow gathers);
2. computes the hit point, the emission the ray sees, the shading frame and
   the offset of new rays for all those lanes at once (:func:`head`);
3. adds the emission to the paths' radiance and chooses each lane's point on
   an emitter (:func:`emit_and_choose`: a binary search per lane, scalar);
4. computes the next-event directions and the first kind's (Lambertian)
   values (:func:`light_directions`) and samples it (:func:`sample_lobes`)
   for every lane, then both again for the lanes of every other kind the
   scene has (:func:`other_kinds`): packed into rows of their own and shaded
   in vectorized loops for a kind with a lane form, one lane at a time
   otherwise;
5. makes the shadow rays and what they carry (:func:`shadow_rays`) and
   compacts them for Embree (:func:`emit_shadows`);
6. makes the new rays (:func:`new_rays`), and plays Russian roulette while
   compacting the surviving lanes to the front of the wavefront
   (:func:`survivors`).

The last bounce (the path's ``max_depth``-th segment, after which no light
sample or new ray follows) only adds the emission its rays see:
:func:`emission_only` does that one entry at a time for the few rays that
hit an emitter's front, without the scratch.

The lane loops of steps 2, 4, 5 and 6 (all but the packing of a kind's
lanes, the kinds shaded one lane at a time and the compactions) contain no
branches that depend on a lane (selects instead)
and touch only the scratch, laid out as one flat array
with rows :data:`CHUNK` apart: with the distance between rows a compile-time
constant, LLVM proves that the rows do not overlap and vectorizes the loops
without run-time alias checks (with a 2-D array whose row stride is only
known at run time it gave up; ``tests/render/test_compiled.py`` reads the
assembly). Each lane does the same operations in the same order as the
one-lane-at-a-time form of the reference, and without fast-math flags
vector instructions round exactly as scalar ones, so the image is the same
to the bit whatever the chunk, wavefront or vector width.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..._numba.hashes import hash_pair
from .. import bsdfs
from ..integrator import ORIGIN_ERROR, RR_KEY, TEST_ERROR
from .emitters import sample_emitter
from .forms import compiled
from .geometry import frame

#: error_model="numpy": IEEE divisions, as the NumPy reference's (numba's
#: default checks every division for zero and raises, which also stops the
#: vectorizer).
_JIT = dict(nogil=True, cache=True, error_model="numpy")
_INLINE = dict(_JIT, inline="always")

#: Lanes shaded together: the rows of the scratch array. 256 lanes of its
#: 133 rows are 274 KiB, within a core's L2 cache.
CHUNK = 256
#: Distance between the scratch's rows: CHUNK plus one cache line, because rows a
#: power of two apart fall into the same few sets of the L1 cache and evict
#: each other (the loops touch 20-40 rows at a time).
ROW = CHUNK + 8

#: The scratch's rows (each ``CHUNK`` float64 values; flags and material
#: kinds are stored as 0.0/1.0 and small whole numbers). Inputs, copied by
#: :func:`gather` (the material: its BSDF's kind, whether that is smooth, so
#: gets a light sample, and its numbers ``M0 .. M3``, ``Materials.params``):
(DX, DY, DZ, OX, OY, OZ, T, V0X, V0Y, V0Z, NX, NY, NZ, ER, EG, EB, PDF_AREA_HIT, REACH, KIND, SMOOTH, M0, M1, M2, M3,
 BR, BG, BB, PREV_PDF, PREV_DELTA, LIGHT_U, LIGHT_V, BSDF_U, BSDF_V,
 # the hit (head): point, shading normal, tangents, outgoing direction (local), whether it came from the side of
 # the geometric normal, offset, emission seen
 PX, PY, PZ, SX, SY, SZ, TX, TY, TZ, BX, BY, BZ, WOX, WOY, WOZ, FRONT, EPS, SEEN, LE_R, LE_G, LE_B,
 # the point chosen on an emitter (emit_and_choose)
 QX, QY, QZ, MX, MY, MZ, PDF_AREA, QE_R, QE_G, QE_B, Q_GROWTH, Q_REACH,
 # next event: direction to the light, its cosine there, local direction, BSDF value and pdf
 DIST, WX, WY, WZ, COS_Q, IX, IY, IZ, FR, FG, FB, PDF_B,
 # the shadow ray and what it carries
 SH_OK, SH_OX, SH_OY, SH_OZ, SH_DX, SH_DY, SH_DZ, SH_SEG, SH_R, SH_G, SH_B,
 # the BSDF sample (local direction, weight, pdf, delta) and the new ray
 NIX, NIY, NIZ, WR, WG, WB, PDF, DELTA, ALIVE, NBR, NBG, NBB, NOX, NOY, NOZ, NDX, NDY, NDZ,
 # the lanes of one kind with a lane form, packed to the front (other_kinds): which lane, what its BSDF reads,
 # what it gives
 PK_LANE, PK_M0, PK_M1, PK_M2, PK_M3, PK_FRONT, PK_OX, PK_OY, PK_OZ, PK_IX, PK_IY, PK_IZ, PK_U, PK_V,
 PK_FR, PK_FG, PK_FB, PK_PDF_B, PK_NIX, PK_NIY, PK_NIZ, PK_WR, PK_WG, PK_WB, PK_PDF, PK_DELTA) = (
    k * ROW for k in range(133))
#: Length of the scratch array: one ROW past the last row.
SCRATCH = PK_DELTA + ROW
#: The per-triangle values :func:`gather` copies, in the order of the rows
#: ``V0X .. M3`` (:func:`hit_data` makes them).
HIT_FIELDS = 17


def hit_data(scene, em_prob, reach):
    """What the shading reads of the triangle a ray hit, one contiguous row
    of :data:`HIT_FIELDS` float64 per triangle of ``scene`` (two cache
    lines instead of one from each of eight arrays): its first vertex, unit
    normal, emitted radiance, the pdf per unit area of choosing a point on it
    (``em_prob / area``, the reference's first operation on the two, so the
    same bits; ``em_prob``: :attr:`pyoa.render.emitters.Emitters.prob`), its
    offset scale (``reach``: :func:`pyoa.render.integrator.triangle_reach`),
    and its material's kind, whether that is smooth (not a delta) and its
    numbers (``Materials.params``)."""
    mat, m = np.asarray(scene.material), scene.materials
    kind = np.asarray(m.kind)[mat]
    return np.ascontiguousarray(np.column_stack([
        np.asarray(scene.triangles, np.float64)[:, 0], scene.normals, scene.emission,
        np.asarray(em_prob) / np.asarray(scene.areas), reach, kind.astype(np.float64),
        (~bsdfs.DELTA[kind]).astype(np.float64), np.asarray(m.params)[mat]]), dtype=np.float64)


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
    # computed for every lane and then selected, so that a loop over lanes has no branch on prev_delta
    h = power_heuristic(prev_pdf, pdf_light)
    return 1.0 if prev_delta else h


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


@njit(**_INLINE)
def path_state(w, i, depth):
    """``(beta r, g, b, prev_pdf, prev_delta)`` of the wavefront's entry ``i``
    at ``depth``: its throughput, and the pdf and delta flag of the BSDF
    sample that made its ray. A camera ray's (depth 1) are not stored
    (:func:`~pyoa.render.compiled.integrator.start_paths` writes only the
    rays and lanes): throughput 1, and counted as a delta lobe, so that what
    a camera ray sees gets no MIS weight."""
    if depth == 1:
        return 1.0, 1.0, 1.0, 0.0, True
    return w.beta[i, 0], w.beta[i, 1], w.beta[i, 2], w.prev_pdf[i], w.prev_delta[i]


@njit(**_JIT)
def gather(start, stop, depth, sc, ps, x, w, F, lanes):
    """Copy the entries ``start .. stop - 1`` of the wavefront ``w`` whose ray
    hit a triangle into the scratch ``F`` (their paths into ``lanes``), with
    the triangle's and the material's data and the path's sampler values of
    this depth. Returns how many."""
    lu, lv, bu, bv = ps.columns[depth, 0], ps.columns[depth, 1], ps.columns[depth, 2], ps.columns[depth, 3]
    h = 0
    for i in range(start, stop):
        tri = w.prim[i]
        if tri < 0:
            continue  # the ray left the scene
        li = w.lane[i]
        lanes[h] = li
        F[DX + h], F[DY + h], F[DZ + h] = w.d[i, 0], w.d[i, 1], w.d[i, 2]
        F[OX + h], F[OY + h], F[OZ + h] = w.o[i, 0], w.o[i, 1], w.o[i, 2]
        F[T + h] = w.t[i]
        for c in range(HIT_FIELDS):  # the triangle's row of sc.hit_data: V0X .. M3
            F[V0X + c * ROW + h] = sc.hit_data[tri, c]
        br, bg, bb, prev_pdf, prev_delta = path_state(w, i, depth)
        F[BR + h], F[BG + h], F[BB + h] = br, bg, bb
        F[PREV_PDF + h] = prev_pdf
        F[PREV_DELTA + h] = 1.0 if prev_delta else 0.0
        F[LIGHT_U + h] = np.float64(x[li, lu]) if lu >= 0 else 0.0
        F[LIGHT_V + h] = np.float64(x[li, lv]) if lv >= 0 else 0.0
        F[BSDF_U + h] = np.float64(x[li, bu]) if bu >= 0 else 0.0
        F[BSDF_V + h] = np.float64(x[li, bv]) if bv >= 0 else 0.0
        h += 1
    return h


@njit(**_JIT)
def head(h, depth, mis, F):
    """For the ``h`` gathered lanes (vectorized): the hit point moved onto
    its triangle's plane (:func:`to_plane`), the emission the ray sees with
    its MIS weight (emitters are one-sided), how far new rays leave the
    point (:func:`offset_distance`), the shading frame facing the incoming
    ray (two-sided surfaces), the outgoing direction in it and whether the
    ray came from the side the geometric normal points to (``FRONT``)."""
    for k in range(h):
        dx, dy, dz = F[DX + k], F[DY + k], F[DZ + k]
        nx, ny, nz = F[NX + k], F[NY + k], F[NZ + k]
        ti = F[T + k]
        px, py, pz = to_plane(F[OX + k] + ti * dx, F[OY + k] + ti * dy, F[OZ + k] + ti * dz,
                              F[V0X + k], F[V0Y + k], F[V0Z + k], nx, ny, nz)
        cos_l = -(nx * dx + ny * dy + nz * dz)
        er, eg, eb = F[ER + k], F[EG + k], F[EB + k]
        seen = (cos_l > 0) & ((er != 0.0) | (eg != 0.0) | (eb != 0.0))
        pdf_light = F[PDF_AREA_HIT + k] * ti * ti / max(cos_l, 1e-12)
        wt = emission_weight(depth, mis, pdf_light, F[PREV_PDF + k], F[PREV_DELTA + k] != 0.0)
        F[SEEN + k] = 1.0 if seen else 0.0
        F[LE_R + k], F[LE_G + k], F[LE_B + k] = F[BR + k] * er * wt, F[BG + k] * eg * wt, F[BB + k] * eb * wt
        F[EPS + k] = offset_distance(px, py, pz, nx, ny, nz, F[REACH + k])
        back = nx * dx + ny * dy + nz * dz > 0
        sx, sy, sz = -nx if back else nx, -ny if back else ny, -nz if back else nz
        (tx, ty, tz), (bx, by, bz) = frame(sx, sy, sz)
        F[PX + k], F[PY + k], F[PZ + k] = px, py, pz
        F[SX + k], F[SY + k], F[SZ + k] = sx, sy, sz
        F[TX + k], F[TY + k], F[TZ + k] = tx, ty, tz
        F[BX + k], F[BY + k], F[BZ + k] = bx, by, bz
        F[WOX + k] = -(dx * tx + dy * ty + dz * tz)
        F[WOY + k] = -(dx * bx + dy * by + dz * bz)
        F[WOZ + k] = max(-(dx * sx + dy * sy + dz * sz), 1e-9)
        F[FRONT + k] = 0.0 if back else 1.0


@njit(**_JIT)
def emit_and_choose(h, sc, F, lanes, radiance):
    """Add the emission each lane's ray sees to its path's radiance and
    choose a point on an emitter by power for each lane whose BSDF is smooth
    (not a delta; :func:`sample_emitter`, a binary search). (The last bounce
    has no light sample: :func:`emission_only`.)"""
    for k in range(h):
        li = lanes[k]
        if F[SEEN + k] != 0.0:
            radiance[li, 0] += F[LE_R + k]
            radiance[li, 1] += F[LE_G + k]
            radiance[li, 2] += F[LE_B + k]
        if F[SMOOTH + k] != 0.0:
            etri, qx, qy, qz, mx, my, mz, pdf_area = sample_emitter(
                sc.em, sc.em_cdf, sc.em_prob, sc.verts, sc.normals, sc.areas, F[LIGHT_U + k], F[LIGHT_V + k])
            F[QX + k], F[QY + k], F[QZ + k] = qx, qy, qz
            F[MX + k], F[MY + k], F[MZ + k] = mx, my, mz
            F[PDF_AREA + k] = pdf_area
            F[QE_R + k], F[QE_G + k], F[QE_B + k] = sc.emission[etri, 0], sc.emission[etri, 1], sc.emission[etri, 2]
            F[Q_GROWTH + k], F[Q_REACH + k] = sc.growth[etri], sc.reach[etri]
        else:
            # no light sample: values that keep the lane's arithmetic finite
            F[QX + k], F[QY + k], F[QZ + k] = F[PX + k] + 1.0, F[PY + k], F[PZ + k]
            F[MX + k], F[MY + k], F[MZ + k] = -1.0, 0.0, 0.0
            F[PDF_AREA + k], F[Q_GROWTH + k], F[Q_REACH + k] = 0.0, 0.0, 0.0
            F[QE_R + k], F[QE_G + k], F[QE_B + k] = 0.0, 0.0, 0.0


#: The registry's first kind (the Lambertian), whose one-point forms
#: :func:`light_directions` and :func:`sample_lobes` run on every lane (most
#: surfaces of most scenes are of that kind; :func:`other_kinds` overwrites
#: the lanes of the others). Its forms must be free of branches.
_BASE = bsdfs.BSDFS[0]
_base_evaluate, _base_sample = compiled(_BASE.evaluate_point), compiled(_BASE.sample_point)
_BASE_DELTA = bool(_BASE.DELTA)


@njit(**_JIT)
def light_directions(h, F):
    """For each lane (vectorized): the unit direction ``w`` to its point on an
    emitter, the distance, the cosine there, ``w`` in the shading frame and
    the first kind's ``(f_cos, pdf)`` of it (the other kinds:
    :func:`other_kinds`)."""
    for k in range(h):
        px, py, pz = F[PX + k], F[PY + k], F[PZ + k]
        vx, vy, vz = F[QX + k] - px, F[QY + k] - py, F[QZ + k] - pz
        dist = math.sqrt(vx * vx + vy * vy + vz * vz)
        inv = 1.0 / max(dist, 1e-12)  # one division, three products (the reference divides thrice)
        wx, wy, wz = vx * inv, vy * inv, vz * inv
        ix = wx * F[TX + k] + wy * F[TY + k] + wz * F[TZ + k]
        iy = wx * F[BX + k] + wy * F[BY + k] + wz * F[BZ + k]
        iz = wx * F[SX + k] + wy * F[SY + k] + wz * F[SZ + k]
        F[DIST + k] = dist
        F[WX + k], F[WY + k], F[WZ + k] = wx, wy, wz
        F[COS_Q + k] = -(F[MX + k] * wx + F[MY + k] * wy + F[MZ + k] * wz)
        F[IX + k], F[IY + k], F[IZ + k] = ix, iy, iz
        F[FR + k], F[FG + k], F[FB + k], F[PDF_B + k] = _base_evaluate(
            F[M0 + k], F[M1 + k], F[M2 + k], F[M3 + k], F[FRONT + k] != 0.0, F[WOX + k], F[WOY + k], F[WOZ + k],
            ix, iy, iz)


@njit(**_JIT)
def sample_lobes(h, F):
    """The first kind's BSDF sample of each lane (vectorized; where ``wo``
    lies below the surface: ``wi = +z``, weight and pdf 0, as
    :func:`~pyoa.render.compiled.bsdfs.sample`); the other kinds:
    :func:`other_kinds`."""
    for k in range(h):
        ox, oy, oz = F[WOX + k], F[WOY + k], F[WOZ + k]
        x, y, z, wr, wg, wb, pdf, delta = _base_sample(F[M0 + k], F[M1 + k], F[M2 + k], F[M3 + k],
                                                       F[FRONT + k] != 0.0, ox, oy, oz, F[BSDF_U + k], F[BSDF_V + k])
        below = oz <= 0.0  # the frame faces the ray, so it does not happen
        F[NIX + k] = 0.0 if below else x
        F[NIY + k] = 0.0 if below else y
        F[NIZ + k] = 1.0 if below else z
        F[WR + k] = 0.0 if below else wr
        F[WG + k] = 0.0 if below else wg
        F[WB + k] = 0.0 if below else wb
        F[PDF + k] = 0.0 if below else pdf
        F[DELTA + k] = 1.0 if (_BASE_DELTA if below else delta) else 0.0


@njit(**_JIT)
def pack(h, kind, F):
    """Copy what the BSDF reads of the lanes of kind ``kind`` to the front of
    the packed rows (``PK_*``, their lane in ``PK_LANE``); returns how many."""
    g = 0
    for k in range(h):
        if F[KIND + k] == kind:
            F[PK_LANE + g] = k
            F[PK_M0 + g], F[PK_M1 + g], F[PK_M2 + g], F[PK_M3 + g] = F[M0 + k], F[M1 + k], F[M2 + k], F[M3 + k]
            F[PK_FRONT + g] = F[FRONT + k]
            F[PK_OX + g], F[PK_OY + g], F[PK_OZ + g] = F[WOX + k], F[WOY + k], F[WOZ + k]
            F[PK_IX + g], F[PK_IY + g], F[PK_IZ + g] = F[IX + k], F[IY + k], F[IZ + k]
            F[PK_U + g], F[PK_V + g] = F[BSDF_U + k], F[BSDF_V + k]
            g += 1
    return g


@njit(**_JIT)
def unpack(g, extend, F):
    """Copy the packed lanes' next-event values and (``extend``) samples back
    to their lanes' rows."""
    for j in range(g):
        k = np.int64(F[PK_LANE + j])
        F[FR + k], F[FG + k], F[FB + k], F[PDF_B + k] = F[PK_FR + j], F[PK_FG + j], F[PK_FB + j], F[PK_PDF_B + j]
        if extend:
            F[NIX + k], F[NIY + k], F[NIZ + k] = F[PK_NIX + j], F[PK_NIY + j], F[PK_NIZ + j]
            F[WR + k], F[WG + k], F[WB + k], F[PDF + k] = F[PK_WR + j], F[PK_WG + j], F[PK_WB + j], F[PK_PDF + j]
            F[DELTA + k] = F[PK_DELTA + j]


def lane_loops(module):
    """A BSDF's lane form: ``(evaluate, sample)``, vectorized loops over the
    ``g`` packed lanes (:func:`pack`) that call its one-point forms (which
    must be free of branches), the sample with the guard of
    :func:`sample_lobes`."""
    evaluate_point, sample_point = compiled(module.evaluate_point), compiled(module.sample_point)
    delta_below = bool(module.DELTA)

    def evaluate(g, F):
        for j in range(g):
            F[PK_FR + j], F[PK_FG + j], F[PK_FB + j], F[PK_PDF_B + j] = evaluate_point(
                F[PK_M0 + j], F[PK_M1 + j], F[PK_M2 + j], F[PK_M3 + j], F[PK_FRONT + j] != 0.0, F[PK_OX + j],
                F[PK_OY + j], F[PK_OZ + j], F[PK_IX + j], F[PK_IY + j], F[PK_IZ + j])

    def sample(g, F):
        for j in range(g):
            oz = F[PK_OZ + j]
            x, y, z, wr, wg, wb, pdf, delta = sample_point(
                F[PK_M0 + j], F[PK_M1 + j], F[PK_M2 + j], F[PK_M3 + j], F[PK_FRONT + j] != 0.0, F[PK_OX + j],
                F[PK_OY + j], oz, F[PK_U + j], F[PK_V + j])
            below = oz <= 0.0
            F[PK_NIX + j] = 0.0 if below else x
            F[PK_NIY + j] = 0.0 if below else y
            F[PK_NIZ + j] = 1.0 if below else z
            F[PK_WR + j] = 0.0 if below else wr
            F[PK_WG + j] = 0.0 if below else wg
            F[PK_WB + j] = 0.0 if below else wb
            F[PK_PDF + j] = 0.0 if below else pdf
            F[PK_DELTA + j] = 1.0 if (delta_below if below else delta) else 0.0

    return njit(**_JIT)(evaluate), njit(**_JIT)(sample)


def _kind_pass(kind, module, rest):
    """The shading of the lanes of one kind other than the first, then
    ``rest``'s: skipped unless the scene has that kind (``kinds[kind]``); its
    lanes packed and shaded by its lane form when it has one (``LANES``), else
    one lane at a time by its one-point forms."""
    if module.LANES:
        evaluate_lanes, sample_lanes = LANE_LOOPS[kind] = lane_loops(module)

        def shade_kind(h, extend, kinds, F):
            if kinds[kind]:
                g = pack(h, kind, F)
                if g > 0:
                    evaluate_lanes(g, F)
                    if extend:
                        sample_lanes(g, F)
                    unpack(g, extend, F)
            rest(h, extend, kinds, F)
    else:
        evaluate_point, sample_point = compiled(module.evaluate_point), compiled(module.sample_point)
        delta_below = bool(module.DELTA)

        def shade_kind(h, extend, kinds, F):
            if kinds[kind]:
                for k in range(h):
                    if F[KIND + k] != kind:
                        continue
                    m0, m1, m2, m3, front = F[M0 + k], F[M1 + k], F[M2 + k], F[M3 + k], F[FRONT + k] != 0.0
                    ox, oy, oz = F[WOX + k], F[WOY + k], F[WOZ + k]
                    F[FR + k], F[FG + k], F[FB + k], F[PDF_B + k] = evaluate_point(
                        m0, m1, m2, m3, front, ox, oy, oz, F[IX + k], F[IY + k], F[IZ + k])
                    if not extend:
                        continue
                    if oz <= 0.0:  # as compiled.bsdfs.sample
                        F[NIX + k], F[NIY + k], F[NIZ + k] = 0.0, 0.0, 1.0
                        F[WR + k], F[WG + k], F[WB + k], F[PDF + k] = 0.0, 0.0, 0.0, 0.0
                        F[DELTA + k] = 1.0 if delta_below else 0.0
                        continue
                    x, y, z, wr, wg, wb, pdf, delta = sample_point(m0, m1, m2, m3, front, ox, oy, oz, F[BSDF_U + k],
                                                                   F[BSDF_V + k])
                    F[NIX + k], F[NIY + k], F[NIZ + k], F[WR + k], F[WG + k], F[WB + k] = x, y, z, wr, wg, wb
                    F[PDF + k], F[DELTA + k] = pdf, 1.0 if delta else 0.0
            rest(h, extend, kinds, F)

    return njit(**_JIT)(shade_kind)


@njit(**_JIT)
def _no_kind(h, extend, kinds, F):
    return None


def _kind_passes():
    """One :func:`_kind_pass` per kind of the registry after the first, chained in kind order."""
    link = _no_kind
    for kind in range(len(bsdfs.BSDFS) - 1, 0, -1):
        link = _kind_pass(kind, bsdfs.BSDFS[kind], link)
    return link


#: The lane form (:func:`lane_loops`) of each kind that has one, by kind id:
#: those :func:`other_kinds` runs (filled by :func:`_kind_pass`).
LANE_LOOPS: dict = {}
_other_kinds = _kind_passes()


@njit(**_JIT)
def other_kinds(h, extend, kinds, F):
    """The next-event ``(f_cos, pdf)`` and (``extend``) the BSDF sample of the
    lanes of every kind but the first that the scene has (``kinds``: per
    kind id, whether a material of the scene has it), written over what
    :func:`light_directions` and :func:`sample_lobes` wrote for them, one
    kind after another (kind order).

    A kind with a lane form (``LANES``, GGX and glass): its arithmetic is long
    and its lanes are few (``deep`` and ``dof7d``: one box of steel), so
    their inputs are packed to the front of rows of their own (scalar,
    :func:`pack`), shaded there in vectorized loops (:func:`lane_loops`) and
    copied back (scalar, :func:`unpack`): about half the time of shading
    them one at a time (``deep``, docs/performance.md). A kind without one
    (the mirror, a new BSDF until it gets one) is shaded one lane at a time
    by its one-point forms. When ``extend``, :func:`sample_lobes` must have
    run on the chunk first (:func:`shade` runs it just before)."""
    _other_kinds(h, extend, kinds, F)


@njit(**_JIT)
def shadow_rays(h, mis, F):
    """For each lane (vectorized): whether it has a shadow ray (a light sample
    facing it that the BSDF does not reject), the ray from ``p + eps n`` to
    ``q + eps_q n_q``, each moved off its surface by its own float32 error
    bound (``q``'s: the end of a segment of length ``dist``), not shortened
    further (as the reference), and what it carries: ``beta f_cos L_e w /
    pdf_light`` with the power heuristic's ``w`` (one division for both)."""
    for k in range(h):
        dist, cos_q = F[DIST + k], F[COS_Q + k]
        fr, fg, fb, pdf_b = F[FR + k], F[FG + k], F[FB + k], F[PDF_B + k]
        pdf_l = F[PDF_AREA + k] * dist * dist / max(cos_q, 1e-12)
        ok = (F[SMOOTH + k] != 0.0) & (cos_q > 0) & ((fr > 0) | (fg > 0) | (fb > 0))
        eps = F[EPS + k]
        side = eps if F[IZ + k] > 0 else -eps
        sx, sy, sz = F[SX + k], F[SY + k], F[SZ + k]
        ax, ay, az = F[PX + k] + side * sx, F[PY + k] + side * sy, F[PZ + k] + side * sz
        qx, qy, qz, mx, my, mz = F[QX + k], F[QY + k], F[QZ + k], F[MX + k], F[MY + k], F[MZ + k]
        eq = offset_distance(qx, qy, qz, mx, my, mz, dist * F[Q_GROWTH + k] + F[Q_REACH + k])
        gx, gy, gz = qx + eq * mx - ax, qy + eq * my - ay, qz + eq * mz - az
        seg = math.sqrt(gx * gx + gy * gy + gz * gz)
        inv = 1.0 / max(seg, 1e-12)
        # power_heuristic(pdf_l, pdf_b) / pdf_l in one division
        f = pdf_l / max(pdf_l * pdf_l + pdf_b * pdf_b, 1e-300) if mis else 1.0 / pdf_l
        F[SH_OK + k] = 1.0 if ok else 0.0
        F[SH_OX + k], F[SH_OY + k], F[SH_OZ + k] = ax, ay, az
        F[SH_DX + k], F[SH_DY + k], F[SH_DZ + k] = gx * inv, gy * inv, gz * inv
        F[SH_SEG + k] = seg
        F[SH_R + k] = F[BR + k] * fr * F[QE_R + k] * f
        F[SH_G + k] = F[BG + k] * fg * F[QE_G + k] * f
        F[SH_B + k] = F[BB + k] * fb * F[QE_B + k] * f


@njit(**_JIT)
def emit_shadows(h, F, lanes, w, shadows):
    """Append the lanes' shadow rays to the wavefront's (``w.sh_*``) from
    index ``shadows``; returns the new count."""
    for k in range(h):
        if F[SH_OK + k] != 0.0:
            j = shadows
            w.sh_o[j, 0], w.sh_o[j, 1], w.sh_o[j, 2] = F[SH_OX + k], F[SH_OY + k], F[SH_OZ + k]
            w.sh_d[j, 0], w.sh_d[j, 1], w.sh_d[j, 2] = F[SH_DX + k], F[SH_DY + k], F[SH_DZ + k]
            w.sh_dist[j] = F[SH_SEG + k]
            w.sh_lane[j] = lanes[k]
            w.sh_c[j, 0], w.sh_c[j, 1], w.sh_c[j, 2] = F[SH_R + k], F[SH_G + k], F[SH_B + k]
            shadows += 1
    return shadows


@njit(**_JIT)
def new_rays(h, F):
    """For each lane (vectorized): the throughput times the sample's weight,
    whether it is still nonzero, and the new ray in world space leaving the
    surface on the side it goes to."""
    for k in range(h):
        br, bg, bb = F[BR + k] * F[WR + k], F[BG + k] * F[WG + k], F[BB + k] * F[WB + k]
        ix, iy, iz = F[NIX + k], F[NIY + k], F[NIZ + k]
        sx, sy, sz = F[SX + k], F[SY + k], F[SZ + k]
        dx = ix * F[TX + k] + iy * F[BX + k] + iz * sx
        dy = ix * F[TY + k] + iy * F[BY + k] + iz * sy
        dz = ix * F[TZ + k] + iy * F[BZ + k] + iz * sz
        eps = F[EPS + k]
        side = eps if dx * sx + dy * sy + dz * sz > 0 else -eps
        F[ALIVE + k] = 1.0 if (br > 0) | (bg > 0) | (bb > 0) else 0.0
        F[NBR + k], F[NBG + k], F[NBB + k] = br, bg, bb
        F[NOX + k], F[NOY + k], F[NOZ + k] = F[PX + k] + side * sx, F[PY + k] + side * sy, F[PZ + k] + side * sz
        F[NDX + k], F[NDY + k], F[NDZ + k] = dx, dy, dz


@njit(**_JIT)
def survivors(h, depth, rr_depth, F, lanes, sample_index, rr_key, w, live):
    """Russian roulette (from depth ``rr_depth``) for the lanes whose
    throughput is nonzero, and the survivors' new rays, throughputs and
    pdfs written to the wavefront from entry ``live`` (compaction: the
    entries written were all gathered before). Returns the new count."""
    for k in range(h):
        if F[ALIVE + k] == 0.0:
            continue
        li = lanes[k]
        br, bg, bb = F[NBR + k], F[NBG + k], F[NBB + k]
        if depth >= rr_depth:
            alive, br, bg, bb = russian_roulette(br, bg, bb, rr_key[li], sample_index[li], depth)
            if not alive:
                continue
        j = live
        w.lane[j] = li
        w.o[j, 0], w.o[j, 1], w.o[j, 2] = F[NOX + k], F[NOY + k], F[NOZ + k]
        w.d[j, 0], w.d[j, 1], w.d[j, 2] = F[NDX + k], F[NDY + k], F[NDZ + k]
        w.beta[j, 0], w.beta[j, 1], w.beta[j, 2] = br, bg, bb
        w.prev_pdf[j] = F[PDF + k]
        w.prev_delta[j] = F[DELTA + k] != 0.0
        live += 1
    return live


#: Columns of :func:`hit_data`'s rows that the last bounce reads (the order
#: of the rows ``V0X .. CB``): the normal, the emitted radiance and the pdf
#: per unit area.
_HIT_N, _HIT_E, _HIT_PDF = ((row - V0X) // ROW for row in (NX, ER, PDF_AREA_HIT))


@njit(**_JIT)
def emission_only(n, depth, mis, sc, w, radiance):
    """The last bounce, after which no light sample and no new ray follow:
    only the emission that each of the ``n`` entries' rays sees, added to
    its path's radiance. One entry at a time, and only those whose ray hit
    the front of an emitter do any arithmetic (few do): gathering every hit
    into the scratch and computing the frames, offsets and the rest of
    :func:`head` for them was most of a shallow scene's last bounce. The
    operations of :func:`head` and :func:`emit_and_choose` on those values,
    in the same order, so the same bits."""
    hd = sc.hit_data
    for i in range(n):
        tri = w.prim[i]
        if tri < 0:
            continue  # the ray left the scene
        er, eg, eb = hd[tri, _HIT_E], hd[tri, _HIT_E + 1], hd[tri, _HIT_E + 2]
        if er == 0.0 and eg == 0.0 and eb == 0.0:
            continue
        dx, dy, dz = w.d[i, 0], w.d[i, 1], w.d[i, 2]
        cos_l = -(hd[tri, _HIT_N] * dx + hd[tri, _HIT_N + 1] * dy + hd[tri, _HIT_N + 2] * dz)
        if not cos_l > 0:
            continue  # emitters are one-sided
        ti = w.t[i]
        pdf_light = hd[tri, _HIT_PDF] * ti * ti / max(cos_l, 1e-12)
        br, bg, bb, prev_pdf, prev_delta = path_state(w, i, depth)
        wt = emission_weight(depth, mis, pdf_light, prev_pdf, prev_delta)
        li = w.lane[i]
        radiance[li, 0] += br * er * wt
        radiance[li, 1] += bg * eg * wt
        radiance[li, 2] += bb * eb * wt


@njit(**_JIT)
def shade(n, depth, sc, ps, x, sample_index, rr_key, w, radiance, F, lanes):
    """One bounce of the ``n`` live entries of the wavefront ``w``, whose
    closest hits are ``w.prim``/``w.t``, :data:`CHUNK` lanes at a time (the
    steps of this module's docstring; ``F`` the scratch, :data:`SCRATCH`
    float64, ``lanes`` :data:`CHUNK` int64). The reference's formulas, with
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
    next_event = depth < ps.max_depth
    if not next_event:
        emission_only(n, depth, ps.mis, sc, w, radiance)
        return 0, 0
    # a new ray when it can find emission (MIS) or feed a later light sample
    extend = ps.mis or depth < ps.max_depth - 1
    live, shadows = 0, 0
    for start in range(0, n, CHUNK):
        h = gather(start, min(start + CHUNK, n), depth, sc, ps, x, w, F, lanes)
        head(h, depth, ps.mis, F)
        emit_and_choose(h, sc, F, lanes, radiance)
        light_directions(h, F)
        if extend:
            sample_lobes(h, F)
        other_kinds(h, extend, sc.kinds, F)
        shadow_rays(h, ps.mis, F)
        shadows = emit_shadows(h, F, lanes, w, shadows)
        if extend:
            new_rays(h, F)
            live = survivors(h, depth, ps.rr_depth, F, lanes, sample_index, rr_key, w, live)
    return live, shadows
