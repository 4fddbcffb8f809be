"""Hardening of ``pyoa study`` (issue 33, items 4, 5, 7, 10 and 13): a
refused run writes nothing, a study's reference is known by its pixels and
the settings that made it, one run at a time holds a study's directory, a
row is counted once, samplers are stored as the catalogue spells them, the
scenes' sizes and ``study.json`` are checked before any work.

Refusals run the command in a subprocess (exit status 2, one line, the
study's files untouched); runs that succeed run in-process, on copies of
one tiny module-scoped study."""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import socket

import numpy as np
import OpenImageIO as oiio
import pytest

from pyoa import study
from pyoa.cli import main
from pyoa.render.image import read_image
from pyoa.render.scene import bundled

from .test_hardening_cli import assert_refused, pyoa

#: The shared study: 2 samplers, 1 count, 2 seeds, 8 x 8, a reference of 2 passes of 64 spp.
ARGS = ["dof7d", "--samplers", "bose,sobol", "--spp", "16", "--seeds", "2", "--size", "8", "8", "--pass-spp", "64",
        "-q"]
REF = ["--reference-spp", "128"]
#: The study's lock file (docs/distributed.md).
LOCK = ".lock"
FILES = ("study.csv", "study.json", "reference-dof7d.exr", "reference-dof7d.variance.exr")


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """A finished study (4 rows), made once."""
    out = tmp_path_factory.mktemp("study") / "made"
    assert main(["study", *ARGS, *REF, "--out", str(out)]) == 0
    return out


@pytest.fixture
def d(made, tmp_path):
    """A copy of the finished study (bytes and mtimes kept) for one test to change."""
    out = tmp_path / "d"
    shutil.copytree(made, out)
    return out


def snapshot(d) -> dict:
    """Bytes and mtime of the study's files."""
    return {n: ((d / n).read_bytes(), (d / n).stat().st_mtime_ns) for n in FILES}


def last_run(d) -> dict:
    return json.loads((d / "study.json").read_text())["runs"][-1]


# -- item 4: a refused run keeps the reference; a reference is its pixels --------------------------


def test_a_refused_reference_change_writes_nothing_and_the_study_goes_on(d):
    before = snapshot(d)
    res = pyoa("study", *ARGS, "--reference-spp", "256", "--out", d)
    assert snapshot(d) == before  # the reference and its variance too
    assert_refused(res, "study", f"{d} holds dof7d renders measured against a reference of 128 spp in 2 passes of "
                                 "64 (--reference-spp 128 --pass-spp 64), not one of 256 spp in 4 passes of 64; give "
                                 "the reference they used, or another --out")
    # the first command goes on: nothing rendered again, the reference as it was
    assert main(["study", *ARGS, *REF, "--out", str(d)]) == 0
    assert last_run(d)["rendered"] == 0
    assert snapshot(d)["reference-dof7d.exr"] == before["reference-dof7d.exr"]


def test_a_reference_written_again_with_the_same_pixels_is_the_same_reference(d):
    """Other file bytes (another compression, another time stamp), the same pixels: not rendered again."""
    path = d / "reference-dof7d.exr"
    pixels, first = read_image(path), path.read_bytes()
    spec = oiio.ImageSpec(8, 8, 3, "float")
    spec.attribute("compression", "none")
    spec.attribute("Software", "another writer")
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec) and out.write_image(pixels) and out.close()
    again = path.read_bytes()
    assert again != first
    assert main(["study", *ARGS, *REF, "--out", str(d)]) == 0
    assert last_run(d)["rendered"] == 0 and path.read_bytes() == again  # used as it is


# -- item 5: one run at a time; a row counted once ------------------------------------------------


def test_a_second_run_on_one_directory_is_refused_naming_the_holder(d):
    before = snapshot(d)
    with open(d / LOCK, "a+") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)  # this test holds the study, as a running study does
        fh.truncate(0)
        fh.write(f"{os.getpid()} {socket.gethostname()}\n")
        fh.flush()
        res = pyoa("study", *ARGS, *REF, "--out", d)
    assert_refused(res, "study", f"study directory {d} is in use by process {os.getpid()} on "
                                 f"{socket.gethostname()}; wait for it or use another --out")
    assert snapshot(d) == before


def test_duplicate_rows_are_counted_once(d, made, capsys):
    """A study.csv with every row twice (two runs at once, before the lock): each row counts once,
    the file is rewritten without the copies, and stderr says so."""
    csv_path = d / "study.csv"
    lines = csv_path.read_text().splitlines(keepends=True)
    csv_path.write_text("".join(lines + lines[1:]))
    assert main(["study", *ARGS, *REF, "--out", str(d)]) == 0
    err = capsys.readouterr().err
    assert f"{csv_path}: dropped 4 duplicate rows" in err and "rewrote the file" in err, err
    assert csv_path.read_bytes() == (made / "study.csv").read_bytes() and last_run(d)["rendered"] == 0
    md, want = (d / "study.md").read_text(), (made / "study.md").read_text()
    assert "Seeds per cell: 2." in md
    table = [line for line in want.splitlines() if line.startswith("| ")]
    assert table and all(line in md for line in table)  # the same means and intervals


