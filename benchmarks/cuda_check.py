"""pyoa's values on an NVIDIA GPU, from the portable C headers, bit for bit.

    python benchmarks/cuda_check.py [--out DIR]

What a renderer written in CUDA does (docs/renderers.md, "CUDA"), checked on
a real GPU: ``benchmarks/cuda/values.cu``, built from ``pyoa/sampler.h``
alone with pyoa's flags and nothing else (``nvcc -std=c++14 -O2
-I$(python -m pyoa.config --include)``, plus ``-arch`` for the GPU found),
makes each sampler on the host, copies its table to device memory, binds the
copy and writes a rectangle of values (pixels x samples x dims) from a
kernel. This script runs it for every catalogue sampler
(:data:`pyoa.catalogue.SAMPLERS`) at one of its catalogue entry's
``test_cases()`` (the one with the most values per pixel among those of at
most 4096 samples; zsobol's and zfaure's with their resolution), over the top
pixel indices (``2**32 - n`` .. ``2**32 - 1``, where a 32-bit overflow would
show; zsobol, zfaure: the last pixels of the image), and compares every
value, bit for bit, with pyoa's NumPy backend (``pyoa.sampler(name,
backend="numpy", ...).generate(pixels=...)``, equal to the reference by the
conformance suites). ``--all-cases`` runs every test case of at most 65536
samples, the orthogonal arrays at every offset.

The rate: bose at 121 samples x 10 dimensions over pixels 0..65535 (79.3
million values, 317 MB), the generate benchmark's case, timed with cudaEvents
over ``--repeats`` launches, next to the GPU's write bandwidth measured in the
same process over the same bytes (a kernel of the same shape that stores a
constant, and cudaMemset; values.cu's header says how). Every row gives
values/s, GB/s written and that fraction of the bandwidth (1.0: the kernel is
bound by its stores, not by computing values).

Writes ``benchmarks/results/cuda-values.{json,md}`` (or into ``--out``) with
the GPU (nvidia-smi and cudaGetDeviceProperties), the driver, the CUDA
runtime and nvcc versions.

Exit status: 0 every value matches; 1 a mismatch, a failed run or a failed
build; 2 no NVIDIA GPU here (no nvidia-smi, nvidia-smi lists none, or
cudaGetDeviceCount fails or counts 0), with a message saying which; 3 no
nvcc (searched: ``--nvcc``, ``$NVCC``, PATH, ``$CUDA_HOME/bin``,
``/usr/local/cuda/bin``).
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import platform
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))  # run from the tree (benchmarks/device_check.sh sets PYTHONPATH as well)
sys.path.insert(0, str(REPO / "benchmarks"))  # common.py

import pyoa  # noqa: E402
from pyoa import c_headers, catalogue  # noqa: E402
from pyoa.catalogue.entries import OFFSETS  # noqa: E402

SOURCE = REPO / "benchmarks" / "cuda" / "values.cu"
RESULTS = REPO / "benchmarks" / "results"
STEM = "cuda-values"
#: exit statuses (the module docstring).
MISMATCH, NO_GPU, NO_NVCC = 1, 2, 3
#: the user seed of every case: above 2^31, so a signed 32-bit seed anywhere would show.
SEED = 0x9E3779B9
#: values per correctness case (about 4 MB), and the pixels per case at most.
CASE_VALUES = 1 << 20
CASE_PIXELS = 4096
#: the largest spp of the cases picked (--all-cases: of the cases run).
PICK_SPP, ALL_SPP = 4096, 65536
#: the rate case: the generate benchmark's bose-cmj-121x10 (benchmarks/bench_generate.py).
RATE = {"name": "bose", "case": {"spp": 121, "dims": 10}, "pixel0": 0, "pixels": 65536}
RUN_TIMEOUT_S = 120


class NoGPU(Exception):
    """No NVIDIA GPU to run on (exit status 2)."""


def say(msg: str) -> None:
    print(msg, flush=True)


# ----------------------------------------------------------------------------- the machine


def nvidia_smi() -> list[dict]:
    """The GPUs nvidia-smi lists, or NoGPU saying why there are none."""
    smi = shutil.which("nvidia-smi")
    if smi is None:
        raise NoGPU("nvidia-smi not found on PATH: this machine has no NVIDIA GPU driver")
    fields = ["name", "driver_version", "compute_cap", "memory.total", "pci.bus_id"]
    try:
        res = subprocess.run([smi, f"--query-gpu={','.join(fields)}", "--format=csv,noheader"],
                             capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.SubprocessError) as exc:
        raise NoGPU(f"nvidia-smi failed: {exc}") from None
    if res.returncode != 0:
        raise NoGPU(f"nvidia-smi failed (exit {res.returncode}): {(res.stderr or res.stdout).strip()}")
    gpus = []
    for line in res.stdout.splitlines():
        parts = [p.strip() for p in line.split(",")]
        if len(parts) == len(fields) and parts[0]:
            gpus.append(dict(zip(fields, parts)))
    if not gpus:
        raise NoGPU(f"nvidia-smi lists no GPU: {res.stdout.strip() or '(no output)'}")
    return gpus


def find_nvcc(given: str | None) -> str | None:
    candidates = [given, os.environ.get("NVCC"), shutil.which("nvcc")]
    for home in (os.environ.get("CUDA_HOME"), os.environ.get("CUDA_PATH"), "/usr/local/cuda"):
        if home:
            candidates.append(str(Path(home) / "bin" / "nvcc"))
    for c in candidates:
        if c and Path(c).is_file() and os.access(c, os.X_OK):
            return c
    return None


def nvcc_version(nvcc: str) -> str:
    res = subprocess.run([nvcc, "--version"], capture_output=True, text=True, timeout=60)
    lines = [x.strip() for x in res.stdout.splitlines() if x.strip()]
    release = [x for x in lines if "release" in x]
    return (release or lines or ["unknown"])[-1]


def build_command(nvcc: str, binary: Path, arch: str | None) -> list[str]:
    """pyoa's flags (python -m pyoa.config --include) and nothing else, as docs/renderers.md says."""
    cmd = [nvcc, "-std=c++14", "-O2", f"-I{c_headers.get_include()}"]
    if arch:
        cmd.append(f"-arch={arch}")
    return [*cmd, str(SOURCE), "-o", str(binary)]


