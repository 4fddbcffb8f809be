"""The renderer's commands: ``pyoa render``, ``pyoa compare`` and ``pyoa reference``."""

from __future__ import annotations

import csv
import io
import math
import sys
from pathlib import Path

from .. import catalogue
from ..analysis.statistics import corrected, mean_ci, ratio_ci, relmse_noise
from ..util.atomic import atomic_path, check_not_inputs
from ..catalogue.entries import MAX_SPP, MAX_UINT32, check_int
from ..cluster import add_arguments as add_engine_arguments
from ..cluster import check_engine, engine
from ..util.units import format_interval, format_rate, format_ratio
from .options import DEFAULT_SPP, add_sampling_options, resolve_spp
from ..render.image import (
    EXR,
    PNG,
    check_crop,
    default_crop,
    check_finite,
    check_output,
    check_writable,
    read_reference,
    rel_mse,
    write_exr,
    write_png,
)
from ..render.layout import MAX_DEPTH
from ..render.progressive import check_progressive, render_progressive, state_path
from ..render.provenance import command_line, describe, printable
from ..render.reference import reference_key, reference_noise, render_reference, variance_path
from ..render.render import SHADINGS, check_job_memory, plan
from ..render.scene import load
from ..render.settings import RenderSettings, check_seeds
from ..render.state import check_state_file
from ..render.tiles import render_on

#: Most passes of ``pyoa reference``: pass seeds hash a uint32 pass index.
MAX_PASSES = MAX_UINT32 + 1


def _command(args) -> str | None:
    """The command line of this run (``pyoa.commands.main`` keeps it), for the images' headers."""
    argv = getattr(args, "argv", None)
    return None if argv is None else command_line(argv)


def _size(args) -> dict:
    """``width``/``height`` keyword arguments of ``render`` from ``--size W H`` (None: the scene's)."""
    w, h = args.size or (None, None)
    return dict(width=w, height=h)


def _check_counts(args, spp: bool = True) -> None:
    """Refuse out-of-range counts of the options every command shares, before
    anything is loaded or rendered (0 is refused, never read as a default)."""
    if spp:
        check_int("--spp", args.spp, 1, MAX_SPP, " (the samplers' limit, 2^24)")
    check_int("--seed", args.seed, 0, MAX_UINT32, " (a uint32)")
    if args.max_depth is not None:
        check_int("--max-depth", args.max_depth, 1, MAX_DEPTH)
    if args.size is not None:
        for name, v in zip(("W", "H"), args.size):
            check_int(f"--size {name}", v, 1)


def _settings(args, sampler: str, spp: int, seed: int | None = None, base: int | None = None) -> RenderSettings:
    """The render settings of a command's options (``--size``, ``--max-depth``, ``--filter``, ``--first``,
    ``--backend``, ``--device``, ``--shading``) for ``sampler`` at ``spp`` (``seed``: ``--seed`` unless given)."""
    return RenderSettings(sampler=sampler, spp=spp, seed=args.seed if seed is None else seed, **_size(args),
                          max_depth=args.max_depth, filter=args.filter, first=args.first, backend=args.backend,
                          device=args.device, shading=args.shading, base=base)


def _plan(scene, args, sampler: str, spp: int, seed: int | None = None, base: int | None = None):
    return plan(scene, _settings(args, sampler, spp, seed, base))


