#!/usr/bin/env python3
"""pyoa's C header samplers against OpenQMC, in one C++ process: ns per value.

What is measured
----------------
``benchmarks/openqmc/bench.cpp`` (C++17) includes pyoa's portable headers
(``pyoa.get_include()``, ``<pyoa/sampler.h>``) and OpenQMC's
(``DIR/include/oqmc/oqmc.h``; OpenQMC is Framestore's and the ASWF's
header-only sampling library, Apache-2.0, https://github.com/AcademySoftwareFoundation/openqmc)
and times both in the same process on the same image: every value of a
``--width`` x ``--height`` image (default 16 x 16 pixels: a round takes
under a second, so the two times of a per-round ratio are close together),
its samples per pixel and 10 dimensions, folded into a checksum:

- pyoa: ``pyoa_sampler_value(s, pixel, sample, dim)`` for Bose (``cmj``
  offset, 121 spp: the issue's required case), ``cmjnd`` and ``bush``
  (strength 3, 125 spp), ``faure`` (121), ``pmj02`` and ``sobol`` (128: they
  need a power of two);
- OpenQMC: ``PmjSampler``, ``SobolSampler``, ``LatticeSampler`` and their
  blue-noise variants (``PmjBnSampler``, ``SobolBnSampler``,
  ``LatticeBnSampler``) at ``--openqmc-spp`` (121): one sampler object per
  (pixel, sample), ``SamplerInterface(x, y, 0, sample, cache)``, a domain per
  K dimensions, ``base.newDomain(d)``, and ``drawSample<K>(float[K])`` with
  K = 1 (one value per call, as pyoa), 2 (a 2D point, OpenQMC's README usage)
  or 4 (its maximum and its own benchmark tool's; 10 dimensions are then
  draws of 4, 4 and 2).

Two loop shapes (see bench.cpp's header comment): ``scalar``, one value at a
time in pixel, sample, dimension loops, with the checksum pinned in a
register after every value (no vectorization possible), and ``lanes``, the
innermost loop over ``BENCH_LANES`` (16) consecutive pixels of a row for one
(sample, dimension) or (sample, domain), which the compiler may vectorize.
pyoa's orthogonal arrays (``bose``, ``cmjnd``, ``bush``) have two more, the
bulk path of ``<pyoa/fill.h>`` for renderers that take a pixel's samples
together: ``fill``, one ``pyoa_sampler_fill(s, pixel, 0, spp, 0, 10, buf,
scratch)`` per pixel (stateless), and ``prepared``, ``pyoa_fill_prepare`` once
per image and ``pyoa_fill_pixel(scratch, pixel, buf)`` per pixel; each pixel's
values are xor-ed into the checksum. Their ratios are taken against
OpenQMC's ``scalar`` draws (and ``lanes``), and the report says which of
fill.h's loops the compiler vectorized (its value loops and permutation
rounds, from the same report).
Whether it did is read from the same compilation's vectorizer report (GCC
``-fopt-info-vec-all``, Clang ``-Rpass=loop-vectorize`` and its missed and
analysis remarks) at the lane loops (marked ``// vec-probe:`` in
bench.cpp; a loop of a template that vectorized for some instantiations is
then compiled once per instantiation to say which).

Every case runs once untimed, then ``--rounds`` rounds (default 21); a round
runs every case once: the headline pairs back to back (``pyoa/bose/scalar``
then ``openqmc/pmj/scalar/2``, ``pyoa/bose/lanes`` then
``openqmc/pmj/lanes/2``), then pyoa's and OpenQMC's other cases evenly
mixed, the order rotated by one case per round. A case's time is the
thread's CPU time (``CLOCK_THREAD_CPUTIME_ID``) around one full-image call,
with the wall time (``steady_clock``) beside it; ns per value = that /
values. Reported: median, minimum and maximum ns per value over the rounds,
and ratios pyoa / OpenQMC as the median of the per-round ratios (a ratio of
medians would carry the shared machine's drift). CPU time, because on a
machine shared with other work a long call (pyoa's, ~30 ms) always absorbs
other processes' time slices while a short one (OpenQMC's, ~2 ms) often
escapes them: in one run at load average 3.4 on 2 cores the headline ratio
was 14.1x from CPU times and 20.5x from wall times (quiet: 14.0x both). The
headline: ``pyoa/bose/scalar`` / ``openqmc/pmj/scalar/2`` (a Bose ``cmj``
value against an OpenQMC PMJ value drawn as 2D points), beside the same
against ``/1`` and ``/4`` draws; and the bulk path's, ``pyoa/bose/fill`` and
``pyoa/bose/prepared`` over the same ``openqmc/pmj/scalar/2``.

Before timing, ``bench --check`` prints the bits of pixels 0, 1 and width + 3
(every sample and dimension) of each pyoa case, from ``pyoa_sampler_value``,
``pyoa_sampler_fill`` and ``pyoa_fill_pixel``; each must equal
``pyoa.sampler(..., backend="numpy").generate`` bit for bit (the benchmark
times the values pyoa documents), and every OpenQMC sampler's mean value
must be within 0.01 of 0.5. Either failing stops the run (exit status 1,
nothing written).

Build: ``g++ -std=c++17 -O2 -march=native -DNDEBUG`` (``--cxx``, ``--flags``
change them; ``-DNDEBUG`` because both libraries assert in debug builds and a
renderer ships without), ``-I pyoa.get_include() -I DIR/include``.

Output: ``benchmarks/results/openqmc.json`` (every round's ns per value,
statistics, ratios, vectorization report, compiler, flags, CPU, OpenQMC's
version and the git tree id of its ``include/``) and ``openqmc.md`` beside
it; both written atomically, then the marked sections of docs/performance.md
made from ``openqmc.json`` and ``openqmc-clang.json`` (``update_docs.after``).
Not part of the test suite (OpenQMC is not
installed in CI): run it by hand::

    git clone --depth 1 --branch v0.7.1 https://github.com/AcademySoftwareFoundation/openqmc /tmp/openqmc
    python benchmarks/bench_openqmc.py --openqmc /tmp/openqmc              # ~30 s on 2 cores
    python benchmarks/bench_openqmc.py --openqmc /tmp/openqmc --cxx clang++-15 --out benchmarks/results/openqmc-clang.json
                                                                            # ~1.5 min (18 vectorizer probes)
    python benchmarks/bench_openqmc.py --openqmc /tmp/openqmc --rounds 3 --width 32 --height 32 --out /tmp/oq.json
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import re
import shlex
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

try:
    import pyoa
except ImportError as _exc:  # pragma: no cover - environment problem
    sys.exit(f"bench_openqmc: cannot import pyoa ({_exc}); install it first: pip install -e .")

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "benchmarks"))
from common import _cpu, _git, loadavg, log, write_text  # noqa: E402
import update_docs  # noqa: E402

SOURCE = REPO / "benchmarks" / "openqmc" / "bench.cpp"
DEFAULT_OUT = REPO / "benchmarks" / "results" / "openqmc.json"
DEFAULT_FLAGS = "-std=c++17 -O2 -march=native -DNDEBUG"
SCHEMA = 1
#: OpenQMC's headers this benchmark includes (oqmc.h includes the rest).
OQMC_HEADERS = ("oqmc.h", "pmj.h", "pmjbn.h", "sobol.h", "sobolbn.h", "lattice.h", "latticebn.h")
#: The OpenQMC sampler classes, by the short name bench.cpp gives them.
OQMC_CLASSES = {"pmj": "oqmc::PmjSampler", "pmjbn": "oqmc::PmjBnSampler", "sobol": "oqmc::SobolSampler",
                "sobolbn": "oqmc::SobolBnSampler", "lattice": "oqmc::LatticeSampler",
                "latticebn": "oqmc::LatticeBnSampler"}
HEADLINE = ("pyoa/bose/scalar", "openqmc/pmj/scalar/2")
#: The bulk path's headlines (pyoa/fill.h): a pixel per pyoa_sampler_fill call, and per pyoa_fill_pixel call
#: on a plan prepared once per image, against the same OpenQMC case.
HEADLINE_FILL = ("pyoa/bose/fill", "openqmc/pmj/scalar/2")
HEADLINE_PREPARED = ("pyoa/bose/prepared", "openqmc/pmj/scalar/2")
#: pyoa's loop shapes that have an OpenQMC twin; the bulk path's ("fill", "prepared") are compared with both.
TWIN_SHAPES = ("scalar", "lanes")


class BenchError(RuntimeError):
    """A failure that ends the run with a message and exit status 1 (2 for a bad --openqmc)."""

    def __init__(self, message: str, status: int = 1):
        super().__init__(message)
        self.status = status


# ---------------------------------------------------------------------------
# OpenQMC's source and its version


def openqmc_include(root: Path) -> Path:
    """``root/include``, checked to hold OpenQMC's headers."""
    inc = root / "include"
    missing = [h for h in OQMC_HEADERS if not (inc / "oqmc" / h).is_file()]
    if missing:
        raise BenchError(
            f"--openqmc {root}: not an OpenQMC source tree (missing {', '.join('include/oqmc/' + h for h in missing)}). "
            "Get it with: git clone --depth 1 --branch v0.7.1 "
            "https://github.com/AcademySoftwareFoundation/openqmc /tmp/openqmc", status=2)
    return inc


