"""The public API of the samplers ``zsobol`` and ``pmj02`` (pyoa/catalogue/baselines.py).

``resolution=(width, height)``: required by zsobol, refused by every other
sampler, validated, and bounding the pixel indices (``Sampler.n_pixels``);
its round trips (pickle, repr); where it comes from when the caller has no
image (``TRIAL_RESOLUTION``: ``pyoa points``, the qmc engine, the analyses)
and when it has one (the renderer's film); pmj02's largest count; and the
screen-space error spectrum of :func:`pyoa.analysis.error_spectrum`.
"""

from __future__ import annotations

import copy
import pickle
import re

import numpy as np
import pytest

import pyoa
from pyoa.analysis import ErrorSpectrum, convergence, error_spectrum
from pyoa.qmc import OrthogonalArray
from pyoa.render import render as R
from pyoa.render import scene as S
from pyoa.samplers import TRIAL_RESOLUTION, trial_options
from tests.helpers import assert_same_bits, run_cli

RES = (4, 3)  # a tiny non-square, non-power-of-two image: 12 pixels


def zsobol(resolution=RES, *, spp=16, dims=4, seed=0, backend="numpy"):
    return pyoa.sampler("zsobol", spp=spp, dims=dims, seed=seed, resolution=resolution, backend=backend)


# --------------------------------------------------------------------------- resolution: required, refused, checked

@pytest.mark.parametrize("name", [n for n in pyoa.samplers() if n not in ("zsobol", "zfaure")])
def test_every_other_sampler_refuses_a_resolution(name):
    spp = pyoa.valid_spp(name, dims=2)[0].spp
    with pytest.raises(ValueError, match=rf"^{name} takes no resolution \(got resolution=\(4, 3\)\); only zsobol, "
                                         r"zfaure depend on where a pixel lies in the image$"):
        pyoa.sampler(name, spp=spp, dims=2, resolution=(4, 3), backend="numpy")


@pytest.mark.parametrize("name", ["zsobol", "zfaure"])
def test_the_image_samplers_need_a_resolution(name):
    with pytest.raises(ValueError, match=rf"{name} needs the image: resolution=\(width, height\)"):
        pyoa.sampler(name, spp=16, dims=2, backend="numpy")


def test_zsobol_needs_a_resolution():
    with pytest.raises(ValueError, match="resolution"):
        pyoa.sampler("zsobol", spp=16, dims=2, backend="numpy")
    with pytest.raises(ValueError, match="resolution"):
        pyoa.sampler("zsobol", spp=16, dims=2, resolution=None, backend="numpy")


@pytest.mark.parametrize("name", ["bose", "sobol02", "pmj02", "random", "sobol", "halton"])
def test_other_samplers_refuse_a_resolution(name):
    spp = 16 if name != "bose" else 25
    pyoa.sampler(name, spp=spp, dims=2, backend="numpy")  # fine without one
    with pytest.raises(ValueError, match=rf"{name}.*resolution"):
        pyoa.sampler(name, spp=spp, dims=2, resolution=(4, 3), backend="numpy")
    # even the trial resolution: it is only ever added for the samplers that need one
    with pytest.raises(ValueError, match="resolution"):
        pyoa.sampler(name, spp=spp, dims=2, resolution=TRIAL_RESOLUTION, backend="numpy")


@pytest.mark.parametrize("bad", [
    (4.0, 3), (4, 3.0), (4.5, 3), (True, 3), (4, False), ("4", 3), "43", "4x3", b"43",
    (4, 3, 1), (4,), (), 4, 4.0, {4, 3}, object(),
])
def test_bad_resolution_types(bad):
    with pytest.raises(TypeError, match="resolution"):
        zsobol(bad)


@pytest.mark.parametrize("bad", [(0, 3), (4, 0), (65537, 3), (4, 65537), (-1, 3), (4, -3), (2**32, 1)])
def test_bad_resolution_values(bad):
    with pytest.raises(ValueError, match=r"resolution (width|height) must be in \[1, 65536\]"):
        zsobol(bad)


@pytest.mark.parametrize("good", [(1, 1), (65536, 65536), (65536, 1), (1, 65536), [4, 3],
                                  (np.int64(4), np.uint16(3))])
def test_good_resolutions_are_stored_as_a_tuple_of_ints(good):
    smp = zsobol(good)
    assert smp.resolution == (int(good[0]), int(good[1]))
    assert type(smp.resolution) is tuple and all(type(v) is int for v in smp.resolution)
    assert smp.n_pixels == int(good[0]) * int(good[1])


