"""Figures and facts stated in the docs (issue 48, items 12 and 15).

- The study's figure keeps a 95 % band whose lower end is at or below 0: cut at
  the panel's floor, marked there, and explained in the legend.
- ``pyoa compare``'s figure puts its colour bar beside the last error map, not
  in a margin beyond the reference's empty cell.
- The analysis results show as tables in a REPL (``repr``) and a notebook
  (``_repr_markdown_``).
- The README and docs state the renderer's compile time that the render itself
  prints, and the Cornell box's sides as the code shades them.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


# -------------------------------------------------------------------------- study.png: bands that reach 0

def _study_table():
    """Two samplers on one scene; two seeds each, so that most 95 % intervals reach below 0."""
    from pyoa import study

    data = {"bose": {16: [1e-2, 1.1e-2], 64: [1e-3, 1.2e-3], 256: [1e-4, 1.5e-4]},
            "random": {16: [2e-2, 2.5e-2], 64: [5e-3, 6e-3], 256: [1e-4, 3e-3]}}
    rows = [{"scene": "cornell", "sampler": name, "spp_asked": spp, "spp": spp, "relmse": v, "relmse_crop": v}
            for name, by in data.items() for spp, vs in by.items() for v in vs]
    return study.cells(rows, {})


def test_study_figure_cuts_a_band_that_reaches_zero_and_marks_it():
    from matplotlib.collections import PolyCollection

    from pyoa import study

    table = _study_table()
    cis = {n: {c.spp: c.ci() for c in by.values()} for n, by in table["cornell"].items()}
    assert cis["bose"][16][1] > 0 and cis["bose"][64][1] < 0 and cis["random"][16][1] < 0  # the case tested
    fig = study.figure(table, ["cornell"], ["bose", "random"])
    fig.canvas.draw()
    (ax,) = fig.axes
    floor = ax.get_ylim()[0]
    assert floor > 0
    bands = [c for c in ax.collections if isinstance(c, PolyCollection)]
    assert len(bands) == 2
    for name, band in zip(("bose", "random"), bands):
        xy = band.get_paths()[0].vertices
        for spp, (m, lo, hi) in cis[name].items():
            ys = xy[np.isclose(xy[:, 0], spp), 1]
            # every count has its band: from its lower end (or the floor where that is <= 0) to its upper end
            assert np.isclose(ys.max(), hi), (name, spp)
            assert np.isclose(ys.min(), lo if lo > 0 else floor), (name, spp)
            assert ys.min() <= m <= ys.max()
    # a triangle at the floor for each cut count, in its sampler's colour, drawn over the axis line; each
    # sampler's a step above the last one's, so that at one count none hides another
    cut = {(name, spp) for name, by in cis.items() for spp, (m, lo, hi) in by.items() if lo <= 0}
    marked, heights = set(), []
    for line in ax.get_lines():
        if line.get_marker() == "v" and len(line.get_xdata()):
            ys = line.get_ydata()
            assert np.allclose(ys, ys[0]) and floor <= ys[0] < floor * 10 ** 0.5 and not line.get_clip_on()
            heights.append(ys[0])
            name = "bose" if line.get_color() == ax.get_lines()[0].get_color() else "random"
            marked |= {(name, int(x)) for x in line.get_xdata()}
    assert marked == cut
    assert len(heights) == 2 and heights[0] != heights[1]  # bose and random each have a cut count
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("reaches 0" in t and "cut" in t for t in legend), legend


def test_study_figure_without_such_bands_has_no_note():
    from pyoa import study

    rows = [{"scene": "s", "sampler": "bose", "spp_asked": n, "spp": n, "relmse": v, "relmse_crop": v}
            for n, vs in ((16, [1e-2, 1.01e-2]), (64, [1e-3, 1.01e-3])) for v in vs]
    fig = study.figure(study.cells(rows, {}), ["s"], ["bose"])
    (ax,) = fig.axes
    assert not [ln for ln in ax.get_lines() if ln.get_marker() == "v"]
    assert not any("reaches 0" in t.get_text() for t in ax.get_legend().get_texts())


# -------------------------------------------------------------------------- compare's figure: the colour bar

@pytest.mark.parametrize("shape", [(32, 32), (16, 48), (48, 16)], ids=["square", "wide", "tall"])
@pytest.mark.parametrize("samplers", [1, 3])
def test_compare_figure_puts_the_colour_bar_beside_the_last_error_map(shape, samplers):
    from matplotlib.colors import LogNorm

    from pyoa.commands import render as render_commands

    h, w = shape
    rng = np.random.default_rng(1)
    ref = (rng.random((h, w, 3)) + 0.2).astype(np.float32)
    crop = (2, 2, 8, 8)
    panels = [(f"s{k}", 16, render_commands.figure_panels((ref * rng.uniform(0.8, 1.2, ref.shape)).astype(np.float32),
                                                   ref, crop)) for k in range(samplers)]
    fig = render_commands.comparison_figure(panels, ref, crop)
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    maps = [im for ax in fig.axes for im in ax.get_images() if isinstance(im.norm, LogNorm)]
    assert len(maps) == samplers
    last = max(maps, key=lambda im: im.axes.get_window_extent(r).x0)
    bar = last.colorbar
    assert bar is not None and bar.norm is last.norm
    m, b = last.axes.get_window_extent(r), bar.ax.get_window_extent(r)
    # right of the last map, with a small gap (not a column and a margin away), and as tall as it
    assert 0 < b.x0 - m.x1 <= 0.1 * max(m.width, m.height), (b, m)
    assert b.width < 0.2 * max(m.width, m.height)
    assert abs(b.y0 - m.y0) < 1.5 and abs(b.y1 - m.y1) < 1.5, (b, m)
    # inside the reference's column: no margin of its own to the right of it
    ref_top = max((ax for ax in fig.axes if ax.get_images()), key=lambda ax: ax.get_window_extent(r).x1)
    assert b.x1 < ref_top.get_window_extent(r).x1


def test_compare_figure_is_written_as_png(tmp_path):
    from pyoa.commands import render as render_commands

    ref = np.full((8, 8, 3), 0.5, np.float32)
    img = ref + np.float32(0.01)
    render_commands.compare_figure(tmp_path / "c.png", [("bose", 4, render_commands.figure_panels(img, ref, (0, 0, 4, 4)))],
                            ref, (0, 0, 4, 4))
    assert (tmp_path / "c.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# -------------------------------------------------------------------------- results in a REPL and a notebook

def _is_table(text: str) -> bool:
    lines = text.splitlines()
    return any(re.fullmatch(r"\|(-+:?\|)+", ln) for ln in lines) and sum(ln.startswith("| ") for ln in lines) >= 3


@pytest.fixture(scope="module")
def results():
    from pyoa import analysis

    x = np.full((16, 3), 0.1)
    return {
        "convergence": analysis.convergence(["random", "bose"], "pairwise", 4, [16, 64], trials=4, backend="numpy"),
        "stratification": analysis.stratification(x, s=2, t=2),
        "error_spectrum": analysis.error_spectrum("sobol02", spp=4, size=8, seeds=1, backend="numpy"),
    }


@pytest.mark.parametrize("which", ["convergence", "stratification", "error_spectrum"])
def test_results_show_as_tables_in_a_repl_and_a_notebook(results, which):
    res = results[which]
    text = repr(res)
    assert "\\n" not in text and "array(" not in text and "\n" in text
    assert _is_table(text), text
    md = res._repr_markdown_()
    assert isinstance(md, str) and _is_table(md) and md.strip() == text.strip()


def test_the_table_method_shows_as_itself(results):
    """The README's ``res.table()``: a str (its text unchanged) that a REPL prints as the table."""
    t = results["convergence"].table()
    assert isinstance(t, str) and t.endswith("|\n")
    assert repr(t) == t.rstrip("\n") and "\\n" not in repr(t)
    assert t._repr_markdown_() == str(t)
    assert "| sampler | variance slope | MSE slope |" in t


