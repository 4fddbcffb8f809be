"""Figures in the docs are written by the benchmarks, not by hand (issue 51, part 6).

A benchmark's figures reach README.md and docs/*.md only through marked
sections (``benchmarks/marked.py``), whose begin marker records the SHA-256
of the generated text; ``benchmarks/update_docs.py`` makes every section again
from the results files. Checked here:

- every marked section of the docs is the text its results files give, and
  none was edited by hand (its marker's digest is that of its text);
- the check catches both: a figure typed into a section, and a section left
  behind by a results file that changed;
- the marker mechanics: replacement in blocks and inside a line, the digest,
  and the refusals (a missing, repeated, unpaired, nested or misspelt marker;
  a marker in the generated text); a refused or idle write leaves the page as
  it was; markers in fenced code blocks are examples;
- ``make_results.py``, which rewrites the results page, keeps the study
  sections it does not make, markers and all (a hand edit stays visible).

Nothing here runs a benchmark: the sections are made from the results files
already in the repository (about 3 s, most of it importing the study's
statistics).
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import figures  # noqa: E402
import marked  # noqa: E402
import update_docs  # noqa: E402

# -------------------------------------------------------------------------- the docs


def test_every_marked_section_is_what_its_results_files_give():
    assert update_docs.problems() == []


def test_the_docs_carry_the_figure_groups():
    """Each figure group is marked where the docs show it (a removed marker would let a hand copy back in)."""
    where = {name: {p.relative_to(ROOT).as_posix() for p in e.pages} for name, e in update_docs.SECTIONS.items()}
    assert where["render-summary"] == where["render-study-headline"] == where["generate-peers"] == {"README.md"}
    for name in ("render-goal", "render-speed", "render-profile", "render-memory", "render-memory-goal",
                 "generate-goal", "generate-vector", "openqmc", "openqmc-goal", "mitsuba-plugin", "mitsuba-goal"):
        assert where[name] == {"docs/performance.md"}, name
    for name in ("render-study", "faure-study", "mitsuba-study"):
        assert where[name] == {"docs/results.md"}, name
    for page in update_docs.PAGES:
        have = marked.sections(page.read_text(encoding="utf-8"))
        assert {n for n, e in update_docs.SECTIONS.items() if page in e.pages} == set(have), page


def _page_of(monkeypatch, tmp_path, name: str) -> Path:
    """update_docs reduced to the page that holds the section ``name``, in a copy."""
    (page,) = update_docs.SECTIONS[name].pages
    copy = tmp_path / page.name
    copy.write_text(page.read_text(encoding="utf-8"), encoding="utf-8")
    monkeypatch.setattr(update_docs, "SECTIONS", {n: update_docs.Entry((copy,), e.sources, e.make, e.inline)
                                                  for n, e in update_docs.SECTIONS.items() if e.pages == (page,)})
    monkeypatch.setattr(update_docs, "PAGES", (copy,))
    return copy


def test_the_check_catches_a_figure_typed_into_a_section(monkeypatch, tmp_path):
    page = _page_of(monkeypatch, tmp_path, "render-summary")
    text = page.read_text(encoding="utf-8")
    rate = f"{figures.load(figures.RENDER)['scenes'][0]['results'][0]['paths_per_s'] / 1e6:.2f} M camera paths/s"
    assert text.count(rate) == 1
    page.write_text(text.replace(rate, "2.71 M camera paths/s"), encoding="utf-8")
    found = update_docs.problems()
    assert len(found) == 2 and "edited by hand" in found[0] and "is not what" in found[1], found
    assert update_docs.update() == [page] and update_docs.problems() == []
    assert page.read_text(encoding="utf-8") == text


def test_the_check_catches_a_section_left_behind_by_its_results_file(monkeypatch, tmp_path):
    page = _page_of(monkeypatch, tmp_path, "render-goal")
    report = figures.load(figures.RENDER)
    cornell = report["scenes"][0]
    assert cornell["scene"] == "cornell" and cornell["results"][0]["tracing"] == "robust"
    cornell["results"][0]["vs_mitsuba"] = 0.5
    changed = tmp_path / "render.json"
    changed.write_text(json.dumps(report), encoding="utf-8")
    monkeypatch.setattr(figures, "RENDER", changed)
    found = update_docs.problems()
    assert [f.split("'")[1] for f in found] == ["render-goal", "render-speed"], found  # the two that show it
    assert all("is not what benchmarks/results/render.json give" in f for f in found)  # no hand edit
    update_docs.update()
    assert "(**0.50x**;" in page.read_text(encoding="utf-8") and update_docs.problems() == []


def test_a_benchmark_writes_only_the_sections_made_from_its_file(monkeypatch, tmp_path):
    calls = []
    monkeypatch.setattr(update_docs, "update", lambda names: calls.append(sorted(names)) or [])
    update_docs.after(figures.RENDER)
    update_docs.after(tmp_path / "render.json")  # a --out elsewhere
    update_docs.after(figures.OPENQMC[1])
    assert calls == [["render-goal", "render-memory", "render-memory-goal", "render-profile", "render-speed",
                      "render-summary"],
                     ["openqmc", "openqmc-goal"]]


def test_make_results_keeps_the_sections_it_does_not_make(tmp_path):
    import make_results

    edited = marked.block("faure-study", "## faure\n\nmade by faure_study.py").replace("made by", "typed by")
    old = tmp_path / "results.md"
    old.write_text(f"# Results\n\n{edited}\n\n---\n", encoding="utf-8")
    page = make_results.Page(quick=False)
    make_results.part_kept(page, old)
    have = marked.sections("\n".join(page.lines))
    assert set(have) == set(make_results.KEPT) and "\n".join(page.lines).count(edited) == 1
    assert have["faure-study"].edited and not have["mitsuba-study"].edited  # the edit stays visible
    assert have["mitsuba-study"].body == "\n\n"  # a new page gets the markers, for mitsuba_study.py to fill


# -------------------------------------------------------------------------- the markers

PAGE = """# A page