def test_n_pixels():
    assert zsobol().n_pixels == 12
    assert zsobol(TRIAL_RESOLUTION).n_pixels == 2**32
    assert pyoa.sampler("bose", spp=25, dims=2, backend="numpy").n_pixels == 2**32
    assert pyoa.sampler("bose", spp=25, dims=2, backend="numpy").resolution is None
    assert pyoa.sampler("pmj02", spp=16, dims=2, backend="numpy").resolution is None


def test_pixels_past_the_image_are_refused(backend):
    smp = zsobol(backend=backend)
    n = RES[0] * RES[1]
    for pixels in ([n], range(n + 1), np.array([0, n]), [n + 5], range(n, n + 1)):
        with pytest.raises(ValueError, match=rf"pixels must lie in \[0, {n}\)"):
            smp.generate(pixels=pixels)
    with pytest.raises(ValueError, match=rf"pixel must be in \[0, {n - 1}\]"):
        smp.value(n, 0, 0)
    with pytest.raises(ValueError, match="pixel"):
        smp.value(2**32 - 1, 0, 0)
    # the last pixel is accepted, by both, with the same bits
    last = smp.generate(pixels=[n - 1])
    assert last.shape == (1, 16, 4)
    assert np.float32(smp.value(n - 1, 15, 3)) == last[0, 15, 3]
    assert_same_bits(smp.generate(pixels=range(n))[n - 1], last[0], "pixel n-1 alone and in range(n)")


def test_last_trial_pixel_is_accepted(backend):
    smp = zsobol(TRIAL_RESOLUTION, spp=4, dims=2, backend=backend)
    x = smp.generate(pixels=[2**32 - 1])
    assert np.float32(smp.value(2**32 - 1, 3, 1)) == x[0, 3, 1]
    with pytest.raises(ValueError):
        smp.generate(pixels=[2**32])


# --------------------------------------------------------------------------- pmj02's counts

def test_pmj02_counts_end_at_2_to_the_16():
    counts = [c.spp for c in pyoa.valid_spp("pmj02")]
    assert counts == [2**k for k in range(17)]
    assert counts[-1] == 65536
    pyoa.sampler("pmj02", spp=65536, dims=2, backend="numpy")


def test_pmj02_refuses_2_to_the_17_naming_the_nearest():
    with pytest.raises(ValueError) as info:
        pyoa.sampler("pmj02", spp=2**17, dims=2, backend="numpy")
    msg = str(info.value)
    assert msg.startswith("pmj02:")
    m = re.search(r"nearest: ([^;]*)", msg)
    assert m, msg
    assert m.group(1) == "65536 (2^16)", msg  # the largest count: nothing above it
    assert "131072" not in m.group(1), msg


@pytest.mark.parametrize("spp", [3, 48, 65535, 65537])
def test_pmj02_refuses_non_powers_of_two(spp):
    with pytest.raises(ValueError, match="pmj02.*nearest"):
        pyoa.sampler("pmj02", spp=spp, dims=2, backend="numpy")


# --------------------------------------------------------------------------- pickle, copy, repr

def test_pickle_keeps_the_resolution_and_the_bits(backend):
    smp = zsobol((5, 3), spp=32, dims=5, seed=11, backend=backend)
    assert smp._arguments()["resolution"] == (5, 3)
    for other in (pickle.loads(pickle.dumps(smp)), copy.deepcopy(smp), copy.copy(smp)):
        assert other.resolution == (5, 3)
        assert other.n_pixels == 15
        assert other.backend == smp.backend
        assert repr(other) == repr(smp)
        assert_same_bits(other.generate(pixels=range(15)), smp.generate(pixels=range(15)), "copy")
        with pytest.raises(ValueError):
            other.generate(pixels=[15])


def test_pickle_without_resolution():
    smp = pyoa.sampler("pmj02", spp=64, dims=3, seed=2, backend="numpy")
    other = pickle.loads(pickle.dumps(smp))
    assert other.resolution is None
    assert_same_bits(other.generate(pixels=range(4)), smp.generate(pixels=range(4)), "pmj02 pickle")


def test_repr_shows_the_resolution():
    assert "resolution=(4, 3)" in repr(zsobol())
    assert "resolution=(65536, 65536)" in repr(zsobol(TRIAL_RESOLUTION))
    assert "resolution" not in repr(pyoa.sampler("pmj02", spp=16, dims=2, backend="numpy"))
    assert "resolution" not in repr(pyoa.sampler("bose", spp=25, dims=2, backend="numpy"))


