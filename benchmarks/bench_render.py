#!/usr/bin/env python3
"""Render throughput: camera paths and rays per second on a bundled scene.

What is measured
----------------
``pyoa.render.render.render(scene, sampler=..., spp=..., width=W, height=H,
max_depth=D)`` (the function behind ``pyoa render``), once as a warm-up on a
16 x 16 image (kernel build, Embree and import costs), then ``--repeats``
timed full renders. The time covers sample generation, ray tracing and
shading, not scene loading or image writing. Reported: median, minimum and
maximum seconds; camera paths per second and rays per second (camera,
continuation and shadow rays) at the median.

Each ``--shading`` (numba: compiled shading calling Embree, the default;
numpy: the reference) is timed, with a single-threaded profile of where the
time goes. If ``mitsuba`` is importable, the same scene is rendered by
Mitsuba 3's ``orthogonal`` sampler (LLVM backend) in the same run for a
side-by-side figure; otherwise the report says it was skipped. The Embree
floor replays a small render's own rays through the shipped tracing path.

Output: ``benchmarks/results/render.json`` and ``render.md`` (``--out``),
written atomically.

Usage::

    python benchmarks/bench_render.py                       # cornell 256x256, depth 5, bose 121 spp
    python benchmarks/bench_render.py --scene dof7d --spp 121 --size 128 128
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import statistics
import sys
import time
import types
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))  # peers.py, shared with bench_generate.py

import numpy as np  # noqa: E402

import peers  # noqa: E402
from bench_generate import _loadavg, machine, machine_lines  # noqa: E402
from pyoa.atomic import atomic_path  # noqa: E402
from pyoa.render.render import render  # noqa: E402
from pyoa.render.scene import load  # noqa: E402


_MITSUBA = """
import json, statistics, sys, time
import numpy as np
import mitsuba as mi
w, h, spp, depth, repeats = map(int, sys.argv[1:6])
mi.set_variant("llvm_ad_rgb")
d = mi.cornell_box()
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


def mitsuba_figure(scene: str, width: int, height: int, spp: int, depth: int, repeats: int) -> dict:
    """Mitsuba 3's ``orthogonal`` sampler on its own ``cornell_box()``, in a
    subprocess (a Dr.Jit/LLVM failure must not take this benchmark down; ``peers.run_json_script``)."""
    if not peers.mitsuba_available():
        return {"status": "skipped", "reason": "mitsuba is not installed (pip install mitsuba)"}
    if scene != "cornell":
        return {"status": "skipped", "reason": "only the cornell scene has a Mitsuba twin"}
    res = peers.run_json_script(_MITSUBA, [width, height, spp, depth, repeats], env=peers.mitsuba_env())
    res["libllvm"] = peers.drjit_llvm()
    return res


def _wrap(cls, name, spent, part, originals):
    """Time every call of ``cls.name`` into ``spent[part]`` (microseconds of cost per batch)."""
    real = getattr(cls, name)
    originals.append((cls, name, real))

    def timed(*a, **kw):
        t0 = time.perf_counter()
        try:
            return real(*a, **kw)
        finally:
            spent[part] += time.perf_counter() - t0

    setattr(cls, name, timed)


def profile_parts(scene, args, shading: str) -> dict:
    """Where one render's time goes, from a separate single-threaded render of
    the same image (one thread, so the parts add up to the wall time).

    ``sampling`` is ``Sampler.generate`` (the OA values of each batch). With
    ``numpy`` shading, ``intersection`` is Embree through embreex (closest
    hits and shadow rays) and ``shading`` everything else (NumPy camera rays,
    BSDFs, emitter sampling, MIS, lane bookkeeping). With ``numba`` shading
    the compiled integrator times its own stages (``camera``, ``embree``:
    packets of closest hits and shadow rays, ``shading``: the compiled bounce
    and the shadow-ray contributions, ``host``: the Python between them) and
    ``other`` is the rest (per-pixel means, the batch loop). The headline
    figures come from the timed runs, not from this one."""
    from pyoa.render.integrator import Integrator
    from pyoa.samplers import Sampler

    spent = {"sampling": 0.0}
    originals = []
    _wrap(Sampler, "generate", spent, "sampling", originals)
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


