"""``pyoa study``: error against samples per pixel, over seeds, with confidence intervals.

A study renders every (scene, sampler, spp, seed) once and measures its
relative MSE (:func:`pyoa.render.image.rel_mse`, the paper's measure [1]_)
against a high-spp reference of the scene, over the whole image and a crop.
Each render is one task of an engine (:mod:`pyoa.cluster`): in-process by
default, or on a Dask cluster. Rows are appended to ``DIR/study.csv`` as
results arrive, so an interrupted study resumes and renders only what is
missing; ``DIR/study.json`` holds the settings every row depends on (scene
contents, size, crop, path length, filter, shading, references) and a study
of other settings is refused rather than mixed in.

The report (``DIR/study.md``, :func:`report`):

* per (scene, sampler, spp), the mean relMSE over seeds with its 95 %
  Student-t interval (:func:`pyoa.analysis.statistics.mean_ci`);
* the reference's own noise: a reference made by ``pyoa reference`` carries
  the per-pixel variance of its mean (``NAME.variance.exr``), and a relMSE
  measured against it is too large by about
  :func:`~pyoa.analysis.statistics.relmse_noise` of that variance; the
  tables give the measured mean minus that estimate (the interval shifts with
  it), and say so. A reference without a variance file is used as is, and
  the report says its noise is unknown;
* the slope of log error against log spp per sampler
  (:func:`~pyoa.analysis.statistics.fit_loglog`), and a headline: bose
  against the best padded 2D sampler and against sobol, as ratios of means
  with intervals (:func:`~pyoa.analysis.statistics.ratio_ci`).

Figures: ``DIR/study.png`` (every scene) and ``DIR/study-SCENE.png``, error
against spp on log-log axes with the intervals as bands, like the paper's
convergence plots.

References
----------
.. [1] W. Jarosz, A. Enayet, A. Kensler, C. Kilpatrick, P. Christensen,
   "Orthogonal Array Sampling for Monte Carlo Rendering", Computer Graphics
   Forum 38(4) (EGSR 2019).
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import os
import time
from contextlib import closing
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import catalogue
from .analysis.statistics import corrected, fit_loglog, mean_ci, ratio_ci, relmse_noise
from .atomic import atomic_path, check_writable
from .catalogue_types import MAX_SPP, MAX_UINT32, check_int

#: Samplers of a study by default: the paper's table (random, the padded 2D
#: samplers, bose, and the high-dimensional halton and sobol).
DEFAULT_SAMPLERS = ("random", "jittered2d", "cmj2d", "sobol02", "bose", "halton", "sobol")
#: Samplers that stratify pairs of dimensions and pad them (the paper's "(pad)";
#: pbrt-v4's zsobol and pmj02 pad their pairs the same way, docs/samplers.md).
PADDED = ("jittered2d", "cmj2d", "sobol02", "zsobol", "pmj02")
#: Columns of study.csv.
FIELDS = ("scene", "sampler", "spp_asked", "spp", "seed", "relmse", "relmse_crop", "mse", "seconds")
#: Version of study.json (a study of another version is not resumed).
STUDY_VERSION = 1
#: Most seeds per (scene, sampler, spp): a typo guard.
MAX_SEEDS = 1 << 16


def parse_list(text: str, what: str) -> list[str]:
    """A comma-separated option as a list of non-empty, distinct items, in order."""
    items = [t.strip() for t in str(text).split(",") if t.strip()]
    if not items:
        raise ValueError(f"{what} {text!r} names nothing; give a comma-separated list")
    return list(dict.fromkeys(items))


def parse_spp(text: str) -> list[int]:
    """``--spp 16,64,256`` as increasing distinct ints in [1, 2^24]."""
    out = []
    for t in parse_list(text, "--spp"):
        try:
            n = int(t)
        except ValueError:
            raise ValueError(f"--spp: {t!r} is not an integer; give counts such as 16,64,256,1024") from None
        out.append(check_int("--spp", n, 1, MAX_SPP, " (the samplers' limit, 2^24)"))
    return sorted(set(out))


def sampler_names(text: str) -> list[str]:
    """``--samplers`` as checked catalogue names (``all``: every sampler)."""
    names = catalogue.names() if str(text).strip() == "all" else parse_list(text, "--samplers")
    for n in names:
        catalogue.get(n)  # unknown names fail here, with the valid ones listed
    return names


@dataclass(frozen=True)
class Job:
    """One render of the study."""

    scene: str
    sampler: str
    spp_asked: int
    spp: int
    seed: int

    @property
    def ident(self) -> tuple:
        return (self.scene, self.sampler, self.spp_asked, self.seed)


def file_digest(path) -> str:
    """SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


