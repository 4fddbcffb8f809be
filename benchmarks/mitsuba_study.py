#!/usr/bin/env python3
"""pyoa inside Mitsuba 3: the ``pyoa`` sampler plugin (``pyoa/mitsuba.py``)
against Mitsuba's own samplers, in Mitsuba's own renderer.

Parts, each written to ``docs/results/mitsuba/``:

1. ``speed``: Mitsuba's Cornell box (``mi.cornell_box()``, 256 x 256, ``path``
   integrator, max depth 5, 121 spp, ``llvm_ad_rgb``) with Mitsuba's
   ``orthogonal``, ``independent`` and ``multijitter`` and pyoa's ``bose``
   and ``faure``. Each scene is loaded once and rendered once to warm up
   (the first render of a configuration compiles its kernels), then
   ``--rounds`` interleaved rounds time ``mi.render(scene, seed=round)``
   (evaluated and synchronized) with ``time.perf_counter``; odd rounds run the
   samplers in reverse order. Every render is made twice per round: with the
   seed as a Python int, as the call is usually written, and as an opaque
   ``mi.UInt32`` (``dr.opaque``). Mitsuba's samplers make the seed opaque
   themselves, and so does the pyoa plugin since commit 844f5aa; before it,
   an int seed stayed a literal and each new seed traced a new kernel that
   Dr.Jit compiled (or loaded from its disk cache) inside the timed render.
   Dr.Jit's kernel history records, per render, how many kernels were
   compiled or loaded and the compile time, so a regression shows.
   ``speed.json``, ``speed.md``.
2. ``errors``: relMSE, the mean over pixels and channels of
   ``(img - ref)^2 / (ref^2 + 0.01)``, at about 121 spp against an
   ``independent`` reference (16384 spp, other seeds, cached as EXR in the
   output folder, so a rerun skips it), over ``--seeds`` seeds, on three
   128 x 128 scenes: ``cornell`` (as above) and ``cornell-dof`` (the same box
   seen through a ``thinlens`` camera at the same position and field of view,
   aperture radius 0.25, focused at 4.1 on the tall box: the back wall and
   the front of the room are blurred), and ``cornell-glossy`` (``cornell-dof``
   with the floor and both boxes in GGX ``roughplastic``: each bounce off
   them samples a lobe and a direction from three consecutive dimensions,
   where strength 3 should matter). Mitsuba's ``independent``,
   ``multijitter``, ``orthogonal``, ``stratified`` (121 spp) and ``ldsampler``
   (it accepts only 4^k: 64 and 256, both rendered), pyoa's ``bose`` (121),
   ``bush`` strength 3 (125), ``faure`` (121) and ``random`` (121).
   ``errors.csv`` (every render), ``errors.json``, ``errors.md``.
3. ``integrand``: ``pyoa.analysis.lagged_pairs`` (dimensions L apart coupled,
   L = 6 and 12: the same column of the next block for ``bush`` t=3 and
   ``bose``) estimated by pyoa's own samplers over 512 pixels, the OA samplers
   also with the old block rule (every block read at row i, rebuilt from the
   same values). ``integrand.json``, ``integrand.md``.
4. ``figure``: ``samplers.png``, seed 0 of ``cornell-dof`` with Mitsuba's
   ``independent``, ``multijitter``, ``orthogonal`` and pyoa's ``bose``,
   ``bush`` and ``faure``, with the reference.
5. ``section``: the speed, errors and integrand markdown into
   ``docs/results.md``'s marked section ``mitsuba-study``, and a "Mitsuba
   plugin" paragraph into ``docs/performance.md``'s ``mitsuba-plugin``
   (``benchmarks/marked.py``; ``benchmarks/update_docs.py`` writes both
   again from the saved files, and ``benchmarks/make_results.py``, which
   rewrites the rest of the results page, keeps the first).

Dr.Jit's LLVM backend needs an LLVM >= 16 (Debian's ``libllvm19``): the
environment is set as ``benchmarks/peers.py`` sets it, before Mitsuba is
imported. ``--quick`` runs small versions of every part (speed at 128 x 128,
2 rounds, 2 seeds, a 1024-spp reference) under ``docs/results/quick/mitsuba/``
(git-ignored) and never touches ``docs/results.md`` or ``docs/performance.md``.

Usage::

    python benchmarks/mitsuba_study.py                        # everything
    python benchmarks/mitsuba_study.py --quick                # smoke run
    python benchmarks/mitsuba_study.py --parts errors,figure  # some parts
    python benchmarks/mitsuba_study.py --parts section        # the pages from the saved parts
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))

import peers
import figures
from common import write_csv, write_text

from pyoa.util.atomic import atomic_path

OUT = REPO / "docs" / "results" / "mitsuba"
#: The marked sections this study writes: in docs/results.md, and in docs/performance.md.
SECTION, PERF_SECTION = "mitsuba-study", "mitsuba-plugin"
PARTS = ("speed", "errors", "integrand", "figure", "section")
VARIANT = "llvm_ad_rgb"
MAX_DEPTH = 5
#: The thin-lens camera of ``cornell-dof``: the camera sits at z = 3.9 looking down -z; the tall
#: box's centre is at z = -0.28 (distance 4.18), its front edge at about 3.8, the back wall at 4.9.
APERTURE_RADIUS = 0.25
FOCUS_DISTANCE = 4.1
#: ``cornell-glossy``: ``cornell-dof``'s camera, and the floor and both boxes in ``roughplastic`` of this
#: GGX roughness (the white walls' diffuse colour under a glossy coat): every bounce off them samples a
#: two-lobe BSDF with one 1D and one 2D number, a triple of consecutive dimensions.
GLOSSY_ALPHA = 0.2
SCENES = ("cornell", "cornell-dof", "cornell-glossy")
#: The ``integrand`` part: ``pyoa.analysis.lagged_pairs`` with lag L in ``d = 2 L`` dimensions (it
#: couples each dimension with the one L later: the same column of the next block for a sampler with
#: L columns per block), estimated by each sampler over INTEGRAND_TRIALS pixels.
INTEGRAND_LAGS = (6, 12)
INTEGRAND_TRIALS = 512
INTEGRAND_SAMPLERS = {"random": dict(spp=121), "jittered2d": dict(spp=121), "cmj2d": dict(spp=121),
                      "sobol": dict(spp=128), "faure": dict(spp=121), "bose": dict(spp=121),
                      "bush": dict(spp=125, strength=3)}
#: Reference renders: Mitsuba ``independent``, in chunks of this many spp (one render each, seeds
#: REF_SEED + k), averaged.
REF_CHUNK = 1024
REF_SEED = 1_000_000
WARMUP_SEED = 999_999

#: label -> sampler dict of the scene.
SAMPLERS = {
    "mitsuba independent": {"type": "independent", "sample_count": 121},
    "mitsuba multijitter": {"type": "multijitter", "sample_count": 121},
    "mitsuba orthogonal": {"type": "orthogonal", "sample_count": 121},
    "mitsuba stratified": {"type": "stratified", "sample_count": 121},
    "mitsuba ldsampler 64": {"type": "ldsampler", "sample_count": 64},
    "mitsuba ldsampler 256": {"type": "ldsampler", "sample_count": 256},
    "pyoa bose": {"type": "pyoa", "sampler": "bose", "sample_count": 121},
    "pyoa bush t=3": {"type": "pyoa", "sampler": "bush", "sample_count": 125, "strength": 3},
    "pyoa faure": {"type": "pyoa", "sampler": "faure", "sample_count": 121},
    "pyoa random": {"type": "pyoa", "sampler": "random", "sample_count": 121},
}
SPEED_SAMPLERS = ("mitsuba orthogonal", "pyoa bose", "mitsuba independent", "mitsuba multijitter", "pyoa faure")
ERROR_SAMPLERS = tuple(SAMPLERS)
FIGURE_SAMPLERS = ("mitsuba independent", "mitsuba multijitter", "mitsuba orthogonal",
                   "pyoa bose", "pyoa bush t=3", "pyoa faure")
FIGURE_SCENE = "cornell-dof"
SPEED_GOAL = 1.0  # issue 49: at least Mitsuba's own orthogonal sampler

mi = dr = None  # set by load_mitsuba()
#: Seed-0 renders of the errors part, (scene, label) -> image, reused by the figure.
IMAGES: dict[tuple[str, str], np.ndarray] = {}


# ---------------------------------------------------------------------------
# helpers


def say(*args) -> None:
    print(*args, flush=True)




def write_json(path: Path, obj) -> None:
    write_text(path, json.dumps(obj, indent=1) + "\n")


def cpu_info() -> dict:
    """lscpu's model name, family and model (the benchmarks' way of naming a CPU)."""
    info = {"model_name": None, "family": None, "model": None, "cores": os.cpu_count()}
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, timeout=10,
                             env=dict(os.environ, LC_ALL="C"), check=False).stdout
    except (OSError, subprocess.SubprocessError):
        out = ""
    for line in out.splitlines():
        key, _, value = line.partition(":")
        key, value = key.strip(), value.strip()
        if key == "Model name":
            info["model_name"] = value
        elif key == "CPU family":
            info["family"] = value
        elif key == "Model":
            info["model"] = value
    try:
        from pyoa.util.hostcpu import host_cpu

        info["isa"] = host_cpu().isa
    except Exception:  # noqa: BLE001 - only a label
        info["isa"] = None
    return info


def cpu_text(cpu: dict) -> str:
    isa = f", {cpu['isa']}" if cpu.get("isa") else ""
    return (f"{cpu['model_name'] or 'unknown CPU'} (lscpu CPU family {cpu['family']}, model {cpu['model']}{isa}), "
            f"{cpu['cores']} cores")


def load_mitsuba():
    """Import Mitsuba and Dr.Jit with the LLVM that can compile Mitsuba's kernels; set the variant
    and register the pyoa plugin."""
    global mi, dr
    if mi is not None:
        return
    os.environ.update(peers.mitsuba_env())
    import drjit
    import mitsuba

    mitsuba.set_variant(VARIANT)
    import pyoa.mitsuba  # noqa: F401  (registers the "pyoa" sampler type)

    mi, dr = mitsuba, drjit


def versions() -> dict:
    return {"mitsuba": mi.__version__, "drjit": dr.__version__, "variant": VARIANT,
            "libllvm": os.environ.get("DRJIT_LIBLLVM_PATH"), "drjit_threads": dr.thread_count()}


def machine(cpu: dict) -> dict:
    return {"cpu": cpu, **versions(), "loadavg": list(os.getloadavg()),
            "date": time.strftime("%Y-%m-%d %H:%M:%S %Z")}


def scene_dict(scene: str, size: int, sampler: dict) -> dict:
    """Mitsuba's Cornell box at ``size`` x ``size`` with ``sampler``, path tracing to depth 5; for
    ``cornell-dof`` seen through a thin lens at the same position and field of view."""
    d = mi.cornell_box()
    if scene in ("cornell-dof", "cornell-glossy"):
        s = d["sensor"]
        d["sensor"] = {"type": "thinlens", "fov": s["fov"], "fov_axis": s["fov_axis"], "to_world": s["to_world"],
                       "near_clip": s["near_clip"], "far_clip": s["far_clip"],
                       "aperture_radius": APERTURE_RADIUS, "focus_distance": FOCUS_DISTANCE, "film": s["film"]}
    elif scene != "cornell":
        raise ValueError(f"unknown scene {scene!r}")
    if scene == "cornell-glossy":
        for shape in ("floor", "small-box", "large-box"):
            d[shape]["bsdf"] = {"type": "roughplastic", "distribution": "ggx", "alpha": GLOSSY_ALPHA,
                                "diffuse_reflectance": d["white"]["reflectance"]}
    d["sensor"]["film"]["width"] = d["sensor"]["film"]["height"] = size
    d["sensor"]["sampler"] = dict(sampler)
    d["integrator"] = {"type": "path", "max_depth": MAX_DEPTH}
    return d


def load_scene(scene: str, size: int, sampler: dict):
    sc = mi.load_dict(scene_dict(scene, size, sampler))
    return sc, int(sc.sensors()[0].sampler().sample_count())


def kernel_stats() -> dict:
    """Dr.Jit's kernel history since the last call (which it clears): kernels compiled, loaded from
    the disk cache, found in memory, and the compile time (ms)."""
    hist = [k for k in dr.kernel_history() if k.get("type") == dr.KernelType.JIT]
    compiled = sum(1 for k in hist if not k.get("cache_hit"))
    disk = sum(1 for k in hist if k.get("cache_hit") and k.get("cache_disk"))
    ms = sum(k.get("codegen_time", 0.0) + (k.get("backend_time", 0.0) if not k.get("cache_hit") else 0.0)
             for k in hist)
    return {"kernels": len(hist), "compiled": compiled, "disk_cache": disk,
            "memory_cache": len(hist) - compiled - disk, "compile_ms": round(ms, 1)}


def render(scene, seed: int, *, opaque: bool = False) -> tuple[np.ndarray, float, dict]:
    """One timed render: ``mi.render(scene, seed=...)``, evaluated and synchronized."""
    dr.kernel_history()  # clear
    s = dr.opaque(mi.UInt32, seed) if opaque else seed
    t0 = time.perf_counter()
    img = mi.render(scene, seed=s)
    dr.eval(img)
    dr.sync_thread()
    dt = time.perf_counter() - t0
    return img, dt, kernel_stats()


def relmse(img: np.ndarray, ref: np.ndarray) -> float:
    return float(np.mean((img.astype(np.float64) - ref) ** 2 / (ref.astype(np.float64) ** 2 + 0.01)))


def t_halfwidth(values: list[float]) -> float:
    """95 % Student-t half-width of the mean."""
    n = len(values)
    if n < 2:
        return float("nan")
    from scipy.stats import t

    return float(t.ppf(0.975, n - 1) * statistics.stdev(values) / math.sqrt(n))


def fmt_sci(x: float) -> str:
    return f"{x:.3e}" if math.isfinite(x) else "n/a"


# ---------------------------------------------------------------------------
# speed


def part_speed(args, cpu: dict) -> dict:
    t_part = time.perf_counter()
    load0 = os.getloadavg()[0]
    size = args.speed_size
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    scenes, spps = {}, {}
    for label in SPEED_SAMPLERS:
        scenes[label], spps[label] = load_scene("cornell", size, SAMPLERS[label])
    warm = {}
    for label in SPEED_SAMPLERS:
        for opaque in (False, True):
            _, dt, ks = render(scenes[label], WARMUP_SEED, opaque=opaque)
            warm[f"{label} {'opaque' if opaque else 'int'}"] = {"seconds": dt, **ks}
            say(f"speed warm-up {label:22s} seed {'opaque' if opaque else 'int   '}: {dt:6.2f} s "
                f"(kernels compiled {ks['compiled']}, {ks['compile_ms']:.0f} ms)")
    items = [(label, opaque) for label in SPEED_SAMPLERS for opaque in (False, True)]
    rows = []
    for r in range(args.rounds):
        for label, opaque in (items if r % 2 == 0 else items[::-1]):
            _, dt, ks = render(scenes[label], r, opaque=opaque)
            paths = size * size * spps[label]
            row = {"round": r, "sampler": label, "seed": "opaque" if opaque else "int", "spp": spps[label],
                   "seconds": round(dt, 4), "mpaths_per_s": round(paths / dt / 1e6, 4), **ks}
            rows.append(row)
            say(f"speed round {r + 1}/{args.rounds} {label:22s} seed {row['seed']:6s}: {dt:6.2f} s, "
                f"{row['mpaths_per_s']:.3f} M paths/s (kernels compiled {ks['compiled']}, disk cache "
                f"{ks['disk_cache']}, {ks['compile_ms']:.0f} ms)")
    summary = {}
    for label in SPEED_SAMPLERS:
        for mode in ("int", "opaque"):
            rs = [x for x in rows if x["sampler"] == label and x["seed"] == mode]
            rates = [x["mpaths_per_s"] for x in rs]
            summary[f"{label}|{mode}"] = {
                "sampler": label, "seed": mode, "spp": spps[label], "median": statistics.median(rates),
                "min": min(rates), "max": max(rates),
                "median_seconds": statistics.median(x["seconds"] for x in rs),
                "compiled_per_render": statistics.mean(x["compiled"] for x in rs),
                "disk_cache_per_render": statistics.mean(x["disk_cache"] for x in rs),
                "compile_ms_median": statistics.median(x["compile_ms"] for x in rs)}
    ratios = {}
    for mode in ("int", "opaque"):
        per_round = []
        for r in range(args.rounds):
            rate = {x["sampler"]: x["mpaths_per_s"] for x in rows if x["round"] == r and x["seed"] == mode}
            per_round.append(rate["pyoa bose"] / rate["mitsuba orthogonal"])
        ratios[mode] = {"per_round": [round(x, 4) for x in per_round], "median": statistics.median(per_round),
                        "min": min(per_round), "max": max(per_round)}
    res = {"machine": machine(cpu), "scene": "cornell", "size": size, "max_depth": MAX_DEPTH,
           "paths_per_render": {k: size * size * v for k, v in spps.items()}, "rounds": args.rounds,
           "samplers": {k: SAMPLERS[k] for k in SPEED_SAMPLERS}, "warmup": warm, "rows": rows,
           "summary": summary, "bose_over_orthogonal": ratios, "goal": SPEED_GOAL,
           "wall_s": round(time.perf_counter() - t_part, 1), "loadavg_start": load0,
           "loadavg_end": os.getloadavg()[0], "quick": args.quick}
    dr.set_flag(dr.JitFlag.KernelHistory, False)
    write_json(OUT / "speed.json", res)
    write_text(OUT / "speed.md", speed_markdown(res))
    say(f"wrote {OUT / 'speed.json'} and speed.md; bose/orthogonal median {ratios['int']['median']:.3f} "
        f"(int seeds), {ratios['opaque']['median']:.3f} (opaque seeds)")
    return res


def seed_compiles(res: dict) -> bool:
    """Whether pyoa's timed renders with an int seed compiled (or loaded) a kernel: the plugin then
    kept the seed as a literal (before commit 844f5aa of pyoa/mitsuba.py)."""
    a = res["summary"]["pyoa bose|int"]
    return a["compiled_per_render"] + a["disk_cache_per_render"] > 0


def speed_markdown(res: dict) -> str:
    m = res["machine"]
    size, R = res["size"], res["rounds"]
    ri, ro = res["bose_over_orthogonal"]["int"], res["bose_over_orthogonal"]["opaque"]
    lines = [
        f"### Speed: `cornell` {size} x {size}, 121 spp, path depth {res['max_depth']}",
        "",
        (f"`mi.cornell_box()` at {size} x {size}, `path` integrator with `max_depth` {res['max_depth']}, "
         f"121 spp, variant `{m['variant']}`; Mitsuba {m['mitsuba']}, Dr.Jit {m['drjit']} "
         f"({m['drjit_threads']} threads), LLVM `{m['libllvm']}`, on {cpu_text(m['cpu'])}; {m['date']}. "
         f"Each scene loaded once and rendered once per seed kind to warm up, then {R} interleaved rounds "
         "(odd rounds in reverse order), each timing `img = mi.render(scene, seed=round); dr.eval(img); "
         "dr.sync_thread()` twice per sampler: with the seed as a Python int (**int**), and as an opaque "
         "`mi.UInt32` (**opaque**, `dr.opaque(mi.UInt32, round)`). M camera paths/s = "
         f"{size} x {size} x spp / seconds; median of the {R} rounds, min-max in brackets. 1-minute load "
         f"average {res['loadavg_start']:.1f} at the start and {res['loadavg_end']:.1f} at the end; the part "
         f"took {res['wall_s']:.0f} s."),
        "",
        ("| sampler | spp | int seed: M paths/s | opaque seed: M paths/s | kernels compiled per render (int) | "
         "kernels loaded from the disk cache per render (int) | compile ms per render (int, median) |"),
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for label in SPEED_SAMPLERS:
        a, b = res["summary"][f"{label}|int"], res["summary"][f"{label}|opaque"]
        name = f"Mitsuba `{label.split()[1]}`" if label.startswith("mitsuba") else f"pyoa `{label.split()[1]}`"
        lines.append(f"| {name} | {a['spp']} | **{a['median']:.3f}** ({a['min']:.3f}-{a['max']:.3f}) | "
                     f"{b['median']:.3f} ({b['min']:.3f}-{b['max']:.3f}) | {a['compiled_per_render']:.1f} | "
                     f"{a['disk_cache_per_render']:.1f} | {a['compile_ms_median']:.0f} |")
    goal = res["goal"]
    lines += [
        "",
        f"pyoa `bose` / Mitsuba `orthogonal`, per round (goal >= {goal}x):",
        "",
        "| seed | " + " | ".join(f"round {r + 1}" for r in range(R)) + " | median |",
        "|---|" + "---:|" * (R + 1),
        "| int | " + " | ".join(f"{x:.3f}" for x in ri["per_round"]) + f" | **{ri['median']:.3f}** |",
        "| opaque | " + " | ".join(f"{x:.3f}" for x in ro["per_round"]) + f" | **{ro['median']:.3f}** |",
        "",
        f"Median ratio: **{ri['median']:.3f}x** with int seeds (goal {'met' if ri['median'] >= goal else 'missed'}), "
        f"**{ro['median']:.3f}x** with opaque seeds (goal {'met' if ro['median'] >= goal else 'missed'}). "
        + ("Mitsuba's own samplers make the seed opaque themselves, so their two rows time the same kernels; "
         "the pyoa plugin kept an int seed as a literal in the traced kernel, so every new int seed was a "
         "new kernel, compiled in the timed render (or loaded from Dr.Jit's disk cache, `~/.drjit`, when "
         "an earlier process rendered the same seed; the two kernel columns count both)."
         if seed_compiles(res) else
         "Both seed kinds time the same kernels: the pyoa plugin makes the seed opaque, as Mitsuba's own "
         "samplers do, and no timed render compiled or loaded a kernel (the kernel columns; an earlier "
         "version of the plugin kept an int seed as a literal and compiled a new kernel for every seed).")
        + " Dr.Jit's kernel history was on during the timed renders (for every sampler alike).",
        "",
        "Data: `results/mitsuba/speed.json` (every render, with its kernel counts).",
        "",
    ]
    if res.get("quick"):
        lines.insert(2, "**QUICK RUN** (smoke test: smaller film, 2 rounds).\n")
    return "\n".join(lines)


# ---------------------------------------------------------------------------
# errors


def ensure_reference(scene: str, size: int, ref_spp: int) -> np.ndarray:
    """The ``independent`` reference of ``scene``: from the cache (EXR + JSON in the output folder)
    when its parameters match, else rendered in chunks of REF_CHUNK spp and cached."""
    path = OUT / f"reference-{scene}-{size}-{ref_spp}.exr"
    meta_path = path.with_suffix(".json")
    meta = {"scene": scene, "size": size, "spp": ref_spp, "sampler": "independent", "chunk_spp": REF_CHUNK,
            "seeds": f"{REF_SEED} + k", "max_depth": MAX_DEPTH, "variant": VARIANT}
    if scene in ("cornell-dof", "cornell-glossy"):
        meta |= {"aperture_radius": APERTURE_RADIUS, "focus_distance": FOCUS_DISTANCE}
    if scene == "cornell-glossy":
        meta |= {"glossy": f"floor and boxes roughplastic ggx alpha {GLOSSY_ALPHA}"}
    if path.exists() and meta_path.exists():
        old = json.loads(meta_path.read_text())
        if {k: old.get(k) for k in meta} == meta:
            say(f"reference {scene}: cached {path.name} ({ref_spp} spp)")
            return np.array(mi.Bitmap(str(path)), dtype=np.float64)
    chunk = min(REF_CHUNK, ref_spp)
    if ref_spp % chunk:
        raise ValueError(f"reference spp {ref_spp} must be a multiple of {chunk}")
    sc, _ = load_scene(scene, size, {"type": "independent", "sample_count": chunk})
    acc = np.zeros((size, size, 3))
    k_total = ref_spp // chunk
    t0 = time.perf_counter()
    for k in range(k_total):
        img, dt, _ = render(sc, REF_SEED + k)
        acc += np.array(img, dtype=np.float64)
        say(f"reference {scene}: chunk {k + 1}/{k_total} ({chunk} spp) {dt:.2f} s")
    ref = acc / k_total
    meta |= {"seconds": round(time.perf_counter() - t0, 1), "mitsuba": mi.__version__}
    with atomic_path(path) as tmp:
        mi.Bitmap(ref.astype(np.float32)).write(str(tmp))
    write_json(meta_path, meta)
    return np.array(mi.Bitmap(str(path)), dtype=np.float64)  # what a rerun reads


def part_errors(args, cpu: dict) -> dict:
    t_part = time.perf_counter()
    load0 = os.getloadavg()[0]
    size = args.size
    rows, refs = [], {}
    for scene in SCENES:
        ref = refs[scene] = ensure_reference(scene, size, args.ref_spp)
        scenes, spps = {}, {}
        for label in ERROR_SAMPLERS:
            scenes[label], spps[label] = load_scene(scene, size, SAMPLERS[label])
        n = len(ERROR_SAMPLERS)
        for seed in range(args.seeds):
            order = ERROR_SAMPLERS[seed % n:] + ERROR_SAMPLERS[:seed % n]  # rotate: no sampler always first
            for label in order:
                img, dt, _ = render(scenes[label], seed)
                img = np.array(img)
                e = relmse(img, ref)
                if seed == 0:
                    IMAGES[(scene, label)] = img
                rows.append({"scene": scene, "sampler": label, "spp": spps[label], "seed": seed,
                             "relmse": f"{e:.6e}", "seconds": round(dt, 3)})
                say(f"errors {scene} seed {seed + 1}/{args.seeds} {label:22s} {spps[label]:4d} spp: "
                    f"relMSE {e:.4e} ({dt:.2f} s)")
    write_csv(OUT / "errors.csv", rows)
    summary = summarize_errors(rows, args.ref_spp)
    res = {"machine": machine(cpu), "size": size, "max_depth": MAX_DEPTH, "seeds": args.seeds,
           "ref_spp": args.ref_spp, "ref_chunk": REF_CHUNK, "aperture_radius": APERTURE_RADIUS,
           "focus_distance": FOCUS_DISTANCE, "glossy_alpha": GLOSSY_ALPHA, "samplers": {k: SAMPLERS[k] for k in ERROR_SAMPLERS},
           "summary": summary, "wall_s": round(time.perf_counter() - t_part, 1), "loadavg_start": load0,
           "loadavg_end": os.getloadavg()[0], "quick": args.quick}
    write_json(OUT / "errors.json", res)
    write_text(OUT / "errors.md", errors_markdown(res))
    say(f"wrote {OUT / 'errors.csv'}, errors.json and errors.md")
    return res


def summarize_errors(rows: list[dict], ref_spp: int) -> dict:
    out = {}
    for scene in SCENES:
        means = {}
        for label in ERROR_SAMPLERS:
            vals = [float(r["relmse"]) for r in rows if r["scene"] == scene and r["sampler"] == label]
            if not vals:
                continue
            spp = next(int(r["spp"]) for r in rows if r["scene"] == scene and r["sampler"] == label)
            means[label] = {"spp": spp, "n": len(vals), "mean": statistics.mean(vals), "hw95": t_halfwidth(vals)}
        ind = means["mitsuba independent"]["mean"]
        orth = means["mitsuba orthogonal"]["mean"]
        for v in means.values():
            v["over_independent"] = v["mean"] / ind
            v["over_orthogonal"] = v["mean"] / orth
        ind_spp = means["mitsuba independent"]["spp"]
        out[scene] = {"samplers": means, "reference_noise": ind * ind_spp / ref_spp}
    return out


def _name(label: str) -> str:
    who, _, what = label.partition(" ")
    return f"{'Mitsuba' if who == 'mitsuba' else 'pyoa'} `{what}`"


def errors_markdown(res: dict) -> str:
    m = res["machine"]
    size, S = res["size"], res["seeds"]
    k = res["ref_spp"] // res["ref_chunk"]
    ref_how = f"the mean of {k} renders of {res['ref_chunk']} spp" if k > 1 else "one render"
    lines = [
        f"### Error at equal spp: `cornell`, `cornell-dof` and `cornell-glossy`, {size} x {size}",
        "",
        (f"relMSE = mean over pixels and channels of (img - ref)^2 / (ref^2 + 0.01), against a Mitsuba "
         f"`independent` reference of {res['ref_spp']} spp (other seeds; {ref_how}). Mean over seeds 0..{S - 1} (`mi.render(scene, "
         f"seed=s)`) ± the 95 % Student-t half-width; ratios are of the means. `cornell`: `mi.cornell_box()` "
         f"at {size} x {size} (its Gaussian reconstruction filter), `path` integrator, `max_depth` "
         f"{res['max_depth']}. `cornell-dof`: the same box through a `thinlens` camera with the cornell box's "
         f"`to_world` and `fov`, `aperture_radius` {res['aperture_radius']}, `focus_distance` "
         f"{res['focus_distance']} (on the tall box; the back wall and the front of the room out of focus). "
         f"`cornell-glossy`: `cornell-dof` with the floor and both boxes in `roughplastic` (GGX, alpha "
         f"{res.get('glossy_alpha', GLOSSY_ALPHA)}, the walls' white under a glossy coat). "
         "Mitsuba's `ldsampler` accepts only powers of 4 (it rounds 121 up to 256), so it is shown at 64 and "
         f"256 spp. Mitsuba {m['mitsuba']}, `{m['variant']}`, on {cpu_text(m['cpu'])}; the part took "
         f"{res['wall_s']:.0f} s."),
        "",
    ]
    if res.get("quick"):
        lines.insert(2, "**QUICK RUN** (smoke test: 2 seeds, small reference).\n")
    for scene in SCENES:
        s = res["summary"].get(scene)
        if not s:
            continue
        lines += [f"`{scene}`:", "", ("| sampler | spp | relMSE (mean ± 95 %) | / Mitsuba `independent` | "
                                        "/ Mitsuba `orthogonal` |"), "|---|---:|---:|---:|---:|"]
        for label, v in s["samplers"].items():
            bold = "**" if label.startswith("pyoa") else ""
            lines.append(f"| {_name(label)} | {v['spp']} | {bold}{v['mean']:.3e}{bold} ± {v['hw95']:.1e} | "
                         f"{v['over_independent']:.3f} | {v['over_orthogonal']:.3f} |")
        smallest = min(v["mean"] for v in s["samplers"].values())
        lines += ["", (f"Estimated reference noise (relMSE of `independent` at 121 spp x 121 / {res['ref_spp']}): "
                       f"{s['reference_noise']:.1e}, {100 * s['reference_noise'] / smallest:.1f} % of the smallest "
                       "mean above; it adds to every row."), ""]
    lines += ["Data: `results/mitsuba/errors.csv` (every render: scene, sampler, spp, seed, relMSE, seconds).", ""]
    return "\n".join(lines)


# ---------------------------------------------------------------------------
# figure


def old_block_rule(smp, x: np.ndarray, pixels) -> np.ndarray:
    """``x`` (``smp.generate(pixels=pixels)``) as the block rule before the
    blocks' own orders of the rows made it: every block past the first read
    at row i. Sample ``i`` of block b reads row ``block_row(i, N, r_b)`` now,
    so the old rule's sample ``block_row(i)`` is today's sample ``i``."""
    from pyoa._numpy.oa import block_order_seed, block_row
    from pyoa.hashes import block_seed, pixel_seed

    N, B = smp.spp, smp.block_dims
    old = x.copy()
    p = pixel_seed(smp.seed, np.asarray(pixels, np.uint32))
    i = np.arange(N, dtype=np.uint32)[None, :]
    for b in range(1, -(-x.shape[2] // B)):
        rows = block_row(i, N, block_order_seed(block_seed(p, b), b, N)[:, None])
        old[np.arange(len(p))[:, None], rows, b * B:(b + 1) * B] = x[:, :, b * B:(b + 1) * B]
    return old


def part_integrand(args, cpu: dict) -> dict:
    """MSE of ``lagged_pairs`` estimates (module docstring), every sampler and lag; the OA samplers
    also with the old block rule (:func:`old_block_rule`), computed from the same values."""
    import pyoa
    import pyoa.catalogue
    from pyoa.analysis import lagged_pairs

    t0 = time.perf_counter()
    trials = 64 if args.quick else INTEGRAND_TRIALS
    pixels = np.arange(trials)
    rows = []
    for lag in INTEGRAND_LAGS:
        f = lagged_pairs(2 * lag, lag)
        for name, kw in INTEGRAND_SAMPLERS.items():
            smp = pyoa.sampler(name, dims=2 * lag, seed=1, **kw)
            x = smp.generate(pixels=pixels)
            variants = [("", x)]
            if pyoa.catalogue.get(name).family == "oa":
                variants.append((" (old block rule)", old_block_rule(smp, x, pixels)))
            for tag, pts in variants:
                est = f(pts.astype(np.float64)).mean(axis=1)
                err = (est - f.exact) ** 2
                rows.append({"lag": lag, "d": 2 * lag, "sampler": name + tag, "spp": smp.spp,
                             "block_dims": smp.block_dims if len(variants) > 1 else None,
                             "mse": float(err.mean()), "hw95": 1.96 * float(err.std(ddof=1)) / math.sqrt(trials)})
                say(f"integrand lag {lag} {name + tag:28s} {smp.spp:4d} spp: MSE {err.mean():.3e}")
    for r in rows:
        base = next(q["mse"] for q in rows if q["lag"] == r["lag"] and q["sampler"] == "random")
        r["over_random"] = r["mse"] / base
    res = {"machine": machine(cpu), "trials": trials, "lags": list(INTEGRAND_LAGS), "rows": rows,
           "formula": lagged_pairs(2 * INTEGRAND_LAGS[0], INTEGRAND_LAGS[0]).formula,
           "wall_s": round(time.perf_counter() - t0, 1), "quick": args.quick}
    write_json(OUT / "integrand.json", res)
    write_text(OUT / "integrand.md", integrand_markdown(res))
    return res


def integrand_markdown(res: dict) -> str:
    lags = res["lags"]
    lines = [f"### A cross-block integrand: `lagged-pairs`, {res['trials']} pixels", "",
             ("`pyoa.analysis.lagged_pairs(2 L, L)`: the mean over k of g(x_k) g(x_(k+L)), g a Gaussian bump "
              "(sigma 0.15), with an exact integral; it couples only dimensions L apart, which for a sampler "
              "with L dimensions per block (`bush` t = 3 at 125: 6; `bose` at 121: 12) is each dimension and "
              "the same column of the next block. MSE of the estimate over the pixels (pyoa's own samplers, "
              "no Mitsuba), ± the 95 % half-width, and as a multiple of independent points' (`random`). "
              "The 'old block rule' rows are the same values with every block past the first read at row i, "
              "as before the blocks' own orders (docs/spec.md section 6)."), "",
             "| sampler | spp | " + " | ".join(f"L = {L}: MSE | / random" for L in lags) + " |",
             "|---|---:|" + "---:|---:|" * len(lags)]
    names = list(dict.fromkeys(r["sampler"] for r in res["rows"]))
    for n in names:
        cells, spp = [], ""
        for L in lags:
            r = next((q for q in res["rows"] if q["lag"] == L and q["sampler"] == n), None)
            spp = r["spp"] if r else spp
            cells.append(f"{r['mse']:.2e} ± {r['hw95']:.0e} | {r['over_random']:.2f}" if r else " | ")
        bold = "**" if n in ("bose", "bush") else ""
        lines.append(f"| {bold}{n}{bold} | {spp} | " + " | ".join(cells) + " |")
    lines += ["", f"Data: `results/mitsuba/integrand.json`; the part took {res['wall_s']:.0f} s.", ""]
    return "\n".join(lines)


def tonemap(img: np.ndarray) -> np.ndarray:
    return np.clip(img, 0.0, 1.0) ** (1 / 2.2)


def part_figure(args, cpu: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scene, size = FIGURE_SCENE, args.size
    ref = ensure_reference(scene, size, args.ref_spp)
    imgs = {}
    for label in FIGURE_SAMPLERS:
        if (scene, label) not in IMAGES:
            sc, spp = load_scene(scene, size, SAMPLERS[label])
            img, dt, _ = render(sc, 0)
            IMAGES[(scene, label)] = np.array(img)
            say(f"figure {label}: {dt:.2f} s")
        imgs[label] = IMAGES[(scene, label)]
    fig, axes = plt.subplots(2, 4, figsize=(13, 7.6), layout="constrained")
    for ax in axes.flat:
        ax.set_xticks([])
        ax.set_yticks([])
    axes[0, 0].imshow(tonemap(ref), interpolation="nearest")
    axes[0, 0].set_title(f"reference\n(Mitsuba independent, {args.ref_spp} spp)", fontsize=10)
    slots = [axes[0, 1], axes[0, 2], axes[0, 3], axes[1, 1], axes[1, 2], axes[1, 3]]
    for ax, label in zip(slots, FIGURE_SAMPLERS):
        spp = SAMPLERS[label]["sample_count"]
        ax.imshow(tonemap(imgs[label]), interpolation="nearest")
        ax.set_title(f"{label.replace('mitsuba', 'Mitsuba')} ({spp} spp)\nrelMSE {relmse(imgs[label], ref):.3e}",
                     fontsize=10)
    axes[1, 0].axis("off")
    axes[1, 0].text(0.0, 0.5, f"{scene}, {size} x {size}\nthin lens: aperture radius {APERTURE_RADIUS},\n"
                    f"focus distance {FOCUS_DISTANCE}\npath tracing, max depth {MAX_DEPTH}\nseed 0 of each "
                    "sampler\n\ntop: Mitsuba's samplers\nbottom: pyoa's, through\nthe pyoa plugin\n\n"
                    "tone map: clip to [0, 1],\ngamma 2.2", fontsize=10, va="center", transform=axes[1, 0].transAxes)
    fig.suptitle(f"Mitsuba 3 {mi.__version__} ({VARIANT}): the same render with Mitsuba's and pyoa's samplers",
                 fontsize=12)
    path = OUT / "samplers.png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100)
    plt.close(fig)
    say(f"wrote {path}")


# ---------------------------------------------------------------------------
# section


def scene_means(errors: dict):
    """``(scene, {label: mean, hw95, ratios...})`` of every scene the errors part measured, in SCENES order."""
    for scene in SCENES:
        sm = errors["summary"].get(scene)
        if sm:
            yield scene, sm["samplers"]


def interpretation(speed: dict | None, errors: dict | None) -> str:
    out = []
    if speed:
        ri, ro = speed["bose_over_orthogonal"]["int"], speed["bose_over_orthogonal"]["opaque"]
        s = speed["summary"]
        m = speed["machine"]
        out.append(
            f"**Speed.** Rendering `cornell` {speed['size']} x {speed['size']} at 121 spp ({m['date'][:10]}, "
            f"{figures.cpu_name(m['cpu']['model_name'])} {m['cpu']['family']}/{m['cpu']['model']}, "
            f"{m['cpu']['cores']} cores), pyoa's `bose` ran at "
            f"{ri['median']:.2f}x Mitsuba's `orthogonal` (median of {speed['rounds']} per-round ratios, "
            f"{ri['min']:.2f}-{ri['max']:.2f}) with the seed passed as a Python int, and {ro['median']:.2f}x "
            f"({ro['min']:.2f}-{ro['max']:.2f}) with an opaque `mi.UInt32` seed; the goal is {speed['goal']}x. "
            + (f"With int seeds each pyoa render compiled {s['pyoa bose|int']['compiled_per_render']:.1f} kernels "
               f"({s['pyoa bose|int']['compile_ms_median']:.0f} ms median) and Mitsuba's "
               f"{s['mitsuba orthogonal|int']['compiled_per_render']:.1f}: the int seed was a literal in pyoa's "
               "traced kernel. " if seed_compiles(speed) else
               "No timed render compiled a kernel (the plugin's seed is opaque). ")
            + f"`faure` ran at {s['pyoa faure|opaque']['median'] / s['mitsuba orthogonal|opaque']['median']:.2f}x "
            f"`orthogonal` (opaque seeds), `independent` at "
            f"{s['mitsuba independent|opaque']['median'] / s['mitsuba orthogonal|opaque']['median']:.2f}x."
            + (f" The errors below were measured earlier ({errors['machine']['date'][:10]}); the plugin's values "
               "are bit for bit NumPy's (`tests/test_mitsuba.py`), so they stand."
               if errors and errors["machine"]["date"] < m["date"] else ""))
    if errors:
        parts = []
        for scene, v in scene_means(errors):
            best = min((k for k in v if v[k]["spp"] <= 128), key=lambda k: v[k]["mean"])  # equal spp: not ldsampler 256
            parts.append(
                f"on `{scene}` pyoa `bose` had {v['pyoa bose']['over_independent']:.2f}x the relMSE of Mitsuba's "
                f"`independent` and {v['pyoa bose']['over_orthogonal']:.2f}x that of `orthogonal` "
                f"(`bush` t=3 {v['pyoa bush t=3']['over_orthogonal']:.2f}x, `faure` "
                f"{v['pyoa faure']['over_orthogonal']:.2f}x, pyoa `random` {v['pyoa random']['over_independent']:.2f}x "
                f"`independent`); the lowest mean at 121-128 spp was {_name(best)}'s ({v[best]['over_orthogonal']:.2f}x "
                f"`orthogonal`)")
        out.append(f"**Error.** At about 121 spp over {errors['seeds']} seeds, " + "; ".join(parts) + ".")
        before = OUT / BEFORE
        out.append(block_order_effect(errors, json.loads(before.read_text()) if before.exists() else None))
    return "\n\n".join(out)


#: The errors part as it was before the blocks' own orders of the rows (pyoa a6b7dc7, AMD EPYC Zen 4):
#: kept, not rerun, so the page can say what the fix changed.
BEFORE = "errors-before-block-order.json"


def _verdict(a: dict, b: dict) -> str:
    """'lower', 'higher' or 'indistinguishable': a's mean against b's, by their 95 % half-widths."""
    if a["mean"] + a["hw95"] < b["mean"] - b["hw95"]:
        return "lower"
    if a["mean"] - a["hw95"] > b["mean"] + b["hw95"]:
        return "higher"
    return "indistinguishable"


def block_order_effect(errors: dict, before: dict | None) -> str:
    """What the blocks' own orders of the rows changed inside Mitsuba, and where strength 3 wins: plain
    sentences from the saved runs."""
    out = []
    if before:
        parts = []
        for scene in SCENES:
            now, old = errors["summary"].get(scene), before["summary"].get(scene)
            if not now or not old:
                continue
            v, o = now["samplers"], old["samplers"]
            parts.append(
                f"on `{scene}` `bush` t=3 went from {o['pyoa bush t=3']['over_independent']:.2f}x to "
                f"{v['pyoa bush t=3']['over_independent']:.2f}x the relMSE of `independent` "
                f"({o['pyoa bush t=3']['over_orthogonal']:.2f}x to {v['pyoa bush t=3']['over_orthogonal']:.2f}x "
                f"`orthogonal`), `bose` from {o['pyoa bose']['over_independent']:.2f}x to "
                f"{v['pyoa bose']['over_independent']:.2f}x ({o['pyoa bose']['over_orthogonal']:.2f}x to "
                f"{v['pyoa bose']['over_orthogonal']:.2f}x `orthogonal`)")
        out.append(
            "**What the blocks' own orders changed.** Before docs/spec.md section 6 gave every block past the "
            "first its own order of the rows, dimension j + B was a function of dimension j (B the block "
            "size), so with `bush` t=3's 6-dimension blocks and Mitsuba's 6 dimensions per bounce every bounce "
            "repeated the strata of the one before (`results/mitsuba/" + BEFORE + "`, the run before the "
            "fix, on " + cpu_text(before["machine"]["cpu"]) + "): " + "; ".join(parts) + ".")
    parts = []
    for scene, v in scene_means(errors):
        bush, bose, orth = v["pyoa bush t=3"], v["pyoa bose"], v["mitsuba orthogonal"]
        parts.append(f"`{scene}`: `bush` t=3 / `bose` {bush['mean'] / bose['mean']:.2f} "
                     f"({_verdict(bush, bose)}), / `orthogonal` {bush['over_orthogonal']:.2f} "
                     f"({_verdict(bush, orth)})")
    lower = [p for p in parts if "/ `orthogonal`" in p and "(lower)" in p.split("/ `orthogonal`")[1]]
    out.append(
        "**Where strength 3 wins.** At 125 against 121 spp, `bush` t=3's mean relMSE against `bose`'s and "
        "Mitsuba `orthogonal`'s (lower or higher: the 95 % intervals do not overlap): " + "; ".join(parts) + ". "
        + ("It is lower than `orthogonal`'s on no scene here. " if not lower else "")
        + "Strength 3 stratifies every triple of dimensions inside a block, but a block of `bush` with s = 5 "
        "holds only 6 dimensions (the camera's and about one bounce's), its dimensions in different blocks are "
        "paired at random as any padded sampler's are, and it has 5 coarse strata per axis against `bose`'s "
        "and `orthogonal`'s 11: the error of these scenes comes mostly from pairs (film and lens position, the "
        "two numbers of a light sample, a BSDF's lobe and direction), which those stratify on an 11 x 11 grid "
        "and `bush` on 5 x 5. The cross-block integrand below shows what the blocks' own orders fixed; where "
        "a triple inside one block dominates the error (the `triples0` integrand of the faure section), "
        "strength 3 does win.")
    return "\n\n".join(out)


def _saved(out: Path, part: str) -> dict | None:
    path = out / f"{part}.json"
    return json.loads(path.read_text()) if path.exists() else None


def section_text(out: Path) -> str:
    """The results page's section from the saved parts in ``out``."""
    speed, errors = _saved(out, "speed"), _saved(out, "errors")
    parts = [speed_markdown(speed) if speed else None, errors_markdown(errors) if errors else None,
             (out / "integrand.md").read_text() if (out / "integrand.md").exists() else None]
    intro = ("`pyoa/mitsuba.py` registers a Mitsuba 3 sampler plugin, `pyoa`: `import pyoa.mitsuba`, then a "
             "scene's sampler `{\"type\": \"pyoa\", \"sampler\": \"bose\", \"sample_count\": 121}` draws pyoa's "
             "values inside Mitsuba's own kernels (Dr.Jit, LLVM backend). This section compares it with "
             "Mitsuba's own samplers in Mitsuba's renderer: speed, and error at equal spp.")
    fig = ("![Mitsuba's and pyoa's samplers](results/mitsuba/samplers.png)\n\n"
           "Seed 0 of each sampler on `cornell-dof`, relMSE in the titles.\n"
           if (out / "samplers.png").exists() else "")
    spent = sum((_saved(out, p) or {}).get("wall_s", 0) for p in ("speed", "errors", "integrand"))
    footer = (f"Regenerate with `python benchmarks/mitsuba_study.py` (its parts took {spent / 60:.0f} minutes "
              "here on 2 cores; `python benchmarks/update_docs.py` rewrites this section from the saved files "
              "in `docs/results/mitsuba/`).")
    return "\n".join(["## pyoa inside Mitsuba 3", "", intro, "", interpretation(speed, errors), "",
                      *[p for p in parts if p], fig, footer])


