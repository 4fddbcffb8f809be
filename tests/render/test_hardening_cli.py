"""Bad input to ``pyoa render``, ``pyoa compare`` and ``pyoa reference``: a
one-line error and exit status 2, checked before the first sample, with an
existing output left as it was. Each case runs the real command in a
subprocess."""

from __future__ import annotations

import json
import os
import re
import sys

import numpy as np
import OpenImageIO as oiio
import pytest

from pyoa.render.image import write_exr, write_png
from pyoa.render.render import render
from pyoa.render.scene import bundled, load

from .limits import run_child

OLD = b"previous output"


@pytest.fixture
def pyoa(as_limit):
    """Run ``python -m pyoa argv`` under the memory cap (limits.py: a count
    read wrongly, such as --spp 10^8 snapped to 16.7 million, fails its test
    instead of exhausting the machine); returns the CompletedProcess."""

    def run(*argv, cwd=None):
        return run_child([sys.executable, "-m", "pyoa", *map(str, argv)], as_limit, cwd)

    return run


def refused(res, command: str, pattern: str) -> str:
    """Assert exit status 2 and one line ``pyoa COMMAND: error: ...`` matching ``pattern``."""
    assert res.returncode == 2, (res.returncode, res.stdout, res.stderr)
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.stderr, res.stderr
    assert lines[0].startswith(f"pyoa {command}: error: "), lines[0]
    assert re.search(pattern, lines[0]), lines[0]
    return lines[0]


@pytest.fixture
def old_exr(tmp_path):
    """An existing output file that a refused command must not touch."""
    path = tmp_path / "old.exr"
    path.write_bytes(OLD)
    return path


@pytest.fixture(scope="module")
def ref8(tmp_path_factory):
    """A linear 8 x 8 reference EXR of cornell."""
    path = tmp_path_factory.mktemp("ref") / "ref8.exr"
    write_exr(path, render(load("cornell"), sampler="sobol", spp=16, seed=3, width=8, height=8).image)
    return path


# -- counts (items 2 and 7) -------------------------------------------------------------


@pytest.mark.parametrize("command, argv, pattern", [
    ("reference", ["--pass-spp", "0"], r"--pass-spp must be in \[1, 16777216\].*got 0"),
    ("reference", ["--pass-spp", "-4"], r"--pass-spp must be in \[1, 16777216\].*got -4"),
    ("reference", ["--spp", "0", "--pass-spp", "4"], r"--spp must be >= 1, got 0"),
    ("reference", ["--spp", "-8", "--pass-spp", "4"], r"--spp must be >= 1, got -8"),
    ("reference", ["--seed", "-1"], r"--seed must be in \[0, 4294967295\]"),
    ("render", ["--spp", "0"], r"--spp must be in \[1, 16777216\] \(the samplers' limit, 2\^24\), got 0"),
    ("render", ["--seed", str(2**32)], r"--seed must be in \[0, 4294967295\] \(a uint32\), got 4294967296"),
    ("render", ["--max-depth", "0"], r"--max-depth must be in \[1, \d+\], got 0"),
    ("render", ["--size", "0", "0"], r"--size W must be >= 1, got 0"),
    ("render", ["--size", "0", "8"], r"--size W must be >= 1, got 0"),
    ("render", ["--size", "8", "-3"], r"--size H must be >= 1, got -3"),
    ("compare", ["--spp", "0"], r"--spp must be in \[1, 16777216\].*got 0"),
    ("compare", ["--spp", "100000000"], r"--spp must be in \[1, 16777216\] \(the samplers' limit, 2\^24\)"),
    ("compare", ["--samplers", ","], r"--samplers ',' names no sampler"),
])
def test_bad_counts_are_refused(pyoa, tmp_path, old_exr, ref8, command, argv, pattern):
    extra = {"render": ["--size", "8", "8", "--out", old_exr],
             "reference": ["--size", "8", "8", "--out", old_exr],
             "compare": ["--size", "8", "8", "--reference", ref8, "--out", tmp_path / "cmp"]}[command]
    res = pyoa(command, "cornell", *extra, *argv, "-q")
    refused(res, command, pattern)
    assert old_exr.read_bytes() == OLD
    assert sorted(os.listdir(tmp_path)) == ["old.exr"]  # compare wrote nothing either


# -- outputs checked before the render (items 6 and 8) ----------------------------------------------


@pytest.mark.parametrize("out, pattern", [
    ("x.png", r"--out '.*x\.png': the file name must end in \.exr"),
    ("missing/x.exr", r"--out: directory '.*missing' does not exist"),
    ("adir.exr", r"--out: cannot write '.*adir\.exr': it is a directory"),
    ("/proc/x.exr", r"--out: cannot write '/proc/x\.exr'"),
])
def test_render_output_checked_first(pyoa, tmp_path, out, pattern):
    (tmp_path / "adir.exr").mkdir()
    res = pyoa("render", "cornell", "--size", "8", "8", "--spp", "4", "--out", out, "-q", cwd=tmp_path)
    line = refused(res, "render", pattern)
    assert ".x.exr." not in line  # never the hidden temporary file
    assert sorted(os.listdir(tmp_path)) == ["adir.exr"]