def git_tree_id(folder: Path) -> str:
    """The git tree object id of ``folder``'s files (what ``git rev-parse <tag>:include`` prints for an
    unmodified checkout), so a copy without ``.git`` (``git archive``, a tarball) is still pinned to the
    exact upstream headers. Regular files only (mode 100644, or 100755 when executable)."""
    entries = []
    for p in folder.iterdir():
        if p.is_dir():
            entries.append((p.name + "/", b"40000 " + p.name.encode() + b"\0" + bytes.fromhex(git_tree_id(p))))
        elif p.is_file():
            data = p.read_bytes()
            blob = hashlib.sha1(b"blob %d\0" % len(data) + data).digest()
            mode = b"100755" if os.access(p, os.X_OK) else b"100644"
            entries.append((p.name, mode + b" " + p.name.encode() + b"\0" + blob))
    body = b"".join(e for _, e in sorted(entries, key=lambda t: t[0].encode()))
    return hashlib.sha1(b"tree %d\0" % len(body) + body).hexdigest()


def openqmc_version(root: Path, inc: Path) -> dict:
    """OpenQMC's release (the newest released version of its CHANGELOG.md), its git commit and tag when
    ``root`` is a git checkout, and the tree id of ``include/``."""
    info: dict = {"path": str(root.resolve()), "include_tree": git_tree_id(inc)}
    changelog = root / "CHANGELOG.md"
    if changelog.is_file():
        m = re.search(r"^## \[(\d+\.\d+\.\d+)\]", changelog.read_text(errors="replace"), re.M)
        info["changelog_version"] = m.group(1) if m else None
    for key, args in (("git_commit", ["rev-parse", "HEAD"]), ("git_describe", ["describe", "--tags", "--always"])):
        try:
            res = subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True, timeout=10)
            top = subprocess.run(["git", "-C", str(root), "rev-parse", "--show-toplevel"], capture_output=True,
                                 text=True, timeout=10)
            # only the tree's own repository (a copy inside another checkout would report that one's commit)
            ok = res.returncode == 0 and Path(top.stdout.strip()).resolve() == root.resolve()
            info[key] = res.stdout.strip() if ok else None
        except (OSError, subprocess.SubprocessError):
            info[key] = None
    return info


