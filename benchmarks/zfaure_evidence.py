#!/usr/bin/env python3
"""Evidence for ``zfaure`` (issue 52): blue-noise error at faure's per-pixel error, on integrands and renders.

Two parts, each written into ``benchmarks/results/zfaure-evidence.json`` (and its ``.md``, the section of
docs/results.md that ``benchmarks/update_docs.py`` makes from it), pictures into ``docs/results/zfaure/``:

``spectra``
    Every pixel of a 64 x 64 image integrates 2D (``ball``, ``gaussian``), 4D (``gaussian``, ``pairwise``) and,
    at some counts, 7D (``gaussian``, ``pairwise``) integrands with its own samples; the error image's
    periodogram, averaged over seeds and divided by the error variance (white noise = 1), is summarized by
    ``low``, its mean over ``1 <= |k| <= size / 8``, exactly as :func:`pyoa.analysis.error_spectrum` does
    (:func:`spectrum` repeats its arithmetic per seed so that the seeds can be bootstrapped;
    ``tests/test_zfaure_evidence.py`` checks the two agree). ``zfaure`` runs at its counts ``b^m`` from 16 to
    1024, ``faure`` at the same count and base (so per-pixel RMSE is compared like for like), ``zsobol``,
    ``pmj02`` and ``bose`` at their valid counts nearest to it. One generation per (sampler, count, seed) at
    the most dimensions measured there serves every integrand: each sampler's first ``d`` dimensions do not
    depend on how many it was asked for.
``renders``
    ``dof7d`` at 49 spp (base 7: its 7 dimensions in one block) and ``cornell`` at 64 spp (base 2), 64 x 64,
    several seeds, against the references the faure study uses; relMSE, the error image's ``low``, and
    MSE and relMSE after a Gaussian blur (sigma 1 and 2 pixels) of both image and reference: what the blue
    noise buys a denoiser.

zfaure's and zsobol's pixels share one sequence, so a seed's per-pixel RMSE varies far more between seeds
than faure's (each pixel's own scramble); every figure carries a standard error over seeds (bootstrap for
``low`` and the RMSE, whose estimators are ratios of means).

Usage::

    python benchmarks/zfaure_evidence.py                       # both parts, all counts (long: see --seeds-at)
    python benchmarks/zfaure_evidence.py --parts spectra --counts 16,25 --seeds 64   # merge these counts in
    python benchmarks/zfaure_evidence.py --quick --out /tmp/z  # a smoke run, seconds, into /tmp/z
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(HERE))

from common import loadavg, machine, write_text  # noqa: E402

RESULTS_JSON = REPO / "benchmarks" / "results" / "zfaure-evidence.json"
FIGURES = REPO / "docs" / "results" / "zfaure"
#: (integrand, dimensions) measured; the 7D ones only at :data:`SEVEN_D_COUNTS`.
INTEGRANDS = (("ball", 2), ("gaussian", 2), ("gaussian", 4), ("pairwise", 4), ("gaussian", 7), ("pairwise", 7))
#: zfaure counts where the 7D integrands are measured: bases 7 and 11 hold all 7 dimensions in one block,
#: 64 (base 2) splits them over four.
SEVEN_D_COUNTS = (49, 64, 121, 343)
OTHERS = ("zsobol", "pmj02", "bose")
#: (scene, zfaure count) rendered.
RENDERS = (("dof7d", 49), ("cornell", 64))
RENDER_SAMPLERS = ("zfaure", "zsobol", "faure", "bose")
SIGMAS = (1, 2)
BOOTSTRAP = 400
#: The pictured integrand and render: (integrand, dims, zfaure count) and the scene.
PICTURED = ("gaussian", 4, 49)


def zfaure_counts(lo: int = 16, hi: int = 1024) -> dict[int, int]:
    """zfaure's counts in [lo, hi] -> their base (``pyoa.catalogue.faure.zfaure_counts``)."""
    from pyoa.catalogue.faure import zfaure_counts as counts

    return {n: b for n, (b, _) in counts().items() if lo <= n <= hi}


def integrands_at(count: int) -> list[tuple[str, int]]:
    return [(f, d) for f, d in INTEGRANDS if d < 7 or count in SEVEN_D_COUNTS]


# ============================================================================ measures


