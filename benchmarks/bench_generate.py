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

The ``fill`` backend row times NumPy's ``ndarray.fill`` into the same
result array: the rate at which the machine writes float32 values at all.
The ``of fill`` column divides every rate (pyoa's and the peers') by the fill
rate of the same case in the same run; the generation goals are stated as
such fractions (docs/performance.md), because the machine's speed drifts
between processes and differs between CPUs. The ``of compute`` column
divides the opencl rate by the cores' bound instead (Compute ceiling, below).

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
minutes, so they are opt-in. ``--cases baselines`` runs every comparison sampler of the catalogue
and every progressive one (``faure``; about 8 minutes with the default case).

Peers
-----
When the required case is among the cases, the same run also measures peer
implementations of the same workload (N = 121 points per pixel, 10
dimensions), so the ratios in the report are measured side by side, not
quoted (``peers.py``; ``--no-peers`` turns them off):

- SciPy's ``scipy.stats.qmc.LatinHypercube(d=10, strength=2, rng=seed)``
  (an OA-based Latin hypercube): one ``.random(121)`` call is one pixel's
  point set. It builds the array in Python loops, so after one warm-up call
  it is timed for ``--peer-budget`` seconds (3 s; 0.5 s with ``--quick``),
  as many calls as fit; values/s = calls x 121 x 10 / elapsed, and the full
  65,536-pixel time is extrapolated from it.
- Mitsuba 3's samplers ``orthogonal``, ``independent``, ``multijitter`` and
  ``ldsampler`` on the ``llvm_ad_rgb`` variant, if ``mitsuba`` is
  importable, all in one subprocess that stays up (an LLVM abort must not
  take the benchmark down): ``seed(seed, wavefront_size=P * spp)`` after
  ``set_samples_per_wavefront(spp)`` (as Mitsuba's render loop does), then
  ten ``next_1d()`` draws, ``dr.eval`` and ``np.asarray``; one warm-up (JIT
  compilation), then the median of ``--repeats`` runs; values/s =
  P x spp x 10 / median. P is ``--peer-pixels`` (default: ``--pixels``).
  The runs go in rounds: each round times pyoa's OpenCL row of the required
  case once, in this process, then each Mitsuba sampler once, and the
  "pyoa OpenCL / peer" ratio is the median of the per-round ratios. The
  machine's speed drifts 15-40 % over a run; a ratio of two medians taken
  minutes apart (pyoa's rows, then the peers) carried that drift: 0.87x and
  1.12x against ``ldsampler`` in two runs of the same code.

A peer that cannot run is listed as ``skipped`` (not installed, or SciPy
rejects the configuration) or ``failed`` (the subprocess's exit status and
first line of stderr), never silently left out. Peers never change the exit
status.

Compute ceiling
---------------
The write rate differs 5x between CPUs, so "of fill" alone does not say
whether the kernels are bound by memory or by the cores' arithmetic. For
the required case and the blocks' cases (``CEILING_CASES``), when the
``opencl`` rows ran on a PoCL CPU device, the report states the other bound
beside it: ``compute_ceiling.ceiling`` (``compute_ceiling.py``, whose
docstring gives the method) builds the case's vector-path kernels in a
subprocess with a fresh ``POCL_CACHE_DIR``, finds PoCL's work-item loop in
the machine code of ``vector_values`` (one iteration: 8 sample positions x
dims values of one pixel), counts its instructions, has ``llvm-mca-15``
(host CPU model) give the cycles one iteration needs, and states
``cores x clock x values per iteration / cycles per iteration``, with the
clock the VM reports (``/proc/cpuinfo``, nominal, not measured). It runs
after every timed call (it compiles kernels, a few seconds per case, and
must not disturb the timing). The ``opencl`` row of those cases gets the
ceiling in M values/s and its median rate's fraction of it ("of compute"),
and a note says which bound the rate is closer to. A ceiling that cannot be
taken (no ``llvm-mca-15`` or disassembler, not a CPU device, a forced
non-vector ``PYOA_OPENCL_PATH``, any error) reads "not measured", with the
reason in the notes and the JSON, and never changes the exit status;
``--no-ceiling`` skips it. The ceiling counts the values kernel alone (not
the tables kernel, the launches or memory stalls), at the nominal clock.

Noise
-----
On the 2-core PoCL machines this project is measured on, the same workload
varies by 15-25 % from one process to the next (docs/performance.md, lessons for PoCL
item 9). Compare figures taken within one invocation of this script (same
process, interleaved runs); treat a difference between two invocations
smaller than about 25 % as noise. The min/max columns show the spread inside
one process, and the load averages before and after the run (in the
metadata) show whether other work competed for the two cores.

Output
------
``benchmarks/results/generate.json`` (``--out`` to change) with every run's
time and the machine's description (and, from schema 3,
``compute_ceilings``: ``compute_ceiling.ceiling``'s dictionary per case,
with ``compute_ceiling_values_per_s`` and ``of_compute_ceiling`` on the
opencl rows), and a Markdown table beside it with the same stem
(``generate.md``); both are written atomically. The table is also printed
at the end. Then the docs' marked sections made from that file, if any are
(``update_docs.after``: ``generate-vector.json`` and the files the README's
table quotes).

Usage::

    python benchmarks/bench_generate.py                 # required case, both backends
    python benchmarks/bench_generate.py --quick         # fast smoke run
    python benchmarks/bench_generate.py --cases all     # every case
    python benchmarks/bench_generate.py --cases default,baselines  # Bose and the comparison samplers
    python benchmarks/bench_generate.py --backends opencl --repeats 9
    python benchmarks/bench_generate.py --no-peers      # pyoa rows only
    python benchmarks/bench_generate.py --no-ceiling    # without the compute ceiling (llvm-mca)
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import statistics
import sys
import time
import warnings
from pathlib import Path
from typing import Callable

import numpy as np

try:
    import pyoa
    from pyoa import catalogue
    from pyoa.samplers import trial_options
except ImportError as _exc:  # pragma: no cover - environment problem
    sys.exit(f"bench_generate: cannot import pyoa ({_exc}); install it first: pip install -e .")

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "benchmarks"))  # peers.py and common.py, shared with bench_render.py
import peers  # noqa: E402
from common import loadavg, log, machine, machine_lines, write_text  # noqa: E402
import update_docs  # noqa: E402

