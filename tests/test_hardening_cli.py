"""Hardening of the non-render commands, run as the user runs them (a
subprocess): every bad count, output path or option value exits 2 with one
line ``pyoa CMD: error: ...`` before any work, and leaves an existing output
file untouched."""

from __future__ import annotations

import os
import resource
import subprocess
import sys

import pytest

GOOD = b"GOOD OLD CONTENT"


#: Address space of each command: a few times what pyoa with matplotlib and
#: NumPy needs (about 0.5 GiB), so a regression that allocates a huge request
#: or lists counts forever fails its test instead of exhausting the machine.
LIMIT = 3 << 30


def _limit_memory():
    resource.setrlimit(resource.RLIMIT_AS, (LIMIT, LIMIT))


def pyoa(*args, cwd=None) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYOA_BACKEND": "numpy"}
    return subprocess.run([sys.executable, "-m", "pyoa", *map(str, args)], capture_output=True, text=True,
                          env=env, cwd=cwd, timeout=120, preexec_fn=_limit_memory)


def assert_refused(res: subprocess.CompletedProcess, command: str, *words: str) -> str:
    """Exit status 2 and exactly one line ``pyoa COMMAND: error: ...`` naming ``words``."""
    assert res.returncode == 2, (res.returncode, res.stdout, res.stderr)
    lines = res.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"pyoa {command}: error: "), res.stderr
    assert "Traceback" not in res.stderr and res.stdout == ""
    for w in words:
        assert w in lines[0], lines[0]
    return lines[0]


@pytest.fixture
def good(tmp_path):
    """An existing output file with good content, per extension."""
    def make(name):
        path = tmp_path / name
        path.write_bytes(GOOD)
        return path
    return make


# ----------------------------------------------------------------------------- counts

POINTS_COUNTS = [
    (["--pixels", "-5"], ["--pixels must be >= 1, got -5"]),
    (["--pixels", "0"], ["--pixels must be >= 1, got 0"]),
    (["--pixel0", "-1"], ["--pixel0 must be in [0, 4294967295], got -1"]),
    (["--pixel0", "4294967296"], ["--pixel0"]),
    (["--pixel0", "4294967295", "--pixels", "2"], ["--pixels 2 from --pixel0 4294967295", "at most 1"]),
    (["--spp", "0"], ["spp must be in [1,"]),
    (["--spp", "-121"], ["spp"]),
    (["--dims", "0"], ["dims must be in [1,"]),
    (["--dims", "-4"], ["dims"]),
    (["--seed", "-1"], ["seed must be in [0, 4294967295]"]),
    (["--seed", "4294967296"], ["seed"]),
    (["bush", "--spp", "64", "--strength", "0"], ["strength must be >= 1"]),
]


@pytest.mark.parametrize("args, words", POINTS_COUNTS, ids=[" ".join(a) for a, _ in POINTS_COUNTS])
def test_points_counts_refused(good, args, words):
    out = good("good.npy")
    res = pyoa("points", "--spp", "9", "--dims", "2", "--out", out, "-q", *args)
    assert_refused(res, "points", *words)
    assert out.read_bytes() == GOOD
    assert os.listdir(out.parent) == ["good.npy"]


SPP_COUNTS = [
    (["bush", "--strength", "99"], ["bush strength must be an integer in [2, 8]", "99"]),
    (["bose", "--strength", "3"], ["bose has strength 2 only (got strength=3)"]),
    (["cmjnd", "--dims", "-4"], ["--dims must be in [1, 1048576], got -4"]),
    (["cmjnd", "--strength", "0"], ["strength must be >= 1"]),  # once listed s**0 = 1 forever
    (["bush", "--strength", "0"], ["strength must be >= 1"]),
    (["bose", "--limit", "-1"], ["--limit must be >= 1, got -1"]),
    (["bose", "--limit", "0"], ["--limit"]),
    (["bose", "--near", "-5"], ["--near must be >= 0, got -5"]),
    (["random", "--strength", "2"], ["random has no strength parameter"]),
]


@pytest.mark.parametrize("args, words", SPP_COUNTS, ids=[" ".join(a) for a, _ in SPP_COUNTS])
def test_spp_refuses_what_the_api_refuses(args, words):
    assert_refused(pyoa("spp", *args), "spp", *words)


FIGURE_COUNTS = [
    ("plot", ["--figure-width", "10"], ["--figure-width must be in [64, 8192] (pixels), got 10"]),
    ("plot", ["--figure-width", "-900"], ["--figure-width"]),
    ("plot", ["--pixel", "-1"], ["pixel must be in [0, 4294967295]"]),
    ("plot", ["--dims", "1"], ["2 <= dims <= 16"]),
    ("plot", ["--spp", "0"], ["spp"]),
    ("plot", ["--seed", "-3"], ["seed"]),
    ("spectrum", ["--trials", "0"], ["trials must be in [1, 100000], got 0"]),
    ("spectrum", ["--trials", "-64"], ["trials"]),
    ("spectrum", ["--freq", "0"], ["freq must be in [4, 512], got 0"]),
    ("spectrum", ["--figure-width", "0"], ["--figure-width"]),
    ("spectrum", ["--pair", "0,-1"], ["dims must be >= 0"]),
    ("spectrum", ["--pair", "1,1"], ["two different dimensions"]),
]


