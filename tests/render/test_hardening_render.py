"""Hardening of the library side of the renderer: ``render()`` refuses sizes
it would substitute or could not hold in memory, scene files refuse values a
float32 image cannot hold, and image writes refuse non-finite pixels and name
the user's path. Memory cases run in a child process under RLIMIT_AS, so a
regression fails the test instead of exhausting the machine."""

from __future__ import annotations

import json
import os
import re
import sys

import numpy as np
import pytest

from pyoa.render import image as image_mod
from pyoa.render.image import write_exr, write_png
from pyoa.render.render import render
from pyoa.render.scene import SceneError, bundled, load

from .limits import python_child, run_child

def cli_under_limit(limit, *argv, cwd=None):
    return run_child([sys.executable, "-m", "pyoa", *map(str, argv)], limit, cwd)


def one_line(res, command, pattern):
    assert res.returncode == 2, (res.returncode, res.stderr[-2000:])
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"pyoa {command}: error: "), res.stderr[-2000:]
    assert re.search(pattern, lines[0]), lines[0]


MEMORY = r"needs \d+\.\d (GiB|TiB|PiB), over the memory limit of \d+\.\d GiB; .*PYOA_MAX_BYTES"


# -- memory (item 5) ------------------------------------------------------------------------------


@pytest.mark.parametrize("command, extra", [
    ("render", []),
    ("reference", ["--pass-spp", "4", "--spp", "8"]),
])
def test_huge_size_is_refused_before_allocating(tmp_path, as_limit, command, extra):
    out = tmp_path / "x.exr"
    out.write_bytes(b"old")
    res = cli_under_limit(as_limit, command, "cornell", "--size", "100000", "100000", "--spp", "4", *extra,
                          "--out", out, "-q")
    one_line(res, command, r"a 100000 x 100000 image " + MEMORY)
    assert out.read_bytes() == b"old"


def test_huge_film_in_scene_is_refused(tmp_path, as_limit):
    data = json.loads(open(bundled()["cornell"]).read())
    data["film"] = {"width": 1000000000, "height": 1000000000}
    (tmp_path / "big.json").write_text(json.dumps(data))
    res = cli_under_limit(as_limit, "render", tmp_path / "big.json", "--spp", "4", "--out", tmp_path / "x.exr", "-q")
    one_line(res, "render", r"a 1000000000 x 1000000000 image " + MEMORY)


def test_float_film_size_is_refused(tmp_path, as_limit):
    data = json.loads(open(bundled()["cornell"]).read())
    data["film"] = {"width": 1e9, "height": 1e9}
    (tmp_path / "big.json").write_text(json.dumps(data))
    res = cli_under_limit(as_limit, "render", tmp_path / "big.json", "--spp", "4", "--out", tmp_path / "x.exr", "-q")
    one_line(res, "render", r"big\.json: film\.width: expected an integer >= 1, got 1000000000\.0")


def test_huge_sample_count_per_batch_is_refused(tmp_path, as_limit):
    """Every sample of a pixel is in one batch: 2^24 spp is gigabytes per worker."""
    res = cli_under_limit(as_limit, "render", "cornell", "--size", "64", "64", "--sampler", "sobol", "--spp",
                          str(2**24), "--out", tmp_path / "x.exr", "-q")
    one_line(res, "render", r"a 64 x 64 render at 16777216 spp \(18 dims\) " + MEMORY)


def test_render_api_refuses_before_allocating(as_limit):
    res = python_child("""
        import sys
        from pyoa.render.render import render
        from pyoa.render.scene import load
        try:
            render(load("cornell"), spp=4, width=100000, height=100000)
        except ValueError as exc:
            print(exc)
            sys.exit(3)
    """, as_limit)
    assert res.returncode == 3, res.stderr[-2000:]
    assert re.fullmatch(r"a 100000 x 100000 image " + MEMORY + r"\n", res.stdout), res.stdout


def test_render_max_bytes_argument():
    with pytest.raises(ValueError, match=r"a 16 x 16 render at 4 spp \(18 dims\) needs .* over the memory limit "
                                         r"of 4\.0 KiB"):
        render(load("cornell"), spp=4, width=16, height=16, max_bytes=4096)  # the image alone is 3 KiB
    assert render(load("cornell"), spp=4, width=2, height=2, max_bytes="1G").image.shape == (2, 2, 3)


# -- sizes are not substituted (item 7) ----------------------------------------------------------------


@pytest.mark.parametrize("kwargs, exc, pattern", [
    ({"width": 0, "height": 8}, ValueError, r"width must be >= 1, got 0"),
    ({"width": 8, "height": 0}, ValueError, r"height must be >= 1, got 0"),
    ({"width": 8.0, "height": 8}, TypeError, r"width must be an integer or None \(the scene's\), got float"),
    ({"width": True, "height": 8}, TypeError, r"width must be an integer"),
    ({"max_depth": 0}, ValueError, r"max_depth must be in \[1, \d+\], got 0"),
    ({"batch_paths": 0}, ValueError, r"batch_paths must be >= 1, got 0"),
])
def test_render_refuses_instead_of_substituting(kwargs, exc, pattern):
    with pytest.raises(exc, match=pattern):
        render(load("cornell"), spp=4, **{"width": 8, "height": 8, **kwargs})