def test_render_png_must_be_png(pyoa, tmp_path, old_exr):
    res = pyoa("render", "cornell", "--size", "8", "8", "--spp", "4", "--out", old_exr, "--png",
               tmp_path / "x.exr", "-q")
    refused(res, "render", r"--png '.*x\.exr': the file name must end in \.png")
    assert old_exr.read_bytes() == OLD and sorted(os.listdir(tmp_path)) == ["old.exr"]


def test_render_crop_needs_reference(pyoa, tmp_path, old_exr):
    res = pyoa("render", "cornell", "--size", "8", "8", "--spp", "4", "--out", old_exr, "--crop", "0", "0", "4",
               "4", "-q")
    refused(res, "render", r"--crop needs --reference")
    assert old_exr.read_bytes() == OLD


def test_compare_outputs_checked_first(pyoa, tmp_path, ref8):
    res = pyoa("compare", "cornell", "--size", "8", "8", "--spp", "4", "--samplers", "bose", "--reference", ref8,
               "--out", tmp_path / "missing" / "cmp", "-q")
    refused(res, "compare", r"--out: directory '.*missing' does not exist")
    res = pyoa("compare", "cornell", "--size", "8", "8", "--spp", "4", "--samplers", "bose", "--reference", ref8,
               "--out", ".", "-q", cwd=tmp_path)
    refused(res, "compare", r"--out '\.' is a directory")
    assert os.listdir(tmp_path) == []


def test_reference_output_checked_first(pyoa, tmp_path):
    res = pyoa("reference", "cornell", "--size", "8", "8", "--spp", "8", "--pass-spp", "4", "--out",
               tmp_path / "r.png", "-q")
    refused(res, "reference", r"--out '.*r\.png': the file name must end in \.exr")
    (tmp_path / "r.exr.state.npz").mkdir()
    res = pyoa("reference", "cornell", "--size", "8", "8", "--spp", "8", "--pass-spp", "4", "--out",
               tmp_path / "r.exr", "-q")
    refused(res, "reference", r"r\.exr\.state\.npz' \(where pyoa reference keeps its running sum\) is a directory")
    assert os.listdir(tmp_path) == ["r.exr.state.npz"]


# -- references (items 4 and 6) -----------------------------------------------------------------------


def test_png_reference_is_refused(pyoa, tmp_path, old_exr):
    """An 8-bit sRGB PNG is display data, not radiance: refused, not compared as if linear."""
    png = tmp_path / "ref.png"
    write_png(png, render(load("cornell"), sampler="bose", spp=4, seed=0, width=8, height=8).image)
    for command, argv in (("render", ["--out", old_exr]), ("compare", ["--out", tmp_path / "cmp"])):
        res = pyoa(command, "cornell", "--size", "8", "8", "--spp", "4", "--reference", png, *argv, "-q")
        refused(res, command, r"--reference '.*ref\.png' holds uint8 pixels .*not linear radiance; give a float "
                              r"or half image such as EXR")
    assert old_exr.read_bytes() == OLD and sorted(os.listdir(tmp_path)) == ["old.exr", "ref.png"]


def test_non_finite_reference_is_refused(pyoa, tmp_path, old_exr):
    """A reference with a NaN pixel would make every relMSE NaN: refused before rendering, naming the pixel."""
    image = np.ones((8, 8, 3), np.float32)
    image[2, 5, 1] = np.nan
    ref = tmp_path / "ref.exr"
    out = oiio.ImageOutput.create(str(ref))  # pyoa's own write_exr refuses NaN: write it with OpenImageIO
    assert out.open(str(ref), oiio.ImageSpec(8, 8, 3, "float")) and out.write_image(image) and out.close()
    res = pyoa("render", "cornell", "--size", "8", "8", "--spp", "4", "--out", old_exr, "--reference", ref, "-q")
    refused(res, "render", r"--reference '.*ref\.exr': 1 of 64 pixels are not finite .*first at \(x, y\) \(5, 2\)$")
    assert old_exr.read_bytes() == OLD


@pytest.mark.parametrize("argv, pattern", [
    (["--crop", "6", "6", "4", "4"], r"crop 6 6 4 4 does not fit in the 8 x 8 image"),
    (["--size", "8", "4"], r"is 8 x 8, the render is 8 x 4; render with --size 8 8"),
])
def test_render_reference_checks_before_rendering(pyoa, tmp_path, old_exr, ref8, argv, pattern):
    size = [] if "--size" in argv else ["--size", "8", "8"]
    res = pyoa("render", "cornell", *size, "--spp", "4", "--out", old_exr, "--reference", ref8, *argv, "-q")
    refused(res, "render", pattern)
    assert old_exr.read_bytes() == OLD


