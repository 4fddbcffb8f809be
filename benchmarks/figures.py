"""The figures the docs show, as text made from the results files.

Each function here reads the results files of one benchmark
(``benchmarks/results/``) and returns the text of one marked section
(:mod:`marked`): a table, a
paragraph, or a fragment of a sentence or table cell. Nothing is measured and
nothing is typed in by hand: a figure in the docs is what its results file
says, rounded. ``update_docs.py`` puts the text into the pages; the
benchmark that writes a results file calls it for the sections that read it.

Every speed figure comes with its CPU (family and model), because the same
workload runs 2.5-3.5x faster on one CPU of this machine kind than on
another; only ratios measured in one run compare.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
RESULTS = REPO / "benchmarks" / "results"
RENDER = RESULTS / "render.json"


def load(path: Path) -> dict:
    """A results file's JSON."""
    return json.loads(Path(path).read_text(encoding="utf-8"))


# ---------------------------------------------------------------------------
# the machine


def cpu_name(model_name: str) -> str:
    """The CPU's marketing name without trademarks and filler: ``Intel(R)
    Xeon(R) Processor`` -> ``Intel Xeon``."""
    name = re.sub(r"\((R|TM)\)", "", model_name)
    name = re.sub(r"\b(Processor|CPU)\b", "", name)
    return " ".join(name.split())


def cpu_short(machine: dict) -> str:
    """``Intel Xeon 6/207``: name, family/model (what tells this machine kind's CPUs apart)."""
    return f"{cpu_name(machine['cpu_model'])} {machine['cpu_family']}/{machine['cpu_model_number']}"


def cpu_long(machine: dict) -> str:
    """``Intel Xeon of family 6 model 207 (AVX-512)``."""
    isa = f" ({machine['cpu_isa']})" if machine.get("cpu_isa") else ""
    return (f"{cpu_name(machine['cpu_model'])} of family {machine['cpu_family']} "
            f"model {machine['cpu_model_number']}{isa}")


def when(date_utc: str) -> str:
    """``2026-11-28T23:50:30Z`` -> ``2026-11-28 23:50``."""
    return date_utc[:16].replace("T", " ")


_WORDS = "zero one two three four five six seven eight nine ten eleven twelve".split()


def count(n: int) -> str:
    """A small count in words, as prose writes it: ``four``."""
    return _WORDS[n] if 0 <= n < len(_WORDS) else str(n)


def pct(x: float) -> str:
    return f"{round(100 * x)} %"


# ---------------------------------------------------------------------------
# bench_render.py: benchmarks/results/render.json

#: What sets a scene apart, beside its dimensions and depth in the tables.
SCENE_NOTES = {"deep": "GGX and mirror"}


def _render_rows(report: dict) -> dict:
    """Per scene: the numba robust and fast rows, the numpy row, Mitsuba and the floors."""
    out = {}
    for sc in report["scenes"]:
        rows = {(r["shading"], r["tracing"]): r for r in sc["results"]}
        out[sc["scene"]] = {"robust": rows[("numba", "robust")], "fast": rows[("numba", "fast")],
                            "numpy": rows[("numpy", "robust")], "depth": sc["max_depth"],
                            "mitsuba": sc["mitsuba"], "floor": sc["embree_floor"]}
    return out


def _floors(rows: dict) -> tuple[float, float]:
    """The lowest and highest share of the Embree floor over every scene and tracing mode."""
    shares = [s[mode]["vs_floor"] for s in rows.values() for mode in ("robust", "fast")]
    return min(shares), max(shares)


def _mitsuba_version(mit: dict) -> str:
    return mit["robust"]["version"]


