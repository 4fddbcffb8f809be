#!/usr/bin/env python3
"""Ray-offset stress test: the evidence behind ``ORIGIN_ERROR`` and ``TEST_ERROR``.

A ray in pyoa's renderer has no start distance: a new ray leaves its hit
point ``p`` from ``p + offset_distance(p, n, reach) * n`` (after ``to_plane``
moved ``p`` onto its triangle's plane), and a shadow ray ends at ``q +
offset_distance(q, n_q, dist * growth + reach) * n_q`` on the light
(``pyoa/render/integrator.py``: ``triangle_reach``, ``offset_distance``,
``to_plane``). The two constants in ``offset_distance`` were chosen with this
test; it counts Embree's wrong answers for several factors:

* **new rays** (self-intersection): rays leaving random points of one
  triangle, alone in an Embree scene, along random directions on either side
  (half of them within 0.1 radian of grazing: cosines 1e-6 to 1e-1), from the
  offset origin; a ray that hits the triangle is counted;
* **shadow rays** (false occlusion): a light triangle alone in the scene,
  shadow rays from points in front of it (1e-3 to 1e2 times its longest edge
  away, half near grazing, and clearly in front: by twice the shipped offset
  there) to random points of it moved off by the light end's offset, as
  ``Integrator.next_event`` traces them; an occluded ray is counted.

Cases: every combination of triangle size (1e-3 to 1e5), distance of the
triangle from the origin (0 to 1e7, within the scene loader's limit ``C <=
2^15 x size``), orientation (axis-aligned, tilted by 1e-6 or 1e-3 radian
about a random axis, random) and shape (well shaped; needles, one edge short;
caps, all three edges long; heights 1e-2, 1e-4 and 1e-6 of the length), each
a fresh random triangle per trial. Triangles that ``triangle_geometry`` finds
flat in float32 (the loader drops them) are skipped and counted.

Variants (each traces the same rays; only the offset changes): the test
term's factor ``TEST_ERROR`` at 1, 2, 4 and 16 x 2^-24 (16, the shipped
value), the origin term's factor ``ORIGIN_ERROR`` at 0.5, 1 and 2 x 2^-24 (4
is shipped; under 1, less than float32's half ulp, origins round back onto
axis-aligned planes), the origin term with only the reach's last term (new rays), and the
reach used before (the longest edge, growth 1; for shadow rays also with the
segment shortened by 1e-4, as then). Other factors are ``offset_distance``'s
own arguments scaled by powers of two, so every row computes its offsets with
the renderer's function, and the shipped row with the renderer's exact bits.

Rays are traced by ``pyoa.render.embree`` (the compiled shading's Embree 4
calls, robust scenes, packets as wide as renders use); ``--embreex`` also
traces every variant through ``embreex`` (the NumPy shading's path) and
reports whether the counts agree. Seeds are fixed per case (``--seed``,
family, case, trial), so the counts do not depend on threads or on which
cases run. The exit status is 1 when the shipped constants leave any
self-intersection or false occlusion, else 0.

Output: ``benchmarks/results/offset-stress.json`` and ``.md`` (``--out``;
``--quick`` writes under ``benchmarks/results/quick/``, which git ignores),
written atomically: the counts per variant, split by each attribute of the
cases, the five worst triangles of each variant (case index and trial: run
again with the same seed they are the same triangles), and the machine;
``--per-case`` adds every triangle's vertices and counts (several MB).

Usage::

    python benchmarks/offset_stress.py            # 4.7e7 new rays and 3.4e7 shadow rays per variant (~1 min on 2 cores)
    python benchmarks/offset_stress.py --quick    # the first trials only: 1.55e7 new, 5.6e6 shadow rays (~15 s)
    python benchmarks/offset_stress.py --list     # the cases and variants
"""

from __future__ import annotations

import argparse
import datetime as _dt
import itertools
import json
import math
import os
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))

import numpy as np  # noqa: E402