# -- the study's directory: settings, rows ------------------------------------------------------


def check_out_dir(out) -> Path:
    """The study's directory: created if missing (its parent must exist);
    refused when it is a file or its files cannot be written."""
    d = Path(out)
    if d.exists() and not d.is_dir():
        raise ValueError(f"--out {str(out)!r} is a file; give a directory for study.csv, study.md and the figures")
    if not d.exists():
        if not d.parent.is_dir():
            raise ValueError(f"--out {str(out)!r}: its parent directory {str(d.parent)!r} does not exist")
        d.mkdir()
    for name in ("study.csv", "study.md", "study.png", "study.json"):
        try:
            check_writable(d / name)
        except OSError as exc:
            raise ValueError(f"--out: {exc}") from None
    return d


def check_settings(path: Path, settings: dict) -> dict:
    """The settings to save in ``study.json``: ``settings``, merged with a
    saved study's when every setting both have agrees; otherwise a
    ValueError naming the first difference (rows of other settings are
    never mixed in)."""
    if not path.exists():
        return settings
    try:
        saved = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise ValueError(f"{path} is not a study's settings ({type(exc).__name__}); remove it, or give another "
                         "--out") from None
    if not isinstance(saved, dict) or saved.get("version") != STUDY_VERSION:
        raise ValueError(f"{path} was written by another pyoa version; give another --out")
    for field in ("size", "crop", "max_depth", "filter", "shading"):
        if saved.get(field) != settings[field]:
            raise ValueError(f"{path.parent} holds a study made with {field} {saved.get(field)}, not "
                             f"{settings[field]}; give another --out to start a new study")
    scenes = dict(saved.get("scenes") or {})
    for name, s in settings["scenes"].items():
        old = scenes.get(name)
        if old is not None:
            for field, say in (("digest", "other scene contents"), ("reference", "another reference")):
                if old.get(field) is not None and s.get(field) is not None and old[field] != s[field]:
                    raise ValueError(f"{path.parent} holds {name} renders made with {say}; give another --out")
            s = {**old, **{k: v for k, v in s.items() if v is not None}}
        scenes[name] = s
    return {**settings, "scenes": scenes, "runs": list(saved.get("runs") or [])}


def write_settings(path: Path, settings: dict) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(settings, indent=1, sort_keys=True) + "\n")


def _row(raw: dict) -> dict | None:
    """A CSV row with its types, or None if it is not a complete row."""
    try:
        row = {"scene": raw["scene"], "sampler": raw["sampler"]}
        for k in ("spp_asked", "spp", "seed"):
            row[k] = int(raw[k])
        for k in ("relmse", "relmse_crop", "mse", "seconds"):
            row[k] = float(raw[k])
    except (KeyError, TypeError, ValueError):
        return None
    if not all(math.isfinite(row[k]) and row[k] >= 0 for k in ("relmse", "relmse_crop", "mse")):
        return None
    return row