def render_goal() -> str:
    """The render row of docs/performance.md's goals table (a cell's text)."""
    rep = load(RENDER)
    rows = _render_rows(rep)
    c = rows["cornell"]
    lo, hi = _floors(rows)
    mit = c["mitsuba"]
    return (f"{cpu_short(rep['machine'])}, compiled shading ({when(rep['date_utc'])}): "
            f"**{c['robust']['paths_per_s'] / 1e6:.3f} M paths/s** against Mitsuba's "
            f"**{mit['robust']['paths_per_s'] / 1e6:.3f}** in the same rounds, both tracing robustly "
            f"(**{c['robust']['vs_mitsuba']:.2f}x**; {c['fast']['vs_mitsuba']:.2f}x both tracing as Mitsuba does "
            f"by default); **{round(100 * lo)}-{pct(hi)}** of the Embree floor on the {count(len(rows))} scenes, where "
            f"Mitsuba reaches {pct(mit['robust']['vs_floor'])} (robust) and {pct(mit['fast']['vs_floor'])} (fast) "
            f"of `cornell`'s.")


def render_summary() -> str:
    """The README's paragraph on render speed."""
    rep = load(RENDER)
    c = _render_rows(rep)["cornell"]
    m = rep["machine"]
    cfg = rep["config"]
    share = c["robust"]["profile"]["shares"]["embree"]
    return (f"Rendering `cornell` ({cfg['size'][0]} x {cfg['size'][1]}, depth {c['depth']}, {cfg['spp']} spp) on "
            f"an {cpu_name(m['cpu_model'])} (family {m['cpu_family']} model {m['cpu_model_number']}), "
            f"{m['cpu_count']} cores, {rep['date_utc'][:10]}: {c['robust']['paths_per_s'] / 1e6:.2f} M camera "
            f"paths/s with the compiled shading (the NumPy reference: {c['numpy']['paths_per_s'] / 1e6:.2f}), "
            f"{c['robust']['vs_mitsuba']:.2f}x Mitsuba {_mitsuba_version(c['mitsuba'])} in the same rounds with "
            f"both tracing robustly and {c['fast']['vs_mitsuba']:.2f}x with both tracing as Mitsuba does by "
            f"default; Embree is {pct(share)} of the compiled renderer's time "
            "(`benchmarks/results/render.md`).")


def _llvm(mit: dict) -> str:
    m = re.search(r"libLLVM[.-]?(?:so\.)?(\d+)", mit["robust"].get("libllvm") or "")
    return f"LLVM {m[1]} backend" if m else "LLVM backend"