def cmd_render(args) -> int:
    args.spp = resolve_spp(args, args.sampler)
    _check_counts(args)
    if args.crop and not args.reference:
        raise ValueError("--crop needs --reference: it is the window of the relative MSE against it")
    if not args.progressive and (args.time is not None or args.resume):
        raise ValueError(f"{'--time' if args.time is not None else '--resume'} needs --progressive (a render that "
                         "writes its image after every doubling of the samples)")
    if args.progressive:
        if args.workers is not None or args.scheduler is not None:
            raise ValueError("--progressive runs in-process (each doubling builds on the last); drop --workers/"
                             "--scheduler, or render --spp N without --progressive on the cluster")
        check_progressive(args.sampler)
        if args.time is not None and not (math.isfinite(args.time) and args.time > 0):
            raise ValueError(f"--time must be a positive number of seconds, got {args.time}")
    check_output(args.out, "--out", EXR)
    if args.png:
        check_output(args.png, "--png", PNG)
    if args.progressive:
        check_state_file(state_path(args.out), "where a progressive render keeps its running sum")
    outputs = [("--out", args.out), ("--png", args.png)]
    if args.progressive:  # written at every doubling
        outputs.append(("--out (its running sum)", state_path(args.out)))
    check_not_inputs(outputs, _reference_inputs(args.reference))
    check_engine(args.workers, args.scheduler)
    scene = load(args.scene)
    p = _plan(scene, args, args.sampler, args.spp, base=args.base)
    check_job_memory(p, f"pyoa render of {p.width} x {p.height} at {p.sampler.spp} spp")
    ref = noise = None
    if args.reference:
        ref = read_reference(args.reference, "--reference", p.width, p.height)
        if args.crop:
            check_crop(args.crop, p.width, p.height)
        # read before the render: a bad variance file fails now, not after it
        noise = reference_noise(args.reference, ref[..., :3].astype("float64"), args.crop or (0, 0, p.width, p.height))
    if args.progressive:
        pres = render_progressive(scene, p.settings, out=args.out, png=args.png, time_budget=args.time,
                                  resume=args.resume, quiet=args.quiet, command=_command(args))
        image = pres.image
        if not args.quiet:
            base = f" (base {pres.base})" if pres.base else ""
            why = f", stopped by --time {args.time:g}" if pres.stopped_by_time else ""
            print(f"{printable(scene.name)}: {pres.sampler}{base} {pres.samples} of {pres.spp} spp{why}; this run "
                  f"{pres.samples - pres.resumed_from} samples in {pres.seconds:.2f} s -> {args.out}"
                  f"{' and ' + args.png if args.png else ''} (running sum in {state_path(args.out)})")
    else:
        with engine(args.workers, args.scheduler) as eng:
            res = render_on(eng, scene, p.settings, progress=not args.quiet)
        check_finite(res.image, f"--out {args.out!r} not written")  # before either file is written
        write_exr(args.out, res.image, describe(scene, p, kind="render", shading=res.shading,
                                                command=_command(args)))
        if args.png:
            write_png(args.png, res.image)
        image = res.image
        if not args.quiet:
            h, w = res.image.shape[:2]
            print(f"{printable(scene.name)}: {w} x {h}, {res.sampler} {res.spp} spp, {res.dims} dims ({res.layout})")
            where = "" if eng.client is None else f" on {eng.description}"
            if res.compiled is None:
                speed = f"{format_rate(res.paths_per_second)} paths/s, {format_rate(res.rays_per_second)} rays/s"
            elif res.stats.paths > res.compiled[1]:  # the first render after an install: its rate without the compile
                speed = (f"{res.compiled[0]:.1f} s of it compiling the renderer (once), "
                         f"{format_rate(res.steady_paths_per_second())} paths/s after")
            else:  # one batch: no rate to give apart from the compile
                speed = "most of it compiling the renderer (once; the next render is quicker)"
            print(f"{res.seconds:.2f} s{where}, {speed} -> {args.out}{' and ' + args.png if args.png else ''}")
    if ref is not None:
        print(relmse_line(image, ref, args.crop, noise, args.reference))
    return 0


def _reference_inputs(reference) -> list[tuple[str, object]]:
    """The files a command given ``--reference`` reads: the image and its variance file
    (:func:`~pyoa.render.reference.variance_path`), as :func:`pyoa.util.atomic.check_not_inputs` takes them."""
    if not reference:
        return []
    return [("--reference", reference), ("--reference's variance file", variance_path(reference))]


def relmse_line(image, ref, crop, noise, reference) -> str:
    """``pyoa render --reference``'s result: the relMSE (and the crop's), with the reference's own
    noise subtracted where its variance file gives it, and said where it does not."""
    line = f"relMSE {rel_mse(image, ref):.6g}"
    if crop:
        line += f", crop {rel_mse(image, ref, crop):.6g}"
    var = variance_path(reference).name
    if noise is None:
        return line + f" (the reference's own noise is unknown: no {var} beside it, as `pyoa reference` writes)"
    line += f"; less the reference's own noise (an estimated {noise[0]:.3g}"
    if crop:
        line += f", crop {noise[1]:.3g}"
    line += f", from {var}): {corrected(rel_mse(image, ref), noise[0]):.6g}"
    if crop:
        line += f", crop {corrected(rel_mse(image, ref, crop), noise[1]):.6g}"
    return line


