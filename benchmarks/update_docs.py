#!/usr/bin/env python3
"""Write every marked section of the docs again from the results files, in seconds.

The docs show figures that benchmarks measured: render speed against
Mitsuba, generation speed against the peers, the C headers against
OpenQMC, the render study's ratios. Each such figure lives in one results
file (``benchmarks/results/``, ``docs/results/``) and reaches a page only
through a marked section (``benchmarks/marked.py``), whose text a function
makes from that file: :data:`SECTIONS` lists them, with the pages each goes
into. A benchmark that writes a results file calls :func:`after` (the study
scripts :func:`update`), so the pages change with the file; this script
does the same for every section without running any benchmark, and
``--check`` (what ``tests/test_marked_figures.py`` checks) says which
sections differ from what their results files give, or were edited by hand.

Text outside the markers (what a figure means, runs kept for history, a
figure no results file holds) is the author's, and is never touched.

Usage::

    python benchmarks/update_docs.py            # rewrite the sections that differ
    python benchmarks/update_docs.py --check    # list them and exit 1, writing nothing
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(HERE))

import figures  # noqa: E402
import marked  # noqa: E402

README = REPO / "README.md"
PERFORMANCE = REPO / "docs" / "performance.md"
RESULTS_PAGE = REPO / "docs" / "results.md"
STUDY = REPO / "docs" / "results" / "study"
FAURE = REPO / "docs" / "results" / "faure"
MITSUBA = REPO / "docs" / "results" / "mitsuba"


@dataclass(frozen=True)
class Entry:
    """A marked section: the ``pages`` it goes into, the results files or folders its text is made from
    (``sources``), the function that makes the text, and whether it sits inside a line (``inline``: a
    table cell, a sentence) rather than on lines of its own."""

    pages: tuple[Path, ...]
    sources: tuple[Path, ...]
    make: Callable[[], str]
    inline: bool = False

    def body(self) -> str:
        text = self.make()
        return text if self.inline else marked.block_body(text)


# The study scripts import pyoa's renderer and analysis: imported only when their sections are made.

def _render_study() -> str:
    import render_study

    return render_study.section(STUDY)


def _render_study_headline() -> str:
    import render_study

    return render_study.headline()


def _faure_study() -> str:
    import faure_study

    return faure_study.section_text(FAURE, {})


def _mitsuba_study() -> str:
    import mitsuba_study

    return mitsuba_study.section_text(MITSUBA)


def _mitsuba_plugin() -> str:
    import mitsuba_study

    return mitsuba_study.performance_text(figures.load(MITSUBA / "speed.json"))


def _mitsuba_goal() -> str:
    import mitsuba_study

    return mitsuba_study.goal_text(figures.load(MITSUBA / "speed.json"))


def _glass_mitsuba() -> str:
    import glass_mitsuba

    return glass_mitsuba.table(figures.load(figures.RESULTS / "cornell-glass-mitsuba.json"))


def _zfaure_evidence() -> str:
    import zfaure_evidence

    return zfaure_evidence.section_text(figures.load(zfaure_evidence.RESULTS_JSON))


def _cluster_speedup() -> str:
    import bench_cluster

    return bench_cluster.section(figures.load(figures.RESULTS / "cluster.json"))


SECTIONS: dict[str, Entry] = {
    # benchmarks/render_study.py: the render study's ratios
    "render-study": Entry((RESULTS_PAGE,), (STUDY,), _render_study),
    "render-study-headline": Entry((README,), (STUDY,), _render_study_headline),
    # benchmarks/faure_study.py, benchmarks/mitsuba_study.py
    "faure-study": Entry((RESULTS_PAGE,), (FAURE,), _faure_study),
    "mitsuba-study": Entry((RESULTS_PAGE,), (MITSUBA,), _mitsuba_study),
    "mitsuba-plugin": Entry((PERFORMANCE,), (MITSUBA / "speed.json",), _mitsuba_plugin),
    "mitsuba-goal": Entry((PERFORMANCE,), (MITSUBA / "speed.json",), _mitsuba_goal, inline=True),
    # benchmarks/bench_render.py: render speed against Mitsuba and the Embree floor
    "render-summary": Entry((README,), (figures.RENDER,), figures.render_summary),
    "render-goal": Entry((PERFORMANCE,), (figures.RENDER,), figures.render_goal, inline=True),
    "render-speed": Entry((PERFORMANCE,), (figures.RENDER,), figures.render_speed),
    "render-profile": Entry((PERFORMANCE,), (figures.RENDER,), figures.render_profile),
    "render-memory": Entry((PERFORMANCE,), (figures.RENDER,), figures.render_memory),
    "render-memory-goal": Entry((PERFORMANCE,), (figures.RENDER,), figures.render_memory_goal, inline=True),
    # benchmarks/bench_generate.py: generation speed against fill and the peers
    "generate-peers": Entry((README,), (figures.GENERATE_VECTOR, figures.GENERATE_H100, *figures.GENERATE_NUMPY),
                            figures.generate_peers),
    "generate-goal": Entry((PERFORMANCE,), (figures.GENERATE_VECTOR,), figures.generate_goal, inline=True),
    "generate-vector": Entry((PERFORMANCE,), (figures.GENERATE_VECTOR,), figures.generate_vector),
    # benchmarks/bench_openqmc.py: the C headers against OpenQMC
    "openqmc": Entry((PERFORMANCE,), figures.OPENQMC, figures.openqmc_table),
    "openqmc-goal": Entry((PERFORMANCE,), figures.OPENQMC, figures.openqmc_goal, inline=True),
    # benchmarks/glass_mitsuba.py: the glass Cornell box against Mitsuba 3
    "glass-mitsuba": Entry((REPO / "docs" / "rendering.md",), (figures.RESULTS / "cornell-glass-mitsuba.json",),
                           _glass_mitsuba),
    # benchmarks/zfaure_evidence.py: zfaure's error spectra and renders against zsobol, faure, bose, pmj02
    "zfaure-evidence": Entry((RESULTS_PAGE,), (REPO / "benchmarks" / "results" / "zfaure-evidence.json",),
                             _zfaure_evidence),
    # benchmarks/bench_cluster.py: a study's speed-up on a local cluster
    "cluster-speedup": Entry((REPO / "docs" / "distributed.md",), (figures.RESULTS / "cluster.json",), _cluster_speedup),
}
#: Every page that holds marked sections.
PAGES = tuple(sorted({p for e in SECTIONS.values() for p in e.pages}))


def _rel(path: Path) -> str:
    return str(path.relative_to(REPO)) if path.is_relative_to(REPO) else str(path)


def update(names: Iterable[str] | None = None) -> list[Path]:
    """Make the named sections (default: all) from their results files and write them into their pages.
    Returns the pages that changed."""
    names = list(SECTIONS) if names is None else list(names)
    unknown = [n for n in names if n not in SECTIONS]
    if unknown:
        raise KeyError(f"no marked section {', '.join(unknown)}; known: {', '.join(SECTIONS)}")
    bodies = {n: SECTIONS[n].body() for n in names}
    changed = []
    for page in PAGES:
        mine = {n: b for n, b in bodies.items() if page in SECTIONS[n].pages}
        if mine and marked.write(page, mine):
            changed.append(page)
    return changed


def after(results: Path) -> list[Path]:
    """Write the sections made from the results file ``results`` (a benchmark calls this after writing
    it; a file no section reads changes no page). Returns the pages that changed."""
    results = Path(results).resolve()
    names = [n for n, e in SECTIONS.items() if results in e.sources]
    return update(names) if names else []


def problems() -> list[str]:
    """What is wrong with the pages' marked sections, one line each: a section edited by hand (its text
    is not the one its marker's digest records), one that differs from what its results files give, a
    marked section no entry makes, or an entry's section missing from its page."""
    out = []
    for page in PAGES:
        have = marked.sections(page.read_text(encoding="utf-8"), _rel(page))
        for name, sec in have.items():
            entry = SECTIONS.get(name)
            if entry is None or page not in entry.pages:
                out.append(f"{_rel(page)}: section {name!r} is made by no entry of update_docs.SECTIONS")
                continue
            if sec.edited:
                out.append(f"{_rel(page)}: section {name!r} was edited by hand (its marker records another text); "
                           "change the results file or the function that makes it instead")
            if sec.body != entry.body():
                out.append(f"{_rel(page)}: section {name!r} is not what "
                           f"{', '.join(_rel(s) for s in entry.sources)} give: run python benchmarks/update_docs.py")
        out += [f"{_rel(page)}: no marked section {n!r}" for n, e in SECTIONS.items()
                if page in e.pages and n not in have]
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="list the sections that differ and exit 1; write nothing")
    args = ap.parse_args(argv)
    if args.check:
        found = problems()
        print("\n".join(found) if found else f"every marked section of {len(PAGES)} pages is what its results give")
        return 1 if found else 0
    for page in update():
        print(f"wrote {_rel(page)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
