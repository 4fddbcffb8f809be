"""The ``pyoa`` command line.

``pyoa points``   generate a point set and save it (.npy or .csv)
``pyoa samplers`` list the samplers, ``pyoa spp NAME`` their valid sample counts
``pyoa backends`` report the usable backends and OpenCL devices
``pyoa plot``     every 2D projection of a point set; ``pyoa spectrum`` its power spectrum
``pyoa render``   render a scene (EXR/PNG); ``pyoa compare`` tabulate samplers'
                  relative MSE against a reference; ``pyoa reference`` render one
``pyoa study``    error against spp over seeds, with confidence intervals
(render, compare, reference and study run on a Dask cluster with
``--workers N`` or ``--scheduler ADDRESS``; in-process by default)

One convention for every command (:data:`CONVENTION`, printed by ``pyoa --help``).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

import numpy as np

from . import OFFSETS, backends, sampler, samplers, valid_spp
from .atomic import atomic_path, check_writable
from .backends import BackendUnavailable, PyoaFallbackWarning
from .catalogue import get
from .catalogue_types import MAX_DIMS, MAX_UINT32, SppChoice, check_int
from .cluster import TasksLost
from .plots import FIGURE_WIDTH
from .plots import MAX_SIZE as MAX_FIGURE_WIDTH
from .plots import MIN_SIZE as MIN_FIGURE_WIDTH
from .samplers import ENV_MAX_BYTES, trial_options

#: The samples per pixel of every command that is given no ``--spp`` (``pyoa reference`` aside).
DEFAULT_SPP = 121
#: How the commands name a sampler and take ``--spp`` and ``--dims`` (``pyoa --help`` prints it).
CONVENTION = f"""\
conventions, the same in every command:
  sampler   a command about one sampler's points names it first: pyoa points bose, plot bose,
            spectrum bose, spp bose; a command about a scene names the scene first and the sampler
            with --sampler (render, reference) or --samplers A,B,... (compare, study). pbrt and
            Mitsuba names (independent, stratified, orthogonal, ...) are accepted.
  --spp     samples per pixel; default {DEFAULT_SPP} (the paper's count), reference 4096. Without --spp a
            sampler that cannot have {DEFAULT_SPP} takes its nearest valid count and says so; a --spp you
            give is refused with the nearest valid counts, except by compare and study, which take
            each sampler's nearest and show it in their tables.
  --dims    always a number of dimensions; spectrum's pair of dimensions is --pair I,J.
  --size    W H of an image (render, compare, reference, study); compare and study take their
            reference's size when --size is not given, and refuse a --size that differs from it.
            A figure's width in pixels (plot, spectrum) is --figure-width PX.
  --reference  one image (render, compare); a study's, one per scene: --reference SCENE=FILE,
            repeated (FILE alone when the study has one scene), before or after the scenes.
  --backend, --device  taken by every command that generates samples (points, plot, spectrum,
            render, compare, reference, study): the sampler backend and OpenCL device.
  names     a table shows the catalogue's name of a sampler, with the name typed beside it when
            that was an alias: bose (orthogonal); CSV files and study.json store the catalogue's.
Old spellings (points --sampler X, spectrum --dims I,J, plot/spectrum --size PX) still work in this
release, with a note."""


def deprecated(command: str, old: str, new: str) -> None:
    """One line on stderr: ``old`` still works in this release; write ``new``."""
    print(f"pyoa {command}: note: {old} is deprecated and goes in the next release; write {new}", file=sys.stderr)


def add_sampling_options(p) -> None:
    """``--backend`` and ``--device`` on the parser of a command that generates samples (points, plot,
    spectrum, render, compare, reference, study): one definition, so every command takes and describes
    them alike. The values go to :func:`pyoa.sampler` (``backend=``, ``device=``), and every backend and
    device give the same bits."""
    p.add_argument("--backend", choices=("opencl", "numpy"), default=None,
                   help="sampler backend (default: $PYOA_BACKEND, else OpenCL when it works, else NumPy)")
    p.add_argument("--device", default=None, metavar="SELECTOR",
                   help="OpenCL device: gpu, cpu, P:D or part of its name, as pyoa backends lists them "
                        "(default: $PYOA_OPENCL_DEVICE, else the first that builds pyoa's kernels)")


def figure_width(args) -> int:
    """``--figure-width PX`` of plot and spectrum, or its old spelling ``--size PX`` (with a note)."""
    if args.size_old is not None and args.figure_width is not None and args.size_old != args.figure_width:
        raise ValueError(f"two figure widths given: --figure-width {args.figure_width} and --size "
                         f"{args.size_old}; give one, as --figure-width PX")
    if args.size_old is not None:
        check_int("--size", args.size_old, MIN_FIGURE_WIDTH, MAX_FIGURE_WIDTH, " (pixels)")
        deprecated(args.command, f"--size {args.size_old}",
                   f"--figure-width {args.size_old} (--size is W H of an image in every other command)")
        return args.size_old
    if args.figure_width is None:
        return FIGURE_WIDTH
    return check_int("--figure-width", args.figure_width, MIN_FIGURE_WIDTH, MAX_FIGURE_WIDTH, " (pixels)")


def resolve_spp(args, name: str, default: int = DEFAULT_SPP, option: str = "spp") -> int:
    """``--spp`` (or the count option ``option``, e.g. ``"pass_spp"``) as given, or without it the sampler's
    valid count nearest ``default`` (said on stderr when it is not ``default``, unless ``-q``)."""
    given = getattr(args, option)
    if given is not None:
        return given
    from .catalogue import nearest_spp

    dims = getattr(args, "dims", None)  # a count where the command has one (spectrum's old --dims is a pair)
    spp = nearest_spp(name, default, dims=dims if isinstance(dims, int) else None,
                      strength=getattr(args, "strength", None))
    if spp != default and not getattr(args, "quiet", False):
        print(f"pyoa {args.command}: {get(name).name} has no {default}-sample set; using its nearest valid count, "
              f"{spp} (give --{option.replace('_', '-')} to choose)", file=sys.stderr)
    return spp
from .units import format_rate

FORMATS = (".npy", ".csv")
#: Values per block of CSV rows written at once (bounds the float64 table).
CSV_BLOCK_VALUES = 1 << 22


def _suffix(path: str) -> str:
    """The lower-case extension of ``path`` (``""`` when it has none)."""
    name = os.path.basename(str(path))
    return name[name.rfind("."):].lower() if "." in name else ""


def check_out(path: str, formats: tuple[str, ...], what: str = "--out") -> None:
    """Refuse, before any work, an output whose extension is not one of
    ``formats`` (what is written there) or that cannot be written."""
    if _suffix(path) not in formats:
        raise ValueError(f"{what} must end in {' or '.join(formats)}, got {str(path)!r}")
    check_writable(path)


def _option(args, name: str, lo: int | None = None, hi: int | None = None) -> int:
    """Command-line option ``--name`` checked as an int in ``[lo, hi]``."""
    return check_int(f"--{name.replace('_', '-')}", getattr(args, name), lo, hi)


def save_points(x: np.ndarray, path: str, pixels: range) -> None:
    """Save a ``(pixels, samples, dims)`` array atomically as .npy or .csv.

    The CSV has one row per (pixel, sample): ``pixel,sample,x0,...`` with
    values printed with 9 significant digits, enough to round-trip float32.
    """
    suffix = _suffix(path)
    if suffix not in FORMATS:
        raise ValueError(f"--out must end in {' or '.join(FORMATS)}, got {path!r}")
    with atomic_path(path) as tmp:
        if suffix == ".npy":
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
    pixel0 = _option(args, "pixel0", 0, MAX_UINT32)
    count = _option(args, "pixels", 1)
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
    rebased = []
    for c in choices:
        prm = entry.with_base(entry.solve(c.spp, dims, None), base)
        rebased.append(SppChoice(c.spp, prm.s, prm.strength, prm.block_dims, entry.detail(prm)))
    return rebased


def cmd_spp(args) -> int:
    _option(args, "limit", 1)
    # named as options here (valid_spp names its keywords: near, dims, strength)
    for name in ("near", "dims", "strength"):
        if getattr(args, name) is not None:
            _option(args, name, 0 if name == "near" else 1, MAX_DIMS if name == "dims" else None)
    # valid_spp refuses --near, --dims and --strength values the sampler cannot have
    choices = valid_spp(args.sampler, near=args.near, dims=args.dims, strength=args.strength)
    shown = choices[: args.limit]
    if args.base is not None:
        shown = _in_base(args.sampler, shown, args.base, args.dims)
    if get(args.sampler).family == "oa":
        print(f"{'spp':>9s} {'s':>5s} {'t':>3s} {'dims/block':>10s}")
        for c in shown:
            print(f"{c.spp:9d} {c.s:5d} {c.strength:3d} {c.block_dims:10d}")
    elif get(args.sampler).family == "progressive":  # any count; the base of each (given or default)
        # full nets b^m: the largest m with b^m <= spp (aligned blocks of b^m samples are nets)
        print(f"{'spp':>9s} {'base':>5s} {'full nets':>10s} {'dims/block':>10s}")
        for c in shown:
            print(f"{c.spp:9d} {c.s:5d} {f'{c.s}^{c.strength}':>10s} {c.block_dims:10d}")
    else:  # comparison samplers: their grid (if any) instead of s and t
        print(f"{'spp':>9s} {'grid':>11s}")
        for c in shown:
            print(f"{c.spp:9d} {c.detail or '-':>11s}")
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
    from .plots import projections

    args.spp = resolve_spp(args, args.sampler)
    projections(args.sampler, spp=args.spp, dims=args.dims, seed=args.seed, pixel=args.pixel, out=args.out,
                size=figure_width(args), **_options(args))
    if not args.quiet:
        print(f"{args.sampler}, {args.spp} spp, {args.dims} dims -> {args.out}")
    return 0


def cmd_spectrum(args) -> int:
    from .plots import spectrum

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
    from .hostcpu import host_cpu

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


class _Parser(argparse.ArgumentParser):
    """argparse's parser with its usage errors in one line, as every other refusal
    (``pyoa render: error: unrecognized arguments: --bogus; see pyoa render --help``), not the usage
    block first; exit status 2 as before."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message}; see {self.prog} --help\n")


