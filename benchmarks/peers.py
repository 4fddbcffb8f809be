"""Peer figures for the benchmarks, measured in the same run as pyoa's.

- ``scipy_lhs``: SciPy's orthogonal-array-based Latin hypercube,
  ``scipy.stats.qmc.LatinHypercube(d, strength=2)``; one ``.random(N)`` call
  is one pixel's point set. It builds the array in Python loops, so it is
  timed for a time budget (as many calls as fit) rather than for the whole
  workload, and the full workload's time is extrapolated.
- ``mitsuba_samplers``: Mitsuba 3's samplers on its LLVM backend, each
  drawing ``dims`` values for ``pixels x spp`` samples in one wavefront, in
  one subprocess that stays up (``MitsubaPeers``: a Dr.Jit/LLVM abort must
  not take the benchmark down), timed in rounds that can alternate with
  pyoa's own timed calls.
- ``run_json_script``: the subprocess runner, shared with
  ``bench_render.py``: runs a Python snippet with this interpreter and reads
  a JSON object from the last line of its standard output.

Every peer entry has the keys ``name``, ``status`` (``ok``, ``skipped`` or
``failed``), ``values_per_s`` (None unless ok), ``details`` (a dict) and
``reason`` (None when ok).
"""

from __future__ import annotations

import importlib.util
import inspect
import json
import re
import signal
import statistics
import subprocess
import sys
import time
from typing import Callable

#: Mitsuba 3 samplers timed by ``run_peers``.
MITSUBA_SAMPLERS = ("orthogonal", "independent", "multijitter", "ldsampler")
MITSUBA_VARIANT = "llvm_ad_rgb"
#: Wall-clock limit of one Mitsuba subprocess (import, JIT compilation, warm-up and the timed runs).
MITSUBA_TIMEOUT_S = 600
#: ``Sampler.seed``'s ``wavefront_size`` is a uint32 and 2**32 - 1 means "not given".
MAX_WAVEFRONT = 2**32 - 2


def _entry(name: str, status: str, *, values_per_s: float | None = None, details: dict | None = None,
           reason: str | None = None) -> dict:
    return {"name": name, "status": status, "values_per_s": values_per_s, "details": details or {},
            "reason": reason}


def module_available(name: str) -> bool:
    """Whether ``name`` can be imported, without importing it."""
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


def mitsuba_available() -> bool:
    return module_available("mitsuba")


def _failure_line(proc: subprocess.CompletedProcess) -> str:
    """The exit status and the first line of stderr (of stdout if stderr is empty); for a Python
    traceback the last line, which names the exception."""
    code = proc.returncode
    what = f"exit {code}"
    if code < 0:
        try:
            what += f" ({signal.Signals(-code).name})"
        except ValueError:
            pass
    lines = [ln.strip() for ln in (proc.stderr or proc.stdout or "").splitlines() if ln.strip()]
    if lines and lines[0].startswith("Traceback"):
        msg = lines[-1]
    else:
        msg = lines[0] if lines else "no output"
    return f"{what}: {msg}"[:300]


_ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


# Which libLLVM Dr.Jit should load: pyoa's own finder (Mitsuba 3.9 needs LLVM >= 16).
from pyoa.util.drjit_llvm import MIN_DRJIT_LLVM, drjit_llvm  # noqa: E402,F401


def run_json_script(script: str, args: list, *, timeout: float | None = None, env: dict | None = None) -> dict:
    """Run ``python -c script *args`` in a subprocess and return the JSON object on the last line
    of its stdout. On a non-zero exit, a timeout or unreadable output, return
    ``{"status": "failed", "reason": ...}`` instead of raising."""
    try:
        proc = subprocess.run([sys.executable, "-c", script, *map(str, args)], capture_output=True, text=True,
                              timeout=timeout, env=env)
    except subprocess.TimeoutExpired:
        return {"status": "failed", "reason": f"timed out after {timeout:g} s"}
    except OSError as exc:
        return {"status": "failed", "reason": f"could not start {sys.executable}: {exc}"[:300]}
    if proc.returncode != 0:
        return {"status": "failed", "reason": _failure_line(proc)}
    # Mitsuba's logger leaves terminal colour codes (ESC [ ... m) on stdout,
    # sometimes in front of the JSON line
    lines = _ANSI.sub("", proc.stdout).strip().splitlines()
    try:
        out = json.loads(lines[-1]) if lines else None
    except json.JSONDecodeError:
        out = None
    if not isinstance(out, dict):
        return {"status": "failed", "reason": f"no JSON result on the last line of stdout: "
                                              f"{(lines[-1] if lines else '')[:200]!r}"}
    return out


