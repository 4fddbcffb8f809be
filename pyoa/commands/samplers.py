"""The commands about one sampler's points: ``pyoa points``, ``samplers``, ``spp``, ``plot``,
``spectrum`` and ``backends``."""

from __future__ import annotations

import argparse
import contextlib
import inspect
import time

import numpy as np

from .. import OFFSETS, backends, sampler, samplers, valid_spp
from ..analysis import error_spectrum
from ..analysis.integrands import INTEGRANDS
from ..util.atomic import atomic_path
from ..catalogue import get
from ..catalogue.entries import MAX_DIMS, MAX_UINT32, SppChoice, check_int
from ..plots import FIGURE_WIDTH
from ..samplers import TRIAL_RESOLUTION, trial_options
from ..util.units import format_rate
from .options import (DEFAULT_SPP, add_sampling_options, check_out, deprecated, figure_width, int_option,
                      resolve_spp, suffix)

FORMATS = (".npy", ".csv")
#: Values per block of CSV rows written at once (bounds the float64 table).
CSV_BLOCK_VALUES = 1 << 22
#: ``--resolution``'s help (points, plot, spectrum).
RESOLUTION_HELP = ("image size of a sampler that needs one (zsobol, zfaure; pixels row-major, y*W + x); "
                   "default 65536 65536")
#: ``pyoa spectrum``'s randomizations averaged and largest frequency shown, without --trials, --freq.
TRIALS, FREQ = 64, 48
#: ``pyoa spectrum --error``'s defaults: :func:`pyoa.analysis.error_spectrum`'s own.
ERROR_DEFAULTS = {name: p.default for name, p in inspect.signature(error_spectrum).parameters.items()
                  if name in ("size", "seeds", "integrand", "dims")}
#: The ranges :func:`pyoa.analysis.error_spectrum` takes (it checks them too, naming its keywords; the command
#: checks them first so that the message names the option as typed; tests/test_zfaure_cli.py holds them equal).
ERROR_LIMITS = {"size": (8, 1024), "seeds": (1, 1024), "dims": (1, 64)}


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
    with _default_image_named(args):
        smp = sampler(args.sampler, spp=args.spp, dims=args.dims, seed=args.seed,
                      **trial_options(args.sampler, options))
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
    if args.resolution is not None:
        opts["resolution"] = tuple(args.resolution)
    return opts


@contextlib.contextmanager
def _default_image_named(args):
    """A sampler that needs the image (zsobol, zfaure) and was given no ``--resolution`` reads its
    pixels in the default image, 65536 x 65536 (:data:`pyoa.samplers.TRIAL_RESOLUTION`, as every
    command's): where the sampler refuses that image (zfaure's 64-bit index at a large base and
    count), its message gains the option that chooses a smaller one."""
    try:
        yield
    except ValueError as exc:
        default = "{} x {}".format(*TRIAL_RESOLUTION)
        if args.resolution is None and get(args.sampler).needs_resolution and f"{default} image" in str(exc):
            raise ValueError(f"{exc} (no --resolution W H was given, so the image is the default {default}: "
                             "give a smaller one that holds the pixels read, row-major)") from None
        raise


def cmd_plot(args) -> int:
    from ..plots import projections

    args.spp = resolve_spp(args, args.sampler)
    with _default_image_named(args):
        projections(args.sampler, spp=args.spp, dims=args.dims, seed=args.seed, pixel=args.pixel, out=args.out,
                    size=figure_width(args), **_options(args))
    if not args.quiet:
        print(f"{args.sampler}, {args.spp} spp, {args.dims} dims -> {args.out}")
    return 0