# --------------------------------------------------------------------------- values depend on the image, not the backend

def test_values_depend_on_the_resolution():
    a = zsobol((4, 3)).generate(pixels=[5])  # (x, y) = (1, 1) in a 4 x 4 Morton square
    # the same index is another place in another width, or in a larger Morton square
    assert not np.array_equal(a, zsobol((8, 3)).generate(pixels=[5]))  # (5, 0)
    assert not np.array_equal(a, zsobol((4, 5)).generate(pixels=[5]))  # (1, 1) of an 8 x 8 square
    # what counts is (x, y) and the power-of-two square covering the image (as pbrt's log2Resolution)
    assert_same_bits(zsobol((4, 4)).generate(pixels=[5]), a, "(1, 1), 4 x 4 square")
    assert_same_bits(zsobol((3, 4)).generate(pixels=[4]), a, "(1, 1) of a 3-wide image")
    # ... and deterministically on (pixel, resolution)
    assert_same_bits(zsobol((4, 3)).generate(pixels=[5]), a, "same pixel, same image")


@pytest.mark.parametrize("resolution, pixels", [
    ((4, 3), range(12)),
    ((5, 3), range(15)),
    ((1920, 1080), [0, 1, 1919, 1920, 1920 * 1080 - 1]),
    (TRIAL_RESOLUTION, [0, 5, 65535, 65536, 2**31, 2**32 - 1]),
])
def test_same_bits_on_every_backend(backend, resolution, pixels):
    got = zsobol(resolution, spp=32, dims=5, seed=3, backend=backend).generate(pixels=pixels)
    want = zsobol(resolution, spp=32, dims=5, seed=3, backend="numpy").generate(pixels=pixels)
    assert_same_bits(got, want, f"{backend} vs numpy, resolution {resolution}")
    ref = zsobol(resolution, spp=32, dims=5, seed=3, backend="numpy")
    for a, p in enumerate(pixels[:3]):
        for i, j in ((0, 0), (31, 4), (17, 2)):
            assert np.float32(ref.value(p, i, j)) == got[a, i, j], (p, i, j)


def test_opencl_equals_numpy_zsobol_and_pmj02(opencl):
    for make in (lambda b: zsobol((7, 9), spp=64, dims=6, seed=9, backend=b),
                 lambda b: pyoa.sampler("pmj02", spp=64, dims=6, seed=9, backend=b)):
        assert_same_bits(make("opencl").generate(pixels=range(63)), make("numpy").generate(pixels=range(63)),
                         "opencl vs numpy")


# --------------------------------------------------------------------------- trial resolution

def test_trial_options():
    assert TRIAL_RESOLUTION == (65536, 65536)
    opts = {"backend": "numpy"}
    assert trial_options("zsobol", opts) == {"backend": "numpy", "resolution": TRIAL_RESOLUTION}
    assert opts == {"backend": "numpy"}  # not changed in place
    assert trial_options("zsobol", {"resolution": None}) == {"resolution": TRIAL_RESOLUTION}
    assert trial_options("zsobol", {"resolution": (4, 3)}) == {"resolution": (4, 3)}
    for name in ("bose", "pmj02", "sobol02", "random"):
        assert trial_options(name, opts) == opts


def test_convergence_runs_zsobol_on_trial_pixels():
    r = convergence(["zsobol", "pmj02"], "gaussian", 2, [16, 64], trials=8, backend="numpy")
    assert not r.skipped
    assert list(r.spp["zsobol"]) == [16, 64] and list(r.spp["pmj02"]) == [16, 64]
    # trial p is pixel p of the trial image
    smp = pyoa.sampler("zsobol", spp=16, dims=2, seed=0, resolution=TRIAL_RESOLUTION, backend="numpy")
    f = pyoa.analysis.INTEGRANDS["gaussian"](2)
    est = f(smp.generate(pixels=range(8))).mean(axis=-1)
    assert np.isclose(r.mean["zsobol"][0], est.mean(), rtol=0, atol=1e-12)


# --------------------------------------------------------------------------- pyoa points

POINTS = ["points", "zsobol", "--spp", "16", "--dims", "4", "--seed", "5", "--backend", "numpy", "-q"]


def test_cli_points_with_a_resolution(tmp_path, capsys):
    out = tmp_path / "p.npy"
    code, _, err = run_cli([*POINTS, "--resolution", "4", "3", "--pixels", "12", "--out", out], capsys)
    assert code == 0, err
    x = np.load(out)
    assert x.shape == (12, 16, 4)
    want = pyoa.sampler("zsobol", spp=16, dims=4, seed=5, resolution=(4, 3), backend="numpy")
    assert_same_bits(x, want.generate(pixels=range(12)), "pyoa points --resolution 4 3")