def read_rows(path: Path) -> list[dict]:
    """The complete rows of ``study.csv``; a line cut short by an
    interruption is dropped, and the file rewritten without it. A file that
    is not a study's CSV is refused."""
    if not path.exists():
        return []
    text = path.read_text()
    lines = text.splitlines(keepends=True)
    if not lines:
        return []
    if lines[0].strip() != ",".join(FIELDS):
        raise ValueError(f"{path} is not a pyoa study's CSV (its header is not {','.join(FIELDS)}); give another "
                         "--out")
    rows, kept = [], [lines[0]]
    for line in lines[1:]:
        if not line.endswith("\n"):
            continue  # the last row, cut short when the study was killed
        raw = next(csv.DictReader(io.StringIO(lines[0] + line)), None)
        row = _row(raw) if raw else None
        if row is None:
            raise ValueError(f"{path}: a row that is not a study's: {line.strip()!r}; remove the file, or give "
                             "another --out")
        rows.append(row)
        kept.append(line)
    if len(kept) != len(lines):
        with atomic_path(path) as tmp:
            tmp.write_text("".join(kept))
    return rows


class RowWriter:
    """Appends rows to ``study.csv``, one flushed line each."""

    def __init__(self, path: Path):
        new = not path.exists() or path.stat().st_size == 0
        self.fh = open(path, "a", newline="")  # noqa: SIM115 - open for the whole study
        self.writer = csv.DictWriter(self.fh, fieldnames=FIELDS, lineterminator="\n")
        if new:
            self.writer.writeheader()
            self.fh.flush()

    def add(self, row: dict) -> None:
        self.writer.writerow({k: row[k] for k in FIELDS})
        self.fh.flush()
        os.fsync(self.fh.fileno())

    def close(self) -> None:
        self.fh.close()


# -- tasks ---------------------------------------------------------------------------------------


def study_task(scene, reference: np.ndarray, crop, kwargs: dict, job: Job, threads: int | None) -> dict:
    """One render of a study and its errors against ``reference``: a CSV row."""
    from .render.image import check_finite, rel_mse
    from .render.tiles import worker_render

    res = worker_render(scene, dict(kwargs, sampler=job.sampler, spp=job.spp, seed=job.seed), threads=threads)
    check_finite(res.image, f"the {job.sampler} render of {job.scene} ({job.spp} spp, seed {job.seed})")
    diff = res.image.astype(np.float64) - reference
    return dict(scene=job.scene, sampler=job.sampler, spp_asked=job.spp_asked, spp=job.spp, seed=job.seed,
                relmse=rel_mse(res.image, reference), relmse_crop=rel_mse(res.image, reference, crop),
                mse=float(np.mean(diff * diff)), seconds=round(res.seconds, 4))


# -- statistics and the report -------------------------------------------------------------------


@dataclass
class Cell:
    """The statistics of one (scene, sampler, spp asked): over its seeds."""

    spp: int
    seeds: int
    values: np.ndarray  # measured relMSE per seed
    crop_values: np.ndarray
    noise: float  # the reference's noise estimate (0 when unknown)
    crop_noise: float

    def ci(self, crop: bool = False) -> tuple[float, float, float]:
        """(mean, low, high) of the noise-corrected relMSE."""
        m, lo, hi = mean_ci(self.crop_values if crop else self.values)
        n = self.crop_noise if crop else self.noise
        return corrected(m, n), corrected(lo, n), corrected(hi, n)


def cells(rows: list[dict], noise: dict) -> dict:
    """``{scene: {sampler: {spp_asked: Cell}}}`` of the rows; ``noise`` maps
    a scene to its reference's (image, crop) noise estimate or None."""
    groups: dict = {}
    for r in rows:
        groups.setdefault(r["scene"], {}).setdefault(r["sampler"], {}).setdefault(r["spp_asked"], []).append(r)
    out: dict = {}
    for scene, by_sampler in groups.items():
        nz = noise.get(scene) or (0.0, 0.0)
        for name, by_spp in by_sampler.items():
            for asked, rs in sorted(by_spp.items()):
                out.setdefault(scene, {}).setdefault(name, {})[asked] = Cell(
                    spp=rs[0]["spp"], seeds=len(rs), values=np.array([r["relmse"] for r in rs]),
                    crop_values=np.array([r["relmse_crop"] for r in rs]), noise=nz[0], crop_noise=nz[1])
    return out