def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    ap = _Parser(prog="pyoa", description="Orthogonal-array sampling for Monte Carlo rendering.",
                 epilog=CONVENTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--version", action="version", version=f"pyoa {__version__}")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    ap.set_defaults(commands=sub.choices)  # _main: an unknown option is refused by its command's parser

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

    from .render.commands import add_parsers
    from .study import add_parser as add_study_parser

    add_parsers(sub)
    add_study_parser(sub)
    return ap


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """pyoa's own fallback warning as its two plain lines (no file name or
    source line: on the command line they point into pyoa, not at the user)."""
    if issubclass(category, PyoaFallbackWarning):
        print(message, file=sys.stderr if file is None else file)
    else:
        print(warnings.formatwarning(message, category, filename, lineno, line), end="",
              file=sys.stderr if file is None else file)


def _open_closed_streams() -> None:
    """Standard output or error closed when pyoa started (``pyoa ... >&-``): Python makes it None, and
    the command would fail at its first message with nothing written. Its descriptor gets /dev/null
    instead, so that the command runs as with that output discarded, and no file the command opens
    takes descriptor 1 or 2 (where a worker process's output would land in it)."""
    for fd, name in ((1, "stdout"), (2, "stderr")):
        if getattr(sys, name) is not None:
            continue
        try:
            os.fstat(fd)
        except OSError:  # closed: /dev/null takes its number
            devnull = os.open(os.devnull, os.O_WRONLY)
            if devnull != fd:
                os.dup2(devnull, fd)
                os.close(devnull)
        setattr(sys, name, open(fd, "w", closefd=False))  # noqa: SIM115 - the process's own stream


class _ReaderMayLeave:
    """``sys.stdout`` or ``sys.stderr`` while a command runs. When the reader of the pipe has gone
    (``pyoa compare ... | head -1``), or the stream cannot be written (``> /dev/full``), the rest of
    what is written goes to /dev/null and the command carries on, so that the work it finishes still
    reaches its files (the error would end it with nothing written); :func:`main` then ends with the
    status of a tool that SIGPIPE ends, or with one line naming the stream's error."""

    def __init__(self, stream):
        self.stream = stream
        #: whether the reader has gone
        self.gone = False
        #: an error other than a closed pipe met while writing (``ENOSPC``...), said at the end
        self.error: OSError | None = None

    def __getattr__(self, name):
        return getattr(self.stream, name)

    def _guarded(self, call, *args):
        try:
            return call(*args)
        except OSError as exc:
            if isinstance(exc, BrokenPipeError):
                self.gone = True
            elif self.error is None:
                self.error = exc
            # the stream's descriptor goes to /dev/null, so that what is still buffered, and Python's flush
            # at exit, do not fail again (https://docs.python.org/3/library/signal.html#note-on-sigpipe)
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, self.stream.fileno())
            os.close(devnull)
            return call(*args)

    def write(self, text: str) -> int:
        return self._guarded(self.stream.write, text)

    def flush(self) -> None:
        self._guarded(self.stream.flush)