def part_section(args) -> None:
    speed, errors = _saved(OUT, "speed"), _saved(OUT, "errors")
    if speed:
        write_text(OUT / "speed.md", speed_markdown(speed))
    if errors:
        write_text(OUT / "errors.md", errors_markdown(errors))
    text = section_text(OUT)
    if args.quick:  # a smoke run leaves the pages alone
        write_text(OUT / "section.md", text)
        say(f"wrote {OUT / 'section.md'} (quick: docs/results.md and docs/performance.md untouched)")
        return
    import update_docs  # this section, and the Mitsuba plugin's paragraph and goal in docs/performance.md

    for page in update_docs.update([SECTION, PERF_SECTION, "mitsuba-goal"] if speed else [SECTION]):
        say(f"wrote {page}")


def goal_text(speed: dict) -> str:
    """The Mitsuba plugin's cell of docs/performance.md's goals table."""
    ri, ro = speed["bose_over_orthogonal"]["int"], speed["bose_over_orthogonal"]["opaque"]
    c = speed["machine"]["cpu"]
    return (f"{figures.cpu_name(c['model_name'])} {c['family']}/{c['model']}: **{ri['median']:.2f}x** (int seeds, "
            f"per round {ri['min']:.2f}-{ri['max']:.2f}) and **{ro['median']:.2f}x** (opaque, "
            f"{ro['min']:.2f}-{ro['max']:.2f})")


