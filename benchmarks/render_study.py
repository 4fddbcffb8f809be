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

The section is a marked section (``benchmarks/marked.py``): its begin
marker records a digest of the text, and ``benchmarks/update_docs.py``
writes it again from the saved study (``--report-only`` does the same for
this section alone), with the README's table of headline ratios
(:func:`headline`). The study's command and the CPU it ran on are kept
beside its rows, in ``benchmark.json``, so that the section made again on
another machine, or with other defaults, still says what was rendered where.

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

from common import REPO, machine, write_text  # noqa: E402

import pyoa  # noqa: E402
from pyoa import commands  # noqa: E402
from pyoa.study import PADDED, cells, read_rows  # noqa: E402

#: The marked sections this study writes: the results page's "Renders", the README's headline ratios.
SECTION, HEADLINE = "render-study", "render-study-headline"
STUDY = REPO / "docs" / "results" / "study"
#: What each scene exercises; its dimension count and path length are read from the renderer's own
#: layout (dimensions), never written here, so the page cannot drift from what `pyoa render` prints.
SCENES = {
    "dof7d": "pixel, lens, time, light (direct lighting, depth of field, motion blur)",
    "bounce9d": "one bounce of indirect light",
    "deep": "glossy and mirror surfaces, long paths",
    "cornell": "Mitsuba's Cornell box",
}


def layout(scene: str):
    """The renderer's layout of ``scene`` (its dimensions and longest path, as ``pyoa render`` prints them)."""
    from pyoa.render.render import plan
    from pyoa.render.scene import load

    return plan(load(scene), sampler="random", spp=1, width=1, height=1).layout


def about(scene: str) -> str:
    """``SCENES[scene]`` with the dimensions and longest path of the scene's layout."""
    lay = layout(scene)
    return f"{lay.dims} dimensions, paths of up to {lay.max_depth} segments; {SCENES[scene]}"


def bose_ratios(by: dict) -> dict:
    """For one scene's cells (sampler -> spp asked -> cell), at each count bose has: bose's noise-corrected
    mean relMSE over the best padded sampler's (the one whose interval's lower end is lowest), as
    ``(name, ratio, lo, hi)``, and over sobol's, as ``(ratio, lo, hi)``: 95 % intervals of
    :func:`pyoa.analysis.statistics.ratio_ci` (the delta method on the two means)."""
    from pyoa.analysis.statistics import ratio_ci

    out = {}
    for asked, c in sorted(by["bose"].items()):
        padded = [(by[n][asked], n) for n in PADDED if asked in by.get(n, {})]
        row = {}
        if padded:
            best, name = min(padded, key=lambda cn: cn[0].ci()[0])
            row["padded"] = (name, *ratio_ci(c.values, best.values, shift_a=c.noise, shift_b=best.noise))
        s = by.get("sobol", {}).get(asked)
        if s is not None:
            row["sobol"] = ratio_ci(c.values, s.values, shift_a=c.noise, shift_b=s.noise)
        out[asked] = row
    return out


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
        for asked, row in bose_ratios(by).items():
            if "padded" in row:
                name, r, lo, hi = row["padded"]
                word = "holds" if hi < 1 else ("does not hold" if lo > 1 else "undecided")
                claim[word].append(f"{scene} {asked}")
                parts.append(f"{asked} spp {r:.2f} [{lo:.2f}, {hi:.2f}] vs {name}")
            if "sobol" in row:
                r, lo, hi = row["sobol"]
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


def study_table(out: Path) -> dict:
    """The study's cells (scene -> sampler -> spp asked -> cell) from its rows, with each reference's noise."""
    settings = json.loads((out / "study.json").read_text())
    noise = {name: tuple(s["noise"]) if s.get("noise") else None for name, s in settings["scenes"].items()}
    return cells(read_rows(out / "study.csv"), noise)


def section(out: Path) -> str:
    """The page section from the study's files: what was rendered where from ``benchmark.json``, the time
    from ``study.json``, the tables from ``study.md`` and the verdicts from ``study.csv``."""
    md = (out / "study.md").read_text()
    settings = json.loads((out / "study.json").read_text())
    m = json.loads((out / "benchmark.json").read_text())
    runs = settings.get("runs", [])
    spent = sum(r["seconds"] for r in runs)
    where = "; ".join(sorted({r["where"] for r in runs if r["rendered"]})) or "?"
    timing = (f"The study (references included) took {spent / 60:.1f} minutes in {len(runs)} run(s) on {where}, "
              f"{m['cpu']} ({m['cpu_count']} cores).")
    rel = out.relative_to(REPO / "docs") if out.is_relative_to(REPO / "docs") else out
    body = md.split("\n", 2)[2] if md.startswith("# ") else md  # drop the study's own title
    # the study's per-scene headings become this page's subsections
    body = body.replace("\n## ", "\n### ")
    for scene in SCENES:
        body = body.replace(f"### {scene}\n", f"### `{scene}`: {about(scene)}\n\n![{scene}]({rel}/study-{scene}.png)\n",
                            1)
    lines = ["## Renders", "",
             f"`pyoa study` (`benchmarks/render_study.py`): {describe(m['argv'])} Rows: `{rel}/study.csv` (one per "
             f"render), settings: `{rel}/study.json`. {timing}", "",
             f"![error against spp]({rel}/study.png)", "",
             "In plain words (ratios of noise-corrected mean image relMSE with 95 % intervals; below 1 bose "
             "has less error):", "", *verdicts(study_table(out)), "", body.strip()]
    return "\n".join(lines) + "\n"


