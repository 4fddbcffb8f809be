#!/usr/bin/env python3
"""Throughput of pyoa's bulk generation, ``Sampler.generate``, per backend.

What is measured
----------------
For each case (a sampler configuration, see ``CASES`` or ``--list``) and each
backend (``opencl``, ``numpy``), one sampler is created with the public API::

    smp = pyoa.sampler(name, spp=..., dims=..., seed=..., offset=..., backend=...)

and ``smp.generate(pixels=range(P))`` is called once as a warm-up (OpenCL
program build and PoCL's kernel cache, first-touch page faults, NumPy's
import-time work). Then ``--repeats`` rounds follow; each round times one
``generate`` call of every (case, backend) pair in turn (interleaved, so a
transient slowdown of the machine hits every row rather than one), each with
``time.perf_counter()`` around the ``generate`` call only (not the sampler's
construction, not the checksum). A run's time therefore includes everything a
user pays for one bulk request: argument validation, allocation of the
float32 ``(P, spp, dims)`` result, every chunk's launch or NumPy evaluation,
and (OpenCL) the device-to-host copy.

Reported per case and backend: the value count ``P * spp * dims``, the median,
minimum and maximum of the timed runs, and the throughput
``values / median seconds`` in millions of float32 values per second. The
warm-up output is hashed (BLAKE2b) so the report also shows whether the
backends produced the same bits.

The required workload is ``bose-cmj-121x10``: Bose, offset ``cmj``,
65,536 pixels x 121 spp x 10 dims (79.3 M values, 317 MB), on both backends.
The NumPy backend needs 15-20 s per run of it, so the default run (one
warm-up plus five timed runs on each backend) takes 2-2.5 minutes on a 2-core
machine. ``--quick`` scales the pixel count down (to 4,096) for a smoke run
of a few seconds; such results are marked ``quick`` and are not comparable
with a full run. ``--cases all`` adds every other case (each OA
construction and offset, and the comparison samplers); that takes about 15
minutes, so they are opt-in. ``--cases baselines`` runs the six comparison
samplers (about 6 minutes with the default case).

Noise
-----
On the 2-core PoCL machines this project is measured on, the same workload
varies by 15-25 % from one process to the next (``/work/shared/POCL-NOTES.md``
item 9). Compare figures taken within one invocation of this script (same
process, interleaved runs); treat a difference between two invocations
smaller than about 25 % as noise. The min/max columns show the spread inside
one process, and the load averages before and after the run (in the
metadata) show whether other work competed for the two cores.

Output
------
``benchmarks/results/generate.json`` (``--out`` to change) with every run's
time and the machine's description, and a Markdown table beside it with the
same stem (``generate.md``); both are written atomically. The table is also
printed at the end.

Usage::

    python benchmarks/bench_generate.py                 # required case, both backends
    python benchmarks/bench_generate.py --quick         # fast smoke run
    python benchmarks/bench_generate.py --cases all     # every case
    python benchmarks/bench_generate.py --cases default,baselines  # Bose and the comparison samplers
    python benchmarks/bench_generate.py --backends opencl --repeats 9
"""

from __future__ import annotations

import argparse
import datetime as _dt
import hashlib
import json
import os
import platform
import socket
import statistics
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

try:
    import pyoa
    from pyoa.atomic import atomic_path
except ImportError as _exc:  # pragma: no cover - environment problem
    sys.exit(f"bench_generate: cannot import pyoa ({_exc}); install it first: pip install -e .")

REPO = Path(__file__).resolve().parent.parent
DEFAULT_OUT = REPO / "benchmarks" / "results" / "generate.json"
FULL_PIXELS = 65536
QUICK_PIXELS = 4096
SCHEMA = 1