def performance_text(speed: dict) -> str:
    """docs/performance.md's "Mitsuba plugin" paragraph from the speed part."""
    ri, ro = speed["bose_over_orthogonal"]["int"], speed["bose_over_orthogonal"]["opaque"]
    s = speed["summary"]
    m = speed["machine"]
    goal = speed["goal"]
    return "\n".join([
        "### Mitsuba plugin",
        "",
        f"pyoa's samplers also run inside Mitsuba 3 (`pyoa/mitsuba.py`, sampler type `pyoa`), traced into "
        f"Mitsuba's own kernels. Rendering Mitsuba's `cornell_box()` at {speed['size']} x {speed['size']}, "
        f"121 spp, path depth {speed['max_depth']}, in one process with {speed['rounds']} interleaved rounds "
        f"after a warm-up (Mitsuba {m['mitsuba']}, Dr.Jit LLVM backend, {cpu_text(m['cpu'])}): pyoa `bose` "
        f"{s['pyoa bose|int']['median']:.2f} M paths/s against Mitsuba `orthogonal`'s "
        f"{s['mitsuba orthogonal|int']['median']:.2f}, **{ri['median']:.2f}x** (median of the per-round "
        f"ratios, {ri['min']:.2f}-{ri['max']:.2f}; goal >= {goal}x: "
        f"{'met' if ri['median'] >= goal else 'missed'}) with `mi.render(scene, seed=int)`, and "
        f"**{ro['median']:.2f}x** ({ro['min']:.2f}-{ro['max']:.2f}) with an opaque seed "
        + ("(`seed=dr.opaque(mi.UInt32, n)`). The difference is compilation: the plugin kept an int seed as a "
           f"literal, so each new seed compiled a new kernel ({s['pyoa bose|int']['compile_ms_median']:.0f} ms "
           "median per render here), where Mitsuba's samplers make the seed opaque. "
           if seed_compiles(speed) else
           "(`seed=dr.opaque(mi.UInt32, n)`): the plugin makes the seed opaque, as Mitsuba's samplers do, so "
           "no render compiles a kernel for a new seed (an earlier version kept an int seed as a literal: "
           "0.35 s of compilation per 256 x 256 render). ")
        + "Table and per-round ratios: "
        "[docs/results/mitsuba/speed.md](results/mitsuba/speed.md); errors at equal spp: "
        "[Results](results.md#pyoa-inside-mitsuba-3).",
    ])