def test_a_failing_stratification_names_its_subsets(results):
    text = repr(results["stratification"])
    assert text.startswith("NOT stratified") and "(0, 1), (0, 2), (1, 2)" in text


# -------------------------------------------------------------------------- facts in the docs

#: A sentence that says numba compiles the renderer (the shading).
COMPILES = re.compile(r"\b(compiles?|compiling) the (renderer|shading)\b|\bnumba compiles\b", re.I)
SECONDS = re.compile(r"\d[\d.,]*(?:-\d+)? s\b")


def _sentences(path: Path):
    for para in re.split(r"\n\s*\n", path.read_text(encoding="utf-8")):
        yield from re.split(r"(?<=[.;])\s+(?=[A-Z(`*\d])", " ".join(para.split()))


def _compile_line() -> str:
    """The line a render prints before numba compiles the renderer: a real render, in a process whose numba
    cache is empty, stopped once it has said it (the compile itself takes 15-60 s)."""
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        env = {**os.environ, "NUMBA_CACHE_DIR": str(Path(d) / "numba")}
        proc = subprocess.Popen([sys.executable, "-m", "pyoa", "render", "cornell", "--spp", "4", "--size", "8", "8",
                                 "--shading", "numba", "--out", str(Path(d) / "c.exr")], stderr=subprocess.PIPE,
                                stdout=subprocess.DEVNULL, text=True, env=env, cwd=d)
        watchdog = threading.Timer(240, proc.kill)  # a render that hangs silently ends the loop below
        watchdog.start()
        try:
            for line in proc.stderr:
                if "compiling the renderer" in line:
                    return line.strip()
            pytest.fail(f"the render ended ({proc.wait()}) without saying that it compiles the renderer")
        finally:
            watchdog.cancel()
            proc.kill()
            proc.wait()