def test_duplicate_rows_that_disagree_are_refused(d, capsys):
    csv_path = d / "study.csv"
    lines = csv_path.read_text().splitlines(keepends=True)
    fields = lines[1].split(",")
    fields[5] = repr(float(fields[5]) * 2)  # relmse
    csv_path.write_text("".join([*lines, ",".join(fields)]))
    before = snapshot(d)
    with pytest.raises(SystemExit) as exc:
        main(["study", *ARGS, *REF, "--out", str(d)])
    err = capsys.readouterr().err.strip()
    assert exc.value.code == 2 and len(err.splitlines()) == 1, err
    assert f"{csv_path}: lines 2 and 6 are two renders of dof7d with bose at 16 spp, seed 0, with different " \
           "errors" in err
    assert snapshot(d) == before


# -- item 7: catalogue names -----------------------------------------------------------------------


def test_samplers_are_stored_as_the_catalogue_spells_them(d, made):
    argv = [a if a != "bose,sobol" else "BOSE,Sobol" for a in ARGS]
    assert main(["study", *argv, *REF, "--out", str(d)]) == 0
    assert last_run(d)["rendered"] == 0
    assert (d / "study.csv").read_bytes() == (made / "study.csv").read_bytes()
    md = (d / "study.md").read_text()
    assert "## Headline" in md and "| bose |" in md and "BOSE" not in md
    # rows of a study that stored the names as typed are read as the catalogue's, and rewritten so
    csv_path = d / "study.csv"
    csv_path.write_text(csv_path.read_text().replace(",bose,", ",BOSE,").replace(",sobol,", ",Sobol,"))
    assert main(["study", *ARGS, *REF, "--out", str(d)]) == 0
    assert last_run(d)["rendered"] == 0
    assert csv_path.read_bytes() == (made / "study.csv").read_bytes()


# -- item 10: every scene's size before any work ---------------------------------------------------


def test_scenes_of_two_sizes_are_refused_before_any_work(tmp_path):
    data = json.loads(open(bundled()["dof7d"]).read())
    data["film"] = {"width": 8, "height": 6}
    (tmp_path / "small.json").write_text(json.dumps(data))
    out = tmp_path / "two"
    res = pyoa("study", "dof7d", tmp_path / "small.json", "--samplers", "bose", "--spp", "16", "--seeds", "1",
               "--reference-spp", "16", "--pass-spp", "16", "-q", "--out", out)
    assert [p.name for p in out.iterdir()] == [LOCK]  # no reference rendered
    assert_refused(res, "study", "dof7d renders 256 x 256 and small 8 x 6; a study has one size: give --size W H")


# -- item 13: study.json checked when it is read ---------------------------------------------------


def damage_json(d, damage) -> None:
    path = d / "study.json"
    settings = json.loads(path.read_text())
    damage(settings)
    path.write_text(json.dumps(settings))


@pytest.mark.parametrize("damage, says", [
    pytest.param(lambda s: s["scenes"].update(dof7d="x"), 'scenes["dof7d"] is not an object', id="scene"),
    pytest.param(lambda s: s["runs"][0].pop("seconds"), "runs[0] has no 'seconds'", id="seconds"),
    pytest.param(lambda s: s.update(runs=5), "runs is 5, not a list of runs", id="runs"),
])
def test_a_damaged_study_json_is_refused_naming_the_field(d, damage, says):
    damage_json(d, damage)
    before = snapshot(d)
    res = pyoa("study", *ARGS, *REF, "--out", d)
    assert snapshot(d) == before
    assert_refused(res, "study", f"{d / 'study.json'}: {says}; the file is damaged: move it and "
                                 f"{d / 'study.csv'} away to start the study afresh, or give another --out")


@pytest.mark.parametrize("damage, says", [
    pytest.param(lambda s: s["scenes"]["dof7d"].update(noise=[1, "x"]),
                 'scenes["dof7d"].noise is [1, "x"], not null or a list of 2 numbers >= 0', id="noise"),
    pytest.param(lambda s: s.update(size=[8]), "size is [8], not a list of 2 integers >= 1", id="size"),
    pytest.param(lambda s: s["scenes"]["dof7d"].pop("digest"), 'scenes["dof7d"] has no \'digest\'', id="digest"),
    pytest.param(lambda s: s["runs"][0].update(seconds=float("nan")), "runs[0].seconds is NaN, not a number >= 0",
                 id="nan"),
])
def test_every_field_of_study_json_is_checked(d, capsys, damage, says):
    """The same check for every field pyoa reads (in-process: the subprocess cases above show the command)."""
    damage_json(d, damage)
    before = snapshot(d)
    with pytest.raises(SystemExit) as exc:
        main(["study", *ARGS, *REF, "--out", str(d)])
    err = capsys.readouterr().err.strip()
    assert exc.value.code == 2 and len(err.splitlines()) == 1 and f"{d / 'study.json'}: {says}; " in err, err
    assert snapshot(d) == before


def test_pixel_identity_is_of_the_pixels():
    a = np.arange(12, dtype=np.float32).reshape(2, 2, 3)
    assert study.pixel_identity(a) == study.pixel_identity(a.astype(np.float64))
    assert study.pixel_identity(a) != study.pixel_identity(a.reshape(1, 4, 3))  # the shape counts
    b = a.copy()
    b[1, 1, 2] = np.nextafter(b[1, 1, 2], np.float32(100))
    assert study.pixel_identity(a) != study.pixel_identity(b)