def embree_floor(scene, args, size=(64, 64)) -> dict:
    """The tracing path pyoa ships (Embree packets called from numba) alone:
    the rays of a ``size`` render of the same scene, sampler, spp and depth
    are recorded, then replayed on two threads (each half of the wavefronts),
    median of 3. ``paths_per_s`` is the rate at the render's own rays per
    path: what the renderer would reach if shading, sampling and bookkeeping
    were free."""
    from concurrent.futures import ThreadPoolExecutor

    from pyoa.render import embree
    from pyoa.render.compiled import integrator as ci

    calls = []
    real_i, real_o = embree.intersect, embree.occluded

    def intersect(sc, fn, width, o, d, prim, t):
        calls.append(("hit", o.copy(), d.copy(), None))
        return real_i(sc, fn, width, o, d, prim, t)

    def occluded(sc, fn, width, o, d, dist, free):
        calls.append(("occ", o.copy(), d.copy(), dist.copy()))
        return real_o(sc, fn, width, o, d, dist, free)

    # the compiled integrator's view of the embree module, with recording queries
    ci.embree = types.SimpleNamespace(**{**vars(embree), "intersect": intersect, "occluded": occluded})
    try:
        res = render(scene, sampler=args.sampler, spp=args.spp, width=size[0], height=size[1],
                     max_depth=args.max_depth, threads=1, shading="numba")
    finally:
        ci.embree = embree
    width = ci.packet_width()
    rtc = embree.Scene(scene.triangles)
    fn_hit, fn_occ = embree.query_addresses(width)
    rays = sum(len(c[1]) for c in calls)

    def replay(part):
        for kind, o, d, dist in part:
            if kind == "hit":
                embree.intersect(rtc.handle, fn_hit, width, o, d, np.empty(len(o), np.int64), np.empty(len(o)))
            else:
                embree.occluded(rtc.handle, fn_occ, width, o, d, dist, np.empty(len(o), np.bool_))

    replay(calls[:4])  # warm
    times = []
    with ThreadPoolExecutor(2) as pool:
        for _ in range(3):
            t0 = time.perf_counter()
            list(pool.map(replay, [calls[0::2], calls[1::2]]))
            times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    rays_per_path = rays / res.stats.paths
    return {"size": list(size), "rays": rays, "packet": width, "threads": 2, "times_s": times,
            "rays_per_s": rays / med, "rays_per_path": rays_per_path, "paths_per_s": rays / med / rays_per_path}