DEFAULT_OUT = REPO / "benchmarks" / "results" / "generate.json"
FULL_PIXELS = 65536
QUICK_PIXELS = 4096
SCHEMA = 3  # 2: the "peers" list; 3: "compute_ceilings" and the opencl rows' compute_ceiling_values_per_s
PEER_BUDGET_S = 3.0
QUICK_PEER_BUDGET_S = 0.5

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
    # the blocks: 12 dimensions fill Bose s=11's first block; 36 are blocks 0-2, where later blocks read
    # their own order of the rows (docs/spec.md section 6)
    "bose-cmj-121x12": dict(name="bose", spp=121, dims=12, offset="cmj", strength=None,
                            about="Bose s=11, cmj, 12 dimensions: one whole block"),
    "bose-cmj-121x36": dict(name="bose", spp=121, dims=36, offset="cmj", strength=None,
                            about="Bose s=11, cmj, 36 dimensions: blocks 0-2, each later block in its own row order"),
}
#: The blocks' cases (``--cases blocks``): the required one, one whole block and three blocks.
BLOCK_CASES = ("bose-cmj-121x10", "bose-cmj-121x12", "bose-cmj-121x36")
# Every comparison sampler of the catalogue (the paper's six, pbrt-v4's zsobol
# and pmj02) and every progressive one (faure, at its default base: b=11 at
# 121 spp and 10 dims, Bose's array size), at the count nearest 121, 10 dimensions.
CASES.update({
    f"{n}-{catalogue.nearest_spp(n, 121)}x10": dict(name=n, spp=catalogue.nearest_spp(n, 121), dims=10, offset=None,
                                                    strength=None, about=catalogue.get(n).description)
    for n in (*catalogue.names("baseline"), *catalogue.names("progressive"))
})
#: The comparison and progressive samplers' cases (``--cases baselines``).
BASELINE_CASES = tuple(c for c, spec in CASES.items() if spec["offset"] is None)
REQUIRED_CASE = "bose-cmj-121x10"
#: The cases whose opencl row gets a compute ceiling (compute_ceiling.py): the required one and the blocks'.
CEILING_CASES = BLOCK_CASES
#: The full set of cases takes about 8 minutes on a 2-core machine (NumPy
#: dominates), over the 5-minute budget for a default run, so only the
#: required case runs by default; ``--cases all`` runs every case.
DEFAULT_CASES = (REQUIRED_CASE,)
BACKENDS = ("opencl", "numpy", "fill")


