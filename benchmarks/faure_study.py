#!/usr/bin/env python3
"""The ``faure`` study: progressive Owen-scrambled Faure sequences against the
orthogonal arrays and the comparison samplers, at every sample count.

Three parts, each timed and written to ``docs/results/faure/``:

1. ``integrands``: RMSE of the estimate of known integrals over ``--trials``
   independent randomizations (pixels ``0 .. trials-1`` of seed 0, as
   :func:`pyoa.analysis.convergence`) against N. The samplers whose
   ``i``-th sample does not depend on spp (``faure`` at a fixed base,
   ``halton``, ``random`` and Owen-scrambled ``sobol``; checked here bit for
   bit) are generated once at the largest count and their running means
   give the estimate at **every** N from 16 to 4096. ``faure``'s default base
   depends on N (:func:`pyoa.catalogue.faure.default_base`), so it is generated
   once per base it takes and cut at the counts that use that base. The
   other samplers are evaluated at their valid counts only: ``bose`` (s^2),
   ``bush`` strength 3 (s^3), ``sobol``, ``pmj02``, ``zsobol`` (powers of 2),
   and ``faure`` with its base matched to the count (b = p at N = p^2 and
   N = p^3, p prime). :func:`pyoa.analysis.convergence` is not used because
   it cannot pass ``base=`` and builds one sampler per count; this script
   computes the same estimator (see ``_accumulate``).
2. ``renders``: relMSE of 64 x 64 renders of ``dof7d``, ``bounce9d``,
   ``deep`` and ``cornell`` at 64 .. 1024 spp (each sampler at its nearest
   valid count), several seeds, against references: the 128 x 128
   references of ``docs/results/`` averaged over 2 x 2 pixels (exact for the
   box filter: a 64 x 64 pixel is the union of four 128 x 128 pixels), and a
   ``pyoa reference`` of ``cornell`` at 64 x 64 rendered here once.
3. ``throughput``: ``benchmarks/bench_generate.py`` on Bose, faure and sobol
   in one process (PoCL and NumPy).

Then ``section`` writes the results into ``docs/results.md``'s marked section
``faure-study`` (``benchmarks/marked.py``; ``benchmarks/update_docs.py``
writes it again from the files in ``docs/results/faure/``, and
``benchmarks/make_results.py``, which rewrites the rest of the page, keeps it).

A full run took about 40 minutes on a 2-core AMD EPYC shared with other work
(integrands 2.5 minutes on a quiet machine, renders 31 minutes with 4 seeds,
throughput 4 minutes); ``--quick`` makes small versions of everything in about
half a minute, under ``docs/results/quick/faure/`` (git-ignored), and never
touches ``docs/results.md``. ``--rebuild`` rewrites the renders and throughput
markdown from their CSV and JSON without computing anything.

Usage::

    python benchmarks/faure_study.py                          # everything
    python benchmarks/faure_study.py --quick                  # smoke run
    python benchmarks/faure_study.py --parts renders,section  # one part, then the page
    python benchmarks/faure_study.py --parts section          # the page's section from the saved parts
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))

import marked
from common import write_csv, write_text

import pyoa
from pyoa import analysis, catalogue
from pyoa.util.atomic import atomic_path
from pyoa.catalogue.faure import BASES, default_base
from pyoa.samplers import trial_options

OUT = REPO / "docs" / "results" / "faure"
RESULTS_MD = REPO / "docs" / "results.md"
SECTION = "faure-study"  # the marked section of docs/results.md
PARTS = ("integrands", "renders", "throughput", "section")


def cpu_name() -> str:
    """The CPU as the benchmarks name it (lscpu's model name, family and model)."""
    try:
        from pyoa.util.hostcpu import host_cpu

        cpu = host_cpu()
        return f"{cpu.name} (lscpu family {cpu.family} model {cpu.model}), {os.cpu_count()} cores"
    except Exception:  # noqa: BLE001 - only a label
        return f"{os.cpu_count()}-core CPU"


class Clock:
    """Wall and CPU time of a part, with the load average around it (the machine is shared)."""

    def __init__(self):
        self.t0, self.c0, self.load0 = time.perf_counter(), time.process_time(), os.getloadavg()[0]

    def wall(self) -> float:
        return time.perf_counter() - self.t0

    def text(self) -> str:
        return (f"{self.wall():.0f} s wall, {time.process_time() - self.c0:.0f} s CPU in this process, 1-minute "
                f"load average {self.load0:.1f} at the start and {os.getloadavg()[0]:.1f} at the end")


def read_csv(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def rel(path: Path) -> str:
    return str(path.relative_to(REPO / "docs"))


def fmt_ci(lo: float, hi: float) -> str:
    return f"[{lo:.2f}, {hi:.2f}]"


# ============================================================================ integrands

SIGMA = 0.15


def _bump_integral(sigma: float = SIGMA) -> float:
    return sigma * math.sqrt(2 * math.pi) * math.erf(1 / (2 * math.sqrt(2) * sigma))


def triples(d: int, centred: bool = False, sigma: float = SIGMA) -> analysis.Integrand:
    """Mean over the C(d,3) triples j<k<l of ``h(x_j) h(x_k) h(x_l)``.

    ``h = g`` (the 1D bump of :func:`pyoa.analysis.pairwise`,
    ``g(u) = exp(-(u-1/2)^2/(2 sigma^2))``): exact integral ``I1^3``, ANOVA
    terms of order 1, 2 and 3. ``centred``: ``h = g - I1``, exact integral 0
    and a *pure* third-order interaction (every lower ANOVA term vanishes):
    a strength-2 array does nothing for it, a strength-3 array stratifies it.
    Computed through the third elementary symmetric polynomial of the
    ``h(x_k)``, ``e3 = (p1^3 - 3 p1 p2 + 2 p3) / 6`` with power sums ``p``.
    """
    if d < 3:
        raise ValueError("triples needs d >= 3")
    i1 = _bump_integral(sigma)
    inv = 1.0 / (2.0 * sigma**2)
    shift = i1 if centred else 0.0
    norm = 1.0 / math.comb(d, 3)

    def f(x):
        v = np.exp(-((x - 0.5) ** 2) * inv) - shift
        p1, p2, p3 = v.sum(axis=-1), (v * v).sum(axis=-1), (v * v * v).sum(axis=-1)
        return norm * (p1 * p1 * p1 - 3.0 * p1 * p2 + 2.0 * p3) / 6.0

    name = "triples0" if centred else "triples"
    what = "h = g - I1 (pure third-order interaction); exact 0" if centred else "h = g; exact I1^3"
    return analysis.Integrand(name, d, 0.0 if centred else i1**3, f, True, "triples",
                              f"mean over triples j<k<l of h(x_j) h(x_k) h(x_l), g the 1D bump (sigma {sigma}), "
                              + what)


def _check_triples() -> None:
    """The symmetric-polynomial form against the sum over triples, on a few points."""
    import itertools

    rng = np.random.default_rng(1)
    x = rng.random((5, 6))
    for centred in (False, True):
        f = triples(6, centred)
        i1 = _bump_integral()
        h = np.exp(-((x - 0.5) ** 2) / (2 * SIGMA**2)) - (i1 if centred else 0)
        brute = np.mean([h[:, a] * h[:, b] * h[:, c] for a, b, c in itertools.combinations(range(6), 3)], axis=0)
        assert np.allclose(f(x), brute), "triples: e3 formula disagrees with the sum over triples"


def cases(quick: bool) -> dict[int, list[analysis.Integrand]]:
    """Integrands per dimension: every integrand of one dimension is evaluated on the same point sets."""
    if quick:
        return {4: [analysis.integrand("gaussian", 4), triples(4, centred=True)]}
    return {4: [analysis.integrand("gaussian", 4), analysis.integrand("pairwise", 4), triples(4),
                triples(4, centred=True), analysis.integrand("ball", 4)],
            10: [analysis.integrand("pairwise", 10), triples(10)]}


def tag(f: analysis.Integrand) -> str:
    return f"{f.name}-{f.d}d"


#: Sampler series evaluated at every N (progressive: prefixes of one long point set).
DENSE = ("faure", "faure b=11", "halton", "random", "sobol (prefix)")
#: Series evaluated at their valid counts only.
VALID = ("faure b=p", "bose", "bush t=3", "sobol", "pmj02", "zsobol")
SERIES = DENSE + VALID
STYLE = {"faure": ("C3", "-"), "faure b=11": ("C1", "-"), "halton": ("C2", "-"), "random": ("0.5", "-"),
         "sobol (prefix)": ("C0", ":"), "faure b=p": ("C3", "D"), "bose": ("k", "s"), "bush t=3": ("C5", "^"),
         "sobol": ("C0", "o"), "pmj02": ("C4", "v"), "zsobol": ("C6", "x")}


class Acc:
    """Sums of squared errors (and their squares) per integrand and count."""

    def __init__(self, integrands, n: int):
        self.e2 = {tag(f): np.zeros(n) for f in integrands}
        self.e4 = {tag(f): np.zeros(n) for f in integrands}
        self.trials = 0


def _accumulate(smp, integrands, trials: int, prefix: bool, lo: int = 1, chunk_bytes: int = 96 << 20) -> Acc:
    """The estimator of :func:`pyoa.analysis.convergence`: pixel p's point
    set (p = 0 .. trials-1) gives one estimate, the mean of f over its
    samples. With ``prefix``, the running mean of its first n samples is the
    estimate at n, for every n in ``[lo, spp]`` (valid only for a sampler
    whose i-th sample does not depend on spp); else only n = spp."""
    spp, d = smp.spp, smp.dims
    counts = np.arange(lo, spp + 1) if prefix else np.array([spp])
    acc = Acc(integrands, len(counts))
    step = max(1, chunk_bytes // (4 * spp * d))
    for p0 in range(0, trials, step):
        p1 = min(trials, p0 + step)
        x = smp.generate(pixels=range(p0, p1))
        for f in integrands:
            v = f(x)
            if prefix:
                est = (np.cumsum(v, axis=1) / np.arange(1, spp + 1))[:, lo - 1:]
            else:
                est = v.mean(axis=1, keepdims=True)
            e2 = (est - f.exact) ** 2
            acc.e2[tag(f)] += e2.sum(axis=0)
            acc.e4[tag(f)] += (e2 * e2).sum(axis=0)
    acc.trials = trials
    acc.counts = counts
    return acc


def _sampler(name: str, spp: int, d: int, base=None, strength=None):
    opts = {}
    if base is not None:
        opts["base"] = base
    if strength is not None:
        opts["strength"] = strength
    return pyoa.sampler(name, spp=spp, dims=d, seed=0, **trial_options(name, opts))


def check_prefixes(d: int, nmax: int) -> list[str]:
    """The prefix evaluation's premise, checked bit for bit: the first n
    samples at spp = nmax are the samples at spp = n."""
    notes = []
    for name, base, counts in [("faure", 11, (16, 100, 121, 1000, 1331)), ("faure", 5, (16, 125, 1000)),
                               ("halton", None, (16, 1000)), ("random", None, (16, 1000)),
                               ("sobol", None, (16, 128, 1024))]:
        top = 1 << (nmax.bit_length() - 1) if name == "sobol" else nmax
        counts = [n for n in counts if n <= top]
        big = _sampler(name, top, d, base).generate(pixels=range(4))
        for n in counts:
            same = np.array_equal(_sampler(name, n, d, base).generate(pixels=range(4)), big[:, :n])
            if not same:
                raise AssertionError(f"{name} base={base}: spp={n} is not the prefix of spp={nmax}")
        notes.append(f"{name}{'' if base is None else f' b={base}'}: n = {', '.join(map(str, counts))}")
    return notes


def _default_groups(d: int, lo: int, hi: int) -> list[tuple[int, int, int]]:
    """(base, first n, last n): runs of counts in [lo, hi] with the same default base."""
    groups: list[list[int]] = []
    for n in range(lo, hi + 1):
        b = default_base(n, d)
        if groups and groups[-1][0] == b:
            groups[-1][2] = n
        else:
            groups.append([b, n, n])
    for b, a, c in groups:  # the sampler's own choice, not only the documented rule
        for n in (a, c):
            got = _sampler("faure", n, d).base
            if got != b:
                raise AssertionError(f"faure default base at spp={n}, dims={d}: {got}, default_base says {b}")
    return [tuple(g) for g in groups]


def valid_counts(name: str, d: int, lo: int, hi: int, strength=None) -> list[int]:
    return [c.spp for c in catalogue.valid_spp(name, dims=d, strength=strength) if lo <= c.spp <= hi]


class Store:
    """Per (integrand tag, series): MSE, standard error of log MSE and base, each a dict count -> value."""

    def __init__(self, lo: int, hi: int, trials: int):
        self.lo, self.hi, self.trials = lo, hi, trials
        self.mse, self.se, self.base_of, self.sigma, self.timing = {}, {}, {}, {}, {}

    def record(self, series: str, integrands, acc: Acc, base) -> None:
        for k, n in enumerate(acc.counts):
            for f in integrands:
                key = (tag(f), series)
                m = acc.e2[tag(f)][k] / acc.trials
                # standard error of log MSE (delta method): sd(e^2) / (sqrt(T) mean(e^2))
                var_e2 = max(acc.e4[tag(f)][k] / acc.trials - m * m, 0.0)
                s = math.sqrt(var_e2 / acc.trials) / m if m > 0 else math.nan
                self.mse.setdefault(key, {})[int(n)] = m
                self.se.setdefault(key, {})[int(n)] = s
                self.base_of.setdefault(key, {})[int(n)] = base

    def prefix(self, series: str, integrands, name: str, spp: int, d: int, base=None, lo=None) -> None:
        """A dense series: every count from ``lo`` to ``spp`` from one point set per pixel."""
        acc = _accumulate(_sampler(name, spp, d, base), integrands, self.trials, True, lo=lo or self.lo)
        self.record(series, integrands, acc, "" if base is None else base)

    def at_counts(self, series: str, integrands, name: str, counts, d: int, strength=None, bases=None) -> None:
        """A series at the given counts only (one sampler per count)."""
        for n in counts:
            b = bases[n] if bases else None
            acc = _accumulate(_sampler(name, n, d, b, strength), integrands, self.trials, False)
            self.record(series, integrands, acc, "" if b is None else b)

    def timed(self, d: int, series: str, t0: float) -> None:
        self.timing[(d, series)] = time.perf_counter() - t0
        print(f"   d={d} {series}: {self.timing[(d, series)]:.1f} s", flush=True)


def run_dimension(st: Store, d: int, integrands) -> None:
    """Every series of the study on the integrands of dimension ``d``."""
    lo, hi = st.lo, st.hi
    primes = [p for p in BASES if p * p <= hi]
    t = time.perf_counter()
    for b, a, c in _default_groups(d, lo, hi):
        st.prefix("faure", integrands, "faure", c, d, base=b, lo=a)
    st.timed(d, "faure", t)
    for series, name, base in [("faure b=11", "faure", 11), ("halton", "halton", None),
                               ("random", "random", None)]:
        t = time.perf_counter()
        st.prefix(series, integrands, name, hi, d, base=base)
        st.timed(d, series, t)
    # sd(f) for the efficiency plot, from random points
    x = _sampler("random", hi, d).generate(pixels=range(min(st.trials, 256)))
    for f in integrands:
        st.sigma[tag(f)] = float(f(x).std())
    t = time.perf_counter()
    st.prefix("sobol (prefix)", integrands, "sobol", 1 << (hi.bit_length() - 1), d)
    st.timed(d, "sobol (prefix)", t)
    t = time.perf_counter()
    root = {p**k: p for p in primes for k in (2, 3) if lo <= p**k <= hi}
    st.at_counts("faure b=p", integrands, "faure", sorted(root), d, bases=root)
    st.timed(d, "faure b=p", t)
    for series, name, strength in [("bose", "bose", None), ("bush t=3", "bush", 3), ("sobol", "sobol", None),
                                   ("pmj02", "pmj02", None), ("zsobol", "zsobol", None)]:
        t = time.perf_counter()
        st.at_counts(series, integrands, name, valid_counts(name, d, lo, hi, strength), d, strength=strength)
        st.timed(d, series, t)


def part_integrands(args) -> tuple[str, float]:
    clock = Clock()
    lo, hi, trials = 16, args.nmax, args.trials
    _check_triples()
    prefix_notes = check_prefixes(4, min(hi, 1331))
    st = Store(lo, hi, trials)
    for d, integrands in cases(args.quick).items():
        run_dimension(st, d, integrands)
    mse, se, base_of, sigma, timing = st.mse, st.se, st.base_of, st.sigma, st.timing
    primes = [p for p in BASES if p * p <= hi]
    rows = []

    # ---- tables
    integrand_list = [f for fs in cases(args.quick).values() for f in fs]
    fit_grid = sorted({round(lo * 2 ** (k / 64)) for k in range(64 * int(math.log2(hi / lo)) + 1)})
    csv_grid = set(range(lo, 65)) | {round(lo * 2 ** (k / 32)) for k in range(32 * int(math.log2(hi / lo)) + 1)}
    slopes = {}
    for f in integrand_list:
        for s in SERIES:
            m = mse.get((tag(f), s))
            if not m:
                continue
            ns = [n for n in (fit_grid if s in DENSE else sorted(m)) if n in m and m[n] > 0]
            slopes[(tag(f), s)] = (float(np.polyfit(np.log(ns), np.log([m[n] for n in ns]), 1)[0])
                                   if len(ns) > 1 else math.nan)
    for f in integrand_list:
        for s in SERIES:
            m = mse.get((tag(f), s), {})
            keep = set(m) if s not in DENSE else (set(csv_grid) | SPECIAL | {p**k for p in primes for k in (2, 3)}
                                                  | set(mse.get((tag(f), "bose"), {})) | set(range(121, hi + 1, 121))
                                                  | set(ON_121) | set(NETS)) & set(m)
            for n in sorted(keep):
                rows.append({"integrand": f.name, "d": f.d, "series": s, "spp": n, "base": base_of[(tag(f), s)][n],
                             "rmse": f"{math.sqrt(m[n]):.5e}", "se_log_mse": f"{se[(tag(f), s)][n]:.3f}"})
    write_csv(OUT / "convergence.csv", rows)
    write_csv(OUT / "slopes.csv", [{"integrand": f.name, "d": f.d, "series": s,
                                    "mse_slope": f"{slopes[(tag(f), s)]:.4f}"}
                                   for f in integrand_list for s in SERIES if (tag(f), s) in slopes])
    figures = []
    for f in integrand_list:
        figures.append(plot_convergence(f, mse, sigma[tag(f)], slopes, trials))

    md = integrands_markdown(args, integrand_list, mse, se, slopes, base_of, figures, prefix_notes, fit_grid,
                             timing, clock.text())
    write_text(OUT / "integrands.md", md)
    return md, clock.wall()


#: Counts that are nets of faure's default base at d = 4 (b = 5) or d = 10 (b = 11).
NETS = (125, 625, 3125, 121, 1331)
#: faure b=11 counts on and between multiples of 121 that the tables quote.
ON_121 = (900, 968, 1000, 1030, 1089, 1200, 1331)
#: Counts the tables quote (kept in the CSV for the dense series too).
SPECIAL = {100, 128, 200, 256, 500, 512, 1000, 1024, 2000, 2048, 3000, 4096}


def ratio_ci(mse, se, a, b, n_a, n_b):
    """RMSE ratio a/b with a 95 % interval (delta method on log MSE, independent estimates)."""
    ma, mb = mse[a][n_a], mse[b][n_b]
    s = math.sqrt(se[a][n_a] ** 2 + se[b][n_b] ** 2)
    r = math.sqrt(ma / mb)
    return r, r * math.exp(-1.96 * s / 2), r * math.exp(1.96 * s / 2)


def plot_convergence(f, mse, sigma_f, slopes, trials) -> Path:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 8), dpi=100)
    FigureCanvasAgg(fig)
    top, bottom = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [1, 1.3]})
    for s in SERIES:
        m = mse.get((tag(f), s))
        if not m:
            continue
        n = np.array(sorted(m), dtype=float)
        r = np.sqrt([m[int(k)] for k in n])
        color, style = STYLE[s]
        slope = slopes.get((tag(f), s), math.nan)
        label = f"{s} ({slope:.2f})"
        if s in DENSE:
            kw = {"lw": 0.8, "color": color, "ls": style}
        else:
            kw = {"ls": "none", "marker": style, "ms": 4, "color": color, "mfc": "none"}
        top.loglog(n, r, label=label, **kw)
        bottom.loglog(n, r * np.sqrt(n) / sigma_f, **kw)
    top.set_ylabel("RMSE")
    top.set_title(f"{f.name}, d={f.d}, {trials} trials (legend: MSE slope)")
    top.legend(fontsize="x-small", ncol=2)
    bottom.axhline(1.0, color="0.5", lw=0.5)
    bottom.set_ylabel("RMSE x sqrt(N) / sd(f)   (random = 1)")
    bottom.set_xlabel("samples per pixel N")
    for ax in (top, bottom):
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
    fig.tight_layout()
    out = OUT / f"convergence-{tag(f)}.png"
    with atomic_path(out) as tmp, open(tmp, "wb") as fh:
        fig.savefig(fh, format="png")
    return out