def slope(by_spp: dict, crop: bool = False) -> float:
    """Fitted slope of log(corrected mean relMSE) against log spp (the positive means)."""
    n = [c.spp for c in by_spp.values()]
    v = [c.ci(crop)[0] for c in by_spp.values()]
    return fit_loglog(n, v)[0]


def _fmt(m: float, lo: float, hi: float) -> str:
    if not math.isfinite(lo):
        return f"{m:.3g}"
    return f"{m:.3g} ± {(hi - lo) / 2:.2g}"


def _ratio(a: Cell, b: Cell) -> str:
    r, lo, hi = ratio_ci(a.values, b.values, shift_a=a.noise, shift_b=b.noise)
    if not math.isfinite(r):
        return "n/a"
    return f"{r:.2f} [{lo:.2f}, {hi:.2f}]" if math.isfinite(lo) else f"{r:.2f}"


def headline(table: dict) -> list[str]:
    """Markdown: per scene and spp, bose / the best padded sampler and bose / sobol."""
    lines = ["| scene | spp | best padded | bose / best padded | bose / sobol |", "|---|---:|---|---:|---:|"]
    any_row = False
    for scene, by_sampler in table.items():
        bose = by_sampler.get("bose", {})
        for asked, c in bose.items():
            padded = [(by_sampler[n][asked], n) for n in PADDED if asked in by_sampler.get(n, {})]
            best = min(padded, key=lambda cn: cn[0].ci()[0]) if padded else None
            sob = by_sampler.get("sobol", {}).get(asked)
            lines.append(f"| {scene} | {c.spp} | {best[1] + ' ' + str(best[0].spp) if best else '-'} | "
                         f"{_ratio(c, best[0]) if best else '-'} | {_ratio(c, sob) if sob else '-'} |")
            any_row = True
    return lines if any_row else []


def report(settings: dict, rows: list[dict], noise: dict, *, samplers=None, spp=None, seconds=None,
           where: str = "") -> str:
    """The Markdown report of a study (see the module docstring); ``seconds``
    the time of every run so far (``settings["runs"]``)."""
    table = cells(rows, noise)
    n_runs = len(settings.get("runs", []))
    runs = f" ({n_runs} runs: the first and its resumptions)" if n_runs > 1 else ""
    w, h = settings["size"]
    x, y, cw, ch = settings["crop"]
    lines = ["# Sampler study", "",
             f"{len(rows)} renders at {w} x {h}, crop {cw} x {ch} at ({x}, {y}); relMSE = mean of "
             "(image - ref)^2 / (ref^2 + 0.01) (the paper's measure). Each cell: the mean over seeds of the relMSE "
             "minus the reference's own noise estimate, ± the half-width of its 95 % Student-t interval over "
             "seeds. The slope is the least-squares fit of log(mean) against log(spp)." +
             (f" Rendered {where if where == 'in-process' else 'on ' + where}." if where else "") +
             (f" It took {seconds:.0f} s in all{runs}." if seconds is not None else ""), ""]
    for scene, by_sampler in table.items():
        s = settings["scenes"].get(scene, {})
        nz = noise.get(scene)
        ref = s.get("reference_name", "?")
        if nz is None:
            say = ("its own noise is unknown (no variance file beside it; references made with `pyoa reference` "
                   "have one), so the figures are not corrected")
        else:
            say = (f"its own noise adds an estimated {nz[0]:.2g} to every image relMSE and {nz[1]:.2g} to every "
                   f"crop relMSE (from the per-pixel variance of its {s.get('reference_passes', '?')} passes); "
                   "both are subtracted below")
        lines += [f"## {scene}", "", f"Reference `{ref}`: {say}.", ""]
        asked = sorted({a for by in by_sampler.values() for a in by})
        names = [n for n in (samplers or by_sampler) if n in by_sampler]
        for crop in (False, True):
            lines += [f"{'Crop' if crop else 'Image'} relMSE:", "",
                      "| sampler | " + " | ".join(f"{a} spp" for a in asked) + " | slope |",
                      "|---|" + "---:|" * (len(asked) + 1)]
            for n in names:
                by = by_sampler[n]
                cols = []
                for a in asked:
                    c = by.get(a)
                    if c is None:
                        cols.append("-")
                        continue
                    note = f" ({c.spp})" if c.spp != a else ""
                    cols.append(_fmt(*c.ci(crop)) + note)
                sl = slope(by, crop)
                lines.append(f"| {n} | " + " | ".join(cols) + f" | {sl:.2f} |" if math.isfinite(sl) else
                             f"| {n} | " + " | ".join(cols) + " | - |")
            lines.append("")
        seeds = sorted({c.seeds for by in by_sampler.values() for c in by.values()})
        lines += [f"Seeds per cell: {', '.join(map(str, seeds))}. A count in parentheses is the sampler's nearest "
                  "valid one, used instead of the column's.", ""]
    head = headline(table)
    if head:
        lines += ["## Headline", "",
                  "Ratios of noise-corrected mean image relMSE (below 1: bose is better), with 95 % intervals "
                  "(delta method over seeds); the best padded sampler is the one of " + ", ".join(PADDED) +
                  " with the lowest mean at that count.", "", *head, ""]
    return "\n".join(lines)