def periodograms(errs: np.ndarray) -> np.ndarray:
    """(seeds, size, size) error images -> their periodograms ``|E(k)|^2 / size^2``, centred (fftshift),
    DC zeroed, flattened to (seeds, size * size): :func:`pyoa.analysis.error_spectrum`'s arithmetic."""
    n = errs.shape[-1]
    p = np.fft.fftshift(np.abs(np.fft.fft2(errs)) ** 2 / (n * n), axes=(-2, -1))
    p[:, n // 2, n // 2] = 0.0
    return p.reshape(len(errs), -1)


def _low_mask(n: int) -> np.ndarray:
    c = n // 2
    ky, kx = np.mgrid[-c:n - c, -c:n - c]
    r = np.hypot(kx, ky)
    return ((r >= 1) & (r <= n / 8)).ravel()


def low_of(mean_power: np.ndarray, n: int) -> np.ndarray:
    """``low`` of mean periodograms (..., n * n): the mean over ``1 <= |k| <= n/8`` over the mean over
    every non-zero frequency (white noise: 1)."""
    white = mean_power.sum(axis=-1) / (n * n - 1)
    return mean_power[..., _low_mask(n)].mean(axis=-1) / white


def _weights(seeds: int, rng: np.random.Generator) -> np.ndarray:
    """(BOOTSTRAP, seeds) resampling weights: seeds drawn with replacement, each row summing to 1."""
    idx = rng.integers(0, seeds, (BOOTSTRAP, seeds))
    return np.stack([np.bincount(row, minlength=seeds) for row in idx]) / seeds


def spectrum(errs: np.ndarray, rng: np.random.Generator) -> dict:
    """The spectrum of (seeds, size, size) error images: ``low``, RMSE, each with its bootstrap standard
    error over seeds, and the radial mean of the normalized mean periodogram."""
    from pyoa.analysis import radial_mean

    seeds, n = errs.shape[0], errs.shape[-1]
    per = periodograms(errs)
    mse = np.mean(errs.reshape(seeds, -1) ** 2, axis=1)
    mean = per.mean(axis=0)
    radii, radial = radial_mean((mean / (mean.sum() / (n * n - 1))).reshape(n, n))
    out = {"seeds": seeds, "low": float(low_of(mean, n)), "rmse": float(math.sqrt(mse.mean())),
           "low_se": None, "rmse_se": None, "radii": radii.tolist(), "radial": [round(float(v), 4) for v in radial]}
    if seeds > 1:
        w = _weights(seeds, rng)
        out["low_se"] = float(low_of(w @ per, n).std(ddof=1))
        out["rmse_se"] = float(np.sqrt(w @ mse).std(ddof=1))
    return out


def fingerprint() -> str:
    """The first 12 hex digits of SHA-256 of a few zfaure samples (NumPy: 8 x 8 pixels, 25 and 64 spp,
    7 dimensions, seeds 0 and 1): entries measured with different zfaure math disagree here, and the section
    says so rather than mixing them silently."""
    import hashlib

    import pyoa

    h = hashlib.sha256()
    for spp in (25, 64):
        for seed in (0, 1):
            x = pyoa.sampler("zfaure", spp=spp, dims=7, seed=seed, backend="numpy", resolution=(8, 8))
            h.update(np.ascontiguousarray(x.generate(pixels=range(64)), dtype="<f4").tobytes())
    return h.hexdigest()[:12]


def _options(name: str, spp: int, base: int | None, size: int, backend: str) -> dict:
    import pyoa

    opts = {"backend": backend}
    if pyoa.catalogue.get(name).needs_resolution:
        opts["resolution"] = (size, size)
    if base is not None:
        opts["base"] = base
    return opts


def measure(name: str, spp: int, base: int | None, dims: int, seeds: int, size: int, backend: str,
            integrands: list[tuple[str, int]]) -> tuple[dict, dict]:
    """Error images of ``integrands`` for seeds 0 .. seeds-1 of one sampler: {(integrand, d): (seeds, size,
    size)} and the seconds spent. Each seed's samples are generated once, at ``dims`` dimensions."""
    import pyoa
    from pyoa.analysis.integrands import _lookup

    fs = {(f, d): _lookup(f, d) for f, d in integrands}
    errs = {key: np.empty((seeds, size, size)) for key in fs}
    opts = _options(name, spp, base, size, backend)
    t = time.perf_counter()
    for s in range(seeds):
        x = pyoa.sampler(name, spp=spp, dims=dims, seed=s, **opts).generate(pixels=range(size * size))
        for (f, d), fn in fs.items():
            errs[(f, d)][s] = (fn(x[..., :d]).mean(axis=1) - fn.exact).reshape(size, size)
    return errs, time.perf_counter() - t


# ============================================================================ spectra


def spectra_jobs(counts: dict[int, int], seeds_for) -> list[dict]:
    """The samplers to measure for zfaure ``counts`` ({N: base}): zfaure and faure at N (base b), the others
    at their nearest valid count, each once, at the most dimensions and seeds any N asks of it. A job an
    earlier run (kept in the JSON) did with as many seeds and integrands is skipped by :func:`part_spectra`,
    so the others of a count always have at least zfaure's seeds."""
    from pyoa import catalogue

    jobs: dict[tuple, dict] = {}

    def add(name, spp, base, n):
        key = (name, spp, base)
        dims = max(d for _, d in integrands_at(n))
        job = jobs.setdefault(key, {"sampler": name, "spp": spp, "base": base, "dims": 0, "seeds": 0,
                                    "integrands": set()})
        job["dims"] = max(job["dims"], dims)
        job["seeds"] = max(job["seeds"], seeds_for(n))
        job["integrands"] |= set(integrands_at(n))

    for n, b in counts.items():
        add("zfaure", n, None, n)
        add("faure", n, b, n)
        for other in OTHERS:
            add(other, catalogue.nearest_spp(other, n), None, n)
    return [dict(j, integrands=sorted(j["integrands"], key=INTEGRANDS.index)) for j in jobs.values()]


def job_key(sampler: str, spp: int, base: int | None) -> str:
    return f"{sampler}-{spp}" + (f"-b{base}" if base is not None else "")


def part_spectra(args, report: dict, save) -> None:
    rng = np.random.default_rng(0)
    jobs = spectra_jobs(args.counts, args.seeds_for)
    report.setdefault("spectra", {})
    report["zfaure_counts"] = sorted(set(report.get("zfaure_counts", [])) | set(args.counts))
    for k, job in enumerate(jobs):
        key = job_key(job["sampler"], job["spp"], job["base"])
        have = report["spectra"].get(key)
        names = {f"{f}-{d}d" for f, d in job["integrands"]}
        if (have and job["sampler"] not in args.redo and have["seeds"] >= job["seeds"]
                and names <= set(have["integrands"])):
            continue  # an earlier run measured it with as many seeds (another count's nearest, say): keep that
        errs, dt = measure(job["sampler"], job["spp"], job["base"], job["dims"], job["seeds"], args.size,
                           args.backend, job["integrands"])
        entry = {"sampler": job["sampler"], "spp": job["spp"], "base": job["base"], "dims_generated": job["dims"],
                 "seeds": job["seeds"], "seconds": round(dt, 2),
                 "integrands": {f"{f}-{d}d": spectrum(e, rng) for (f, d), e in errs.items()}}
        if job["sampler"] == "zfaure":
            entry["zfaure_fingerprint"] = fingerprint()
        report["spectra"][key] = entry
        print(f"   [{k + 1}/{len(jobs)}] {job['sampler']} {job['spp']} ({job['dims']}D, {job['seeds']} seeds): "
              f"{dt:.1f} s", flush=True)
        save()


def comparisons(report: dict) -> list[dict]:
    """One row per (integrand, zfaure count) measured: zfaure's low and RMSE, faure's at the same count and
    base, the RMSE ratio with its standard error, and the others' low and RMSE at their nearest counts."""
    from pyoa import catalogue

    sp = report.get("spectra", {})
    counts = zfaure_counts()
    rows = []
    for f, d in INTEGRANDS:
        name = f"{f}-{d}d"
        for n in report.get("zfaure_counts", []):
            b = counts[n]
            z, fa = sp.get(job_key("zfaure", n, None)), sp.get(job_key("faure", n, b))
            if z is None or fa is None or name not in z["integrands"]:
                continue
            zi, fi = z["integrands"][name], fa["integrands"][name]
            ratio = zi["rmse"] / fi["rmse"]
            se = None
            if zi["rmse_se"] is not None and fi["rmse_se"] is not None:
                se = ratio * math.hypot(zi["rmse_se"] / zi["rmse"], fi["rmse_se"] / fi["rmse"])
            row = {"integrand": name, "dims": d, "count": n, "base": b, "one_block": b >= d,
                   "zfaure": _short(zi), "faure": _short(fi), "rmse_ratio": ratio, "rmse_ratio_se": se}
            for other in OTHERS:
                m = catalogue.nearest_spp(other, n)
                o = sp.get(job_key(other, m, None))
                if o is not None and name in o["integrands"]:
                    row[other] = dict(_short(o["integrands"][name]), spp=m)
            rows.append(row)
    return rows


def _short(s: dict) -> dict:
    return {k: s[k] for k in ("seeds", "low", "low_se", "rmse", "rmse_se")}


# ============================================================================ renders


def reference(scene: str, size: int) -> tuple[np.ndarray, str]:
    """The ``size x size`` reference of ``scene`` and how it was made: the faure study's (``dof7d``: 128 x
    128, 4096 spp of sobol; ``cornell``: 64 x 64, 32768 spp) averaged over blocks of pixels."""
    from pyoa.render.image import read_image

    path, made = {"dof7d": (REPO / "docs/results/dof7d-reference.exr", "4096 spp of sobol, by make_results.py"),
                  "cornell": (REPO / "docs/results/faure/cornell-reference-64.exr",
                              "32768 spp of sobol, by faure_study.py")}[scene]
    img = read_image(path).astype(np.float64)
    h, w = img.shape[:2]
    k = h // size
    if h != w or k * size != h:
        raise SystemExit(f"{path}: {w} x {h} does not average down to {size} x {size}")
    how = f"`{path.relative_to(REPO)}` ({w} x {h}, {made})" + (f" averaged over {k} x {k} pixels" if k > 1 else "")
    return img.reshape(size, k, size, k, 3).mean(axis=(1, 3)), how


def render_metrics(img: np.ndarray, ref: np.ndarray) -> dict:
    """One render's relMSE, MSE, and both after a Gaussian blur of image and reference (per channel)."""
    from scipy.ndimage import gaussian_filter

    from pyoa.render.image import rel_mse

    out = {"relmse": rel_mse(img, ref), "mse": float(np.mean((img - ref) ** 2))}
    for s in SIGMAS:
        a, r = gaussian_filter(img, (s, s, 0)), gaussian_filter(ref, (s, s, 0))
        out[f"blur{s}_mse"] = float(np.mean((a - r) ** 2))
        out[f"blur{s}_relmse"] = rel_mse(a, r)
    return out


def part_renders(args, report: dict, save) -> None:
    from pyoa import catalogue
    from pyoa.render.render import render
    from pyoa.render.scene import load

    rng = np.random.default_rng(1)
    scenes = [name for name, _ in args.renders]
    kept = {(r["scene"], r["sampler"]): r for r in report.get("renders", [])
            if r["sampler"] not in args.redo and r["seeds"] == args.render_seeds and r["scene"] in scenes}
    rows = {}
    report["references"] = {}

    def ordered(rows: dict) -> list[dict]:
        return [rows[k] for k in sorted(rows, key=lambda k: (scenes.index(k[0]), RENDER_SAMPLERS.index(k[1])))]

    for name, n in args.renders:
        scene = load(name)
        ref, how = reference(name, args.size)
        report["references"][name] = how
        b = zfaure_counts(n, n)[n]
        for smp in RENDER_SAMPLERS:
            if (name, smp) in kept:  # not redone: its bits did not change
                rows[(name, smp)] = kept[(name, smp)]
                continue
            spp = n if smp in ("zfaure", "faure") else catalogue.nearest_spp(smp, n)
            extra = {"base": b} if smp == "faure" else {}
            per, errs = [], []
            t = time.perf_counter()
            for seed in range(args.render_seeds):
                img = render(scene, sampler=smp, spp=spp, seed=seed, width=args.size, height=args.size,
                             **extra).image.astype(np.float64)
                per.append(render_metrics(img, ref))
                errs.append((img - ref).mean(axis=2))
            dt = time.perf_counter() - t
            errs = np.array(errs)
            sp = spectrum(errs, rng)
            row = {"scene": name, "sampler": smp, "spp": spp, "base": b if smp in ("zfaure", "faure") else None,
                   "seeds": args.render_seeds, "seconds": round(dt, 2), "low": sp["low"], "low_se": sp["low_se"],
                   "rmse": sp["rmse"], "radii": sp["radii"], "radial": sp["radial"]}
            for key in per[0]:
                v = np.array([p[key] for p in per])
                row[key] = float(v.mean())
                row[f"{key}_se"] = float(v.std(ddof=1) / math.sqrt(len(v))) if len(v) > 1 else None
            if smp == "zfaure":
                row["zfaure_fingerprint"] = fingerprint()
            rows[(name, smp)] = row
            report["renders"] = ordered(rows)
            print(f"   {name} {smp} {spp}: relMSE {row['relmse']:.3e}, low {row['low']:.3f}, {dt:.0f} s", flush=True)
            save()
    report["renders"] = ordered(rows)


# ============================================================================ pictures

def _figure(w: float, h: float):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w, h), dpi=80)
    FigureCanvasAgg(fig)
    return fig


