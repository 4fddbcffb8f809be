"""The renderer's command line: ``pyoa render``, ``pyoa compare``, ``pyoa reference``
(:mod:`pyoa.commands.render`), run in-process through :func:`pyoa.commands.main`."""

from __future__ import annotations

import csv
import os
import re

import numpy as np
import pytest

from pyoa.commands import main
from pyoa.commands import render as render_commands
from pyoa.render import reference, tiles
from pyoa.render import image as image_mod
from pyoa.render.image import read_image, rel_mse, write_exr
from pyoa.render.render import render
from pyoa.render.scene import load


def run_error(capsys, argv) -> str:
    """Run ``pyoa argv`` expecting exit status 2; return its stderr."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert f"pyoa {argv[0]}: error:" in err or "usage:" in err
    return err


def listing(path):
    return sorted(os.listdir(path))


# -- pyoa render ----------------------------------------------------------------------


def test_render_writes_exr_and_png(tmp_path, capsys):
    out, png = tmp_path / "x.exr", tmp_path / "x.png"
    assert main(["render", "cornell", "--size", "16", "16", "--spp", "4", "--out", str(out), "--png", str(png),
                 "-q"]) == 0
    assert capsys.readouterr().out == ""  # -q: nothing but results, and there are none
    img = read_image(out)
    assert img.shape == (16, 16, 3) and img.dtype == np.float32
    assert np.all(np.isfinite(img)) and img.mean() > 0
    # the EXR holds exactly the render (default sampler bose, seed 0)
    want = render(load("cornell"), sampler="bose", spp=4, seed=0, width=16, height=16).image
    np.testing.assert_array_equal(img, want)
    # the PNG: 8-bit sRGB of the same image
    p = read_image(png)
    assert p.shape == (16, 16, 3)
    np.testing.assert_array_equal(np.round(p * 255).astype(np.uint8), image_mod.to_srgb8(want))
    assert listing(tmp_path) == ["x.exr", "x.png"]  # no temporary files left


def test_render_non_square_size_and_options(tmp_path, capsys):
    out = tmp_path / "r.exr"
    assert main(["render", "dof7d", "--size", "12", "8", "--spp", "8", "--sampler", "sobol", "--seed", "3",
                 "--max-depth", "2", "--filter", "gaussian", "--first", "light1", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "dof7d: 12 x 8, sobol 8 spp, 7 dims (0:light1.u, 1:light1.v, 2:pixel.x" in text
    assert str(out) in text
    want = render(load("dof7d"), sampler="sobol", spp=8, seed=3, width=12, height=8, max_depth=2,
                  filter="gaussian", first=["light1"]).image
    np.testing.assert_array_equal(read_image(out), want)


def _relmse_line(capsys, ref_path, out) -> str:
    """What ``pyoa render --reference REF --crop 4 4 8 8`` (16 x 16, 4 spp) prints."""
    assert main(["render", "cornell", "--size", "16", "16", "--spp", "4", "--out", str(out), "-q",
                 "--reference", str(ref_path), "--crop", "4", "4", "8", "8"]) == 0
    return capsys.readouterr().out.strip()


def test_render_reference_prints_relmse(tmp_path, capsys):
    ref_path, out = tmp_path / "ref.exr", tmp_path / "x.exr"
    ref = render(load("cornell"), sampler="sobol", spp=16, seed=9, width=16, height=16).image
    write_exr(ref_path, ref)
    line = _relmse_line(capsys, ref_path, out)
    m = re.fullmatch(r"relMSE (\S+), crop (\S+) \(the reference's own noise is unknown: no ref.variance.exr "
                     r"beside it, as `pyoa reference` writes\)", line)
    assert m, line
    img = read_image(out)
    assert float(m.group(1)) == pytest.approx(rel_mse(img, ref), rel=1e-5)
    assert float(m.group(2)) == pytest.approx(rel_mse(img, ref, (4, 4, 8, 8)), rel=1e-5)
    assert float(m.group(1)) > 0
    # against itself: 0
    assert main(["render", "cornell", "--size", "16", "16", "--spp", "4", "--out", str(tmp_path / "y.exr"), "-q",
                 "--reference", str(out)]) == 0
    assert capsys.readouterr().out.strip().startswith("relMSE 0 (the reference's own noise is unknown")


def test_render_reference_subtracts_the_reference_noise(tmp_path, capsys):
    from pyoa.render.reference import reference_noise

    ref_path, out = tmp_path / "ref.exr", tmp_path / "x.exr"
    assert main(["reference", "cornell", "--size", "16", "16", "--spp", "64", "--pass-spp", "16",
                 "--out", str(ref_path), "-q"]) == 0
    line = _relmse_line(capsys, ref_path, out)
    m = re.fullmatch(r"relMSE (\S+), crop (\S+); less the reference's own noise \(an estimated (\S+), crop (\S+), "
                     r"from ref.variance.exr\): (\S+), crop (\S+)", line)
    assert m, line
    ref = read_image(ref_path)[..., :3].astype(np.float64)
    noise = reference_noise(ref_path, ref, (4, 4, 8, 8))
    img = read_image(out)
    measured = rel_mse(img, ref), rel_mse(img, ref, (4, 4, 8, 8))
    assert [float(m.group(k)) for k in (3, 4)] == pytest.approx(noise, rel=2e-3)
    assert float(m.group(5)) == pytest.approx(measured[0] - noise[0], rel=1e-5)
    assert float(m.group(6)) == pytest.approx(measured[1] - noise[1], rel=1e-5)


@pytest.mark.parametrize("argv, message", [
    (["render", "nosuchscene"], r"nosuchscene: no such scene file or bundled scene; bundled: .*cornell"),
    (["render", "cornell", "--sampler", "nosuchsampler", "--spp", "4"], r"nosuchsampler"),
    (["render", "cornell", "--sampler", "bose", "--spp", "10"], r"bose: 10 is not .*nearest: 9 \(s=3\), 16"),
    (["render", "cornell", "--sampler", "sobol", "--spp", "12"], r"12"),
    (["render", "cornell", "--first", "light9"], r"unknown integrand dimension 'light9'; valid: pixel\.x"),
    (["render", "cornell", "--max-depth", "0"], r"--max-depth must be in \[1, \d+\], got 0"),
    (["render", "missing/scene.json"], r"scene file not found"),
])
def test_render_errors(tmp_path, capsys, argv, message):
    out = tmp_path / "x.exr"
    err = run_error(capsys, [*argv, "--size", "8", "8", "--out", str(out), "-q"])
    assert re.search(message, err), err
    assert not out.exists()


def test_render_reference_of_the_wrong_size(tmp_path, capsys):
    ref = tmp_path / "ref.exr"
    write_exr(ref, np.ones((8, 12, 3), dtype=np.float32))
    err = run_error(capsys, ["render", "cornell", "--size", "16", "16", "--spp", "4", "--out",
                             str(tmp_path / "x.exr"), "-q", "--reference", str(ref)])
    assert "is 12 x 8, the render is 16 x 16; render with --size 12 8" in err
    err = run_error(capsys, ["render", "cornell", "--size", "16", "16", "--spp", "4", "--out",
                             str(tmp_path / "x.exr"), "-q", "--reference", str(tmp_path / "none.exr")])
    assert "no such image" in err


@pytest.mark.parametrize("crop", [["10", "10", "8", "8"], ["0", "0", "0", "4"], ["-1", "0", "4", "4"],
                                  ["0", "0", "17", "1"]])
def test_render_crop_outside_the_image(tmp_path, capsys, crop):
    ref = tmp_path / "ref.exr"
    write_exr(ref, np.ones((16, 16, 3), dtype=np.float32))
    err = run_error(capsys, ["render", "cornell", "--size", "16", "16", "--spp", "4", "--out",
                             str(tmp_path / "x.exr"), "-q", "--reference", str(ref), "--crop", *crop])
    assert f"crop {' '.join(crop)} does not fit in the 16 x 16 image" in err


def test_render_failure_leaves_the_output_untouched(tmp_path, monkeypatch):
    out, png = tmp_path / "x.exr", tmp_path / "x.png"
    out.write_bytes(b"previous exr")
    png.write_bytes(b"previous png")

    def boom(*args, **kwargs):
        raise RuntimeError("render failed")

    monkeypatch.setattr(tiles, "render", boom)
    with pytest.raises(RuntimeError, match="render failed"):
        main(["render", "cornell", "--size", "8", "8", "--spp", "4", "--out", str(out), "--png", str(png), "-q"])
    assert out.read_bytes() == b"previous exr" and png.read_bytes() == b"previous png"
    assert listing(tmp_path) == ["x.exr", "x.png"]


def test_failed_image_write_is_atomic(tmp_path, monkeypatch):
    """OpenImageIO failing half-way through: the old file stays, no temporary is left."""
    out = tmp_path / "x.exr"
    out.write_bytes(b"previous exr")
    real = image_mod._oiio()

    class FailingOutput:
        def __init__(self):
            self.path = None

        def open(self, path, spec):
            self.path = path
            with open(path, "wb") as fh:
                fh.write(b"half an image")
            return True

        def write_image(self, pixels):
            return False

        def close(self):
            return True

        def geterror(self):
            return "disk full"

    class FakeOIIO:
        ImageSpec = real.ImageSpec

        class ImageOutput:
            @staticmethod
            def create(path):
                return FailingOutput()

        @staticmethod
        def geterror():
            return ""

    monkeypatch.setattr(image_mod, "_oiio", lambda: FakeOIIO)
    with pytest.raises(OSError, match=f"cannot write {re.escape(repr(str(out)))}: OpenImageIO: disk full"):
        image_mod.write_exr(out, np.zeros((8, 8, 3), np.float32))
    assert out.read_bytes() == b"previous exr"
    assert listing(tmp_path) == ["x.exr"]


# -- pyoa compare -----------------------------------------------------------------------


@pytest.fixture
def reference16(tmp_path):
    path = tmp_path / "ref.exr"
    write_exr(path, render(load("cornell"), sampler="sobol", spp=64, seed=5, width=16, height=16).image)
    return path


def test_compare(tmp_path, capsys, reference16):
    stem = tmp_path / "cmp"
    assert main(["compare", "cornell", "--size", "16", "16", "--spp", "12", "--samplers", "random, bose,sobol",
                 "--reference", str(reference16), "--out", str(stem), "-q"]) == 0
    printed = capsys.readouterr().out
    md = (tmp_path / "cmp.md").read_text()
    assert md in printed
    with open(tmp_path / "cmp.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["sampler"] for r in rows] == ["random", "bose", "sobol"]
    assert [r["seed"] for r in rows] == ["0", "0", "0"]
    # bose: 9 or 16 are valid, 9 is nearer 12; sobol: 8 and 16 are equally near, ties go to fewer
    assert [int(r["spp"]) for r in rows] == [12, 9, 8]
    assert [int(r["spp_asked"]) for r in rows] == [12, 12, 12]
    ref = read_image(reference16)
    for r in rows:
        img = render(load("cornell"), sampler=r["sampler"], spp=int(r["spp"]), seed=0, width=16, height=16).image
        assert float(r["relmse"]) == pytest.approx(rel_mse(img, ref), rel=1e-9)
        # default crop: the quarter-size window at (W/4, H/4)
        assert float(r["relmse_crop"]) == pytest.approx(rel_mse(img, ref, (4, 4, 4, 4)), rel=1e-9)
        assert float(r["seconds"]) >= 0
    lines = [ln for ln in md.splitlines() if ln.startswith("| ")]
    assert lines[0] == "| sampler | spp | relMSE (image) | relMSE (crop 4x4 at 4,4) | / random | seconds |"
    assert len(lines) == 1 + 3
    # a substituted count is in the table's own spp column; one seed: values without intervals
    assert lines[2].startswith(f"| bose | 9 (12 asked: nearest valid) | {float(rows[1]['relmse']):.3g} | ")
    assert lines[1].startswith(f"| random | 12 | {float(rows[0]['relmse']):.3g} | ")
    assert f"| {float(rows[1]['relmse']) / float(rows[0]['relmse']):.2f} |" in lines[2]
    # a reference with no variance file: its noise is said to be unknown, nothing is subtracted
    assert "its own noise is unknown (no ref.variance.exr beside it" in md
    assert "one seed: no interval" in md
    fig = read_image(tmp_path / "cmp.png")
    assert fig.ndim == 3 and fig.shape[0] > 50 and fig.shape[1] > fig.shape[0]
    assert sorted(os.listdir(tmp_path)) == ["cmp.csv", "cmp.md", "cmp.png", "ref.exr"]


def test_compare_over_seeds_subtracts_the_reference_noise(tmp_path, capsys):
    """``--seeds N``: N renders per sampler (seeds --seed ..), each cell the mean less the reference's
    own noise (from its variance file) with a Student-t interval, ratios with ratio_ci's interval:
    the statistics of ``pyoa study``."""
    from pyoa.analysis.statistics import mean_ci, ratio_ci
    from pyoa.render.reference import reference_noise

    ref_path = tmp_path / "ref.exr"
    assert main(["reference", "cornell", "--size", "16", "16", "--spp", "64", "--pass-spp", "16",
                 "--out", str(ref_path), "-q"]) == 0
    assert (tmp_path / "ref.variance.exr").is_file()
    stem = tmp_path / "cmp"
    assert main(["compare", "cornell", "--size", "16", "16", "--spp", "9", "--samplers", "bose,random",
                 "--seed", "5", "--seeds", "3", "--reference", str(ref_path), "--out", str(stem), "-q"]) == 0
    md = capsys.readouterr().out
    with open(tmp_path / "cmp.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [(r["sampler"], int(r["seed"])) for r in rows] == [("bose", 5), ("bose", 6), ("bose", 7),
                                                                ("random", 5), ("random", 6), ("random", 7)]
    ref = read_image(ref_path)[..., :3].astype(np.float64)
    for r in rows[::2]:
        img = render(load("cornell"), sampler=r["sampler"], spp=9, seed=int(r["seed"]), width=16, height=16).image
        assert float(r["relmse"]) == pytest.approx(rel_mse(img, ref), rel=1e-9)
    noise, crop_noise = reference_noise(ref_path, ref, (4, 4, 4, 4))
    assert noise > 0 and crop_noise > 0
    assert f"adds an estimated {noise:.2g} to every image relMSE and {crop_noise:.2g}" in md
    values = {n: np.array([float(r["relmse"]) for r in rows if r["sampler"] == n]) for n in ("bose", "random")}
    crops = {n: np.array([float(r["relmse_crop"]) for r in rows if r["sampler"] == n]) for n in ("bose", "random")}
    lines = [ln for ln in md.splitlines() if ln.startswith("| ")]
    for line, name in zip(lines[1:], ("bose", "random")):
        m, lo, hi = mean_ci(values[name])
        cm, clo, chi = mean_ci(crops[name])
        assert line.startswith(f"| {name} | 9 | {m - noise:.3g} ± {(hi - lo) / 2:.2g} | "
                               f"{cm - crop_noise:.3g} ± {(chi - clo) / 2:.2g} | ")
    r, lo, hi = ratio_ci(values["random"], values["bose"], shift_a=noise, shift_b=noise)
    assert f"| {r:.2f} [{lo:.2f}, {hi:.2f}] |" in lines[2]
    assert "3 seeds (5..7) per sampler" in md


@pytest.mark.parametrize(("argv", "message"), [
    (["--seeds", "0"], r"--seeds must be in \[1, 65536\]"),
    (["--seed", "4294967295", "--seeds", "2"], r"--seed must be in \[0, 4294967294\] \(the first of --seeds"),
])
def test_compare_refuses_bad_seeds(tmp_path, capsys, reference16, argv, message):
    err = run_error(capsys, ["compare", "cornell", "--size", "16", "16", "--spp", "4", "--samplers", "bose",
                             "--reference", str(reference16), "--out", str(tmp_path / "cmp"), "-q", *argv])
    assert re.search(message, err), err
    assert not (tmp_path / "cmp.md").exists()


def test_compare_crop_and_errors(tmp_path, capsys, reference16):
    stem = tmp_path / "cmp"
    assert main(["compare", "cornell", "--size", "16", "16", "--spp", "4", "--samplers", "bose",
                 "--reference", str(reference16), "--out", str(stem), "--crop", "0", "8", "16", "8", "-q"]) == 0
    capsys.readouterr()
    assert "relMSE (crop 16x8 at 0,8)" in (tmp_path / "cmp.md").read_text()
    (tmp_path / "cmp.md").unlink()

    def fail(argv, message):
        err = run_error(capsys, ["compare", "cornell", "--size", "16", "16", "--spp", "4", "--out", str(stem), "-q",
                                 *argv])
        assert re.search(message, err), err
        assert not (tmp_path / "cmp.md").exists()

    fail(["--samplers", "bose,nosuchsampler", "--reference", str(reference16)], "nosuchsampler")
    fail(["--samplers", "bose", "--reference", str(tmp_path / "none.exr")], "no such image")
    small = tmp_path / "small.exr"
    write_exr(small, np.ones((8, 8, 3), dtype=np.float32))
    fail(["--samplers", "bose", "--reference", str(small)], r"render with --size 8 8")
    fail(["--samplers", "bose", "--reference", str(reference16), "--crop", "12", "0", "8", "8"], "does not fit")
    with pytest.raises(SystemExit) as exc:  # --reference is required
        main(["compare", "cornell", "-q"])
    assert exc.value.code == 2


def test_compare_unknown_sampler_renders_nothing(tmp_path, capsys, monkeypatch, reference16):
    calls = []
    monkeypatch.setattr(tiles, "render", lambda *a, **k: calls.append(1))
    run_error(capsys, ["compare", "cornell", "--samplers", "random,nope", "--reference", str(reference16),
                       "--out", str(tmp_path / "cmp"), "-q"])
    assert calls == []


# -- pyoa reference ------------------------------------------------------------------------


REF_ARGS = ["cornell", "--size", "8", "8", "--spp", "8", "--pass-spp", "4", "-q"]


def test_reference_is_the_mean_of_passes(tmp_path):
    out = tmp_path / "ref.exr"
    assert main(["reference", *REF_ARGS, "--out", str(out)]) == 0
    img = read_image(out)
    assert img.shape == (8, 8, 3)
    sc = load("cornell")
    seeds = [reference.pass_seed(0, k) for k in (0, 1)]
    # independent seeds, none of them a small one a render would use
    assert len(set(seeds)) == 2 and min(seeds) > 1000
    passes = [render(sc, sampler="sobol", spp=4, seed=s, width=8, height=8).image.astype(np.float64) for s in seeds]
    np.testing.assert_array_equal(img, ((passes[0] + passes[1]) / 2).astype(np.float32))
    # beside it, the per-pixel variance of the mean: for 2 passes (a - b)^2 / 4
    var = read_image(tmp_path / "ref.variance.exr")
    want = ((passes[0] - passes[1]) ** 2 / 4).astype(np.float32)
    np.testing.assert_allclose(var, want, rtol=1e-6, atol=1e-12)
    assert var.max() > 0
    assert listing(tmp_path) == ["ref.exr", "ref.variance.exr"]  # the state file is removed at the end


#: tiles.render (what every pass task calls) itself, before any test wraps it
REAL_RENDER = tiles.render


def record_passes(monkeypatch, fail_at=None):
    """Wrap tiles.render (one call per reference pass): record each pass's
    seed, and raise KeyboardInterrupt in call ``fail_at`` (1-based) to
    simulate an interrupted run. Returns the list of seeds."""
    calls = []

    def wrapped(scene, settings, **kwargs):
        calls.append(settings.seed)
        if len(calls) == fail_at:
            raise KeyboardInterrupt
        return REAL_RENDER(scene, settings, **kwargs)

    monkeypatch.setattr(tiles, "render", wrapped)
    return calls


def test_reference_resumes_after_an_interruption(tmp_path, monkeypatch):
    out = tmp_path / "ref.exr"
    state = tmp_path / "ref.exr.state.npz"
    # the uninterrupted result
    assert main(["reference", *REF_ARGS, "--out", str(tmp_path / "full.exr")]) == 0
    full = read_image(tmp_path / "full.exr")

    calls = record_passes(monkeypatch, fail_at=2)
    with pytest.raises(SystemExit, match="^130$"):  # pyoa.commands: Ctrl-C is exit status 130
        main(["reference", *REF_ARGS, "--out", str(out)])
    assert calls == [reference.pass_seed(0, 0), reference.pass_seed(0, 1)]
    assert state.exists() and not out.exists()
    with np.load(state) as st:
        assert int(st["passes"]) == 1 and st["sum"].shape == (8, 8, 3)

    calls = record_passes(monkeypatch)
    assert main(["reference", *REF_ARGS, "--out", str(out)]) == 0
    assert calls == [reference.pass_seed(0, 1)]  # only the pass that was missing
    np.testing.assert_array_equal(read_image(out), full)
    assert not state.exists()


def test_reference_ignores_a_state_of_other_settings(tmp_path, monkeypatch, capsys):
    out = tmp_path / "ref.exr"
    record_passes(monkeypatch, fail_at=2)
    with pytest.raises(SystemExit, match="^130$"):
        main(["reference", *REF_ARGS, "--out", str(out)])
    calls = record_passes(monkeypatch)
    # another seed: the saved pass (of seed 0) is not reused
    assert main(["reference", *REF_ARGS, "--seed", "10", "--out", str(out)]) == 0
    assert calls == [reference.pass_seed(10, 0), reference.pass_seed(10, 1)]
    assert not (tmp_path / "ref.exr.state.npz").exists()


def test_reference_errors(tmp_path, capsys):
    err = run_error(capsys, ["reference", "cornell", "--size", "8", "8", "--spp", "10", "--pass-spp", "4", "-q",
                             "--out", str(tmp_path / "r.exr")])
    assert "--spp (10) must be a multiple of --pass-spp (4)" in err
    err = run_error(capsys, ["reference", "nosuchscene", "--out", str(tmp_path / "r.exr"), "-q"])
    assert "no such scene" in err
    assert listing(tmp_path) == []


def test_the_first_render_says_it_is_compiling_and_its_bar_starts_after(tmp_path):
    """After an install numba compiles the renderer (15-60 s) before the first path: the render says so,
    and its progress bar starts once that is done (it used to sit at its first step with an ETA of
    minutes). Later renders, from numba's cache, say nothing of it."""
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"))  # an empty cache: a fresh install
    cmd = [sys.executable, "-m", "pyoa", "render", "dof7d", "--size", "128", "128", "--spp", "16",
           "--out", str(tmp_path / "a.exr")]  # 4 batches: one compiles, three give the rate
    first = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900)
    assert first.returncode == 0, first.stderr
    said = first.stderr.find("compiling the renderer with numba (once per installed version of pyoa")
    assert said >= 0, first.stderr
    assert "px" not in first.stderr[:said]  # no bar before the message
    assert re.search(r"s of it compiling the renderer \(once\), [0-9.]+ (?:[kMG] )?paths/s after", first.stdout), first.stdout
    second = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900)
    assert second.returncode == 0, second.stderr
    assert "compiling the renderer" not in second.stderr
    assert "px" in second.stderr  # the bar itself is still shown


