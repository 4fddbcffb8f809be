#!/usr/bin/env python3
"""The render tables of ``docs/results.md`` as ``pyoa study`` runs: every
sampler, 16 to 1024 spp, several seeds, with confidence intervals.

Runs ``pyoa study dof7d bounce9d deep cornell --samplers all --spp
16,64,256,1024 --seeds 8 --reference-spp 16384 --size 64 64 --workers 2
--out docs/results/study`` (the study resumes: rows already in
``study.csv`` are not rendered again, and finished references are reused),
then writes the "Renders" section of ``docs/results.md`` between
``<!-- render-study:begin -->`` and ``<!-- render-study:end -->``: the
study's tables and figures, and verdicts computed from its numbers (where
bose beats the best padded sampler, where sobol beats bose, and whether the
paper's claim holds at each count with its interval).

``--quick`` makes a small study under ``docs/results/quick/study`` (git
ignored) and prints the section instead of writing the page.

Usage::

    python benchmarks/render_study.py                 # the study (resumes) and the page section
    python benchmarks/render_study.py --workers 2 --seeds 8
    python benchmarks/render_study.py --quick
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import REPO, machine, replace_section  # noqa: E402

import pyoa  # noqa: E402
from pyoa import commands  # noqa: E402
from pyoa.study import PADDED, cells, read_rows  # noqa: E402

RESULTS_MD = REPO / "docs" / "results.md"
BEGIN, END = "<!-- render-study:begin -->", "<!-- render-study:end -->"
#: What each scene exercises; its dimension count and path length are read from the renderer's own
#: layout (dimensions), never written here, so the page cannot drift from what `pyoa render` prints.
SCENES = {
    "dof7d": "pixel, lens, time, light (direct lighting, depth of field, motion blur)",
    "bounce9d": "one bounce of indirect light",
    "deep": "glossy and mirror surfaces, long paths",
    "cornell": "Mitsuba's Cornell box",
}


def about(scene: str) -> str:
    """``SCENES[scene]`` with the dimensions and longest path of the scene's layout (as ``pyoa render``
    prints them)."""
    from pyoa.render.render import plan
    from pyoa.render.scene import load

    layout = plan(load(scene), sampler="random", spp=1, width=1, height=1).layout
    return f"{layout.dims} dimensions, paths of up to {layout.max_depth} segments; {SCENES[scene]}"


def verdicts(table: dict) -> list[str]:
    """Plain sentences from the study's numbers: bose against the best padded
    sampler and against sobol, per scene, across the counts."""
    from pyoa.analysis.statistics import ratio_ci

    lines = []
    claim = {"holds": [], "does not hold": [], "undecided": []}
    high = {"wins": [], "ties": [], "loses": []}  # bush at strength >= 3 against bose
    for scene, by in table.items():
        if "bose" not in by:
            continue
        parts, sob = [], []
        for asked, c in sorted(by["bose"].items()):
            padded = [(by[n][asked], n) for n in PADDED if asked in by.get(n, {})]
            if padded:
                best, name = min(padded, key=lambda cn: cn[0].ci()[0])
                r, lo, hi = ratio_ci(c.values, best.values, shift_a=c.noise, shift_b=best.noise)
                word = "holds" if hi < 1 else ("does not hold" if lo > 1 else "undecided")
                claim[word].append(f"{scene} {asked}")
                parts.append(f"{asked} spp {r:.2f} [{lo:.2f}, {hi:.2f}] vs {name}")
            s = by.get("sobol", {}).get(asked)
            if s is not None:
                r, lo, hi = ratio_ci(c.values, s.values, shift_a=c.noise, shift_b=s.noise)
                sob.append(f"{asked} spp {r:.2f} [{lo:.2f}, {hi:.2f}]")
        strength3 = []
        for asked, c in sorted(by.get("bush", {}).items()):
            b = by["bose"].get(asked)
            if b is not None:
                r, lo, hi = ratio_ci(c.values, b.values, shift_a=c.noise, shift_b=b.noise)
                word = "wins" if hi < 1 else ("loses" if lo > 1 else "ties")
                # the strength bush takes at this count (the largest t with N = s^t; every scene has >= 7 dims)
                t = pyoa.sampler("bush", spp=c.spp, dims=7).strength
                strength3.append(f"{asked} spp (t = {t}) {r:.2f} [{lo:.2f}, {hi:.2f}] ({word})")
                if t >= 3:
                    high[word].append(f"{scene} {asked} (s = {pyoa.sampler('bush', spp=c.spp, dims=7).s}, t = {t})")
        lines.append(f"- **{scene}**: bose / best padded: {'; '.join(parts)}. bose / sobol: {'; '.join(sob)}."
                     + (f" bush / bose: {'; '.join(strength3)}." if strength3 else ""))
    total = sum(len(v) for v in claim.values())
    lines += ["", f"The paper's claim (a strength-2 OA beats padded 2D samplers) at each scene and count, "
                  f"judged by the 95 % interval of the ratio: it holds (interval below 1) at {len(claim['holds'])} "
                  f"of {total}, fails (interval above 1) at {len(claim['does not hold'])}"
                  + (f" ({', '.join(claim['does not hold'])})" if claim["does not hold"] else "")
                  + f", and the interval contains 1 at {len(claim['undecided'])}"
                  + (f" ({', '.join(claim['undecided'])})" if claim["undecided"] else "") + "."]
    if any(high.values()):
        lines += ["", "Strength 3 and more (`bush` where its count is s^t with t >= 3) against `bose` at the same "
                      f"count: it wins at {len(high['wins'])}"
                      + (f" ({', '.join(high['wins'])})" if high["wins"] else "")
                      + f", ties at {len(high['ties'])}" + (f" ({', '.join(high['ties'])})" if high["ties"] else "")
                      + f" and loses at {len(high['loses'])}" + (f" ({', '.join(high['loses'])})" if high["loses"] else "")
                      + ". At these counts a higher strength means fewer strata per axis (s = 4 at 64 and 256 "
                        "samples, against `bose`'s 8 and 16) and blocks of s + 1 = 5 dimensions, so every "
                        "pair it stratifies is coarser and most pairs of a path fall across blocks, where "
                        "both samplers pair at random (docs/spec.md section 6). These scenes' error comes "
                        "mostly from pairs of dimensions (pixel and lens, light position), which `bose` "
                        "stratifies on a finer grid. A triple pays only where three dimensions of one block "
                        "interact more than pairs do (the `triples0` integrand of the faure section below); "
                        "no render of this study is such a case at these counts, nor is any scene of the "
                        "Mitsuba study below (its glossy scene included)."]
    return lines


def section(out: Path, meta: dict) -> str:
    """The page section from the study's files."""
    md = (out / "study.md").read_text()
    rows = read_rows(out / "study.csv")
    settings = json.loads((out / "study.json").read_text())
    noise = {}
    for name, s in settings["scenes"].items():
        noise[name] = tuple(s["noise"]) if s.get("noise") else None
    rel = out.relative_to(REPO / "docs") if out.is_relative_to(REPO / "docs") else out
    body = md.split("\n", 2)[2] if md.startswith("# ") else md  # drop the study's own title
    # the study's per-scene headings become this page's subsections
    body = body.replace("\n## ", "\n### ")
    for scene in SCENES:
        body = body.replace(f"### {scene}\n", f"### `{scene}`: {about(scene)}\n\n![{scene}]({rel}/study-{scene}.png)\n",
                            1)
    table = cells(rows, noise)
    lines = [BEGIN, "## Renders", "",
             f"`pyoa study` (`benchmarks/render_study.py`): {meta['what']} Rows: `{rel}/study.csv` (one per "
             f"render), settings: `{rel}/study.json`. {meta['timing']}", "",
             f"![error against spp]({rel}/study.png)", "",
             "In plain words (ratios of noise-corrected mean image relMSE with 95 % intervals; below 1 bose "
             "has less error):", "", *verdicts(table), "", body.strip(), "", END]
    return "\n".join(lines) + "\n"