# ---------------------------------------------------------------------------
# building


def compiler_version(cxx: str) -> str:
    try:
        res = subprocess.run([cxx, "--version"], capture_output=True, text=True, timeout=30)
    except OSError as exc:
        raise BenchError(f"cannot run the compiler {cxx!r}: {exc}") from exc
    return res.stdout.splitlines()[0].strip() if res.stdout else "unknown"


def compiler_kind(version: str) -> str:
    """``"clang"`` or ``"gcc"``: which optimization-report flags the compiler takes."""
    return "clang" if "clang" in version.lower() else "gcc"


def vec_report_flags(kind: str, path: Path) -> list[str]:
    """Flags that make the compiler report its loop vectorizer's decisions (into ``path`` for GCC; on
    stderr for Clang, which compile_bench then writes to ``path``). They do not change the code."""
    if kind == "clang":
        return ["-Rpass=loop-vectorize", "-Rpass-missed=loop-vectorize", "-Rpass-analysis=loop-vectorize"]
    return [f"-fopt-info-vec-all={path}"]


def compile_bench(cxx: str, flags: list[str], includes: list[str], out: Path, extra: list[str],
                  remarks: Path | None = None) -> float:
    """Compile bench.cpp; with ``remarks``, stderr (Clang's optimization remarks) is written there."""
    cmd = [cxx, *flags, *(f"-I{i}" for i in includes), *extra, str(SOURCE), "-o", str(out)]
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        raise BenchError(f"compiling bench.cpp failed ({shlex.join(cmd)}):\n{res.stderr[-4000:]}")
    if remarks is not None and res.stderr:
        with open(remarks, "a") as fh:
            fh.write(res.stderr)
    return time.perf_counter() - t0


def lane_loops() -> list[dict]:
    """The lane loops of bench.cpp: the lines marked ``// vec-probe: <part>`` and the kernel each is in."""
    loops, kernel = [], None
    for no, line in enumerate(SOURCE.read_text().splitlines(), 1):
        m = re.search(r"std::uint32_t (\w+)\(", line)
        if m and "__attribute__" in line:
            kernel = m.group(1)
        m = re.search(r"// vec-probe: (\w+)", line)
        if m and kernel:
            loops.append({"line": no, "kernel": kernel, "part": m.group(1)})
    return loops


#: GCC's -fopt-info lines and Clang's -Rpass remarks about bench.cpp.
def _msg_patterns(source: str) -> tuple[re.Pattern, re.Pattern]:
    """GCC's -fopt-info lines and Clang's -Rpass remarks about file ``source`` (a base name)."""
    name = re.escape(source)
    return (re.compile(rf".*\b{name}:(\d+):\d+: (optimized|missed): (.*)"),
            re.compile(rf".*\b{name}:(\d+):\d+: remark: (.*?) \[-Rpass(-missed|-analysis)?=loop-vectorize\]"))


_GCC_MSG, _CLANG_MSG = _msg_patterns("bench.cpp")