def integrands_markdown(args, integrand_list, mse, se, slopes, base_of, figures, prefix_notes, fit_grid, timing,
                        took) -> str:
    lo, hi, trials = 16, args.nmax, args.trials
    L = []
    add = L.append
    add("### Analytic integrands: error at every sample count\n")
    add(f"RMSE of the estimate over {trials} independent randomizations (pixels 0 .. {trials - 1} of seed 0, one "
        "point set each, as `pyoa.analysis.convergence`) against N. **Every N from "
        f"{lo} to {hi}** ({hi - lo + 1} counts) for the samplers whose i-th sample does not depend on spp: "
        "they are generated once at the largest count and the running mean of the first N samples is the "
        "estimate at N (checked bit for bit against a sampler built at N: "
        + "; ".join(prefix_notes) + "). These are `faure` at its default base (which depends on N: "
        "generated once per base it takes, cut where the base changes), `faure` at base 11, `halton`, `random` "
        "and `sobol (prefix)`, the first N points of Owen-scrambled Sobol at any N (not a catalogue count: what "
        "a progressive Sobol render would use). The others at their valid counts in "
        f"[{lo}, {hi}] only: `bose` (s^2, s a prime power), `bush` strength 3 (s^3), `sobol`, `pmj02` and "
        "`zsobol` (powers of 2), and `faure b=p`, faure with its base matched to the count (b = p at "
        "N = p^2 and N = p^3, p prime), the like-for-like comparison with Bose (and Bush).\n")
    groups = {d: _default_groups(d, lo, hi) for d in sorted({f.d for f in integrand_list})}
    add("Default base (`pyoa.catalogue.faure.default_base`): " + "; ".join(
        f"d={d}: " + ", ".join(f"b={b} for N={a}..{c}" for b, a, c in g) for d, g in groups.items())
        + ". At d=4 the default is the smallest prime >= d once b^2 <= N (every dimension in one "
        "(0, b)-sequence), so the default-base curve is base 5 (a (0,4,5)-net at 625, every 4D box of "
        "volume 5^-4 holding one point), not the b = floor(sqrt N) of Bose.\n")
    add("Fitted slopes are least-squares slopes of log MSE against log N (the scale of the Convergence "
        "section above: random -1, steeper is better); dense series are fitted on counts every 1/64 octave "
        f"from {lo} to {hi} ({len(fit_grid)} counts, so that 16..256 does not outweigh the rest), the others "
        "on all their valid counts. Integrands: `gaussian` (product of d bumps), `pairwise`, `ball` "
        "(discontinuous) from `pyoa.analysis`; `triples` (mean over triples of products of three bumps, "
        "exact I1^3) and `triples0` (the same with centred bumps g - I1: a pure third-order interaction, "
        "exact 0) are defined in this script.\n")
    names = [s for s in SERIES if any((tag(f), s) in slopes for f in integrand_list)]
    add("#### Fitted MSE slopes\n")
    add("| integrand | d | " + " | ".join(names) + " |")
    add("|---|---:|" + "---:|" * len(names))
    for f in integrand_list:
        vals = [slopes.get((tag(f), s), math.nan) for s in names]
        best = min(v for v in vals if math.isfinite(v))
        add(f"| {f.name} | {f.d} | " + " | ".join(("**{:.2f}**" if v == best else "{:.2f}").format(v)
                                                 for v in vals) + " |")
    add("")

    # faure vs bose at b^2
    sq = sorted(n for n in mse.get((tag(integrand_list[0]), "faure b=p"), {}) if round(n ** 0.5) ** 2 == n)
    shown = [n for n in sq if n in (25, 49, 121, 169, 361, 961, 1681, 3721)] or sq
    add("#### faure against Bose at N = b^2\n")
    add("RMSE ratio faure / bose at the same N = p^2 (below 1: faure better), with a 95 % interval "
        f"(delta method on log MSE, {trials} trials each). `b=p`: faure with base p = sqrt(N), the same "
        "strength-2 array size as Bose's s = p; `default`: the default base at that N (the faure "
        "row's base); `b=11`: base 11 at every N. The geometric mean is over every prime p with "
        f"p^2 in [{lo}, {hi}] ({len(sq)} counts).\n")
    add("| integrand | d | " + " | ".join(f"N={n}" for n in shown) + " | geo. mean, b=p | default | b=11 |")
    add("|---|---:|" + "---:|" * (len(shown) + 3))
    summary = {}
    for f in integrand_list:
        t = tag(f)
        if (t, "bose") not in mse:
            continue
        cells = []
        for n in shown:
            r, a, b = ratio_ci(mse, se, (t, "faure b=p"), (t, "bose"), n, n)
            cells.append(f"{r:.2f} {fmt_ci(a, b)}")
        gm = {k: math.exp(np.mean([math.log(ratio_ci(mse, se, (t, k), (t, "bose"), n, n)[0]) for n in sq]))
              for k in ("faure b=p", "faure", "faure b=11")}
        summary[t] = gm
        add(f"| {f.name} | {f.d} | " + " | ".join(cells) + f" | {gm['faure b=p']:.2f} | {gm['faure']:.2f} | "
            f"{gm['faure b=11']:.2f} |")
    add("")

    # faure vs bush at p^3
    cubes = sorted(n for n in mse.get((tag(integrand_list[0]), "faure b=p"), {}) if round(n ** (1 / 3)) ** 3 == n
                   and n in mse.get((tag(integrand_list[0]), "bush t=3"), {}))
    if cubes:
        add("#### faure against Bush (strength 3) at N = p^3\n")
        add("RMSE ratio faure (base p) / bush at the same N = p^3, 95 % interval.\n")
        add("| integrand | d | " + " | ".join(f"N={n}" for n in cubes) + " |")
        add("|---|---:|" + "---:|" * len(cubes))
        for f in integrand_list:
            t = tag(f)
            cells = []
            for n in cubes:
                r, a, b = ratio_ci(mse, se, (t, "faure b=p"), (t, "bush t=3"), n, n)
                cells.append(f"{r:.2f} {fmt_ci(a, b)}")
            add(f"| {f.name} | {f.d} | " + " | ".join(cells) + " |")
        add("")

    # faure vs sobol
    pairs = [(128, 128), (1024, 1024), (1000, 1024), (4096, 4096)]
    pairs = [(a, b) for a, b in pairs if a <= hi and b <= hi]
    add("#### faure against Sobol (powers of 2)\n")
    add("RMSE ratio faure(N) / sobol(M), 95 % interval (faure at its default base and at base 11; "
        "`1000 / 1024` compares 1000 faure samples with 1024 Sobol ones). Absolute RMSE in the CSV.\n")
    add("| integrand | d | " + " | ".join(f"{a} / {b} default | {a} / {b} b=11" for a, b in pairs) + " |")
    add("|---|---:|" + "---:|" * (2 * len(pairs)))
    for f in integrand_list:
        t = tag(f)
        cells = []
        for a, b in pairs:
            for k in ("faure", "faure b=11"):
                r, x, y = ratio_ci(mse, se, (t, k), (t, "sobol"), a, b)
                cells.append(f"{r:.2f} {fmt_ci(x, y)}")
        add(f"| {f.name} | {f.d} | " + " | ".join(cells) + " |")
    add("")

    # each at its own nets
    add("#### faure and Sobol, each at its own nets\n")
    add("faure's strength is at N = b^m, Sobol's at N = 2^m, so the comparisons at 128 and 1024 put one of them "
        "off its nets. Here faure (default base) at its nets against Sobol's RMSE at the same N, interpolated "
        "log-linearly between Sobol's powers of two around it. RMSE x 1e4; ratio below 1: faure better.\n")
    add("| integrand | d | N = b^m (base) | faure | sobol below | sobol above | sobol interpolated | ratio |")
    add("|---|---:|---|---:|---:|---:|---:|---:|")
    for f in integrand_list:
        t = tag(f)
        fa, so = mse.get((t, "faure"), {}), mse.get((t, "sobol"), {})
        for n in sorted(n for n in NETS if lo <= n <= hi and n in fa and (t, "faure") in base_of):
            b = base_of[(t, "faure")][n]
            m = round(math.log(n, b))
            if b**m != n or m < 2:
                continue
            a_, c_ = 1 << (n.bit_length() - 1), 1 << n.bit_length()
            if a_ not in so or c_ not in so:
                continue
            w = math.log(n / a_) / math.log(c_ / a_)
            interp = math.exp((1 - w) * math.log(so[a_]) + w * math.log(so[c_])) ** 0.5
            add(f"| {f.name} | {f.d} | {n} = {b}^{m} | {1e4 * math.sqrt(fa[n]):.3g} | "
                f"{1e4 * math.sqrt(so[a_]):.3g} ({a_}) | {1e4 * math.sqrt(so[c_]):.3g} ({c_}) | {1e4 * interp:.3g} | "
                f"{math.sqrt(fa[n]) / interp:.2f} |")
    add("")

    # a fixed base between its multiples of b^2
    on = [n for n in ON_121 if n <= hi]
    bose_near = [n for n in (841, 961, 1024, 1369) if n <= hi]
    add("#### A fixed base: multiples of b^2\n")
    add("A progressive render keeps its base (here 11, the default at 121 spp and 8 to 11 dimensions). Every "
        "prefix of lam x 121 samples holds lam points in each 11 x 11 cell of every pair, so the error dips at "
        "multiples of 121 and rises between them (the saw-tooth in the figures). RMSE x 1e4 of faure b=11 at "
        "counts on and between multiples of 121 (968 = 8 x 121, 1089 = 9 x 121, 1331 = 11^3), and Bose's at "
        "its counts nearby.\n")
    add("| integrand | d | " + " | ".join(f"b=11 N={n}" for n in on) + " | "
        + " | ".join(f"bose {n}" for n in bose_near) + " |")
    add("|---|---:|" + "---:|" * (len(on) + len(bose_near)))
    for f in integrand_list:
        t = tag(f)
        fb, bo = mse.get((t, "faure b=11"), {}), mse.get((t, "bose"), {})
        add(f"| {f.name} | {f.d} | " + " | ".join(f"{1e4 * math.sqrt(fb[n]):.3g}" if n in fb else "-" for n in on)
            + " | " + " | ".join(f"{1e4 * math.sqrt(bo[n]):.3g}" if n in bo else "-" for n in bose_near) + " |")
    add("")

    # between squares
    between = [n for n in (100, 200, 500, 1000, 2000, 3000) if n <= hi]
    add("#### Between Bose's counts\n")
    add("At counts where Bose has no array, faure (default base) against what a Bose user can run: the "
        "nearest valid count below and above (fewer or more samples), and the progressive alternatives at the "
        "same N. RMSE x 1e4 (lower is better); base in brackets.\n")
    add("| integrand | d | N | faure | faure b=11 | bose below | bose above | halton | sobol (prefix) | random |")
    add("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for f in integrand_list:
        t = tag(f)
        bose = sorted(mse.get((t, "bose"), {}))
        for n in between:
            below = max((c for c in bose if c <= n), default=None)
            above = min((c for c in bose if c >= n), default=None)

            def r(series, at, t=t):
                m = mse.get((t, series), {})
                return f"{1e4 * math.sqrt(m[at]):.3g}" if at in m else "-"
            add(f"| {f.name} | {f.d} | {n} | {r('faure', n)} (b={base_of[(t, 'faure')][n]}) | "
                f"{r('faure b=11', n)} | {r('bose', below)} ({below}) | {r('bose', above)} ({above}) | "
                f"{r('halton', n)} | {r('sobol (prefix)', n)} | {r('random', n)} |")
    add("")
    for f, fig in zip(integrand_list, figures):
        add(f"![convergence {tag(f)}]({rel(fig)})\n")
    t = ", ".join(f"d={d} {s} {v:.0f} s" for (d, s), v in timing.items() if v >= 1)
    add(f"Data: `{rel(OUT / 'convergence.csv')}` (RMSE and the standard error of log MSE, {trials} trials; for "
        f"the dense series every N from {lo} to 64, then every 1/32 octave, and every count quoted or valid for "
        f"bose; all counts for the others; the figures show every N) and `{rel(OUT / 'slopes.csv')}`. "
        f"This part took {took} on {cpu_name()} (per series: {t}).\n")
    return "\n".join(L)


# ============================================================================ renders

SCENES = ("dof7d", "bounce9d", "deep", "cornell")
TARGETS = (64, 100, 128, 200, 256, 500, 1024)
RENDER_SAMPLERS = ("faure", "bose", "sobol", "halton", "random", "pmj02", "zsobol")


def load_reference(scene: str, size: int, quick: bool) -> tuple[np.ndarray, str, float, int]:
    """The reference at size x size, how it was made, the seconds spent making it, and the number of
    independent sobol-256 estimates averaged in each of its pixels (its noise is about relMSE(sobol, 256)
    divided by that)."""
    from pyoa.render.image import read_image

    ref = REPO / "docs" / "results" / f"{scene}-reference.exr"
    if ref.exists():
        img = read_image(ref).astype(np.float64)
        h, w = img.shape[:2]
        if h % size == 0 and w % size == 0 and h // size == w // size:
            k = h // size
            how = (f"`{rel(ref)}` ({w} x {h}, 4096 spp of sobol in 16 passes of 256, by make_results.py) "
                   f"averaged over {k} x {k} pixels")
            return img.reshape(size, k, size, k, 3).mean(axis=(1, 3)), how, 0.0, 16 * k * k
    from pyoa import commands

    spp = 2048 if quick else 32768
    out = OUT / f"{scene}-reference-{size}.exr"
    made = 0.0
    if not out.exists():
        t = time.perf_counter()
        commands.main(["reference", scene, "--size", str(size), str(size), "--spp", str(spp), "--pass-spp", "256",
                  "--out", str(out), "-q"])
        made = time.perf_counter() - t
        print(f"   reference {scene} {size}x{size} {spp} spp: {made:.0f} s", flush=True)
    how = f"`{rel(out)}` (`pyoa reference {scene} --size {size} {size} --spp {spp} --pass-spp 256`: sobol passes)"
    return read_image(out).astype(np.float64), how, made, spp // 256


def _faure_base(scene, spp: int) -> int:
    from pyoa.render.render import plan

    return plan(scene, sampler="faure", spp=spp, width=8, height=8).sampler.base


def rebuild_renders(args) -> str:
    """renders.md again from renders.csv (no rendering; the references are read, not made)."""
    rows = read_csv(OUT / "renders.csv")
    size = args.size
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    targets = sorted({int(t) for r in rows for t in r["targets"].split()})
    refs = {}
    for name in scenes:
        _, how, made, div = load_reference(name, size, args.quick)
        refs[name] = (how, made, div)
    timing = {name: sum(float(r["seconds"]) for r in rows if r["scene"] == name) for name in scenes}
    args.seeds = len({r["seed"] for r in rows})
    took = (f"{sum(timing.values()):.0f} s of rendering (the sum of the renders' own times in the CSV; this page "
            "was rebuilt from it with --rebuild)")
    md = renders_markdown(args, rows, refs, timing, took, targets)
    write_text(OUT / "renders.md", md)
    return md


def part_renders(args) -> tuple[str, float]:
    from pyoa.render.image import rel_mse
    from pyoa.render.render import render
    from pyoa.render.scene import load

    clock = Clock()
    size, seeds = args.size, args.seeds
    scenes = ("dof7d", "cornell") if args.quick else SCENES
    targets = (64, 128, 256) if args.quick else TARGETS
    redo = RENDER_SAMPLERS if args.samplers is None else args.samplers
    # --samplers re-renders only those samplers and keeps every other sampler's saved rows: their bits did not
    # change, and relMSE does not drift with the machine's speed (only the seconds column does).
    kept = [] if args.samplers is None else [r for r in read_csv(OUT / "renders.csv") if r["sampler"] not in redo]
    if kept and {int(r["seed"]) for r in kept} != set(range(seeds)):
        raise SystemExit(f"--samplers: the saved renders.csv has seeds {sorted({int(r['seed']) for r in kept})}, "
                         f"this run {list(range(seeds))}; pass the same --seeds (and --size) or re-render all")
    rows, refs, timing = [], {}, {}
    for name in scenes:
        ts = time.perf_counter()
        scene = load(name)
        ref, how, made, div = load_reference(name, size, args.quick)
        refs[name] = (how, made, div)
        for smp in redo:
            counts = {}
            for t in targets:
                counts.setdefault(catalogue.nearest_spp(smp, t), []).append(t)
            for spp, ts_ in sorted(counts.items()):
                base = _faure_base(scene, spp) if smp == "faure" else ""
                for seed in range(seeds):
                    t = time.perf_counter()
                    res = render(scene, sampler=smp, spp=spp, seed=seed, width=size, height=size)
                    dt = time.perf_counter() - t
                    rows.append({"scene": name, "sampler": smp, "targets": " ".join(map(str, ts_)), "spp": spp,
                                 "base": base, "seed": seed, "relmse": f"{rel_mse(res.image, ref):.6e}",
                                 "seconds": f"{dt:.3f}"})
        timing[name] = time.perf_counter() - ts
        print(f"   {name}: {timing[name]:.0f} s", flush=True)
    took = clock.text()
    if kept:
        took += f" for {', '.join(redo)} (the other samplers' rows were kept from the previous run)"
        order = {s: k for k, s in enumerate(RENDER_SAMPLERS)}
        rows = sorted(kept + rows, key=lambda r: (scenes.index(r["scene"]), order[r["sampler"]], int(r["spp"]),
                                                  int(r["seed"])))
    write_csv(OUT / "renders.csv", rows)
    md = renders_markdown(args, rows, refs, timing, took, targets)
    write_text(OUT / "renders.md", md)
    return md, clock.wall()


def _summary(rows):
    """(scene, sampler, spp) -> (mean, lo, hi, n, base, targets) with a Student-t 95 % interval of the mean."""
    from scipy import stats

    out = {}
    keys = sorted({(r["scene"], r["sampler"], int(r["spp"])) for r in rows})
    for key in keys:
        sel = [r for r in rows if (r["scene"], r["sampler"], int(r["spp"])) == key]
        v = np.array([float(r["relmse"]) for r in sel])
        m = v.mean()
        h = stats.t.ppf(0.975, len(v) - 1) * v.std(ddof=1) / math.sqrt(len(v)) if len(v) > 1 else math.nan
        out[key] = (m, m - h, m + h, len(v), sel[0]["base"], sel[0]["targets"])
    return out


def _used(rows, targets) -> dict:
    """sampler -> the count it rendered for each target, in target order."""
    out = {}
    for s in RENDER_SAMPLERS:
        sel = [r for r in rows if r["sampler"] == s]
        if sel:
            out[s] = [next(int(r["spp"]) for r in sel if str(t) in r["targets"].split()) for t in targets]
    return out


def renders_markdown(args, rows, refs, timing, took, targets) -> str:
    size, seeds = args.size, args.seeds
    summ = _summary(rows)
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    L = []
    add = L.append
    add("### Renders\n")
    add(f"relMSE (mean over pixels and channels of (image - ref)^2 / (ref^2 + 0.01)) of {size} x {size} renders "
        f"(`pyoa.render.render(..., width={size}, height={size})`, box filter), seeds 0 .. {seeds - 1}: the mean "
        f"over seeds, ± the half-width of its 95 % Student-t interval ({seeds - 1} degrees of freedom) relative "
        "to the mean. Each "
        "sampler renders at its count nearest the target (`catalogue.nearest_spp`, ties towards fewer samples; "
        f"`@N` in a cell) for the targets {', '.join(map(str, targets))}: "
        + "; ".join(f"{s} {', '.join(map(str, used))}" for s, used in _used(rows, targets).items())
        + " (a count serving two targets is one set of renders). faure uses its default base, which depends on "
        "N and on the scene's dimensions (`b=` in its cells).\n")
    add("References: " + "; ".join(f"`{s}`: {how}" for s, (how, _, _) in refs.items()) + ". A reference's own "
        "noise adds to every relMSE: about relMSE(sobol, 256 spp) divided by the number of independent "
        "256-sample sobol estimates averaged in a reference pixel (passes x sub-pixels), given per scene below "
        "(`ref. noise`); it matters only at the largest counts.\n")
    for scene in scenes:
        add(f"#### `{scene}`\n")
        sampl = [s for s in RENDER_SAMPLERS if any(k[0] == scene and k[1] == s for k in summ)]
        add("| target spp | " + " | ".join(sampl) + " |")
        add("|---:|" + "---:|" * len(sampl))
        for t in targets:
            cells = []
            for s in sampl:
                hit = [(k, v) for k, v in summ.items() if k[0] == scene and k[1] == s and str(t) in v[5].split()]
                (k, (m, _lo, b, _n, base, _)), = hit
                spp = k[2]
                at = "" if spp == t else f" @{spp}"
                bb = f" b={base}" if base != "" else ""
                cells.append(f"{m:.3g} ±{(b - m) / m:.0%}{at}{bb}")
            add(f"| {t} | " + " | ".join(cells) + " |")
        sob = [v[0] for k, v in summ.items() if k[0] == scene and k[1] == "sobol" and k[2] == 256]
        if sob:
            div = refs[scene][2]
            add(f"\nref. noise, estimated: relMSE(sobol, 256) / {div} = {sob[0] / div:.2g}.")
        # verdicts
        f_ = {k[2]: v[0] for k, v in summ.items() if k[0] == scene and k[1] == "faure"}
        notes = []
        for other in ("bose", "sobol"):
            o = {tuple(v[5].split()): (k[2], v[0]) for k, v in summ.items() if k[0] == scene and k[1] == other}
            rs = []
            for t in targets:
                n, ov = next(v for ts, v in o.items() if str(t) in ts)
                if t in f_:
                    rs.append(f"{t}: {ov * n / (f_[t] * t):.2f}" + ("" if n == t else f" (@{n})"))
            notes.append(f"{other} / faure (above 1: faure better): " + ", ".join(rs))
        add("\nrelMSE x spp ratios (the relMSE ratio where both rendered the same count; `@N`: the other "
            "sampler's count, compared per sample): " + "; ".join(notes) + ".\n")
    add("#### Summary: each sampler against faure\n")
    add("Geometric mean over the targets of (sampler's relMSE x its spp) / (faure's relMSE x its spp): above 1, "
        "faure has the lower error per sample.\n")
    others = [s for s in RENDER_SAMPLERS if s != "faure"]
    add("| scene | " + " | ".join(others) + " |")
    add("|---|" + "---:|" * len(others))
    for scene in scenes:
        f_ = {k[2]: v[0] for k, v in summ.items() if k[0] == scene and k[1] == "faure"}
        cells = []
        for other in others:
            o = {tuple(v[5].split()): (k[2], v[0]) for k, v in summ.items() if k[0] == scene and k[1] == other}
            logs = []
            for t in targets:
                hit = [v for ts, v in o.items() if str(t) in ts]
                if hit and t in f_:
                    n, ov = hit[0]
                    logs.append(math.log(ov * n / (f_[t] * t)))
            cells.append(f"{math.exp(sum(logs) / len(logs)):.2f}" if logs else "-")
        add(f"| {scene} | " + " | ".join(cells) + " |")
    add("")
    plot = plot_renders(summ, scenes, targets)
    add(f"![render relMSE]({rel(plot)})\n")
    t = ", ".join(f"{s} {v:.0f} s" for s, v in timing.items())
    made = [f"{s} reference {m:.0f} s" for s, (_, m, _) in refs.items() if m]
    add(f"Data: `{rel(OUT / 'renders.csv')}` (every render: seed, relMSE, seconds). This part took {took} "
        f"on {cpu_name()} ({t}{'; ' + ', '.join(made) if made else ''}).\n")
    return "\n".join(L)


def plot_renders(summ, scenes, targets) -> Path:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 8), dpi=100)
    FigureCanvasAgg(fig)
    axes = fig.subplots(2, 2).ravel()
    colors = {"faure": "C3", "bose": "k", "sobol": "C0", "halton": "C2", "random": "0.5", "pmj02": "C4",
              "zsobol": "C6"}
    for ax, scene in zip(axes, scenes):
        for s in RENDER_SAMPLERS:
            ks = sorted(k for k in summ if k[0] == scene and k[1] == s)
            if not ks:
                continue
            n = np.array([k[2] for k in ks], float)
            m = np.array([summ[k][0] for k in ks])
            err = np.array([[summ[k][0] - summ[k][1] for k in ks], [summ[k][2] - summ[k][0] for k in ks]])
            err = np.minimum(np.nan_to_num(err), 0.999 * m)  # log axis: keep the bar above 0
            ax.errorbar(n, m * n, yerr=err * n, marker="o", ms=3, lw=0.8, capsize=2, color=colors[s], label=s)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(scene)
        ax.set_xlabel("spp")
        ax.set_ylabel("relMSE x spp (random: flat)")
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
    axes[0].legend(fontsize="x-small")
    for ax in axes[len(scenes):]:
        ax.set_visible(False)
    fig.tight_layout()
    out = OUT / "renders.png"
    with atomic_path(out) as tmp, open(tmp, "wb") as fh:
        fig.savefig(fh, format="png")
    return out


