#!/usr/bin/env python3
"""Generate ``docs/results.md``: the evidence page (projections, spectra,
convergence studies and render comparisons), with every figure it shows.

Everything is computed here, from the public API and the ``pyoa`` commands;
nothing is copied from elsewhere. Figures and tables go to ``docs/results/``.
The render study's section is a marked section (``benchmarks/marked.py``),
and so are the sections of ``faure_study.py`` and ``mitsuba_study.py``,
which this script keeps as they stand (``benchmarks/update_docs.py`` writes
all three again from their saved results, in seconds).
A full run takes about 8 minutes on a 2-core machine (6 when the render
references in docs/results/ already exist, which it then reuses; it prints the time of each part); ``--quick`` makes small versions of everything in about a
minute (marked as such on the page, for checking the script itself).

Usage::

    python benchmarks/make_results.py            # full page
    python benchmarks/make_results.py --quick    # smoke run
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))


sys.path.insert(0, str(REPO / "benchmarks"))

import marked  # noqa: E402

from pyoa import analysis, catalogue  # noqa: E402
from pyoa.util.atomic import atomic_path  # noqa: E402
from pyoa.plots import error_spectra, projections, spectrum  # noqa: E402

OUT = REPO / "docs" / "results"
#: Bose and every comparison sampler of the catalogue (the paper's six, then
#: pbrt-v4's zsobol and pmj02), at the count nearest 121 (128 for the
#: power-of-two samplers).
LINEUP = [(n, catalogue.nearest_spp(n, 121)) for n in ("bose", *catalogue.names("baseline"))]
#: The padded 2D samplers, which stratify pairs of dimensions only.


#: Convergence cases (integrand, dimensions): smooth and discontinuous, 2 to 10
#: dimensions; `pairwise` couples every pair of dimensions (also the pairs that
#: padding leaves unstratified), `additive` none (the control case).
CASES = [("gaussian", 2), ("halfspace", 2), ("gaussian", 4), ("pairwise", 4), ("ball", 4),
         ("additive", 6), ("diagonal-halfspace", 7), ("pairwise", 10)]
CASES_QUICK = [("gaussian", 2), ("pairwise", 4)]


#: What the convergence table shows (checked against the measured slopes
#: when the page was last generated; re-read it after changing the cases).
INTERPRETATION = """\
What the slopes show:

- **Integrands that couple dimensions across pairs** (`pairwise`: every pair
  of dimensions interacts, including the pairs that padding leaves
  unstratified). This is the paper's claim, and it holds. Bose converges at
  about N^-2.1 in 4D and N^-2.3 in 10D. The padded jittered, CMJ and (0,2)
  samplers stay near N^-1 to N^-1.3, because their cross-pair projections
  are random. Owen-scrambled Sobol is steeper still (N^-2.5 to -2.8), and
  Halton is close to Bose.
- **Smooth product integrands in more dimensions than the strength**
  (`gaussian` in 4D). This is where strength-2 OAs do *not* help: every
  sampler but the high-dimensional QMC ones converges at about N^-1. Sobol
  (-1.7) and Halton (-1.6) win, as the paper notes for high-dimensional QMC.
- **In 2D** (`gaussian`, `halfspace`), every stratified sampler beats random.
  Smooth integrands reach N^-2 (jittered, Halton) to N^-3 (CMJ, Bose, with
  their 1D Latin hypercube). Discontinuous ones reach about N^-1.5, the rate
  of an edge through a stratified square.
- **Additive integrands** (`additive`, the control case) depend only on 1D
  projections. There every Latin-hypercube sampler (`cmj2d`, `sobol02`,
  `bose`, `sobol`) is about equally good, near N^-3, and OAs have nothing
  to add.
- **Discontinuities in 4 to 7 dimensions** (`ball`, `diagonal-halfspace`):
  every method stays near N^-1. Halton and Sobol are marginally better.
- **pbrt-v4's samplers** (`zsobol`, `pmj02`) are padded (0,2) samplers:
  like `sobol02` they reach N^-2.5 to N^-3 on 2D and additive integrands,
  and like every padded sampler they fall to about N^-1 once an integrand
  couples dimensions across pairs (`pairwise`: -1.07 in 4D, -1.02 and -1.06
  in 10D), where Bose keeps N^-2.1 to N^-2.3. Where Bose does not beat them:
  2D and additive integrands (their nets are as good or better) and the
  strength-exceeding cases (`gaussian` 4D, `ball` 4D), where all three are
  near N^-1. zsobol's gain is elsewhere: its per-pixel error is the same,
  but distributed as blue noise across the image (next section).
