"""The command line (pyoa.commands): files equal to the API bit for bit, errors exit 2,
writes are atomic."""

from __future__ import annotations

import csv
import os
import subprocess
import sys

import numpy as np
import pytest

import pyoa
from pyoa import commands
from tests.helpers import assert_same_bits, run_cli


def leftovers(folder, name):
    return [p for p in os.listdir(folder) if p != name and name in p]


POINTS = ["points", "cmjnd", "--spp", "125", "--strength", "3", "--dims", "7", "--pixels", "3",
          "--pixel0", "4294967293", "--seed", "11", "--offset", "mj", "--jitter", "0.75", "-q"]


def api_points(backend):
    s = pyoa.sampler("cmjnd", spp=125, strength=3, dims=7, seed=11, offset="mj", jitter=0.75, backend=backend)
    return s.generate(pixels=range(4294967293, 4294967296))


def test_points_npy(tmp_path, capsys, backend):
    out = tmp_path / "x.npy"
    code, stdout, _ = run_cli(POINTS + ["--backend", backend, "--out", out], capsys)
    assert code == 0 and stdout == ""  # -q prints nothing
    x = np.load(out)
    assert x.dtype == np.float32 and x.shape == (3, 125, 7)
    assert_same_bits(x, api_points(backend))
    assert leftovers(tmp_path, "x.npy") == []