#: name -> sampler parameters. ``bose-cmj-121x10`` is the required workload.
CASES: dict[str, dict] = {
    "bose-cmj-121x10": dict(name="bose", spp=121, dims=10, offset="cmj", strength=None,
                            about="Bose s=11, correlated multi-jittered offsets (required workload)"),
    "cmjnd-cmj-125x3": dict(name="cmjnd", spp=125, dims=3, offset="cmj", strength=3,
                            about="CMJND s=5 t=3, correlated multi-jittered offsets"),
    "bose-mj-121x10": dict(name="bose", spp=121, dims=10, offset="mj", strength=None,
                           about="Bose s=11, multi-jittered offsets"),
    "bose-j-121x10": dict(name="bose", spp=121, dims=10, offset="j", strength=None,
                          about="Bose s=11, jittered offsets"),
    "bose-centered-121x10": dict(name="bose", spp=121, dims=10, offset="centered", strength=None,
                                 about="Bose s=11, centred in the coarse strata"),
    "bose-gf-cmj-64x10": dict(name="bose", spp=64, dims=10, offset="cmj", strength=None,
                               about="Bose over GF(8) (s=8, table arithmetic), correlated multi-jittered offsets"),
    "bush-cmj-125x10": dict(name="bush", spp=125, dims=10, offset="cmj", strength=3,
                            about="Bush s=5 t=3, correlated multi-jittered offsets"),
    "bush-gf-cmj-256x10": dict(name="bush", spp=256, dims=10, offset="cmj", strength=4,
                               about="Bush over GF(4) (s=4, t=4), correlated multi-jittered offsets"),
    "ak-cmj-98x10": dict(name="addelman-kempthorne", spp=98, dims=10, offset="cmj", strength=None,
                         about="Addelman-Kempthorne q=7 (index 2), correlated multi-jittered offsets"),
    "bosebush-cmj-128x10": dict(name="bose-bush", spp=128, dims=10, offset="cmj", strength=None,
                                about="Bose-Bush s=8 in GF(16) (index 2), correlated multi-jittered offsets"),
    # The paper's comparison samplers, at the same or the nearest valid count.
    "random-121x10": dict(name="random", spp=121, dims=10, offset=None, strength=None,
                          about="independent uniform random values"),
    "jittered2d-121x10": dict(name="jittered2d", spp=121, dims=10, offset=None, strength=None,
                              about="padded 2D jittered, 11 x 11 per pair"),
    "cmj2d-121x10": dict(name="cmj2d", spp=121, dims=10, offset=None, strength=None,
                         about="padded 2D correlated multi-jittered (Kensler), 11 x 11 per pair"),
    "sobol02-128x10": dict(name="sobol02", spp=128, dims=10, offset=None, strength=None,
                           about="padded (0,2)-sequence, Owen-scrambled, 2^7"),
    "halton-121x10": dict(name="halton", spp=121, dims=10, offset=None, strength=None,
                          about="Owen-scrambled Halton, bases 2..29"),
    "sobol-128x10": dict(name="sobol", spp=128, dims=10, offset=None, strength=None,
                         about="Owen-scrambled Sobol (Joe-Kuo), 2^7"),
}
#: The comparison samplers' cases (``--cases baselines``).
BASELINE_CASES = tuple(c for c, spec in CASES.items() if spec["offset"] is None)
REQUIRED_CASE = "bose-cmj-121x10"
#: The full set of cases takes about 8 minutes on a 2-core machine (NumPy
#: dominates), over the 5-minute budget for a default run, so only the
#: required case runs by default; ``--cases all`` runs every case.
DEFAULT_CASES = (REQUIRED_CASE,)
BACKENDS = ("opencl", "numpy")


# ---------------------------------------------------------------------------
# machine description


def _cpu_model() -> str | None:
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as fh:
            for line in fh:
                key, _, value = line.partition(":")
                if key.strip() in ("model name", "Hardware", "Processor", "cpu model"):
                    return value.strip()
    except OSError:
        pass
    return platform.processor() or None


