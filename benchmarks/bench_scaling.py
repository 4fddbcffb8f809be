#!/usr/bin/env python3
"""How pyoa's throughput scales with the request's size, and how much memory it needs.

What is measured
----------------
1. Bulk generation, ``Sampler.generate``, per backend (``opencl``, ``numpy``),
   through the public API::

       smp = pyoa.sampler("bose", spp=N, dims=D, offset="cmj", seed=..., backend=B)
       smp.generate(pixels=range(P))

   along three sweeps, each point one (N, D, P):

   - ``spp``: N = 121, 361, 1369, 3721, 10201 (Bose s = 11, 19, 37, 61, 101)
     at D = 10;
   - ``dims``: D = 2, 4, 8, 16, 32, 64 at N = 121 (a Bose block holds at most
     s + 1 = 12 dimensions; further dimensions use further blocks);
   - ``pixels``: P = 1, 16, 256, 4,096, 65,536, 1,048,576 at N = 121, D = 10.

   In the ``spp`` and ``dims`` sweeps P is chosen so every call produces about
   the same number of values, ``P = round(target / (N * D))`` (target 8e7, or
   2e6 with ``--quick``). Each (point, backend) is warmed up with one
   untimed call (program build, PoCL's kernel cache, first-touch page faults);
   then ``--repeats`` rounds follow, each timing one call of every (point,
   backend) pair of the sweep in turn (interleaved, as in
   ``bench_generate.py``, so a transient slowdown of the machine is spread
   over the whole curve rather than one point). ``time.perf_counter()``
   brackets the ``generate`` call only. Reported per point: median, minimum
   and maximum seconds and values / median seconds. A point whose value count
   is over ``--max-values`` is skipped with a note (the 1,048,576-pixel point
   is 1.27e9 values, 5 GB of float32).

2. Memory, for the largest ``pixels`` point that fits the cap: in a fresh
   Python subprocess per backend (run before the sweeps), the resident set
   after import, sampler construction and a warm-up ``generate`` of one pixel
   (the baseline), then the peak resident set during the big ``generate``
   call. ``peak - baseline`` minus the output's size is the working set
   beyond the output. The peak is ``VmHWM`` of ``/proc/self/status``, reset
   to the current resident set after the warm-up (``/proc/self/clear_refs``)
   where the kernel allows, else the peak since start: not
   ``resource.getrusage(RUSAGE_SELF).ru_maxrss``, which a child inherits from
   its parent across fork and exec (a child of a 1 GB parent starts at
   1 GB); ``ru_maxrss`` values are recorded in the JSON all the same. It is
   compared with
   the bound the library states: OpenCL keeps at most one output chunk
   (256 MiB) plus one table buffer no larger than its chunk, plus small
   per-launch arrays (on PoCL, device buffers are host memory, so they count
   in the resident set); NumPy works in chunks of 2**20 values with about 20
   temporaries each (taken as 4-byte values), on up to ``os.cpu_count()``
   threads. Both bounds also get the request's own index arrays (12 bytes per
   pixel: the int64 range and its uint32 copy) and, for OpenCL, the table keys
   of one chunk (12 bytes per (pixel, dimension), counted twice for their
   host temporaries); the report lists every term.

3. Rendering: camera paths per second (``W * H * spp / seconds``) and rays per
   second of ``pyoa.render.render.render`` on the bundled ``cornell`` scene
   (Bose, 121 spp, max depth 5) against the image size 32x32, 64x64, 128x128,
   256x256, after one 16x16 warm-up render, sizes interleaved over
   ``--repeats`` rounds. ``RenderResult.seconds`` covers sample generation,
   tracing and shading, not scene loading.

Noise
-----
On the 2-core PoCL machines this project is measured on, the same workload
varies by 15-25 % from one process to the next (docs/performance.md, lessons for PoCL
item 9), and a shared host can slow single runs by up to 2x. Read the shape of
each curve within one report; treat differences under about 25 % between
separate invocations as noise; the min/max columns (and the error bars in the
figures) show the spread inside one process, and the load averages before and
after the run are in the metadata. The smallest ``pixels`` points measure
per-call overhead (validation, launch, allocation), not the kernels.

Output
------
``benchmarks/results/scaling.json`` (``--out`` to change the stem) with every
run's time and the machine's description (``common.machine()``),
``scaling.md`` beside it, and the figures ``scaling-spp.png``,
``scaling-dims.png``, ``scaling-pixels.png`` and ``render-size.png`` in
``docs/performance/`` (``--figures``). ``--quick`` divides the sizes (2e6
values per call, pixels up to 65,536, 25 spp and 8x8-64x64 images for the
render) for a smoke run of well under a minute, and writes to the uncommitted
``benchmarks/results/quick/`` and ``docs/performance/quick/`` instead. Every
file is written atomically (``pyoa.util.atomic.atomic_path``).

A full run takes several minutes on a 2-core machine (the NumPy backend's
1,048,576-pixel point alone is about 25 s per call) and needs about 6 GB of
memory; ``--max-values`` lowers the largest point, ``--sweeps`` picks parts.

Usage::

    python benchmarks/bench_scaling.py                  # every sweep, memory and render (full sizes)
    python benchmarks/bench_scaling.py --quick          # smoke run, results under .../quick/
    python benchmarks/bench_scaling.py --sweeps spp,dims --backends opencl
    python benchmarks/bench_scaling.py --max-values 1e8 # skip the points over 1e8 values
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
import warnings
from pathlib import Path

BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH))

import numpy as np  # noqa: E402

from bench_generate import (  # noqa: E402  (benchmarks/ is on sys.path above)
    BACKENDS,
    _csv,
    _digest,
    _fail,
    _line,
    _opencl_details,
    summarize,
)
from common import MEMORY_CHILD_HELPERS, loadavg, log, machine, machine_lines, write_text  # noqa: E402

try:
    import pyoa
    from pyoa.util.atomic import atomic_path
except ImportError as _exc:  # pragma: no cover - environment problem
    sys.exit(f"bench_scaling: cannot import pyoa ({_exc}); install it first: pip install -e .")

REPO = BENCH.parent
SCHEMA = 1
SAMPLER, OFFSET = "bose", "cmj"

SPP_POINTS = (121, 361, 1369, 3721, 10201)  # Bose s = 11, 19, 37, 61, 101
DIMS_POINTS = (2, 4, 8, 16, 32, 64)
PIXEL_POINTS = (1, 16, 256, 4096, 65536, 1048576)
QUICK_PIXEL_POINTS = (1, 16, 256, 4096, 65536)
BASE_SPP, BASE_DIMS = 121, 10
FULL_TARGET, QUICK_TARGET = 8e7, 2e6
#: 1.3e9 values (5.2 GB of float32) admits the full run's 1,048,576-pixel point (1.27e9).
DEFAULT_MAX_VALUES = 1.3e9

RENDER_SCENE = "cornell"
RENDER_SIZES = (32, 64, 128, 256)
QUICK_RENDER_SIZES = (8, 16, 32, 64)
RENDER_SPP, QUICK_RENDER_SPP = 121, 25
RENDER_DEPTH = 5

SWEEPS = ("spp", "dims", "pixels")
PARTS = (*SWEEPS, "memory", "render")
FIGURES = {"spp": "scaling-spp.png", "dims": "scaling-dims.png", "pixels": "scaling-pixels.png",
           "render": "render-size.png"}
MiB = 1 << 20


# ---------------------------------------------------------------------------
# generate sweeps


def sweep_points(sweep: str, target: float, quick: bool) -> list[dict]:
    """The (spp, dims, pixels) of every point of ``sweep``; ``x`` is the swept quantity."""
    def sized(n: int, d: int) -> int:
        return max(1, round(target / (n * d)))

    if sweep == "spp":
        pts = [dict(x=n, spp=n, dims=BASE_DIMS, pixels=sized(n, BASE_DIMS)) for n in SPP_POINTS]
    elif sweep == "dims":
        pts = [dict(x=d, spp=BASE_SPP, dims=d, pixels=sized(BASE_SPP, d)) for d in DIMS_POINTS]
    else:
        pts = [dict(x=p, spp=BASE_SPP, dims=BASE_DIMS, pixels=p) for p in (QUICK_PIXEL_POINTS if quick else PIXEL_POINTS)]
    for p in pts:
        p.update(sweep=sweep, values=p["spp"] * p["dims"] * p["pixels"])
    return pts


def _entry(point: dict, backend: str) -> dict:
    label = f"{point['sweep']}={point['x']}"
    return {"case": label, "sweep": point["sweep"], "x": point["x"], "backend": backend,
            "spp": point["spp"], "dims": point["dims"], "pixels": point["pixels"], "values": point["values"],
            "status": "ok", "times_s": []}


def prepare(point: dict, backend: str, seed: int, max_values: float) -> tuple[dict, object]:
    """Sampler and warm-up for one (point, backend); (entry, None) when skipped or failed."""
    entry = _entry(point, backend)
    if point["values"] > max_values:
        entry.update(status="skipped", reason=f"{point['values']:,} values is over --max-values {max_values:,.0f}")
        log(f"  {entry['case']:<22} {backend:<7} SKIPPED: {entry['reason']}")
        return entry, None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", pyoa.PyoaFallbackWarning)  # never a silent fallback
            smp = pyoa.sampler(SAMPLER, spp=point["spp"], dims=point["dims"], seed=seed, offset=OFFSET,
                               backend=backend)
    except Exception as exc:  # noqa: BLE001 - an unusable backend is reported, not fatal
        _fail(entry, "skipped", exc)
        return entry, None
    entry.update(device=smp.device, s=smp.s, block_dims=smp.block_dims)
    entry.update(_opencl_details(smp))
    try:
        t0 = time.perf_counter()
        x = smp.generate(pixels=range(point["pixels"]))
        entry["warmup_s"] = time.perf_counter() - t0
        entry["digest"] = _digest(x)
        del x
    except Exception as exc:  # noqa: BLE001 - e.g. an OpenCL runtime error, or over max_bytes
        _fail(entry, "failed", exc)
        return entry, None
    _line(entry, "warm-up", entry["warmup_s"])
    return entry, smp


def run_sweep(sweep: str, backends: list[str], args) -> list[dict]:
    """Warm up every (point, backend) of ``sweep``, then time them round-robin, ``repeats`` rounds."""
    log(f"sweep {sweep}:")
    pairs = [prepare(p, b, args.seed, args.max_values)
             for p in sweep_points(sweep, args.target_values, args.quick) for b in backends]
    for k in range(args.repeats):
        for i, (entry, smp) in enumerate(pairs):
            if smp is None:
                continue
            try:
                t0 = time.perf_counter()
                x = smp.generate(pixels=range(entry["pixels"]))
                dt = time.perf_counter() - t0
                del x  # one result array alive at a time
            except Exception as exc:  # noqa: BLE001
                _fail(entry, "failed", exc)
                pairs[i] = (entry, None)
                continue
            entry["times_s"].append(dt)
            _line(entry, f"run {k + 1}/{args.repeats}", dt)
    return [summarize(entry) for entry, _ in pairs]


# ---------------------------------------------------------------------------
# memory, in a fresh subprocess per backend

_MEMORY_CHILD = MEMORY_CHILD_HELPERS + r"""
import json, resource, sys, time, warnings
import numpy as np
import pyoa

