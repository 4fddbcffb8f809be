"""Progress that tells the truth (issue 48, item 14): bars in whole samples with an ETA against
``--time``, plain lines instead of carriage returns when standard error is no terminal, rates without
one-time costs, a line before a long wait, and a refused scheduler port that fails at once."""

from __future__ import annotations

import os
import re
import socket
import subprocess
import sys
import time

import pytest

from pyoa import cluster

ENV = dict(os.environ, PYTHONUNBUFFERED="1")


def pyoa_cmd(*args) -> list[str]:
    return [sys.executable, "-m", "pyoa", *map(str, args)]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_a_scheduler_port_where_nothing_listens_fails_at_once():
    """``--scheduler tcp://127.0.0.1:PORT`` with nothing listening: the refused connection is the
    answer, given at once, not after the whole connection timeout (10 s)."""
    address = f"tcp://127.0.0.1:{_free_port()}"
    t0 = time.perf_counter()
    with pytest.raises(cluster.ClusterUnavailable, match="connection refused: nothing listens on port") as exc:
        with cluster.engine(None, address):
            pass
    took = time.perf_counter() - t0
    assert took < 2, took
    assert address in str(exc.value) and "dask scheduler" in str(exc.value)


# --------------------------------------------------------------------------- bars

def _stderr_of(*args, cwd) -> str:
    proc = subprocess.run(pyoa_cmd(*args), capture_output=True, env=ENV, cwd=cwd, timeout=600)
    assert proc.returncode == 0, proc.stderr.decode()
    return proc.stderr.decode()


def test_progressive_bar_counts_whole_samples_and_its_eta_is_against_time(tmp_path):
    """The progressive bar reads ``8/64 spp [00:01<00:12, --time 100 s]``: whole samples per pixel
    (never ``5.0/4096``), and the time left is an estimate bounded by ``--time``, not the time to
    ``--spp``; on a log (standard error no terminal) in lines, without carriage returns."""
    err = _stderr_of("render", "cornell", "--progressive", "--sampler", "faure", "--spp", 64, "--size", 16, 16,
                     "--time", 100, "--out", tmp_path / "p.exr", cwd=tmp_path)
    assert "\r" not in err, err
    bars = [line for line in err.splitlines() if "spp [" in line]
    assert bars and bars[-1].split("|")[-1].startswith(" 64/64 spp"), err
    for line in bars:
        m = re.search(r"\| (\S+)/64 spp \[(\d\d):(\d\d)<(\d\d):(\d\d), --time 100 s\]$", line)
        assert m and m.group(1).isdigit(), line
        elapsed, left = 60 * int(m.group(2)) + int(m.group(3)), 60 * int(m.group(4)) + int(m.group(5))
        assert elapsed + left <= 101, line  # the render stops within --time


def test_bars_are_lines_when_standard_error_is_not_a_terminal(tmp_path):
    """A render's pixel bar and a reference's pass bar, written to a pipe: whole lines, no carriage
    return (a log used to get one endless line of redrawn bars), the last one complete."""
    err = _stderr_of("reference", "cornell", "--spp", 64, "--pass-spp", 8, "--size", 8, 8, "--out",
                     tmp_path / "r.exr", cwd=tmp_path)
    assert "\r" not in err and [line for line in err.splitlines() if "passes:" in line][-1].count("8/8 ["), err
    err = _stderr_of("render", "cornell", "--spp", 4, "--size", 64, 64, "--out", tmp_path / "i.exr", cwd=tmp_path)
    assert "\r" not in err and [line for line in err.splitlines() if " px" in line or "px/s" in line], err


def test_a_bar_on_a_log_writes_a_line_per_tenth_and_its_last_state():
    """:func:`pyoa.util.progress.bar` on a stream that is no terminal: a line at the start, at each tenth
    it passes, and at the end, each whole; tqdm's ``write`` between lines takes nothing back."""
    import io

    from pyoa.util import progress

    log = io.StringIO()
    bar = progress.bar(total=10, desc="job", unit="step", file=log, mininterval=0)
    for k in range(10):
        bar.update(1)
        if k == 4:
            bar.write("a message", file=log)
    bar.close()
    text = log.getvalue()
    assert "\r" not in text and "\x1b" not in text
    lines = text.splitlines()
    assert lines[0].startswith("job:   0%") and lines[-1].startswith("job: 100%") and "a message" in lines
    assert [int(re.search(r"(\d+)/10", line).group(1)) for line in lines if line != "a message"] == list(range(11))


# --------------------------------------------------------------------------- rates and waits

def test_points_rate_leaves_the_one_time_table_build_out_and_says_the_wait(tmp_path):
    """The first pmj02 run of a machine builds its table (seconds; 9.1 s on the issue's machine): a
    line says so before the wait, and the rate is the generation's alone, the build's time given apart
    (the line used to read "9.1 s (28 values/s)")."""
    env = dict(ENV, PYOA_CACHE_DIR=str(tmp_path / "cache"))
    proc = subprocess.run(pyoa_cmd("points", "pmj02", "--spp", 128, "--dims", 4, "--backend", "numpy", "--out",
                                   tmp_path / "p.npy"), capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.startswith("building the pmj02 table (once: it is kept in"), proc.stderr
    m = re.search(r"512 values \(.*\) in ([\d.]+) (m?s) \(([\d.]+) (k |M |G |)values/s\), after ([\d.]+) (m?s) of "
                  r"one-time setup", proc.stdout)
    assert m, proc.stdout
    scale = {"s": 1, "ms": 1e-3}
    seconds, rate, prefix = float(m.group(1)) * scale[m.group(2)], float(m.group(3)), m.group(4)
    setup = float(m.group(5)) * scale[m.group(6)]
    assert setup > 0.3 and seconds < setup, proc.stdout  # the build is the one-time cost, not the generation
    rate *= {"": 1, "k ": 1e3, "M ": 1e6, "G ": 1e9}[prefix]
    assert rate > 10 * 512 / setup, proc.stdout  # not the rate of the build and the generation together