def _git(*args: str) -> str | None:
    try:
        res = subprocess.run(["git", "-C", str(REPO), *args], capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return res.stdout.strip() if res.returncode == 0 else None


def _version(module: str) -> str | None:
    try:
        from importlib.metadata import version

        return version(module)
    except Exception:  # noqa: BLE001 - not installed, or no metadata
        return None


def machine() -> dict:
    commit = _git("rev-parse", "HEAD")
    status = _git("status", "--porcelain", "--untracked-files=no") if commit else None
    try:
        usable = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        usable = None
    return {
        "date_utc": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "hostname": socket.gethostname(),
        "cpu_model": _cpu_model(),
        "cpu_count": os.cpu_count(),
        "cpu_count_usable": usable,
        "platform": platform.platform(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "pyopencl": _version("pyopencl"),
        "pocl_binary_distribution": _version("pocl-binary-distribution"),
        "pyoa": pyoa.__version__,
        "pyoa_path": str(Path(pyoa.__file__).resolve().parent),
        "git_commit": commit,
        "git_dirty": bool(status) if status is not None else None,
        "environment": {k: v for k, v in sorted(os.environ.items())
                        if k.startswith(("PYOA_", "POCL_", "OMP_", "OPENBLAS_", "MKL_"))},
    }


# ---------------------------------------------------------------------------
# timing


def _loadavg() -> list[float] | None:
    """1, 5 and 15-minute load averages: a load well above 0 before the run means other work competed."""
    try:
        return [round(v, 2) for v in os.getloadavg()]
    except (AttributeError, OSError):
        return None


def _log(msg: str) -> None:
    print(msg, flush=True)


def _digest(x: np.ndarray) -> str:
    return hashlib.blake2b(np.ascontiguousarray(x).view(np.uint8), digest_size=16).hexdigest()


def _opencl_details(smp) -> dict:
    """Full OpenCL platform and driver versions (``Sampler.device`` abbreviates them); {} if not OpenCL."""
    try:
        info = smp._backend.info  # private, read-only use: the LLVM version matters for PoCL
        return {"opencl_platform_version": info.platform.version.strip(),
                "opencl_driver_version": info.device.driver_version.strip()}
    except Exception:  # noqa: BLE001 - NumPy backend, or a changed internal layout
        return {}


def _line(entry: dict, what: str, dt: float) -> None:
    _log(f"  {entry['case']:<22} {entry['backend']:<7} {what:<9} {dt:8.3f} s "
         f"{entry['values'] / dt / 1e6:9.1f} M values/s")


def _fail(entry: dict, status: str, exc: Exception) -> None:
    entry.update(status=status, reason=f"{type(exc).__name__}: {exc}")
    _log(f"  {entry['case']:<22} {entry['backend']:<7} {status.upper()}: {entry['reason']}")


def prepare(case: str, backend: str, pixels: int, seed: int) -> tuple[dict, object]:
    """Create the sampler and run the untimed-for-the-median warm-up; never raises for a backend failure.

    Returns the result entry and the sampler (None when skipped or failed).
    """
    spec = CASES[case]
    values = pixels * spec["spp"] * spec["dims"]
    entry = {"case": case, "backend": backend, "pixels": pixels, "spp": spec["spp"], "dims": spec["dims"],
             "values": values, "status": "ok", "times_s": []}
    try:
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("error", pyoa.PyoaFallbackWarning)  # never a silent fallback
            smp = pyoa.sampler(spec["name"], spp=spec["spp"], dims=spec["dims"], seed=seed,
                               offset=spec["offset"], strength=spec["strength"], backend=backend)
        entry["setup_s"] = time.perf_counter() - t0
    except Exception as exc:  # noqa: BLE001 - an unusable backend is reported, not fatal
        _fail(entry, "skipped", exc)
        return entry, None
    entry.update(device=smp.device, sampler=repr(smp), s=smp.s, strength=smp.strength)
    entry.update(_opencl_details(smp))
    try:
        t0 = time.perf_counter()
        x = smp.generate(pixels=range(pixels))
        entry["warmup_s"] = time.perf_counter() - t0
        entry["digest"] = _digest(x)
        del x
    except Exception as exc:  # noqa: BLE001 - e.g. an OpenCL runtime error
        _fail(entry, "failed", exc)
        return entry, None
    _line(entry, "warm-up", entry["warmup_s"])
    return entry, smp


def timed_run(entry: dict, smp, k: int, repeats: int) -> bool:
    """One timed ``generate``; appends to ``entry['times_s']``. False (and the entry marked failed) on error."""
    try:
        t0 = time.perf_counter()
        x = smp.generate(pixels=range(entry["pixels"]))
        dt = time.perf_counter() - t0
        del x  # one result array alive at a time
    except Exception as exc:  # noqa: BLE001
        _fail(entry, "failed", exc)
        return False
    entry["times_s"].append(dt)
    _line(entry, f"run {k + 1}/{repeats}", dt)
    return True


def summarize(entry: dict) -> dict:
    times = entry["times_s"]
    if times:
        med = statistics.median(times)
        v = entry["values"]
        entry.update(median_s=med, min_s=min(times), max_s=max(times),
                     median_values_per_s=v / med, best_values_per_s=v / min(times),
                     spread=(max(times) - min(times)) / med)
    return entry


def bench(cases: list[str], backends: list[str], pixels: int, repeats: int, seed: int) -> list[dict]:
    """Warm up every (case, backend), then time them round-robin, ``repeats`` rounds.

    Interleaving spreads a transient slowdown of the machine (another process,
    a noisy neighbour) over every row instead of one, so the rows of one run
    stay comparable with each other.
    """
    pairs = [prepare(case, backend, pixels, seed) for case in cases for backend in backends]
    for k in range(repeats):
        for i, (entry, smp) in enumerate(pairs):
            if smp is not None and not timed_run(entry, smp, k, repeats):
                pairs[i] = (entry, None)
    return [summarize(entry) for entry, _ in pairs]


# ---------------------------------------------------------------------------
# report


def _m(v: float) -> str:
    return f"{v / 1e6:,.1f}"


def _load(avg) -> str:
    return " / ".join(f"{v:.2f}" for v in avg) if avg else "unknown"


def markdown(report: dict) -> str:
    meta, cfg = report["machine"], report["config"]
    lines = ["# pyoa generate benchmark", ""]
    if cfg["quick"]:
        lines += [f"**QUICK RUN** ({cfg['pixels']:,} pixels instead of {FULL_PIXELS:,}): a smoke test, "
                  "not comparable with a full run.", ""]
    elif cfg["pixels"] != FULL_PIXELS:
        lines += [f"**Reduced workload**: {cfg['pixels']:,} pixels instead of {FULL_PIXELS:,}.", ""]
    lines += [
        f"Median of {cfg['repeats']} timed `Sampler.generate(pixels=range({cfg['pixels']}))` calls after one "
        f"warm-up, seed {cfg['seed']}; M values/s = values / median seconds. Process-to-process noise "
        "on this machine kind is 15-25 %: compare rows of this table, not separate runs.",
        "",
        "| case | backend | values | median s | M values/s | min s | max s | spread | vs numpy |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    numpy_rate = {r["case"]: r.get("median_values_per_s") for r in report["results"] if r["backend"] == "numpy"}
    for r in report["results"]:
        if "median_s" not in r:
            lines.append(f"| {r['case']} | {r['backend']} | {r['values']:,} | {r['status']} | | | | | |")
            continue
        base = numpy_rate.get(r["case"])
        ratio = f"{r['median_values_per_s'] / base:.1f}x" if base and r["backend"] != "numpy" else ""
        lines.append(
            f"| {r['case']} | {r['backend']} | {r['values']:,} | {r['median_s']:.3f} | "
            f"{_m(r['median_values_per_s'])} | {r['min_s']:.3f} | {r['max_s']:.3f} | "
            f"{100 * r['spread']:.0f} % | {ratio} |"
        )
    notes = [f"- {r['case']} / {r['backend']}: {r['status']}: {r['reason']}"
             for r in report["results"] if r["status"] != "ok"]
    for case, same in report["bits_match"].items():
        notes.append(f"- {case}: backends gave {'identical' if same else 'DIFFERENT'} bits (BLAKE2b of the output)")
    if notes:
        lines += ["", *notes]
    lines += ["", "Cases:", ""]
    for case in cfg["cases"]:
        spec = CASES[case]
        st = f", strength={spec['strength']}" if spec["strength"] else ""
        st += f", offset={spec['offset']!r}" if spec["offset"] else ""
        lines.append(f"- `{case}`: `pyoa.sampler({spec['name']!r}, spp={spec['spp']}, dims={spec['dims']}"
                     f"{st})`; {spec['about']}")
    devices = {r["backend"]: r["device"] for r in report["results"] if r.get("device")}
    commit = meta["git_commit"] or "unknown"
    if meta["git_dirty"]:
        commit += " (with uncommitted changes)"
    lines += [
        "",
        "Machine and software:",
        "",
        f"- date (UTC): {meta['date_utc']}; total wall time {report['total_s']:.0f} s",
        f"- host: {meta['hostname']}; CPU: {meta['cpu_model']}; cores: {meta['cpu_count']} "
        f"({meta['cpu_count_usable']} usable); load average (1/5/15 min) {_load(meta['loadavg_start'])} "
        f"before, {_load(meta['loadavg_end'])} after",
        f"- Python {meta['python']}, NumPy {meta['numpy']}, pyopencl {meta['pyopencl']}, "
        f"pyoa {meta['pyoa']} (git {commit})",
    ]
    for name, dev in devices.items():
        lines.append(f"- {name} device: {dev}")
    ocl = next((r for r in report["results"] if r.get("opencl_platform_version")), None)
    if ocl:
        lines.append(f"- OpenCL platform version: {ocl['opencl_platform_version']}; "
                     f"driver {ocl['opencl_driver_version']}")
    if meta["environment"]:
        lines.append("- environment: " + ", ".join(f"`{k}={v}`" for k, v in meta["environment"].items()))
    return "\n".join(lines) + "\n"


def _write(path: Path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
        umask = os.umask(0)
        os.umask(umask)
        tmp.chmod(0o666 & ~umask)  # mkstemp creates 0600; results are meant to be shared


# ---------------------------------------------------------------------------
# command line


def _csv(choices, what: str, *, extra: dict | None = None):
    def parse(text: str) -> list[str]:
        items = [t.strip().lower() for t in text.split(",") if t.strip()]
        out: list[str] = []
        for t in items:
            if extra and t in extra:
                out += [c for c in extra[t] if c not in out]
            elif t in choices:
                if t not in out:
                    out.append(t)
            else:
                valid = ", ".join([*choices, *(extra or {})])
                raise argparse.ArgumentTypeError(f"unknown {what} {t!r}; valid: {valid}")
        if not out:
            raise argparse.ArgumentTypeError(f"no {what} given")
        return out

    return parse


def parse_args(argv=None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(
        description="Time pyoa Sampler.generate per backend (median of N runs after one warm-up).",
    )
    ap.add_argument("--backends", type=_csv(BACKENDS, "backend"), default=",".join(BACKENDS),
                    help="comma-separated backends (default: opencl,numpy)")
    ap.add_argument("--cases", type=_csv(tuple(CASES), "case", extra={"all": tuple(CASES),
                                                                       "default": DEFAULT_CASES,
                                                                       "baselines": BASELINE_CASES}),
                    default="default",
                    help=f"comma-separated case names, 'default' ({', '.join(DEFAULT_CASES)}), "
                         "'baselines' (the comparison samplers) or 'all' (see --list; default: default)")
    ap.add_argument("--repeats", type=int, default=5, help="timed runs after the warm-up (default: 5)")
    ap.add_argument("--pixels", type=int, default=None,
                    help=f"pixels per generate call (default: {FULL_PIXELS}; {QUICK_PIXELS} with --quick)")
    ap.add_argument("--quick", action="store_true",
                    help=f"smoke run: {QUICK_PIXELS} pixels unless --pixels; results are marked quick")
    ap.add_argument("--seed", type=int, default=0, help="sampler seed (default: 0)")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT,
                    help="JSON result path; the Markdown table goes beside it with suffix .md "
                         "(default: benchmarks/results/generate.json)")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error("--repeats must be at least 1")
    if args.pixels is None:
        args.pixels = QUICK_PIXELS if args.quick else FULL_PIXELS
    if args.pixels < 1:
        ap.error("--pixels must be at least 1")
    return args


def main(argv=None) -> int:
    args = parse_args(argv)
    if args.list:
        for case, spec in CASES.items():
            mark = " (default)" if case in DEFAULT_CASES else ""
            print(f"{case:<22} {spec['about']}{mark}")
        return 0
    out_json = args.out
    out_md = out_json.with_suffix(".md")
    out_json.parent.mkdir(parents=True, exist_ok=True)

    t_start = time.perf_counter()
    meta = machine()
    _log(f"pyoa {meta['pyoa']} (git {meta['git_commit'] or 'unknown'}) on {meta['cpu_model']}, "
         f"{meta['cpu_count']} cores; {args.pixels:,} pixels, {args.repeats} repeats"
         + (" [QUICK]" if args.quick else ""))
    load_start = _loadavg()
    results = bench(args.cases, args.backends, args.pixels, args.repeats, args.seed)
    meta["loadavg_start"], meta["loadavg_end"] = load_start, _loadavg()
    bits_match = {}
    for case in args.cases:
        digests = {r["digest"] for r in results if r["case"] == case and r.get("digest")}
        if sum(1 for r in results if r["case"] == case and r.get("digest")) > 1:
            bits_match[case] = len(digests) == 1

    report = {
        "schema": SCHEMA,
        "benchmark": "pyoa Sampler.generate throughput",
        "method": f"median of {args.repeats} timed generate calls after one warm-up; "
                  "time.perf_counter around generate only; cases and backends interleaved round-robin",
        "config": {"cases": args.cases, "backends": args.backends, "pixels": args.pixels,
                   "repeats": args.repeats, "seed": args.seed, "quick": args.quick,
                   "full_workload": args.pixels == FULL_PIXELS},
        "machine": meta,
        "results": results,
        "bits_match": bits_match,
        "total_s": time.perf_counter() - t_start,
    }
    md = markdown(report)
    _write(out_json, json.dumps(report, indent=2) + "\n")
    _write(out_md, md)
    print()
    print(md, end="")
    print(f"\nwrote {out_json} and {out_md} ({report['total_s']:.0f} s)")
    ok = any(r["status"] == "ok" for r in results)
    mismatch = any(not same for same in bits_match.values())
    return 0 if ok and not mismatch else 1


if __name__ == "__main__":
    sys.exit(main())