"""


class Page:
    def __init__(self, quick: bool):
        self.quick = quick
        self.lines = ["# Results", ""]
        self.t0 = time.perf_counter()
        self.reused: list[str] = []  # render references taken from an earlier run
        if quick:
            self.lines += ["**QUICK RUN: small sizes, for checking the script; not the published figures.**", ""]

    def add(self, *lines: str) -> None:
        self.lines += list(lines)

    def part(self, title: str):
        print(f"== {title} ({time.perf_counter() - self.t0:.0f} s so far)", flush=True)
        self.add(f"## {title}", "")


def rel(path: Path) -> str:
    return str(path.relative_to(REPO / "docs"))


def part_projections(page: Page) -> None:
    page.part("2D projections")
    page.add("Every 2D projection of one pixel's point set (6 dimensions, seed 0), with the coarse strata "
             "drawn. Bose (s = 11) has one point in each of the 11 x 11 cells of *every* pair of dimensions; "
             "padded jittered sampling stratifies only the pairs (0,1), (2,3), (4,5) and is unstratified "
             "across them; Sobol is a (t,m,s)-net whose pairs are stratified in elementary intervals but "
             "not on a square grid.", "")
    for name, spp in [("bose", 121), ("jittered2d", 121), ("sobol", 128)]:
        out = OUT / f"proj-{name}.png"
        projections(name, spp=spp, dims=6, seed=0, out=str(out), size=500 if page.quick else 900)
        page.add(f"![{name} projections]({rel(out)})", "")


def part_spectra(page: Page) -> None:
    page.part("Power spectra")
    trials = 16 if page.quick else 256
    page.add(f"Expected power spectrum of the projection onto dimensions (0,1) and (1,2), averaged over "
             f"{trials} randomizations, with its radial mean (white noise = 1). Low power near the centre "
             "means the projection is stratified. For the padded samplers (1,2) straddles two pairs and is "
             "nearly white; for Bose every pair is stratified on its 11 x 11 grid (as low as a jittered pair), "
             "and the primary pair (0,1) is a full CMJ pattern (lower still). The bright lines along the axes "
             "of the `cmj` spectra come from the correlated sub-strata (Kensler's CMJ shows the same).", "",
             "| sampler | spp | low-frequency power, dims 0,1 | dims 1,2 |", "|---|---:|---:|---:|")
    figures = []
    for name, spp in LINEUP:
        lows = []
        for dims in [(0, 1), (1, 2)]:
            out = OUT / f"spectrum-{name}-{dims[0]}{dims[1]}.png"
            _, r, m = spectrum(name, spp=spp, dims=dims, trials=trials, freq=32 if page.quick else 48,
                               out=str(out), size=500 if page.quick else 800)
            lows.append(float(m[r <= 4].mean()))
            figures.append((name, dims, out))
        page.add(f"| {name} | {spp} | {lows[0]:.3f} | {lows[1]:.3f} |")
    page.add("", "(mean radial power over frequencies 1 <= |k| <= 4)", "")
    for name, dims, out in figures:
        if dims == (0, 1) or name in ("jittered2d", "bose"):
            page.add(f"![{name} spectrum, dims {dims[0]},{dims[1]}]({rel(out)})", "")


def part_convergence(page: Page) -> dict:
    page.part("Convergence")
    trials = 16 if page.quick else 128
    targets = [16, 64, 256] if page.quick else [16, 64, 256, 1024, 4096]
    names = [n for n, _ in LINEUP]
    slopes = {}
    page.add(f"Variance of the estimate of known integrals over {trials} independent randomizations "
             f"against the sample count (nearest valid count of each sampler to {targets}), with the fitted "
             "slope of log variance against log N (random sampling: -1; the steeper the better).", "")
    cases = CASES_QUICK if page.quick else CASES
    results = []
    for integrand, d in cases:
        res = analysis.convergence(names, integrand, d, targets, trials=trials, seed=0)
        tag = f"{integrand}-{d}d"
        out = OUT / f"convergence-{tag}.png"
        res.plot(str(out))
        slopes[tag] = res.slope
        results.append((tag, integrand, d, res, out))
    page.add("### Fitted slopes", "", "| integrand | d | " + " | ".join(names) + " |",
             "|---|---:|" + "---:|" * len(names))
    for tag, integrand, d, res, out in results:
        best = min(res.slope.values())
        cells = [f"**{res.slope[n]:.2f}**" if res.slope[n] == best else f"{res.slope[n]:.2f}" for n in names]
        page.add(f"| {integrand} | {d} | " + " | ".join(cells) + " |")
    page.add("", INTERPRETATION, "")
    for tag, integrand, d, res, out in results:
        page.add(f"### {integrand}, {d} dimensions", "", res.table(), "", f"![convergence {tag}]({rel(out)})", "")
    return slopes


def part_error_spectra(page: Page) -> None:
    page.part("Screen-space error: blue noise")
    size, seeds = (32, 2) if page.quick else (64, 8)
    page.add(f"Each pixel of a {size} x {size} image estimates the area of a disk (the `ball` integrand in 2D, "
             "dimensions 0 and 1) with its own samples; the periodogram of the error image, averaged over "
             f"{seeds} seeds and divided by the error variance, is flat at 1 when the pixels' errors are "
             "independent. `zsobol` (Ahmed and Wonka 2020) orders the pixels along a scrambled Z curve so that "
             "neighbouring pixels' samples together form larger nets: their errors cancel, the spectrum is "
             "dark at low frequencies (blue noise), and a blur or a denoiser removes more of the error. The "
             "other samplers randomize every pixel independently, so their error is white; per-pixel RMSE is "
             "what the sampler's own stratification gives.", "",
             "| sampler | spp | low-frequency power (frequencies 1 to size/8) | per-pixel RMSE |", "|---|---:|---:|---:|")
    shown = []
    for spp in (16, 64):
        for name, _ in LINEUP:
            n = catalogue.nearest_spp(name, spp)
            res = analysis.error_spectrum(name, spp=n, size=size, seeds=seeds)
            page.add(f"| {name} | {n} | {res.low:.3f} | {res.rmse:.4g} |")
            if spp == 16 and name in ("zsobol", "sobol02", "pmj02", "bose"):
                shown.append(res)
    out = OUT / "error-spectra.png"
    error_spectra(shown, out=str(out), size=800 if page.quick else 1400)
    page.add("", f"![screen-space error spectra]({rel(out)})", "")


def part_renders(page: Page) -> None:
    """The render tables: a ``pyoa study`` over every sampler, counts and
    seeds, with intervals (``benchmarks/render_study.py``, which resumes a
    study already in docs/results/study and can rewrite this section alone)."""
    import render_study

    text = render_study.run(quick=page.quick, workers=2, seeds=8)
    page.add(marked.block(render_study.SECTION, text), "")


#: The sections other scripts write into the page: kept from the page as it was (empty on a new page).
KEPT = ("faure-study", "mitsuba-study")


def part_kept(page: Page, old: Path) -> None:
    text = old.read_text(encoding="utf-8") if old.exists() else ""
    have = marked.sections(text, str(old))
    for name in KEPT:  # markers and all, so that a hand edit stays visible to the docs test
        page.add(text[slice(*have[name].outer)] if name in have else marked.block(name, ""), "")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Generate docs/results.md and its figures.")
    ap.add_argument("--quick", action="store_true", help="small sizes, about a minute")
    ap.add_argument("--out", default=str(REPO / "docs" / "results.md"))
    args = ap.parse_args(argv)
    global OUT
    if args.quick:  # never overwrite the published figures with a smoke run
        OUT = OUT / "quick"
    OUT.mkdir(parents=True, exist_ok=True)
    page = Page(args.quick)
    part_projections(page)
    part_spectra(page)
    slopes = part_convergence(page)
    part_error_spectra(page)
    part_renders(page)
    part_kept(page, Path(args.out))
    total = time.perf_counter() - page.t0
    reused = (f" The render references of {', '.join(page.reused)} were reused from an earlier run "
              "(delete docs/results/*-reference.exr to re-render them: about 6 more minutes)."
              if page.reused else "")
    page.add("---", "", f"Generated by `python benchmarks/make_results.py{' --quick' if args.quick else ''}` "
             f"in {total / 60:.1f} minutes on a {__import__('os').cpu_count()}-CPU machine.{reused}", "")
    with atomic_path(args.out) as tmp:
        tmp.write_text("\n".join(page.lines))
    print(f"wrote {args.out} ({total:.0f} s)")
    for tag, s in slopes.items():
        print(tag, {k: round(v, 2) for k, v in s.items()})
    return 0


if __name__ == "__main__":
    sys.exit(main())