def render_speed() -> str:
    """docs/performance.md, "Rendering": the run, every scene against its floor, and `cornell` beside Mitsuba."""
    rep = load(RENDER)
    rows = _render_rows(rep)
    m = rep["machine"]
    commit = (m.get("git_commit") or "unknown")[:7]
    out = [f"The run of {when(rep['date_utc'])} UTC on an **{cpu_long(m)}**, {m['cpu_count']} cores, "
           f"commit {commit}:", "",
           "| scene (dims, depth) | rays/path | compiled, robust M paths/s | / Embree floor (robust) "
           "| compiled, fast | / floor (fast) | NumPy reference |",
           "|---|---:|---:|---:|---:|---:|---:|"]
    for name, s in rows.items():
        what = ", ".join([str(s["robust"]["dims"]), str(s["depth"]), *filter(None, [SCENE_NOTES.get(name)])])
        bold = "**" if name == "cornell" else ""
        out.append(f"| `{name}` ({what}) | {s['robust']['rays_per_path']:.2f} | "
                   f"{bold}{s['robust']['paths_per_s'] / 1e6:.3f}{bold} | **{pct(s['robust']['vs_floor'])}** | "
                   f"{s['fast']['paths_per_s'] / 1e6:.3f} | **{pct(s['fast']['vs_floor'])}** | "
                   f"{s['numpy']['paths_per_s'] / 1e6:.3f} |")
    c = rows["cornell"]
    mit, floor = c["mitsuba"], c["floor"]
    cfg = rep["config"]
    v = _mitsuba_version(mit)
    r = floor["robust"]
    mr, mf = mit["robust"]["paths_per_s"], mit["fast"]["paths_per_s"]
    out += ["", f"Side by side with Mitsuba {v} (`orthogonal` sampler, `path` integrator, {_llvm(mit)}, its own "
                f"`cornell_box()`, max depth {c['depth']}), in the same rounds:", "",
            f"| `cornell` {cfg['size'][0]} x {cfg['size'][1]}, {cfg['spp']} spp, depth {c['depth']} "
            "| M camera paths/s | / Mitsuba, same tracing mode |",
            "|---|---:|---:|",
            f"| pyoa, compiled shading, robust tracing (the default) | **{c['robust']['paths_per_s'] / 1e6:.3f}** "
            f"| **{c['robust']['vs_mitsuba']:.2f}x** |",
            f"| Mitsuba {v}, `embree_use_robust_intersections: true` | {mr / 1e6:.3f} | 1.00x |",
            f"| pyoa, compiled shading, fast tracing | {c['fast']['paths_per_s'] / 1e6:.3f} "
            f"| **{c['fast']['vs_mitsuba']:.2f}x** |",
            f"| Mitsuba {v} as it comes (non-robust) | {mf / 1e6:.3f} | 1.00x |",
            f"| Embree floor, robust: the render's own rays replayed through the shipped path ({r['packet']}-wide "
            f"packets from numba, {r['threads']} threads, each every other wavefront in one compiled call) "
            f"| {r['paths_per_s'] / 1e6:.3f} | {r['paths_per_s'] / mr:.2f}x |",
            f"| Embree floor, fast | {floor['fast']['paths_per_s'] / 1e6:.3f} "
            f"| {floor['fast']['paths_per_s'] / mf:.2f}x |",
            "",
            f"Of those floors, in the same rounds, pyoa reached {pct(c['robust']['vs_floor'])} (robust) and "
            f"{pct(c['fast']['vs_floor'])} (fast), Mitsuba {pct(mit['robust']['vs_floor'])} and "
            f"{pct(mit['fast']['vs_floor'])} (the benchmark's Mitsuba rows, at pyoa's rays per path: the same "
            "scene and depth)."]
    return "\n".join(out)


#: The profile's columns in docs/performance.md: (scene, tracing).
PROFILE_COLUMNS = (("cornell", "robust"), ("cornell", "fast"), ("dof7d", "robust"), ("dof7d", "fast"),
                   ("bounce9d", "robust"), ("deep", "robust"))
#: The profile's rows: label, the compiled loop's parts summed, whether the figure is bold for `cornell` robust.
PROFILE_ROWS = (("sampling (`Sampler.generate`, PoCL, two batches a call)", ("sampling",), False),
                ("camera rays", ("camera",), False),
                ("Embree (closest hits, shadow rays)", ("embree",), True),
                ("shading (emission, NEE, BSDF, roulette, compaction)", ("shading",), True),
                ("host (Python around the compiled call) and the rest", ("host", "other"), False))


def render_profile() -> str:
    """docs/performance.md: where a compiled render's time goes, scene by scene (one thread)."""
    rep = load(RENDER)
    rows = _render_rows(rep)
    head = " | ".join(f"`{s}` {t}" for s, t in PROFILE_COLUMNS)
    out = [f"Where the time goes (one thread, a separate render of the same image; the compiled loop times its "
           f"own stages; the run of {when(rep['date_utc'])}; the renderer samples on a thread of its own, ahead "
           "of its worker, so the profile holds a lock across each sampler call and each batch's tracing to "
           "keep the parts one thread's time):", "",
           f"| part | {head} |", "|---|" + "---:|" * len(PROFILE_COLUMNS)]
    for label, parts, bold in PROFILE_ROWS:
        cells = []
        for scene, tracing in PROFILE_COLUMNS:
            p = rows[scene][tracing]["profile"]
            secs = sum(p["parts_s"][k] for k in parts)
            share = sum(p["shares"][k] for k in parts)
            b = "**" if bold and (scene, tracing) == ("cornell", "robust") else ""
            cells.append(f"{b}{secs:.2f} s ({pct(share)}){b}")
        out.append(f"| {label} | " + " | ".join(cells) + " |")
    totals = [f"{rows[s][t]['profile']['seconds']:.2f} s, {rows[s][t]['profile']['paths_per_s'] / 1e6:.3f}"
              for s, t in PROFILE_COLUMNS]
    out.append("| total, M paths/s | " + " | ".join(totals) + " |")
    return "\n".join(out)