def vec_messages(text: str, line: int, source: str = "bench.cpp") -> tuple[bool, list[str]]:
    """Whether the compiler's vectorization report ``text`` (GCC's or Clang's) says bench.cpp's loop at
    ``line`` was vectorized, and its distinct reasons where not (the messages at that line and in the
    loop's next 5 lines). No message at all at the line: the vectorizer did not consider the loop (Clang
    only takes innermost loops). ``source``: the file the line is in (bench.cpp, or pyoa's fill.h)."""
    gcc_msg, clang_msg = _msg_patterns(source)
    done, why, seen = False, [], False
    for msg in text.splitlines():
        m = gcc_msg.match(msg)
        if m:
            at, ok, what = int(m.group(1)), m.group(2) == "optimized", m.group(3).strip()
            ok = ok and "loop vectorized" in what
        else:
            m = clang_msg.match(msg)
            if not m:
                continue
            at, what = int(m.group(1)), m.group(2).strip()
            ok = what.startswith("vectorized loop")
        seen |= at == line
        if at == line and ok:
            done = True
        elif line <= at <= line + 5 and not ok and what not in why and "interleaving" not in what:
            why.append(what)
    if not seen:
        why.insert(0, "no vectorizer message at this loop: it was not considered (it contains other loops)")
    return done, why


def vectorization(report_text: str, kind: str, cxx: str, flags: list[str], includes: list[str],
                  tmp: Path) -> dict:
    """Per lane kernel: was its lane loop vectorized? From the main build's report; OpenQMC's kernels
    are templates (one source line for all instantiations), so where some instantiation vectorized, each
    one is compiled alone (-DBENCH_VEC_PROBE_OQMC, -c) to say which."""
    report = {}
    for loop in lane_loops():
        done, why = vec_messages(report_text, loop["line"])
        key = f"{loop['kernel']}:{loop['part']}"
        entry = {"line": loop["line"], "vectorized": done, "missed": why[:6]}
        if loop["kernel"] == "oqmcLanes" and done:
            per = {}
            for name, cls in OQMC_CLASSES.items():
                for k in (1, 2, 4):
                    probe = tmp / f"probe-{name}-{k}.txt"
                    compile_bench(cxx, flags, includes, tmp / "probe.o",
                                  ["-c", f"-DBENCH_VEC_PROBE_OQMC={cls}", f"-DBENCH_VEC_PROBE_K={k}",
                                   *vec_report_flags(kind, probe)], remarks=probe)
                    per[f"{name}/{k}"] = vec_messages(probe.read_text() if probe.exists() else "",
                                                      loop["line"])[0]
            entry["per_instantiation"] = per
            entry["vectorized"] = "some" if not all(per.values()) else True
        report[key] = entry
    return report


def fill_loops(fill_h: Path) -> list[dict]:
    """The loops of pyoa/fill.h that are written to vectorize: the value loops (each instance of
    PYOA_FILL_VALUES in pyoa_fill_column_tabled: 'cmj' and 'centered', cells at the sample or at the row)
    and the three walk rounds of pyoa_fill_rounds (the per-pixel permutation tables and a later block's
    rows)."""
    loops, fn = [], None
    for no, line in enumerate(fill_h.read_text().splitlines(), 1):
        m = re.match(r"PYOA_HOST_FN [\w ]+?\*?(\w+)\(", line)
        if m:
            fn = m.group(1)
        if "PYOA_FILL_VALUES(" in line and "#define" not in line:
            part = ("values centered" if "centered" in line else "values cmj") + \
                   (", cells by row" if "ca[row]" in line else ", cells by sample")
            loops.append({"line": no, "function": fn, "part": part})
        elif fn == "pyoa_fill_rounds" and "for (m = 0u; m < PYOA_FILL_LANES" in line:
            loops.append({"line": no, "function": fn, "part": "permutation walk rounds"})
    return loops


def fill_vectorization(report_text: str, fill_h: Path) -> dict:
    """Per vectorizable loop of pyoa/fill.h: did this build vectorize it (from the main build's report)?"""
    out = {}
    for loop in fill_loops(fill_h):
        done, why = vec_messages(report_text, loop["line"], source="fill.h")
        out[f"{loop['function']}:{loop['part']}"] = {"line": loop["line"], "vectorized": done, "missed": why[:6]}
    return out


# ---------------------------------------------------------------------------
# checking and running


def run_bench(exe: Path, args: list[str]) -> dict:
    res = subprocess.run([str(exe), *args], capture_output=True, text=True)
    if res.returncode != 0:
        raise BenchError(f"{exe.name} {' '.join(args)} failed with status {res.returncode}:\n{res.stderr[-4000:]}")
    return json.loads(res.stdout)