# ============================================================================ throughput

THROUGHPUT_CASES = ("bose-cmj-121x10", "faure-121x10", "sobol-128x10")


def part_throughput(args) -> tuple[str, float]:
    t0 = time.perf_counter()
    out = OUT / "generate-faure.json"
    cmd = [sys.executable, str(REPO / "benchmarks" / "bench_generate.py"), "--cases", ",".join(THROUGHPUT_CASES),
           "--backends", args.backends, "--repeats", str(2 if args.quick else args.repeats), "--no-peers",
           "--out", str(out)] + (["--quick"] if args.quick else [])
    print("   " + " ".join(cmd[1:]), flush=True)
    subprocess.run(cmd, check=True)
    elapsed = time.perf_counter() - t0
    md = throughput_markdown(out, cmd, elapsed)
    write_text(OUT / "throughput.md", md)
    return md, elapsed


def throughput_markdown(path: Path, cmd=None, elapsed=None) -> str:
    """The throughput table, from bench_generate.py's JSON alone (its config gives the command line)."""
    rep = json.loads(path.read_text())
    meta, cfg = rep["machine"], rep["config"]
    res = {(r["case"], r["backend"]): r for r in rep["results"]}
    backends = [b for b in cfg["backends"] if b != "fill"]
    device = res.get((THROUGHPUT_CASES[0], "opencl"), {}).get("device")
    argv = (f"--cases {','.join(cfg['cases'])} --backends {','.join(cfg['backends'])} --repeats {cfg['repeats']}"
            + (" --no-peers" if not cfg.get("peers") else "") + (" --quick" if cfg.get("quick") else ""))
    load = f"{meta.get('loadavg_start')} at the start, {meta.get('loadavg_end')} at the end"
    intro = (f"`python benchmarks/bench_generate.py {argv} --out docs/{rel(path)}` ({cfg['pixels']:,} pixels x "
             f"121 or 128 spp x 10 dims, median of {cfg['repeats']} runs after a warm-up, cases interleaved in one "
             f"process) on {meta.get('cpu') or meta.get('cpu_model')} (lscpu family {meta.get('cpu_family')} "
             f"model {meta.get('cpu_model_number')}), {meta['cpu_count']} cores"
             + (f"; OpenCL: {device}" if device else "")
             + f"; load averages (1/5/15 min) {load}, the machine shared with other work. M values/s "
             "(min-max of the timed runs in brackets):\n")
    L = ["### Generation throughput\n", intro,
         "| case | " + " | ".join(backends) + " | opencl of fill |", "|---|" + "---:|" * (len(backends) + 1)]
    rate = {}
    for case in THROUGHPUT_CASES:
        cells = []
        for b in backends:
            r = res.get((case, b), {})
            if "median_values_per_s" in r:
                rate[(case, b)] = r["median_values_per_s"]
                cells.append(f"{r['median_values_per_s'] / 1e6:,.1f} ({r['values'] / r['max_s'] / 1e6:,.0f}-"
                             f"{r['values'] / r['min_s'] / 1e6:,.0f})")
            else:
                cells.append(r.get("status", "-"))
        o, fill = res.get((case, "opencl"), {}), res.get((case, "fill"), {})
        frac = (f"{o['median_values_per_s'] / fill['median_values_per_s']:.3f}"
                if "median_values_per_s" in o and "median_values_per_s" in fill else "-")
        L.append(f"| {case} | " + " | ".join(cells) + f" | {frac} |")
    f, bo, so = THROUGHPUT_CASES[1], THROUGHPUT_CASES[0], THROUGHPUT_CASES[2]
    ratios = [f"{b}: Bose {rate[(bo, b)] / rate[(f, b)]:.0f}x and sobol {rate[(so, b)] / rate[(f, b)]:.0f}x "
              "faure's rate" for b in backends if all((c, b) in rate for c in THROUGHPUT_CASES)]
    bits = rep.get("bits_match", {})
    L.append("\nIn this run, " + "; ".join(ratios) + ". PoCL and NumPy bits identical: "
             + (", ".join(f"{k} {v}" for k, v in bits.items()) or "n/a")
             + f". The benchmark took {rep.get('total_s', elapsed or 0):.0f} s.\n")
    return "\n".join(L)


