"""What pyoa writes on its standard streams: a closed pipe loses no finished work, ``pyoa info``
prints foreign header strings safely and its ``--json`` is strict JSON, an interrupted cluster run
says one line (issue 48, items 5, 7, 8, 9)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from pyoa import commands

#: The environment of the subprocesses: unbuffered standard output (as PYTHONUNBUFFERED=1 or a
#: terminal makes it), so that a print meets the closed pipe at once, not at the flush at exit.
ENV = dict(os.environ, PYTHONUNBUFFERED="1")


def foreign_exr(path: Path, attributes: dict) -> Path:
    """A 4 x 2 EXR written by OpenImageIO itself, not by pyoa, with ``attributes`` in its header."""
    import OpenImageIO as oiio

    spec = oiio.ImageSpec(4, 2, 3, "float")
    for name, value in attributes.items():
        spec.attribute(name, value)
    out = oiio.ImageOutput.create(str(path))
    assert out is not None and out.open(str(path), spec), oiio.geterror()
    assert out.write_image(np.full((2, 4, 3), 0.5, np.float32))
    out.close()
    return path


# --------------------------------------------------------------------------- pyoa info (items 7, 8)

def test_info_escapes_control_characters_of_header_strings_and_names(tmp_path, capsys):
    """A newline in a header string or a file name cannot forge a line of ``pyoa info``; ESC and CR
    of a foreign ``pyoa:command`` do not reach the terminal: each is printed as its escape."""
    path = foreign_exr(tmp_path / "a\nkind  render.exr", {
        "pyoa:scene": "cornell\nkind  reference", "pyoa:command": "pyoa render\x1b[2J\rforged\u202e",
        "pyoa:kind": "render"})
    assert commands.main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\r" not in out and "\u202e" not in out
    lines = out.splitlines()
    assert sum(line.lstrip().startswith("kind") for line in lines) == 1, out  # the real kind line only
    assert len(lines) == 4, out  # the file's line and its three attributes, one line each
    assert "cornell\\nkind  reference" in out and "pyoa render\\x1b[2J\\rforged\\u202e" in out
    assert lines[0].startswith(str(tmp_path / "a\\nkind  render.exr") + ": 4 x 2")


def test_info_json_is_strict_json_for_non_finite_header_floats(tmp_path, capsys):
    """A foreign EXR's float ``pyoa:spp = NaN`` and ``pyoa:seed = inf`` give JSON that a parser which
    refuses NaN and Infinity reads; the values stay recognisable (as strings)."""
    path = foreign_exr(tmp_path / "nan.exr", {"pyoa:spp": float("nan"), "pyoa:seed": float("inf"),
                                             "pyoa:base": float("-inf"), "pyoa:samples": 2.5})

    def refuse(constant):
        raise ValueError(f"not JSON: {constant}")

    assert commands.main(["info", "--json", str(path)]) == 0
    got = json.loads(capsys.readouterr().out, parse_constant=refuse)[str(path)]
    assert got["spp"] == "nan" and got["seed"] == "inf" and got["base"] == "-inf" and got["samples"] == 2.5
    assert (got["width_px"], got["height_px"], got["channels"]) == (4, 2, 3)


# --------------------------------------------------------------------------- a closed pipe (item 5)

def pyoa_cmd(*args) -> list[str]:
    return [sys.executable, "-m", "pyoa", *map(str, args)]


def closed_stdout(cmd: list[str], cwd: Path, timeout: float = 600) -> tuple[int, bytes]:
    """Run ``cmd`` with its standard output a pipe that the reader closes at once (``| head -c0``):
    its status and standard error."""
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=ENV, cwd=cwd)
    proc.stdout.close()
    _, err = proc.communicate(timeout=timeout)
    return proc.returncode, err


@pytest.fixture(scope="module")
def reference_8x8(tmp_path_factory) -> Path:
    """A tiny Cornell box render to compare against."""
    path = tmp_path_factory.mktemp("ref") / "ref.exr"
    subprocess.run(pyoa_cmd("render", "cornell", "--spp", 4, "--size", 8, 8, "--out", path, "-q"), check=True,
                   env=ENV, capture_output=True)
    return path


def test_compare_with_its_reader_gone_writes_every_output(tmp_path, reference_8x8):
    """``pyoa compare ... | head -1``: the renders are not thrown away; STEM.md, .csv and .png are
    written, and the command ends quietly with SIGPIPE's status."""
    rc, err = closed_stdout(pyoa_cmd("compare", "cornell", "--samplers", "bose,random", "--spp", 4, "--reference",
                                     reference_8x8, "--out", tmp_path / "hq", "-q"), tmp_path)
    assert rc == 141 and b"Traceback" not in err and b"rror" not in err, (rc, err.decode())
    for suffix in (".md", ".png"):
        assert (tmp_path / f"hq{suffix}").stat().st_size > 0
    assert len((tmp_path / "hq.csv").read_text().splitlines()) == 3  # the header and both samplers