def check(exe: Path, args: argparse.Namespace) -> dict:
    """pyoa's values through the header == the Python API's, bit for bit; OpenQMC's means near 0.5."""
    out = run_bench(exe, ["--check", "--width", str(args.width), "--height", str(args.height),
                          "--seed", str(args.seed)])
    problems, checked = [], []
    for c in out["check"]:
        kw = {"spp": c["spp"], "dims": c["dims"], "seed": c["seed"], "backend": "numpy"}
        if c["offset"]:
            kw["offset"] = c["offset"]
        if c["strength"]:
            kw["strength"] = c["strength"]
        want = pyoa.sampler(c["sampler"], **kw).generate(pixels=c["pixels"]).view(np.uint32).ravel()
        n_problems = len(problems)
        # pyoa_sampler_value, and the bulk path of pyoa/fill.h (pyoa_sampler_fill; pyoa_fill_pixel on a plan)
        for key, what in (("bits", "pyoa_sampler_value"), ("fill_bits", "pyoa_sampler_fill"),
                          ("prepared_bits", "pyoa_fill_pixel")):
            got = np.asarray(c[key], dtype=np.uint32)
            if got.shape != want.shape or not np.array_equal(got, want):
                bad = int(np.argmax(got != want)) if got.shape == want.shape else -1
                problems.append(f"pyoa {c['sampler']}: the header's values ({what}) differ from "
                                f"pyoa.sampler(...).generate (first at flat index {bad} of pixels {c['pixels']})")
        checked.append(f"{c['sampler']} spp={c['spp']} pixels {c['pixels']}: {want.size} values bit-exact "
                       "(value, fill, prepared fill)" if len(problems) == n_problems else
                       f"{c['sampler']}: MISMATCH")
    for name, mean in out["means"].items():
        if name.startswith("openqmc/") and abs(mean - 0.5) > 0.01:
            problems.append(f"{name}: mean value {mean:.4f}, not within 0.01 of 0.5")
    if problems:
        raise BenchError("check failed:\n  " + "\n  ".join(problems))
    return {"pyoa_bits": checked, "means": out["means"]}


def ratio_stats(num: list[float], den: list[float]) -> dict:
    """Per-round ratios num[r] / den[r]: median, min, max; and the ratio of the two fastest rounds
    (``of_minima``: each side's least disturbed run, a check on the median when the machine is busy)."""
    r = [a / b for a, b in zip(num, den)]
    return {"median": statistics.median(r), "min": min(r), "max": max(r), "of_minima": min(num) / min(den),
            "per_round": [round(x, 4) for x in r]}


def summarize(raw: dict) -> tuple[list[dict], dict]:
    """Per case: median/min/max ns per value; ratios of every pyoa case to every OpenQMC case of the
    same shape (median of the per-round ratios)."""
    cases = []
    for c in raw["cases"]:
        ns = c["ns_per_value"]
        med = statistics.median(ns)
        cases.append({**c, "median_ns": med, "min_ns": min(ns), "max_ns": max(ns),
                      "spread": (max(ns) - min(ns)) / med, "median_ns_per_2d_point": 2 * med,
                      "m_values_per_s": 1e3 / med, "median_wall_ns": statistics.median(c["wall_ns_per_value"])})
    by = {c["name"]: c for c in cases}
    ratios = {}
    for p in cases:
        if p["library"] != "pyoa":
            continue
        shapes = (p["shape"],) if p["shape"] in TWIN_SHAPES else TWIN_SHAPES
        for q in cases:
            if q["library"] == "openqmc" and q["shape"] in shapes:
                ratios[f"{p['name']} / {q['name']}"] = ratio_stats(p["ns_per_value"], q["ns_per_value"])
    # scalar vs lanes of one sampler: the speed-up the lane loop gave (vectorized or not)
    for c in cases:
        if c["shape"] == "lanes":
            twin = by.get(c["name"].replace("/lanes", "/scalar"))
            if twin:
                c["scalar_over_lanes"] = ratio_stats(twin["ns_per_value"], c["ns_per_value"])["median"]
    return cases, ratios


def headline_wall(cases: list[dict], pair: tuple[str, str] = HEADLINE) -> dict | None:
    """A headline ratio from the wall-clock times (for comparison with the CPU-time one)."""
    by = {c["name"]: c for c in cases}
    if not all(n in by for n in pair):
        return None
    return ratio_stats(by[pair[0]]["wall_ns_per_value"], by[pair[1]]["wall_ns_per_value"])


# ---------------------------------------------------------------------------
# report


def fmt_ratio(r: dict | None) -> str:
    if not r:
        return "n/a"
    return f"{r['median']:.2f} ({r['min']:.2f}-{r['max']:.2f})"