class _Fill:
    """The ``fill`` row: NumPy's ``ndarray.fill`` into the same result array,
    the rate at which this machine can write float32 values at all (memory
    bandwidth). The generation goals are fractions of it, measured in the
    same run (docs/performance.md)."""

    device = "NumPy ndarray.fill (memory-bandwidth ceiling)"
    s = strength = None

    def __init__(self, shape: tuple):
        self.shape = shape

    def __repr__(self) -> str:
        return f"ndarray.fill{self.shape}"

    def generate(self, pixels, out=None):
        x = np.empty(self.shape, np.float32) if out is None else out
        x.fill(0.5)
        return x


# ---------------------------------------------------------------------------
# timing


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
    log(f"  {entry['case']:<22} {entry['backend']:<7} {what:<9} {dt:8.3f} s "
         f"{entry['values'] / dt / 1e6:9.1f} M values/s")


def _fail(entry: dict, status: str, exc: Exception) -> None:
    entry.update(status=status, reason=f"{type(exc).__name__}: {exc}")
    log(f"  {entry['case']:<22} {entry['backend']:<7} {status.upper()}: {entry['reason']}")


#: Output arrays reused across timed calls, one per shape (see ``--fresh-output``).
_OUTPUTS: dict[tuple, np.ndarray] = {}


def _output(entry: dict, fresh: bool):
    """The ``out=`` argument of a timed call: None (generate allocates a new
    array) with ``fresh``, else one array per shape, reused by every call."""
    if fresh:
        return None
    shape = (entry["pixels"], entry["spp"], entry["dims"])
    if shape not in _OUTPUTS:
        _OUTPUTS[shape] = np.empty(shape, np.float32)
    return _OUTPUTS[shape]


def prepare(case: str, backend: str, pixels: int, seed: int, fresh: bool = False) -> tuple[dict, object]:
    """Create the sampler and run the untimed-for-the-median warm-up; never raises for a backend failure.

    Returns the result entry and the sampler (None when skipped or failed).
    """
    spec = CASES[case]
    values = pixels * spec["spp"] * spec["dims"]
    # "opencl[P:D]": the OpenCL backend on that device (--opencl-devices all)
    name, _, device = backend.partition("[")
    device = device.rstrip("]") or None
    entry = {"case": case, "backend": backend, "pixels": pixels, "spp": spec["spp"], "dims": spec["dims"],
             "values": values, "status": "ok", "times_s": []}
    try:
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("error", pyoa.PyoaFallbackWarning)  # never a silent fallback
            smp = _Fill((pixels, spec["spp"], spec["dims"])) if name == "fill" else pyoa.sampler(
                spec["name"], spp=spec["spp"], dims=spec["dims"], seed=seed,
                **trial_options(spec["name"], dict(offset=spec["offset"], strength=spec["strength"], backend=name,
                                                   device=device)))
        entry["setup_s"] = time.perf_counter() - t0
    except Exception as exc:  # noqa: BLE001 - an unusable backend is reported, not fatal
        _fail(entry, "skipped", exc)
        return entry, None
    entry.update(device=smp.device, sampler=repr(smp), s=smp.s, strength=smp.strength)
    entry.update(_opencl_details(smp))
    try:
        t0 = time.perf_counter()
        x = smp.generate(pixels=range(pixels), out=_output(entry, fresh))
        entry["warmup_s"] = time.perf_counter() - t0
        entry["digest"] = _digest(x)
        del x
    except Exception as exc:  # noqa: BLE001 - e.g. an OpenCL runtime error
        _fail(entry, "failed", exc)
        return entry, None
    _line(entry, "warm-up", entry["warmup_s"])
    return entry, smp


def timed_run(entry: dict, smp, k: int, repeats: int, fresh: bool = False) -> bool:
    """One timed ``generate``; appends to ``entry['times_s']``. False (and the entry marked failed) on error."""
    try:
        out = _output(entry, fresh)
        t0 = time.perf_counter()
        x = smp.generate(pixels=range(entry["pixels"]), out=out)
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


def bench(cases: list[str], backends: list[str], pixels: int, repeats: int, seed: int,
          fresh: bool = False) -> list[dict]:
    """Warm up every (case, backend), then time them round-robin, ``repeats`` rounds.

    Interleaving spreads a transient slowdown of the machine (another process,
    a noisy neighbour) over every row instead of one, so the rows of one run
    stay comparable with each other.
    """
    pairs = [prepare(case, backend, pixels, seed, fresh) for case in cases for backend in backends]
    for k in range(repeats):
        for i, (entry, smp) in enumerate(pairs):
            if smp is not None and not timed_run(entry, smp, k, repeats, fresh):
                pairs[i] = (entry, None)
    return [summarize(entry) for entry, _ in pairs]