def test_docs_state_the_compile_time_that_the_render_prints():
    line = _compile_line()
    (figure,) = re.findall(r"\d+-\d+ s", line)
    said = []
    for path in DOCS:
        for s in _sentences(path):
            if COMPILES.search(s):
                said.append(s)
                assert "per machine" not in s, f"{path.name}: {s}"  # numba's cache is per install and CPU model
                if SECONDS.search(s):
                    assert figure in s, f"{path.name} states another compile time than the render's {figure}: {s}"
    assert len([s for s in said if figure in s]) >= 3  # README, rendering.md, distributed.md
    from pyoa.render.render import COMPILING

    assert line == COMPILING  # the one place that says it


def test_docs_say_which_cornell_surfaces_are_one_sided():
    """The code shades every surface two-sided (the normal turned towards the ray) and lets emitters emit on
    their front only; Mitsuba's cornell_box() is one-sided. No doc may call pyoa's surfaces one-sided."""
    from pyoa.render import bsdfs

    assert "every surface is two-sided" in " ".join(bsdfs.__doc__.split())
    text = " ".join((ROOT / "docs" / "rendering.md").read_text(encoding="utf-8").split())
    assert "every surface is one-sided" not in text
    assert "pyoa shades every surface two-sided" in text and "In Mitsuba each surface is one-sided" in text
    readme = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    (cornell,) = re.findall(r"`cornell` \(([^`]*`cornell_box\(\)`[^)]*\))", readme)
    assert "two-sided" in cornell and "docs/rendering.md" in cornell


def test_docs_state_one_pmj02_build_time():
    """The pmj02 table's first build (numba's compile included) depends on the CPU: every doc that times it
    gives the range of :mod:`pyoa.tables.pmj02`' docstring, which names the CPUs measured."""
    from pyoa.tables import pmj02 as pmj02_tables

    doc = " ".join(pmj02_tables.__doc__.split())
    (figure,) = re.findall(r"(\d+-\d+ s) in all", doc)
    assert figure == pmj02_tables.BUILD_TIME  # what the build prints while it runs
    assert "AMD EPYC Zen 5" in doc and "Intel Xeon" in doc
    said = [(path.name, s) for path in DOCS for s in _sentences(path)
            if "numba" in s and re.search(r"\bbuil", s) and SECONDS.search(s) and not COMPILES.search(s)]
    assert {name for name, _ in said} >= {"README.md", "samplers.md", "performance.md"}, said
    for name, s in said:
        assert figure in s, f"{name} states another pmj02 build time than {figure}: {s}"