def test_cli_points_past_the_image(tmp_path, capsys):
    out = tmp_path / "p.npy"
    code, stdout, err = run_cli([*POINTS, "--resolution", "4", "3", "--pixels", "13", "--out", out], capsys)
    assert code == 2
    assert stdout == ""
    assert err.startswith("pyoa points: error:") and err.endswith("\n") and err.count("\n") == 1, err
    assert "12" in err, err
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []  # no temporary left behind either
    # an image that ends before --pixel0 too
    code, _, err = run_cli([*POINTS, "--resolution", "4", "3", "--pixel0", "12", "--out", out], capsys)
    assert code == 2 and err.count("\n") == 1 and not out.exists(), err


def test_cli_points_resolution_refused_by_other_samplers(tmp_path, capsys):
    out = tmp_path / "p.npy"
    code, _, err = run_cli(["points", "pmj02", "--spp", "16", "--resolution", "4", "3", "-q",
                            "--backend", "numpy", "--out", out], capsys)
    assert code == 2 and "resolution" in err and err.count("\n") == 1, err
    assert not out.exists()


def test_cli_points_without_a_resolution_uses_the_trial_image(tmp_path, capsys):
    out = tmp_path / "p.npy"
    pixel0 = 2**32 - 3
    code, _, err = run_cli([*POINTS, "--pixel0", pixel0, "--pixels", "3", "--out", out], capsys)
    assert code == 0, err
    want = pyoa.sampler("zsobol", spp=16, dims=4, seed=5, resolution=TRIAL_RESOLUTION, backend="numpy")
    assert_same_bits(np.load(out), want.generate(pixels=range(pixel0, 2**32)), "pyoa points, trial image")

    code, _, err = run_cli([*POINTS, "--pixel0", "5", "--pixels", "1", "--out", out], capsys)
    assert code == 0, err
    x = np.load(out)
    assert_same_bits(x, want.generate(pixels=[5]), "pyoa points, pixel 5 of the trial image")
    assert not np.array_equal(x, zsobol((4, 3), seed=5).generate(pixels=[5]))


# --------------------------------------------------------------------------- the renderer

@pytest.fixture(scope="module")
def cornell():
    return S.load("cornell")


@pytest.mark.parametrize("width, height", [(5, 3), (1, 1), (3, 7)])
def test_render_plan_gives_zsobol_the_film(cornell, width, height):
    p = R.plan(cornell, sampler="zsobol", spp=16, width=width, height=height, backend="numpy")
    assert p.sampler.name == "zsobol"
    assert p.sampler.resolution == (width, height)
    assert p.sampler.n_pixels == width * height


def test_render_plan_default_film_and_other_samplers(cornell):
    p = R.plan(cornell, sampler="zsobol", spp=4, backend="numpy")
    assert p.sampler.resolution == (cornell.width, cornell.height)
    for name, spp in (("bose", 16), ("pmj02", 16), ("sobol02", 16)):
        p = R.plan(cornell, sampler=name, spp=spp, width=5, height=3, backend="numpy")
        assert p.sampler.resolution is None


def test_render_plan_refuses_a_film_zsobol_cannot_cover(cornell):
    with pytest.raises(ValueError, match="resolution width"):
        R.plan(cornell, sampler="zsobol", spp=4, width=65537, height=1, backend="numpy")


def test_render_zsobol_tiny(cornell):
    a = R.render(cornell, sampler="zsobol", spp=4, width=5, height=3, backend="numpy", shading="numpy", threads=1)
    b = R.render(cornell, sampler="zsobol", spp=4, width=5, height=3, backend="numpy", shading="numpy",
                 threads=2, batch_paths=8)
    assert a.sampler == "zsobol" and a.image.shape == (3, 5, 3)
    assert np.all(np.isfinite(a.image))
    assert_same_bits(b.image, a.image, "zsobol render, other batches")


# --------------------------------------------------------------------------- the qmc engine