# ============================================================================ the page

#: Written after reading the measured tables (re-read it after changing the cases).
INTERPRETATION = """\
What the measurements show (numbers from the tables below; RMSE ratios faure / other, below 1 = faure
better, with 1024 trials a ratio is known to about +-6 %):

- **faure matches Bose at N = b^2 when its base is b.** Over the 16 prime squares from 25 to 3721 the
  geometric mean of faure(b = sqrt N) / bose is 1.00 (gaussian 4D), 1.02 (triples 4D), 1.00
  (triples0 4D), 1.01 (ball 4D), 1.05 (pairwise 10D) and 1.01 (triples 10D); at N = 121, 169 and 961
  gaussian gives 1.02, 0.97 and 1.00. The exception is `pairwise` in 4D (1.19; 1.20, 1.17 and 1.27 at
  121, 169, 961): Bose's default `cmj` offsets make its padded pairs (0,1) and (2,3) full correlated
  multi-jittered patterns (per-pair estimator sd 5.6e-4 there, 3.0e-3 on the other four pairs and on
  every pair of faure, at 121 spp), which 2 of the 6 pairs of a 4D pairwise sum reward. Bose with
  `offset="mj"` has RMSE 1.29e-3 at 121, faure 1.25e-3, Bose `cmj` 1.07e-3 (2048 trials, measured
  separately).
- **faure beats Bose where Bose has no array or only strength 2.** Its default base at d = 4 is 5 (the
  smallest prime >= d), so 125 samples are a strength-3 and 625 a strength-4 array: at Bose's own
  counts the geometric-mean ratio is 0.55 (gaussian), 0.57 (triples), 0.42 (triples0, the pure
  third-order interaction) and 0.91 (ball). Between Bose's counts, at N = 1000, faure's RMSE is
  6.2e-4 (gaussian 4D) against Bose's 12.2e-4 at both 961 and 1024, 2.9e-4 against 7.5e-4 and 7.4e-4
  (triples0). Against Bush (strength 3) at N = p^3 faure also stratifies every pair on p^2 x p grids:
  pairwise 4D 0.35, 0.25, 0.15, 0.13 at 125, 343, 1331, 2197, triples 4D 0.44-0.56, pairwise 10D
  0.16 and 0.13 at 1331 and 2197.
- **faure loses on pure pair interactions away from b^2, and where b < d.** The default base trades
  pair strata for higher strength: pairwise 4D at Bose's counts with base 5 is 2.14x Bose's RMSE
  (geometric mean); pairwise 10D at N = 1000 uses base 11 (all 10 dimensions in one block, 8 full
  121-sample arrays and 32 samples) and has 1.69e-4 against Bose's 0.52e-4 at 961 (3.2x), where
  faure with base 31 matches Bose (1.06 at 961). A fixed base 11 dips at every multiple of 121
  (pairwise 10D: 0.92e-4 at 968, 1.69e-4 at 1000, 2.08e-4 at 1030, 0.73e-4 at 1089) and reaches
  0.22e-4 at 1331 = 11^3, below Bose's 0.37e-4 at 1369. Against Bush on the pure third-order
  integrand faure is 1.07-1.23x (triples0 4D, 125 to 2197), and at N = 27 (base 3 < d = 4, the fourth
  dimension an independent copy) 1.44-1.96x on gaussian, pairwise and triples.
- **Sobol.** At 128 faure (default base) is better in 4D (0.75 gaussian, 0.82 triples, 0.83 triples0,
  0.99 ball; 1.10 pairwise) and on triples 10D (0.86), worse on pairwise 10D (1.31). At 1024 Sobol is
  at a net and faure is not: 1.22 (gaussian), 3.77 (pairwise), 1.60 (triples), 1.27 (triples0), 1.01
  (ball) in 4D and 4.45 / 2.16 (pairwise / triples) in 10D; 1000 faure samples against 1024 Sobol
  ones: 1.19, 2.41, 1.43, 1.25, 1.04, 4.30, 2.11. Each at its own nets (Sobol interpolated log-linearly
  between powers of two), faure is about as good or better: 0.54-1.08 in 4D at 125, 625, 3125 and 0.46-0.69
  in 10D at 121 and 1331. At counts that are nobody's nets, faure, Halton and the first N points of
  Owen-scrambled Sobol are of one kind (fitted slopes -1.64, -1.65, -1.69 on gaussian 4D, -1.98,
  -1.98, -1.99 on pairwise 4D): at N = 1000 their RMSEs are within 7 % on gaussian, triples and ball
  4D, faure's is 35 % lower on pairwise 4D and 9-36 % higher than Sobol's prefix on triples0 4D and
  both 10D integrands. Being valid at every N is not unique to faure among scrambled sequences, only
  among orthogonal arrays.
- **Discontinuous integrand** (`ball` 4D): faure, Halton, Sobol and Bush all reach about N^-1.22,
  Bose -1.05, pmj02 and zsobol -1.03; at N = 1000 faure's RMSE (59.7e-4) equals Halton's and Sobol's
  prefix's (58.9e-4, 59.1e-4), Bose has 68.6e-4 at 961.
- **Renders** (64 x 64, 4 seeds; faure re-rendered after the copies' sample-order fix, the other
  samplers' renders unchanged): per sample, faure is about as good as Bose on `dof7d`, `bounce9d` and
  `deep` (geometric-mean ratio Bose / faure 0.96, 0.98, 0.97; faure ahead at 1024 spp on dof7d and
  bounce9d, 1.21 and 1.18, the latter well outside the seeds' spread; each scene's reference noise,
  given under its table, is 4-7 % of the 1024-spp errors and pulls such ratios towards 1) and behind
  Bose on `cornell` (0.78: Bose lower at every count), behind Sobol on `dof7d` and `bounce9d` (0.78,
  0.84), and ahead of Halton, random and the padded pmj02 and zsobol on `dof7d` and `bounce9d`
  (1.32-1.89 against the padded ones). On `deep` (46 dimensions) nothing stands out: random's error
  per sample is only 1.13x faure's, the others 0.97-1.00x. The fix moved these ratios by at most 0.02:
  the renders' dimensions past the first block carry little of their error.
- **Cost**: faure generates 7.4 M values/s on PoCL here, against Bose's 769 and Sobol's 115 in the same
  run (105x and 16x), and 1.9 M values/s with NumPy. (The renders' `seconds` column is not a cost
  comparison: faure's rows come from a later run than the others', made while other work shared the
  two cores.)
"""