# ---------------------------------------------------------------------------
# compute ceiling


def _no_ceiling(reason: str) -> dict:
    return {"status": "not measured", "reason": reason}


def compute_ceilings(cases: list[str], results: list[dict], seed: int) -> dict[str, dict]:
    """``compute_ceiling.ceiling`` of every case in CEILING_CASES whose opencl row ran on a PoCL CPU
    device, keyed by case; a case it cannot measure gets status "not measured" and the reason. Sets
    ``compute_ceiling_values_per_s`` and ``of_compute_ceiling`` on those opencl rows. Never raises."""
    wanted = [c for c in cases if c in CEILING_CASES]
    rows = {r["case"]: r for r in results if r["backend"] == "opencl"}
    wanted = [c for c in wanted if c in rows]
    if not wanted:
        return {}
    try:
        import compute_ceiling  # benchmarks/ is on sys.path (see the imports above)
    except Exception as exc:  # noqa: BLE001 - a missing or broken helper is reported, not fatal
        return {c: _no_ceiling(f"cannot import compute_ceiling.py ({type(exc).__name__}: {exc})") for c in wanted}
    path = os.environ.get("PYOA_OPENCL_PATH") or "auto"
    out: dict[str, dict] = {}
    for case in wanted:
        row, spec = rows[case], CASES[case]
        device = row.get("device") or ""
        if row["status"] != "ok" or "median_values_per_s" not in row:
            res = _no_ceiling(f"the opencl row did not run ({row['status']})")
        elif "(cpu)" not in device or "Portable Computing Language" not in device:
            res = _no_ceiling(f"not a PoCL CPU device ({device})")
        elif path not in ("auto", "vector"):
            res = _no_ceiling(f"PYOA_OPENCL_PATH={path}: the opencl row did not take the vector path")
        else:
            t0 = time.perf_counter()
            try:
                res = compute_ceiling.ceiling(spec["name"], spec["spp"], spec["dims"], spec["offset"],
                                              strength=spec["strength"], seed=seed)
            except Exception as exc:  # noqa: BLE001 - ceiling() should not raise; never fail the benchmark
                res = _no_ceiling(f"{type(exc).__name__}: {exc}")
            res["elapsed_s"] = time.perf_counter() - t0
        if res["status"] == "ok":
            cap = res["ceiling_values_per_s"]
            row["compute_ceiling_values_per_s"] = cap
            row["of_compute_ceiling"] = row["median_values_per_s"] / cap
            log(f"  {case:<22} opencl  compute ceiling {cap / 1e6:9.1f} M values/s "
                f"({res['cycles_per_iteration']:.1f} cycles / {res['values_per_iteration']} values, "
                f"-mcpu={res['mca']['mcpu']}); measured {row['of_compute_ceiling']:.2f} of it")
        else:
            row["compute_ceiling"] = f"not measured: {res['reason']}"
            log(f"  {case:<22} opencl  compute ceiling not measured: {res['reason']}")
        out[case] = res
    return out


# ---------------------------------------------------------------------------
# report


def _m(v: float) -> str:
    return f"{v / 1e6:,.1f}"


def _rate(v: float) -> str:
    """M values/s with three significant figures or more: 173.2, 4.51, 0.403."""
    m = v / 1e6
    return f"{m:,.1f}" if m >= 100 else f"{m:.3g}" if m >= 0.001 else f"{m:.2e}"


def _ratio(a: float | None, b: float | None) -> str:
    if not a or not b:
        return ""
    r = a / b
    return f"{r:,.0f}x" if r >= 100 else f"{r:.1f}x" if r >= 1 else f"{r:.2f}x"


def _peer_ratio(p: dict, pyoa_rate: float | None) -> str:
    """pyoa's OpenCL rate over the peer's: the median of the per-round ratios
    where the peer was timed in rounds with pyoa (marked r), else the ratio
    of the two medians."""
    per_round = p["details"].get("pyoa_over_peer")
    if per_round:
        return _ratio(per_round, 1.0) + " r"
    return _ratio(pyoa_rate, p["values_per_s"])