def test_qmc_engine_uses_the_trial_image():
    eng = OrthogonalArray(d=3, sampler="zsobol", rng=1)
    x = eng.random(8)
    assert x.shape == (8, 3) and x.dtype == np.float64
    assert np.all((x >= 0) & (x < 1))
    assert eng.pyoa_sampler.resolution == TRIAL_RESOLUTION
    smp = pyoa.sampler("zsobol", spp=eng.spp, dims=3, seed=eng.pyoa_seed, resolution=TRIAL_RESOLUTION)
    assert_same_bits(x.astype(np.float32), smp.generate(pixels=[0], samples=range(8))[0], "qmc points 0..7")
    assert np.array_equal(x, smp.generate(pixels=[0], samples=range(8))[0].astype(np.float64))
    # the same rng, the same points; the run continues into array 1 = pixel 1
    again = OrthogonalArray(d=3, sampler="zsobol", rng=1)
    assert np.array_equal(again.random(8), x)
    more = again.random(eng.spp)
    assert np.array_equal(more[: eng.spp - 8], smp.generate(pixels=[0], samples=range(8, eng.spp))[0])
    assert np.array_equal(more[eng.spp - 8:], smp.generate(pixels=[1], samples=range(8))[0])


# --------------------------------------------------------------------------- error_spectrum

@pytest.fixture(scope="module")
def spectra():
    return {name: error_spectrum(name, spp=16, size=64, seeds=4, backend="numpy")
            for name in ("zsobol", "sobol02", "random", "pmj02")}


def test_error_spectrum_fields(spectra):
    z = spectra["zsobol"]
    assert isinstance(z, ErrorSpectrum)
    assert (z.sampler, z.integrand, z.spp, z.size, z.seeds) == ("zsobol", "ball", 16, 64, 4)
    assert z.power.shape == (64, 64)
    assert z.power[32, 32] == 0  # DC
    assert len(z.radii) == len(z.radial) and z.radii[0] == 1 and z.radii[-1] == 32
    assert np.all(np.isfinite(z.radial)) and np.all(np.isfinite(z.power))
    assert z.rmse > 0
    assert isinstance(z.low, float)


def test_error_spectrum_zsobol_is_blue_noise(spectra):
    z, w = spectra["zsobol"].low, spectra["sobol02"].low
    assert z < 0.5
    assert z < 0.5 * w


def test_error_spectrum_random_is_white(spectra):
    assert 0.8 <= spectra["random"].low <= 1.2


@pytest.mark.parametrize("name", ["zsobol", "sobol02", "random", "pmj02"])
def test_error_spectrum_is_normalized(spectra, name):
    power = spectra[name].power
    c = power.shape[0] // 2
    nondc = np.ones(power.shape, bool)
    nondc[c, c] = False
    assert np.isclose(power[nondc].mean(), 1.0, rtol=1e-12, atol=0)
    assert np.all(power >= 0)


@pytest.mark.parametrize("kw, what", [
    ({"size": 4}, "size"),
    ({"size": 1025}, "size"),
    ({"seeds": 0}, "seeds"),
    ({"integrand": "nope"}, "integrand"),
    ({"integrand": "gaussian", "spp": 15}, "15"),
])
def test_error_spectrum_argument_errors(kw, what):
    args = {"spp": 16, "size": 8, "seeds": 1, "backend": "numpy"}
    args.update(kw)
    with pytest.raises(ValueError, match=what):
        error_spectrum("zsobol", **args)


def test_error_spectrum_invalid_spp_for_the_sampler():
    with pytest.raises(ValueError, match="pmj02.*nearest"):
        error_spectrum("pmj02", spp=2**17, size=8, seeds=1, backend="numpy")
    with pytest.raises(ValueError, match="bose"):
        error_spectrum("bose", spp=15, size=8, seeds=1, backend="numpy")
    with pytest.raises(ValueError, match="unknown sampler"):
        error_spectrum("nope", spp=16, size=8, seeds=1, backend="numpy")


def test_error_spectrum_is_deterministic():
    a = error_spectrum("zsobol", spp=16, size=16, seeds=2, seed=3, backend="numpy")
    b = error_spectrum("zsobol", spp=16, size=16, seeds=2, seed=3, backend="numpy")
    assert a.low == b.low and a.rmse == b.rmse
    assert np.array_equal(a.power, b.power) and np.array_equal(a.radial, b.radial)
    c = error_spectrum("zsobol", spp=16, size=16, seeds=2, seed=4, backend="numpy")
    assert not np.array_equal(a.power, c.power)


def test_error_spectrum_same_on_every_backend(backend):
    a = error_spectrum("zsobol", spp=16, size=16, seeds=2, backend=backend)
    b = error_spectrum("zsobol", spp=16, size=16, seeds=2, backend="numpy")
    assert np.array_equal(a.power, b.power) and a.low == b.low
