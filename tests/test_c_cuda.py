"""The CUDA device check (benchmarks/cuda_check.py and benchmarks/cuda/values.cu), as far as a machine
without a GPU can take it.

- ``values.cu`` compiles with nvcc, with the command cuda_check.py builds it with (pyoa's flags and
  nothing else) plus ``--Werror all-warnings`` and the host compiler's ``-Wall -Wextra``.
- The program's host path (``--host``: the same rectangle from ``pyoa_sampler_value`` on the CPU, no
  CUDA call) gives NumPy's values, bit for bit, for samplers with and without tables, zsobol and zfaure
  with their image, a sub-rectangle of samples and dimensions and an offset: its arguments, its layout
  (pixels x samples x dims, row-major) and its file are right, so on a GPU a mismatch can only be the
  device's.
  Its errors: a count pyoa refuses (exit 1, the Python API's message), a rectangle outside the
  sampler's ranges (exit 1).
- Without a GPU, the program exits 2 with cudaGetDeviceCount's reason, and cuda_check.py exits 2 with a
  clear message both when nvidia-smi is missing and when it is there but CUDA sees no device
  (``CUDA_VISIBLE_DEVICES=""``, so this holds on a GPU machine too).
- cuda_check.py end to end on the host path (``--host``): every catalogue sampler once plus the rate
  case, all bit for bit, its JSON and Markdown written; and with a stand-in program that writes zeros,
  every case is reported as a mismatch and it exits 1 (the check can fail).

Everything that needs a GPU (the device's values, the rates) runs only in benchmarks/device_check.sh.
Set ``PYOA_REQUIRE_NVCC=1`` to fail instead of skip without nvcc.
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import pyoa
from pyoa import c_headers, catalogue

from .test_c_headers import need

ROOT = Path(__file__).resolve().parents[1]
CHECK = ROOT / "benchmarks" / "cuda_check.py"
SEED = 4000000000  # above 2^31


def _load_check():
    spec = importlib.util.spec_from_file_location("cuda_check", CHECK)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


cuda_check = _load_check()


@pytest.fixture(scope="module")
def values(tmp_path_factory) -> Path:
    """values.cu built as cuda_check.py builds it, with every warning an error."""
    nvcc = need("nvcc", "PYOA_REQUIRE_NVCC")
    binary = tmp_path_factory.mktemp("cuda") / "values"
    cmd = cuda_check.build_command(nvcc, binary, None)
    res = subprocess.run([*cmd, "--Werror", "all-warnings", "-Xcompiler", "-Wall,-Wextra"], capture_output=True,
                         text=True, timeout=300)
    assert res.returncode == 0, f"{' '.join(cmd)}:\n{res.stderr}"
    assert res.stderr.strip() == "", res.stderr
    return binary


def run(*args, env=None, timeout=120) -> subprocess.CompletedProcess:
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=timeout, env=env)


def test_the_build_uses_pyoas_flags_and_nothing_else():
    """No flag that could change the bits: -std, -O2, pyoa's include folder, the GPU's -arch."""
    cmd = cuda_check.build_command("nvcc", Path("values"), "sm_90")
    assert cmd == ["nvcc", "-std=c++14", "-O2", f"-I{c_headers.get_include()}", "-arch=sm_90",
                   str(cuda_check.SOURCE), "-o", "values"]
    assert cuda_check.SOURCE.is_file()


def test_values_cu_compiles_without_a_warning(values):
    assert values.is_file() and os.access(values, os.X_OK)


# (name, sampler options, values.cu arguments beyond the positional ones, generate's samples and dims)
HOST_CASES = [
    ("bose", dict(spp=81, dims=10), [], {}),  # GF(9): the field's tables
    ("bush", dict(spp=64, dims=7, strength=3, offset="mj"), ["--strength", "3", "--offset", "mj"], {}),
    ("sobol", dict(spp=16, dims=5), ["--samples", "3", "9", "--dim-range", "1", "4"],
     dict(samples=range(3, 12), dims=range(1, 5))),
    ("zsobol", dict(spp=32, dims=5, resolution=(5, 3)), ["--resolution", "5", "3"], {}),
    ("faure", dict(spp=49, dims=8, base=7), ["--base", "7"], {}),
    ("zfaure", dict(spp=125, dims=7, resolution=(7, 3), base=5), ["--resolution", "7", "3", "--base", "5"], {}),
    ("addelman-kempthorne", dict(spp=18, dims=9), [], {}),
]


@pytest.mark.parametrize("name, options, extra, rect", HOST_CASES, ids=[c[0] for c in HOST_CASES])
def test_the_host_path_writes_numpys_values(values, tmp_path, name, options, extra, rect):
    """The rectangle in generate's layout, bit for bit; the pixels at the top of the uint32 range
    (zsobol, zfaure: the whole image)."""
    p0, n = (0, options["resolution"][0] * options["resolution"][1]) if "resolution" in options else (2**32 - 3, 3)
    out = tmp_path / "v.bin"
    res = run(values, name, options["spp"], options["dims"], SEED, p0, n, out, "--host", *extra)
    assert res.returncode == 0, res.stderr
    report = json.loads(res.stdout)
    want = pyoa.sampler(name, backend="numpy", seed=SEED, **options).generate(pixels=range(p0, p0 + n), **rect)
    got = np.fromfile(out, "<f4")
    assert report["values"] == want.size == got.size
    assert got.view(np.uint32).tolist() == want.reshape(-1).view(np.uint32).tolist()


def test_the_host_path_differs_for_another_seed(values, tmp_path):
    """The seed reaches the values (a program that ignored an argument would still pass a single case)."""
    got = []
    for seed in (1, 2):
        res = run(values, "bose", 49, 3, seed, 0, 2, tmp_path / f"{seed}.bin", "--host")
        assert res.returncode == 0, res.stderr
        got.append(np.fromfile(tmp_path / f"{seed}.bin", "<f4"))
    assert got[0].size == 2 * 49 * 3 and not np.array_equal(got[0], got[1])


@pytest.mark.parametrize("args, message", [
    (["bose", 50, 3, 0, 0, 1], None),  # the Python API's message
    (["bose", 49, 3, 0, 2**32 - 1, 2], "PIXEL0 + PIXELS exceeds 2^32"),
    (["bose", 49, 3, 0, 0, 1, "--samples", 40, 10], "S0 + NS exceeds the sampler's spp"),
    (["bose", 49, 3, 0, 0, 1, "--dim-range", 2, 2], "D0 + ND exceeds DIMS"),
    (["sobol", 16, 0, 0, 0, 1], "the rectangle is empty"),
    (["bose", 49, 3, -1, 0, 1], "SEED must be an integer in [0, 2^32)"),
    (["bose", 49, 3, 0, 0, 1, "--bogus"], "unknown option or missing argument: --bogus"),
])
def test_the_program_refuses_bad_arguments(values, tmp_path, args, message):
    res = run(values, *args[:6], tmp_path / "v.bin", *args[6:], "--host")
    assert res.returncode == 1 and res.stdout == ""
    if message is None:
        with pytest.raises(ValueError) as exc:
            pyoa.sampler("bose", spp=50, dims=3)
        message = str(exc.value)
    assert message in res.stderr
    assert not (tmp_path / "v.bin").exists()


def _no_device_env() -> dict:
    return dict(os.environ, CUDA_VISIBLE_DEVICES="")  # no device visible, with or without a GPU


def test_the_program_exits_2_without_a_cuda_device(values, tmp_path):
    """cudaGetDeviceCount fails (no driver here) or counts 0 (CUDA_VISIBLE_DEVICES="" on a GPU machine):
    exit 2 with its reason, before any table is built or file written."""
    for args in (["--probe"], ["pmj02", 16, 5, 0, 0, 4, tmp_path / "v.bin"]):
        res = run(values, *args, env=_no_device_env())
        assert res.returncode == 2, res.stderr
        assert res.stderr.startswith("values: no CUDA device: cudaGetDeviceCount "), res.stderr
        assert res.stdout == ""
    assert not (tmp_path / "v.bin").exists()


def _path_without_nvidia_smi(tmp_path: Path) -> str:
    """A PATH with this Python and nothing else."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir(exist_ok=True)
    (bin_dir / "python3").symlink_to(sys.executable)
    return str(bin_dir)