def _peer_details(p: dict) -> str:
    d = p["details"]
    if p["status"] != "ok":
        return p["reason"] or ""
    if "calls" in d:  # SciPy
        return (f"scipy {d['scipy']}, `{d['call']}`: {d['calls']:,} calls in {d['elapsed_s']:.2f} s; per call "
                f"median {1e3 * d['median_call_s']:.2f} ms (min {1e3 * d['min_call_s']:.2f}, "
                f"max {1e3 * d['max_call_s']:.2f}); float64 output")
    spp = f"{d['sample_count']} spp" + (f" (asked {d['requested_spp']})" if d["sample_count"] != d["requested_spp"]
                                        else "")
    px = f"{d['pixels']:,} pixels" + (f" (asked {d['requested_pixels']:,})" if d["pixels"] != d["requested_pixels"]
                                      else "")
    runs = len(d["times_s"])
    return (f"Mitsuba {d['version']} `{d['variant']}`, {px} x {spp} x {d['dims']} dims; median of {runs} "
            f"run{'s' if runs != 1 else ''} {d['median_s']:.3f} s (min {d['min_s']:.3f}, max {d['max_s']:.3f}), "
            f"warm-up {d['warmup_s']:.2f} s")


def peers_markdown(report: dict) -> list[str]:
    """The "Peers (same run)" section: each peer's rate and pyoa's (required case, this run) over it."""
    cfg = report["config"]
    lines = ["", "Peers (same run):", ""]
    if not cfg["peers"]:
        return lines + [f"Not run: {cfg['peers_note']}."]
    pyoa_rate = {r["backend"]: r.get("median_values_per_s") for r in report["results"]
                 if r["case"] == REQUIRED_CASE}
    spec = CASES[REQUIRED_CASE]
    runs = f"{cfg['repeats']} run{'s' if cfg['repeats'] != 1 else ''}"
    lines += [
        f"The `{REQUIRED_CASE}` workload ({spec['spp']} points per pixel, {spec['dims']} dimensions) by other "
        f"implementations, timed after pyoa's rows (SciPy in this process, Mitsuba in one subprocess). SciPy's "
        f"ratios divide pyoa's median M values/s from the table above by the peer's. SciPy: as many "
        f"`.random({spec['spp']})` calls (one pixel each) as fit in {cfg['peer_budget_s']:g} s after one warm-up call. The est. s column is the time the "
        f"full workload ({FULL_PIXELS:,} pixels x {spec['spp']} x {spec['dims']}) would take at the peer's rate. "
        f"Mitsuba: {cfg['peer_pixels']:,} pixels in one wavefront per run, median of {runs} after a warm-up, "
        f"in rounds that each time pyoa's OpenCL row once, then each Mitsuba sampler once; a Mitsuba row's "
        f"pyoa OpenCL / peer is the median of the per-round ratios (marked r), robust to the machine's drift "
        f"between the table above and the peers.",
        "",
        f"| peer | status | M values/s | of fill | pyoa OpenCL / peer | pyoa NumPy / peer | est. s, {FULL_PIXELS:,} px | "
        "details |",
        "|---|---|---:|---:|---:|---:|---:|---|",
    ]
    fill = pyoa_rate.get("fill")
    for p in report["peers"]:
        rate = p["values_per_s"]
        full = p["details"].get("full_workload_s")
        lines.append(
            f"| {p['name']} | {p['status']} | {_rate(rate) if rate else ''} | "
            f"{f'{rate / fill:.3f}' if rate and fill else ''} | "
            f"{_peer_ratio(p, pyoa_rate.get('opencl'))} | {_ratio(pyoa_rate.get('numpy'), rate)} | "
            f"{f'{full:,.1f}' if full else ''} | {_peer_details(p)} |"
        )
    return lines


