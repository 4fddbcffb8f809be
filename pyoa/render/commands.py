"""The renderer's commands: ``pyoa render``, ``pyoa compare`` and ``pyoa reference``."""

from __future__ import annotations

import csv
import io
import json
import os
from pathlib import Path

import numpy as np

from .. import constructions
from ..atomic import atomic_path
from ..cli import _rate
from .image import read_image, rel_mse, write_exr, write_png
from .render import SHADINGS, render
from .scene import load


def _size(args) -> dict:
    """``width``/``height`` keyword arguments of ``render`` from ``--size W H`` (None: the scene's)."""
    w, h = args.size or (None, None)
    return dict(width=w, height=h)


def _reference(path, shape):
    ref = read_image(path)[..., :3]
    if ref.shape != shape:
        raise ValueError(f"reference {path!r} is {ref.shape[1]} x {ref.shape[0]}, the render is "
                         f"{shape[1]} x {shape[0]}; render with --size {ref.shape[1]} {ref.shape[0]}")
    return ref


def cmd_render(args) -> int:
    scene = load(args.scene)
    res = render(scene, sampler=args.sampler, spp=args.spp, seed=args.seed,
                 **_size(args),
                 max_depth=args.max_depth, filter=args.filter, first=args.first, backend=args.backend,
                 shading=args.shading, progress=not args.quiet)
    write_exr(args.out, res.image)
    if args.png:
        write_png(args.png, res.image)
    if not args.quiet:
        h, w = res.image.shape[:2]
        print(f"{scene.name}: {w} x {h}, {res.sampler} {res.spp} spp, {res.dims} dims ({res.layout})")
        print(f"{res.seconds:.2f} s, {_rate(res.paths_per_second)}paths/s, {_rate(res.rays_per_second)}rays/s "
              f"-> {args.out}{' and ' + args.png if args.png else ''}")
    if args.reference:
        ref = _reference(args.reference, res.image.shape)
        line = f"relMSE {rel_mse(res.image, ref):.6g}"
        if args.crop:
            line += f", crop {rel_mse(res.image, ref, args.crop):.6g}"
        print(line)
    return 0


def cmd_compare(args) -> int:
    scene = load(args.scene)
    names = [n.strip() for n in args.samplers.split(",") if n.strip()]
    for n in names:
        constructions.get(n)  # unknown names fail before any rendering
    ref = None
    rows = []
    crops = []
    for name in names:
        spp = constructions.nearest_spp(name, args.spp)
        res = render(scene, sampler=name, spp=spp, seed=args.seed,
                     **_size(args),
                     max_depth=args.max_depth, filter=args.filter, first=args.first, backend=args.backend,
                     shading=args.shading, progress=not args.quiet)
        if ref is None:
            ref = _reference(args.reference, res.image.shape)
        crop = args.crop or _default_crop(res.image.shape)
        rows.append(dict(sampler=name, spp=spp, note="" if spp == args.spp else f"nearest valid to {args.spp}",
                         relmse=rel_mse(res.image, ref), relmse_crop=rel_mse(res.image, ref, crop),
                         seconds=round(res.seconds, 3)))
        x, y, w, h = crop
        crops.append((name, spp, res.image[y:y + h, x:x + w]))
        if not args.quiet:
            print(f"{name:12s} {spp:6d} spp  relMSE {rows[-1]['relmse']:.5g}  crop {rows[-1]['relmse_crop']:.5g}  "
                  f"({res.seconds:.1f} s)")
    md = markdown_table(scene.name, rows, crop)
    print(md)
    stem = Path(args.out)
    with atomic_path(stem.with_suffix(".md")) as tmp:
        tmp.write_text(md)
    with atomic_path(stem.with_suffix(".csv")) as tmp:
        buf = io.StringIO()
        wr = csv.DictWriter(buf, fieldnames=list(rows[0]))
        wr.writeheader()
        wr.writerows(rows)
        tmp.write_text(buf.getvalue())
    x, y, w, h = crop
    crop_figure(stem.with_suffix(".png"), crops, ref[y:y + h, x:x + w])
    if not args.quiet:
        print(f"-> {stem.with_suffix('.md')}, {stem.with_suffix('.csv')}, {stem.with_suffix('.png')}")
    return 0