def maxrss_kib():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss

backend, spp, dims, pixels, seed = sys.argv[1], *map(int, sys.argv[2:6])
with warnings.catch_warnings():
    warnings.simplefilter("error", pyoa.PyoaFallbackWarning)
    smp = pyoa.sampler("bose", spp=spp, dims=dims, seed=seed, offset="cmj", backend=backend)
x = smp.generate(pixels=range(1))
del x
chunk_values = None
try:
    chunk_values = int(smp._backend.rows_per_chunk(dims) * dims)  # private, read-only use
except Exception:
    pass
res = {"status": "ok", "device": smp.device, "chunk_values": chunk_values,
       "baseline_maxrss_kib": maxrss_kib(), "baseline_hwm_kib": status_kib("VmHWM"),
       "baseline_rss_kib": status_kib("VmRSS")}
res["hwm_reset"] = reset_peak()  # so the peak is the big call's own
t0 = time.perf_counter()
x = smp.generate(pixels=range(pixels))
res.update(seconds=time.perf_counter() - t0, output_bytes=int(x.nbytes), peak_maxrss_kib=maxrss_kib(),
           peak_hwm_kib=status_kib("VmHWM"), after_rss_kib=status_kib("VmRSS"))
print(json.dumps(res))
"""


def _bound(backend: str, child: dict, spp: int, dims: int, pixels: int) -> dict:
    """The library's stated memory bound for this request, term by term (bytes)."""
    index = 12 * pixels  # np.arange(..., dtype=int64).astype(uint32) of the pixel range
    cpus = os.cpu_count() or 1
    if backend == "opencl":
        chunk_values = child.get("chunk_values") or (256 * MiB) // 4
        chunk = 4 * min(chunk_values, spp * dims * pixels)
        chunk_pixels = min(pixels, chunk_values // (spp * dims) + 2)
        terms = {"output chunk buffer": chunk, "table buffer (at most one chunk)": chunk,
                 # a later block's rows per (pixel, sample position padded to 8): blocks <= dims, and the
                 # padding is below the 8 or more positions, so under twice the chunk
                 "later blocks' rows (vector_rows: under twice the chunk)": 2 * chunk,
                 "table keys of one chunk (x2 for host temporaries)": 2 * 12 * chunk_pixels * dims,
                 "request index arrays": index}
        stated = ("one output chunk (256 MiB) + one table buffer no larger than its chunk + the later blocks' "
                  "rows, under twice the chunk + small per-launch arrays")
    else:
        chunk_values = child.get("chunk_values") or (1 << 20)
        n_chunks = -(-pixels * spp // max(1, chunk_values // dims))
        threads = min(n_chunks, cpus)
        terms = {f"{threads} thread(s) x 20 temporaries x {chunk_values:,} values x 4 B": threads * 20 * chunk_values * 4,
                 "request index arrays": index}
        stated = f"chunks of 2**20 values, about 20 temporaries each, on up to os.cpu_count() = {cpus} threads"
    return {"stated": stated, "terms": terms, "bytes": sum(terms.values())}


def measure_memory(backends: list[str], args) -> list[dict]:
    pts = [p for p in sweep_points("pixels", args.target_values, args.quick) if p["values"] <= args.max_values]
    if not pts:
        log("memory: every pixels point is over --max-values; skipped")
        return [{"backend": b, "status": "skipped", "reason": "every pixels point is over --max-values"}
                for b in backends]
    p = max(pts, key=lambda q: q["values"])
    log(f"memory: {p['pixels']:,} pixels x {p['spp']} spp x {p['dims']} dims, fresh process per backend")
    out = []
    for b in backends:
        entry = {"backend": b, "spp": p["spp"], "dims": p["dims"], "pixels": p["pixels"], "values": p["values"]}
        proc = subprocess.run([sys.executable, "-c", _MEMORY_CHILD, b, str(p["spp"]), str(p["dims"]),
                               str(p["pixels"]), str(args.seed)], capture_output=True, text=True, cwd=REPO)
        if proc.returncode != 0:
            tail = (proc.stderr or proc.stdout).strip().splitlines()
            entry.update(status="failed", reason=f"exit {proc.returncode}: {tail[-1] if tail else ''}"[:300])
            log(f"  {b:<7} FAILED: {entry['reason']}")
            out.append(entry)
            continue
        child = json.loads(proc.stdout.strip().splitlines()[-1])
        entry.update(child)
        # ru_maxrss survives fork + exec: a child's value starts at its parent's
        # peak (this process's, a few GB after the pixels sweep), so the
        # per-address-space VmHWM of /proc/self/status is used, reset after the
        # warm-up where the kernel allows it. ru_maxrss is kept in the JSON.
        if child["hwm_reset"]:
            base, method = child["baseline_rss_kib"], "VmRSS after warm-up -> VmHWM after the call (HWM reset)"
        else:
            base, method = child["baseline_hwm_kib"], "VmHWM after warm-up -> VmHWM after the call"
        entry.update(baseline_kib=base, peak_kib=child["peak_hwm_kib"], method=method)
        grown = 1024 * (entry["peak_kib"] - base)
        working = grown - child["output_bytes"]
        bound = _bound(b, child, p["spp"], p["dims"], p["pixels"])
        entry.update(peak_minus_baseline_bytes=grown, working_set_bytes=working, bound=bound,
                     under_bound=working <= bound["bytes"])
        log(f"  {b:<7} baseline {base / 1024:8.1f} MiB  peak {entry['peak_kib'] / 1024:8.1f} MiB  "
             f"output {child['output_bytes'] / MiB:8.1f} MiB  working set beyond output {working / MiB:7.1f} MiB  "
             f"bound {bound['bytes'] / MiB:7.1f} MiB: {'under' if entry['under_bound'] else 'OVER'}")
        out.append(entry)
    return out


# ---------------------------------------------------------------------------
# render


def run_render(args) -> dict:
    from pyoa.render.render import render
    from pyoa.render.scene import load

    spp, sizes = args.render_spp, args.render_sizes
    log(f"render: {RENDER_SCENE}, {SAMPLER} {spp} spp, max depth {args.max_depth}, sizes {sizes}")
    info = {"scene": RENDER_SCENE, "sampler": SAMPLER, "spp": spp, "max_depth": args.max_depth,
            "backend": args.render_backend or "auto", "results": []}
    try:
        scene = load(RENDER_SCENE)
        t0 = time.perf_counter()
        warm = render(scene, sampler=SAMPLER, spp=spp, width=16, height=16, max_depth=args.max_depth,
                      backend=args.render_backend)
        info.update(warmup_s=time.perf_counter() - t0, dims=warm.dims, layout=warm.layout, status="ok")
        if args.render_backend is None:  # which backend the automatic choice picked
            auto = pyoa.sampler(SAMPLER, spp=spp, dims=warm.dims, seed=args.seed)
            info["backend"] = f"auto ({auto.backend})"
    except Exception as exc:  # noqa: BLE001 - reported, the generate sweeps still count
        info.update(status="failed", reason=f"{type(exc).__name__}: {exc}")
        log(f"  render FAILED: {info['reason']}")
        return info
    rows = [{"size": [s, s], "paths": s * s * spp, "times_s": [], "rays": None} for s in sizes]
    for k in range(args.repeats):
        for row in rows:
            w, h = row["size"]
            res = render(scene, sampler=SAMPLER, spp=spp, width=w, height=h, max_depth=args.max_depth,
                         backend=args.render_backend)
            row["times_s"].append(res.seconds)
            row["rays"] = res.stats.rays  # the same for every run (fixed seed)
            log(f"  {w}x{h:<14} run {k + 1}/{args.repeats} {res.seconds:8.3f} s "
                 f"{row['paths'] / res.seconds / 1e6:9.3f} M paths/s")
    for row in rows:
        t = row["times_s"]
        med = statistics.median(t)
        row.update(median_s=med, min_s=min(t), max_s=max(t), paths_per_s=row["paths"] / med,
                   rays_per_s=row["rays"] / med, rays_per_path=row["rays"] / row["paths"])
    info["results"] = rows
    return info


# ---------------------------------------------------------------------------
# figures


def _save(fig, path: Path) -> None:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
        umask = os.umask(0)
        os.umask(umask)
        tmp.chmod(0o666 & ~umask)


def figures(report: dict, outdir: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    quick = " [QUICK]" if report["config"]["quick"] else ""
    host = f"{report['machine']['cpu_count']} CPUs, {report['machine']['date_utc'][:10]}"
    written = []
    xlabel = {"spp": "samples per pixel N (D = 10, ~equal values per call)",
              "dims": "dimensions D (N = 121, ~equal values per call)",
              "pixels": "pixels P per call (N = 121, D = 10)"}
    for sweep in SWEEPS:
        rows = [r for r in report["sweeps"].get(sweep, []) if "median_s" in r]
        if not rows:
            continue
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        for backend in report["config"]["backends"]:
            rs = sorted((r for r in rows if r["backend"] == backend), key=lambda r: r["x"])
            if not rs:
                continue
            xs = [r["x"] for r in rs]
            ys = np.array([r["median_values_per_s"] / 1e6 for r in rs])
            lo = ys - np.array([r["values"] / r["max_s"] / 1e6 for r in rs])
            hi = np.array([r["values"] / r["min_s"] / 1e6 for r in rs]) - ys
            device = rs[0]["device"].split(" on ")[0]  # "pthread-AMD EPYC (cpu)", "NumPy 2.4.6"
            ax.errorbar(xs, ys, yerr=[lo, hi], marker="o", capsize=3, label=f"{backend}: {device}"[:50])
        ax.set_xscale("log")
        if sweep == "pixels":
            ax.set_yscale("log")
        else:
            ax.set_ylim(bottom=0)
        xs_all = sorted({r["x"] for r in rows})
        ax.set_xticks(xs_all)
        ax.set_xticklabels([f"{x:,}" for x in xs_all], rotation=30 if sweep == "pixels" else 0)
        ax.minorticks_off()
        ax.set_xlabel(xlabel[sweep])
        ax.set_ylabel("M values/s (median; bars: min-max)")
        ax.set_title(f"pyoa generate: bose cmj, throughput vs {sweep}{quick}\n{host}", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        path = outdir / FIGURES[sweep]
        _save(fig, path)
        plt.close(fig)
        written.append(path)
    rnd = report.get("render") or {}
    rows = rnd.get("results") or []
    if rows:
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        xs = [r["size"][0] * r["size"][1] for r in rows]
        ys = np.array([r["paths_per_s"] / 1e6 for r in rows])
        lo = ys - np.array([r["paths"] / r["max_s"] / 1e6 for r in rows])
        hi = np.array([r["paths"] / r["min_s"] / 1e6 for r in rows]) - ys
        ax.errorbar(xs, ys, yerr=[lo, hi], marker="o", capsize=3,
                    label=f"{rnd['sampler']} {rnd['spp']} spp, backend {rnd['backend']}")
        ax.set_xscale("log")
        ax.set_xticks(xs)
        ax.set_xticklabels([f"{r['size'][0]}x{r['size'][1]}" for r in rows])
        ax.minorticks_off()
        ax.set_ylim(bottom=0)
        ax.set_xlabel("image size")
        ax.set_ylabel("M camera paths/s (median; bars: min-max)")
        ax.set_title(f"pyoa render: {rnd['scene']}, max depth {rnd['max_depth']}{quick}\n{host}", fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        path = outdir / FIGURES["render"]
        _save(fig, path)
        plt.close(fig)
        written.append(path)
    return written


# ---------------------------------------------------------------------------
# report


def markdown(report: dict) -> str:
    cfg, meta = report["config"], report["machine"]
    lines = ["# pyoa scaling benchmark", ""]
    if cfg["quick"]:
        lines += [f"**QUICK RUN** (about {cfg['target_values']:,.0f} values per call, pixels up to "
                  f"{max(QUICK_PIXEL_POINTS):,}, render {cfg['render_spp']} spp): a smoke test, not comparable "
                  "with a full run.", ""]
    lines += [
        f"`pyoa.sampler(\"{SAMPLER}\", spp=N, dims=D, offset=\"{OFFSET}\", seed={cfg['seed']}, backend=B)"
        f".generate(pixels=range(P))`: median of {cfg['repeats']} timed calls after one warm-up, the points "
        "and backends of a sweep interleaved; M values/s = values / median seconds. Process-to-process noise "
        "on this machine kind is 15-25 %: read the shape of a curve, not single figures.",
    ]
    heads = {"spp": "N", "dims": "D", "pixels": "P"}
    bold = {"spp": 0, "dims": 1, "pixels": 2}
    for sweep in SWEEPS:
        rows = report["sweeps"].get(sweep)
        if not rows:
            continue
        lines += ["", f"## Throughput vs {sweep}", "",
                  "| backend | N | D | P | values | median s | min s | max s | M values/s |",
                  "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
        for r in rows:
            cells = [f"{r['spp']:,}", f"{r['dims']}", f"{r['pixels']:,}"]
            cells[bold[sweep]] = f"**{cells[bold[sweep]]}**"  # the swept quantity
            head = f"| {r['backend']} | {' | '.join(cells)} | {r['values']:,} |"
            if "median_s" in r:
                lines.append(f"{head} {r['median_s']:.4f} | {r['min_s']:.4f} | {r['max_s']:.4f} | "
                             f"{r['median_values_per_s'] / 1e6:,.1f} |")
            else:
                lines.append(f"{head} {r['status']} | | | |")
        notes = [f"- {r['case']} / {r['backend']}: {r['status']}: {r['reason']}" for r in rows if r["status"] != "ok"]
        for x, same in report["bits_match"].get(sweep, {}).items():
            if not same:
                notes.append(f"- {heads[sweep]} = {x}: the backends gave DIFFERENT bits")
        if notes:
            lines += ["", *notes]
    mem = report.get("memory")
    if mem:
        lines += ["", "## Memory", "",
                  "Fresh process per backend; baseline = resident set after import and a one-pixel warm-up; "
                  "peak = peak resident set of the process during one big `generate` (`VmHWM`); working set = "
                  "peak - baseline - output. (`ru_maxrss` is in the JSON too, but a child inherits its "
                  "parent's value across fork and exec, so it is not used.)",
                  "", "| backend | P | output MiB | baseline MiB | peak MiB | peak - baseline MiB | "
                  "working set MiB | bound MiB | under bound |",
                  "|---|---:|---:|---:|---:|---:|---:|---:|---|"]
        for m in mem:
            if m.get("status") != "ok":
                lines.append(f"| {m['backend']} | {m.get('pixels', '')} | {m['status']}: {m.get('reason', '')} "
                             "| | | | | | |")
                continue
            lines.append(
                f"| {m['backend']} | {m['pixels']:,} | {m['output_bytes'] / MiB:,.1f} | {m['baseline_kib'] / 1024:,.1f} | "
                f"{m['peak_kib'] / 1024:,.1f} | {m['peak_minus_baseline_bytes'] / MiB:,.1f} | "
                f"{m['working_set_bytes'] / MiB:,.1f} | {m['bound']['bytes'] / MiB:,.1f} | "
                f"{'yes' if m['under_bound'] else '**NO**'} |")
        lines.append("")
        for m in mem:
            if m.get("status") == "ok":
                terms = "; ".join(f"{k} {v / MiB:,.1f} MiB" for k, v in m["bound"]["terms"].items())
                lines.append(f"- {m['backend']} bound (stated: {m['bound']['stated']}): {terms}")
    rnd = report.get("render")
    if rnd:
        lines += ["", "## Render throughput vs image size", ""]
        if rnd.get("status") != "ok":
            lines.append(f"render {rnd.get('status')}: {rnd.get('reason')}")
        else:
            lines += [f"`pyoa.render.render.render`, scene `{rnd['scene']}`, {rnd['sampler']} {rnd['spp']} spp "
                      f"({rnd['dims']} dims), max depth {rnd['max_depth']}, backend {rnd['backend']}; median of "
                      f"{cfg['repeats']} renders after a 16x16 warm-up; paths = W x H x spp.", "",
                      "| size | paths | median s | min s | max s | M paths/s | M rays/s | rays/path |",
                      "|---|---:|---:|---:|---:|---:|---:|---:|"]
            for r in rnd["results"]:
                lines.append(f"| {r['size'][0]}x{r['size'][1]} | {r['paths']:,} | {r['median_s']:.3f} | "
                             f"{r['min_s']:.3f} | {r['max_s']:.3f} | {r['paths_per_s'] / 1e6:.3f} | "
                             f"{r['rays_per_s'] / 1e6:.3f} | {r['rays_per_path']:.2f} |")
    devices = {}
    for rows in report["sweeps"].values():
        for r in rows:
            if r.get("device"):
                devices.setdefault(r["backend"], r["device"])
    lines += ["", *machine_lines(meta, report["total_s"], devices)]
    if report.get("figures"):
        lines.append("- figures: " + ", ".join(f"`{p}`" for p in report["figures"]))
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------
# command line


def _positive_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not v > 0 or v != v or v == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive finite number, got {text!r}")
    return v


def _sizes(text: str) -> list[int]:
    try:
        out = [int(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"image sizes must be comma-separated integers, got {text!r}") from None
    if not out or any(s < 1 for s in out):
        raise argparse.ArgumentTypeError(f"image sizes must be positive, got {text!r}")
    return out


def parse_args(argv=None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description="Plot how pyoa's generate and render throughput scale, "
                                             "and measure generate's memory working set.")
    ap.add_argument("--quick", action="store_true",
                    help=f"smoke run: ~{QUICK_TARGET:.0e} values per call, pixels up to {max(QUICK_PIXEL_POINTS):,}, "
                         f"render {QUICK_RENDER_SPP} spp at {','.join(map(str, QUICK_RENDER_SIZES))} px; "
                         "results go to benchmarks/results/quick/ and docs/performance/quick/")
    ap.add_argument("--sweeps", type=_csv(PARTS, "sweep", extra={"all": PARTS}), default="all",
                    help=f"comma-separated parts to run: {', '.join(PARTS)} or all (default: all)")
    ap.add_argument("--backends", type=_csv(BACKENDS, "backend"), default=",".join(BACKENDS),
                    help="comma-separated generate backends (default: opencl,numpy)")
    ap.add_argument("--repeats", type=int, default=3, help="timed runs per point after the warm-up (default: 3)")
    ap.add_argument("--target-values", type=_positive_float, default=None,
                    help=f"values per call in the spp and dims sweeps (default: {FULL_TARGET:.0e}; "
                         f"{QUICK_TARGET:.0e} with --quick)")
    ap.add_argument("--max-values", type=_positive_float, default=DEFAULT_MAX_VALUES,
                    help=f"skip (with a note) any point over this many values (default: {DEFAULT_MAX_VALUES:.2g})")
    ap.add_argument("--render-spp", type=int, default=None,
                    help=f"render samples per pixel, a valid Bose count (default: {RENDER_SPP}; "
                         f"{QUICK_RENDER_SPP} with --quick)")
    ap.add_argument("--render-sizes", type=_sizes, default=None,
                    help="comma-separated square image sizes (default: "
                         f"{','.join(map(str, RENDER_SIZES))}; {','.join(map(str, QUICK_RENDER_SIZES))} with --quick)")
    ap.add_argument("--render-backend", choices=BACKENDS, default=None,
                    help="sampler backend of the render (default: pyoa's automatic choice)")
    ap.add_argument("--max-depth", type=int, default=RENDER_DEPTH, help=f"render path length (default: {RENDER_DEPTH})")
    ap.add_argument("--seed", type=int, default=0, help="sampler seed (default: 0)")
    ap.add_argument("--out", type=Path, default=None,
                    help="JSON result path; the Markdown goes beside it with suffix .md (default: "
                         "benchmarks/results/scaling.json, or benchmarks/results/quick/scaling.json with --quick)")
    ap.add_argument("--figures", type=Path, default=None,
                    help="folder for the PNG figures (default: docs/performance, or docs/performance/quick "
                         "with --quick); created if missing")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error("--repeats must be at least 1")
    if args.max_depth < 1:
        ap.error("--max-depth must be at least 1")
    if not 0 <= args.seed < 2**32:
        ap.error("--seed must be in [0, 2**32)")
    if args.target_values is None:
        args.target_values = QUICK_TARGET if args.quick else FULL_TARGET
    if args.render_spp is None:
        args.render_spp = QUICK_RENDER_SPP if args.quick else RENDER_SPP
    if "render" in args.sweeps:
        near = [c.spp for c in pyoa.valid_spp(SAMPLER, near=args.render_spp)]
        if args.render_spp not in near:
            ap.error(f"--render-spp {args.render_spp} is not a valid {SAMPLER} sample count; "
                     f"nearest: {', '.join(map(str, near))}")
    if args.render_sizes is None:
        args.render_sizes = list(QUICK_RENDER_SIZES if args.quick else RENDER_SIZES)
    sub = "quick" if args.quick else ""
    if args.out is None:
        args.out = REPO / "benchmarks" / "results" / sub / "scaling.json"
    if args.figures is None:
        args.figures = REPO / "docs" / "performance" / sub
    if args.out.suffix != ".json":
        ap.error(f"--out must end in .json, got {str(args.out)!r}")
    return args


def main(argv=None) -> int:
    args = parse_args(argv)
    out_json, out_md = args.out, args.out.with_suffix(".md")
    out_json.parent.mkdir(parents=True, exist_ok=True)
    args.figures.mkdir(parents=True, exist_ok=True)

    t_start = time.perf_counter()
    meta = machine()
    log(f"pyoa {meta['pyoa']} (git {meta['git_commit'] or 'unknown'}) on {meta['cpu_model']}, "
         f"{meta['cpu_count']} cores; parts {','.join(args.sweeps)}, {args.repeats} repeats"
         + (" [QUICK]" if args.quick else ""))
    load_start = loadavg()
    # memory first: the children then start from a small parent (see measure_memory)
    memory = measure_memory(args.backends, args) if "memory" in args.sweeps else None
    sweeps = {s: run_sweep(s, args.backends, args) for s in SWEEPS if s in args.sweeps}
    rnd = run_render(args) if "render" in args.sweeps else None
    meta["loadavg_start"], meta["loadavg_end"] = load_start, loadavg()

    bits_match = {}
    for s, rows in sweeps.items():
        by_x: dict[int, list[str]] = {}
        for r in rows:
            if r.get("digest"):
                by_x.setdefault(r["x"], []).append(r["digest"])
        bits_match[s] = {x: len(set(d)) == 1 for x, d in by_x.items() if len(d) > 1}

    report = {
        "schema": SCHEMA,
        "benchmark": "pyoa scaling: generate throughput vs spp, dims and pixels; memory; render vs image size",
        "method": f"median of {args.repeats} timed calls after one warm-up; time.perf_counter around the call "
                  "only; the points and backends of a sweep interleaved round-robin; memory from VmHWM "
                  "(peak resident set) in a fresh subprocess per backend",
        "config": {"quick": args.quick, "parts": args.sweeps, "backends": args.backends, "repeats": args.repeats,
                   "seed": args.seed, "sampler": SAMPLER, "offset": OFFSET, "target_values": args.target_values,
                   "max_values": args.max_values, "render_spp": args.render_spp,
                   "render_sizes": args.render_sizes, "render_backend": args.render_backend,
                   "max_depth": args.max_depth},
        "machine": meta,
        "sweeps": sweeps,
        "bits_match": bits_match,
        "memory": memory,
        "render": rnd,
    }
    report["total_s"] = time.perf_counter() - t_start
    written = figures(report, args.figures)
    report["figures"] = [str(p.relative_to(REPO)) if p.is_relative_to(REPO) else str(p) for p in written]
    md = markdown(report)
    write_text(out_json, json.dumps(report, indent=2) + "\n")
    write_text(out_md, md)
    print()
    print(md, end="")
    print(f"\nwrote {out_json}, {out_md} and {len(written)} figure(s) in {args.figures} "
          f"({report['total_s']:.0f} s)")
    ok = any(r["status"] == "ok" for rows in sweeps.values() for r in rows) or bool(rnd and rnd.get("status") == "ok")
    ok = ok or any(m.get("status") == "ok" for m in memory or [])
    mismatch = any(not same for per in bits_match.values() for same in per.values())
    return 0 if ok and not mismatch else 1


if __name__ == "__main__":
    sys.exit(main())