def test_study_with_its_reader_gone_writes_its_rows_and_report(tmp_path):
    """``pyoa study ... | head -1``: every render's row reaches study.csv, and the report is written."""
    out = tmp_path / "st"
    rc, err = closed_stdout(pyoa_cmd("study", "cornell", "--samplers", "bose", "--spp", 16, "--seeds", 2,
                                     "--reference-spp", 64, "--size", 8, 8, "--out", out), tmp_path)
    assert rc == 141 and b"Traceback" not in err and b"rror" not in err, (rc, err.decode())
    assert len((out / "study.csv").read_text().splitlines()) == 3  # the header and both seeds
    assert (out / "study.md").stat().st_size > 0 and (out / "study.png").stat().st_size > 0


@pytest.mark.parametrize("closed", ["stdout", "stderr", "both"])
def test_a_stream_closed_from_the_start_loses_no_output(tmp_path, reference_8x8, closed):
    """``pyoa compare ... >&-`` (or ``2>&-``): Python starts with that stream None; the command still
    renders and writes every file, and ends with 0 (the wrapper of the closed-pipe fix met None with an
    AttributeError, status 120 and nothing written)."""
    fds = {"stdout": (1,), "stderr": (2,), "both": (1, 2)}[closed]
    cmd = pyoa_cmd("compare", "cornell", "--samplers", "bose", "--spp", 4, "--reference", reference_8x8,
                   "--out", tmp_path / "hq")
    proc = subprocess.run(cmd, cwd=tmp_path, env=ENV, capture_output=True, timeout=600,
                          preexec_fn=lambda: [os.close(fd) for fd in fds])
    assert proc.returncode == 0, (proc.returncode, proc.stderr.decode())
    for suffix in (".md", ".csv", ".png"):
        assert (tmp_path / f"hq{suffix}").stat().st_size > 0


def test_standard_output_that_cannot_be_written_is_named_once_the_work_is_done(tmp_path, reference_8x8):
    """``pyoa compare ... > /dev/full``: the renders go on to their files, then one line names standard
    output's error, status 2 (it said only ``[Errno 28] No space left on device``, with no file written)."""
    with open("/dev/full", "w") as full:
        proc = subprocess.run(pyoa_cmd("compare", "cornell", "--samplers", "bose", "--spp", 4, "--reference",
                                       reference_8x8, "--out", tmp_path / "hq"),
                              cwd=tmp_path, env=ENV, stdout=full, stderr=subprocess.PIPE, text=True, timeout=600)
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines()[-1] == ("pyoa compare: error: cannot write standard output: No space "
                                                    "left on device (the command ran to its end; only what it "
                                                    "printed is lost)")
    for suffix in (".md", ".csv", ".png"):
        assert (tmp_path / f"hq{suffix}").stat().st_size > 0


# --------------------------------------------------------------------------- Ctrl-C on a local cluster (item 9)

def test_ctrl_c_on_a_local_cluster_prints_pyoa_line_only(tmp_path):
    """Ctrl-C at a terminal signals the whole foreground job (here: SIGINT to the process group of a
    real ``pyoa reference --workers 2``, whose workers run their passes): no traceback of a worker, no
    Dask warning about the tasks it cancels or the workers it stops; pyoa's one line, status 130."""
    import select

    cmd = pyoa_cmd("reference", "cornell", "--spp", 262144, "--pass-spp", 1024, "--size", 16, 16, "--workers", 2,
                   "--out", tmp_path / "w.exr")
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=ENV, cwd=tmp_path,
                            start_new_session=True)
    err = b""
    try:
        deadline = time.monotonic() + 300
        while b"passes" not in err and time.monotonic() < deadline:  # the cluster is up: its bar is shown
            if select.select([proc.stderr], [], [], 1)[0]:
                err += os.read(proc.stderr.fileno(), 1 << 16)
        assert b"passes" in err, err.decode()
        time.sleep(2)  # the workers are rendering passes
        os.killpg(proc.pid, signal.SIGINT)
        _, rest = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    err = (err + rest).decode()
    lines = [line for line in err.replace("\r", "\n").splitlines() if line.strip() and "passes" not in line]
    assert proc.returncode == 130 and len(lines) == 1 and lines[0].startswith("pyoa reference: interrupted; "), err