# ---------------------------------------------------------------------------
# SciPy


def scipy_lhs(n: int, d: int, *, budget_s: float, seed: int = 0, max_calls: int | None = None,
              full_pixels: int | None = None) -> dict:
    """Time ``LatinHypercube(d, strength=2).random(n)`` for about ``budget_s`` seconds after one warm-up
    call; ``values_per_s = calls * n * d / elapsed``. One engine serves every call (each call draws a
    new randomized OA-LHS, as one pixel would). Skipped, with SciPy's message, when strength 2 cannot
    make ``n`` points in ``d`` dimensions (it needs n = p^2 for a prime p, and d <= p + 1)."""
    name = "scipy LatinHypercube(strength=2)"
    try:
        import scipy
        from scipy.stats import qmc
    except ImportError as exc:
        return _entry(name, "skipped", reason=f"scipy is not installed ({exc})")
    details = {"scipy": scipy.__version__, "n": n, "d": d, "budget_s": budget_s,
               "call": f"qmc.LatinHypercube(d={d}, strength=2, rng={seed}).random({n})"}
    # SciPy 1.15 renamed the keyword seed -> rng; older versions only know seed.
    key = "rng" if "rng" in inspect.signature(qmc.LatinHypercube).parameters else "seed"
    try:
        engine = qmc.LatinHypercube(d=d, strength=2, **{key: seed})
        t0 = time.perf_counter()
        x = engine.random(n)
        details["warmup_s"] = time.perf_counter() - t0
    except ValueError as exc:  # SciPy's own statement that the configuration is impossible
        return _entry(name, "skipped", details=details, reason=f"scipy: {exc}")
    except Exception as exc:  # noqa: BLE001 - reported, never fatal
        return _entry(name, "failed", details=details, reason=f"{type(exc).__name__}: {exc}"[:300])
    if x.shape != (n, d):
        return _entry(name, "failed", details=details, reason=f"random({n}) returned shape {x.shape}")
    details["dtype"] = str(x.dtype)
    times: list[float] = []
    start = time.perf_counter()
    while True:
        t0 = time.perf_counter()
        engine.random(n)
        t1 = time.perf_counter()
        times.append(t1 - t0)
        if t1 - start >= budget_s or (max_calls is not None and len(times) >= max_calls):
            break
    elapsed = time.perf_counter() - start
    calls = len(times)
    rate = calls * n * d / elapsed
    details.update(calls=calls, elapsed_s=elapsed, median_call_s=statistics.median(times),
                   min_call_s=min(times), max_call_s=max(times))
    if full_pixels:
        details["full_pixels"] = full_pixels
        details["full_workload_s"] = full_pixels * elapsed / calls
    return _entry(name, "ok", values_per_s=rate, details=details)


# ---------------------------------------------------------------------------
# Mitsuba 3

#: argv: variant, comma-separated sampler names, pixels, spp, dims, seed, largest wavefront.
#: Loads every sampler and draws once with each (the JIT compilation), prints one JSON line
#: (``ready`` with each sampler's facts), then times one draw per line of standard input
#: naming a sampler, answering one JSON line each, until standard input closes.
_MITSUBA_SERVER = r"""
import json, sys, time
import numpy as np
import mitsuba as mi
import drjit as dr
variant, names = sys.argv[1], sys.argv[2].split(",")
pixels, spp, dims, seed, max_wavefront = map(int, sys.argv[3:8])
mi.set_variant(variant)
samplers, facts = {}, {}
for name in names:
    sampler = mi.load_dict({"type": name, "sample_count": spp})
    spp_used = int(sampler.sample_count())  # ldsampler rounds up to a power-of-two square
    used_pixels = min(pixels, max_wavefront // spp_used)
    # As Mitsuba's own render loop does: all of a pixel's samples in one wavefront, so sample
    # indices 0..spp-1 of one sequence per pixel (without it every lane is sample 0 of its own sequence).
    if hasattr(sampler, "set_samples_per_wavefront"):
        sampler.set_samples_per_wavefront(spp_used)
    samplers[name] = (sampler, used_pixels * spp_used)
    facts[name] = {"sample_count": spp_used, "pixels": used_pixels, "wavefront_size": used_pixels * spp_used}

def draw(name):
    sampler, wavefront = samplers[name]
    t0 = time.perf_counter()
    sampler.seed(seed, wavefront)
    vals = [sampler.next_1d() for _ in range(dims)]
    dr.eval(*vals)
    arrs = [np.asarray(v) for v in vals]
    dt = time.perf_counter() - t0
    assert all(a.shape == (wavefront,) for a in arrs), [a.shape for a in arrs]
    return dt

for name in names:
    facts[name]["warmup_s"] = draw(name)
print(json.dumps({"status": "ready", "version": mi.__version__, "drjit": dr.__version__,
                  "variant": mi.variant(), "dims": dims, "samplers": facts}), flush=True)
for line in sys.stdin:
    print(json.dumps({"s": draw(line.strip())}), flush=True)
"""


