"""Every code block of README.md and docs/*.md runs as written.

Blocks are read by pytest-codeblocks (``extract_from_file``: ```python and
```bash/sh blocks, with the marks written before them as HTML comments,
``<!--pytest.mark.skip(reason="...")-->``, and ``<!--pytest-codeblocks:cont-->``
to continue the block before). Each block runs in a fresh temporary
directory, as a user would paste it: a Python block as a script file
(``python block.py``: a script, so that code which starts worker processes
must guard itself with ``if __name__ == "__main__":``, as the docs say), a
shell block with ``bash -e -o pipefail``, with this interpreter's ``pyoa`` and
``python`` first on the PATH. A skip must say why; blocks in other languages
(``xml``) and unlabelled ones (outputs, formulas) are text, not run.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from pytest_codeblocks import extract_from_file

from .mitsuba_support import REQUIRE_MITSUBA

ROOT = Path(__file__).resolve().parents[1]
FILES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
RUNNABLE = {"python": "python", "bash": "bash", "sh": "bash"}
#: Seconds one block may take (the longest, the README's analysis example, takes about 20 s).
BLOCK_TIMEOUT = 300


def _blocks():
    for path in FILES:
        for block in extract_from_file(path):
            lang = RUNNABLE.get((block.syntax or "").strip().split(" ")[0])
            if lang is None:
                continue
            marks = [eval(m, {"pytest": pytest, "sys": sys, "os": os}) for m in block.marks]  # noqa: S307 - our docs
            yield pytest.param(path, block, lang, marks=marks, id=f"{path.relative_to(ROOT)}:{block.lineno}")


BLOCKS = list(_blocks())


def test_the_docs_have_runnable_blocks():
    """The collection itself works: a parser change that found no block would pass every test below."""
    names = {p.values[0].name for p in BLOCKS}
    assert {"README.md", "samplers.md", "distributed.md", "mitsuba.md"} <= names
    assert len(BLOCKS) >= 15


def test_every_skip_says_why():
    for param in BLOCKS:
        for mark in param.marks:
            if mark.name in ("skip", "skipif"):
                assert mark.kwargs.get("reason", "").strip(), f"{param.id}: a skipped block must give reason=..."


@pytest.mark.parametrize(("path", "block", "lang"), BLOCKS)
def test_block_runs_as_written(path, block, lang, tmp_path):
    if block.importorskip:
        try:
            __import__(block.importorskip)
        except ImportError as exc:
            if REQUIRE_MITSUBA and block.importorskip in ("mitsuba", "drjit"):
                pytest.fail(f"PYOA_REQUIRE_MITSUBA=1 but {block.importorskip} cannot be imported: {exc}")
            pytest.skip(f"needs {block.importorskip}: {exc}")
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}",
               MPLBACKEND="Agg", PYTHONUNBUFFERED="1")
    if lang == "python":
        script = tmp_path / "block.py"
        script.write_text(block.code)
        argv = [sys.executable, str(script)]
    else:
        argv = ["bash", "-e", "-o", "pipefail", "-c", block.code]
    res = subprocess.run(argv, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=BLOCK_TIMEOUT)
    where = f"{path.relative_to(ROOT)} line {block.lineno}"
    assert res.returncode == 0, f"{where} failed ({res.returncode}):\n{res.stdout[-3000:]}\n{res.stderr[-3000:]}"
    if block.expected_output is not None:
        got, want = res.stdout, block.expected_output
        if block.expected_output_ignore_whitespace:
            got, want = "".join(got.split()), "".join(want.split())
        assert got == want, f"{where}: output differs from the block after it"


def _flat(path: Path) -> str:
    """A Markdown file's text with its line breaks as spaces (a quote may wrap)."""
    return " ".join(path.read_text().split())


def test_quoted_error_messages_are_pyoas_own(tmp_path):
    """The docs quote pyoa's refusals; a reworded message must be quoted anew (the README once quoted one
    that pyoa no longer printed)."""
    import json

    import pyoa
    from pyoa.render.scene import load

    with pytest.raises(ValueError) as exc:
        pyoa.sampler("bose", spp=120, dims=2)
    message = str(exc.value)
    for name in ("README.md", "docs/errors.md", "docs/mitsuba.md"):
        text = _flat(ROOT / name)
        # quoted whole, or with its middle elided as "s^2 ...;"
        elided = message.split(" with ")[0] + " ...; " + message.split("; ")[1]
        assert message in text or elided in text, name
    scene = json.loads((ROOT / "scenes" / "cornell.json").read_text())
    scene["shapes"][3]["material"] = "whte"
    bad = tmp_path / "cornell.json"
    bad.write_text(json.dumps(scene))
    with pytest.raises(ValueError) as exc:
        load(bad)
    quoted = "cornell.json: shapes[3].material: unknown material 'whte'; valid: white, red, green"
    assert str(exc.value).endswith(quoted[len("cornell.json"):]) and quoted in _flat(ROOT / "docs" / "rendering.md")


def test_every_relative_link_stays_in_the_repository():
    """The docs link only to files of this repository (a user's clone has nothing beside it), and every
    such link names a file or folder that exists; web links are left to the reader."""
    import re

    files = [*FILES, *sorted((ROOT / "benchmarks").glob("*.md")), *sorted((ROOT / "scenes").glob("*.md"))]
    bad = []
    for path in files:
        text = path.read_text()
        for target in re.findall(r"\]\(([^)\s]+)\)", text) + re.findall(r"^\[[^\]]+\]:\s*(\S+)", text, re.M):
            if re.match(r"[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
                continue  # a URL (https:, mailto:) or an anchor in the same file
            where = (path.parent / target.split("#")[0]).resolve()
            if not where.is_relative_to(ROOT) or not where.exists():
                bad.append(f"{path.relative_to(ROOT)}: {target}")
    assert not bad, "links outside the repository or to nothing:\n" + "\n".join(bad)


def test_the_docs_list_the_padded_samplers_the_study_uses():
    """docs/distributed.md names the samplers a study's headline calls "padded" (it once left zsobol out)."""
    from pyoa.study import PADDED

    text = _flat(ROOT / "docs" / "distributed.md")
    assert "(of " + ", ".join(f"`{n}`" for n in PADDED) + ", the one with the lowest mean)" in text