def cmd_spectrum(args) -> int:
    if args.error:
        return _error_spectrum(args)
    from ..plots import spectrum

    _refuse_given(args, "of --error (the screen-space error spectrum); add --error", "integrand", "seeds")
    if args.size_old is not None:  # one value: the old spelling of --figure-width; W H is --error's image
        if len(args.size_old) != 1:
            raise ValueError(f"--size {' '.join(map(str, args.size_old))}: --size W H is the image of --error "
                             "(the screen-space error spectrum); the figure's width is --figure-width PX")
        args.size_old = args.size_old[0]
    if args.dims is not None and args.pair is not None:
        raise ValueError("give the pair of dimensions once, as --pair I,J (--dims is its old spelling)")
    if args.dims is not None and args.dims.strip().lstrip("+-").isdigit():  # a count: --error's
        raise ValueError(f"--dims {args.dims} counts dimensions (the integrand's, with --error); the projection's "
                         "pair is --pair I,J, two dimensions I,J such as 0,1")
    pair = args.pair or args.dims or "0,1"
    option = "--pair" if args.dims is None else "--dims (the old spelling of --pair)"
    try:
        i, j = (int(v) for v in pair.split(","))
    except ValueError:
        raise ValueError(f"{option} must be two dimensions I,J such as 0,1; got {pair!r}") from None
    if args.dims is not None:  # advised only once parsed, so that the advice is a valid --pair
        deprecated("spectrum", f"--dims {args.dims}", f"--pair {i},{j} (--dims is a count in every command)")
    args.spp = resolve_spp(args, args.sampler)
    trials = TRIALS if args.trials is None else args.trials
    freq = FREQ if args.freq is None else args.freq
    if args.resolution is not None and 0 < args.resolution[0] * args.resolution[1] < trials:
        w, h = args.resolution  # the figure's randomizations are pixels 0 .. trials-1 of the image
        raise ValueError(f"--resolution {w} {h} has {w * h} pixels; the spectrum averages --trials {trials} "
                         f"randomizations, pixels 0..{trials - 1}: give an image of at least {trials} pixels")
    with _default_image_named(args):
        _, radii, mean = spectrum(args.sampler, spp=args.spp, dims=(i, j), trials=trials, seed=args.seed,
                                  freq=freq, out=args.out, size=figure_width(args), **_options(args))
    if not args.quiet:
        low = mean[radii <= max(2, len(radii) // 8)].mean()
        print(f"{args.sampler}, {args.spp} spp, dims {i},{j}, {trials} trials: "
              f"mean low-frequency power {low:.3f} (white noise: 1) -> {args.out}")
    return 0


def _refuse_given(args, what: str, *names: str) -> None:
    """Refuse the first of the options ``names`` that was given: it is an option ``what`` says."""
    for name in names:
        if getattr(args, name) is not None:
            raise ValueError(f"--{name.replace('_', '-')} is an option {what}")


def _error_spectrum(args) -> int:
    """``pyoa spectrum SAMPLER --error``: :func:`pyoa.analysis.error_spectrum` of the sampler on a
    ``--size N N`` image, its figure (:func:`pyoa.plots.error_spectra`) and its table. Every option is
    checked, and named as typed, before the first sample; one not given takes the function's default."""
    from ..plots import error_spectra

    _refuse_given(args, "of the projection's spectrum, not of --error (whose image is --size N N)",
                  "pair", "trials", "freq", "offset", "jitter", "strength", "resolution")
    if args.device is not None:
        raise ValueError("--device is not taken with --error: the error spectrum runs on --backend's default "
                         "device ($PYOA_OPENCL_DEVICE chooses it)")
    given = {}
    if args.dims is not None:
        try:
            given["dims"] = int(args.dims)
        except ValueError:
            raise ValueError(f"--dims {args.dims}: with --error, --dims counts the integrand's dimensions (such "
                             "as 4); a pair I,J is the projection's (--pair, without --error)") from None
        check_int("--dims", given["dims"], *ERROR_LIMITS["dims"])
    if args.size_old is not None:  # the error image's W H (one value is the old spelling of --figure-width)
        if len(args.size_old) != 2:
            n = args.size_old[0]
            raise ValueError(f"--size {' '.join(map(str, args.size_old))}: with --error, --size is the error "
                             f"image's W H (square, such as --size {n} {n}); the figure's width is --figure-width PX")
        width, height = (check_int(f"--size {name}", v, *ERROR_LIMITS["size"])
                         for name, v in zip("WH", args.size_old))
        if width != height:
            side = max(width, height)
            raise ValueError(f"--size {width} {height}: the error image is square (its spectrum's rings are "
                             f"frequencies |k|); give --size N N, such as --size {side} {side}")
        given["size"], args.size_old = width, None
    if args.seeds is not None:
        given["seeds"] = check_int("--seeds", args.seeds, *ERROR_LIMITS["seeds"])
    seeds = given.get("seeds", ERROR_DEFAULTS["seeds"])
    check_int("--seed", args.seed, 0, MAX_UINT32 - seeds + 1, " (the first of --seeds uint32 seeds)")
    if args.integrand is not None:
        given["integrand"] = args.integrand  # an unknown name is refused with the valid ones, before sampling
    size = figure_width(args)
    check_out(args.out, (".png",))
    args.dims = given.get("dims")  # resolve_spp: the nearest valid count for this many dimensions
    args.spp = resolve_spp(args, args.sampler)
    res = error_spectrum(args.sampler, spp=args.spp, seed=args.seed, base=args.base, backend=args.backend, **given)
    error_spectra([res], out=args.out, size=size)
    if not args.quiet:
        print(res.table())
        print(f"-> {args.out}")
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
                        "prime >= dims if smaller); zfaure's is fixed by its count, spp = b^m")
    p.add_argument("--resolution", type=int, nargs=2, metavar=("W", "H"), default=None, help=RESOLUTION_HELP)
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

    def figure_options(p, out, size_help=argparse.SUPPRESS):
        p.add_argument("sampler", help="sampler name (see `pyoa samplers`)")
        p.add_argument("--spp", type=int, default=None, help=spp_help)
        p.add_argument("--seed", type=int, default=0, help="user seed (default 0)")
        p.add_argument("--offset", choices=OFFSETS, default=None, help="offset style of OA samplers")
        p.add_argument("--jitter", type=float, default=None, help="jitter amount in [0, 1]")
        p.add_argument("--strength", type=int, default=None, help="strength t (bush, cmjnd)")
        p.add_argument("--base", type=int, default=None,
                       help="faure's prime digit base; zfaure's is fixed by its count, spp = b^m")
        p.add_argument("--resolution", type=int, nargs=2, metavar=("W", "H"), default=None, help=RESOLUTION_HELP)
        add_sampling_options(p)
        p.add_argument("--figure-width", type=int, default=None, metavar="PX",
                       help=f"figure width in pixels (default {FIGURE_WIDTH})")
        if size_help is argparse.SUPPRESS:  # --size PX: only the old spelling of --figure-width
            p.add_argument("--size", type=int, dest="size_old", default=None, help=size_help)
        else:  # --size W H of an image; one value is still the old --figure-width
            p.add_argument("--size", type=int, nargs="+", dest="size_old", default=None, metavar="N",
                           help=size_help)
        p.add_argument("--out", default=out, help=f"PNG output (default {out})")
        p.add_argument("-q", "--quiet", action="store_true", help="print nothing")

    p = sub.add_parser("plot", help="plot every 2D projection of one pixel's point set (PNG)")
    figure_options(p, "projections.png")
    p.add_argument("--dims", type=int, default=6, help="dimensions, 2..16 (default 6)")
    p.add_argument("--pixel", type=int, default=0, help="pixel index (default 0)")
    p.set_defaults(func=cmd_plot)

    p = sub.add_parser("spectrum", help="expected power spectrum of a 2D projection, or with --error the "
                                        "screen-space error spectrum (PNG)")
    figure_options(p, "spectrum.png", size_help=(
        "with --error: the error image, N N (square, {1} to {2}; default {0} {0})".format(ERROR_DEFAULTS["size"],
                                                                                         *ERROR_LIMITS["size"])))
    p.add_argument("--pair", default=None, help="the two dimensions I,J of the projection (default 0,1)")
    p.add_argument("--trials", type=int, default=None, help=f"randomizations averaged (default {TRIALS})")
    p.add_argument("--freq", type=int, default=None, help=f"largest integer frequency shown (default {FREQ})")
    p.add_argument("--error", action="store_true", help=(
        "the screen-space error spectrum instead (pyoa.analysis.error_spectrum): each pixel of a --size N N image "
        "integrates --integrand over --dims dimensions with its own samples, and the figure shows the "
        "periodogram of the error image over --seeds seeds (white noise: 1; a dark centre is blue noise) "
        "and its radial mean; the table gives the low-frequency power and the per-pixel RMSE"))
    p.add_argument("--integrand", default=None, help=(
        f"with --error: the integrand, one of {', '.join(INTEGRANDS)} (default {ERROR_DEFAULTS['integrand']})"))
    p.add_argument("--dims", default=None, metavar="D", help=(
        "with --error: the integrand's dimensions, {} to {} (default {}); ".format(*ERROR_LIMITS["dims"],
                                                                                  ERROR_DEFAULTS["dims"]) +
        "I,J is the old spelling of --pair"))
    p.add_argument("--seeds", type=int, default=None, metavar="N", help=(
        f"with --error: independent images averaged, seeds --seed, --seed + 1, ... (default "
        f"{ERROR_DEFAULTS['seeds']})"))
    p.set_defaults(func=cmd_spectrum)

