"""Compiler flags for pyoa's portable C headers, as ``numpy-config`` or
``pybind11 --includes`` give theirs::

    cc -std=c99 -O2 $(python -m pyoa.config --cflags) my_renderer.c $(python -m pyoa.config --libs)

``--cflags`` prints ``-I<folder>``, the folder of :func:`pyoa.get_include`
(``#include <pyoa/sampler.h>`` then resolves), and nothing else. ``--libs``
prints ``-lm``: pyoa is header-only (no library of its own), but its
headers call the C maths library's ``fmaf``, which some builds (``-O0``)
leave to libm. The headers keep their float results
bit-exact by themselves (``pyoa/config.h``: no FMA contraction, correctly
rounded division, CUDA's ``__f*_rn`` intrinsics), so no flag is needed for
that. ``--include`` prints the bare folder (quote it where the path may hold
spaces: ``-I"$(python -m pyoa.config --include)"``), and ``--write-pkg-config
DIR`` writes ``DIR/pyoa.pc`` with the same Cflags, for build systems that ask
pkg-config (``PKG_CONFIG_PATH=DIR pkg-config --cflags pyoa``).

Flags a build must NOT add, because they change pyoa's bits (docs/spec.md
section 7; :data:`FORBIDDEN_FLAGS` lists them, with the reason, for ``--help``):
value-unsafe float optimisations (``-ffast-math``, ``-Ofast``,
``-funsafe-math-optimizations``, ``-fassociative-math``,
``-freciprocal-math``; MSVC's ``/fp:fast``, which the headers refuse), a
change of the rounding mode (``fesetround`` at run time: conversions and
operations assume round-to-nearest), and x87 arithmetic (``-mfpmath=387``, or
``-m32`` without SSE2: the headers refuse it with ``#error``). Clang's
``-ffp-contract=fast`` also fuses across the headers' ``FP_CONTRACT OFF``
pragma, so it is refused too; GCC's (and GCC's GNU modes, which default to
it) is harmless, because the headers turn contraction off with a pragma GCC
honours (tests/test_c_headers.py proves it). nvcc needs no flag:
``--fmad``, ``--prec-div`` and ``--use_fast_math`` do not touch the
``__f*_rn`` intrinsics.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .c_headers import get_include

#: what the headers need at link time: libm (fmaf, through PYOA_FMA in pyoa/floats.h).
LIBS = "-lm"

#: flag -> why it breaks bit-exactness with pyoa's reference (shown by --help).
FORBIDDEN_FLAGS = {
    "-ffast-math / -Ofast": "reassociates, contracts and flushes floats (value-unsafe)",
    "-funsafe-math-optimizations, -fassociative-math, -freciprocal-math": "reorder or replace float operations",
    "-ffp-contract=fast (clang)": "clang then fuses a * b + c into an FMA despite the headers' pragma",
    "-mfpmath=387, -m32 without -msse2": "x87 rounds to a wider format (the headers stop with #error)",
    "/fp:fast (MSVC)": "the headers stop with #error; use /fp:precise",
}

PC_FILE = "pyoa.pc"


def cflags() -> str:
    """The compiler flags: ``-I`` and the headers' folder, nothing else."""
    return f"-I{get_include()}"


def pkg_config_text() -> str:
    """The text of ``pyoa.pc``: a header-only package whose Cflags are
    :func:`cflags` and whose Libs are :data:`LIBS` (pkg-config splits Cflags
    as a shell would, so a folder with spaces is quoted there)."""
    from . import __version__

    include = get_include()
    quoted = f'"{include}"' if any(c.isspace() for c in include) else include
    return "\n".join([
        f"includedir={quoted}",
        "",
        "Name: pyoa",
        "Description: pyoa's portable C/C++/CUDA headers: orthogonal-array samplers for Monte Carlo rendering "
        "(header-only)",
        f"Version: {__version__}",
        "Cflags: -I${includedir}",
        f"Libs: {LIBS}",
        "",
    ])


def write_pkg_config(folder) -> Path:
    """Write :func:`pkg_config_text` to ``folder/pyoa.pc`` (``folder`` must
    exist and be a directory); return the file's path."""
    folder = Path(folder)
    if not folder.is_dir():
        raise NotADirectoryError(f"--write-pkg-config: {folder} is not a directory (create it first)")
    target = folder / PC_FILE
    target.write_text(pkg_config_text())
    return target


def _parser() -> argparse.ArgumentParser:
    forbidden = "\n".join(f"  {flag}: {why}" for flag, why in FORBIDDEN_FLAGS.items())
    parser = argparse.ArgumentParser(
        prog="python -m pyoa.config",
        description="Compiler flags for pyoa's portable C, C++ and CUDA headers (header-only: no library of "
                    "its own). Example: cc -std=c99 -O2 $(python -m pyoa.config --cflags) app.c "
                    "$(python -m pyoa.config --libs)",
        epilog="Flags that break bit-exactness with pyoa's reference (do not add them):\n" + forbidden
               + "\nnvcc needs no flag: the headers use the __f*_rn intrinsics, which --fmad and --use_fast_math "
                 "leave alone.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--cflags", action="store_true", help="print the compiler flags (-I<folder>)")
    what.add_argument("--libs", action="store_true", help=f"print the link flags ({LIBS}: libm; pyoa itself is "
                                                           "header-only)")
    what.add_argument("--include", action="store_true", help="print the headers' folder (pyoa.get_include())")
    what.add_argument("--pkg-config", action="store_true", help="print the text of pyoa.pc")
    what.add_argument("--write-pkg-config", metavar="DIR",
                      help="write DIR/pyoa.pc (then PKG_CONFIG_PATH=DIR pkg-config --cflags pyoa)")
    return parser


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    if args.cflags:
        print(cflags())
    elif args.libs:
        print(LIBS)
    elif args.include:
        print(get_include())
    elif args.pkg_config:
        sys.stdout.write(pkg_config_text())
    else:
        try:
            target = write_pkg_config(args.write_pkg_config)
        except OSError as exc:
            print(f"python -m pyoa.config: error: {exc}", file=sys.stderr)
            return 2
        print(target)
    return 0


if __name__ == "__main__":
    sys.exit(main())