class MitsubaPeers:
    """Mitsuba 3's samplers ``names`` (LLVM backend) in one subprocess that
    stays up between draws, so that their timed runs can alternate with
    pyoa's (a Dr.Jit/LLVM abort must not take the benchmark down, and
    Mitsuba's thread pool stays out of this process). A draw is
    ``seed(seed, wavefront_size=pixels*spp)`` then ``dims`` times
    ``next_1d()``, evaluated; every sampler draws once when the process
    starts (JIT compilation). Use as a context manager; :meth:`draw` raises
    ``RuntimeError`` when the process fails or takes longer than ``timeout``
    seconds for one answer."""

    def __init__(self, names, pixels: int, spp: int, dims: int, *, seed: int = 0,
                 timeout: float = MITSUBA_TIMEOUT_S):
        self.names, self.timeout = tuple(names), timeout
        argv = [MITSUBA_VARIANT, ",".join(self.names), pixels, spp, dims, seed, MAX_WAVEFRONT]
        self._proc = subprocess.Popen([sys.executable, "-c", _MITSUBA_SERVER, *map(str, argv)],
                                      stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                      text=True, env=mitsuba_env())
        self.facts = self._answer()  # status "ready", versions, each sampler's spp, pixels and warm-up

    def __enter__(self) -> "MitsubaPeers":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        if self._proc.poll() is None:
            self._proc.stdin.close()
            try:
                self._proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait()

    def draw(self, name: str) -> float:
        """Seconds of one timed draw of sampler ``name``."""
        self._proc.stdin.write(name + "\n")
        self._proc.stdin.flush()
        return float(self._answer()["s"])

    def _answer(self) -> dict:
        """The next JSON line of the subprocess's output (Mitsuba's logger
        leaves terminal colour codes, ESC [ ... m, on stdout)."""
        import selectors

        sel = selectors.DefaultSelector()
        sel.register(self._proc.stdout, selectors.EVENT_READ)
        deadline = time.monotonic() + self.timeout
        try:
            while True:
                left = deadline - time.monotonic()
                if left <= 0 or not sel.select(timeout=left):
                    self._proc.kill()
                    raise RuntimeError(f"Mitsuba gave no answer in {self.timeout:g} s")
                line = self._proc.stdout.readline()
                if not line:  # the process ended
                    self._proc.wait()
                    err = self._proc.stderr.read().strip().splitlines()
                    raise RuntimeError(f"Mitsuba's process ended (exit status {self._proc.returncode}): "
                                       + (err[-1] if err else "no message")[:300])
                try:
                    out = json.loads(_ANSI.sub("", line).strip())
                except json.JSONDecodeError:
                    continue
                if isinstance(out, dict):
                    return out
        finally:
            sel.close()


def mitsuba_env() -> dict:
    """The environment of a Mitsuba subprocess: ours, with DRJIT_LIBLLVM_PATH
    pointing at an LLVM that can compile Mitsuba's kernels (:func:`drjit_llvm`)."""
    import os

    env = dict(os.environ)
    llvm = drjit_llvm()
    if llvm:
        env["DRJIT_LIBLLVM_PATH"] = llvm
    return env