def test_render_refuses_a_huge_max_depth(as_limit):
    """10^12 path segments: refused before a layout of 4 * 10^12 dimensions is built."""
    res = python_child("""
        import sys
        from pyoa.render.render import render
        from pyoa.render.scene import load
        try:
            render(load("cornell"), spp=4, width=8, height=8, max_depth=10**12)
        except ValueError as exc:
            print(exc)
            sys.exit(3)
    """, as_limit)
    assert res.returncode == 3, res.stderr[-2000:]
    assert re.fullmatch(r"max_depth must be in \[1, \d+\], got 1000000000000\n", res.stdout), res.stdout


# -- scene values a float32 image cannot hold (item 3) ------------------------------------------------------


def _scene(tmp_path, edit, name="x.json"):
    data = json.loads(open(bundled()["cornell"]).read())
    edit(data)
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return path


def _light(data):
    return next(i for i, s in enumerate(data["shapes"]) if "emission" in s)


@pytest.mark.parametrize("value", [1e308, 3.5e38])
def test_emission_over_float32_is_refused(tmp_path, value):
    index = []

    def edit(d):
        index.append(_light(d))
        d["shapes"][index[0]]["emission"] = [1.0, value, 1.0]

    path = _scene(tmp_path, edit)
    with pytest.raises(SceneError, match=rf"^x\.json: shapes\[{index[0]}\]\.emission\[1\]: expected a number in "
                                         rf"\[0, 3\.40282e\+38\], got {re.escape(json.dumps(value))}$"):
        load(path)


def test_vertices_beyond_float32_are_refused(tmp_path):
    def edit(d):
        d["shapes"][0]["to_world"] = [[1, 0, 0, 1e300], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]

    with pytest.raises(SceneError, match=r"^x\.json: shapes\[0\]\.to_world: vertices beyond the float32 range"):
        load(_scene(tmp_path, edit))


def test_film_size_must_be_an_integer_literal(tmp_path):
    with pytest.raises(SceneError, match=r"^x\.json: film\.height: expected an integer >= 1, got 256\.0"):
        load(_scene(tmp_path, lambda d: d["film"].update(height=256.0)))


def test_huge_integer_literal_names_the_field(tmp_path):
    path = tmp_path / "x.json"
    path.write_text(open(bundled()["cornell"]).read().replace('"max_depth": 5', '"max_depth": -' + "7" * 5000))
    with pytest.raises(SceneError, match=r"^x\.json: integrator\.max_depth: expected an integer in \[1, \d+\], "
                                         r"got an integer of 5000 digits$"):
        load(path)


def test_deep_nesting_is_a_scene_error(tmp_path):
    path = tmp_path / "x.json"
    path.write_text('{"shapes": ' + "[" * 100_000 + "]" * 100_000 + "}")
    with pytest.raises(SceneError, match=r"^x\.json: invalid scene: lists or objects nested too deeply$"):
        load(path)


# -- image writes (items 3 and 8) -----------------------------------------------------------------------


@pytest.mark.parametrize("write", [write_exr, write_png])
def test_non_finite_pixels_are_never_written(tmp_path, write):
    path = tmp_path / ("x.exr" if write is write_exr else "x.png")
    path.write_bytes(b"old")
    img = np.ones((4, 5, 3), np.float32)
    img[1, 3, 0] = np.nan
    img[2, 0, 2] = np.inf
    img[3, 4, 1] = -np.inf
    with pytest.raises(ValueError, match=rf"^'{re.escape(str(path))}' not written: 3 of 20 pixels are not finite "
                                         r"\(NaN or inf.*\), first at \(x, y\) \(3, 1\), \(0, 2\), \(4, 3\)$"):
        write(path, img)
    assert path.read_bytes() == b"old" and os.listdir(tmp_path) == [path.name]


def test_float64_over_float32_range_is_not_written_as_inf(tmp_path):
    img = np.ones((2, 2, 3))
    img[0, 1, 1] = 1e39  # finite in float64, inf in the float32 EXR
    with pytest.raises(ValueError, match=r"1 of 4 pixels are not finite .* first at \(x, y\) \(1, 0\)$"):
        write_exr(tmp_path / "x.exr", img)
    assert os.listdir(tmp_path) == []


def test_openimageio_errors_name_the_users_path(tmp_path, monkeypatch):
    """OpenImageIO's message names the file it was given (the hidden
    temporary): the error must name the user's path instead."""
    out = tmp_path / "x.exr"
    given = []

    class FakeOIIO:
        class ImageOutput:
            @staticmethod
            def create(path):
                given.append(path)
                return None

        @staticmethod
        def geterror():
            return f'could not find a format writer for "{given[-1]}"'

    monkeypatch.setattr(image_mod, "_oiio", lambda: FakeOIIO)
    with pytest.raises(ValueError) as exc:
        write_exr(out, np.zeros((2, 2, 3), np.float32))
    msg = str(exc.value)
    assert given and given[-1] != str(out)  # OpenImageIO was given the temporary file
    assert msg == f"cannot write {str(out)!r}: OpenImageIO: could not find a format writer for \"{out}\"", msg
    assert os.listdir(tmp_path) == []
