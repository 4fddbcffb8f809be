"""No lost work (issue 48, items 1, 2 and the truncated reference of 10).

* Every file pyoa reads goes through one regular-file check
  (:func:`pyoa.render.state.check_state_file` / ``open_regular``): a FIFO
  given as an image, a scene or a mesh is refused at once, never waited on.
* No command writes a file it reads: an output that is an input, in any
  spelling (``./``, ``sub/../``, a symlink, a hard link), is refused before
  any rendering (:func:`pyoa.util.atomic.check_not_inputs`).
* A variance file is tied to its reference by the digest of the reference's
  pixels in its header; one of another image is refused, never used.
* A truncated reference says so, with OpenImageIO's reason.

Commands that could hang run in a subprocess with a timeout, so that the
old hang fails its test instead of blocking the suite.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time

import numpy as np
import pytest

from pyoa.commands import main
from pyoa.render.image import read_image, write_exr
from pyoa.render.image import read_attributes as read
from pyoa.render.reference import reference_noise
from pyoa.render.scene import SceneError, bundled, load

#: Seconds a refused command may take before the test calls it a hang (a refusal takes about 1 s: imports).
HANG = 60
SIZE = ["--size", "8", "8"]


def pyoa(*argv, cwd=None) -> subprocess.CompletedProcess:
    """``python -m pyoa argv`` in a child, killed after :data:`HANG` seconds (TimeoutExpired: a hang)."""
    return subprocess.run([sys.executable, "-m", "pyoa", *map(str, argv)], capture_output=True, text=True,
                          cwd=cwd, timeout=HANG, env={**os.environ, "PYOA_BACKEND": "numpy"})


def refused_line(res: subprocess.CompletedProcess, command: str) -> str:
    """Exit status 2 and one line ``pyoa COMMAND: error: ...``: that line."""
    assert res.returncode == 2, (res.returncode, res.stdout, res.stderr)
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"pyoa {command}: error: "), res.stderr
    return lines[0]


def refused_in_process(capsys, argv) -> str:
    """Run ``pyoa argv`` in-process: exit status 2, one line on stderr, nothing rendered (no progress)."""
    with pytest.raises(SystemExit) as exc:
        main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    assert exc.value.code == 2, err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"pyoa {argv[0]}: error: "), err
    return lines[0]


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """A reference of 2 passes (so with a variance file) made by ``pyoa reference``, 8 x 8."""
    d = tmp_path_factory.mktemp("lost_work")
    assert main(["reference", "cornell", "--spp", "8", "--pass-spp", "4", *SIZE, "-q", "--out",
                 str(d / "ref.exr")]) == 0
    return d


@pytest.fixture
def d(made, tmp_path, monkeypatch):
    """A copy of the reference and its variance file in the current directory (for relative spellings)."""
    for name in ("ref.exr", "ref.variance.exr"):
        (tmp_path / name).write_bytes((made / name).read_bytes())
    monkeypatch.chdir(tmp_path)
    return tmp_path


def snapshot(d) -> dict:
    return {p.name: p.read_bytes() for p in sorted(d.iterdir()) if p.is_file() and not p.is_symlink()}


# -- item 1: a FIFO is refused at once ----------------------------------------------------------------


@pytest.mark.parametrize("argv", [
    ["info", "f.exr"],
    ["render", "cornell", "--spp", "4", "--size", "16", "16", "--reference", "f.exr", "--out", "o.exr"],
    ["compare", "cornell", "--samplers", "bose", "--reference", "f.exr", "--out", "c"],
], ids=["info", "render", "compare"])
def test_a_fifo_image_is_refused_at_once(tmp_path, argv):
    """OpenImageIO's open of a FIFO waits for a writer for ever: refused by the one regular-file check."""
    os.mkfifo(tmp_path / "f.exr")
    t = time.perf_counter()
    line = refused_line(pyoa(*argv, cwd=tmp_path), argv[0])
    seconds = time.perf_counter() - t
    assert "'f.exr' (" in line and "is a FIFO (named pipe), not a regular file" in line, line
    assert seconds < HANG
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.exr"]


def test_a_fifo_variance_file_is_refused_at_once(d):
    os.unlink("ref.variance.exr")
    os.mkfifo("ref.variance.exr")
    line = refused_line(pyoa("render", "cornell", "--spp", "4", *SIZE, "--reference", "ref.exr", "--out", "o.exr",
                             cwd=d), "render")
    assert "'ref.variance.exr' (the variance of a reference) is a FIFO (named pipe)" in line, line


def test_a_scene_that_is_not_a_regular_file_is_refused(tmp_path):
    """A FIFO scene file was called "not found"; a symlink to a device likewise: now said what it is."""
    os.mkfifo(tmp_path / "f.json")
    with pytest.raises(SceneError, match=r"^f\.json: '.*/f\.json' \(a scene file\) is a FIFO \(named pipe\), not a "
                                         r"regular file; give a scene \.json file$"):
        load(tmp_path / "f.json")
    (tmp_path / "z.json").symlink_to("/dev/zero")
    with pytest.raises(SceneError, match=r"is a symlink to '/dev/zero', a character device, not a regular file"):
        load(tmp_path / "z.json")