#: The memory table's rows in docs/performance.md: (scene, shading, size, batch paths).
MEMORY_ROWS = (("cornell", "numba", 256, 65536), ("cornell", "numba", 512, 65536), ("cornell", "numba", 256, 16384),
               ("dof7d", "numba", 256, 65536), ("deep", "numba", 256, 65536), ("cornell", "numpy", 256, 65536),
               ("deep", "numpy", 256, 65536))


def _memory(rep: dict) -> dict:
    return {(r["scene"], r["shading"], r["size"][0], r["batch_paths"]): r for r in rep["memory"]}


def mib(n: float) -> str:
    return f"{n / 2**20:.1f} MiB"


def render_memory() -> str:
    """docs/performance.md, "Render memory": each row's peak against its stated bound."""
    rep = load(RENDER)
    mem = _memory(rep)
    dims = {s["scene"]: s["results"][0]["dims"] for s in rep["scenes"]}
    out = [f"The run of {when(rep['date_utc'])} (`benchmarks/results/render.md`):", "",
           "| scene | shading | size | paths in flight | peak above baseline | sampler values made ahead, at most "
           "| stated bound |", "|---|---|---|---:|---:|---:|---:|"]
    named = set()
    for key in MEMORY_ROWS:
        scene, shading, size, batch = key
        r = mem[key]
        label = f"`{scene}`" + ("" if scene in named else f" ({dims[scene]} dims)")
        named.add(scene)
        where = f"{size} x {size}" + ("" if batch == 65536 else f", batch {batch:,}")
        out.append(f"| {label} | {'NumPy' if shading == 'numpy' else shading} | {where} | {r['paths_in_flight']:,} | "
                   f"{mib(r['above_bytes'])} | {mib(r['samples_ahead_bytes'])} | {mib(r['bound_bytes'])} |")
    close = max(rep["memory"], key=lambda r: r["above_bytes"] / r["bound_bytes"])
    base = mem[("cornell", "numba", 256, 65536)]
    big, small = mem[("cornell", "numba", 512, 65536)], mem[("cornell", "numba", 256, 16384)]
    within = all(r["above_bytes"] <= r["bound_bytes"] for r in rep["memory"])
    out += ["", f"{'Every row of the run is' if within else 'Not every row of the run is'} within its bound; the "
                f"closest is `{close['scene']}` with the {'NumPy' if close['shading'] == 'numpy' else 'compiled'} "
                f"shading, {close['above_bytes'] / 2**20:.1f} of {mib(close['bound_bytes'])} "
                f"({pct(close['above_bytes'] / close['bound_bytes'])}). Quadrupling `cornell`'s image added "
                f"{mib(big['above_bytes'] - base['above_bytes'])} (its float32 RGB: "
                f"{(big['image_bytes'] - base['image_bytes']) / 2**20:.2f} MiB), and a quarter of the batch cut the "
                f"peak to {pct(small['above_bytes'] / base['above_bytes'])}."]
    return "\n".join(out)


def render_memory_goal() -> str:
    """The render memory row of docs/performance.md's goals table: `cornell`'s bound and peak (a cell's text)."""
    r = _memory(load(RENDER))[("cornell", "numba", 256, 65536)]
    return (f"{r['bound_bytes'] / 2**20:.0f} MiB for `cornell` 256 x 256 x 121 "
            f"({r['above_bytes'] / 2**20:.0f} MiB measured)")


# ---------------------------------------------------------------------------
# bench_openqmc.py: benchmarks/results/openqmc.json (g++) and openqmc-clang.json (clang)

