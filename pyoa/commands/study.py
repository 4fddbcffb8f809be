"""``pyoa study``: the command line of :func:`pyoa.study.run_study`."""

from __future__ import annotations

from pathlib import Path

from .. import catalogue
from ..cluster import add_arguments
from ..render.provenance import command_line
from ..render.render import SHADINGS
from ..study import StudySettings, run_study
from .options import add_sampling_options


def cmd_study(args) -> int:
    """``pyoa study`` (see :mod:`pyoa.study` and ``pyoa study --help``)."""
    return run_study(StudySettings(
        scenes=tuple(args.scenes), out=args.out, samplers=args.samplers, spp=args.spp, seeds=args.seeds,
        seed=args.seed, reference=tuple(args.reference) if args.reference else None,
        reference_spp=args.reference_spp, pass_spp=args.pass_spp,
        size=tuple(args.size) if args.size else None, crop=tuple(args.crop) if args.crop else None,
        max_depth=args.max_depth, filter=args.filter, backend=args.backend, device=args.device,
        shading=args.shading, workers=args.workers, scheduler=args.scheduler, quiet=args.quiet,
        command=command_line(args.argv)))


def interrupted(args) -> str:
    """What an interrupted study leaves (:func:`pyoa.commands.main.main` prints it): the rows
    and reference passes already in DIR, which a rerun continues from."""
    out = Path(args.out)
    if (out / "study.csv").is_file() or any(out.glob("*.state.npz")):
        return f"the finished renders are kept in {out} (run the same command again to continue)"
    return "no render finished"


def add_parsers(sub) -> None:
    """``pyoa study`` on the subparsers ``sub`` of :func:`pyoa.commands.main.build_parser`."""

    p = sub.add_parser("study", help="error against spp over seeds, with confidence intervals (renders, CSV, "
                                     "report, figures)")
    p.add_argument("scenes", nargs="+", metavar="SCENE", help="bundled scene names or .json files")
    p.add_argument("--samplers", default=",".join(catalogue.DEFAULT_SAMPLERS),
                   help=f"comma-separated sampler names, or all (default: bose and every comparison sampler, "
                        f"{','.join(catalogue.DEFAULT_SAMPLERS)})")
    p.add_argument("--spp", default="16,64,256,1024",
                   help="comma-separated sample counts; a sampler without one uses its nearest valid count "
                        "(default 16,64,256,1024)")
    p.add_argument("--seeds", type=int, default=8, help="renders per (scene, sampler, spp), seeds --seed, "
                                                         "--seed+1, ... (default 8)")
    p.add_argument("--seed", type=int, default=0, help="first seed (default 0)")
    p.add_argument("--reference", action="append", default=None, metavar="SCENE=REF.exr",
                   help="the reference image of a scene; repeat it for each scene (REF.exr alone when the study "
                        "has one scene)")
    p.add_argument("--reference-spp", type=int, default=None, metavar="N",
                   help="render the references (pyoa reference, sobol passes) with N spp into DIR")
    p.add_argument("--pass-spp", type=int, default=256, help="samples per reference pass (default 256)")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), default=None,
                   help="image size (default: the references' when --reference is given, and a --size that "
                        "differs from theirs is refused; else the scenes')")
    p.add_argument("--crop", type=int, nargs=4, metavar=("X", "Y", "W", "H"), default=None,
                   help="crop window (default: the quarter-size window at (W/4, H/4))")
    p.add_argument("--max-depth", type=int, default=None, help="longest path in segments (default: the scene's)")
    p.add_argument("--filter", choices=("box", "gaussian"), default="box", help="pixel filter (default box)")
    add_sampling_options(p)
    p.add_argument("--shading", choices=SHADINGS, default=None, help="numba (default) or numpy")
    p.add_argument("--out", required=True, metavar="DIR", help="directory of study.csv, study.md, the figures "
                                                               "(and the references)")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing (the report is in DIR/study.md)")
    add_arguments(p)
    p.set_defaults(func=cmd_study, interrupted=interrupted)