def main(argv: list[str] | None = None) -> int:
    """``pyoa ARGS``: run the command, with a one-line message and status 2 for what it refuses. A
    closed standard output (``| head``) neither stops the command nor makes it say anything: it
    finishes, writes its files and ends with 141 = 128 + SIGPIPE, as a shell reports a tool whose
    reader left. Standard output that cannot be written (a full disk) does not stop it either; it
    ends with one line naming that error and status 2. A stream closed from the start (``>&-``)
    reads as /dev/null."""
    _open_closed_streams()
    out, err = _ReaderMayLeave(sys.stdout), _ReaderMayLeave(sys.stderr)
    sys.stdout, sys.stderr = out, err
    ran: dict = {}
    try:
        status = _main(argv, ran)
    finally:
        out.flush()  # what is still buffered meets a closed pipe here, not in Python's flush at exit
        err.flush()
        sys.stdout, sys.stderr = out.stream, err.stream
    if out.error is not None and not status:
        print(f"pyoa {ran.get('command', '')}: error: cannot write standard output: {out.error.strerror or out.error}"
              " (the command ran to its end; only what it printed is lost)", file=sys.stderr)
        return 2
    return 128 + 13 if out.gone and not status else status  # 13: SIGPIPE


def _main(argv: list[str] | None, ran: dict) -> int:
    ap = build_parser()
    args, unknown = ap.parse_known_args(argv)
    if unknown:  # the command's parser says it, naming the command (the top-level one would say "pyoa")
        args.commands[args.command].error(f"unrecognized arguments: {' '.join(unknown)}")
    ran["command"] = args.command
    args.argv = list(sys.argv[1:] if argv is None else argv)  # what made an image goes into its header
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _show_warning
            return args.func(args)
    except (ValueError, TypeError, OSError, BackendUnavailable, TasksLost) as exc:  # ClusterUnavailable: ValueError
        # OSError: an output that cannot be written (pyoa.atomic names the
        # user's path), a missing input file; a one-line message, not a traceback
        ap.exit(2, f"pyoa {args.command}: error: {exc}\n")
    except MemoryError as exc:
        # the memory plans refuse a job over $PYOA_MAX_BYTES before it starts, but they are estimates, and
        # the process may be allowed less than the limit (ulimit -v, a container)
        first = (str(exc).strip().splitlines() or [""])[0]
        ap.exit(2, f"pyoa {args.command}: error: out of memory{f' ({first})' if first else ''}: this job needs more "
                   "memory than the process may use; render a smaller scene, image or sample count, or set "
                   f"${ENV_MAX_BYTES} to the memory available so that such a job is refused before it "
                   "starts\n")
    except KeyboardInterrupt:
        # Ctrl-C, or SIGINT from a job manager: every output is written atomically (pyoa.atomic), so none is
        # left half-written; a command's ``interrupted(args)`` says what it kept. 130 = 128 + SIGINT, as a shell
        # reports a process that SIGINT ended.
        kept = getattr(args, "interrupted", None)
        note = kept(args) if kept else "no output is left half-written (each is replaced only by a complete one)"
        ap.exit(130, f"pyoa {args.command}: interrupted; {note}\n")


if __name__ == "__main__":
    sys.exit(main())