def markdown(rep: dict) -> str:
    cfg, m, oq = rep["config"], rep["machine"], rep["openqmc"]
    cases, ratios = rep["cases"], rep["ratios"]
    head = ratios.get(" / ".join(HEADLINE))
    lines = [
        "# pyoa C headers vs OpenQMC: ns per value, one C++ process",
        "",
        f"Image {cfg['width']} x {cfg['height']} pixels, 10 dimensions, seed {cfg['seed']}; "
        f"{cfg['rounds']} rounds after one warm-up, cases interleaved (the headline pairs back to back, the order "
        "rotated each round); "
        f"lane loops of {rep['raw']['lanes']} pixels. Ratios are medians of per-round ratios "
        "(min-max in parentheses); < 1 means pyoa is cheaper.",
        "",
    ]
    if head:
        lines += [f"**Headline: a pyoa Bose `cmj` value (121 spp, one `pyoa_sampler_value` call) costs "
                  f"{head['median']:.2f}x an OpenQMC PMJ value drawn as 2D points** "
                  f"(per-round {head['min']:.2f}-{head['max']:.2f}; fastest round / fastest round "
                  f"{head['of_minima']:.2f}; from wall-clock times "
                  f"{fmt_ratio(rep.get('headline_wall'))}); against PMJ values drawn one per call "
                  f"{fmt_ratio(ratios.get('pyoa/bose/scalar / openqmc/pmj/scalar/1'))}, four per call "
                  f"{fmt_ratio(ratios.get('pyoa/bose/scalar / openqmc/pmj/scalar/4'))}.", ""]
    fill, prep = ratios.get(" / ".join(HEADLINE_FILL)), ratios.get(" / ".join(HEADLINE_PREPARED))
    if fill:
        by = {c["name"]: c for c in cases}
        lines += [f"**Bulk path (`pyoa/fill.h`): a Bose `cmj` value through `pyoa_sampler_fill`, one call per "
                  f"pixel for its 121 x 10 values, costs {fill['median']:.2f}x an OpenQMC PMJ value drawn as 2D "
                  f"points** ({by[HEADLINE_FILL[0]]['median_ns']:.2f} ns; per-round {fill['min']:.2f}-"
                  f"{fill['max']:.2f}; from wall-clock times {fmt_ratio(rep.get('headline_fill_wall'))}); against "
                  f"PMJ drawn one / four per call "
                  f"{fmt_ratio(ratios.get('pyoa/bose/fill / openqmc/pmj/scalar/1'))} / "
                  f"{fmt_ratio(ratios.get('pyoa/bose/fill / openqmc/pmj/scalar/4'))}."
                  + (f" With the pixel-independent work prepared once per image (`pyoa_fill_prepare`, then "
                     f"`pyoa_fill_pixel` per pixel): **{prep['median']:.2f}x** "
                     f"({by[HEADLINE_PREPARED[0]]['median_ns']:.2f} ns; per-round {prep['min']:.2f}-"
                     f"{prep['max']:.2f}); against PMJ drawn one / four per call "
                     f"{fmt_ratio(ratios.get('pyoa/bose/prepared / openqmc/pmj/scalar/1'))} / "
                     f"{fmt_ratio(ratios.get('pyoa/bose/prepared / openqmc/pmj/scalar/4'))}." if prep else ""),
                  ""]
    lines += ["ns = this thread's CPU time per value (CLOCK_THREAD_CPUTIME_ID: time slices other processes "
              "took are not counted; the wall-clock median is the last column but one).", "",
              "| case | spp | values per call | ns/value median | min | max | spread | ns per 2D point | "
              "M values/s | wall ns/value | scalar/lanes |",
              "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for c in sorted(cases, key=lambda c: (c["library"] != "pyoa", c["name"].split("/")[1], c["shape"],
                                          c["per_draw"])):
        sl = f"{c['scalar_over_lanes']:.2f}" if "scalar_over_lanes" in c else ""
        lines.append(f"| `{c['name']}` | {c['spp']} | {c['per_draw']} | {c['median_ns']:.2f} | {c['min_ns']:.2f} | "
                     f"{c['max_ns']:.2f} | {100 * c['spread']:.0f} % | {c['median_ns_per_2d_point']:.2f} | "
                     f"{c['m_values_per_s']:.0f} | {c['median_wall_ns']:.2f} | {sl} |")
    lines += ["", "Ratios pyoa / OpenQMC (same loop shape, the bulk path's `fill` and `prepared` against "
              "OpenQMC's scalar draws; median of per-round ratios, min-max):", "",
              "| pyoa case | / PMJ, 1 per call | / PMJ, 2D | / PMJ, 4 per call | / PMJ-BN, 2D | / Sobol, 2D | "
              "/ Lattice, 2D |",
              "|---|---:|---:|---:|---:|---:|---:|"]
    for c in cases:
        if c["library"] != "pyoa":
            continue
        sh = c["shape"] if c["shape"] in TWIN_SHAPES else "scalar"
        cols = [ratios.get(f"{c['name']} / openqmc/{s}/{sh}/{k}") for s, k in
                (("pmj", 1), ("pmj", 2), ("pmj", 4), ("pmjbn", 2), ("sobol", 2), ("lattice", 2))]
        lines.append(f"| `{c['name']}` | " + " | ".join(fmt_ratio(r) for r in cols) + " |")
    lines += ["", f"Vectorization of the lane loops ({rep['compiler']['kind']}'s vectorizer report of this build):", ""]
    for key, v in rep["vectorization"].items():
        state = {True: "vectorized", False: "not vectorized", "some": "vectorized for some samplers"}[v["vectorized"]]
        extra = ""
        if v.get("per_instantiation"):
            extra = "; per sampler/K: " + ", ".join(f"{k} {'yes' if y else 'no'}"
                                                   for k, y in v["per_instantiation"].items())
        why = (f" ({rep['compiler']['kind']}: {'; '.join(v['missed'][:3])})"
               if v["missed"] and not v["vectorized"] else "")
        lines.append(f"- `{key}` (bench.cpp line {v['line']}): {state}{extra}{why}")
    if rep.get("fill_vectorization"):
        lines += ["", f"Vectorization of the bulk path's loops (`pyoa/fill.h`, inlined into bench.cpp's "
                  f"`pyoaFill`; {rep['compiler']['kind']}'s report of this build):", ""]
        for key, v in rep["fill_vectorization"].items():
            why = f" ({'; '.join(v['missed'][:3])})" if v["missed"] and not v["vectorized"] else ""
            lines.append(f"- `{key}` (fill.h line {v['line']}): "
                         f"{'vectorized' if v['vectorized'] else 'not vectorized'}{why}")
    setup = {}
    for c in cases:
        setup.setdefault(f"{c['library']}/{c['sampler']}", (c["setup_ns"], c["table_bytes"]))
    lines += ["", "One-time setup (OpenQMC `initialiseCache`; pyoa `pyoa_sampler_make` + table fill and bind), "
              "measured once: " + "; ".join(f"{k} {ns / 1e6:.2f} ms, {b / 1024:.0f} KiB"
                                             for k, (ns, b) in setup.items()) + ".", ""]
    lines += [
        "Machine and software:",
        "",
        f"- date (UTC): {m['date_utc']}; host {m['hostname']}; total wall time {rep['total_s']:.0f} s",
        f"- CPU: {m['lscpu_model_name']} ({m['cpu']}); {m['cpu_count']} cores; load average (1/5/15 min) "
        f"{m['loadavg_start']} before, {m['loadavg_end']} after",
        f"- compiler: {rep['compiler']['version']} (`{rep['compiler']['reported']}`); flags "
        f"`{' '.join(rep['compiler']['flags'])}`; OpenQMC arch {rep['raw']['openqmc_arch']}",
        f"- OpenQMC {oq.get('changelog_version') or '?'}"
        + (f", git {oq['git_describe']} ({oq['git_commit']})" if oq.get("git_commit") else "")
        + (f", stated as {oq['ref']}" if oq.get("ref") else "")
        + f"; include/ tree {oq['include_tree']}",
        f"- pyoa {m['pyoa']} (git {m['git_commit']}{' with uncommitted changes' if m['git_dirty'] else ''}); "
        f"Python {m['python']}",
        f"- check: pyoa's header values equal pyoa.sampler(...).generate bit for bit ("
        + "; ".join(rep["check"]["pyoa_bits"]) + "); OpenQMC mean values "
        + ", ".join(f"{k.split('/')[1]} {v:.4f}" for k, v in rep["check"]["means"].items()
                    if k.startswith("openqmc/")),
        "",
    ]
    return "\n".join(lines)