def _default_crop(shape):
    h, w = shape[:2]
    return (w // 4, h // 4, max(1, w // 4), max(1, h // 4))


def markdown_table(scene: str, rows, crop) -> str:
    x, y, w, h = crop
    lines = [f"| sampler | spp | relMSE (image) | relMSE (crop {w}x{h} at {x},{y}) | note |",
             "|---|---:|---:|---:|---|"]
    for r in rows:
        lines.append(f"| {r['sampler']} | {r['spp']} | {r['relmse']:.5g} | {r['relmse_crop']:.5g} | {r['note']} |")
    return f"Scene `{scene}`; relMSE = mean of (image - ref)^2 / (ref^2 + 0.01)\n\n" + "\n".join(lines) + "\n"


def crop_figure(path, crops, ref_crop) -> None:
    """The crops side by side with the reference's, labelled (matplotlib), written atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .image import to_srgb8

    panels = [*crops, ("reference", None, ref_crop)]
    fig, axes = plt.subplots(1, len(panels), figsize=(2.2 * len(panels), 2.8), squeeze=False, layout="constrained")
    for ax, (name, spp, img) in zip(axes[0], panels):
        ax.imshow(to_srgb8(img), interpolation="nearest")
        ax.set_title(name if spp is None else f"{name}\n{spp} spp", fontsize=9)
        ax.axis("off")
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100)
    plt.close(fig)


#: Key of the reference passes' seeds (see pass_seed).
REFERENCE_KEY = 0x52454631


def pass_seed(seed: int, k: int) -> int:
    """Sampler seed of reference pass ``k``: a hash of (seed, k), so that no
    pass shares its scramble with a render made with a small seed (a
    reference rendered with seeds 0, 1, ... would share its first samples
    with ``pyoa compare --seed 0`` and flatter that sampler)."""
    from ..reference.hashes import hash_pair

    return hash_pair(seed, k, REFERENCE_KEY)


def cmd_reference(args) -> int:
    """Render a high-spp reference as the mean of passes with independent seeds;
    after every pass the running sum is saved (``OUT.state.npz``), so an
    interrupted run resumes where it stopped."""
    scene = load(args.scene)
    if args.spp % args.pass_spp:
        raise ValueError(f"--spp ({args.spp}) must be a multiple of --pass-spp ({args.pass_spp})")
    passes = args.spp // args.pass_spp
    state = Path(str(args.out) + ".state.npz")
    key = json.dumps(dict(scene=os.path.abspath(scene.path), size=args.size, max_depth=args.max_depth,
                          sampler=args.sampler, pass_spp=args.pass_spp, seed=args.seed, filter=args.filter))
    total, done = None, 0
    if state.exists():
        with np.load(state) as st:
            if str(st["key"]) == key:
                total, done = st["sum"], int(st["passes"])
                if not args.quiet:
                    print(f"resuming {state}: {done} of {passes} passes done")
    from tqdm.auto import tqdm

    for k in tqdm(range(done, passes), initial=done, total=passes, desc="reference passes", disable=args.quiet):
        res = render(scene, sampler=args.sampler, spp=args.pass_spp, seed=pass_seed(args.seed, k),
                     **_size(args),
                     max_depth=args.max_depth, filter=args.filter, backend=args.backend, shading=args.shading)
        img = res.image.astype(np.float64)
        total = img if total is None else total + img
        with atomic_path(state) as tmp:
            with open(tmp, "wb") as fh:
                np.savez(fh, sum=total, passes=k + 1, key=key)
    write_exr(args.out, (total / passes).astype(np.float32))
    state.unlink(missing_ok=True)
    if not args.quiet:
        print(f"reference: {passes} passes x {args.pass_spp} spp -> {args.out}")
    return 0


def add_parsers(sub) -> None:
    """Add ``render``, ``compare`` and ``reference`` to the ``pyoa`` command line."""

    def common(p, spp):
        p.add_argument("scene", help="a bundled scene name (cornell, dof7d, bounce9d, deep) or a .json file")
        p.add_argument("--spp", type=int, default=spp, help=f"samples per pixel (default {spp})")
        p.add_argument("--seed", type=int, default=0, help="sampler seed (default 0)")
        p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), default=None,
                       help="image size (default: the scene's)")
        p.add_argument("--max-depth", type=int, default=None,
                       help="longest path in segments, as Mitsuba's max_depth (default: the scene's)")
        p.add_argument("--filter", choices=("box", "gaussian"), default="box", help="pixel filter (default box)")
        p.add_argument("--first", type=lambda s: [t for t in s.split(",") if t], default=None,
                       help="integrand dimensions to put in the first sampler dimensions, e.g. light1,lens")
        p.add_argument("--backend", choices=("opencl", "numpy"), default=None, help="sampler backend")
        p.add_argument("--shading", choices=SHADINGS, default=None,
                       help="numba: compiled shading calling Embree (default); numpy: the NumPy reference "
                            "(default: $PYOA_SHADING, else numba)")
        p.add_argument("-q", "--quiet", action="store_true", help="print nothing but results")

    p = sub.add_parser("render", help="render a scene with one sampler (EXR, optional PNG)")
    common(p, 16)
    p.add_argument("--sampler", default="bose", help="sampler name (default bose)")
    p.add_argument("--out", default="render.exr", help="EXR output (default render.exr)")
    p.add_argument("--png", default=None, help="also write an sRGB PNG")
    p.add_argument("--reference", default=None, help="reference EXR: print the relative MSE")
    p.add_argument("--crop", type=int, nargs=4, metavar=("X", "Y", "W", "H"), default=None,
                   help="also the relative MSE of this window")
    p.set_defaults(func=cmd_render)

    p = sub.add_parser("compare", help="render with several samplers and tabulate relMSE against a reference")
    common(p, 121)
    p.add_argument("--samplers", default="random,jittered2d,cmj2d,sobol02,bose,halton,sobol",
                   help="comma-separated sampler names")
    p.add_argument("--reference", required=True, help="reference EXR (pyoa reference SCENE)")
    p.add_argument("--crop", type=int, nargs=4, metavar=("X", "Y", "W", "H"), default=None,
                   help="crop window (default: the quarter-size window at (W/4, H/4))")
    p.add_argument("--out", default="compare", help="output stem: STEM.md, STEM.csv, STEM.png (default compare)")
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser("reference", help="render a high-spp reference in resumable passes")
    common(p, 4096)
    p.add_argument("--sampler", default="sobol", help="sampler of each pass (default sobol)")
    p.add_argument("--pass-spp", type=int, default=256, help="samples per pass (default 256)")
    p.add_argument("--out", default="reference.exr", help="EXR output (default reference.exr)")
    p.set_defaults(func=cmd_reference)