def build(nvcc: str, binary: Path, compute_cap: str | None) -> dict:
    """Compile values.cu for the GPU's architecture (sm_90 for compute capability 9.0); if nvcc does not
    know it, again for nvcc's default (PTX, compiled by the driver at load)."""
    arch = "sm_" + compute_cap.replace(".", "") if compute_cap and compute_cap.replace(".", "").isdigit() else None
    tries = [arch, None] if arch else [None]
    errors = []
    for a in tries:
        cmd = build_command(nvcc, binary, a)
        t0 = time.perf_counter()
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        seconds = time.perf_counter() - t0
        if res.returncode == 0:
            return {"command": " ".join(cmd), "seconds": round(seconds, 2), "arch": a,
                    "warnings": res.stderr.strip(), "failed_first": errors}
        errors.append(f"{' '.join(cmd)}:\n{res.stderr.strip()}")
    raise RuntimeError("nvcc failed:\n" + "\n\n".join(errors))


def probe(binary: Path) -> dict:
    """values --probe: the device (cudaGetDeviceProperties), or NoGPU with the program's reason."""
    res = subprocess.run([str(binary), "--probe"], capture_output=True, text=True, timeout=RUN_TIMEOUT_S)
    if res.returncode == NO_GPU:
        raise NoGPU(res.stderr.strip())
    if res.returncode != 0:
        raise RuntimeError(f"{binary.name} --probe failed (exit {res.returncode}): {res.stderr.strip()}")
    return json.loads(res.stdout)


def host() -> dict:
    meta = {"date_utc": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "hostname": socket.gethostname(), "platform": platform.platform(), "cpu_count": os.cpu_count(),
            "python": platform.python_version(), "numpy": np.__version__, "pyoa": pyoa.__version__}
    try:
        res = subprocess.run(["git", "-C", str(REPO), "rev-parse", "HEAD"], capture_output=True, text=True,
                             timeout=10)
        meta["git_commit"] = res.stdout.strip() if res.returncode == 0 else None
    except (OSError, subprocess.SubprocessError):
        meta["git_commit"] = None
    return meta


# ----------------------------------------------------------------------------- the cases


def label(case: dict, offset: str | None = None) -> str:
    parts = [f"{case['spp']} spp", f"{case['dims']} dims"]
    parts += [f"{k} {'x'.join(map(str, v)) if isinstance(v, tuple) else v}" for k, v in case.items()
              if k not in ("spp", "dims")]
    return ", ".join(parts + ([f"offset {offset}"] if offset else []))