def test_a_mesh_that_is_not_a_regular_file_is_refused(tmp_path):
    data = json.loads(open(bundled()["cornell"]).read())
    data["shapes"].append({"type": "mesh", "file": "m.obj", "material": next(iter(data["materials"]))})
    (tmp_path / "x.json").write_text(json.dumps(data))
    os.mkfifo(tmp_path / "m.obj")
    with pytest.raises(SceneError, match=r"^x\.json: shapes\[\d+\]\.file: .*m\.obj' \(a mesh file\) is a FIFO "
                                         r"\(named pipe\), not a regular file"):
        load(tmp_path / "x.json")


def test_a_file_a_mesh_names_that_is_not_a_regular_file_is_refused(tmp_path):
    """An OBJ's material library that is a FIFO blocked trimesh's load for ever (it opens what exists)."""
    (tmp_path / "a.obj").write_text("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n")
    os.mkfifo(tmp_path / "m.mtl")
    data = json.loads(open(bundled()["cornell"]).read())
    data["shapes"].append({"type": "mesh", "file": "a.obj", "material": next(iter(data["materials"]))})
    (tmp_path / "x.json").write_text(json.dumps(data))
    line = refused_line(pyoa("render", "x.json", *SIZE, "--spp", "4", cwd=tmp_path), "render")
    assert line.endswith(f"m.mtl' (a file that mesh 'a.obj' names) is a FIFO (named pipe), not a regular file; "
                         "give a regular file"), line
    assert line.startswith("pyoa render: error: x.json: shapes["), line


# -- item 10: a truncated reference ------------------------------------------------------------------