OPENQMC = (RESULTS / "openqmc.json", RESULTS / "openqmc-clang.json")


def ns(x: float) -> str:
    """ns per value: three figures or one decimal, whichever is more."""
    return f"{x:.1f}" if x >= 10 else f"{x:.2f}"


def times(r: dict, bold: bool = False, spread: bool = True) -> str:
    """A ratio of medians as ``0.59x (0.41-1.00)``: the median of the per-round ratios, then their range."""
    d = 1 if r["median"] >= 10 else 2
    b = "**" if bold else ""
    rng = f" ({r['min']:.{d}f}-{r['max']:.{d}f})" if spread else ""
    return f"{b}{r['median']:.{d}f}x{b}{rng}"


def _compiler(rep: dict, major: bool = False) -> str:
    """``g++ 12.2`` / ``clang++ 15.0.6`` (a trailing ``.0`` dropped); ``major``: ``g++ 12`` / ``clang 15``."""
    clang = rep["compiler"]["kind"] == "clang"
    v = re.search(r"\d+(?:\.\d+)*", rep["compiler"]["reported"])[0]
    if major:
        return f"{'clang' if clang else 'g++'} {v.split('.')[0]}"
    return f"{'clang++' if clang else 'g++'} {re.sub(r'[.]0$', '', v)}"


def _kind(rep: dict) -> str:
    return "clang" if rep["compiler"]["kind"] == "clang" else "g++"


def _oq(rep: dict) -> tuple[dict, dict]:
    return {c["name"]: c["median_ns"] for c in rep["cases"]}, rep["ratios"]


def openqmc_table() -> str:
    """docs/performance.md: ns per value of pyoa's C paths and OpenQMC's, g++ and clang side by side."""
    reps = [load(p) for p in OPENQMC]
    m = reps[0]["machine"]
    flags = " ".join(reps[0]["compiler"]["flags"])
    runs = " and ".join(f"{when(r['machine']['date_utc'])[11:]} ({_kind(r)})" for r in reps)
    rounds = reps[0]["config"]["rounds"]
    out = [f"{cpu_name(m['cpu_model'])}, family {m['cpu_family']} model {m['cpu_model_number']} ({m['cpu_isa']}), "
           f"{m['cpu_count']} cores, `{flags}`, {reps[0]['machine']['date_utc'][:10]} {runs} UTC; ns per value, "
           f"median of {rounds} rounds:", "",
           "| | " + " | ".join(_compiler(r) for r in reps) + " |", "|---|" + "---:|" * len(reps)]

    def row(label: str, cell) -> None:
        out.append(f"| {label} | " + " | ".join(cell(*_oq(r), r) for r in reps) + " |")

    def paths(s: str, bold_last: bool = False):
        def cell(v, _r, _rep):
            last = ns(v[f"pyoa/{s}/prepared"])
            last = f"**{last}**" if bold_last else last
            return f"{ns(v[f'pyoa/{s}/scalar'])} / {ns(v[f'pyoa/{s}/fill'])} / {last}"
        return cell

    row("pyoa `bose` `cmj`: per value / one fill per pixel / prepared", paths("bose", True))
    row("pyoa `cmjnd`, strength 3: the same", paths("cmjnd"))
    row("pyoa `bush`, strength 3: the same", paths("bush"))
    row("pyoa `faure` / `pmj02` / `sobol`, per value",
        lambda v, r, rep: " / ".join(ns(v[f"pyoa/{s}/scalar"]) for s in ("faure", "pmj02", "sobol")))
    row("OpenQMC PMJ, 1 / **2** / 4 values per draw",
        lambda v, r, rep: f"{ns(v['openqmc/pmj/scalar/1'])} / **{ns(v['openqmc/pmj/scalar/2'])}** / "
                          f"{ns(v['openqmc/pmj/scalar/4'])}")
    row("OpenQMC Sobol, 2 per draw", lambda v, r, rep: ns(v["openqmc/sobol/scalar/2"]))
    row("**Bose / OpenQMC PMJ (2D draws)**: prepared", lambda v, r, rep: times(rep["headline_prepared"], bold=True))
    row("the same: one fill per pixel", lambda v, r, rep: times(rep["headline_fill"]))
    row("the same: per value", lambda v, r, rep: times(rep["headline"]))
    row("prepared against PMJ drawn 1 / 4 per call",
        lambda v, r, rep: " / ".join(times(r[f"pyoa/bose/prepared / openqmc/pmj/scalar/{k}"], spread=False)
                                     for k in (1, 4)))
    p = [r["headline_prepared"]["median"] for r in reps]
    p4 = [r["ratios"]["pyoa/bose/prepared / openqmc/pmj/scalar/4"]["median"] for r in reps]
    fill = [r["headline_fill"]["median"] for r in reps]
    one = [r["headline"]["median"] for r in reps]
    sob = [r["ratios"]["pyoa/sobol/scalar / openqmc/sobol/scalar/2"]["median"] for r in reps]
    names = [_kind(r) for r in reps]
    out += ["", f"Bose's prepared bulk path costs {' and '.join(f'{x:.2f}x ({n})' for x, n in zip(p, names))} an "
                f"OpenQMC PMJ value drawn two at a time, {' and '.join(f'{x:.2f}x' for x in p4)} one drawn four at a "
                f"time (its cheapest); one fill per pixel costs {min(fill):.1f}-{max(fill):.1f}x, one value per call "
                f"{min(one):.0f}-{max(one):.0f}x. pyoa's own `sobol` costs {min(sob):.1f}-{max(sob):.1f}x OpenQMC's "
                "Sobol per value."]
    return "\n".join(out)