Before. <!-- cell:begin -->1.00x<!-- cell:end --> after.

<!-- table:begin -->
| a | b |
<!-- table:end -->

```markdown
<!-- example:begin -->
```
"""


def test_replace_puts_the_text_between_the_markers_and_records_its_digest():
    new = marked.replace(PAGE, {"cell": "1.28x", "table": marked.block_body("| a | c |")})
    assert new == (PAGE.replace("<!-- cell:begin -->1.00x", f"<!-- cell:begin sha256={marked.digest('1.28x')} -->1.28x")
                   .replace("<!-- table:begin -->\n| a | b |",
                            f"<!-- table:begin sha256={marked.digest(chr(10) + '| a | c |' + chr(10))} -->\n| a | c |"))
    have = marked.sections(new)
    assert list(have) == ["cell", "table"]  # not the example in the code block
    assert have["cell"].body == "1.28x" and not have["cell"].edited and not have["table"].edited
    assert marked.replace(new, {"cell": "1.28x"}) == new
    assert marked.sections(new.replace(">1.28x<", ">1.29x<"))["cell"].edited
    assert marked.sections(PAGE)["cell"].edited  # no digest yet: not written by a benchmark
    assert marked.digest("1.28x") == __import__("hashlib").sha256(b"1.28x").hexdigest()[:16]


@pytest.mark.parametrize(("page", "bodies", "says"), [
    (PAGE, {"missing": "x"}, "no section 'missing'"),
    (PAGE + "<!-- cell:begin -->x<!-- cell:end -->", {"cell": "x"}, "'cell' is marked twice"),
    ("<!-- a:begin -->x", {"a": "y"}, "'a' begins but never ends"),
    ("x<!-- a:end -->", {"a": "y"}, "'a' ends but never began"),
    ("<!-- a:begin --><!-- b:begin --><!-- b:end --><!-- a:end -->", {"a": "y"}, "'b' begins inside 'a'"),
    ("<!-- a:begin sha256=123 -->x<!-- a:end -->", {"a": "y"}, "only 'sha256=' and 16 hex digits"),
    ("<!-- A_b:begin -->x<!-- A_b:end -->", {"A_b": "y"}, "use lower case letters"),
    ("<!-- a:begin -->x<!-- a:end -->", {"a": "<!-- b:end -->"}, "holds a marker"),
], ids=["missing", "twice", "unclosed", "unopened", "nested", "digest", "name", "marker-in-text"])
def test_replace_refuses_markers_it_cannot_trust(page, bodies, says):
    with pytest.raises(marked.MarkerError, match=says.replace("(", r"\(")):
        marked.replace(page, bodies)


def test_write_changes_the_page_only_when_a_section_changes(tmp_path):
    page = tmp_path / "page.md"
    page.write_text(PAGE, encoding="utf-8")
    assert marked.write(page, {"cell": "1.28x"})
    stat = page.stat()
    assert not marked.write(page, {"cell": "1.28x"})
    assert page.stat().st_mtime_ns == stat.st_mtime_ns and page.stat().st_ino == stat.st_ino
    text = page.read_text(encoding="utf-8")
    with pytest.raises(marked.MarkerError):
        marked.write(page, {"cell": "1.30x", "gone": "x"})  # one refusal: nothing written
    assert page.read_text(encoding="utf-8") == text
    assert not [f for f in os.listdir(tmp_path) if f != "page.md"]  # no temporary file left behind
