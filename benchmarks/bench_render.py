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

If ``mitsuba`` is importable, the same scene is rendered by Mitsuba 3's
``orthogonal`` sampler (LLVM backend) for a side-by-side figure; otherwise
the report says it was skipped.

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
import os
import statistics
import time
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))  # peers.py, shared with bench_generate.py

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


def profile_parts(scene, args) -> dict:
    """Where one render's time goes, from a separate single-threaded render of
    the same image (one thread, so the parts add up to the wall time):
    ``sampling`` (``Sampler.generate``: the OA values of each batch),
    ``intersection`` (Embree through embreex: closest hits and shadow rays),
    ``shading`` (everything else: NumPy camera rays, BSDFs, emitter sampling,
    MIS, lane bookkeeping). The timers wrap the three methods and cost
    microseconds per batch; the headline figures come from the timed runs,
    not from this one."""
    from pyoa.render.integrator import Integrator
    from pyoa.samplers import Sampler

    spent = {"sampling": 0.0, "intersection": 0.0}
    originals = []

    def wrap(cls, name, part):
        real = getattr(cls, name)
        originals.append((cls, name, real))

        def timed(*a, **kw):
            t0 = time.perf_counter()
            try:
                return real(*a, **kw)
            finally:
                spent[part] += time.perf_counter() - t0

        setattr(cls, name, timed)

    wrap(Sampler, "generate", "sampling")
    wrap(Integrator, "_intersect", "intersection")
    wrap(Integrator, "_visible", "intersection")
    try:
        w, h = args.size
        res = render(scene, sampler=args.sampler, spp=args.spp, width=w, height=h, max_depth=args.max_depth,
                     threads=1)
    finally:
        for cls, name, real in originals:
            setattr(cls, name, real)
    parts = dict(spent, shading=res.seconds - sum(spent.values()))
    return {"threads": 1, "seconds": res.seconds, "paths_per_s": res.paths_per_second,
            "rays_per_s": res.rays_per_second, "parts_s": parts,
            "shares": {k: v / res.seconds for k, v in parts.items()}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", default="cornell")
    ap.add_argument("--sampler", default="bose")
    ap.add_argument("--spp", type=int, default=121)
    ap.add_argument("--size", type=int, nargs=2, default=(256, 256))
    ap.add_argument("--max-depth", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=str(REPO / "benchmarks" / "results" / "render.json"))
    args = ap.parse_args(argv)
    scene = load(args.scene)
    w, h = args.size
    t_start = time.perf_counter()
    meta = machine()
    meta["loadavg_start"] = _loadavg()
    render(scene, sampler=args.sampler, spp=args.spp, width=16, height=16, max_depth=args.max_depth)
    runs = []
    for k in range(args.repeats):
        res = render(scene, sampler=args.sampler, spp=args.spp, width=w, height=h, max_depth=args.max_depth)
        runs.append(res)
        print(f"run {k + 1}/{args.repeats}: {res.seconds:.2f} s, {res.paths_per_second / 1e6:.3f} M paths/s, "
              f"{res.rays_per_second / 1e6:.3f} M rays/s", flush=True)
    times = [r.seconds for r in runs]
    med = statistics.median(times)
    mid = runs[times.index(med)] if med in times else runs[0]
    report = {
        "date_utc": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "machine": meta,
        "config": {"scene": args.scene, "sampler": args.sampler, "spp": args.spp, "size": [w, h],
                   "max_depth": args.max_depth, "repeats": args.repeats, "dims": mid.dims},
        "times_s": times, "median_s": med, "min_s": min(times), "max_s": max(times),
        "paths_per_s": mid.stats.paths / med, "rays_per_s": mid.stats.rays / med,
        "rays_per_path": mid.stats.rays / mid.stats.paths,
        "mitsuba": mitsuba_figure(args.scene, w, h, args.spp, args.max_depth, args.repeats),
        "profile": profile_parts(scene, args),
    }
    meta["loadavg_end"] = _loadavg()
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(out) as tmp:
        tmp.write_text(json.dumps(report, indent=2) + "\n")
    mit = report["mitsuba"]
    mline = (f"Mitsuba {mit['version']} `orthogonal` on its own `cornell_box()` (LLVM backend, "
             f"{mit.get('libllvm') or 'Dr.Jit default libLLVM'}), same size, depth and spp, median of "
             f"{len(mit['times_s'])}: {mit['paths_per_s'] / 1e6:.3f} M paths/s; "
             f"pyoa / Mitsuba = {report['paths_per_s'] / mit['paths_per_s']:.2f}"
             if mit["status"] == "ok" else f"Mitsuba: {mit['status']} ({mit['reason']})")
    md = (f"# pyoa render benchmark\n\n`{args.scene}` {w} x {h}, max depth {args.max_depth}, {args.sampler} "
          f"{args.spp} spp ({mid.dims} dims), {args.repeats} runs after a warm-up, {os.cpu_count()} CPUs, "
          f"{report['date_utc']}\n\n| median s | min s | max s | M paths/s | M rays/s | rays/path |\n"
          f"|---:|---:|---:|---:|---:|---:|\n| {med:.2f} | {min(times):.2f} | {max(times):.2f} | "
          f"{report['paths_per_s'] / 1e6:.3f} | {report['rays_per_s'] / 1e6:.3f} | {report['rays_per_path']:.2f} |\n\n"
          f"{mline}\n\n" + _profile_md(report["profile"])
          + "\n" + "\n".join(machine_lines(meta, time.perf_counter() - t_start, {})) + "\n")
    with atomic_path(out.with_suffix(".md")) as tmp:
        tmp.write_text(md)
    print(md)
    return 0


def _profile_md(prof: dict) -> str:
    rows = "".join(f"| {k} | {v:.2f} | {100 * prof['shares'][k]:.0f} % |\n" for k, v in prof["parts_s"].items())
    return (f"Where the time goes (a separate render on 1 thread: {prof['seconds']:.2f} s, "
            f"{prof['paths_per_s'] / 1e6:.3f} M paths/s):\n\n| part | s | share |\n|---|---:|---:|\n{rows}")


if __name__ == "__main__":
    sys.exit(main())