def mitsuba_samplers(names, pixels: int, spp: int, dims: int, *, repeats: int, seed: int = 0,
                     full_pixels: int | None = None, pyoa_run: Callable[[], float] | None = None,
                     log: Callable[[str], None] = print) -> list[dict]:
    """Mitsuba 3's samplers ``names`` (:class:`MitsubaPeers`), ``repeats``
    rounds of one timed draw each; ``values_per_s = wavefront * dims /
    median``. With ``pyoa_run`` (one timed pyoa call, returning its values
    per second), each round starts with it, and each sampler's details hold
    pyoa's rates of those rounds (``pyoa_values_per_s``) and the median of
    the per-round ratios pyoa / sampler (``pyoa_over_peer``): the machine's
    speed drifts 15-40 % over a run, and a ratio of two medians taken
    minutes apart carries that drift, a ratio within one round far less."""
    labels = {name: f"mitsuba {name}" for name in names}
    if not mitsuba_available():
        return [_entry(labels[n], "skipped", reason="mitsuba is not installed") for n in names]
    try:
        with MitsubaPeers(names, pixels, spp, dims, seed=seed) as mts:
            times = {n: [] for n in names}
            pyoa_rates = []
            for k in range(repeats):
                if pyoa_run is not None:
                    pyoa_rates.append(pyoa_run())
                for n in names:
                    times[n].append(mts.draw(n))
                log(f"peers: round {k + 1}/{repeats}: "
                    + (f"pyoa {pyoa_rates[-1] / 1e6:.0f}, " if pyoa_run is not None else "")
                    + ", ".join(f"{n} {t:.3f} s" for n, t in ((n, times[n][-1]) for n in names)))
            facts = mts.facts
    except (RuntimeError, OSError) as exc:
        return [_entry(labels[n], "failed", details={"variant": MITSUBA_VARIANT, "libllvm": drjit_llvm()},
                       reason=str(exc)[:300]) for n in names]
    out = []
    for n in names:
        d = {k: facts[k] for k in ("version", "drjit", "variant", "dims")} | facts["samplers"][n]
        med = statistics.median(times[n])
        values = d["wavefront_size"] * dims
        d.update(times_s=times[n], median_s=med, min_s=min(times[n]), max_s=max(times[n]),
                 libllvm=drjit_llvm(), requested_pixels=pixels, requested_spp=spp)
        rate = values / med
        if pyoa_run is not None:
            d["pyoa_values_per_s"] = pyoa_rates
            d["pyoa_over_peer"] = statistics.median(p * t / values for p, t in zip(pyoa_rates, times[n]))
        if full_pixels:
            d["full_pixels"] = full_pixels
            d["full_workload_s"] = full_pixels * spp * dims / rate  # the requested workload at this rate
        out.append(_entry(labels[n], "ok", values_per_s=rate, details=d))
    return out


# ---------------------------------------------------------------------------


def run_peers(spp: int, dims: int, *, pixels: int, budget_s: float, repeats: int, seed: int = 0,
              full_pixels: int | None = None, pyoa_run: Callable[[], float] | None = None,
              log: Callable[[str], None] = print) -> list[dict]:
    """SciPy's OA-LHS, then Mitsuba's samplers in rounds (interleaved with
    ``pyoa_run`` where given: :func:`mitsuba_samplers`); never raises."""
    out = []
    log(f"peers: scipy LatinHypercube(strength=2), N={spp}, d={dims}, budget {budget_s:g} s")
    out.append(scipy_lhs(spp, dims, budget_s=budget_s, seed=seed, max_calls=pixels, full_pixels=full_pixels))
    if mitsuba_available():
        log(f"peers: mitsuba {', '.join(MITSUBA_SAMPLERS)} ({MITSUBA_VARIANT}), {pixels:,} pixels x {spp} spp x "
            f"{dims} dims, warm-up + {repeats} rounds" + (", each after one pyoa call" if pyoa_run else ""))
    out += mitsuba_samplers(MITSUBA_SAMPLERS, pixels, spp, dims, repeats=repeats, seed=seed,
                            full_pixels=full_pixels, pyoa_run=pyoa_run, log=log)
    for p in out:
        if p["status"] == "ok":
            log(f"  {p['name']:<34} {p['values_per_s'] / 1e6:12.3f} M values/s")
        else:
            log(f"  {p['name']:<34} {p['status'].upper()}: {p['reason']}")
    return out
