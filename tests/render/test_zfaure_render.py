"""``zfaure`` in the renderer: each pixel traces the sampler's own samples of its full-image index.

``zfaure``'s values depend on where a pixel sits in the image (its position on a Morton order of the
film, :mod:`pyoa.reference.zfaure`), so the renderer must hand it the film's resolution and the
row-major index ``y * width + x`` of the whole image, in every batch and every tile. These tests
check that a pixel's value is the mean of its paths traced with the sampler API's samples (and not
with those of another resolution), that tiles and batch sizes do not change a bit, and that the
command line renders it and refuses what it cannot render with the valid counts named.
"""

from __future__ import annotations

import numpy as np
import pytest

import pyoa
from pyoa.commands import main
from pyoa.render.image import read_image
from pyoa.render.integrator import Integrator
from pyoa.render.render import pixel_sums, plan, render
from pyoa.render.scene import load

#: dof7d has 7 dimensions a path (lens and time among them): at 49 = 7^2 samples they are one Faure
#: block of base 7; a 7 x 5 film is not a power of 7 (its Morton grid is padded to 7 x 7).
SCENE, SPP, SEED, WIDTH, HEIGHT = "dof7d", 49, 3, 7, 5


@pytest.fixture(scope="module")
def scene():
    return load(SCENE)


@pytest.fixture(scope="module")
def full(scene):
    return render(scene, sampler="zfaure", spp=SPP, seed=SEED, width=WIDTH, height=HEIGHT, shading="numpy").image


def _traced(scene, pixel: int, resolution: tuple[int, int]) -> np.ndarray:
    """The float32 mean radiance of ``pixel``'s paths traced with the sampler API's values for an
    image of ``resolution``, as :func:`pyoa.render.render.render` forms it."""
    p = plan(scene, sampler="zfaure", spp=SPP, seed=SEED, width=WIDTH, height=HEIGHT, shading="numpy")
    x = pyoa.sampler("zfaure", spp=SPP, dims=p.layout.dims, seed=SEED, resolution=resolution,
                     backend="numpy").generate(pixels=[pixel])[0]
    integ = Integrator(scene, p.layout, WIDTH, HEIGHT)
    rad, _ = integ.radiance(np.full(SPP, pixel), np.arange(SPP), x, seed=SEED)
    return (pixel_sums(rad, SPP) / SPP).astype(np.float32)[0]


def test_the_plan_gives_the_sampler_the_films_resolution(scene):
    p = plan(scene, sampler="zfaure", spp=SPP, seed=SEED, width=WIDTH, height=HEIGHT)
    assert p.sampler.resolution == (WIDTH, HEIGHT) and p.sampler.base == 7 and p.layout.dims >= 7


@pytest.mark.parametrize("pixel", [0, 9, WIDTH * HEIGHT - 1])
def test_a_pixel_is_the_mean_of_the_samplers_samples(scene, full, pixel):
    y, x = divmod(pixel, WIDTH)
    np.testing.assert_array_equal(full[y, x], _traced(scene, pixel, (WIDTH, HEIGHT)))


def test_another_resolution_gives_another_pixel(scene, full):
    """The check above can fail: the same pixel index in a wider film sits elsewhere on the order."""
    assert not np.array_equal(full[1, 2], _traced(scene, WIDTH + 2, (WIDTH + 1, HEIGHT)))


@pytest.mark.parametrize("pixels", [range(9, 23), range(WIDTH * HEIGHT - 1, WIDTH * HEIGHT)])
def test_a_tile_is_the_full_renders_pixels(scene, full, pixels):
    """A tile (a cluster's task) numbers its pixels in the full image: each is bit-identical."""
    tile = render(scene, sampler="zfaure", spp=SPP, seed=SEED, width=WIDTH, height=HEIGHT, shading="numpy",
                  pixels=pixels).image
    np.testing.assert_array_equal(tile, full.reshape(-1, 3)[pixels.start:pixels.stop])


def test_a_tile_is_the_full_renders_pixels_in_the_compiled_shading(scene):
    kw = dict(sampler="zfaure", spp=SPP, seed=SEED, width=WIDTH, height=HEIGHT, shading="numba")
    whole = render(scene, **kw).image.reshape(-1, 3)
    np.testing.assert_array_equal(render(scene, pixels=range(16, 30), **kw).image, whole[16:30])


def test_batches_and_threads_do_not_change_a_bit(scene, full):
    # one pixel a batch (49 paths), on one thread and on two
    for threads in (1, 2):
        img = render(scene, sampler="zfaure", spp=SPP, seed=SEED, width=WIDTH, height=HEIGHT, shading="numpy",
                     batch_paths=SPP, threads=threads).image
        np.testing.assert_array_equal(img, full)


# -- the command line ----------------------------------------------------------------------------


def _refused(capsys, argv) -> str:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    return capsys.readouterr().err


def test_pyoa_render_zfaure_writes_the_render(tmp_path, capsys):
    out = tmp_path / "z.exr"
    assert main(["render", "cornell", "--sampler", "zfaure", "--spp", "16", "--size", "8", "6", "--seed", "2",
                 "--out", str(out), "-q"]) == 0
    want = render(load("cornell"), sampler="zfaure", spp=16, seed=2, width=8, height=6).image
    np.testing.assert_array_equal(read_image(out), want)
    assert capsys.readouterr().out == ""


@pytest.mark.parametrize("argv, words", [
    # not a prime power b^m (m >= 2): the nearest valid counts on both sides
    (["--spp", "100"], ["zfaure: 100 is not a power b^m of a prime b with m >= 2", "nearest: 81 (b=3), 121 (b=11)"]),
    (["--spp", "5"], ["zfaure: 5 is not a power b^m", "nearest: 4 (b=2), 8 (b=2)"]),
    # the count fixes the base: the base's own counts are named
    (["--spp", "25", "--base", "7"], ["25 samples are 5^2, base 5; base 7 takes 49, 343"]),
    # not progressive: the catalogue's reason
    (["--spp", "25", "--progressive"], ["zfaure cannot render progressively: a pixel's samples are indices "
                                        "z * spp + i of one sequence"]),
])
def test_pyoa_render_zfaure_refuses_with_what_is_valid(tmp_path, capsys, argv, words):
    out = tmp_path / "z.exr"
    err = _refused(capsys, ["render", "cornell", "--sampler", "zfaure", "--size", "4", "4", *argv,
                            "--out", str(out)])
    for w in words:
        assert w in err, err
    assert not out.exists()


def test_pyoa_compare_takes_zfaures_nearest_count(tmp_path, capsys):
    ref = tmp_path / "ref.exr"
    from pyoa.render.image import write_exr

    write_exr(ref, render(load("cornell"), sampler="sobol", spp=16, seed=5, width=8, height=8).image)
    assert main(["compare", "cornell", "--samplers", "zfaure", "--spp", "100", "--reference", str(ref),
                 "--out", str(tmp_path / "c"), "-q"]) == 0
    assert "| zfaure | 81 (100 asked: nearest valid) |" in (tmp_path / "c.md").read_text()