from common import _version, loadavg, log, machine, machine_lines, write_text  # noqa: E402
from pyoa.render import embree  # noqa: E402
from pyoa.render.compiled.integrator import packet_width  # noqa: E402
from pyoa.render.geometry import triangle_point  # noqa: E402
from pyoa.render.integrator import ORIGIN_ERROR, TEST_ERROR, offset_distance, to_plane, triangle_reach  # noqa: E402
from pyoa.render.scene import MAX_POSITION_RATIO, triangle_geometry  # noqa: E402

EPS = 2.0**-24
OUT = REPO / "benchmarks" / "results" / "offset-stress.json"
QUICK_OUT = REPO / "benchmarks" / "results" / "quick" / "offset-stress.json"

SIZES = (1e-3, 1.0, 1e3, 1e5)
DISTANCES = (0.0, 1.0, 1e3, 1e5, 1e7)
ORIENTATIONS = ("axis", "tilt1e-6", "tilt1e-3", "random")
SHAPES = ("good", "needle1e-2", "needle1e-4", "needle1e-6", "cap1e-2", "cap1e-4", "cap1e-6")
FAMILIES = ("new", "shadow")
#: Shadow rays start 10^U(lo, hi) longest edges away from the light.
SHADOW_DISTANCE = (-3.0, 2.0)
#: Rays per triangle and random triangles (trials) per case, per family, by
#: default and with --quick. Trial k of a case has the same seed in both, so a
#: quick run's counts are those of the full run's first trials (two trials of
#: new rays: the 1.55e7 new rays that the comment above ORIGIN_ERROR quotes).
FULL = {"rays": 20_000, "trials": {"new": 6, "shadow": 6}}
QUICK = {"rays": 20_000, "trials": {"new": 2, "shadow": 1}}
#: The case attributes of the breakdown tables, and their values.
DIMENSIONS = (("orientation", ORIENTATIONS), ("shape", SHAPES), ("size", SIZES), ("distance", DISTANCES))


@dataclass(frozen=True)
class Variant:
    key: str
    label: str
    origin: float  # ORIGIN_ERROR of this row, in units of 2^-24
    test: float  # TEST_ERROR of this row, in units of 2^-24
    reach: str = "reach"  # "reach" (triangle_reach), "longest" (longest edge, growth 1), "floor" (its last term)
    shorten: float = 0.0  # shadow segment shortened by this fraction
    families: tuple[str, ...] = FAMILIES


def variants() -> list[Variant]:
    o, t = ORIGIN_ERROR / EPS, TEST_ERROR / EPS
    rows = [Variant(f"test{f:g}", f"TEST_ERROR {f:g} x 2^-24" + (" (shipped)" if f == t else ""), o, f)
            for f in sorted({1.0, 2.0, 4.0, 16.0, t})]
    rows += [Variant(f"origin{g:g}", f"ORIGIN_ERROR {g:g} x 2^-24 (TEST_ERROR {t:g})", g, t)
             for g in (0.5, 1.0, 2.0) if g != o]
    rows += [
        Variant("floor", "origin term and the reach's last term only (2^-24 max_k w_k)", o, t, reach="floor",
                families=("new",)),
        Variant("longest", "longest edge as reach, growth 1 (before)", o, t, reach="longest"),
        Variant("longest-short", "longest edge, growth 1, segment shortened by 1e-4 (before)", o, t,
                reach="longest", shorten=1e-4, families=("shadow",)),
    ]
    return rows


def shipped_key() -> str:
    return f"test{TEST_ERROR / EPS:g}"


def offset(p: np.ndarray, n: np.ndarray, extent: np.ndarray, origin: float, test: float) -> np.ndarray:
    """``offset_distance(p, n, extent)`` as if ``ORIGIN_ERROR`` were
    ``origin x 2^-24`` and ``TEST_ERROR`` ``test x 2^-24``: its arguments
    scaled by powers of two (exact), so the renderer's own function computes
    every row, and the shipped factors give its exact bits."""
    a, b = origin * EPS / ORIGIN_ERROR, test * EPS / TEST_ERROR
    for s in (a, b):
        if math.frexp(s)[0] != 0.5:
            raise ValueError(f"factor ratio {s} is not a power of two")
    return offset_distance(p if a == 1.0 else p * a, n, extent if b == 1.0 else extent * b)


# ---------------------------------------------------------------------------
# cases