def ceiling_notes(report: dict, rate: dict) -> list[str]:
    """One note per compute ceiling: which bound, fill (memory) or compute, the opencl rate is closer to."""
    notes = []
    for case, c in (report.get("compute_ceilings") or {}).items():
        if c["status"] != "ok":
            notes.append(f"- {case} / opencl: compute ceiling not measured: {c['reason']}")
            continue
        got, fill, cap = rate.get((case, "opencl")), rate.get((case, "fill")), c["ceiling_values_per_s"]
        how = (f"{c['cores']} cores x {c['clock_mhz']:,.0f} MHz (nominal, as the VM reports it) x "
               f"{c['values_per_iteration']} values / {c['cycles_per_iteration']:,.1f} cycles per work-item "
               f"(llvm-mca -mcpu={c['mca']['mcpu']}; {c['counts']['instructions']:,} instructions, "
               f"{c['instructions_per_value']:.2f} per value; compute_ceiling.py)")
        if not got:
            notes.append(f"- {case} / opencl: compute ceiling {_m(cap)} M values/s = {how}")
        elif fill:
            closer = "compute (the cores' arithmetic)" if got / cap > got / fill else "memory (fill)"
            far = f", though far from both (at most {max(got / cap, got / fill):.2f} of either)" if max(
                got / cap, got / fill) < 0.5 else ""
            sim = c.get("simulated_ceiling_values_per_s")
            # The block throughput assumes every instruction issues as soon as a port is free; llvm-mca's
            # simulation of the loop also waits for each instruction's operands (docs/performance.md,
            # "What bounds generation": measured rates sit at 0.7-0.9 of it)
            simulated = (f"; {got / sim:.2f} of llvm-mca's simulation of the loop, dependencies included "
                         f"({_m(sim)} M values/s)") if sim else ""
            notes.append(f"- {case} / opencl: {got / fill:.2f} of fill ({_m(fill)} M values/s) and {got / cap:.2f} "
                         f"of the compute ceiling ({_m(cap)} M values/s = {how}): closer to the {closer} "
                         f"bound{far}{simulated}")
        else:
            notes.append(f"- {case} / opencl: {got / cap:.2f} of the compute ceiling ({_m(cap)} M values/s = "
                         f"{how}); no fill row in this run to compare with")
    return notes


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
        f"warm-up, seed {cfg['seed']}, "
        + ("each allocating its result (`--fresh-output`)" if cfg.get("fresh_output")
           else "each writing into one reused `out=` array") +
        "; M values/s = values / median seconds. Process-to-process noise "
        "on this machine kind is 15-25 %: compare rows of this table, not separate runs.",
        "",
    ]
    show_cap = bool(report.get("compute_ceilings"))  # the two columns only when some row has a ceiling
    lines += [
        "| case | backend | values | median s | M values/s | min s | max s | spread | vs numpy | of fill |"
        + (" compute ceiling M values/s | of compute |" if show_cap else ""),
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|" + ("---:|---:|" if show_cap else ""),
    ]
    numpy_rate = {r["case"]: r.get("median_values_per_s") for r in report["results"] if r["backend"] == "numpy"}
    fill_rate = {r["case"]: r.get("median_values_per_s") for r in report["results"] if r["backend"] == "fill"}
    for r in report["results"]:
        if "median_s" not in r:
            lines.append(f"| {r['case']} | {r['backend']} | {r['values']:,} | {r['status']} | | | | | | |"
                         + (" | |" if show_cap else ""))
            continue
        base = numpy_rate.get(r["case"])
        ratio = f"{r['median_values_per_s'] / base:.1f}x" if base and r["backend"] not in ("numpy", "fill") else ""
        fill = fill_rate.get(r["case"])
        of_fill = f"{r['median_values_per_s'] / fill:.3f}" if fill and r["backend"] != "fill" else ""
        cap = r.get("compute_ceiling_values_per_s")
        cap_text = _m(cap) if cap else "not measured" if r.get("compute_ceiling") else ""  # why: in the notes
        of_cap = f"{r['of_compute_ceiling']:.3f}" if cap else ""
        lines.append(
            f"| {r['case']} | {r['backend']} | {r['values']:,} | {r['median_s']:.3f} | "
            f"{_m(r['median_values_per_s'])} | {r['min_s']:.3f} | {r['max_s']:.3f} | "
            f"{100 * r['spread']:.0f} % | {ratio} | {of_fill} |" + (f" {cap_text} | {of_cap} |" if show_cap else "")
        )
    notes = [f"- {r['case']} / {r['backend']}: {r['status']}: {r['reason']}"
             for r in report["results"] if r["status"] != "ok"]
    rate = {(r["case"], r["backend"]): r.get("median_values_per_s") for r in report["results"]}
    for backend in ("opencl", "numpy"):
        a, b = rate.get(("bose-cmj-121x36", backend)), rate.get(("bose-cmj-121x12", backend))
        if a and b:
            notes.append(f"- {backend}: 36 dimensions (blocks 0-2) at {a / b:.2f}x the values per second of 12 "
                         "(one block), in this run")
    for case, same in report["bits_match"].items():
        notes.append(f"- {case}: backends gave {'identical' if same else 'DIFFERENT'} bits (BLAKE2b of the output)")
    notes += ceiling_notes(report, rate)
    if notes:
        lines += ["", *notes]
    lines += peers_markdown(report)
    lines += ["", "Cases:", ""]
    for case in cfg["cases"]:
        spec = CASES[case]
        st = f", strength={spec['strength']}" if spec["strength"] else ""
        st += f", offset={spec['offset']!r}" if spec["offset"] else ""
        lines.append(f"- `{case}`: `pyoa.sampler({spec['name']!r}, spp={spec['spp']}, dims={spec['dims']}"
                     f"{st})`; {spec['about']}")
    devices = {r["backend"]: r["device"] for r in report["results"] if r.get("device")}
    lines += ["", *machine_lines(meta, report["total_s"], devices)]
    ocl = next((r for r in report["results"] if r.get("opencl_platform_version")), None)
    if ocl:
        lines.append(f"- OpenCL platform version: {ocl['opencl_platform_version']}; "
                     f"driver {ocl['opencl_driver_version']}")
    if meta["environment"]:
        lines.append("- environment: " + ", ".join(f"`{k}={v}`" for k, v in meta["environment"].items()))
    return "\n".join(lines) + "\n"


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
                    help="comma-separated backends; 'fill' is NumPy's ndarray.fill into the same array, the "
                         "memory-bandwidth ceiling the 'of fill' column divides by (default: opencl,numpy,fill)")
    ap.add_argument("--cases", type=_csv(tuple(CASES), "case", extra={"all": tuple(CASES),
                                                                       "default": DEFAULT_CASES,
                                                                       "baselines": BASELINE_CASES,
                                                                       "blocks": BLOCK_CASES}),
                    default="default",
                    help=f"comma-separated case names, 'default' ({', '.join(DEFAULT_CASES)}), "
                         "'baselines' (the comparison and progressive samplers), 'blocks' (Bose 121 at 10, 12 "
                         "and 36 dimensions: later blocks' own row orders) or 'all' (see --list; "
                         "default: default)")
    ap.add_argument("--repeats", type=int, default=5, help="timed runs after the warm-up (default: 5)")
    ap.add_argument("--pixels", type=int, default=None,
                    help=f"pixels per generate call (default: {FULL_PIXELS}; {QUICK_PIXELS} with --quick)")
    ap.add_argument("--quick", action="store_true",
                    help=f"smoke run: {QUICK_PIXELS} pixels unless --pixels; results are marked quick")
    ap.add_argument("--seed", type=int, default=0, help="sampler seed (default: 0)")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT,
                    help="JSON result path; the Markdown table goes beside it with suffix .md "
                         "(default: benchmarks/results/generate.json)")
    ap.add_argument("--no-peers", dest="peers", action="store_false",
                    help="do not time the peers (SciPy's OA-LHS, Mitsuba 3's samplers)")
    ap.add_argument("--peer-budget", type=float, default=None,
                    help=f"seconds of timed SciPy LatinHypercube calls (default: {PEER_BUDGET_S:g}; "
                         f"{QUICK_PEER_BUDGET_S:g} with --quick)")
    ap.add_argument("--peer-pixels", type=int, default=None,
                    help="pixels per Mitsuba wavefront (x spp samples; default: --pixels)")
    ap.add_argument("--fresh-output", action="store_true",
                    help="let every timed generate allocate its result (default: one reused out= array per "
                         "shape, faulted in by the warm-up: the issue's 'copy into a reused host array')")
    ap.add_argument("--opencl-devices", choices=("default", "all"), default="default",
                    help="'all': time the opencl rows on every OpenCL device that builds pyoa's kernels, in this "
                         "run (rows opencl[P:D] beside pyoa's default device's opencl row); default: default")
    ap.add_argument("--no-ceiling", dest="ceiling", action="store_false",
                    help="do not compute the opencl rows' compute ceiling (compute_ceiling.py: llvm-mca on PoCL's "
                         "machine code; only for the required and the blocks' cases)")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error("--repeats must be at least 1")
    if args.pixels is None:
        args.pixels = QUICK_PIXELS if args.quick else FULL_PIXELS
    if args.pixels < 1:
        ap.error("--pixels must be at least 1")
    if args.peer_budget is None:
        args.peer_budget = QUICK_PEER_BUDGET_S if args.quick else PEER_BUDGET_S
    if not args.peer_budget > 0:
        ap.error("--peer-budget must be positive")
    if args.peer_pixels is None:
        args.peer_pixels = args.pixels
    if args.peer_pixels < 1:
        ap.error("--peer-pixels must be at least 1")
    return args