def test_cuda_check_exits_2_without_nvidia_smi(tmp_path):
    env = dict(os.environ, PATH=_path_without_nvidia_smi(tmp_path))
    res = run(sys.executable, CHECK, "--out", tmp_path / "out", env=env, timeout=60)
    assert res.returncode == 2, res.stdout + res.stderr
    assert "cuda_check: no NVIDIA GPU to run on: nvidia-smi not found on PATH" in res.stdout
    assert not (tmp_path / "out").exists()


FAKE_SMI = """#!/bin/sh
echo "NVIDIA Stand-in, 580.00, 9.0, 143771 MiB, 00000000:00:00.0"
"""


def test_cuda_check_exits_2_when_cuda_sees_no_device(values, tmp_path):
    """nvidia-smi lists a GPU but cudaGetDeviceCount finds none: exit 2 with the program's reason."""
    bin_dir = Path(_path_without_nvidia_smi(tmp_path))
    (bin_dir / "nvidia-smi").write_text(FAKE_SMI)
    (bin_dir / "nvidia-smi").chmod(0o755)
    env = dict(_no_device_env(), PATH=str(bin_dir))
    res = run(sys.executable, CHECK, "--binary", values, "--out", tmp_path / "out", env=env, timeout=60)
    assert res.returncode == 2, res.stdout + res.stderr
    assert "GPU: NVIDIA Stand-in (driver 580.00, compute capability 9.0)" in res.stdout
    assert "cuda_check: no NVIDIA GPU to run on: values: no CUDA device: cudaGetDeviceCount" in res.stdout
    assert not (tmp_path / "out").exists()