def cases() -> list[tuple[float, float, str, str]]:
    """(size, distance from the origin, orientation, shape) within the loader's limit."""
    return [(size, dist, orient, shape)
            for size, dist, orient, shape in itertools.product(SIZES, DISTANCES, ORIENTATIONS, SHAPES)
            if dist <= MAX_POSITION_RATIO * size]


def rotation(rng: np.random.Generator, orient: str) -> np.ndarray:
    """An axis permutation with signs, turned by ``tiltA`` radian about a random
    axis, or a random rotation."""
    if orient == "random":
        q, r = np.linalg.qr(rng.normal(size=(3, 3)))
        return q * np.sign(np.diag(r))
    m = np.eye(3)[rng.permutation(3)] * rng.choice([-1.0, 1.0], 3)[:, None]
    if orient == "axis":
        return m
    angle = float(orient.removeprefix("tilt"))
    ax = rng.normal(size=3)
    ax /= np.linalg.norm(ax)
    k = np.array([[0, -ax[2], ax[1]], [ax[2], 0, -ax[0]], [-ax[1], ax[0], 0]])
    return (np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k) @ m


def triangle(rng: np.random.Generator, size: float, dist: float, orient: str, shape: str) -> np.ndarray:
    """``(3, 3)`` float32 vertices, as the scene stores them: a shape of
    length ``size`` turned by ``rotation`` and centred ``dist`` from the origin
    in a random direction."""
    if shape == "good":  # three points on the unit circle, at least 0.6 radian apart
        ang = np.sort(rng.uniform(0, 2 * np.pi, 3)) + np.array([0.0, 0.6, 1.2])
        v = np.stack([np.cos(ang), np.sin(ang), np.zeros(3)], 1)
    else:  # a needle has one short edge (height h at one end), a cap none (height h in the middle)
        h = float(shape.removeprefix("needle").removeprefix("cap"))
        v = np.array([[0.0, 0, 0], [1, 0, 0], [1.0 if shape.startswith("needle") else 0.5, h, 0]])
    v = v[rng.permutation(3)]
    centre = rng.normal(size=3)
    centre *= dist / np.linalg.norm(centre)
    return ((size * v) @ rotation(rng, orient).T + centre).astype(np.float32)