# ---------------------------------------------------------------------------


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help="small sizes, 1-2 minutes, under docs/results/quick/mitsuba (pages untouched)")
    ap.add_argument("--parts", default=",".join(PARTS), help=f"comma-separated subset of {', '.join(PARTS)}")
    ap.add_argument("--rounds", type=int, default=None, help="speed: timed rounds (default 7; quick 2)")
    ap.add_argument("--speed-size", type=int, default=None, help="speed: film width and height (default 256; quick 128)")
    ap.add_argument("--seeds", type=int, default=None, help="errors: seeds per sampler (default 8; quick 2)")
    ap.add_argument("--size", type=int, default=128, help="errors and figure: film width and height (default 128)")
    ap.add_argument("--ref-spp", type=int, default=None,
                    help=f"errors: reference spp, a multiple of {REF_CHUNK} (default 16384; quick 1024)")
    args = ap.parse_args(argv)
    parts = [p.strip() for p in args.parts.split(",") if p.strip()]
    bad = [p for p in parts if p not in PARTS]
    if bad or not parts:
        ap.error(f"unknown part(s) {bad or 'none given'}; valid: {', '.join(PARTS)}")
    q = args.quick
    args.rounds = args.rounds or (2 if q else 7)
    args.speed_size = args.speed_size or (128 if q else 256)
    args.seeds = args.seeds or (2 if q else 8)
    args.ref_spp = args.ref_spp or (1024 if q else 16384)
    if args.ref_spp % REF_CHUNK and args.ref_spp > REF_CHUNK:
        ap.error(f"--ref-spp must be a multiple of {REF_CHUNK} (or at most {REF_CHUNK})")
    global OUT
    if q:  # never overwrite the published results with a smoke run (docs/results/quick/ is git-ignored)
        OUT = REPO / "docs" / "results" / "quick" / "mitsuba"
    OUT.mkdir(parents=True, exist_ok=True)
    cpu = cpu_info()
    t0 = time.perf_counter()
    if any(p in parts for p in ("speed", "errors", "integrand", "figure")):  # machine() names the versions
        load_mitsuba()
        say(f"mitsuba study on {cpu_text(cpu)}; Mitsuba {mi.__version__}, Dr.Jit {dr.__version__}, "
            f"LLVM {os.environ.get('DRJIT_LIBLLVM_PATH')}{' [QUICK]' if q else ''}; output {OUT}")
    for name, fn in (("speed", part_speed), ("errors", part_errors), ("integrand", part_integrand),
                     ("figure", part_figure)):
        if name in parts:
            t = time.perf_counter()
            say(f"== {name}")
            fn(args, cpu)
            say(f"== {name}: {time.perf_counter() - t:.0f} s")
    if "section" in parts:
        part_section(args)
    say(f"done in {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
