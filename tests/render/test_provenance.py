"""Renders say what made them: pyoa's EXRs carry the scene, sampler, settings,
software and machine in their headers (pyoa.render.provenance), and
``pyoa info`` reads them back."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import pyoa
from pyoa.commands import main
from pyoa.util.hostcpu import host_cpu
from pyoa.render import image, provenance
from pyoa.render.image import read_image, write_exr
from pyoa.render.integrator import RENDERER_VERSION
from pyoa.render.scene import load
from pyoa.render.state import scene_digest

LAYOUT_DOF7D = "0:pixel.x, 1:pixel.y, 2:lens.u, 3:lens.v, 4:time, 5:light1.u, 6:light1.v"


def common(meta: dict) -> None:
    """What every pyoa image says about the software and the machine."""
    assert meta["renderer"] == RENDERER_VERSION
    assert meta["version"] == pyoa.__version__
    assert meta["cpu"] == host_cpu().describe()
    git = provenance.git_revision()
    assert meta.get("git", "") == git
    if (Path(pyoa.__file__).resolve().parents[1] / ".git").exists():
        assert re.fullmatch(r"[0-9a-f]{40}(\+dirty)?", git), git


def test_render_writes_what_made_it(tmp_path, capsys):
    out = tmp_path / "a b.exr"  # a space: the command line is quoted as a shell takes it back
    argv = ["render", "dof7d", "--size", "12", "8", "--spp", "9", "--seed", "7", "--sampler", "bose",
            "--filter", "gaussian", "--max-depth", "2", "--out", str(out), "-q"]
    assert main(argv) == 0
    meta = image.read_attributes(out)
    scene = load("dof7d")
    want = {"kind": "render", "scene": "dof7d", "scene_file": str(scene.path), "scene_sha256": scene_digest(scene),
            "width": 12, "height": 8, "sampler": "bose", "spp": 9, "seed": 7, "max_depth": 2, "filter": "gaussian",
            "shading": "numba", "layout": LAYOUT_DOF7D,
            "command": "pyoa render dof7d --size 12 8 --spp 9 --seed 7 --sampler bose --filter gaussian "
                       f"--max-depth 2 --out '{out}' -q"}
    assert {k: meta[k] for k in want} == want
    common(meta)
    assert read_image(out).shape == (8, 12, 3)  # the pixels are untouched by the header


def test_reference_and_its_variance_say_so(tmp_path):
    out = tmp_path / "ref.exr"
    assert main(["reference", "dof7d", "--size", "8", "8", "--spp", "32", "--pass-spp", "16", "--seed", "3",
                 "--out", str(out), "-q"]) == 0
    for path, kind in ((out, "reference"), (tmp_path / "ref.variance.exr", "reference variance")):
        meta = image.read_attributes(path)
        assert (meta["kind"], meta["sampler"], meta["spp"], meta["passes"], meta["pass_spp"], meta["seed"]) == \
            (kind, "sobol", 32, 2, 16, 3)
        assert meta["command"].startswith("pyoa reference dof7d ")
        common(meta)


def test_progressive_render_counts_its_samples(tmp_path):
    out = tmp_path / "p.exr"
    argv = ["render", "dof7d", "--size", "8", "8", "--sampler", "faure", "--progressive", "--out", str(out), "-q"]
    assert main([*argv, "--spp", "4"]) == 0
    meta = image.read_attributes(out)
    assert (meta["kind"], meta["sampler"], meta["samples"], meta["spp"]) == ("progressive render", "faure", 4, 4)
    assert "base" in meta
    assert main([*argv, "--spp", "8", "--resume"]) == 0
    assert (image.read_attributes(out)["samples"], image.read_attributes(out)["spp"]) == (8, 8)


def test_info_prints_them_and_json(tmp_path, capsys):
    out = tmp_path / "a.exr"
    assert main(["render", "dof7d", "--size", "8", "8", "--spp", "4", "--out", str(out), "-q"]) == 0
    plain = tmp_path / "plain.exr"
    write_exr(plain, np.ones((4, 5, 3), np.float32))
    capsys.readouterr()
    assert main(["info", str(out), str(plain)]) == 0
    text = capsys.readouterr().out
    assert f"{out}: 8 x 8, 3 channels (float)" in text
    assert re.search(r"^  kind +render$", text, re.M)
    assert re.search(r"^  sampler +bose$", text, re.M)
    assert re.search(r"^  command +pyoa render dof7d --size 8 8 --spp 4 ", text, re.M)
    assert f"{plain}: 5 x 4, 3 channels (float)\n  no pyoa metadata" in text
    assert main(["info", "--json", str(out)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data[str(out)]["spp"] == 4 and data[str(out)]["width_px"] == 8
    assert data[str(out)] == dict(image.read_attributes(out), width_px=8, height_px=8, channels=3)


def test_info_refuses_a_missing_file_before_printing(tmp_path, capsys):
    out = tmp_path / "a.exr"
    write_exr(out, np.ones((2, 2, 3), np.float32))
    with pytest.raises(SystemExit) as exc:
        main(["info", str(out), str(tmp_path / "none.exr")])
    assert exc.value.code == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "no such image" in captured.err


def test_metadata_values_are_checked_before_writing(tmp_path):
    out = tmp_path / "a.exr"
    for bad in (1.5, True, None, [1]):
        with pytest.raises(TypeError, match="image metadata 'x' must be a str or an int"):
            write_exr(out, np.ones((2, 2, 3), np.float32), {"x": bad})
        assert not out.exists()
    write_exr(out, np.ones((2, 2, 3), np.float32), {"x": "y", "n": 3})
    assert image.read_attributes(out) == {"x": "y", "n": 3}
