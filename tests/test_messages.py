"""Messages that say what is valid (issue 48, items 10 and 16), run as the user runs them.

- ``render(first="light1")``: a str is refused as one (a sequence of names is
  needed), not read letter by letter.
- ``pyoa reference --sampler addelman-kempthorne``: its default --pass-spp
  (256) is taken as the sampler's nearest valid count with a note, as
  ``render`` takes its default --spp; a --pass-spp given is refused naming the
  option and its nearest valid counts.
- ``pyoa spectrum --dims 4`` (the old spelling of --pair): the advice it gives
  is a valid --pair, never one that is then refused.
- ``pyoa spp --near`` and every "nearest:" list: the valid counts on both
  sides of the count.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest

import pyoa


def pyoa_cli(*args, cwd=None) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYOA_BACKEND": "numpy"}
    return subprocess.run([sys.executable, "-m", "pyoa", *map(str, args)], capture_output=True, text=True,
                          env=env, cwd=cwd, timeout=300)


def refused(res: subprocess.CompletedProcess, command: str) -> str:
    """Exit status 2 and one line ``pyoa COMMAND: error: ...``; returns the message."""
    assert res.returncode == 2, (res.returncode, res.stdout, res.stderr)
    lines = res.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"pyoa {command}: error: "), res.stderr
    return lines[0]


# -- render(first=...) ----------------------------------------------------------------------------------

def test_render_first_as_a_str_says_a_sequence_of_names_is_needed():
    from pyoa.render.render import render
    from pyoa.render.scene import load

    scene = load("cornell")
    with pytest.raises(TypeError) as info:
        render(scene, sampler="bose", spp=16, first="light1", width=4, height=4)
    msg = str(info.value)
    assert "sequence of integrand dimension names" in msg and "['light1']" in msg, msg
    assert "'l'" not in msg, msg  # not read letter by letter
    for bad in (5, ["light1", 3]):
        with pytest.raises(TypeError, match="sequence of integrand dimension names"):
            render(scene, sampler="bose", spp=16, first=bad, width=4, height=4)


# -- pyoa reference --pass-spp --------------------------------------------------------------------------

def test_reference_takes_the_nearest_valid_pass_count_by_default(tmp_path):
    """addelman-kempthorne has no 256-sample set: without --pass-spp the passes take its nearest valid
    count (242), said on stderr naming --pass-spp, as render says of its default --spp."""
    res = pyoa_cli("reference", "cornell", "--sampler", "addelman-kempthorne", "--spp", 484, "--size", 2, 2,
                   "--out", tmp_path / "r.exr")
    assert res.returncode == 0, res.stderr
    assert "using its nearest valid count, 242 (give --pass-spp to choose)" in res.stderr, res.stderr
    assert "reference: 2 passes x 242 spp" in res.stdout, res.stdout
    assert (tmp_path / "r.exr").is_file()


def test_reference_without_spp_takes_whole_passes(tmp_path):
    """Neither count given: the whole passes of 242 nearest the default 4096 samples (17 x 242)."""
    res = pyoa_cli("reference", "cornell", "--sampler", "addelman-kempthorne", "--size", 1, 1,
                   "--out", tmp_path / "r.exr")
    assert res.returncode == 0, res.stderr
    assert "using 4114, 17 passes (give --spp to choose)" in res.stderr, res.stderr
    assert "reference: 17 passes x 242 spp" in res.stdout, res.stdout


def test_reference_refuses_a_pass_count_given_naming_the_option(tmp_path):
    res = pyoa_cli("reference", "cornell", "--sampler", "addelman-kempthorne", "--pass-spp", 256, "--spp", 512,
                   "--size", 2, 2, "--out", tmp_path / "r.exr")
    msg = refused(res, "reference")
    assert "--pass-spp 256: addelman-kempthorne: 256 is not" in msg and "nearest: 242 (s=11), 338 (s=13)" in msg, msg
    assert not (tmp_path / "r.exr").exists()
    # a --spp that the resolved default does not divide says where that pass count came from
    res = pyoa_cli("reference", "cornell", "--sampler", "addelman-kempthorne", "--spp", 1000, "--size", 2, 2,
                   "--out", tmp_path / "r.exr", "-q")
    msg = refused(res, "reference")
    assert "--spp (1000) must be a multiple of --pass-spp (242, addelman-kempthorne's valid count nearest the " \
           "default 256; give --pass-spp" in msg, msg


# -- pyoa spectrum --dims (the old --pair) ---------------------------------------------------------------

def test_spectrum_old_dims_advice_is_a_valid_pair(tmp_path):
    res = pyoa_cli("spectrum", "bose", "--dims", 4, "--out", tmp_path / "s.png")
    msg = refused(res, "spectrum")
    assert "--pair 4 " not in res.stderr and "--dims" in msg and "two dimensions I,J" in msg, res.stderr
    res = pyoa_cli("spectrum", "bose", "--dims", "0, 2", "--spp", 16, "--trials", 1, "--out", tmp_path / "s.png")
    assert res.returncode == 0, res.stderr
    advice = re.search(r"write --pair (\S+)", res.stderr)
    assert advice and advice.group(1) == "0,2", res.stderr
    # the advice, followed, is accepted
    res = pyoa_cli("spectrum", "bose", "--pair", advice.group(1), "--spp", 16, "--trials", 1,
                   "--out", tmp_path / "t.png")
    assert res.returncode == 0 and "deprecated" not in res.stderr, res.stderr


# -- the valid counts on both sides ---------------------------------------------------------------------

def _listed(res: subprocess.CompletedProcess) -> list[int]:
    assert res.returncode == 0, res.stderr
    return [int(line.split()[0]) for line in res.stdout.strip().splitlines()[1:]]


@pytest.mark.parametrize("name, near, counts", [
    ("cmjnd", 100, [81, 81, 100, 121]),  # 81 = 9^2 = 3^4
    ("faure", 1000, [999, 1000, 1001]),
    ("bose-bush", 256, [128, 512]),  # the two closest (32, 128) are both below
    ("bose", 120, [81, 121]),
])
def test_spp_near_lists_the_valid_counts_on_both_sides(name, near, counts):
    assert _listed(pyoa_cli("spp", name, "--near", near)) == counts


def test_refusals_name_the_nearest_counts_on_both_sides():
    with pytest.raises(ValueError, match=r"nearest: 128 \(s=8\), 512 \(s=16\)"):
        pyoa.sampler("bose-bush", spp=256, dims=4, backend="numpy")
    with pytest.raises(ValueError, match=r"nearest: 25 \(s=5\), 49 \(s=7\)"):
        pyoa.sampler("bose", spp=32, dims=4, backend="numpy")
    assert [c.spp for c in pyoa.valid_spp("random", near=7)] == [6, 7, 8]
    assert [c.spp for c in pyoa.valid_spp("sobol", near=2**24 + 5)] == [2**24]  # nothing above the largest


# -- found by the review of these fixes -----------------------------------------------------------


@pytest.mark.parametrize("args, option", [(("spp", "bose", "--near", "-5"), "--near"),
                                          (("spp", "bose", "--dims", "0"), "--dims"),
                                          (("plot", "bose", "--figure-width", "0", "-q"), "--figure-width"),
                                          (("spectrum", "bose", "--size", "10", "-q"), "--size")])
def test_a_refused_option_is_named_as_typed(tmp_path, args, option):
    """The command line names its options: ``--near must be >= 0`` (it said ``near must be >= 0``, the
    Python keyword), ``--figure-width must be in [64, 8192]`` (it said ``figure size must be ...``)."""
    message = refused(pyoa_cli(*args, cwd=tmp_path), args[0])
    assert message.split(": error: ", 1)[1].startswith(f"{option} must be"), message


def test_compare_takes_all_as_study_does(tmp_path):
    """``--samplers all`` is every sampler in compare as in study (compare said ``unknown sampler 'all'``):
    here the run goes on to its next check, the missing reference."""
    message = refused(pyoa_cli("compare", "cornell", "--samplers", "all", "--reference", "missing.exr",
                               cwd=tmp_path), "compare")
    assert "all" not in message and "missing.exr" in message, message


def test_points_says_one_pixel(tmp_path):
    res = pyoa_cli("points", "bose", "--spp", "16", "--dims", "2", "--pixels", "1", "--out", "p.npy", cwd=tmp_path)
    assert res.returncode == 0 and "(1 pixel x 16 samples x 2 dims)" in res.stdout, res.stdout + res.stderr


@pytest.mark.parametrize("args, says", [(("render", "cornell", "--bogus"), "unrecognized arguments: --bogus"),
                                        (("spp", "bose", "--near", "1e9"), "argument --near: invalid int value")])
def test_a_usage_error_is_one_line_naming_its_command(tmp_path, args, says):
    """argparse's own refusals are one line led by ``pyoa COMMAND: error:``, as every other (an unknown option
    printed the whole usage block and ``pyoa: error: unrecognized arguments``)."""
    message = refused(pyoa_cli(*args, cwd=tmp_path), args[0])
    assert says in message and message.endswith(f"see pyoa {args[0]} --help"), message