def picture_errors(report: dict, out: Path, backend: str) -> list[Path]:
    """Seed 0's error images side by side (zfaure, zsobol, faure), for the pictured integrand and the first
    rendered scene, where the report has them; seed 0 is generated or rendered again (seconds: the same
    bits), so the picture does not depend on which run measured what."""
    from pyoa import catalogue
    from pyoa.render.render import render
    from pyoa.render.scene import load

    f, d, n = PICTURED
    size = report["settings"]["size"]
    b = zfaure_counts(n, n)[n]
    panels = []
    spectra = [("zfaure", n, None), ("zsobol", catalogue.nearest_spp("zsobol", n), None), ("faure", n, b)]
    if all(job_key(*k) in report.get("spectra", {}) for k in spectra):
        panels.append((f"{f} {d}D", [(f"{s} {m}", measure(s, m, bb, d, 1, size, backend, [(f, d)])[0][(f, d)][0])
                                     for s, m, bb in spectra]))
    if report.get("renders"):
        scene = report["renders"][0]["scene"]
        ref, _ = reference(scene, report["settings"]["render_size"])
        rows = {r["sampler"]: r for r in report["renders"] if r["scene"] == scene}
        images = []
        for s in ("zfaure", "zsobol", "faure"):
            r = rows[s]
            extra = {"base": r["base"]} if s == "faure" else {}
            img = render(load(scene), sampler=s, spp=r["spp"], seed=0, width=ref.shape[1], height=ref.shape[0],
                         **extra).image.astype(np.float64)
            images.append((f"{s} {r['spp']}", (img - ref).mean(axis=2)))
        panels.append((scene, images))
    if not panels:
        return []
    fig = _figure(7.5, 2.6 * len(panels))
    for i, (title, images) in enumerate(panels):
        lim = float(np.percentile(np.abs([img for _, img in images]), 99))  # a few fireflies saturate
        for j, (label, img) in enumerate(images):
            ax = fig.add_subplot(len(panels), 3, 3 * i + j + 1)
            ax.imshow(img, cmap="RdBu_r", vmin=-lim, vmax=lim, interpolation="nearest")
            ax.set_title(f"{title}: {label}", fontsize=9)
            ax.set_xticks([])
            ax.set_yticks([])
    fig.tight_layout()
    path = out / "errors.png"
    fig.savefig(path)
    return [path]