def directions(rng: np.random.Generator, n: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """``(d, side)``: unit directions leaving the plane of normal ``n`` on side
    ``side`` (+-1), half with the cosine to ``n`` uniform, half 10^U(-6, -1)
    (within 0.1 radian of grazing)."""
    side = rng.choice([-1.0, 1.0], count)
    cos = np.where(rng.random(count) < 0.5, rng.random(count), 10.0 ** rng.uniform(-6, -1, count))
    phi = rng.uniform(0, 2 * np.pi, count)
    a = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    s = np.sqrt(1 - cos**2)
    d = (s * np.cos(phi))[:, None] * a + (s * np.sin(phi))[:, None] * b + cos[:, None] * n
    return d * side[:, None], side


def extents(tris: np.ndarray):
    """``(normal, reach, growth, longest, floor)`` of one triangle as the
    renderer computes them (``triangle_geometry``, ``triangle_reach``), the
    longest edge (the reach before) and the reach's last term, or None when
    the triangle is flat in float32."""
    normals, areas, keep = triangle_geometry(tris)
    if not keep[0]:
        return None
    reach, growth = triangle_reach(tris, normals, areas)
    t = tris[0].astype(np.float64)
    longest = max(float(np.linalg.norm(t[b] - t[a])) for a, b in ((0, 1), (1, 2), (2, 0)))
    floor = EPS * float((t.max(axis=0) - t.min(axis=0)).max())
    return normals[0], float(reach[0]), float(growth[0]), longest, floor


class Tracer:
    """One triangle in a ``pyoa.render.embree`` scene (and, with ``embreex``,
    in an embreex scene too)."""

    def __init__(self, tris: np.ndarray, width: int, with_embreex: bool):
        self.width = width
        self.hit_fn, self.occ_fn = embree.query_addresses(width)
        self.scene = embree.Scene(tris)
        self.ex = None
        if with_embreex:
            from embreex import rtcore_scene as rtcs
            from embreex.mesh_construction import TriangleMesh

            self.ex = rtcs.EmbreeScene()
            TriangleMesh(self.ex, np.ascontiguousarray(tris, dtype=np.float32))

    def hits(self, o, d) -> tuple[int, int | None]:
        prim, t = np.empty(len(o), np.int64), np.empty(len(o))
        embree.intersect(self.scene.handle, self.hit_fn, self.width, o, d, prim, t)
        ex = None
        if self.ex is not None:
            ex = int(np.sum(self.ex.run(o.astype(np.float32), d.astype(np.float32), output=1)["primID"] >= 0))
        return int(np.sum(prim >= 0)), ex

    def occluded(self, o, d, dist) -> tuple[int, int | None]:
        free = np.empty(len(o), np.bool_)
        embree.occluded(self.scene.handle, self.occ_fn, self.width, o, d, dist, free)
        ex = None
        if self.ex is not None:
            ex = int(np.sum(self.ex.run(o.astype(np.float32), d.astype(np.float32),
                                        dists=dist.astype(np.float32), query="OCCLUDED") == 0))
        return int(np.sum(~free)), ex

    def close(self):
        self.scene.close()


def run_new(rng, tris, geo, count, rows, tracer) -> dict:
    """New rays leaving random points of the triangle; counts of hits per variant."""
    n, reach, _growth, longest, floor = geo
    v = tris[0].astype(np.float64)
    m = np.broadcast_to(n, (count, 3))
    # a point of the triangle as the renderer has it: on the plane (to_plane)
    p = to_plane(triangle_point(rng.random((count, 2))) @ v, np.broadcast_to(v[0], (count, 3)), m)
    d, side = directions(rng, n, count)
    away = side[:, None] * n  # the normal facing the new ray, as ns in Integrator.radiance
    ext = {"reach": reach, "longest": longest, "floor": floor}
    out, ex = {}, {}
    for var in rows:
        off = offset(p, m, np.full(count, ext[var.reach]), var.origin, var.test)
        out[var.key], ex[var.key] = tracer.hits(p + off[:, None] * away, d)
    return {"rays": count, "counts": out, "embreex": ex if tracer.ex is not None else None}


def run_shadow(rng, tris, geo, count, rows, tracer) -> dict:
    """Shadow rays from points in front of the light to random points of it;
    counts of occluded rays per variant."""
    n, reach, growth, longest, _floor = geo
    v = tris[0].astype(np.float64)
    m = np.broadcast_to(n, (count, 3))
    # light samples as Emitters.sample draws them (barycentric, float64)
    q = triangle_point(rng.random((count, 2))) @ v
    foot = triangle_point(rng.random((count, 2))) @ v
    u, side = directions(rng, n, count)
    u *= side[:, None]  # every start on the light's emitting side (+n)
    start = foot + (longest * 10.0 ** rng.uniform(*SHADOW_DISTANCE, count))[:, None] * u
    dist = np.linalg.norm(q - start, axis=1)
    # clearly in front: by twice the shipped offset there (as tests/render/test_hardening_precision.py)
    front = (start - v[0]) @ n > 2 * offset_distance(start, m, dist * growth + reach)
    start, q, dist = start[front], q[front], dist[front]
    kept = len(start)
    m = m[:kept]
    out, ex = {}, {}
    for var in rows:
        ext = dist * growth + reach if var.reach == "reach" else dist + longest
        end = q + offset(q, m, ext, var.origin, var.test)[:, None] * n  # as Integrator.next_event
        seg = end - start
        length = np.linalg.norm(seg, axis=1)
        out[var.key], ex[var.key] = tracer.occluded(start, seg / length[:, None], length * (1.0 - var.shorten))
    return {"rays": kept, "generated": count, "counts": out, "embreex": ex if tracer.ex is not None else None}


def run_task(task, args, width) -> dict:
    family, index, trial = task
    size, dist, orient, shape = cases()[index]
    rng = np.random.default_rng([args.seed, FAMILIES.index(family), index, trial])
    tris = triangle(rng, size, dist, orient, shape)[None]
    rec = {"family": family, "case": index, "trial": trial, "size": size, "distance": dist,
           "orientation": orient, "shape": shape}
    if args.per_case:
        rec["vertices"] = tris[0].tolist()
    geo = extents(tris)
    if geo is None:
        return {**rec, "skipped": "flat in float32 (triangle_geometry)"}
    rec.update(reach=geo[1], growth=geo[2], longest=geo[3])
    rows = [v for v in variants() if family in v.families]
    tracer = Tracer(tris, width, args.embreex)
    try:
        res = (run_new if family == "new" else run_shadow)(rng, tris, geo, args.rays, rows, tracer)
    finally:
        tracer.close()
    return {**rec, **res}


# ---------------------------------------------------------------------------
# summary and report


def summarize(records: list[dict]) -> dict:
    out = {}
    for family in FAMILIES:
        recs = [r for r in records if r["family"] == family]
        if not recs:
            continue
        done = [r for r in recs if "skipped" not in r]
        rows = [v for v in variants() if family in v.families]
        fam = {"triangles": len(recs), "skipped_flat": len(recs) - len(done),
               "rays": sum(r["rays"] for r in done), "variants": {}}
        for var in rows:
            bad = [r for r in done if r["counts"][var.key]]
            worst = sorted(bad, key=lambda r: -r["counts"][var.key])[:5]
            by = {dim: {f"{val:g}" if isinstance(val, float) else val:
                        sum(r["counts"][var.key] for r in done if r[dim] == val) for val in vals}
                  for dim, vals in DIMENSIONS}
            ex = (sum(r["embreex"][var.key] for r in done) if done and done[0]["embreex"] is not None else None)
            fam["variants"][var.key] = {
                "label": var.label, "origin_factor": var.origin, "test_factor": var.test, "reach": var.reach,
                "shorten": var.shorten, "count": sum(r["counts"][var.key] for r in done),
                "embreex_count": ex, "triangles_with_any": len(bad), "by": by,
                "worst": [{k: r[k] for k in ("case", "trial", "size", "distance", "orientation", "shape")}
                          | {"count": r["counts"][var.key], "rays": r["rays"]} for r in worst],
            }
        out[family] = fam
    return out


def _count(c: dict | None, rays: int) -> str:
    if c is None:
        return "n/a"
    k = c["count"]
    frac = f" ({k / rays:.1e})" if k and rays else ""
    return f"{k:,}{frac} in {c['triangles_with_any']}"


def markdown(report: dict, total_s: float) -> str:
    cfg, summ = report["config"], report["summary"]
    new, sh = summ.get("new"), summ.get("shadow")
    lines = ["# pyoa ray-offset stress test", "",
             f"{report['date_utc']}; CPU: {report['machine'].get('cpu')}; Embree through `pyoa.render.embree`, "
             f"{cfg['packet_width']}-wide packets; seed {cfg['seed']}; {cfg['rays']:,} rays per triangle, "
             f"{cfg['trials']['new']} (new rays) and {cfg['trials']['shadow']} (shadow rays) random triangles per "
             "case.", ""]
    if cfg["quick"]:
        lines += [f"**QUICK RUN**: {cfg['trials']['new']} trial(s) per case of new rays and {cfg['trials']['shadow']} "
                  f"of shadow rays, {cfg['rays']:,} rays each; its counts are those of a full run's first trials "
                  "(the same seeds), so they are a subset of its counts.", ""]
    lines += [
        "New rays leave random points of one triangle (alone in the scene) from the offset origin and are counted "
        "when they hit it (self-intersection); shadow rays from points in front of a light triangle (alone in the "
        "scene) to random points of it are counted when occluded (false occlusion). Each cell: rays counted "
        "(their fraction) in how many triangles. Shipped: `ORIGIN_ERROR` = "
        f"{ORIGIN_ERROR / EPS:g} x 2^-24, `TEST_ERROR` = {TEST_ERROR / EPS:g} x 2^-24.", ""]
    head = []
    if new:
        head.append(f"new rays hitting their triangle (of {new['rays']:,})")
    if sh:
        head.append(f"shadow rays occluded by their light (of {sh['rays']:,})")
    lines += ["| offsets | " + " | ".join(head) + " |", "|---|" + "---:|" * len(head)]
    for var in variants():
        cells = []
        for fam in (new, sh):
            if fam is not None:
                cells.append(_count(fam["variants"].get(var.key), fam["rays"]))
        label = f"**{var.label}**" if var.key == shipped_key() else var.label
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    lines.append("")
    for name, fam in (("New rays", new), ("Shadow rays", sh)):
        if fam is None:
            continue
        lines.append(f"{name}: {fam['triangles']:,} triangles ({fam['skipped_flat']} flat in float32, skipped), "
                     f"{fam['rays']:,} rays per variant.")
    lines.append("")
    if any(v["embreex_count"] is not None for fam in (new, sh) if fam for v in fam["variants"].values()):
        same = all(v["embreex_count"] == v["count"] for fam in (new, sh) if fam for v in fam["variants"].values())
        lines += [f"`embreex` (the NumPy shading's tracer) on the same rays: "
                  f"{'the same counts in every row' if same else 'DIFFERENT counts (see the JSON)'}.", ""]
    for name, fam in (("New rays", new), ("Shadow rays", sh)):
        if fam is None:
            continue
        keys = [k for k, v in fam["variants"].items() if v["count"]]
        if not keys:
            continue
        lines += [f"{name} counted, by the cases' attributes (the variants with any count):", "",
                  "| case | " + " | ".join(f"`{k}`" for k in keys) + " |", "|---|" + "---:|" * len(keys)]
        for dim, _vals in DIMENSIONS:
            for val in fam["variants"][keys[0]]["by"][dim]:
                lines.append(f"| {dim} {val} | "
                             + " | ".join(f"{fam['variants'][k]['by'][dim][val]:,}" for k in keys) + " |")
        lines.append("")
    lines += ["Variant keys: " + "; ".join(f"`{v.key}`: {v.label}" for v in variants()) + ".", ""]
    for name, fam in (("new rays", new), ("shadow rays", sh)):
        if fam is None:
            continue
        ship = fam["variants"][shipped_key()]
        if ship["count"]:
            lines += [f"**The shipped offsets failed** for {name}: worst triangles "
                      + "; ".join(f"size {w['size']:g} at {w['distance']:g}, {w['orientation']}, {w['shape']}: "
                                  f"{w['count']} of {w['rays']}" for w in ship["worst"]), ""]
    lines += [f"Wall time: new rays {report['seconds'].get('new', 0):.0f} s, shadow rays "
              f"{report['seconds'].get('shadow', 0):.0f} s on {cfg['threads']} threads.", ""]
    embree_line = (f"{report['embree']['library']} (the one embreex {report['embree']['embreex']} ships), "
                   f"{cfg['packet_width']}-wide packets, robust scenes")
    lines += machine_lines(report["machine"], total_s, {})
    lines += [f"- Embree: {embree_line}"]
    return "\n".join(lines) + "\n"


def _families(text: str) -> list[str]:
    items = [v.strip() for v in text.split(",") if v.strip()]
    if not items or any(v not in FAMILIES for v in items):
        raise argparse.ArgumentTypeError(f"--families takes a comma-separated subset of {','.join(FAMILIES)}")
    return items


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 epilog="See benchmarks/README.md (Ray offsets) and the comment above ORIGIN_ERROR "
                                        "in pyoa/render/integrator.py.")
    ap.add_argument("--families", type=_families, default=list(FAMILIES),
                    help="comma-separated: new (self-intersection), shadow (false occlusion); default both")
    ap.add_argument("--rays", type=int, default=None,
                    help=f"rays per triangle (default {FULL['rays']:,}, also with --quick)")
    ap.add_argument("--trials", type=int, default=None,
                    help=f"random triangles per case (default {FULL['trials']['new']} for new rays and "
                         f"{FULL['trials']['shadow']} for shadow rays; {QUICK['trials']['new']} and "
                         f"{QUICK['trials']['shadow']} with --quick)")
    ap.add_argument("--seed", type=int, default=0, help="base seed (default 0); each case's seed derives from it")
    ap.add_argument("--threads", type=int, default=None, help="worker threads (default: the usable cores)")
    ap.add_argument("--packet", type=int, choices=embree.WIDTHS, default=None,
                    help="Embree packet width (default: the renderer's, 16 with AVX-512, else 8)")
    ap.add_argument("--embreex", action="store_true", help="also trace every variant through embreex and compare")
    ap.add_argument("--quick", action="store_true",
                    help="the first trials only (about 15 s): results marked QUICK, under results/quick/")
    ap.add_argument("--out", default=None, help=f"JSON result (default {OUT.relative_to(REPO)}; "
                                                f"{QUICK_OUT.relative_to(REPO)} with --quick); Markdown beside it")
    ap.add_argument("--per-case", action="store_true",
                    help="also write every triangle's vertices and counts into the JSON (several MB)")
    ap.add_argument("--list", action="store_true", help="print the cases and variants and exit")
    args = ap.parse_args(argv)
    preset = QUICK if args.quick else FULL
    args.rays = preset["rays"] if args.rays is None else args.rays
    trials = {f: (preset["trials"][f] if args.trials is None else args.trials) for f in FAMILIES}
    if args.rays < 1 or min(trials.values()) < 1:
        ap.error("--rays and --trials must be positive")
    if args.list:
        for i, c in enumerate(cases()):
            print(i, *c)
        for v in variants():
            print(v.key, "-", v.label, "-", ",".join(v.families))
        return 0
    try:
        usable = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        usable = os.cpu_count() or 1
    args.threads = args.threads or usable
    width = args.packet or packet_width()
    out = Path(args.out) if args.out else (QUICK_OUT if args.quick else OUT)
    out.parent.mkdir(parents=True, exist_ok=True)

    t_start = time.perf_counter()
    meta = machine()
    log(f"pyoa {meta['pyoa']} (git {meta['git_commit'] or 'unknown'}) on {meta['cpu']}"
        + (" [QUICK]" if args.quick else ""))
    meta["loadavg_start"] = loadavg()
    records, seconds = [], {}
    with ThreadPoolExecutor(max_workers=args.threads) as pool:
        # compile (or load numba's cache) once before the threads start
        run_task(("new", 0, 0), argparse.Namespace(**{**vars(args), "rays": 16}), width)
        for family in args.families:
            tasks = [(family, i, k) for i in range(len(cases())) for k in range(trials[family])]
            log(f"{family}: {len(tasks)} triangles x {args.rays:,} rays")
            t0 = time.perf_counter()
            done = list(pool.map(lambda t: run_task(t, args, width), tasks))
            seconds[family] = time.perf_counter() - t0
            records += done
            fam = summarize(done)[family]
            log(f"  {seconds[family]:.1f} s, {fam['rays']:,} rays per variant: "
                + ", ".join(f"{k} {v['count']}" for k, v in fam["variants"].items()))
    meta["loadavg_end"] = loadavg()
    summary = summarize(records)
    report = {
        "date_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "machine": meta,
        "config": {"families": args.families, "rays": args.rays, "trials": trials, "seed": args.seed,
                   "threads": args.threads, "packet_width": width, "embreex": args.embreex, "quick": args.quick,
                   "sizes": SIZES, "distances": DISTANCES, "orientations": ORIENTATIONS, "shapes": SHAPES,
                   "shadow_distance_log10": SHADOW_DISTANCE, "max_position_ratio": MAX_POSITION_RATIO,
                   "origin_error": ORIGIN_ERROR, "test_error": TEST_ERROR},
        "embree": {"library": Path(embree.library_path()).name, "embreex": _version("embreex")},
        "variants": [vars(v) | {"families": list(v.families)} for v in variants()],
        "seconds": seconds,
        "summary": summary,
    }
    if args.per_case:
        report["cases"] = records
    total = time.perf_counter() - t_start
    report["total_s"] = total
    write_text(out, json.dumps(report, indent=1) + "\n")
    md = markdown(report, total)
    write_text(out.with_suffix(".md"), md)
    print(md)
    log(f"wrote {out} and {out.with_suffix('.md')}")
    failed = [f for f, fam in summary.items() if fam["variants"][shipped_key()]["count"]]
    if failed:
        log(f"the shipped offsets left wrong answers: {', '.join(failed)}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
