"""``pyoa spectrum`` for samplers that need the image (``zfaure``, ``zsobol``), and ``pyoa spectrum
--error``: the screen-space error spectrum of :func:`pyoa.analysis.error_spectrum` from the command
line, equal to the API's, with every bad option refused before any sampling and named as typed."""

from __future__ import annotations

import numpy as np
import pytest

import pyoa
from pyoa.analysis import error_spectrum
from pyoa.commands import samplers as sampler_commands
from pyoa.plots import spectrum
from tests.helpers import run_cli

ERROR = ["spectrum", "zfaure", "--error", "--backend", "numpy"]


def test_the_projection_spectrum_of_zfaure_reads_the_image_given(tmp_path, capsys):
    """--resolution reaches the sampler: the printed figure is the API's for that image, not the default's."""
    out = tmp_path / "s.png"
    code, printed, err = run_cli(["spectrum", "zfaure", "--spp", "9", "--trials", "4", "--resolution", "8", "2",
                                  "--backend", "numpy", "--out", out], capsys)
    assert code == 0 and err == "" and out.is_file()
    _, radii, mean = spectrum("zfaure", spp=9, trials=4, out=str(tmp_path / "api.png"), resolution=(8, 2),
                              backend="numpy")
    low = mean[radii <= max(2, len(radii) // 8)].mean()
    assert f"zfaure, 9 spp, dims 0,1, 4 trials: mean low-frequency power {low:.3f}" in printed
    # and without --resolution: the default image of every command (65536 x 65536), for zsobol too
    for name, spp in (("zfaure", "9"), ("zsobol", "16")):
        code, printed, err = run_cli(["spectrum", name, "--spp", spp, "--trials", "4", "--backend", "numpy",
                                      "--out", out], capsys)
        assert code == 0 and err == "" and "mean low-frequency power" in printed


def test_the_error_spectrum_is_the_apis(tmp_path, capsys):
    out = tmp_path / "e.png"
    code, printed, err = run_cli([*ERROR, "--spp", "25", "--dims", "4", "--integrand", "gaussian", "--size", "16",
                                  "16", "--seeds", "2", "--seed", "7", "--figure-width", "300", "--out", out], capsys)
    assert code == 0 and err == "", err
    want = error_spectrum("zfaure", spp=25, dims=4, integrand="gaussian", size=16, seeds=2, seed=7, backend="numpy")
    assert str(want.table()) in printed and printed.rstrip().endswith(f"-> {out}")
    assert "| dimensions | 4 |" in printed and f"| RMSE per pixel | {want.rmse:.4g} |" in printed
    with open(out, "rb") as fh:
        head = fh.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and int.from_bytes(head[16:20], "big") == 300


def test_the_error_spectrum_without_a_count_takes_the_nearest_and_quiet_prints_nothing(tmp_path, capsys):
    out = tmp_path / "e.png"
    # zsobol has no 121-sample set: its nearest, said on stderr unless -q
    code, printed, err = run_cli(["spectrum", "zsobol", "--error", "--backend", "numpy", "--size", "8", "8",
                                  "--seeds", "1", "--out", out], capsys)
    assert code == 0 and "using its nearest valid count, 128" in err and "| spp | 128 |" in printed
    code, printed, err = run_cli([*ERROR, "--spp", "4", "--size", "8", "8", "--seeds", "1", "--out", out, "-q"],
                                 capsys)
    assert code == 0 and printed == "" and err == "" and out.is_file()


@pytest.mark.parametrize("argv, message", [
    # the error image: W H, square, in range
    (["--size", "64"], "--size 64: with --error, --size is the error image's W H (square, such as --size 64 64)"),
    (["--size", "64", "32"], "the error image is square"),
    (["--size", "4", "4"], "--size W must be in [8, 1024], got 4"),
    (["--size", "8", "2048"], "--size H must be in [8, 1024], got 2048"),
    # --dims is a count here, named as typed
    (["--dims", "0,1"], "with --error, --dims counts the integrand's dimensions"),
    (["--dims", "0"], "--dims must be in [1, 64], got 0"),
    (["--dims", "65"], "--dims must be in [1, 64], got 65"),
    (["--seeds", "0"], "--seeds must be in [1, 1024], got 0"),
    (["--seed", "4294967295", "--seeds", "2"], "--seed must be in [0, 4294967294] (the first of --seeds"),
    (["--integrand", "bal"], "unknown integrand 'bal'; valid: gaussian"),
    (["--integrand", "halfspace", "--dims", "30"], "supports d <= 18"),
    # the count: zfaure's valid ones named
    (["--spp", "100"], "nearest: 81 (b=3), 121 (b=11)"),
    (["--spp", "25", "--base", "7"], "base 7 takes 49, 343"),
    # options of the projection's spectrum, not of this one
    (["--trials", "3"], "--trials is an option of the projection's spectrum, not of --error"),
    (["--pair", "0,1"], "--pair is an option of the projection's spectrum"),
    (["--resolution", "8", "8"], "(whose image is --size N N)"),
    (["--device", "gpu"], "--device is not taken with --error"),
    (["--out", "e.jpg"], "--out must end in .png"),
])
def test_the_error_spectrum_refuses_bad_options_before_sampling(tmp_path, capsys, monkeypatch, argv, message):
    def no_sampling(*args, **kwargs):
        raise AssertionError("sampled before refusing")

    if "--spp" not in argv and "--integrand" not in argv:  # these two are refused by the API itself, before sampling
        monkeypatch.setattr(sampler_commands, "error_spectrum", no_sampling)
    out = [] if "--out" in argv else ["--out", str(tmp_path / "e.png")]
    code, _, err = run_cli([*ERROR, *argv, *out], capsys)
    assert code == 2 and message in err and err.startswith("pyoa spectrum: error: "), err
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("argv, message", [
    (["--seeds", "3"], "--seeds is an option of --error (the screen-space error spectrum); add --error"),
    (["--integrand", "ball"], "--integrand is an option of --error"),
    (["--size", "64", "64"], "--size 64 64: --size W H is the image of --error"),
    # a count for --dims is --error's; the projection's pair is --pair
    (["--dims", "4"], "--dims 4 counts dimensions (the integrand's, with --error); the projection's pair is --pair"),
    (["--resolution", "4", "1", "--trials", "8"], "--resolution 4 1 has 4 pixels; the spectrum averages --trials 8"),
])
def test_the_projection_spectrum_refuses_the_error_spectrums_options(tmp_path, capsys, argv, message):
    code, _, err = run_cli(["spectrum", "zfaure", "--spp", "9", *argv, "--out", tmp_path / "s.png"], capsys)
    assert code == 2 and message in err, err
    assert not any(tmp_path.iterdir())


def test_the_commands_limits_are_the_apis():
    """The command checks error_spectrum's ranges first (to name its options); they must be the API's."""
    for name, (lo, hi) in sampler_commands.ERROR_LIMITS.items():
        for bad in (lo - 1, hi + 1):
            with pytest.raises(ValueError, match=f"{name} must be in \\[{lo}, {hi}\\]"):
                error_spectrum("random", spp=1, backend="numpy", **{name: bad})
    assert sampler_commands.ERROR_DEFAULTS == {"size": 64, "seeds": 8, "integrand": "ball", "dims": 2}


@pytest.mark.parametrize("command", ["points", "plot", "spectrum"])
def test_a_default_image_the_sampler_refuses_names_resolution(tmp_path, capsys, command):
    """251^3 samples in the default 65536 x 65536 image pass zfaure's 64-bit index: the refusal says
    the image was the default and which option gives a smaller one."""
    out = tmp_path / ("p.npy" if command == "points" else "p.png")
    code, _, err = run_cli([command, "zfaure", "--spp", str(251**3), "--backend", "numpy", "--out", out], capsys)
    assert code == 2 and "pass the 64-bit index" in err, err
    assert "no --resolution W H was given, so the image is the default 65536 x 65536" in err
    # a refusal that is not about the image gets no such note
    code, _, err = run_cli([command, "zfaure", "--spp", "100", "--backend", "numpy", "--out", out], capsys)
    assert code == 2 and "nearest: 81" in err and "--resolution" not in err, err


def test_points_of_zfaure_equal_the_api_for_the_image_given(tmp_path, capsys):
    out = tmp_path / "p.npy"
    code, _, _ = run_cli(["points", "zfaure", "--spp", "25", "--dims", "6", "--resolution", "7", "3", "--pixel0",
                          "5", "--pixels", "9", "--seed", "4", "--backend", "numpy", "--out", out, "-q"], capsys)
    assert code == 0
    want = pyoa.sampler("zfaure", spp=25, dims=6, seed=4, resolution=(7, 3), backend="numpy").generate(
        pixels=range(5, 14))
    np.testing.assert_array_equal(np.load(out), want)