def picture_spectra(report: dict, out: Path) -> list[Path]:
    """Radial spectra (white noise = 1) of the pictured count on the 2D, 4D and 7D integrands and of the
    first render, one panel each, every sampler a line."""
    from pyoa import catalogue

    f0, d0, n = PICTURED
    b = zfaure_counts(n, n).get(n)
    sp = report.get("spectra", {})
    keys = [("zfaure", n, None), ("faure", n, b)] + [(o, catalogue.nearest_spp(o, n), None) for o in OTHERS]
    panels = []
    for name in ("ball-2d", f"{f0}-{d0}d", "gaussian-7d"):
        lines = [(f"{s} {m}", sp[job_key(s, m, bb)]["integrands"][name]) for s, m, bb in keys
                 if job_key(s, m, bb) in sp and name in sp[job_key(s, m, bb)]["integrands"]]
        if lines:
            panels.append((name, lines))
    if report.get("renders"):
        scene = report["renders"][0]["scene"]
        panels.append((scene, [(f"{r['sampler']} {r['spp']}", r) for r in report["renders"] if r["scene"] == scene]))
    if not panels:
        return []
    fig = _figure(3.0 * len(panels), 2.8)
    for i, (title, lines) in enumerate(panels):
        ax = fig.add_subplot(1, len(panels), i + 1)
        for label, s in lines:
            ax.plot(s["radii"], s["radial"], label=label, lw=1.2)
        ax.axhline(1.0, color="grey", lw=0.6, ls=":")
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("|k|", fontsize=8)
        ax.tick_params(labelsize=7)
        if i == 0:
            ax.set_ylabel("power / white", fontsize=8)
        ax.legend(fontsize=6)
    fig.tight_layout()
    path = out / "spectra.png"
    fig.savefig(path)
    return [path]


