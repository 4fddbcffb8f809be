"""What every benchmark shares: the machine's description, timing and atomic
result files.

A throughput figure means nothing without its CPU (the same workload runs
2.5-3.5x faster on the Zen 5 EPYC of this machine kind than on its AVX2 EPYC)
and its load (the machine drifts 15-40 % between processes), so every report
carries ``machine()`` and its ``machine_lines()`` section, and every figure
comes from ``timed()``: a warm-up, then repeats, median with min and max.
``bench_generate.py``, ``bench_scaling.py`` and ``bench_render.py`` import
from here; nothing here is timed itself.
"""

from __future__ import annotations

import csv
import datetime as _dt
import os
import platform
import socket
import statistics
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

import pyoa
from pyoa.util.atomic import atomic_path

REPO = Path(__file__).resolve().parent.parent


# ---------------------------------------------------------------------------
# machine description


def _cpu() -> dict:
    """Vendor, family, model and widest vector ISA: the same workload runs
    2.5-3.5x faster on the Zen 5 EPYC (AVX-512) than on the AVX2 EPYC of this
    machine kind, so a figure without its CPU is not comparable."""
    from pyoa.util.hostcpu import host_cpu

    cpu = host_cpu()
    return {"cpu_model": cpu.name, "cpu_vendor": cpu.vendor, "cpu_family": cpu.family,
            "cpu_model_number": cpu.model, "cpu_isa": cpu.isa, "cpu": cpu.describe()}


def _opencl_devices() -> dict:
    """The OpenCL device pyoa uses by default and every device's status
    (compiler: platform, LLVM version and target CPU)."""
    try:
        from pyoa._opencl.choice import open_device, probe_all

        statuses = probe_all()
        try:
            used = open_device()[0].selector
        except Exception:  # noqa: BLE001 - no device builds: the statuses say why
            used = None
    except Exception as exc:  # noqa: BLE001 - no OpenCL at all
        return {"opencl_default": None, "opencl_devices": [], "opencl_error": f"{type(exc).__name__}: {exc}"}
    return {
        "opencl_default": used,
        "opencl_devices": [{"selector": st.info.selector, "device": st.info.device.name.strip(),
                            "compiler": st.info.compiler(), "works": st.works, "reason": st.reason}
                           for st in statuses],
    }


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
        "date_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "hostname": socket.gethostname(),
        **_cpu(),
        "cpu_count": os.cpu_count(),
        "cpu_count_usable": usable,
        "platform": platform.platform(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "pyopencl": _version("pyopencl"),
        "pocl_binary_distribution": _version("pocl-binary-distribution"),
        **_opencl_devices(),
        "pyoa": pyoa.__version__,
        "pyoa_path": str(Path(pyoa.__file__).resolve().parent),
        "git_commit": commit,
        "git_dirty": bool(status) if status is not None else None,
        "environment": {k: v for k, v in sorted(os.environ.items())
                        if k.startswith(("PYOA_", "POCL_", "OMP_", "OPENBLAS_", "MKL_"))},
    }


# ---------------------------------------------------------------------------
# timing


def loadavg() -> list[float] | None:
    """1, 5 and 15-minute load averages: a load well above 0 before the run means other work competed."""
    try:
        return [round(v, 2) for v in os.getloadavg()]
    except (AttributeError, OSError):
        return None


def log(msg: str) -> None:
    print(msg, flush=True)


def timed(fn: Callable[[], object], repeats: int, *, warmup: bool = True, label: str | None = None) -> dict:
    """Call ``fn`` once untimed (``warmup``: kernel builds, JIT, caches,
    first-touch page faults), then ``repeats`` times with ``time.perf_counter()``
    around each call. Returns the seconds of every run, their median, minimum
    and maximum, and the last call's result (``"result"``, not serialized).
    With ``label`` each run is logged as it ends."""
    if repeats < 1:
        raise ValueError(f"repeats must be >= 1, got {repeats}")
    if warmup:
        fn()
    times, result = [], None
    for k in range(repeats):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
        if label:
            log(f"  {label} run {k + 1}/{repeats}: {times[-1]:.3f} s")
    return {"times_s": times, "median_s": statistics.median(times), "min_s": min(times), "max_s": max(times),
            "result": result}



#: Helpers of the benchmarks' memory children (fresh processes, so the code
#: travels as source, prepended to each child's script): ``status_kib(key)``
#: reads ``VmRSS``/``VmHWM`` from ``/proc/self/status``; ``reset_peak()`` sets
#: ``VmHWM`` to the current RSS (Linux >= 4.0), so the peak measured after it
#: is the measured call's own, and says whether it could.
MEMORY_CHILD_HELPERS = r"""
def status_kib(key):
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    return None

def reset_peak():
    rss = status_kib("VmRSS")
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
    except OSError:
        return False
    return status_kib("VmHWM") <= rss + 1024
"""


# ---------------------------------------------------------------------------
# reports


def _load(avg) -> str:
    return " / ".join(f"{v:.2f}" for v in avg) if avg else "unknown"


def machine_lines(meta: dict, total_s: float, devices: dict) -> list[str]:
    """The "Machine and software" section of a report (shared by the benchmarks)."""
    commit = meta["git_commit"] or "unknown"
    if meta["git_dirty"]:
        commit += " (with uncommitted changes)"
    lines = [
        "Machine and software:",
        "",
        f"- date (UTC): {meta['date_utc']}; total wall time {total_s:.0f} s",
        f"- host: {meta['hostname']}; CPU: {meta.get('cpu') or meta['cpu_model']}; cores: {meta['cpu_count']} "
        f"({meta['cpu_count_usable']} usable); load average (1/5/15 min) {_load(meta['loadavg_start'])} "
        f"before, {_load(meta['loadavg_end'])} after",
        f"- Python {meta['python']}, NumPy {meta['numpy']}, pyopencl {meta['pyopencl']}, "
        f"pyoa {meta['pyoa']} (git {commit})",
    ]
    lines += [f"- {name} device: {dev}" for name, dev in devices.items()]
    for d in meta.get("opencl_devices", []):
        state = ("works" + (", pyoa's default" if d["selector"] == meta.get("opencl_default") else "")
                 if d["works"] else f"fails: {d['reason']}")
        lines.append(f"- OpenCL device {d['selector']}: {d['device']} [{d['compiler']}]: {state}")
    if meta.get("opencl_error"):
        lines.append(f"- OpenCL: {meta['opencl_error']}")
    return lines


def write_text(path: Path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
        umask = os.umask(0)
        os.umask(umask)
        tmp.chmod(0o666 & ~umask)  # mkstemp creates 0600; results are meant to be shared


def write_csv(path: Path, rows: list[dict]) -> None:
    """``rows`` (dicts with the same keys) as a CSV file, written atomically."""
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