def pyoa_round(results: list[dict], args) -> Callable[[], float] | None:
    """One timed OpenCL call of the required case, returning its values per
    second, for the peers' rounds to alternate with (peers.mitsuba_samplers);
    None where that row did not run."""
    row = next((r for r in results if r["case"] == REQUIRED_CASE and r["backend"] == "opencl"), None)
    if row is None or row["status"] != "ok":
        return None
    entry, smp = prepare(REQUIRED_CASE, "opencl", args.pixels, args.seed, args.fresh_output)
    if smp is None:
        return None

    def run() -> float:
        out = _output(entry, args.fresh_output)
        t0 = time.perf_counter()
        smp.generate(pixels=range(entry["pixels"]), out=out)
        return entry["values"] / (time.perf_counter() - t0)

    return run


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
    log(f"pyoa {meta['pyoa']} (git {meta['git_commit'] or 'unknown'}) on {meta['cpu']}, "
         f"{meta['cpu_count']} cores; {args.pixels:,} pixels, {args.repeats} repeats"
         + (" [QUICK]" if args.quick else ""))
    load_start = loadavg()
    rows = list(args.backends)
    if args.opencl_devices == "all" and "opencl" in rows:
        others = [d["selector"] for d in meta["opencl_devices"] if d["works"] and d["selector"] != meta["opencl_default"]]
        at = rows.index("opencl") + 1
        rows[at:at] = [f"opencl[{sel}]" for sel in others]
    results = bench(args.cases, rows, args.pixels, args.repeats, args.seed, args.fresh_output)
    run_peers = args.peers and REQUIRED_CASE in args.cases
    peer_results: list[dict] = []
    if run_peers:
        spec = CASES[REQUIRED_CASE]
        peer_results = peers.run_peers(spec["spp"], spec["dims"], pixels=args.peer_pixels,
                                       budget_s=args.peer_budget, repeats=args.repeats, seed=args.seed,
                                       full_pixels=FULL_PIXELS, pyoa_run=pyoa_round(results, args), log=log)
    meta["loadavg_start"], meta["loadavg_end"] = load_start, loadavg()
    # after the timing and the load average: it compiles kernels in a subprocess (a few seconds per case)
    ceilings = compute_ceilings(args.cases, results, args.seed) if args.ceiling else {}
    bits_match = {}
    for case in args.cases:
        mine = [r for r in results if r["case"] == case and r.get("digest") and r["backend"] != "fill"]
        digests = {r["digest"] for r in mine}
        if len(mine) > 1:
            bits_match[case] = len(digests) == 1

    report = {
        "schema": SCHEMA,
        "benchmark": "pyoa Sampler.generate throughput",
        "method": f"median of {args.repeats} timed generate calls after one warm-up; "
                  "time.perf_counter around generate only; cases and backends interleaved round-robin",
        "config": {"cases": args.cases, "backends": rows, "opencl_devices": args.opencl_devices,
                   "pixels": args.pixels,
                   "repeats": args.repeats, "seed": args.seed, "quick": args.quick,
                   "fresh_output": args.fresh_output,
                   "full_workload": args.pixels == FULL_PIXELS,
                   "peers": run_peers, "peer_budget_s": args.peer_budget, "peer_pixels": args.peer_pixels,
                   "peers_note": None if run_peers else "--no-peers" if not args.peers else
                   f"the required case {REQUIRED_CASE} is not among the cases",
                   "ceiling": args.ceiling},
        "machine": meta,
        "results": results,
        "bits_match": bits_match,
        "peers": peer_results,
        "compute_ceilings": ceilings,
        "total_s": time.perf_counter() - t_start,
    }
    md = markdown(report)
    write_text(out_json, json.dumps(report, indent=2) + "\n")
    write_text(out_md, md)
    print()
    print(md, end="")
    print(f"\nwrote {out_json} and {out_md} ({report['total_s']:.0f} s)")
    for page in update_docs.after(out_json):  # the docs' sections made from this file
        print(f"wrote {page}")
    ok = any(r["status"] == "ok" for r in results)
    mismatch = any(not same for same in bits_match.values())
    return 0 if ok and not mismatch else 1


if __name__ == "__main__":
    sys.exit(main())