def test_points_csv(tmp_path, capsys):
    out = tmp_path / "x.CSV"  # extension check is case-insensitive
    code, _, _ = run_cli(POINTS + ["--out", out], capsys)
    assert code == 0
    with open(out, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["pixel", "sample"] + [f"x{d}" for d in range(7)]
    body = rows[1:]
    assert len(body) == 3 * 125
    want = api_points("numpy")
    pix = np.array([int(r[0]) for r in body])
    smp = np.array([int(r[1]) for r in body])
    assert np.array_equal(pix, np.repeat([4294967293, 4294967294, 4294967295], 125))
    assert np.array_equal(smp, np.tile(np.arange(125), 3))
    vals = np.array([[float(v) for v in r[2:]] for r in body])
    # decimal text round-trips to the same float32 bits
    assert_same_bits(vals.astype(np.float32).reshape(3, 125, 7), want)


def test_points_default_sampler_and_verbose_output(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, stdout, _ = run_cli(["points", "--backend", "numpy"], capsys)
    assert code == 0
    x = np.load(tmp_path / "points.npy")
    assert_same_bits(x, pyoa.sampler("bose", spp=121, dims=8, backend="numpy").generate())
    assert "Sampler('bose'" in stdout and "points.npy" in stdout and "968 values" in stdout


@pytest.mark.parametrize("name", ["x.txt", "x", "x.npz", "x.npy.bak"])
def test_bad_extension_exits_2(tmp_path, capsys, name):
    code, _, err = run_cli(["points", "--spp", "9", "--dims", "2", "--out", tmp_path / name, "-q"], capsys)
    assert code == 2
    assert "--out must end in .npy or .csv" in err and "error" in err
    assert os.listdir(tmp_path) == []


def test_bad_spp_exits_2(tmp_path, capsys):
    code, _, err = run_cli(["points", "--spp", "128", "--out", tmp_path / "x.npy"], capsys)
    assert code == 2
    assert "121 (s=11)" in err and "169 (s=13)" in err and "Traceback" not in err
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("args, words", [
    (["--seed", "-1"], ["seed"]),
    (["--jitter", "2"], ["jitter"]),
    (["--sampler", "niederreiter"], ["niederreiter"]),
    (["--dims", "0"], ["dims"]),
    (["--pixel0", "4294967295", "--pixels", "2"], ["pixels"]),
])
def test_bad_values_exit_2(tmp_path, capsys, args, words):
    code, _, err = run_cli(["points", "--spp", "9", "--out", tmp_path / "x.npy", "-q"] + args, capsys)
    assert code == 2
    for w in words:
        assert w in err


def test_bad_choice_exits_2(tmp_path, capsys):
    code, _, err = run_cli(["points", "--offset", "diagonal", "--out", tmp_path / "x.npy"], capsys)
    assert code == 2 and "diagonal" in err


def test_missing_directory_exits_2(tmp_path, capsys):
    code, _, err = run_cli(["points", "--spp", "9", "--out", tmp_path / "nope" / "x.npy", "-q"], capsys)
    assert code == 2 and "does not exist" in err


# ----------------------------------------------------------------------------- atomic writes

def _good_file(path):
    path.write_bytes(b"GOOD OLD CONTENT")
    return path.read_bytes()


@pytest.mark.parametrize("exc", [OSError("disk full"), KeyboardInterrupt()])
def test_failed_npy_write_leaves_old_file(tmp_path, capsys, monkeypatch, exc):
    out = tmp_path / "x.npy"
    old = _good_file(out)
    seen = []

    def half_save(file, arr, *a, **k):
        seen.append(str(file))
        with open(file, "wb") as fh:
            fh.write(b"\x93NUMPY half")
        raise exc

    monkeypatch.setattr(np, "save", half_save)
    argv = ["points", "--spp", "9", "--dims", "2", "--backend", "numpy", "--out", str(out), "-q"]
    if isinstance(exc, OSError):  # a write error is a one-line error naming the user's file, exit 2
        code, _, err = run_cli(argv, capsys)
        assert code == 2 and err == f"pyoa points: error: cannot write {str(out)!r}: disk full\n"
    else:  # Ctrl-C: one line and exit status 130
        code, _, err = run_cli(argv, capsys)
        assert code == 130 and err.startswith("pyoa points: interrupted; ") and len(err.splitlines()) == 1, err
    assert seen and seen[0] != str(out)  # it wrote elsewhere first
    assert out.read_bytes() == old
    assert leftovers(tmp_path, "x.npy") == [], os.listdir(tmp_path)


def test_failed_csv_write_leaves_old_file(tmp_path, capsys, monkeypatch):
    out = tmp_path / "x.csv"
    old = _good_file(out)

    def half_savetxt(fh, arr, *a, **k):
        fh.write("0,0,0.5\n")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(np, "savetxt", half_savetxt)
    code, _, err = run_cli(["points", "--spp", "9", "--dims", "2", "--backend", "numpy", "--out", out, "-q"], capsys)
    assert code == 2 and err == f"pyoa points: error: cannot write {str(out)!r}: No space left on device\n"
    assert out.read_bytes() == old
    assert leftovers(tmp_path, "x.csv") == []


def test_successful_write_replaces_old_file(tmp_path, capsys):
    out = tmp_path / "x.npy"
    _good_file(out)
    code, _, _ = run_cli(["points", "--spp", "9", "--dims", "2", "--backend", "numpy", "--out", out, "-q"], capsys)
    assert code == 0
    assert np.load(out).shape == (1, 9, 2)


# ----------------------------------------------------------------------------- other commands

def test_samplers_command(capsys):
    code, out, _ = run_cli(["samplers"], capsys)
    assert code == 0
    assert out.split()[0] == "bose" and "\ncmjnd" in out


def test_spp_command(capsys):
    code, out, _ = run_cli(["spp", "bose", "--near", "128"], capsys)
    assert code == 0
    lines = out.strip().splitlines()
    assert lines[0].split() == ["spp", "s", "t", "dims/block"]
    assert [ln.split() for ln in lines[1:]] == [["121", "11", "2", "12"], ["169", "13", "2", "14"]]
    code, out, _ = run_cli(["spp", "cmjnd", "--strength", "3", "--limit", "3"], capsys)
    assert code == 0 and "8     2   3" in out and "more" in out
    code, _, err = run_cli(["spp", "niederreiter"], capsys)
    assert code == 2 and "niederreiter" in err


def test_backends_command(capsys):
    code, out, _ = run_cli(["backends"], capsys)
    assert code == 0
    assert "numpy" in out and "opencl" in out and "PYOA_BACKEND" in out
    assert sum(line.startswith("*") for line in out.splitlines()) == 1


def test_module_entry_point(tmp_path):
    out = tmp_path / "y.npy"
    env = {k: v for k, v in os.environ.items() if k != "PYOA_BACKEND"}
    res = subprocess.run([sys.executable, "-m", "pyoa", "points", "--spp", "25", "--dims", "3", "--backend", "numpy",
                          "--out", str(out), "-q"], capture_output=True, text=True, env=env, timeout=120)
    assert res.returncode == 0, res.stderr
    assert_same_bits(np.load(out), pyoa.sampler("bose", spp=25, dims=3, backend="numpy").generate())
    res = subprocess.run([sys.executable, "-m", "pyoa", "points", "--spp", "24", "--out", str(out)],
                         capture_output=True, text=True, env=env, timeout=120)
    assert res.returncode == 2 and "25 (s=5)" in res.stderr


def test_unusable_explicit_backend_exits_2(tmp_path, capsys, monkeypatch):
    """`--backend opencl` where OpenCL cannot be used is a user-facing error: exit
    status 2 and a one-line message, like a bad --spp (not a traceback)."""
    import importlib

    import pyoa._opencl.backend as ocl

    B = importlib.import_module("pyoa.backends")

    def broken(*a, **k):
        raise RuntimeError("simulated: no OpenCL platform")

    monkeypatch.setattr(ocl, "OpenCLBackend", broken)
    monkeypatch.setattr(B, "_opencl", {})
    code, _, err = run_cli(["points", "--spp", "9", "--backend", "opencl", "--out", tmp_path / "x.npy", "-q"], capsys)
    assert code == 2
    assert "simulated: no OpenCL platform" in err
    assert os.listdir(tmp_path) == []


# ----------------------------------------------------------------------------- Bush and GF Bose from the CLI

def test_points_bush_equals_api(tmp_path, capsys, backend):
    out = tmp_path / "b.npy"
    code, _, _ = run_cli(["points", "bush", "--spp", "64", "--strength", "3", "--dims", "11",
                          "--pixels", "2", "--seed", "4", "--backend", backend, "--out", out, "-q"], capsys)
    assert code == 0
    want = pyoa.sampler("bush", spp=64, strength=3, dims=11, seed=4, backend=backend).generate(pixels=range(2))
    assert_same_bits(np.load(out), want)


def test_cli_bush_and_gf_bose_listing_and_errors(tmp_path, capsys):
    code, out, _ = run_cli(["samplers"], capsys)
    assert code == 0 and "\nbush" in out
    code, out, _ = run_cli(["spp", "bush", "--strength", "8"], capsys)
    assert code == 0 and [ln.split() for ln in out.strip().splitlines()[1:]] == [["16777216", "8", "8", "9"]]
    code, out, _ = run_cli(["spp", "bose", "--near", "70"], capsys)
    assert code == 0 and [ln.split()[:2] for ln in out.strip().splitlines()[1:]] == [["64", "8"], ["81", "9"]]
    code, _, err = run_cli(["points", "bush", "--spp", "8", "--strength", "3", "--dims", "4",
                            "--out", tmp_path / "x.npy"], capsys)
    assert code == 2 and "nearest: 27 (s=3, t=3)" in err  # none below 8
    assert not (tmp_path / "x.npy").exists()


# ----------------------------------------------------------------------------- index 2 from the CLI

@pytest.mark.parametrize("name, spp, dims, offset", [("bose-bush", 32, 20, "mj"), ("addelman-kempthorne", 50, 13, "cmj")])
def test_points_index2_equals_api(tmp_path, capsys, backend, name, spp, dims, offset):
    """`pyoa points --sampler bose-bush --spp 32 ...` (and Addelman-Kempthorne): the
    .npy is the API's array bit for bit, dimensions past the block included; the
    CSV round-trips to the same bits."""
    out = tmp_path / "x.npy"
    args = ["points", name, "--spp", spp, "--dims", dims, "--pixels", "3", "--pixel0", "4294967293",
            "--seed", "4294967295", "--offset", offset, "--jitter", "0.75", "--backend", backend]
    code, stdout, _ = run_cli(args + ["--out", out, "-q"], capsys)
    assert code == 0 and stdout == ""
    want = pyoa.sampler(name, spp=spp, dims=dims, seed=2**32 - 1, offset=offset, jitter=0.75,
                        backend=backend).generate(pixels=range(4294967293, 4294967296))
    x = np.load(out)
    assert x.shape == (3, spp, dims) and x.dtype == np.float32
    assert_same_bits(x, want)
    code, stdout, _ = run_cli(args + ["--out", tmp_path / "x.csv"], capsys)
    assert code == 0 and f"Sampler('{name}'" in stdout and f"{3 * spp * dims:,} values" in stdout
    with open(tmp_path / "x.csv", newline="") as fh:
        rows = list(csv.reader(fh))[1:]
    vals = np.array([[float(v) for v in r[2:]] for r in rows]).astype(np.float32).reshape(3, spp, dims)
    assert_same_bits(vals, want)


def test_cli_index2_listing_and_errors(tmp_path, capsys):
    code, out, _ = run_cli(["samplers"], capsys)
    assert code == 0 and "\naddelman-kempthorne " in out and "\nbose-bush " in out
    code, out, _ = run_cli(["spp", "bose-bush"], capsys)
    assert code == 0 and [ln.split() for ln in out.strip().splitlines()[1:]] == \
        [[str(2 * s * s), str(s), "2", str(2 * s + 1)] for s in (2, 4, 8, 16, 32, 64, 128)]
    code, out, _ = run_cli(["spp", "addelman-kempthorne", "--near", "100"], capsys)
    assert code == 0 and [ln.split() for ln in out.strip().splitlines()[1:]] == [["98", "7", "2", "15"],
                                                                                   ["162", "9", "2", "19"]]
    code, out, _ = run_cli(["spp", "addelman-kempthorne", "--limit", "3"], capsys)
    assert code == 0 and "18 " in out and "... 423 more" in out
    code, _, err = run_cli(["points", "addelman-kempthorne", "--spp", "32", "--out", tmp_path / "x.npy"],
                           capsys)
    # with the default 8 dims, 32 = 2^5 is a cmjnd count too
    assert code == 2 and "18 (s=3)" in err and "50 (s=5)" in err
    assert "32 is valid for cmjnd (s=2, t=5), bose-bush (s=4)" in err
    assert "Traceback" not in err
    code, _, err = run_cli(["points", "bose-bush", "--spp", "18", "--out", tmp_path / "x.npy"], capsys)
    assert code == 2 and "8 (s=2)" in err and "valid for addelman-kempthorne (s=3)" in err
    code, _, err = run_cli(["points", "bose-bush", "--spp", "32", "--strength", "3",
                            "--out", tmp_path / "x.npy"], capsys)
    assert code == 2 and "strength 2 only" in err
    assert os.listdir(tmp_path) == []


# -- one convention for every command (pyoa --help) ---------------------------------------------------


def test_help_states_the_convention(capsys):
    code, out, _ = run_cli(["--help"], capsys)
    assert code == 0
    assert "conventions, the same in every command:" in out and "--pair I,J" in out


def test_points_names_its_sampler_first_and_keeps_the_old_spelling(tmp_path, capsys):
    new, old = tmp_path / "new.npy", tmp_path / "old.npy"
    code, _, err = run_cli(["points", "halton", "--spp", "10", "--out", new, "-q"], capsys)
    assert code == 0 and err == ""
    code, _, err = run_cli(["points", "--sampler", "halton", "--spp", "10", "--out", old, "-q"], capsys)
    assert code == 0 and "note: --sampler halton is deprecated" in err and "write pyoa points halton" in err
    np.testing.assert_array_equal(np.load(new), np.load(old))
    code, _, err = run_cli(["points", "halton", "--sampler", "sobol", "--out", old, "-q"], capsys)
    assert code == 2 and "two samplers given" in err


def test_without_spp_a_sampler_takes_its_count_nearest_121_and_says_so(tmp_path, capsys):
    out = tmp_path / "p.npy"
    code, _, err = run_cli(["points", "sobol", "--dims", "2", "--out", out], capsys)
    assert code == 0 and np.load(out).shape == (1, 128, 2)
    assert "sobol has no 121-sample set; using its nearest valid count, 128" in err
    code, _, err = run_cli(["points", "bose", "--dims", "2", "--out", out, "-q"], capsys)
    assert code == 0 and np.load(out).shape == (1, 121, 2) and err == ""
    code, _, err = run_cli(["plot", "sobol", "--dims", "3", "--out", tmp_path / "a.png", "-q"], capsys)
    assert code == 0 and (tmp_path / "a.png").is_file()
    # a count given is exact: refused with the nearest valid ones, never replaced
    code, _, err = run_cli(["points", "sobol", "--spp", "121", "--out", out], capsys)
    assert code == 2 and "nearest: 64" in err and "128" in err


def test_spectrum_takes_its_pair_as_pair_and_the_old_dims_with_a_note(tmp_path, capsys):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    code, out_new, err = run_cli(["spectrum", "jittered2d", "--spp", "16", "--pair", "0,2", "--trials", "2",
                                  "--out", a], capsys)
    assert code == 0 and err == "" and "dims 0,2" in out_new
    code, out_old, err = run_cli(["spectrum", "jittered2d", "--spp", "16", "--dims", "0,2", "--trials", "2",
                                  "--out", b], capsys)
    assert code == 0 and "note: --dims 0,2 is deprecated" in err and "write --pair 0,2" in err
    assert out_old.replace(str(b), "") == out_new.replace(str(a), "")
    code, _, err = run_cli(["spectrum", "jittered2d", "--pair", "0,1", "--dims", "0,2", "--out", a], capsys)
    assert code == 2 and "give the pair of dimensions once" in err


def test_render_and_the_points_commands_share_the_default_spp():
    from pyoa import commands
    from pyoa.commands import render as render_commands

    assert commands.options.DEFAULT_SPP == render_commands.DEFAULT_SPP == 121