def test_compare_figure_panels_hold_the_error_map():
    """The figure's error map is the relMSE's own per-pixel terms, averaged over channels; images over
    FIGURE_SIDE are block-averaged for the figure, the crop stays at full resolution."""
    rng = np.random.default_rng(4)
    ref = rng.random((10, 14, 3)).astype(np.float32)
    img = (ref + rng.normal(0, 0.1, ref.shape)).astype(np.float32)
    full, err, crop, k = render_commands.figure_panels(img, ref, (2, 3, 5, 4))
    assert k == 1 and full.shape == img.shape and crop.shape == (4, 5, 3)
    want = ((img.astype(np.float64) - ref) ** 2 / (ref.astype(np.float64) ** 2 + 1e-2)).mean(axis=2)
    np.testing.assert_allclose(err, want, rtol=1e-12)
    assert float(err.mean()) == pytest.approx(rel_mse(img, ref), rel=1e-6)
    big = np.ones((render_commands.FIGURE_SIDE * 2 + 1, 10, 3), np.float32)
    full, err, crop, k = render_commands.figure_panels(big, big, (0, 0, 4, 4))
    assert k == 3 and full.shape == ((2 * render_commands.FIGURE_SIDE + 1) // 3, 10 // 3, 3) and crop.shape == (4, 4, 3)


def test_compare_takes_the_reference_size_and_render_defaults_to_121(tmp_path, capsys, reference16):
    stem = tmp_path / "cmp"
    assert main(["compare", "cornell", "--spp", "4", "--samplers", "bose", "--reference", str(reference16),
                 "--out", str(stem), "-q"]) == 0  # no --size: the 16 x 16 reference's
    capsys.readouterr()
    with open(f"{stem}.csv", newline="") as fh:
        row = next(csv.DictReader(fh))
    img = render(load("cornell"), sampler="bose", spp=4, seed=0, width=16, height=16).image
    assert float(row["relmse"]) == pytest.approx(rel_mse(img, read_image(reference16)), rel=1e-9)
    from pyoa.render.image import read_attributes

    out = tmp_path / "r.exr"
    assert main(["render", "dof7d", "--size", "8", "8", "--out", str(out), "-q"]) == 0
    assert read_attributes(out)["spp"] == 121
    assert main(["render", "dof7d", "--size", "8", "8", "--sampler", "sobol", "--out", str(out)]) == 0
    assert read_attributes(out)["spp"] == 128
    assert "sobol has no 121-sample set; using its nearest valid count, 128" in capsys.readouterr().err