def openqmc_goal() -> str:
    """The OpenQMC row of docs/performance.md's goals table (a cell's text)."""
    reps = [load(p) for p in OPENQMC]
    flags = " ".join(f for f in reps[0]["compiler"]["flags"] if f.startswith(("-O", "-march")))

    def both(key: str, bold: bool = False, d: int = 2) -> str:
        b = "**" if bold else ""
        return b + " / ".join(f"{r[key]['median']:.{d}f}x" for r in reps) + b

    return (f"{cpu_short(reps[0]['machine'])}, CPU time, median of {reps[0]['config']['rounds']} per-round ratios, "
            f"{' / '.join(_compiler(r, major=True) for r in reps)} `{flags}`: bulk path prepared once per image "
            f"(`pyoa_fill_prepare` + `pyoa_fill_pixel`) {both('headline_prepared', bold=True)}; one "
            f"`pyoa_sampler_fill` per pixel {both('headline_fill', d=1)}; one stateless `pyoa_sampler_value` per "
            f"value {both('headline', d=1)} (`benchmarks/results/openqmc.md`, `openqmc-clang.md`)")


# ---------------------------------------------------------------------------
# bench_generate.py: benchmarks/results/generate-*.json

#: The vector path with the peers in the same run (AMD EPYC Zen 4).
GENERATE_VECTOR = RESULTS / "generate-vector.json"
#: The same script on an NVIDIA H100 through its OpenCL driver, with the kernels of the time.
GENERATE_H100 = RESULTS / "generate-h100.json"
#: The runs of the NumPy backend on the AVX2 EPYC (the reused-array case): their range is quoted.
GENERATE_NUMPY = tuple(RESULTS / f for f in ("generate.json", "generate-numpy.json", "generate-mitsuba.json"))
REQUIRED = "bose-cmj-121x10"


def _case_rate(report: dict, backend: str, case: str = REQUIRED) -> float:
    (row,) = [r for r in report["results"] if r["case"] == case and r["backend"] == backend]
    return row["median_values_per_s"]


def _peer(report: dict, name: str) -> float:
    (p,) = [p for p in report["peers"] if p["name"] == name and p["status"] == "ok"]
    return p["values_per_s"]