@pytest.mark.parametrize("command, args, words", FIGURE_COUNTS,
                         ids=[f"{c} {' '.join(a)}" for c, a, _ in FIGURE_COUNTS])
def test_figure_counts_refused(good, command, args, words):
    out = good("fig.png")
    assert_refused(pyoa(command, "bose", "--spp", "9", "--out", out, "-q", *args), command, *words)
    assert out.read_bytes() == GOOD


# ----------------------------------------------------------------------------- outputs

@pytest.mark.parametrize("command", ["plot", "spectrum"])
@pytest.mark.parametrize("name", ["p.txt", "p.npy", "p", "p.png.bak", ".png"])
def test_figure_extension_must_be_png(good, command, name):
    out = good(name)
    line = assert_refused(pyoa(command, "bose", "--spp", "9", "--out", out, "-q"), command,
                          "must end in .png", repr(str(out)))
    assert "PNG" in line
    assert out.read_bytes() == GOOD


@pytest.mark.parametrize("command", ["plot", "spectrum"])
def test_figure_png_still_written(tmp_path, command):
    out = tmp_path / "fig.PNG"
    res = pyoa(command, "bose", "--spp", "9", "--size", "64", "--trials", "2", "--out", out, "-q") \
        if command == "spectrum" else pyoa(command, "bose", "--spp", "9", "--size", "64", "--out", out, "-q")
    assert res.returncode == 0, res.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("command, args", [
    ("points", ["--spp", "9", "--dims", "2"]),
    ("plot", ["bose", "--spp", "9"]),
    ("spectrum", ["bose", "--spp", "9"]),
])
def test_output_checked_before_work(tmp_path, command, args):
    """A missing directory, a directory as the output, an unwritable place:
    refused before sampling, naming the user's path (never the hidden
    temporary file)."""
    ext = ".npy" if command == "points" else ".png"
    missing = tmp_path / "nope" / f"x{ext}"
    assert_refused(pyoa(command, *args, "--out", missing, "-q"), command, "does not exist", repr(str(missing)))
    folder = tmp_path / f"folder{ext}"
    folder.mkdir()
    assert_refused(pyoa(command, *args, "--out", folder, "-q"), command,
                   f"cannot write {str(folder)!r}: it is a directory")
    proc = f"/proc/x{ext}"
    line = assert_refused(pyoa(command, *args, "--out", proc, "-q"), command, f"cannot write {proc!r}: ")
    assert f".x{ext}." not in line  # no temporary name
    assert sorted(os.listdir(tmp_path)) == [f"folder{ext}"] and os.listdir(folder) == []


def test_points_output_a_directory_by_name(tmp_path):
    assert_refused(pyoa("points", "--spp", "9", "--out", ".", "-q", cwd=tmp_path), "points",
                   "--out must end in .npy or .csv, got '.'")
    assert os.listdir(tmp_path) == []


def test_good_points_still_replace_the_file(good):
    out = good("good.npy")
    res = pyoa("points", "--spp", "9", "--dims", "2", "--pixels", "2", "--out", out, "-q")
    assert res.returncode == 0, res.stderr
    import numpy as np

    assert np.load(out).shape == (2, 9, 2)



def test_csv_written_in_blocks_equals_one_block(tmp_path, monkeypatch):
    """CSV rows go out a block of pixels at a time (the float64 table of a
    whole large request would not fit where generate's result did); the file
    is the same whatever the block size."""
    from pyoa import commands
    from pyoa.commands import samplers as sampler_commands

    args = ["points", "cmjnd", "--spp", "27", "--dims", "4", "--pixels", "7", "--pixel0", "5",
            "--backend", "numpy", "-q", "--out"]
    assert commands.main(args + [str(tmp_path / "one.csv")]) == 0
    monkeypatch.setattr(sampler_commands, "CSV_BLOCK_VALUES", 2 * 27 * 6)  # two pixels per block
    assert commands.main(args + [str(tmp_path / "blocks.csv")]) == 0
    one = (tmp_path / "one.csv").read_text()
    assert (tmp_path / "blocks.csv").read_text() == one and one.count("\n") == 1 + 7 * 27


@pytest.mark.parametrize("argv", [["spp", "bose"], ["samplers"]])
def test_a_closed_pipe_ends_the_command_quietly(argv):
    """``pyoa spp bose | head``: the reader closes the pipe (here before the
    command writes at all); the command stops quietly with the status of a
    tool that SIGPIPE ends (128 + 13), not with an error about Errno 32."""
    proc = subprocess.Popen([sys.executable, "-m", "pyoa", *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 141 and err == b"", (proc.returncode, err)
