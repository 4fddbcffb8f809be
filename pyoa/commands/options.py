"""What every command shares: the default count, the sampling options, count and output checks.

One definition each, so that every command takes, checks and describes an
option alike (the conventions :data:`CONVENTION` states, ``pyoa --help``).
"""

from __future__ import annotations

import os
import sys

from ..util.atomic import check_writable
from ..catalogue import get, nearest_spp
from ..catalogue.entries import check_int
from ..plots import FIGURE_WIDTH
from ..plots import MAX_SIZE as MAX_FIGURE_WIDTH
from ..plots import MIN_SIZE as MIN_FIGURE_WIDTH


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
  --dims    always a number of dimensions (spectrum --error: its integrand's); spectrum's pair of
            dimensions is --pair I,J.
  --size    W H of an image (render, compare, reference, study, spectrum --error: square); compare
            and study take their reference's size when --size is not given, and refuse a --size
            that differs from it.
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
    dims = getattr(args, "dims", None)  # a count where the command has one (spectrum's old --dims is a pair)
    spp = nearest_spp(name, default, dims=dims if isinstance(dims, int) else None,
                      strength=getattr(args, "strength", None))
    if spp != default and not getattr(args, "quiet", False):
        print(f"pyoa {args.command}: {get(name).name} has no {default}-sample set; using its nearest valid count, "
              f"{spp} (give --{option.replace('_', '-')} to choose)", file=sys.stderr)
    return spp
def suffix(path: str) -> str:
    """The lower-case extension of ``path`` (``""`` when it has none)."""
    name = os.path.basename(str(path))
    return name[name.rfind("."):].lower() if "." in name else ""


def check_out(path: str, formats: tuple[str, ...], what: str = "--out") -> None:
    """Refuse, before any work, an output whose extension is not one of
    ``formats`` (what is written there) or that cannot be written."""
    if suffix(path) not in formats:
        raise ValueError(f"{what} must end in {' or '.join(formats)}, got {str(path)!r}")
    check_writable(path)


def int_option(args, name: str, lo: int | None = None, hi: int | None = None) -> int:
    """Command-line option ``--name`` checked as an int in ``[lo, hi]``."""
    return check_int(f"--{name.replace('_', '-')}", getattr(args, name), lo, hi)