def _compare_outputs(out: str) -> list[Path]:
    """STEM.md, STEM.csv and STEM.png of ``--out STEM``, each checked writable."""
    stem = Path(out)
    if stem.name in ("", ".", "..") or stem.is_dir():
        raise ValueError(f"--out {out!r} is a directory; give a stem such as {str(stem / 'compare')!r} "
                         "(writes STEM.md, STEM.csv, STEM.png)")
    paths = [stem.with_suffix(s) for s in (".md", ".csv", ".png")]
    for path in paths:
        check_writable(path, "--out")
    return paths


def cmd_compare(args) -> int:
    # "all": every sampler of the catalogue, as study reads it
    typed = (list(catalogue.names()) if args.samplers.strip().lower() == "all" else
             [n.strip() for n in args.samplers.split(",") if n.strip()])
    if not typed:
        raise ValueError(f"--samplers {args.samplers!r} names no sampler; give a comma-separated list such as "
                         "bose,sobol (see pyoa samplers)")
    # each sampler once (unknown names fail here, before any rendering): the tables show the catalogue's
    # name with an alias beside it, the CSV the catalogue's name
    labels = catalogue.labels(typed)
    names = list(labels)
    _check_counts(args)
    seeds = check_seeds(args.seed, args.seeds)
    md_path, csv_path, png_path = _compare_outputs(args.out)
    check_not_inputs([("--out", path) for path in (md_path, csv_path, png_path)], _reference_inputs(args.reference))
    if args.size is None:  # the reference fixes the size: it need not be repeated
        from ..render.image import image_info

        args.size = list(image_info(args.reference, "--reference")[:2])
    scene = load(args.scene)
    jobs = []
    for name in names:  # every sampler's render is checked before the first one starts
        spp = catalogue.nearest_spp(name, args.spp)
        p = _plan(scene, args, name, spp)
        check_job_memory(p, f"pyoa compare of {p.width} x {p.height} at {spp} spp ({name})")
        jobs.append((name, spp))
    ref = read_reference(args.reference, "--reference", p.width, p.height)
    crop = args.crop or default_crop(ref.shape)
    check_crop(crop, p.width, p.height)
    noise = reference_noise(args.reference, ref[..., :3].astype("float64"), crop)
    check_engine(args.workers, args.scheduler)
    rows = []
    crops = []
    with engine(args.workers, args.scheduler) as eng:
        for name, spp in jobs:
            for seed in seeds:
                rows.append(_compare_one(eng, scene, args, name, spp, seed, ref, crop, crops, labels[name]))
    md = markdown_table(scene.name, rows, crop, seeds=seeds, noise=noise, reference=args.reference,
                        asked=args.spp, labels=labels)
    with atomic_path(md_path) as tmp:  # the files first: printing cannot lose them (a closed pipe, Ctrl-C)
        tmp.write_text(md)
    with atomic_path(csv_path) as tmp:
        buf = io.StringIO()
        wr = csv.DictWriter(buf, fieldnames=list(rows[0]))
        wr.writeheader()
        wr.writerows(rows)
        tmp.write_text(buf.getvalue())
    compare_figure(png_path, crops, ref, crop)
    print(md)
    if not args.quiet:
        print(f"-> {md_path}, {csv_path}, {png_path}")
    return 0