# -- non-finite images (item 3) ----------------------------------------------------------------------


def test_render_of_a_float32_overflowing_emission_is_refused(pyoa, tmp_path, old_exr):
    data = json.loads(open(bundled()["cornell"]).read())
    lights = [s for s in data["shapes"] if "emission" in s]
    lights[0]["emission"] = [1e308, 1e308, 1e308]
    scene = tmp_path / "hot.json"
    scene.write_text(json.dumps(data))
    res = pyoa("render", scene, "--size", "8", "8", "--spp", "4", "--out", old_exr, "-q")
    refused(res, "render", r"hot\.json: shapes\[\d+\]\.emission\[0\]: expected a number in \[0, 3\.40282e\+38\]")
    assert old_exr.read_bytes() == OLD


# -- scene files (items 2 and 5) -----------------------------------------------------------------------


def test_scene_with_a_5000_digit_width_names_the_field(pyoa, tmp_path, old_exr):
    text = open(bundled()["cornell"]).read().replace('"width": 256', '"width": ' + "9" * 5000)
    scene = tmp_path / "wide.json"
    scene.write_text(text)
    res = pyoa("render", scene, "--spp", "4", "--out", old_exr, "-q")
    refused(res, "render", r"wide\.json: film\.width: expected an integer >= 1, got an integer of 5000 digits")
    assert old_exr.read_bytes() == OLD


def test_scene_nested_100000_deep(pyoa, tmp_path, old_exr):
    scene = tmp_path / "deep.json"
    scene.write_text('{"description": ' + "[" * 100_000 + "]" * 100_000 + "}")
    res = pyoa("render", scene, "--size", "8", "8", "--spp", "4", "--out", old_exr, "-q")
    refused(res, "render", r"deep\.json: invalid scene: lists or objects nested too deeply")
    assert old_exr.read_bytes() == OLD


# -- nothing is rendered before the checks (item 6), in-process ---------------------------------------


@pytest.mark.parametrize("command, argv, pattern", [
    ("render", ["--out", "missing/x.exr"], r"--out: directory 'missing' does not exist"),
    ("render", ["--out", "adir.exr"], r"--out: cannot write 'adir\.exr': it is a directory"),
    ("render", ["--out", "/proc/x.exr"], r"--out: cannot write '/proc/x\.exr'"),
    ("render", ["--out", "x.exr", "--png", "missing/x.png"], r"--png: directory 'missing' does not exist"),
    ("render", ["--out", "x.exr", "--reference", "ref.png"], r"--reference 'ref\.png' holds uint8 pixels"),
    ("render", ["--out", "x.exr", "--reference", "ref8.exr", "--crop", "6", "6", "4", "4"],
     r"crop 6 6 4 4 does not fit in the 8 x 8 image"),
    ("compare", ["--out", "missing/cmp", "--reference", "ref8.exr"], r"--out: directory 'missing' does not exist"),
    ("compare", ["--out", "cmp", "--reference", "ref4.exr"], r"is 4 x 4, the render is 8 x 8"),
    ("compare", ["--out", "cmp", "--reference", "ref8.exr", "--crop", "6", "6", "4", "4"], r"crop 6 6 4 4 does not"),
    ("reference", ["--out", "missing/r.exr", "--pass-spp", "4"], r"--out: directory 'missing' does not exist"),
])
def test_checks_come_before_the_first_render(tmp_path, monkeypatch, capsys, command, argv, pattern):
    from pyoa.commands import main
    from pyoa.render import tiles

    monkeypatch.chdir(tmp_path)
    (tmp_path / "adir.exr").mkdir()
    write_exr(tmp_path / "ref8.exr", np.ones((8, 8, 3), np.float32))
    write_exr(tmp_path / "ref4.exr", np.ones((4, 4, 3), np.float32))
    write_png(tmp_path / "ref.png", np.ones((8, 8, 3), np.float32))
    before = sorted(os.listdir(tmp_path))

    def no_render(*args, **kwargs):
        raise AssertionError("rendered before checking its arguments")

    monkeypatch.setattr(tiles, "render", no_render)
    with pytest.raises(SystemExit) as exc:
        main([command, "cornell", "--size", "8", "8", "--spp", "4", *argv, "-q"])
    assert exc.value.code == 2
    line = capsys.readouterr().err.strip()
    assert line.startswith(f"pyoa {command}: error: ") and re.search(pattern, line), line
    assert sorted(os.listdir(tmp_path)) == before