# ============================================================================ text


def _pm(v: float, se: float | None, fmt: str) -> str:
    return f"{v:{fmt}}" + (f" ± {se:{fmt}}" if se is not None else "")


def _cpu(m: dict) -> str:
    import figures

    return f"{figures.cpu_long(m)}, {m['cpu_count']} cores"


def _other(r: dict, o: str) -> tuple[str, str]:
    """The low (with the count in brackets) and RMSE cells of another sampler in a comparison row."""
    if o not in r:
        return "-", "-"
    v = r[o]
    return f"{_pm(v['low'], v['low_se'], '.3f')} ({v['spp']})", f"{v['rmse']:.3g}"


def section_text(report: dict, figures_rel: str = "results/zfaure") -> str:
    """The results page's section (and the ``.md`` file) from the report; pictures under ``figures_rel``
    (relative to docs/)."""
    m, s = report["machine"], report["settings"]
    L = ["### Measured: zfaure against zsobol, faure, bose and pmj02", ""]
    prints = {e.get("zfaure_fingerprint") for e in report.get("spectra", {}).values() if e["sampler"] == "zfaure"}
    prints |= {r.get("zfaure_fingerprint") for r in report.get("renders", []) if r["sampler"] == "zfaure"}
    prints.discard(None)  # entries measured before fingerprints were recorded
    if len(prints) > 1:
        L += [f"**Warning**: the zfaure figures below come from {len(prints)} versions of its math "
              f"(fingerprints {', '.join(sorted(prints))}); measure them again with `--redo zfaure`.", ""]
    rows = comparisons(report)
    if rows:
        L += [f"Error spectra, {s['size']} x {s['size']} pixels, each pixel its own samples "
              f"(`pyoa.analysis.error_spectrum`'s measure: low is the mean normalized periodogram at "
              f"1 <= |k| <= {s['size'] // 8}, white noise = 1; RMSE per pixel), seeds 0 .. seeds-1 (zfaure's; "
              "the others at least as many), ± one bootstrap standard error over seeds. faure runs at zfaure's "
              "count and base; zsobol, pmj02 and bose at their nearest valid count (in brackets). block: whether "
              "the base b >= the integrand's dimensions, so that all of them lie in one Faure block.", ""]
        for name in dict.fromkeys(r["integrand"] for r in rows):
            L += [f"`{name}`:", "",
                  "| N | b | block | seeds | zfaure low | zfaure RMSE | / faure's | faure low | zsobol low | zsobol RMSE "
                  "| pmj02 low | pmj02 RMSE | bose low | bose RMSE |",
                  "|---:|---:|:-:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
            for r in (r for r in rows if r["integrand"] == name):
                z, fa = r["zfaure"], r["faure"]
                cells = [str(r["count"]), str(r["base"]), "yes" if r["one_block"] else "no", str(z["seeds"]),
                         f"**{_pm(z['low'], z['low_se'], '.3f')}**", f"{z['rmse']:.3g}",
                         _pm(r["rmse_ratio"], r["rmse_ratio_se"], ".3f"), f"{fa['low']:.2f}"]
                for o in OTHERS:
                    cells += _other(r, o)
                L.append("| " + " | ".join(cells) + " |")
            L.append("")
        took = sum(e["seconds"] for e in report["spectra"].values())
        L += [f"Sampling and integration took {took / 60:.0f} minutes ({s['backend']} backend).", ""]
    if report.get("renders"):
        L += [f"Renders, {s['render_size']} x {s['render_size']} pixels (`pyoa.render.render`, box filter), seeds "
              f"0 .. {report['renders'][0]['seeds'] - 1}, ± one standard error over seeds (bootstrap for low); "
              "references: " + "; ".join(f"`{k}`: {v}" for k, v in report["references"].items())
              + ". low is the same measure on the error image (mean over the colour channels); the blur is "
              "`scipy.ndimage.gaussian_filter` of image and reference alike, per channel.", "",
              "| scene | sampler | spp | relMSE | RMSE | low | blur 1 px: MSE | / faure's | relMSE "
              "| blur 2 px: MSE | / faure's | relMSE |",
              "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
        faure = {r["scene"]: r for r in report["renders"] if r["sampler"] == "faure"}
        for r in report["renders"]:
            name = r["sampler"] + (f" (b {r['base']})" if r["base"] else "")
            cells = [r["scene"], name, str(r["spp"]), _pm(r["relmse"], r["relmse_se"], ".2e"), f"{r['rmse']:.4f}",
                     _pm(r["low"], r["low_se"], ".3f")]
            for sg in SIGMAS:
                cells += [_pm(r[f"blur{sg}_mse"], r[f"blur{sg}_mse_se"], ".2e"),
                          f"{r[f'blur{sg}_mse'] / faure[r['scene']][f'blur{sg}_mse']:.2f}", f"{r[f'blur{sg}_relmse']:.2e}"]
            L.append("| " + " | ".join(cells) + " |")
        took = sum(r["seconds"] for r in report["renders"])
        L += ["", f"Rendering took {took / 60:.1f} minutes.", ""]
    captions = {"errors.png": "Seed 0's error images side by side (red: above the exact value, blue: below; one "
                              "colour scale per row, saturating at its 99th percentile of the absolute error).",
                "spectra.png": "Radial mean of the error spectra (white noise = 1)."}
    for fig, caption in captions.items():
        if fig in report.get("figures", []):
            L += [f"![{caption}]({figures_rel}/{fig})", "", caption, ""]
    runs = "; ".join(f"`python benchmarks/zfaure_evidence.py{' ' * bool(r['command'])}{r['command']}`" +
                     f" ({r['date_utc'][:16].replace('T', ' ')} UTC, {r.get('seconds', 0) / 60:.0f} min)"
                     for r in report.get("runs", []))
    L.append(f"Measured on {_cpu(m)}, shared with other work (load average before each run in the JSON), by {runs}.")
    return "\n".join(L)


# ============================================================================ main


def _counts_arg(text: str) -> dict[int, int]:
    valid = zfaure_counts(1, 1 << 24)
    counts = [int(v) for v in text.split(",") if v.strip()]
    bad = [n for n in counts if n not in valid]
    if bad:
        raise argparse.ArgumentTypeError(f"{bad} are not zfaure counts (b^m, b prime, m >= 2)")
    return {n: valid[n] for n in sorted(counts)}


def _seeds_at(text: str) -> dict[int, int]:
    return {int(a): int(b) for a, b in (p.split(":") for p in text.split(",") if p.strip())}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="a smoke run in seconds: 16 x 16, counts 25 and 49, "
                    "4 seeds, dof7d only; never touches docs/results.md")
    ap.add_argument("--out", type=Path, default=None,
                    help="write the JSON, markdown and pictures here (default: benchmarks/results and "
                         "docs/results/zfaure; quick: docs/results/quick/zfaure)")
    ap.add_argument("--parts", default="spectra,renders",
                    help="comma-separated subset of spectra, renders; empty: only the pictures and the text again")
    ap.add_argument("--counts", type=_counts_arg, default=None,
                    help="zfaure counts to measure (default: every one in 16..1024); results of other counts "
                         "already in the JSON are kept")
    ap.add_argument("--seeds", type=int, default=None, help="seeds per count (default 32; quick 4)")
    ap.add_argument("--seeds-at", type=_seeds_at, default={},
                    help="per-count seeds overriding --seeds, e.g. 25:128,1024:8")
    ap.add_argument("--size", type=int, default=None, help="image side (default 64; quick 16)")
    ap.add_argument("--render-seeds", type=int, default=None, help="render seeds (default 8; quick 2)")
    ap.add_argument("--redo", default="", help="comma-separated samplers to measure again even where the JSON "
                    "has them (their math changed); the others' entries and render rows are kept")
    ap.add_argument("--backend", default=None, help="sampler backend (default: opencl if it has zfaure, else numpy)")
    args = ap.parse_args(argv)
    q = args.quick
    parts = [p.strip() for p in args.parts.split(",") if p.strip()]
    if set(parts) - {"spectra", "renders"}:
        ap.error(f"unknown parts {set(parts) - {'spectra', 'renders'}}")
    args.size = args.size or (16 if q else 64)
    args.render_seeds = args.render_seeds or (2 if q else 8)
    args.counts = args.counts or (_counts_arg("25,49") if q else zfaure_counts())
    seeds = args.seeds or (4 if q else 32)
    args.seeds_for = lambda n: args.seeds_at.get(n, seeds)
    args.renders = RENDERS[:1] if q else RENDERS
    args.redo = {v.strip() for v in args.redo.split(",") if v.strip()}
    args.backend = args.backend or _backend()
    out = args.out or (REPO / "docs" / "results" / "quick" / "zfaure" if q else None)
    results = out / "zfaure-evidence.json" if out else RESULTS_JSON
    figs = out or FIGURES
    figs.mkdir(parents=True, exist_ok=True)
    results.parent.mkdir(parents=True, exist_ok=True)
    report = json.loads(results.read_text()) if results.exists() else {}
    if report.get("settings", {}).get("size") != args.size:
        report = {}  # another image size: nothing of it can be merged
    command = "".join(f" {a}" for a in (sys.argv[1:] if argv is None else argv))
    report["machine"] = machine()
    report["settings"] = {"size": args.size, "render_size": args.size, "backend": args.backend,
                          "bootstrap": BOOTSTRAP}
    run = {"command": command.strip(), "date_utc": report["machine"]["date_utc"], "loadavg_before": loadavg()}
    report.setdefault("runs", []).append(run)

    def save() -> None:
        report["comparisons"] = comparisons(report)
        text = json.dumps(report, indent=1)
        # a list of numbers (the radial spectra) on one line: the file stays small and readable
        text = re.sub(r"\[\s+([-+.\deE,\s]+?)\s+\]", lambda m: "[" + " ".join(m[1].split()) + "]", text)
        write_text(results, text + "\n")

    t = time.perf_counter()
    if "spectra" in parts:
        print(f"spectra: counts {list(args.counts)}, {args.size} x {args.size}, {args.backend}", flush=True)
        part_spectra(args, report, save)
    if "renders" in parts:
        print(f"renders: {args.renders}, {args.size} x {args.size}, {args.render_seeds} seeds", flush=True)
        part_renders(args, report, save)
    run["seconds"] = round(time.perf_counter() - t)
    made = picture_errors(report, figs, args.backend) + picture_spectra(report, figs)
    report["figures"] = sorted(set(report.get("figures", [])) | {p.name for p in made})
    save()
    text = section_text(report, "results/zfaure" if out is None else str(figs))
    write_text(results.with_suffix(".md"), text + "\n")
    if out is None:
        import update_docs

        changed = update_docs.after(results)
        print(f"wrote {', '.join(str(p.relative_to(REPO)) for p in changed) or 'no page (unchanged)'}")
    print(f"wrote {results} and {len(made)} pictures in {time.perf_counter() - t:.0f} s")
    return 0


def _backend() -> str:
    """opencl where it runs zfaure, else numpy (the same bits)."""
    import pyoa

    try:
        pyoa.sampler("zfaure", spp=4, dims=2, seed=0, backend="opencl", resolution=(2, 2)).generate(pixels=range(4))
        return "opencl"
    except Exception:  # noqa: BLE001 - no OpenCL, or no zfaure kernel yet
        return "numpy"


if __name__ == "__main__":
    sys.exit(main())