def lscpu_model_name() -> str | None:
    try:
        res = subprocess.run(["lscpu"], capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    m = re.search(r"^Model name:\s*(.+)$", res.stdout, re.M)
    return m.group(1).strip() if m else None


def parse_args(argv=None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--openqmc", type=Path, required=True, help="OpenQMC's source tree (with include/oqmc/)")
    ap.add_argument("--openqmc-ref", default=None,
                    help="what the tree is, for the report when it is not a git checkout (e.g. 'v0.7.1 72617f5')")
    ap.add_argument("--rounds", type=int, default=21, help="timed rounds after the warm-up (default: 21)")
    ap.add_argument("--width", type=int, default=16, help="image width, a multiple of 16, <= 256 (default: 16)")
    ap.add_argument("--height", type=int, default=16, help="image height, <= 256 (default: 16)")
    ap.add_argument("--seed", type=int, default=0, help="pyoa's seed (default: 0); OpenQMC's frame is 0")
    ap.add_argument("--only", default=None, help="comma-separated case-name prefixes (e.g. pyoa/bose,openqmc/pmj/)")
    ap.add_argument("--cxx", default=os.environ.get("CXX", "g++"), help="C++ compiler (default: $CXX or g++)")
    ap.add_argument("--flags", default=DEFAULT_FLAGS, help=f"compiler flags (default: {DEFAULT_FLAGS!r})")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT,
                    help="JSON result; the Markdown goes beside it with suffix .md (default: %(default)s)")
    args = ap.parse_args(argv)
    if args.rounds < 1:
        ap.error("--rounds must be >= 1")
    if not (0 < args.width <= 256 and args.width % 16 == 0 and 0 < args.height <= 256):
        ap.error("need 0 < --width <= 256 (a multiple of 16) and 0 < --height <= 256 (OpenQMC encodes 8 bits of x, y)")
    return args


def main(argv=None) -> int:
    args = parse_args(argv)
    try:
        return run(args)
    except BenchError as exc:
        print(f"bench_openqmc: {exc}", file=sys.stderr)
        return exc.status


def run(args: argparse.Namespace) -> int:
    t_start = time.perf_counter()
    inc = openqmc_include(args.openqmc)
    pyoa_inc = pyoa.get_include()
    if not (Path(pyoa_inc) / "pyoa" / "sampler.h").is_file():
        raise BenchError(f"{pyoa_inc}/pyoa/sampler.h is missing: this pyoa has no C sampler API")
    if shutil.which(args.cxx) is None:
        raise BenchError(f"no C++ compiler {args.cxx!r} on PATH (--cxx)")
    flags = shlex.split(args.flags)
    includes = [pyoa_inc, str(inc)]
    cxx_version = compiler_version(args.cxx)
    kind = compiler_kind(cxx_version)
    oq = openqmc_version(args.openqmc, inc)
    oq["ref"] = args.openqmc_ref
    load_start = loadavg()
    with tempfile.TemporaryDirectory(prefix="bench_openqmc-") as tmpname:
        tmp = Path(tmpname)
        exe, info = tmp / "bench", tmp / "vec.txt"
        log(f"compiling {SOURCE.relative_to(REPO)} with {args.cxx} {args.flags} ...")
        build_s = compile_bench(args.cxx, flags, includes, exe, vec_report_flags(kind, info), remarks=info)
        log("  reading the vectorizer's report ...")
        vec = vectorization(info.read_text() if info.exists() else "", kind, args.cxx, flags, includes, tmp)
        fill_vec = fill_vectorization(info.read_text() if info.exists() else "", Path(pyoa_inc) / "pyoa" / "fill.h")
        log(f"  built in {build_s:.0f} s; checking pyoa's values against the Python API ...")
        checked = check(exe, args)
        log(f"  {len(checked['pyoa_bits'])} pyoa samplers bit-exact; timing {args.rounds} rounds ...")
        run_args = ["--rounds", str(args.rounds), "--width", str(args.width), "--height", str(args.height),
                    "--seed", str(args.seed)] + (["--only", args.only] if args.only else [])
        raw = run_bench(exe, run_args)
    load_end = loadavg()
    cases, ratios = summarize(raw)
    commit = _git("rev-parse", "HEAD")
    status = _git("status", "--porcelain", "--untracked-files=no") if commit else None
    import datetime as _dt

    meta = {"date_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "hostname": socket.gethostname(), **_cpu(), "lscpu_model_name": lscpu_model_name(),
            "cpu_count": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version(),
            "pyoa": pyoa.__version__, "git_commit": commit, "git_dirty": bool(status) if status is not None else None,
            "loadavg_start": load_start, "loadavg_end": load_end}
    rep = {
        "schema": SCHEMA,
        "benchmark": "pyoa C header samplers vs OpenQMC, ns per value, one C++ process",
        "method": "bench.cpp: each case draws every value of a width x height image (spp, 10 dims) once per "
                  "round; one warm-up, then rounds with the case order rotated by one each round; "
                  "thread CPU time (CLOCK_THREAD_CPUTIME_ID) around each full-image call, wall time beside it; "
                  "ratios are medians of per-round ratios",
        "config": {"width": args.width, "height": args.height, "rounds": args.rounds, "seed": args.seed,
                   "only": args.only, "headline": " / ".join(HEADLINE)},
        "compiler": {"cxx": args.cxx, "version": cxx_version, "kind": kind, "reported": raw["compiler"],
                     "flags": flags, "includes": includes, "build_s": build_s},
        "openqmc": oq,
        "machine": meta,
        "check": checked,
        "vectorization": vec,
        "fill_vectorization": fill_vec,
        "cases": cases,
        "ratios": ratios,
        "headline": ratios.get(" / ".join(HEADLINE)),
        "headline_wall": headline_wall(cases),
        "headline_fill": ratios.get(" / ".join(HEADLINE_FILL)),
        "headline_fill_wall": headline_wall(cases, HEADLINE_FILL),
        "headline_prepared": ratios.get(" / ".join(HEADLINE_PREPARED)),
        "raw": {k: v for k, v in raw.items() if k != "cases"},
        "total_s": time.perf_counter() - t_start,
    }
    md = markdown(rep)
    out_json, out_md = args.out, args.out.with_suffix(".md")
    out_json.parent.mkdir(parents=True, exist_ok=True)
    write_text(out_json, json.dumps(rep, indent=2) + "\n")
    write_text(out_md, md)
    print()
    print(md, end="")
    print(f"\nwrote {out_json} and {out_md} ({rep['total_s']:.0f} s)")
    for page in update_docs.after(out_json):  # the docs' sections made from this file
        print(f"wrote {page}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