def plot(path, table: dict, scenes: list[str], samplers: list[str]) -> None:
    """Error against spp on log-log axes, one panel per scene, one line per
    sampler with its 95 % band (Matplotlib's Agg canvas, written atomically)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    scenes = [s for s in scenes if s in table]
    if not scenes:
        return
    cols = min(len(scenes), 2)
    rows_ = -(-len(scenes) // cols)
    fig = Figure(figsize=(6.0 * cols, 4.6 * rows_), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    # one colour per sampler, the same in every panel (tab10 repeats after 10)
    from matplotlib import colormaps

    colours = colormaps["tab20"].colors
    colour = {n: colours[(2 * k) % 20 + (2 * k) // 20 % 2] for k, n in enumerate(samplers)}
    for i, scene in enumerate(scenes):
        ax = fig.add_subplot(rows_, cols, i + 1)
        for name in samplers:
            by = table[scene].get(name)
            if not by:
                continue
            pts = sorted((c.spp, *c.ci()) for c in by.values())
            n = np.array([p[0] for p in pts], dtype=float)
            m = np.array([p[1] for p in pts])
            lo = np.array([p[2] for p in pts])
            hi = np.array([p[3] for p in pts])
            keep = m > 0
            if not keep.any():
                continue
            sl = slope(by)
            (line,) = ax.loglog(n[keep], m[keep], marker="o", ms=3, lw=1.2, color=colour[name],
                                label=f"{name} ({sl:.2f})" if math.isfinite(sl) else name,
                                ls="-" if name not in PADDED else "--")
            band = keep & np.isfinite(lo) & (lo > 0)
            if band.any():
                ax.fill_between(n[band], lo[band], hi[band], color=line.get_color(), alpha=0.18, lw=0)
        ax.set_title(scene)
        ax.set_xlabel("samples per pixel")
        ax.set_ylabel("relMSE (reference noise removed)")
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
        ax.legend(fontsize="x-small", title="sampler (slope)", title_fontsize="x-small")
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fig.savefig(fh, format="png")


# -- the command ---------------------------------------------------------------------------------


def _reference_noise(ref_path: Path, ref: np.ndarray, crop) -> tuple[float, float] | None:
    """(image, crop) noise estimates of a reference from its variance file, or None without one."""
    from .render.image import read_image
    from .render.reference import variance_path

    vp = variance_path(ref_path)
    if not vp.is_file():
        return None
    var = read_image(vp)[..., :3].astype(np.float64)
    if var.shape != ref.shape:
        raise ValueError(f"{vp} is {var.shape[1]} x {var.shape[0]}, its reference {ref.shape[1]} x "
                         f"{ref.shape[0]}: not this reference's variance; remove it")
    return relmse_noise(var, ref), relmse_noise(var, ref, crop)


def run(args) -> int:
    """``pyoa study`` (see the module docstring and ``pyoa study --help``)."""
    from .cluster import check_engine, engine, progress_over
    from .render.commands import _check_job_memory, _default_crop
    from .render.image import EXR, check_crop, check_output, read_reference
    from .render.reference import reference_key, render_reference
    from .render.render import plan, resolve_shading
    from .render.scene import load
    from .render.scene_source import source_of
    from .render.state import scene_digest
    from .render.state import state_path as reference_state

    t_start = time.perf_counter()
    scenes_arg = list(dict.fromkeys(args.scenes))
    names = sampler_names(args.samplers)
    spp_list = parse_spp(args.spp)
    seeds = check_int("--seeds", args.seeds, 1, MAX_SEEDS)
    seed0 = check_int("--seed", args.seed, 0, MAX_UINT32 - seeds + 1, " (the first of --seeds uint32 seeds)")
    if args.max_depth is not None:
        from .render.layout import MAX_DEPTH

        check_int("--max-depth", args.max_depth, 1, MAX_DEPTH)
    if args.size is not None:
        for n, v in zip(("W", "H"), args.size):
            check_int(f"--size {n}", v, 1)
    if args.reference and args.reference_spp is not None:
        raise ValueError("give --reference (existing images) or --reference-spp (render them), not both")
    if not args.reference and args.reference_spp is None:
        raise ValueError("a study needs references: --reference REF.exr per scene, or --reference-spp N to "
                         "render them (pyoa reference, e.g. 16384)")
    if args.reference and len(args.reference) != len(scenes_arg):
        raise ValueError(f"--reference gives {len(args.reference)} image(s) for {len(scenes_arg)} scene(s); give "
                         "one per scene, in the scenes' order")
    if args.reference_spp is not None:
        check_int("--reference-spp", args.reference_spp, 1)
        pass_spp = check_int("--pass-spp", min(args.pass_spp, args.reference_spp), 1, MAX_SPP)
        if args.reference_spp % pass_spp:
            raise ValueError(f"--reference-spp ({args.reference_spp}) must be a multiple of --pass-spp ({pass_spp})")
    check_engine(args.workers, args.scheduler)
    out = check_out_dir(args.out)
    shading = resolve_shading(args.shading)
    size = dict(width=args.size[0], height=args.size[1]) if args.size else dict(width=None, height=None)
    # plan() takes every render setting but the shading
    planned = dict(**size, max_depth=args.max_depth, filter=args.filter, first=None, backend=args.backend)
    common = dict(planned, shading=shading)
    # every check a long job could fail at its end, on the client, before any task
    loaded, jobs, refs = {}, [], {}
    dims = None
    for i, sname in enumerate(scenes_arg):
        scene = load(sname)
        if scene.name in loaded:
            raise ValueError(f"two scenes named {scene.name!r}; a study tells scenes apart by name")
        loaded[scene.name] = scene
        for name in names:
            for asked in spp_list:
                n = catalogue.nearest_spp(name, asked)
                if n is None:
                    raise ValueError(f"{name} has no valid sample count near {asked}")
                p = plan(scene, sampler=name, spp=n, seed=seed0, **planned)
                _check_job_memory(p, f"a {scene.name} render with {name} at {n} spp")
                dims = (p.width, p.height)
                jobs += [Job(scene.name, name, asked, n, seed0 + k) for k in range(seeds)]
        w, h = dims
        if args.reference:
            refs[scene.name] = Path(args.reference[i])
            read_reference(refs[scene.name], "--reference", w, h)
        else:
            refs[scene.name] = out / f"reference-{scene.name}.exr"
            check_output(refs[scene.name], "the study's reference", EXR)
    crop = tuple(args.crop) if args.crop else _default_crop((dims[1], dims[0]))
    check_crop(crop, *dims)
    settings = dict(version=STUDY_VERSION, size=list(dims), crop=list(crop), max_depth=args.max_depth,
                    filter=args.filter, shading=shading,
                    scenes={n: dict(digest=scene_digest(s), reference=None) for n, s in loaded.items()})
    settings = check_settings(out / "study.json", settings)
    rows = read_rows(out / "study.csv")
    for r in rows:
        if r["scene"] in loaded and settings["scenes"][r["scene"]].get("reference") is None:
            raise ValueError(f"{out / 'study.csv'} holds {r['scene']} rows but study.json no reference for "
                             "them; give another --out")
    with engine(args.workers, args.scheduler) as eng:
        where = eng.description
        # references first (resumable passes on the same engine)
        images, noise = {}, {}
        for name, scene in loaded.items():
            path = refs[name]
            if args.reference_spp is not None:
                saved = settings["scenes"][name]
                fresh = (path.is_file() and not reference_state(path).exists()
                         and saved.get("reference") == file_digest(path)
                         and saved.get("reference_spp") == args.reference_spp)
                if not fresh:
                    passes = args.reference_spp // pass_spp
                    p = plan(scene, sampler="sobol", spp=pass_spp, seed=0, **planned)
                    key = reference_key(scene, p, pass_spp=pass_spp, passes=passes, seed=0, filter=args.filter,
                                        shading=shading)
                    kwargs = dict(sampler="sobol", spp=pass_spp, **common)
                    if not args.quiet:
                        print(f"reference of {name}: {args.reference_spp} spp in {passes} passes on {where}")
                    render_reference(eng, scene, out=path, key=key, kwargs=kwargs, seed=0, quiet=args.quiet,
                                     command="pyoa study")
                settings["scenes"][name]["reference_spp"] = args.reference_spp
                settings["scenes"][name]["reference_passes"] = args.reference_spp // pass_spp
            images[name] = read_reference(path, "--reference", *dims).astype(np.float64)
            digest = file_digest(path)
            old = settings["scenes"][name].get("reference")
            if old is not None and old != digest and any(r["scene"] == name for r in rows):
                raise ValueError(f"{out} holds {name} renders measured against another reference; give another "
                                 "--out (or the reference they used)")
            noise[name] = _reference_noise(path, images[name], crop)
            shown = path.name if path.resolve().parent == out.resolve() else str(path)  # DIR's own: its name
            settings["scenes"][name].update(reference=digest, reference_name=shown,
                                            noise=list(noise[name]) if noise[name] else None)
        write_settings(out / "study.json", settings)
        done = {(r["scene"], r["sampler"], r["spp_asked"], r["seed"]) for r in rows}
        todo = [j for j in jobs if j.ident not in done]
        if not args.quiet:
            print(f"study: {len(jobs)} renders, {len(jobs) - len(todo)} already in {out / 'study.csv'}, "
                  f"{len(todo)} to render on {where}")
        shared = {n: (eng.share(s if eng.client is None else source_of(s)), eng.share(images[n]))
                  for n, s in loaded.items()}
        threads = eng.task_threads()
        kwargs = dict(common)
        args_list = [(*shared[j.scene], crop, kwargs, j, threads) for j in todo]
        writer = RowWriter(out / "study.csv")
        try:
            with closing(eng.run(study_task, args_list, key="pyoa-study")) as results:
                for _, row in progress_over(results, len(todo), "study", args.quiet, unit="render"):
                    writer.add(row)
                    rows.append(row)
        finally:
            writer.close()
    seconds = time.perf_counter() - t_start
    # what each run (the first and every resumption) rendered, where, and how long it took
    settings.setdefault("runs", []).append(dict(seconds=round(seconds, 1), where=where, rendered=len(todo),
                                                date=time.strftime("%Y-%m-%dT%H:%M:%S")))
    write_settings(out / "study.json", settings)
    wanted = {j.ident for j in jobs}
    mine = [r for r in rows if (r["scene"], r["sampler"], r["spp_asked"], r["seed"]) in wanted]
    # the report follows the command's order of scenes and samplers, not the order rows were rendered in
    # (a resumed study appends the rows it renders after the ones it found)
    place = {(s, n): k for k, (s, n) in enumerate((s, n) for s in loaded for n in names)}
    mine.sort(key=lambda r: (place.get((r["scene"], r["sampler"]), len(place)), r["spp_asked"], r["seed"]))
    md = report(settings, mine, noise, samplers=names, seconds=sum(r["seconds"] for r in settings["runs"]),
                where=where)
    with atomic_path(out / "study.md") as tmp:
        tmp.write_text(md)
    table = cells(mine, noise)
    plot(out / "study.png", table, list(loaded), names)
    for name in loaded:
        plot(out / f"study-{name}.png", table, [name], names)
    if not args.quiet:
        print(md)
        print(f"-> {out / 'study.md'}, {out / 'study.csv'}, {out / 'study.png'} ({seconds:.0f} s)")
    return 0


def add_parser(sub) -> None:
    """``pyoa study`` on the command line."""
    from .cluster import add_arguments
    from .render.render import SHADINGS

    p = sub.add_parser("study", help="error against spp over seeds, with confidence intervals (renders, CSV, "
                                     "report, figures)")
    p.add_argument("scenes", nargs="+", metavar="SCENE", help="bundled scene names or .json files")
    p.add_argument("--samplers", default=",".join(DEFAULT_SAMPLERS),
                   help=f"comma-separated sampler names, or all (default {','.join(DEFAULT_SAMPLERS)})")
    p.add_argument("--spp", default="16,64,256,1024",
                   help="comma-separated sample counts; a sampler without one uses its nearest valid count "
                        "(default 16,64,256,1024)")
    p.add_argument("--seeds", type=int, default=8, help="renders per (scene, sampler, spp), seeds --seed, "
                                                         "--seed+1, ... (default 8)")
    p.add_argument("--seed", type=int, default=0, help="first seed (default 0)")
    p.add_argument("--reference", nargs="+", default=None, metavar="REF.exr",
                   help="one reference image per scene, in the scenes' order")
    p.add_argument("--reference-spp", type=int, default=None, metavar="N",
                   help="render the references (pyoa reference, sobol passes) with N spp into DIR")
    p.add_argument("--pass-spp", type=int, default=256, help="samples per reference pass (default 256)")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), default=None, help="image size (default: "
                                                                                         "the scenes')")
    p.add_argument("--crop", type=int, nargs=4, metavar=("X", "Y", "W", "H"), default=None,
                   help="crop window (default: the quarter-size window at (W/4, H/4))")
    p.add_argument("--max-depth", type=int, default=None, help="longest path in segments (default: the scene's)")
    p.add_argument("--filter", choices=("box", "gaussian"), default="box", help="pixel filter (default box)")
    p.add_argument("--backend", choices=("opencl", "numpy"), default=None, help="sampler backend")
    p.add_argument("--shading", choices=SHADINGS, default=None, help="numba (default) or numpy")
    p.add_argument("--out", required=True, metavar="DIR", help="directory of study.csv, study.md, the figures "
                                                               "(and the references)")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing (the report is in DIR/study.md)")
    add_arguments(p)
    p.set_defaults(func=run)