def _compare_one(eng, scene, args, name: str, spp: int, seed: int, ref, crop, crops: list,
                 label: str | None = None) -> dict:
    """Render one sampler (its catalogue name ``name``, shown as ``label``) and seed of ``pyoa compare`` on
    ``eng``: its CSV row; what the figure shows of each sampler's first seed (:func:`figure_panels`) is
    appended to ``crops``."""
    label = label or name
    res = render_on(eng, scene, _settings(args, name, spp, seed), progress=not args.quiet)
    check_finite(res.image, f"the {name} render ({spp} spp, seed {seed})")  # a NaN relMSE is no answer
    row = dict(sampler=name, spp_asked=args.spp, spp=spp, seed=seed, relmse=rel_mse(res.image, ref),
               relmse_crop=rel_mse(res.image, ref, crop), seconds=round(res.seconds, 3))
    if seed == args.seed:
        crops.append((label, spp, figure_panels(res.image, ref, crop)))
    if not args.quiet:
        print(f"{label:12s} {spp:6d} spp  seed {seed:<4d} relMSE {row['relmse']:.5g}  crop {row['relmse_crop']:.5g}  "
              f"({res.seconds:.1f} s)")
    return row


def markdown_table(scene: str, rows: list[dict], crop, *, seeds: list[int], noise, reference, asked: int,
                   labels: dict | None = None) -> str:
    """The report of ``pyoa compare``: per sampler, the mean relMSE over seeds less the reference's own
    noise (:func:`~pyoa.render.reference.reference_noise`), with its 95 % Student-t interval
    (:func:`~pyoa.analysis.statistics.mean_ci`) and its ratio to the first sampler's
    (:func:`~pyoa.analysis.statistics.ratio_ci`), as ``pyoa study`` computes them. ``labels`` maps a
    row's sampler to the name the table shows (:func:`pyoa.catalogue.shown`; default: the row's)."""
    labels = labels or {}
    import numpy as np

    x, y, w, h = crop
    nz = noise or (0.0, 0.0)
    by: dict = {}
    for r in rows:
        by.setdefault(r["sampler"], []).append(r)
    first = next(iter(by))
    base = np.array([r["relmse"] for r in by[first]])
    seeds_say = (f"seed {seeds[0]}" if len(seeds) == 1 else
                 f"{len(seeds)} seeds ({seeds[0]}..{seeds[-1]}) per sampler")
    if noise is None:
        ref_say = (f"its own noise is unknown (no {variance_path(reference).name} beside it; references made "
                   "with `pyoa reference` have one), so the figures are not corrected")
    else:
        ref_say = (f"its own noise adds an estimated {nz[0]:.2g} to every image relMSE and {nz[1]:.2g} to every "
                   f"crop relMSE (from the per-pixel variance in {variance_path(reference).name}); both are "
                   "subtracted below")
    cells = ("Each cell: the mean over seeds" + (" minus that noise" if noise is not None else "") +
             ", ± the half-width of its 95 % Student-t interval" if len(seeds) > 1 else
             "Each cell: one render's relMSE" + (" minus that noise" if noise is not None else "") +
             " (one seed: no interval; give --seeds 2 or more for intervals)")
    lines = [f"Scene `{printable(scene)}`, {seeds_say}; relMSE = mean of (image - ref)^2 / (ref^2 + 0.01).", "",
             f"Reference `{Path(reference).name}`: {ref_say}.", "",
             f"{cells}. The ratio is the image relMSE's to {labels.get(first, first)}'s" +
             (" (below 1: less error), with its 95 % interval (delta method on the log ratio, Student's t)."
              if len(seeds) > 1 else " (below 1: less error)."), "",
             f"| sampler | spp | relMSE (image) | relMSE (crop {w}x{h} at {x},{y}) | "
             f"/ {labels.get(first, first)} | seconds |",
             "|---|---:|---:|---:|---:|---:|"]
    for name, rs in by.items():
        spp = rs[0]["spp"]
        spp_cell = f"{spp}" if spp == asked else f"{spp} ({asked} asked: nearest valid)"
        image = np.array([r["relmse"] for r in rs])
        crop_v = np.array([r["relmse_crop"] for r in rs])
        cells_ = []
        for v, n in ((image, nz[0]), (crop_v, nz[1])):
            m, lo, hi = mean_ci(v)
            cells_.append(format_interval(corrected(m, n), corrected(lo, n), corrected(hi, n)))
        ratio = "1" if name == first else format_ratio(*ratio_ci(image, base, shift_a=nz[0], shift_b=nz[0]))
        secs = sum(r["seconds"] for r in rs) / len(rs)
        lines.append(f"| {labels.get(name, name)} | {spp_cell} | {cells_[0]} | {cells_[1]} | {ratio} | {secs:.2f} |")
    return "\n".join(lines) + "\n"