def test_one_case_per_catalogue_sampler():
    cases = cuda_check.picked_cases(False)
    assert [c["name"] for c in cases] == list(catalogue.SAMPLERS)
    for c in cases:
        case = c["case"]
        assert case in catalogue.get(c["name"]).test_cases() and case["spp"] <= cuda_check.PICK_SPP
        top = case["resolution"][0] * case["resolution"][1] if "resolution" in case else 2**32
        assert c["pixel0"] + c["pixels"] == top and c["pixels"] >= 1
        assert c["pixels"] * case["spp"] * case["dims"] <= cuda_check.CASE_VALUES or c["pixels"] == 1


def test_cuda_check_end_to_end_on_the_host_path(values, tmp_path):
    out = tmp_path / "out"
    res = run(sys.executable, CHECK, "--binary", values, "--host", "--rate-pixels", "64", "--case-values", "50000",
              "--out", out, timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    data = json.loads((out / "cuda-values.json").read_text())
    rows = data["rows"]
    assert [r["sampler"] for r in rows] == [*catalogue.SAMPLERS, "bose"] and rows[-1]["rate"]
    assert all(r["match"] for r in rows) and data["meta"]["mode"] == "host"
    assert rows[-1]["values"] == 64 * 121 * 10
    md = (out / "cuda-values.md").read_text()
    assert md.count("| yes |") == len(rows) and "| NO |" not in md
    assert f"{len(rows)} of {len(rows)} cases bit for bit" in res.stdout


STAND_IN = """#!{python}
# A values program that writes zeros: every case must be reported as a mismatch.
import sys
name, spp, dims, seed, p0, n, out = sys.argv[1:8]
count = int(n) * int(spp) * int(dims)
open(out, "wb").write(bytes(4 * count))
print('{{"values": %d}}' % count)
"""


def test_cuda_check_reports_mismatches(tmp_path):
    """The check can fail: a program whose values are wrong gives NO on every row and exit status 1."""
    fake = tmp_path / "values"
    fake.write_text(STAND_IN.format(python=sys.executable))
    fake.chmod(0o755)
    out = tmp_path / "out"
    res = run(sys.executable, CHECK, "--binary", fake, "--host", "--rate-pixels", "4", "--case-values", "5000",
              "--samplers", "bose,sobol,zsobol", "--out", out, timeout=300)
    assert res.returncode == 1, res.stdout + res.stderr
    rows = json.loads((out / "cuda-values.json").read_text())["rows"]
    assert [r["sampler"] for r in rows] == ["bose", "sobol", "zsobol", "bose"]
    assert not any(r["match"] for r in rows)
    assert all("values differ; first at (pixel 0, sample 0, dim " in r["error"] for r in rows)
    assert "## Failures" in (out / "cuda-values.md").read_text() and "FAILED: bose, " in res.stdout


def test_compare_names_the_first_difference():
    want = np.arange(24, dtype=np.float32).reshape(2, 3, 4) / 32
    got = want.reshape(-1).copy()
    assert cuda_check.compare(got, want) == (True, "")
    got.view(np.uint32)[17] ^= 1  # pixel 1, sample 1, dim 1: one bit
    ok, why = cuda_check.compare(got, want)
    assert not ok and why.startswith("1 of 24 values differ; first at (pixel 1, sample 1, dim 1)")
    assert cuda_check.compare(got[:-1], want) == (False, "23 values written, 24 expected")


def test_the_device_check_runs_cuda_check():
    """The GPU half runs in benchmarks/device_check.sh: cuda_check.py with a timeout, its files in $OUT."""
    script = (ROOT / "benchmarks" / "device_check.sh").read_text()
    assert 'python3 benchmarks/cuda_check.py "${cuda_args[@]}" --out "$OUT"' in script
    assert 'timeout "${CUDA_LIMIT:-120}"' in script