#: The README's headline rows: (scene, spp asked).
HEADLINE_ROWS = (("dof7d", 16), ("dof7d", 1024), ("bounce9d", 1024), ("deep", 1024), ("cornell", 1024))


def headline(out: Path = STUDY) -> str:
    """The README's table: bose over the best padded 2D sampler and over sobol at :data:`HEADLINE_ROWS`."""
    table = study_table(out)
    lines = ["| scene | spp | bose / best padded 2D sampler | bose / sobol |", "|---|---:|---:|---:|"]
    ratios = {scene: bose_ratios(table[scene]) for scene in dict(HEADLINE_ROWS)}
    for scene, asked in HEADLINE_ROWS:
        row = ratios[scene][asked]
        (_, r, lo, hi), (rs, los, his) = row["padded"], row["sobol"]
        lines.append(f"| {scene} ({layout(scene).dims}D) | {asked} | {r:.2f} [{lo:.2f}, {hi:.2f}] | "
                     f"{rs:.2f} [{los:.2f}, {his:.2f}] |")
    return "\n".join(lines)


def argv_for(quick: bool, workers: int, seeds: int) -> list[str]:
    """The ``pyoa study`` command line of the study (published, or ``quick``)."""
    out = (STUDY.parent / "quick" / "study" if quick else STUDY).relative_to(REPO)
    scenes = ["dof7d", "cornell"] if quick else list(SCENES)
    size, spp, ref_spp = ("16", "16,64", "1024") if quick else ("64", "16,64,256,1024", "16384")
    argv = ["study", *scenes, "--samplers", "all", "--spp", spp, "--seeds", "3" if quick else str(seeds),
            "--reference-spp", ref_spp, "--size", size, size, "--out", str(out), "-q"]
    return argv + (["--workers", str(workers)] if workers > 0 else [])


def describe(argv: list[str]) -> str:
    """What the study renders, in words, and its command."""
    opt = {k: argv[i + 1] for i, k in enumerate(argv) if k.startswith("--")}
    scenes = argv[1:argv.index("--samplers")]
    return (f"{len(scenes)} scenes at {opt['--size']} x {opt['--size']}, every sampler, spp {opt['--spp']}, "
            f"{opt['--seeds']} seeds, references of {opt['--reference-spp']} spp made by `pyoa reference` passes "
            f"on the same cluster; command "
            f"`pyoa {' '.join(a for a in argv if a != '-q')}`.")


def study(argv: list[str]) -> Path:
    """Run (or resume) the study of ``argv`` (its ``--out`` relative to the repository); its command and
    the CPU it ran on go to ``benchmark.json`` beside it."""
    i = argv.index("--out") + 1
    out = REPO / argv[i]
    out.parent.mkdir(parents=True, exist_ok=True)
    rc = commands.main([*argv[:i], str(out), *argv[i + 1:]])
    if rc:
        raise SystemExit(rc)
    meta = machine()
    write_text(out / "benchmark.json",
               json.dumps({"argv": argv, "cpu": meta["cpu"], "cpu_count": meta["cpu_count"]}) + "\n")
    return out


def run(*, quick: bool = False, workers: int = 2, seeds: int = 8, report_only: bool = False) -> str:
    """Run (or resume, or with ``report_only`` only read) the study; return the page section's text."""
    argv = argv_for(quick, workers, seeds)
    return section(REPO / argv[argv.index("--out") + 1] if report_only else study(argv))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="a small study, printed, not written to the page")
    ap.add_argument("--workers", type=int, default=2, help="local Dask workers (default 2; 0: in-process)")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--report-only", action="store_true", help="write the sections from the saved study")
    args = ap.parse_args(argv)
    if args.quick:
        print(run(quick=True, workers=args.workers, seeds=args.seeds, report_only=args.report_only))
        return 0
    if not args.report_only:
        study(argv_for(False, args.workers, args.seeds))
    import update_docs

    for page in update_docs.update(names=[SECTION, HEADLINE]):
        print(f"wrote {page}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
