"""The commands about one sampler's points: ``pyoa points``, ``samplers``, ``spp``, ``plot``,
``spectrum`` and ``backends``."""

from __future__ import annotations

import argparse
import time

import numpy as np

from .. import OFFSETS, backends, sampler, samplers, valid_spp
from ..util.atomic import atomic_path
from ..catalogue import get
from ..catalogue.entries import MAX_DIMS, MAX_UINT32, SppChoice
from ..plots import FIGURE_WIDTH
from ..samplers import trial_options
from ..util.units import format_rate
from .options import (DEFAULT_SPP, add_sampling_options, check_out, deprecated, figure_width, int_option,
                      resolve_spp, suffix)

FORMATS = (".npy", ".csv")
#: Values per block of CSV rows written at once (bounds the float64 table).
CSV_BLOCK_VALUES = 1 << 22


def save_points(x: np.ndarray, path: str, pixels: range) -> None:
    """Save a ``(pixels, samples, dims)`` array atomically as .npy or .csv.

    The CSV has one row per (pixel, sample): ``pixel,sample,x0,...`` with
    values printed with 9 significant digits, enough to round-trip float32.
    """
    ext = suffix(path)
    if ext not in FORMATS:
        raise ValueError(f"--out must end in {' or '.join(FORMATS)}, got {path!r}")
    with atomic_path(path) as tmp:
        if ext == ".npy":
            np.save(tmp, x)
        else:
            n_p, n_s, n_d = x.shape
            with open(tmp, "w") as fh:
                fh.write(",".join(["pixel", "sample"] + [f"x{d}" for d in range(n_d)]) + "\n")
                fmt = "%d,%d" + ",%.9g" * n_d
                # A block of pixels at a time: the float64 table of the whole
                # array would need 2.5 times the memory generate was allowed.
                step = max(1, CSV_BLOCK_VALUES // (n_s * (n_d + 2)))
                for a in range(0, n_p, step):
                    b = min(a + step, n_p)
                    pix = np.repeat(np.asarray(pixels[a:b], dtype=np.int64), n_s)
                    smp = np.tile(np.arange(n_s), b - a)
                    table = np.column_stack([pix, smp, x[a:b].reshape((b - a) * n_s, n_d).astype(np.float64)])
                    np.savetxt(fh, table, fmt=fmt)


def _pixel_range(args) -> range:
    """``--pixel0`` and ``--pixels`` as the range of pixels (at least one, all uint32)."""
    pixel0 = int_option(args, "pixel0", 0, MAX_UINT32)
    count = int_option(args, "pixels", 1)
    if pixel0 + count > MAX_UINT32 + 1:
        raise ValueError(f"--pixels {count} from --pixel0 {pixel0} runs past the last pixel index {MAX_UINT32} "
                         f"(pixels are uint32); at most {MAX_UINT32 + 1 - pixel0} from there")
    return range(pixel0, pixel0 + count)


def _sampler_arg(args, default: str = "bose") -> str:
    """The sampler of ``pyoa points``: positional, or the old ``--sampler`` (with a note), else ``default``."""
    if args.sampler is not None and args.sampler_option is not None and args.sampler != args.sampler_option:
        raise ValueError(f"two samplers given: {args.sampler!r} and --sampler {args.sampler_option!r}; give one, "
                         f"first: pyoa points {args.sampler} ...")
    if args.sampler is None and args.sampler_option is not None:
        deprecated("points", f"--sampler {args.sampler_option}", f"pyoa points {args.sampler_option} ...")
        return args.sampler_option
    return args.sampler or default


def _seconds(t: float) -> str:
    """A duration to three significant digits: ``"0.497 ms"``, ``"12.3 ms"``, ``"2.448 s"``."""
    return f"{t * 1e3:.3g} ms" if t < 1 else f"{t:.3f} s"


def cmd_points(args) -> int:
    args.sampler = _sampler_arg(args)
    args.spp = resolve_spp(args, args.sampler)
    pixels = _pixel_range(args)
    check_out(args.out, FORMATS)
    options = {"offset": args.offset, "jitter": args.jitter, "strength": args.strength, "backend": args.backend,
               "device": args.device, "resolution": tuple(args.resolution) if args.resolution else None,
               "base": args.base}
    smp = sampler(args.sampler, spp=args.spp, dims=args.dims, seed=args.seed, **trial_options(args.sampler, options))
    # One value first: it pays the one-time costs (the backend's kernel build, a table such as pmj02's,
    # built once and cached), so that the rate below is the generation's alone, as render's is.
    t0 = time.perf_counter()
    smp.generate(pixels=pixels[:1], samples=range(1), dims=range(1))
    setup = time.perf_counter() - t0
    t0 = time.perf_counter()
    x = smp.generate(pixels=pixels, progress=not args.quiet)
    dt = time.perf_counter() - t0
    save_points(x, args.out, pixels)
    if not args.quiet:
        print(smp)
        print(f"{x.size:,} values ({x.shape[0]} pixel{'s' * (x.shape[0] != 1)} x {x.shape[1]} samples x {x.shape[2]} dims) "
              f"in {_seconds(dt)} ({format_rate(x.size / max(dt, 1e-9))} values/s), after {_seconds(setup)} of "
              f"one-time setup (kernels, tables) -> {args.out}")
    return 0


def cmd_samplers(args) -> int:
    names = samplers()
    width = max(map(len, names))
    for name, desc in names.items():
        print(f"{name:{width}s}  {desc}")
    return 0


def _in_base(name: str, choices, base: int, dims: int | None) -> list[SppChoice]:
    """``choices`` in the digit base ``base`` (``pyoa spp faure --base B``);
    a sampler without a base refuses it, with its own message, as
    :func:`pyoa.sampler` does."""
    entry = get(name)
    return [entry.choice(entry.with_base(entry.solve(c.spp, dims, None), base)) for c in choices]


def cmd_spp(args) -> int:
    int_option(args, "limit", 1)
    # named as options here (valid_spp names its keywords: near, dims, strength)
    for name in ("near", "dims", "strength"):
        if getattr(args, name) is not None:
            int_option(args, name, 0 if name == "near" else 1, MAX_DIMS if name == "dims" else None)
    # valid_spp refuses --near, --dims and --strength values the sampler cannot have
    choices = valid_spp(args.sampler, near=args.near, dims=args.dims, strength=args.strength)
    shown = choices[: args.limit]
    if args.base is not None:
        shown = _in_base(args.sampler, shown, args.base, args.dims)
    print("\n".join(get(args.sampler).spp_table(shown)))  # the columns of its family
    if len(choices) > args.limit:
        print(f"... {len(choices) - args.limit} more (use --near N or --limit)")
    return 0


def _options(args) -> dict:
    """The sampler options given on the command line (offset and jitter only when set)."""
    opts = {"backend": args.backend, "device": args.device}
    if args.offset is not None:
        opts["offset"] = args.offset
    if args.jitter is not None:
        opts["jitter"] = args.jitter
    if args.strength is not None:
        opts["strength"] = args.strength
    if args.base is not None:
        opts["base"] = args.base
    return opts


def cmd_plot(args) -> int:
    from ..plots import projections

    args.spp = resolve_spp(args, args.sampler)
    projections(args.sampler, spp=args.spp, dims=args.dims, seed=args.seed, pixel=args.pixel, out=args.out,
                size=figure_width(args), **_options(args))
    if not args.quiet:
        print(f"{args.sampler}, {args.spp} spp, {args.dims} dims -> {args.out}")
    return 0


def cmd_spectrum(args) -> int:
    from ..plots import spectrum

    if args.dims is not None and args.pair is not None:
        raise ValueError("give the pair of dimensions once, as --pair I,J (--dims is its old spelling)")
    pair = args.pair or args.dims or "0,1"
    option = "--pair" if args.dims is None else "--dims (the old spelling of --pair)"
    try:
        i, j = (int(v) for v in pair.split(","))
    except ValueError:
        raise ValueError(f"{option} must be two dimensions I,J such as 0,1; got {pair!r}") from None
    if args.dims is not None:  # advised only once parsed, so that the advice is a valid --pair
        deprecated("spectrum", f"--dims {args.dims}", f"--pair {i},{j} (--dims is a count in every command)")
    args.spp = resolve_spp(args, args.sampler)
    _, radii, mean = spectrum(args.sampler, spp=args.spp, dims=(i, j), trials=args.trials, seed=args.seed,
                              freq=args.freq, out=args.out, size=figure_width(args), **_options(args))
    if not args.quiet:
        low = mean[radii <= max(2, len(radii) // 8)].mean()
        print(f"{args.sampler}, {args.spp} spp, dims {i},{j}, {args.trials} trials: "
              f"mean low-frequency power {low:.3f} (white noise: 1) -> {args.out}")
    return 0


def cmd_backends(args) -> int:
    from ..util.hostcpu import host_cpu

    report = backends()  # first: a bad $PYOA_BACKEND is refused before anything is printed
    print(f"CPU: {host_cpu().describe()}")
    for b in report:
        mark = "*" if b["default"] else " "
        state = b["device"] if b["usable"] else f"not usable: {b['reason']}"
        print(f"{mark} {b['name']:7s} {state}")
        if not b["usable"] and b.get("fix"):
            print(f"          fix: {b['fix']}")
        for d in b.get("devices", []):
            verdict = ("works" + (" (used)" if d["used"] else "")) if d["works"] else f"fails: {d['reason']}"
            print(f"      device {d['selector']} {d['name']} ({d['kind']}) [{d['compiler']}]: {verdict}")
            if args.verbose and d["log"]:
                print("        " + "\n        ".join(d["log"].strip().splitlines()))
    print("(* = what backend=None picks; choose with PYOA_BACKEND, PYOA_OPENCL_DEVICE; "
          "--verbose shows the build log of a device that fails)")
    return 0



def add_parsers(sub) -> None:
    """The sampler commands' parsers on the subparsers ``sub`` of :func:`pyoa.commands.main.build_parser`."""
    spp_help = (f"samples per pixel (default {DEFAULT_SPP}, or the sampler's valid count nearest it)")
    p = sub.add_parser("points", help="generate a point set and save it (.npy or .csv)")
    p.add_argument("sampler", nargs="?", default=None, help="sampler name (see `pyoa samplers`; default bose)")
    p.add_argument("--sampler", dest="sampler_option", default=None, help=argparse.SUPPRESS)  # the old spelling
    p.add_argument("--spp", type=int, default=None, help=spp_help)
    p.add_argument("--dims", type=int, default=8, help="dimensions (default 8)")
    p.add_argument("--pixels", type=int, default=1, help="number of pixels (default 1)")
    p.add_argument("--pixel0", type=int, default=0, help="first pixel index (default 0)")
    p.add_argument("--seed", type=int, default=0, help="user seed in [0, 2^32) (default 0)")
    p.add_argument("--offset", choices=OFFSETS, default=None, help="offset style of OA samplers (default cmj)")
    p.add_argument("--jitter", type=float, default=1.0,
                   help="jitter amount in [0, 1] (OA samplers, jittered2d, cmj2d; default 1)")
    p.add_argument("--strength", type=int, default=None, help="strength t (bush, cmjnd)")
    p.add_argument("--base", type=int, default=None,
                   help="faure's prime digit base (default: the largest prime b with b^2 <= spp, or the smallest "
                        "prime >= dims if smaller)")
    p.add_argument("--resolution", type=int, nargs=2, metavar=("W", "H"), default=None,
                   help="image size of a sampler that needs one (zsobol; pixels row-major, y*W + x); "
                        "default 65536 65536")
    add_sampling_options(p)
    p.add_argument("--out", default="points.npy", help="output file, .npy or .csv (default points.npy)")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    p.set_defaults(func=cmd_points)

    p = sub.add_parser("samplers", help="list the samplers")
    p.set_defaults(func=cmd_samplers)

    p = sub.add_parser("spp", help="list a sampler's valid sample counts")
    p.add_argument("sampler", help="sampler name (see `pyoa samplers`)")
    p.add_argument("--near", type=int, default=None, help="only the valid counts nearest this one on both sides (and it, if valid)")
    p.add_argument("--dims", type=int, default=None,
                   help="only the counts that give this many dimensions (default: any)")
    p.add_argument("--strength", type=int, default=None,
                   help="only the counts of this strength t (bush, cmjnd; default: any)")
    p.add_argument("--base", type=int, default=None,
                   help="faure's prime digit base (default: each count's default base, given --dims)")
    p.add_argument("--limit", type=int, default=40, help="print at most this many (default 40)")
    p.set_defaults(func=cmd_spp)

    p = sub.add_parser("backends", help="report the usable backends and whether each OpenCL device works")
    p.add_argument("-v", "--verbose", action="store_true", help="print the whole build log of each device that fails")
    p.set_defaults(func=cmd_backends)

    def figure_options(p, out):
        p.add_argument("sampler", help="sampler name (see `pyoa samplers`)")
        p.add_argument("--spp", type=int, default=None, help=spp_help)
        p.add_argument("--seed", type=int, default=0, help="user seed (default 0)")
        p.add_argument("--offset", choices=OFFSETS, default=None, help="offset style of OA samplers")
        p.add_argument("--jitter", type=float, default=None, help="jitter amount in [0, 1]")
        p.add_argument("--strength", type=int, default=None, help="strength t (bush, cmjnd)")
        p.add_argument("--base", type=int, default=None, help="faure's prime digit base")
        add_sampling_options(p)
        p.add_argument("--figure-width", type=int, default=None, metavar="PX",
                       help=f"figure width in pixels (default {FIGURE_WIDTH})")
        p.add_argument("--size", type=int, dest="size_old", default=None, help=argparse.SUPPRESS)  # the old spelling
        p.add_argument("--out", default=out, help=f"PNG output (default {out})")
        p.add_argument("-q", "--quiet", action="store_true", help="print nothing")

    p = sub.add_parser("plot", help="plot every 2D projection of one pixel's point set (PNG)")
    figure_options(p, "projections.png")
    p.add_argument("--dims", type=int, default=6, help="dimensions, 2..16 (default 6)")
    p.add_argument("--pixel", type=int, default=0, help="pixel index (default 0)")
    p.set_defaults(func=cmd_plot)

    p = sub.add_parser("spectrum", help="expected power spectrum of a 2D projection (PNG)")
    figure_options(p, "spectrum.png")
    p.add_argument("--pair", default=None, help="the two dimensions I,J of the projection (default 0,1)")
    p.add_argument("--dims", default=None, help=argparse.SUPPRESS)  # the old spelling of --pair
    p.add_argument("--trials", type=int, default=64, help="randomizations averaged (default 64)")
    p.add_argument("--freq", type=int, default=48, help="largest integer frequency shown (default 48)")
    p.set_defaults(func=cmd_spectrum)