def run(*, quick: bool = False, workers: int = 2, seeds: int = 8, report_only: bool = False) -> str:
    """Run (or resume) the study and return the page section."""
    out = REPO / "docs" / "results" / ("quick/study" if quick else "study")
    out.parent.mkdir(parents=True, exist_ok=True)
    scenes = ["dof7d", "cornell"] if quick else list(SCENES)
    size, spp, ref_spp = ("16", "16,64", "1024") if quick else ("64", "16,64,256,1024", "16384")
    seeds_ = "3" if quick else str(seeds)
    argv = ["study", *scenes, "--samplers", "all", "--spp", spp, "--seeds", seeds_, "--reference-spp", ref_spp,
            "--size", size, size, "--out", str(out), "-q"]
    if workers > 0:
        argv += ["--workers", str(workers)]
    if not report_only:
        rc = commands.main(argv)
        if rc:
            raise SystemExit(rc)
    settings = json.loads((out / "study.json").read_text())
    runs = settings.get("runs", [])
    meta = machine()
    what = (f"{len(scenes)} scenes at {size} x {size}, every sampler, spp {spp}, {seeds_} seeds, references of "
            f"{ref_spp} spp made by `pyoa reference` passes on the same cluster; command "
            f"`pyoa {' '.join(a for a in argv if a != '-q').replace(str(REPO) + '/', '')}`.")
    spent = sum(r["seconds"] for r in runs)
    where = "; ".join(sorted({r["where"] for r in runs if r["rendered"]})) or "?"
    when = (f"The study (references included) took {spent / 60:.1f} minutes in {len(runs)} run(s) on {where}, "
            f"{meta['cpu']} ({meta['cpu_count']} cores).")
    return section(out, {"what": what, "timing": when})


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="a small study, printed, not written to the page")
    ap.add_argument("--workers", type=int, default=2, help="local Dask workers (default 2; 0: in-process)")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--report-only", action="store_true", help="write the section from the saved study")
    args = ap.parse_args(argv)
    text = run(quick=args.quick, workers=args.workers, seeds=args.seeds, report_only=args.report_only)
    if args.quick:
        print(text)
    else:
        replace_section(RESULTS_MD, BEGIN, END, text, before="\n<!-- faure-study:begin -->")
        print(f"wrote the Renders section of {RESULTS_MD}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