#: Longest side of the full images in ``pyoa compare``'s figure (larger renders are shown block-averaged).
FIGURE_SIDE = 384


def _shrink(a, k: int):
    """``a`` (H, W, ...) averaged over k x k blocks (the edge rows and columns that do not fill a block
    dropped): what the figure shows of an image larger than :data:`FIGURE_SIDE`."""
    if k <= 1:
        return a
    h, w = (a.shape[0] // k) * k, (a.shape[1] // k) * k
    return a[:h, :w].reshape(h // k, k, w // k, k, *a.shape[2:]).mean(axis=(1, 3))


def figure_panels(image, ref, crop) -> tuple:
    """What ``pyoa compare``'s figure keeps of one render: the full image and its per-pixel relative squared
    error ``mean over channels of (I - R)^2 / (R^2 + 0.01)`` (the relMSE's terms), both shrunk to at most
    :data:`FIGURE_SIDE` pixels a side, and the crop at full resolution."""
    import numpy as np

    x, y, w, h = crop
    err = ((image.astype(np.float64) - ref) ** 2 / (ref.astype(np.float64) ** 2 + 1e-2)).mean(axis=2)
    k = max(1, -(-max(image.shape[:2]) // FIGURE_SIDE))
    return _shrink(image, k), _shrink(err, k), image[y:y + h, x:x + w], k


def compare_figure(path, panels, ref, crop) -> None:
    """``pyoa compare``'s PNG (:func:`comparison_figure`), written atomically."""
    fig = comparison_figure(panels, ref, crop)
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fig.savefig(fh, format="png")


def comparison_figure(panels, ref, crop):
    """``pyoa compare``'s figure (matplotlib's Agg canvas), as papers show sampler comparisons: per
    sampler (its first seed) the full image with the crop outlined, the crop at full resolution, and
    the per-pixel error map in false colour on one logarithmic scale for every sampler; the
    reference's image and crop in the last column, and the error maps' colour bar beside the last
    map, in the reference's empty error cell."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.colors import LogNorm
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    from ..render.image import to_srgb8

    x, y, w, h = crop
    k = panels[0][2][3] if panels else 1
    ref_full = _shrink(ref, k)
    errs = np.concatenate([p[2][1].ravel() for p in panels]) if panels else np.ones(1)
    pos = errs[errs > 0]
    lo, hi = (float(np.percentile(pos, 1)), float(np.percentile(pos, 99.5))) if pos.size else (1e-6, 1.0)
    norm = LogNorm(vmin=lo, vmax=max(hi, lo * 10))
    cols = len(panels) + 1
    fig = Figure(figsize=(2.4 * cols + 0.3, 7.4), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(3, cols, squeeze=False)
    shown = None
    for c, (name, spp, (full, err, crop_img, _)) in enumerate([*panels, ("reference", None, (ref_full, None,
                                                                                              ref[y:y + h, x:x + w], k))]):
        top, mid, bottom = axes[0][c], axes[1][c], axes[2][c]
        top.imshow(to_srgb8(full), interpolation="nearest")
        top.add_patch(Rectangle((x / k - 0.5, y / k - 0.5), w / k, h / k, fill=False, ec="yellow", lw=1))
        top.set_title(name if spp is None else f"{name}, {spp} spp", fontsize=9)
        mid.imshow(to_srgb8(crop_img), interpolation="nearest")
        if err is not None:
            shown = bottom.imshow(np.maximum(err, lo), norm=norm, cmap="magma", interpolation="nearest")
        for ax in (top, mid, bottom):
            ax.set_xticks([])
            ax.set_yticks([])
        if err is None:
            bottom.axis("off")
    axes[0][0].set_ylabel("image", fontsize=9)
    axes[1][0].set_ylabel(f"crop {w} x {h} at ({x}, {y})", fontsize=9)
    axes[2][0].set_ylabel("relative squared error", fontsize=9)
    if shown is not None:
        # The bar stands beside the last error map, as tall as it, in the reference's empty error cell: a
        # bar for the whole row took a margin of its own, right of that empty cell. Its place is given
        # in the map's axes units, so it follows the map's aspect; widths scale with a tall map's h / w.
        last = shown.axes
        eh, ew = shown.get_array().shape[:2]
        u = max(1.0, eh / ew)
        cax = last.inset_axes([1.0 + 0.04 * u, 0.0, 0.07 * u, 1.0])
        cax.set_in_layout(False)  # it and its label lie in the empty cell: no margin of their own
        fig.colorbar(shown, cax=cax, label="(I - R)^2 / (R^2 + 0.01)")
    return fig


#: ``pyoa reference``'s default --spp and --pass-spp; without them a sampler takes its valid pass count nearest
#: PASS_SPP, and the whole passes nearest REFERENCE_SPP (said on stderr), as ``render`` takes its --spp.
REFERENCE_SPP, PASS_SPP = 4096, 256


def cmd_reference(args) -> int:
    """Render a high-spp reference as the mean of passes with independent seeds
    (:mod:`pyoa.render.reference`); after every pass the running sums are
    saved (``OUT.state.npz``), so an interrupted run resumes where it stopped,
    in-process or on a cluster. A state of other settings, or one that does
    not hold a valid partial sum, is not resumed: the run starts over and says
    why. Besides OUT, writes OUT's per-pixel variance (``NAME.variance.exr``)."""
    _check_counts(args, spp=False)
    entry = catalogue.get(args.sampler)
    pass_given = args.pass_spp is not None
    if pass_given:  # a count given is exact: refused, naming the option, with the nearest valid ones
        check_int("--pass-spp", args.pass_spp, 1, MAX_SPP, " (the samplers' limit, 2^24)")
        try:
            entry.resolve(args.pass_spp, None, None)
        except ValueError as exc:
            raise ValueError(f"--pass-spp {args.pass_spp}: {exc}") from None
    else:  # the default, as render's --spp: the sampler's valid count nearest it, said on stderr
        args.pass_spp = resolve_spp(args, args.sampler, PASS_SPP, option="pass_spp")
    if args.spp is None:  # the default: the whole passes nearest REFERENCE_SPP samples
        args.spp = max(1, round(REFERENCE_SPP / args.pass_spp)) * args.pass_spp
        if args.spp != REFERENCE_SPP and not args.quiet:
            print(f"pyoa reference: {REFERENCE_SPP} samples are not whole passes of {args.pass_spp}; using "
                  f"{args.spp}, {args.spp // args.pass_spp} passes (give --spp to choose)", file=sys.stderr)
    check_int("--spp", args.spp, 1)
    if args.spp % args.pass_spp:
        default = "the default" if args.pass_spp == PASS_SPP else f"{entry.name}'s valid count nearest the default {PASS_SPP}"
        why = "" if pass_given else f", {default}; give --pass-spp, a valid count of {entry.name} that divides {args.spp}"
        raise ValueError(f"--spp ({args.spp}) must be a multiple of --pass-spp ({args.pass_spp}{why})")
    passes = args.spp // args.pass_spp
    check_int("--spp / --pass-spp (passes)", passes, 1, MAX_PASSES, " (pass seeds hash a uint32 index)")
    check_output(args.out, "--out", EXR)
    check_output(variance_path(args.out), "--out (its variance)", EXR)
    check_state_file(state_path(args.out), "where pyoa reference keeps its running sum")
    check_engine(args.workers, args.scheduler)
    scene = load(args.scene)
    check_not_inputs([("--out", args.out), ("--out (its variance)", variance_path(args.out)),
                      ("--out (its running sum)", state_path(args.out))], [("the scene file", scene.path)])
    p = _plan(scene, args, args.sampler, args.pass_spp)
    check_job_memory(p, f"pyoa reference of {p.width} x {p.height} at {args.pass_spp} spp per pass")
    key = reference_key(scene, p, pass_spp=args.pass_spp, passes=passes, seed=args.seed)
    settings = p.worker_settings()
    meta = describe(scene, p, kind="reference", command=_command(args), passes=passes, pass_spp=args.pass_spp)
    meta["spp"] = args.spp  # the reference's samples per pixel; the plan's is one pass's
    with engine(args.workers, args.scheduler) as eng:
        _, var = render_reference(eng, scene, out=args.out, key=key, settings=settings, seed=args.seed,
                                  quiet=args.quiet, metadata=meta)
    if not args.quiet:
        where = "" if eng.client is None else f" on {eng.description}"
        print(f"reference: {passes} passes x {args.pass_spp} spp{where} -> {args.out}")
        if var is not None:
            ref = read_reference(args.out, "--out", p.width, p.height)
            print(f"its own noise: relMSE {relmse_noise(var, ref):.3g} (per-pixel variance of the mean -> "
                  f"{variance_path(args.out)})")
    return 0


#: The order ``pyoa info`` prints an image's attributes in (others follow, sorted).
INFO_ORDER = ("kind", "command", "scene", "scene_file", "scene_sha256", "width", "height", "sampler", "spp",
              "seed", "base", "samples", "passes", "pass_spp", "max_depth", "filter", "shading", "layout",
              "renderer", "version", "git", "cpu")


def cmd_info(args) -> int:
    """``pyoa info FILE ...``: each image's size and what made it (:mod:`pyoa.render.provenance`)."""
    import json

    from ..render.image import image_info, read_attributes
    from ..render.provenance import json_value

    found = {}
    for path in args.files:  # every file is read before anything is printed: one bad name, one error
        found[path] = (image_info(path), read_attributes(path))
    if args.json:  # strict JSON (allow_nan=False): a foreign header's NaN is a string, never a bare NaN
        print(json.dumps({str(p): dict({k: json_value(v) for k, v in meta.items()}, width_px=info[0],
                                       height_px=info[1], channels=info[2])
                          for p, (info, meta) in found.items()}, indent=2, allow_nan=False))
        return 0
    # header strings (and file names) are anyone's: their control characters are printed escaped, so that
    # a newline cannot forge a line below and an ESC cannot drive the terminal
    for path, ((w, h, c, fmt), meta) in found.items():
        print(f"{printable(path)}: {w} x {h}, {c} channels ({printable(fmt)})")
        if not meta:
            print("  no pyoa metadata (not an image of pyoa render, reference or study, or one from before they "
                  "kept it)")
            continue
        keys = [k for k in INFO_ORDER if k in meta] + sorted(k for k in meta if k not in INFO_ORDER)
        width = max(len(printable(k)) for k in keys)
        for k in keys:
            print(f"  {printable(k):{width}s}  {printable(meta[k])}")
    return 0


def render_interrupted(args) -> str:
    """What an interrupted ``pyoa render`` leaves (:func:`pyoa.commands.main.main` prints it):
    a progressive render's last complete doubling, else nothing."""
    state = state_path(args.out)
    if args.progressive and state.is_file():
        return f"{args.out} and {state} hold the last complete doubling (continue with --resume)"
    return "nothing written (the image is written once it is complete)"


def reference_interrupted(args) -> str:
    """What an interrupted ``pyoa reference`` leaves (:func:`pyoa.commands.main.main` prints it): its finished passes."""
    state = state_path(args.out)
    if state.is_file():
        return f"the finished passes are kept in {state} (run the same command again to resume)"
    return "nothing written"


def add_parsers(sub) -> None:
    """Add ``render``, ``compare`` and ``reference`` to the ``pyoa`` command line."""

    def common(p, spp, spp_help=None, size_help="image size (default: the scene's)"):
        p.add_argument("scene", help="a bundled scene name (cornell, dof7d, bounce9d, deep) or a .json file")
        p.add_argument("--spp", type=int, default=spp, help=spp_help or f"samples per pixel (default {spp})")
        p.add_argument("--seed", type=int, default=0, help="sampler seed (default 0)")
        p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), default=None, help=size_help)
        p.add_argument("--max-depth", type=int, default=None,
                       help="longest path in segments, as Mitsuba's max_depth (default: the scene's)")
        p.add_argument("--filter", choices=("box", "gaussian"), default="box", help="pixel filter (default box)")
        p.add_argument("--first", type=lambda s: [t for t in s.split(",") if t], default=None,
                       help="integrand dimensions to put in the first sampler dimensions, e.g. light1,lens")
        add_sampling_options(p)
        p.add_argument("--shading", choices=SHADINGS, default=None,
                       help="numba: compiled shading calling Embree (default); numpy: the NumPy reference "
                            "(default: $PYOA_SHADING, else numba)")
        p.add_argument("-q", "--quiet", action="store_true", help="print nothing but results")
        add_engine_arguments(p)

    p = sub.add_parser("render", help="render a scene with one sampler (EXR, optional PNG)")
    common(p, None, f"samples per pixel (default {DEFAULT_SPP}, or the sampler's valid count nearest it)")
    p.add_argument("--sampler", default="bose", help="sampler name (default bose)")
    p.add_argument("--base", type=int, default=None,
                   help="faure's prime digit base (default: chosen from --spp and the scene's dimensions)")
    p.add_argument("--progressive", action="store_true",
                   help="write the image after every doubling of the samples (1, 2, 4, ..., --spp) and keep the "
                        "running sum in OUT.state.npz; progressive samplers only (faure, sobol, halton, ...)")
    p.add_argument("--time", type=float, default=None, metavar="SECONDS",
                   help="with --progressive: stop after the last doubling predicted to fit in SECONDS")
    p.add_argument("--resume", action="store_true",
                   help="with --progressive: continue OUT.state.npz (to a larger --spp too, for samplers whose "
                        "samples do not depend on --spp: faure, sobol, halton, pmj02, random)")
    p.add_argument("--out", default="render.exr", help="EXR output (default render.exr)")
    p.add_argument("--png", default=None, help="also write an sRGB PNG")
    p.add_argument("--reference", default=None, help="reference EXR: print the relative MSE")
    p.add_argument("--crop", type=int, nargs=4, metavar=("X", "Y", "W", "H"), default=None,
                   help="also the relative MSE of this window")
    p.set_defaults(func=cmd_render, interrupted=render_interrupted)

    p = sub.add_parser("compare", help="render with several samplers and tabulate relMSE against a reference")
    common(p, DEFAULT_SPP, f"samples per pixel (default {DEFAULT_SPP}); each sampler renders its valid count "
                           "nearest it, shown in the table",
           "image size (default: the reference's, and a --size that differs from it is refused)")
    p.add_argument("--samplers", default=",".join(catalogue.DEFAULT_SAMPLERS),
                   help=f"comma-separated sampler names, or all (default: bose and every comparison sampler, "
                        f"{','.join(catalogue.DEFAULT_SAMPLERS)})")
    p.add_argument("--reference", required=True, help="reference EXR (pyoa reference SCENE); its size is the "
                                                      "render's unless --size is given")
    p.add_argument("--crop", type=int, nargs=4, metavar=("X", "Y", "W", "H"), default=None,
                   help="crop window (default: the quarter-size window at (W/4, H/4))")
    p.add_argument("--seeds", type=int, default=1, metavar="N",
                   help="render each sampler with seeds --seed .. --seed+N-1 and report means with 95 %% "
                        "intervals (default 1: one render each, no interval)")
    p.add_argument("--out", default="compare", help="output stem: STEM.md, STEM.csv, STEM.png (default compare)")
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser("info", help="print what made an image: scene, sampler, spp, seed, settings, pyoa "
                                    "version and revision, CPU, command line (from its EXR header)")
    p.add_argument("files", nargs="+", metavar="FILE", help="images written by pyoa (EXR)")
    p.add_argument("--json", action="store_true", help="print one JSON object, keyed by file")
    p.set_defaults(func=cmd_info)

    p = sub.add_parser("reference", help="render a high-spp reference in resumable passes")
    common(p, None, f"samples per pixel (default {REFERENCE_SPP}, or the whole passes nearest it)")
    p.add_argument("--sampler", default="sobol", help="sampler of each pass (default sobol)")
    p.add_argument("--pass-spp", type=int, default=None,
                   help=f"samples per pass (default {PASS_SPP}, or the sampler's valid count nearest it)")
    p.add_argument("--out", default="reference.exr", help="EXR output (default reference.exr)")
    p.set_defaults(func=cmd_reference, interrupted=reference_interrupted)