def mvals(v: float) -> str:
    """M values/s as the README shows them: 1,639; 312; 0.70."""
    m = v / 1e6
    return f"{m:,.0f}" if m >= 10 else f"{m:.2f}"


def generate_peers() -> str:
    """The README's table: Bose `cmj` from pyoa's backends beside Mitsuba's and SciPy's samplers."""
    vec = load(GENERATE_VECTOR)
    m = vec["machine"]
    opencl = _case_rate(vec, "opencl")
    numpy = [_case_rate(load(p), "numpy") / 1e6 for p in GENERATE_NUMPY]
    mitsuba = next(p["details"]["version"] for p in vec["peers"] if p["name"] == "mitsuba orthogonal")
    return "\n".join([
        f"Bose `cmj`, 65,536 pixels x 121 spp x 10 dims into a reused array, on an {cpu_name(m['cpu_model'])} of "
        f"family {m['cpu_family']} model {m['cpu_model_number']} ({m['cpu_isa']}), {m['cpu_count']} cores, unless a "
        f"row says otherwise; Mitsuba and SciPy were measured side by side with pyoa in one run "
        f"({vec['machine']['date_utc'][:10]}, `benchmarks/results/generate-vector.md`; `docs/performance.md`):",
        "",
        "| | M values/s |",
        "|---|---:|",
        f"| pyoa, OpenCL on PoCL ({m['cpu_count']} cores; kernels specialized per request shape) | {mvals(opencl)} "
        f"({opencl / _case_rate(vec, 'fill'):.2f} of `ndarray.fill`) |",
        f"| pyoa, NumPy fallback (AVX2 EPYC, earlier run) | {min(numpy):.0f}-{max(numpy):.0f} |",
        f"| pyoa, OpenCL on an NVIDIA H100 (earlier kernels) | {mvals(_case_rate(load(GENERATE_H100), 'opencl'))} |",
        f"| Mitsuba {mitsuba} `orthogonal` sampler (Dr.Jit LLVM) | {mvals(_peer(vec, 'mitsuba orthogonal'))} |",
        f"| Mitsuba {mitsuba} `multijitter` / `ldsampler` | {mvals(_peer(vec, 'mitsuba multijitter'))} / "
        f"{mvals(_peer(vec, 'mitsuba ldsampler'))} |",
        f"| scipy `qmc.LatinHypercube(strength=2)` | {mvals(_peer(vec, 'scipy LatinHypercube(strength=2)'))} |",
    ])


def generate_goal() -> str:
    """The first row of docs/performance.md's goals table: the vector path against fill and Mitsuba (a cell)."""
    vec = load(GENERATE_VECTOR)
    opencl = _case_rate(vec, "opencl")
    return (f"{cpu_name(vec['machine']['cpu_model'])} {vec['machine']['cpu_family']}/"
            f"{vec['machine']['cpu_model_number']}, [vector path](#the-vector-path-kernels-specialized-per-shape): "
            f"**{opencl / 1e9:.2f}e9 values/s = {opencl / _case_rate(vec, 'fill'):.3f} of fill**, "
            f"**{opencl / _peer(vec, 'mitsuba orthogonal'):.1f}x** Mitsuba's `orthogonal` in the same run")


#: docs/performance.md's vector-path table: (case, label, bold). Bush and CMJND at strength 3 are left out:
#: they took the table path after this run, and the run that measured them so was not kept.
VECTOR_ROWS = (("bose-cmj-121x10", "**Bose s=11 `cmj`** (required)", True),
               ("bose-centered-121x10", "Bose s=11 `centered`", False),
               ("bose-mj-121x10", "**Bose s=11 `mj`**", True),
               ("bose-j-121x10", "**Bose s=11 `j`**", True),
               ("bose-gf-cmj-64x10", "Bose over GF(8), 64 spp `cmj`", False),
               ("bush-gf-cmj-256x10", "Bush over GF(4) t=4, 256 spp", False),
               ("ak-cmj-98x10", "Addelman-Kempthorne q=7, 98 spp", False),
               ("bosebush-cmj-128x10", "Bose-Bush s=8, 128 spp", False),
               ("jittered2d-121x10", "`jittered2d` 11 x 11", False),
               ("cmj2d-121x10", "`cmj2d` 11 x 11", False))