def section_text(out: Path, timings: dict) -> str:
    """The results page's section from the saved parts in ``out`` (``timings``: this run's parts, in s)."""
    parts = []
    for name in ("integrands", "renders", "throughput"):
        p = out / f"{name}.md"
        if p.exists():
            parts.append(p.read_text())
    total = ", ".join(f"{k} {v:.0f} s" for k, v in timings.items())
    footer = ("Generated by `python benchmarks/faure_study.py` (each part above states its own time and machine"
              + (f"; this run: {total}" if total else "") + ").")
    intro = ("`faure` (Owen-scrambled Faure (0, s)-sequence in a prime base b, `pyoa/catalogue/faure.py`) "
             "is valid at every N: every aligned block of b^m samples is a (0, m, b)-net, so its first "
             "b^2 samples are a strength-2 orthogonal array like `bose` at s = b, its first b^3 a "
             "strength-3 one, and a pixel's i-th sample does not depend on spp. This section measures "
             "what that buys and costs.")
    return "\n".join(["## faure: progressive orthogonal arrays", "", intro, "", INTERPRETATION, *parts, footer])


def part_section(args, timings: dict) -> None:
    text = section_text(OUT, timings)
    if args.quick:  # a smoke run leaves the page alone
        write_text(OUT / "section.md", text)
        print(f"wrote {OUT / 'section.md'} (quick: docs/results.md untouched)")
    else:
        changed = marked.write(RESULTS_MD, {SECTION: marked.block_body(text)})
        print(f"{'wrote the section into' if changed else 'the section is unchanged in'} {RESULTS_MD}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="small sizes, about a minute, under docs/results/quick/faure")
    ap.add_argument("--parts", default=",".join(PARTS), help=f"comma-separated subset of {', '.join(PARTS)}")
    ap.add_argument("--trials", type=int, default=None, help="randomizations per count (default 1024; quick 64)")
    ap.add_argument("--nmax", type=int, default=None, help="largest sample count (default 4096; quick 512)")
    ap.add_argument("--size", type=int, default=None, help="render width and height (default 64; quick 32)")
    ap.add_argument("--seeds", type=int, default=None, help="render seeds (default 4; quick 2)")
    ap.add_argument("--backends", default="opencl,numpy,fill", help="bench_generate.py backends")
    ap.add_argument("--repeats", type=int, default=5, help="bench_generate.py timed runs (default 5)")
    ap.add_argument("--rebuild", action="store_true",
                    help="rewrite the renders and throughput markdown from their saved CSV/JSON, computing nothing")
    ap.add_argument("--samplers", default=None,
                    help=f"renders: re-render only these (comma-separated subset of {', '.join(RENDER_SAMPLERS)}) "
                         "and keep the other samplers' rows of renders.csv")
    args = ap.parse_args(argv)
    if args.samplers is not None:
        args.samplers = tuple(s.strip() for s in args.samplers.split(",") if s.strip())
        bad = [s for s in args.samplers if s not in RENDER_SAMPLERS]
        if bad or not args.samplers:
            ap.error(f"--samplers {bad or 'is empty'}; valid: {', '.join(RENDER_SAMPLERS)}")
    parts = [p.strip() for p in args.parts.split(",") if p.strip()]
    bad = [p for p in parts if p not in PARTS]
    if bad:
        ap.error(f"unknown part(s) {bad}; valid: {', '.join(PARTS)}")
    q = args.quick
    args.trials = args.trials or (64 if q else 1024)
    args.nmax = args.nmax or (512 if q else 4096)
    args.size = args.size or (32 if q else 64)
    args.seeds = args.seeds or (2 if q else 4)
    global OUT
    if q:  # never overwrite the published figures with a smoke run (docs/results/quick/ is git-ignored)
        OUT = REPO / "docs" / "results" / "quick" / "faure"
    OUT.mkdir(parents=True, exist_ok=True)
    print(f"faure study on {cpu_name()}{' [QUICK]' if q else ''}", flush=True)
    timings = {}
    for name, fn in (("integrands", part_integrands), ("renders", part_renders), ("throughput", part_throughput)):
        if name in parts and not args.rebuild:
            print(f"== {name}", flush=True)
            _, timings[name] = fn(args)
            print(f"== {name}: {timings[name]:.0f} s", flush=True)
    if args.rebuild:
        if "renders" in parts and (OUT / "renders.csv").exists():
            rebuild_renders(args)
        if "throughput" in parts and (OUT / "generate-faure.json").exists():
            write_text(OUT / "throughput.md", throughput_markdown(OUT / "generate-faure.json"))
    if "section" in parts:
        part_section(args, timings)
    return 0


if __name__ == "__main__":
    sys.exit(main())
