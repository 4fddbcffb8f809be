"""A study's own files (issue 48, items 3 and 4).

study.csv is read as CSV, not line by line: a scene whose name holds a
newline, a quote, a comma or non-ASCII characters round-trips, and a study
of such a scene resumes. A damaged study.json (nested too deeply) or
study.csv (a field over the csv module's limit, bytes that are not UTF-8)
is a one-line refusal, exit status 2, its files untouched.
"""

from __future__ import annotations

import shutil

import pytest

from pyoa import study
from pyoa.commands import main
from pyoa.render.scene import bundled

NAMES = ["a\nb", "cr\rz", 'say "hi"', "x,y", "été ünï 日本", "cr\rlf\r\n", "\u2028sep", "plain"]


def row(scene: str, seed: int = 0) -> dict:
    return dict(scene=scene, sampler="bose", spp_asked=16, spp=16, seed=seed, relmse=0.25, relmse_crop=0.5,
                mse=0.125, seconds=1.5)


def write_rows(path, rows) -> None:
    writer = study.RowWriter(path)
    try:
        for r in rows:
            writer.add(r)
    finally:
        writer.close()


def test_rows_round_trip_names_with_newlines_quotes_commas_and_non_ascii(tmp_path):
    path = tmp_path / "study.csv"
    rows = [row(n, k) for k, n in enumerate(NAMES)]
    write_rows(path, rows)
    assert study.read_rows(path) == rows
    before = path.read_bytes()
    assert study.read_rows(path, repair=True) == rows and path.read_bytes() == before  # nothing to repair


def test_a_row_cut_inside_a_quoted_name_is_dropped_as_a_cut_line(tmp_path, capsys):
    """A study killed while writing its last row: the row is dropped (and the file repaired), even when the
    cut falls just after a newline inside a quoted scene name."""
    path = tmp_path / "study.csv"
    rows = [row("a\nb"), row("a\nb", 1)]
    write_rows(path, rows)
    whole = path.read_bytes()
    last = whole.rindex(b'"a\nb",')
    for cut in (last + 3, last + 10, len(whole) - 1):  # after "a<NL>, in the numbers, before the line break
        path.write_bytes(whole[:cut])
        assert study.read_rows(path) == rows[:1]
    assert study.read_rows(path, repair=True) == rows[:1]
    assert study.read_rows(path) == rows[:1] and path.read_bytes() == whole[:last]
    assert capsys.readouterr().err == ""  # a cut line goes without a word


def test_a_study_of_a_scene_whose_name_holds_a_newline_resumes(tmp_path, capsys, monkeypatch):
    """The issue's case: the first run succeeded, every later one said 'a row that is not a study's'."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "oddsc").mkdir()
    scene = tmp_path / "oddsc" / 'a\nb "c", é.json'
    shutil.copy(bundled()["cornell"], scene)
    argv = ["study", str(scene), "--samplers", "bose", "--spp", "16", "--seeds", "2", "--reference-spp", "32",
            "--pass-spp", "16", "--size", "8", "8", "--out", "D"]
    assert main(argv) == 0
    rows = study.read_rows(tmp_path / "D" / "study.csv")
    assert [r["scene"] for r in rows] == ['a\nb "c", é'] * 2
    before = (tmp_path / "D" / "study.csv").read_bytes()
    assert main(argv) == 0  # resumed: nothing left to render, no row added
    assert (tmp_path / "D" / "study.csv").read_bytes() == before
    # the report names the scene escaped: a table row and a heading stay one line each
    md = (tmp_path / "D" / "study.md").read_text()
    assert "## a\\nb" in md and not any(line.startswith('b "c"') for line in md.splitlines()), md
    assert "\x1b" not in capsys.readouterr().out


# -- item 4: damaged files ---------------------------------------------------------------------------


def refused(capsys, d) -> str:
    """``pyoa study`` on the directory ``d``: exit status 2 and one line; its files untouched."""
    before = {p.name: p.read_bytes() for p in d.iterdir()}
    with pytest.raises(SystemExit) as exc:
        main(["study", "cornell", "--samplers", "bose", "--spp", "16", "--seeds", "2", "--reference-spp", "32",
              "--size", "8", "8", "--out", str(d), "-q"])
    err = capsys.readouterr().err
    assert exc.value.code == 2, err
    assert len(err.strip().splitlines()) == 1 and err.startswith("pyoa study: error: "), err
    assert {p.name: p.read_bytes() for p in d.iterdir() if p.name != ".lock"} == before
    return err.strip()


def test_a_study_json_nested_too_deeply_is_a_damaged_file(tmp_path, capsys):
    (tmp_path / "study.json").write_text("[" * 100000 + "]" * 100000)
    err = refused(capsys, tmp_path)
    assert err == (f"pyoa study: error: {tmp_path / 'study.json'} is not a study's settings (lists or objects nested "
                   f"too deeply); the file is damaged: move it and {tmp_path / 'study.csv'} away to start the study "
                   "afresh, or give another --out")


@pytest.mark.parametrize("bad, said", [
    ('"' + "x" * 200_000 + '",bose,16,16,0,0.25,0.5,0.125,1.5\n', "line 2: field larger than field limit (131072)"),
    ('"x"y,bose,16,16,0,0.25,0.5,0.125,1.5\n', "line 2: ',' expected after '\"'"),
], ids=["over-the-field-limit", "stray-quote"])
def test_a_study_csv_csv_cannot_read_is_a_damaged_file(tmp_path, capsys, bad, said):
    path = tmp_path / "study.csv"
    path.write_text(",".join(study.FIELDS) + "\n" + bad)
    err = refused(capsys, tmp_path)
    assert err == (f"pyoa study: error: {path}: {said}; the file is damaged: move it away (its rows are then "
                   "rendered again), or give another --out"), err


def test_a_study_csv_that_is_not_utf8_is_a_damaged_file(tmp_path, capsys):
    path = tmp_path / "study.csv"
    path.write_bytes((",".join(study.FIELDS) + "\n").encode() + b"\xff\xfe,bose,16,16,0,0.25,0.5,0.125,1.5\n")
    err = refused(capsys, tmp_path)
    assert err.startswith(f"pyoa study: error: {path} is not UTF-8 text (invalid start byte at byte ") and \
        err.endswith("); the file is damaged: move it away (its rows are then rendered again), or give another "
                     "--out"), err