VECTOR_UNCHANGED = ("random-121x10", "sobol-128x10", "sobol02-128x10", "halton-121x10")


def _mv(v: float) -> str:
    """M values/s to three figures: 1,639; 383; 82; 14.7."""
    m = v / 1e6
    return f"{m:,.0f}" if m >= 20 else f"{m:.1f}" if m >= 1 else f"{m:.2f}"


def generate_vector() -> str:
    """docs/performance.md, "The vector path": every case of the run against fill, and the peers."""
    vec = load(GENERATE_VECTOR)
    m = vec["machine"]
    fill = {r["case"]: r["median_values_per_s"] for r in vec["results"] if r["backend"] == "fill"}
    ocl = {r["case"]: r["median_values_per_s"] for r in vec["results"] if r["backend"] == "opencl"}
    mitsuba = next(p["details"]["version"] for p in vec["peers"] if p["name"] == "mitsuba orthogonal")
    out = [f"`bench_generate.py --cases all --backends opencl,fill` with the peers "
           f"(`benchmarks/results/generate-vector.{{json,md}}`, {vec['machine']['date_utc'][:10]}, "
           f"{cpu_name(m['cpu_model'])} of family {m['cpu_family']} model {m['cpu_model_number']}, "
           f"{m['cpu_count']} cores), 65,536 pixels into a reused array, median of {vec['config']['repeats']}; "
           "M values/s and the fraction of fill in the same run:", "",
           "| case | M values/s | of fill |", "|---|---:|---:|"]
    for case, label, bold in VECTOR_ROWS:
        b = "**" if bold else ""
        out.append(f"| {label} | {b}{_mv(ocl[case])}{b} | {b}{ocl[case] / fill[case]:.3f}{b} |")
    out.append("| `random`, `sobol`, `sobol02`, `halton` (unchanged kernels) | "
               + " / ".join(_mv(ocl[c]) for c in VECTOR_UNCHANGED) + " | |")
    out.append(f"| fill (`ndarray.fill`) | {min(fill.values()) / 1e6:,.0f}-{max(fill.values()) / 1e6:,.0f} | 1 |")
    req, req_fill = ocl[REQUIRED], fill[REQUIRED]

    def peer(name: str) -> float:
        return _peer(vec, name)

    def vs(name: str) -> str:
        r = req / peer(name)
        return f"{r:,.0f}x" if r >= 100 else f"{r:.1f}x" if r >= 1 else f"{r:.2f}x"

    def of(name: str) -> str:
        f = peer(name) / req_fill
        return f"{f:.3f}" if f >= 0.001 else f"{f:.4f}"

    out += [f"| Mitsuba {mitsuba} `orthogonal` | {_mv(peer('mitsuba orthogonal'))} (pyoa `cmj` "
            f"{vs('mitsuba orthogonal')}) | {of('mitsuba orthogonal')} |",
            f"| Mitsuba `multijitter` / `ldsampler` | {_mv(peer('mitsuba multijitter'))} / "
            f"{_mv(peer('mitsuba ldsampler'))} (pyoa {vs('mitsuba multijitter')} / {vs('mitsuba ldsampler')}) | "
            f"{of('mitsuba multijitter')} / {of('mitsuba ldsampler')} |",
            f"| Mitsuba `independent` | {_mv(peer('mitsuba independent'))} (pyoa {vs('mitsuba independent')}) | "
            f"{of('mitsuba independent')} |",
            f"| SciPy `LatinHypercube(strength=2)` | {_mv(peer('scipy LatinHypercube(strength=2)'))} (pyoa "
            f"{vs('scipy LatinHypercube(strength=2)')}) | {of('scipy LatinHypercube(strength=2)')} |"]
    return "\n".join(out)