def time_renders(scene, args, shading: str) -> dict:
    """Warm-up, then ``--repeats`` timed renders with ``shading``."""
    w, h = args.size
    render(scene, sampler=args.sampler, spp=args.spp, width=16, height=16, max_depth=args.max_depth,
           shading=shading)
    runs = []
    for k in range(args.repeats):
        res = render(scene, sampler=args.sampler, spp=args.spp, width=w, height=h, max_depth=args.max_depth,
                     shading=shading)
        runs.append(res)
        print(f"{shading} run {k + 1}/{args.repeats}: {res.seconds:.2f} s, {res.paths_per_second / 1e6:.3f} M "
              f"paths/s, {res.rays_per_second / 1e6:.3f} M rays/s", flush=True)
    times = [r.seconds for r in runs]
    med = statistics.median(times)
    mid = runs[times.index(med)] if med in times else runs[0]
    return {"shading": shading, "times_s": times, "median_s": med, "min_s": min(times), "max_s": max(times),
            "paths_per_s": mid.stats.paths / med, "rays_per_s": mid.stats.rays / med,
            "rays_per_path": mid.stats.rays / mid.stats.paths, "dims": mid.dims,
            "profile": profile_parts(scene, args, shading)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", default="cornell")
    ap.add_argument("--sampler", default="bose")
    ap.add_argument("--spp", type=int, default=121)
    ap.add_argument("--size", type=int, nargs=2, default=(256, 256))
    ap.add_argument("--max-depth", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--shading", default="numba,numpy",
                    help="comma-separated shadings to time (default numba,numpy)")
    ap.add_argument("--out", default=str(REPO / "benchmarks" / "results" / "render.json"))
    args = ap.parse_args(argv)
    shadings = [v.strip() for v in args.shading.split(",") if v.strip()]
    bad = [v for v in shadings if v not in ("numba", "numpy")]
    if bad or not shadings:
        ap.error(f"--shading takes numba and/or numpy, got {args.shading!r}")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    scene = load(args.scene)
    w, h = args.size
    t_start = time.perf_counter()
    meta = machine()
    meta["loadavg_start"] = _loadavg()
    rows = [time_renders(scene, args, sh) for sh in shadings]
    mit = mitsuba_figure(args.scene, w, h, args.spp, args.max_depth, args.repeats)
    floor = embree_floor(scene, args) if "numba" in shadings else None
    meta["loadavg_end"] = _loadavg()
    report = {
        "date_utc": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "machine": meta,
        "config": {"scene": args.scene, "sampler": args.sampler, "spp": args.spp, "size": [w, h],
                   "max_depth": args.max_depth, "repeats": args.repeats, "shadings": shadings},
        "results": rows, "mitsuba": mit, "embree_floor": floor,
    }
    with atomic_path(out) as tmp:
        tmp.write_text(json.dumps(report, indent=2) + "\n")
    md = markdown(report, time.perf_counter() - t_start)
    with atomic_path(out.with_suffix(".md")) as tmp:
        tmp.write_text(md)
    print(md)
    return 0


def markdown(report: dict, total_s: float) -> str:
    cfg, mit, floor = report["config"], report["mitsuba"], report["embree_floor"]
    w, h = cfg["size"]
    mit_rate = mit.get("paths_per_s") if mit["status"] == "ok" else None
    lines = ["# pyoa render benchmark", "",
             f"`{cfg['scene']}` {w} x {h}, max depth {cfg['max_depth']}, {cfg['sampler']} {cfg['spp']} spp "
             f"({report['results'][0]['dims']} dims), {cfg['repeats']} runs after a warm-up, all CPUs, "
             f"{report['date_utc']}. Mitsuba and the Embree floor in the same run.", "",
             "| renderer | median s | min s | max s | M paths/s | M rays/s | rays/path | / Mitsuba |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in report["results"]:
        ratio = f"{r['paths_per_s'] / mit_rate:.2f}x" if mit_rate else ""
        lines.append(f"| pyoa, {r['shading']} shading | {r['median_s']:.2f} | {r['min_s']:.2f} | {r['max_s']:.2f} | "
                     f"{r['paths_per_s'] / 1e6:.3f} | {r['rays_per_s'] / 1e6:.2f} | {r['rays_per_path']:.2f} | {ratio} |")
    if mit_rate:
        lines.append(f"| Mitsuba {mit['version']} `orthogonal` (LLVM, {mit.get('libllvm') or 'default libLLVM'}), its "
                     f"own `cornell_box()` | {mit['median_s']:.2f} | {min(mit['times_s']):.2f} | "
                     f"{max(mit['times_s']):.2f} | {mit_rate / 1e6:.3f} | | | 1.00x |")
    else:
        lines.append(f"| Mitsuba | {mit['status']}: {mit.get('reason')} | | | | | | |")
    if floor:
        numba = next((r for r in report["results"] if r["shading"] == "numba"), None)
        share = f"; the numba renderer reaches {numba['paths_per_s'] / floor['paths_per_s']:.0%} of it" if numba else ""
        ratio = f" = {floor['paths_per_s'] / mit_rate:.2f}x Mitsuba" if mit_rate else ""
        lines += ["", f"Embree floor (the rays of a {floor['size'][0]} x {floor['size'][1]} render of the same "
                      f"scene replayed through the shipped tracing path: {floor['packet']}-wide packets from numba, "
                      f"{floor['threads']} threads): {floor['rays_per_s'] / 1e6:.2f} M rays/s = "
                      f"{floor['paths_per_s'] / 1e6:.3f} M paths/s at {floor['rays_per_path']:.2f} rays/path"
                      f"{ratio}{share}."]
    for r in report["results"]:
        prof = r["profile"]
        lines += ["", f"Where the time goes, {r['shading']} shading (a separate render on 1 thread: "
                      f"{prof['seconds']:.2f} s, {prof['paths_per_s'] / 1e6:.3f} M paths/s):", "",
                  "| part | s | share |", "|---|---:|---:|"]
        lines += [f"| {k} | {v:.2f} | {100 * prof['shares'][k]:.0f} % |" for k, v in prof["parts_s"].items()]
    lines += ["", *machine_lines(report["machine"], total_s, {})]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main())
