"""pyoa.plots and the `pyoa plot` / `pyoa spectrum` commands: valid PNGs of the
stated size, and spectra with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from pyoa import commands
from pyoa.plots import power_spectrum, projections, radial_mean, spectrum

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_shape(path) -> tuple[int, int]:
    import matplotlib.image as mpimg

    with open(path, "rb") as fh:
        assert fh.read(8) == PNG_SIGNATURE, f"{path} is not a PNG"
    return mpimg.imread(path).shape[:2]


def test_projection_matrix_png(tmp_path):
    out = tmp_path / "p.png"
    x = projections("bose", spp=25, dims=4, seed=3, out=str(out), size=160, backend="numpy")
    assert png_shape(out) == (160, 160)
    assert x.shape == (25, 4) and x.dtype == np.float32
    # the plotted points are the sampler's, pixel 0
    import pyoa

    want = pyoa.sampler("bose", spp=25, dims=4, seed=3, backend="numpy").generate(pixels=[0])[0]
    assert np.array_equal(x, want)


@pytest.mark.parametrize("dims", [1, 17])
def test_projection_dims_limits(tmp_path, dims):
    with pytest.raises(ValueError, match="dims"):
        projections("random", spp=8, dims=dims, out=str(tmp_path / "x.png"), size=100)
    assert not (tmp_path / "x.png").exists()


def test_power_spectrum_known_answers():
    # one point: |exp(.)|^2 / 1 = 1 at every frequency
    p = power_spectrum(np.array([[[0.3, 0.7]]]), 4)
    assert p.shape == (9, 9) and np.allclose(p, 1.0)
    # a full k x k grid: zero power at every non-zero frequency below k, N at multiples of k
    k = 8
    g = (np.stack(np.meshgrid(np.arange(k), np.arange(k)), -1).reshape(-1, 2) + 0.5) / k
    p = power_spectrum(g[None], 12)
    c = 12
    assert np.isclose(p[c, c], k * k)
    low = p[c - (k - 1):c + k, c - (k - 1):c + k].copy()
    low[k - 1, k - 1] = 0
    assert np.allclose(low, 0, atol=1e-9)
    assert np.isclose(p[c, c + k], k * k)


def test_radial_mean_of_constant_and_ring():
    r, m = radial_mean(np.ones((21, 21)))
    assert np.allclose(m, 1.0) and r[0] == 1
    p = np.zeros((21, 21))
    p[10, 13] = 4.0  # |k| = 3: one of the ring's cells
    r, m = radial_mean(p)
    assert m[list(r).index(3)] > 0 and np.all(m[r != 3] == 0)


def test_spectrum_random_is_white_and_bose_is_not(tmp_path):
    _, r, white = spectrum("random", spp=64, trials=64, freq=16, out=str(tmp_path / "r.png"), size=200,
                           backend="numpy")
    _, r2, bose = spectrum("bose", spp=64, trials=64, freq=16, out=str(tmp_path / "b.png"), size=200,
                           backend="numpy")
    assert png_shape(tmp_path / "r.png") == (100, 200)
    # white noise: expected power 1 at every frequency (64 trials: mean within ~0.1)
    assert abs(white.mean() - 1.0) < 0.1
    # a stratified set has almost no power at the lowest frequencies
    assert bose[r2 <= 3].mean() < 0.2 and white[r <= 3].mean() > 0.7


@pytest.mark.parametrize("kw, words", [
    (dict(dims=(1, 1)), ["two different"]),
    (dict(trials=0), ["trials"]),
    (dict(freq=2), ["freq"]),
    (dict(size=10), ["size"]),
])
def test_spectrum_bad_arguments(tmp_path, kw, words):
    args = dict(spp=16, out=str(tmp_path / "s.png"), backend="numpy")
    args.update(kw)
    with pytest.raises(ValueError) as err:
        spectrum("random", **args)
    assert all(w in str(err.value) for w in words)


def test_cli_plot_and_spectrum(tmp_path, capsys):
    out = tmp_path / "proj.png"
    assert commands.main(["plot", "cmjnd", "--spp", "27", "--dims", "3", "--figure-width", "120", "--out", str(out),
                     "--backend", "numpy"]) == 0
    assert png_shape(out) == (120, 120)
    out = tmp_path / "spec.png"
    assert commands.main(["spectrum", "jittered2d", "--spp", "49", "--pair", "2,3", "--trials", "8", "--freq", "8",
                     "--figure-width", "160", "--out", str(out), "--backend", "numpy"]) == 0
    assert png_shape(out) == (80, 160)
    assert "low-frequency power" in capsys.readouterr().out


@pytest.mark.parametrize("argv, words", [
    (["spectrum", "bose", "--pair", "0"], ["--pair", "I,J"]),
    (["plot", "bose", "--spp", "120"], ["120", "121"]),
    (["plot", "sobol", "--offset", "mj"], ["offset"]),
])
def test_cli_figure_errors(tmp_path, capsys, argv, words):
    with pytest.raises(SystemExit) as ex:
        commands.main([*argv, "--out", str(tmp_path / "x.png"), "--figure-width", "100"])
    assert ex.value.code == 2
    err = capsys.readouterr().err
    assert all(w in err for w in words), err
    assert not (tmp_path / "x.png").exists()