def place(case: dict, values: int = CASE_VALUES) -> tuple[int, int]:
    """(first pixel, pixel count) of a correctness case: the top of the uint32 pixel range (zsobol,
    zfaure: of the image), about `values` values (one pixel at least, CASE_PIXELS at most)."""
    n = max(1, min(CASE_PIXELS, values // (case["spp"] * case["dims"])))
    top = case["resolution"][0] * case["resolution"][1] if "resolution" in case else 2**32
    n = min(n, top)
    return top - n, n


def picked_cases(all_cases: bool, names: list[str] | None = None, values: int = CASE_VALUES) -> list[dict]:
    """One case per catalogue sampler (the module docstring), or every small case with --all-cases; of
    the samplers `names` only, when given."""
    out = []
    for name, entry in catalogue.SAMPLERS.items():
        if names is not None and name not in names:
            continue
        cases = [c for c in entry.test_cases() if c["spp"] <= (ALL_SPP if all_cases else PICK_SPP)]
        if not cases:
            raise RuntimeError(f"{name}: no test case of at most {PICK_SPP} samples")
        if not all_cases:
            cases = [max(cases, key=lambda c: c["spp"] * c["dims"])]
        for case in cases:
            offsets = OFFSETS if all_cases and entry.family == "oa" else (None,)
            for offset in offsets:
                p0, n = place(case, values)
                out.append({"name": name, "case": dict(case), "offset": offset, "pixel0": p0, "pixels": n})
    return out


def run_args(c: dict, out: Path, repeats: int) -> list[str]:
    case = c["case"]
    args = [c["name"], str(case["spp"]), str(case["dims"]), str(SEED), str(c["pixel0"]), str(c["pixels"]), str(out),
            "--repeats", str(repeats)]
    for key, value in case.items():
        if key in ("spp", "dims"):
            continue
        if key == "resolution":
            args += ["--resolution", str(value[0]), str(value[1])]
        elif key in ("strength", "base"):
            args += [f"--{key}", str(value)]
        else:
            raise RuntimeError(f"{c['name']}: test case option {key!r} has no values.cu flag")
    if c.get("offset"):
        args += ["--offset", c["offset"]]
    return args


def expected(c: dict) -> np.ndarray:
    extra = {"offset": c["offset"]} if c.get("offset") else {}
    smp = pyoa.sampler(c["name"], backend="numpy", seed=SEED, **c["case"], **extra)
    return smp.generate(pixels=range(c["pixel0"], c["pixel0"] + c["pixels"]))


def compare(got: np.ndarray, want: np.ndarray) -> tuple[bool, str]:
    """(bit-for-bit equal, what differs)."""
    if got.size != want.size:
        return False, f"{got.size} values written, {want.size} expected"
    a, b = got.view(np.uint32), want.reshape(-1).view(np.uint32)
    bad = np.flatnonzero(a != b)
    if bad.size == 0:
        return True, ""
    k = int(bad[0])
    p, i, j = np.unravel_index(k, want.shape)
    return False, (f"{bad.size} of {a.size} values differ; first at (pixel {p}, sample {i}, dim {j}) of the "
                   f"rectangle: {got[k]!r} (0x{a[k]:08x}), NumPy {want.reshape(-1)[k]!r} (0x{b[k]:08x})")


def run_case(binary: Path, c: dict, work: Path, repeats: int, on_host: bool = False) -> dict:
    out = work / f"{c['name']}.bin"
    row = {"sampler": c["name"], "case": label(c["case"], c.get("offset")), "options": c["case"],
           "offset": c.get("offset"), "seed": SEED, "pixel0": c["pixel0"], "pixels": c["pixels"],
           "rate": c.get("rate", False)}
    t0 = time.perf_counter()
    try:
        res = subprocess.run([str(binary), *run_args(c, out, repeats), *(["--host"] if on_host else [])],
                             capture_output=True, text=True, timeout=RUN_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return {**row, "match": False, "error": f"timed out after {RUN_TIMEOUT_S} s"}
    row["run_s"] = round(time.perf_counter() - t0, 2)
    if res.returncode != 0:
        return {**row, "match": False, "error": f"exit {res.returncode}: {res.stderr.strip()}"}
    report = json.loads(res.stdout)
    got = np.fromfile(out, dtype="<f4")
    out.unlink()
    match, why = compare(got, expected(c))
    keep = ("values", "bytes", "table_bytes", "repeats", "kernel_ms_median", "kernel_ms_min", "values_per_s",
            "gb_per_s", "write_kernel_gb_per_s", "memset_gb_per_s", "bandwidth_gb_per_s", "fraction_of_bandwidth")
    row.update({k: report[k] for k in keep if k in report}, match=match)
    if why:
        row["error"] = why
    return row


# ----------------------------------------------------------------------------- the report


def fmt(v, spec: str) -> str:
    return format(v, spec) if isinstance(v, (int, float)) else "-"


def markdown(meta: dict, rows: list[dict]) -> str:
    gpu, dev, b = meta["gpu"], meta["device"], meta["build"]
    rate = next((r for r in rows if r["rate"]), None)
    lines = [
        "# pyoa's values in CUDA (benchmarks/cuda_check.py)",
        "",
        "Every catalogue sampler's values from `benchmarks/cuda/values.cu` (the portable headers, the table in "
        "device memory), compared bit for bit with pyoa's NumPy backend; rates timed with cudaEvents and set "
        "against the GPU's write bandwidth measured in the same process over the same bytes.",
        "",
        "## Machine and software",
        "",
        f"- GPU: {gpu.get('name')} (compute capability {dev.get('compute_capability')}, {dev.get('sm_count')} SMs, "
        f"{gpu.get('memory.total')}), driver {gpu.get('driver_version')}",
        f"- CUDA runtime {dev.get('cuda_runtime_version')}, driver API {dev.get('cuda_driver_version')}; "
        f"nvcc: {meta['nvcc_version']}",
        f"- build: `{b['command']}`" + (f" ({b['seconds']} s)" if b.get("seconds") is not None else ""),
        f"- host: {meta['host']['hostname']}, {meta['host']['platform']}, Python {meta['host']['python']}, "
        f"NumPy {meta['host']['numpy']}, pyoa {meta['host']['pyoa']}, commit {meta['host'].get('git_commit')}",
        f"- date (UTC): {meta['host']['date_utc']}; seed {SEED:#x}; {meta['repeats']} timed launches per case",
        "",
    ]
    if rate and "values_per_s" in rate:
        lines += [
            f"**Rate** (bose, 121 spp x 10 dims, {rate['pixels']} pixels, {rate['values'] / 1e6:.1f} M values): "
            f"{rate['values_per_s']:.3g} values/s, {rate['gb_per_s']:.0f} GB/s written, "
            f"{rate['fraction_of_bandwidth']:.2f} of the write bandwidth ({rate['write_kernel_gb_per_s']:.0f} GB/s "
            f"by a store-only kernel, {rate['memset_gb_per_s']:.0f} GB/s by cudaMemset; "
            f"theoretical {dev.get('theoretical_gb_per_s', 0):.0f} GB/s).",
            "",
        ]
    lines += ["| sampler | case | pixels | values | bit for bit | values/s | GB/s | fraction of bandwidth |",
              "|---|---|---|---:|---|---:|---:|---:|"]
    for r in rows:
        pixels = f"{r['pixel0']}..{r['pixel0'] + r['pixels'] - 1}"
        lines.append(f"| {r['sampler']}{' (rate)' if r['rate'] else ''} | {r['case']} | {pixels} | "
                     f"{fmt(r.get('values'), ',')} | {'yes' if r['match'] else 'NO'} | "
                     f"{fmt(r.get('values_per_s'), '.3g')} | {fmt(r.get('gb_per_s'), '.1f')} | "
                     f"{fmt(r.get('fraction_of_bandwidth'), '.2f')} |")
    errors = [r for r in rows if r.get("error")]
    if errors:
        lines += ["", "## Failures", ""] + [f"- {r['sampler']} ({r['case']}): {r['error']}" for r in errors]
    lines += ["", "The small cases are bound by the launch, not the GPU: their rates are not throughput figures; "
              "the rate row is.", ""]
    return "\n".join(lines)


def write(out_dir: Path, meta: dict, rows: list[dict]) -> None:
    from common import write_text  # atomic, world-readable (benchmarks/common.py)

    out_dir.mkdir(parents=True, exist_ok=True)
    write_text(out_dir / f"{STEM}.json", json.dumps({"meta": meta, "rows": rows}, indent=2) + "\n")
    write_text(out_dir / f"{STEM}.md", markdown(meta, rows))
    say(f"wrote {out_dir / (STEM + '.json')} and {out_dir / (STEM + '.md')}")


# ----------------------------------------------------------------------------- main


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=RESULTS, help=f"folder for {STEM}.json and .md (default: {RESULTS})")
    ap.add_argument("--nvcc", help="the nvcc to use (default: $NVCC, PATH, $CUDA_HOME/bin, /usr/local/cuda/bin)")
    ap.add_argument("--binary", type=Path, help="a values.cu binary already built (skips nvcc)")
    ap.add_argument("--repeats", type=int, default=10, help="timed launches per case (default 10)")
    ap.add_argument("--rate-pixels", type=int, default=RATE["pixels"], help="pixels of the rate case (default 65536)")
    ap.add_argument("--all-cases", action="store_true", help="every test case of at most 65536 samples, every offset")
    ap.add_argument("--samplers", help="comma-separated catalogue names (default: every sampler; the rate case "
                                       "runs when bose is among them)")
    ap.add_argument("--case-values", type=int, default=CASE_VALUES,
                    help=f"values per correctness case (default {CASE_VALUES})")
    ap.add_argument("--keep", action="store_true", help="keep the work folder (the binary)")
    ap.add_argument("--host", action="store_true",
                    help="run values.cu's host path (pyoa_sampler_value on the CPU) instead of the GPU: no GPU "
                         "needed and no rates; checks this script and the program's arguments, layout and file "
                         "(tests/test_c_cuda.py)")
    args = ap.parse_args(argv)
    names = None
    if args.samplers:
        names = [catalogue.get(n.strip()).name for n in args.samplers.split(",") if n.strip()]

    work = Path(tempfile.mkdtemp(prefix="pyoa-cuda-"))
    try:
        try:
            gpus = [{"name": "none (--host: values.cu's host path)"}] if args.host else nvidia_smi()
            say("GPU: " + "; ".join(f"{g['name']} (driver {g.get('driver_version')}, compute capability "
                                    f"{g.get('compute_cap')})" for g in gpus))
            if args.binary:
                binary, built = args.binary.resolve(), {"command": f"(given) {args.binary}", "seconds": None}
                nvcc = find_nvcc(args.nvcc)
            else:
                nvcc = find_nvcc(args.nvcc)
                if nvcc is None:
                    say("cuda_check: nvcc not found (--nvcc, $NVCC, PATH, $CUDA_HOME/bin, /usr/local/cuda/bin); "
                        "install the CUDA toolkit to run this check")
                    return NO_NVCC
                binary = work / "values"
                try:
                    built = build(nvcc, binary, None if args.host else gpus[0].get("compute_cap"))
                except RuntimeError as exc:
                    say(f"cuda_check: {exc}")
                    return MISMATCH
                say(f"built in {built['seconds']} s: {built['command']}")
            device = {"device": "host", "compute_capability": None, "sm_count": None,
                      "cuda_runtime_version": None} if args.host else probe(binary)
        except NoGPU as exc:
            say(f"cuda_check: no NVIDIA GPU to run on: {exc}")
            return NO_GPU
        say(f"device: {device['device']} (compute capability {device['compute_capability']}, "
            f"{device['sm_count']} SMs, CUDA runtime {device['cuda_runtime_version']})")

        cases = picked_cases(args.all_cases, names, args.case_values)
        if names is None or RATE["name"] in names:
            cases.append({**RATE, "case": dict(RATE["case"]), "offset": None, "pixels": args.rate_pixels,
                          "rate": True})
        rows = []
        say(f"{'sampler':<22} {'case':<36} {'values':>11} {'match':>5} {'values/s':>10} {'GB/s':>7} {'of bw':>6}")
        for c in cases:
            r = run_case(binary, c, work, args.repeats, args.host)
            rows.append(r)
            say(f"{r['sampler'] + (' (rate)' if r['rate'] else ''):<22} {r['case']:<36} "
                f"{fmt(r.get('values'), ','):>11} {'yes' if r['match'] else 'NO':>5} "
                f"{fmt(r.get('values_per_s'), '.3g'):>10} {fmt(r.get('gb_per_s'), '.1f'):>7} "
                f"{fmt(r.get('fraction_of_bandwidth'), '.2f'):>6}")
            if r.get("error"):
                say(f"    {r['error']}")
        meta = {"gpu": gpus[0], "gpus": gpus, "device": device, "nvcc": nvcc,
                "nvcc_version": nvcc_version(nvcc) if nvcc else None, "build": built, "repeats": args.repeats,
                "seed": SEED, "host": host(), "mode": "host" if args.host else "cuda"}
        write(args.out, meta, rows)
        bad = [r for r in rows if not r["match"]]
        say(f"{len(rows) - len(bad)} of {len(rows)} cases bit for bit" + (
            f"; FAILED: {', '.join(r['sampler'] for r in bad)}" if bad else ""))
        return MISMATCH if bad else 0
    finally:
        if args.keep:
            say(f"kept {work}")
        else:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