def test_a_truncated_reference_says_so_with_openimageio_reason(d, capsys):
    data = (d / "ref.exr").read_bytes()
    (d / "t.exr").write_bytes(data[: len(data) * 2 // 3])
    line = refused_in_process(capsys, ["render", "cornell", "--spp", "4", *SIZE, "--reference", "t.exr",
                                       "--out", "o.exr"])
    assert line.startswith("pyoa render: error: reading 't.exr' failed: it is truncated or damaged (OpenImageIO: "), line
    assert line.endswith(")") and len(line) > len("pyoa render: error: reading 't.exr' failed: it is truncated or "
                                                  "damaged (OpenImageIO: )"), line
    assert not (d / "o.exr").exists()


# -- item 2: an output that is an input ---------------------------------------------------------------


SPELLINGS = ["./ref.exr", "sub/../ref.exr", "symlink.exr", "hardlink.exr"]


def spell(d, spelling: str) -> str:
    (d / "sub").mkdir(exist_ok=True)
    if spelling == "symlink.exr":
        os.symlink("ref.exr", d / spelling)
    elif spelling == "hardlink.exr":
        os.link(d / "ref.exr", d / spelling)
    return spelling


@pytest.mark.parametrize("spelling", SPELLINGS)
def test_a_render_never_replaces_its_reference(d, capsys, spelling):
    """The issue's case: --out ./ref.exr --reference ref.exr rendered, then replaced the reference."""
    out = spell(d, spelling)
    before = snapshot(d)
    line = refused_in_process(capsys, ["render", "cornell", "--spp", "4", *SIZE, "--out", out,
                                       "--reference", "ref.exr"])
    assert line == (f"pyoa render: error: --out {out!r} is the same file as --reference 'ref.exr' (one device and "
                    "inode), which this command reads: writing it would replace it; give another --out")
    assert snapshot(d) == before


@pytest.mark.parametrize("argv, option", [
    (["--out", "ref.variance.exr"], "--out"),
    (["--out", "o.exr", "--png", "link.png"], "--png"),
    (["--progressive", "--sampler", "sobol", "--out", "./ref.exr"], "--out"),
], ids=["variance", "png", "progressive"])
def test_no_render_output_is_the_reference_or_its_variance(d, capsys, argv, option):
    """--progressive would replace it at every doubling; a PNG through a symlink; the variance file."""
    os.symlink("ref.exr", "link.png")
    before = snapshot(d)
    line = refused_in_process(capsys, ["render", "cornell", "--spp", "4", *SIZE, *argv, "--reference", "ref.exr"])
    assert line.startswith(f"pyoa render: error: {option} "), line
    assert "which this command reads: writing it would replace it" in line, line
    assert snapshot(d) == before and not (d / "o.exr").exists()


def test_compare_outputs_are_never_its_reference(d, capsys):
    os.symlink("ref.exr", "c.png")
    before = snapshot(d)
    line = refused_in_process(capsys, ["compare", "cornell", "--samplers", "bose", "--spp", "4", "--reference",
                                       "ref.exr", "--out", "c"])
    assert "--out 'c.png' is the same file as --reference 'ref.exr'" in line, line
    assert snapshot(d) == before and not (d / "c.md").exists() and os.path.islink("c.png")


def test_study_files_are_never_its_reference(d, capsys):
    """A study's report (or study.csv, appended to) linked to its reference is refused before any render."""
    (d / "D").mkdir()
    os.link(d / "ref.exr", d / "D" / "study.md")
    before = snapshot(d)
    line = refused_in_process(capsys, ["study", "cornell", "--samplers", "bose", "--spp", "16", "--seeds", "2",
                                       *SIZE, "--reference", "ref.exr", "--out", "D", "-q"])
    assert "--out 'D/study.md' is the same file as cornell's reference 'ref.exr'" in line, line
    assert snapshot(d) == before and sorted(os.listdir(d / "D")) == [".lock", "study.md"]


def test_reference_output_is_never_its_scene(d, capsys):
    scene = d / "s.json"
    scene.write_text(open(bundled()["cornell"]).read())
    os.symlink("s.json", "r.exr")
    line = refused_in_process(capsys, ["reference", str(scene), "--spp", "8", "--pass-spp", "4", *SIZE,
                                       "--out", "r.exr"])
    assert "--out 'r.exr' is the same file as the scene file" in line, line
    assert os.path.islink("r.exr") and not os.path.exists("r.variance.exr")


# -- item 2: a variance file belongs to its reference --------------------------------------------------


def test_pyoa_reference_ties_its_variance_to_its_pixels(made):
    from pyoa.render.image import pixel_digest
    from pyoa.render.reference import VARIANCE_OF

    ref = read_image(made / "ref.exr")[..., :3]
    assert read(made / "ref.variance.exr")[VARIANCE_OF] == pixel_digest(ref)
    assert reference_noise(made / "ref.exr", ref, (0, 0, 4, 4)) is not None


def test_a_variance_file_of_an_image_written_over_its_reference_is_refused(d, capsys):
    """The issue's case: a render written over ref.exr left ref.variance.exr beside it, and the next
    --reference ref.exr subtracted the old reference's noise (a negative corrected relMSE)."""
    other = read_image("ref.exr")[..., :3] * 1.5
    write_exr("ref.exr", other, dict(kind="render"))
    for argv in (["render", "cornell", "--spp", "4", *SIZE, "--out", "o.exr", "--reference", "ref.exr"],
                 ["compare", "cornell", "--samplers", "bose", "--spp", "4", "--reference", "ref.exr", "--out", "c"]):
        line = refused_in_process(capsys, argv)
        assert line.endswith("ref.variance.exr is the variance of another image than 'ref.exr' (its pixels changed "
                             "since the variance was written, e.g. an image written over it): remove "
                             "ref.variance.exr (its noise is then unknown) or make the reference again with pyoa "
                             "reference"), line
    assert not any(os.path.exists(p) for p in ("o.exr", "c.md", "c.csv", "c.png"))
    with pytest.raises(ValueError, match="is the variance of another image"):
        reference_noise("ref.exr", other, (0, 0, 4, 4))


def _strip(path, kind=None):
    """Write ``path``'s pixels again without pyoa's header (an older pyoa's file), or with only ``kind``."""
    write_exr(path, read_image(path)[..., :3], dict(kind=kind) if kind else None)


def test_an_old_variance_file_is_used_with_a_note(d, capsys):
    """Variance files of before the digest (docs/results/study has some) cannot be checked: used, and said."""
    _strip("ref.exr")
    _strip("ref.variance.exr")
    ref = read_image("ref.exr")[..., :3]
    assert reference_noise("ref.exr", ref, (0, 0, 4, 4)) is not None
    err = capsys.readouterr().err
    assert err == ("pyoa: note: ref.variance.exr does not record which reference it belongs to (written before pyoa "
                   "recorded it); taken as the variance of 'ref.exr' unchecked; make the reference again with pyoa "
                   "reference to tie them\n")


def test_an_old_variance_file_beside_a_render_is_refused(d):
    """Without a digest, a reference whose header says it is a render is known not to be its reference."""
    _strip("ref.variance.exr")
    _strip("ref.exr", kind="render")
    with pytest.raises(ValueError, match=r"^ref\.variance\.exr is not the variance of 'ref\.exr' \('ref\.exr' is a "
                                         r"render\): remove ref\.variance\.exr"):
        reference_noise("ref.exr", read_image("ref.exr")[..., :3], (0, 0, 4, 4))


def test_the_bundled_study_references_keep_their_variance():
    """docs/results/study ships references with variance files of before the digest: still used."""
    root = os.path.join(os.path.dirname(__file__), "..", "..", "docs", "results", "study")
    path = os.path.join(root, "reference-cornell.exr")
    noise = reference_noise(path, read_image(path)[..., :3], (0, 0, 8, 8))
    assert noise is not None and np.isfinite(noise).all() and min(noise) > 0
