#!/usr/bin/env python3
"""The figure of ``faure``'s 2D projections in docs/samplers.md.

One pixel of ``pyoa.sampler("faure", base=b, dims=b, ...)`` (default b = 5),
two pairs of dimensions: ``(0, 1)``, the van der Corput coordinate against
the first Pascal-matrix coordinate, and a pair of higher coordinates
(default ``(2, 4)``). For each pair, left to right:

1. ``N = b^2`` on the ``b x b`` grid: one point per cell (strength 2, the
   ``bose`` property);
2. ``N = 2 b^2`` on the same grid: two points per cell, one from each aligned
   block of ``b^2`` (the two blocks drawn in different colours, each is a
   net of its own);
3. ``N = b^3`` on the ``b^2 x b`` grid and
4. ``N = b^3`` on the ``b x b^2`` grid: one point per elementary box (the
   strong-OA stratification, finer than strength 2);
5. (unless ``--no-bose``) ``bose`` at ``N = s^2``, ``s = b``, on the same
   pair and the ``s x s`` grid, for comparison.

Every stratification a panel shows is checked on the float32 values before
the figure is written (one point per box, or two for ``2 b^2``); a failed
check stops the script. ``faure`` is progressive, so the panels of a pair
are prefixes of one sequence: the ``b^2`` points of panel 1 are the first
block of panel 2 and of panels 3 and 4.

Runs in about a second; the PNG is written atomically.

Usage::

    python benchmarks/faure_figure.py                        # docs/results/faure-projections.png
    python benchmarks/faure_figure.py --base 7 --pair 3 5 --out docs/results/faure-projections-7.png
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

import pyoa  # noqa: E402
from pyoa.util.atomic import atomic_path, check_writable  # noqa: E402
from pyoa.catalogue.faure import BASES  # noqa: E402

#: Colours of the two aligned blocks of the 2 b^2 panel (and of single-block panels).
FIRST, SECOND = "#1f4e9c", "#d9480f"


def points(name: str, spp: int, dims: int, seed: int, pixel: int, **kw) -> np.ndarray:
    """One pixel's ``(spp, dims)`` float32 point set."""
    return pyoa.sampler(name, spp=spp, dims=dims, seed=seed, **kw).generate(pixels=[pixel])[0]


def box_counts(x: np.ndarray, y: np.ndarray, nx: int, ny: int) -> np.ndarray:
    """Points per cell of the ``nx x ny`` grid (exact: ``floor(v * n)`` of a float32 in float64)."""
    cx = np.floor(x.astype(np.float64) * nx).astype(np.int64)
    cy = np.floor(y.astype(np.float64) * ny).astype(np.int64)
    return np.bincount(cx * ny + cy, minlength=nx * ny)


def grid(ax, nx: int, ny: int, coarse: int) -> None:
    """Lines at the elementary intervals ``1/nx`` and ``1/ny``; the multiples of
    ``1/coarse`` (the ``b x b`` cells) drawn darker where they are finer."""
    for n, line in ((nx, ax.axvline), (ny, ax.axhline)):
        for k in range(1, n):
            major = n == coarse or (k * coarse) % n == 0
            line(k / n, color="0.35" if major else "0.72", lw=0.9 if major else 0.5, zorder=1)


def panel(ax, x, y, *, nx, ny, coarse, title, split=None, size=14) -> None:
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.set_aspect("equal")
    ax.set_xticks([0, 0.5, 1])
    ax.set_yticks([0, 0.5, 1])
    ax.tick_params(labelsize=8)
    grid(ax, nx, ny, coarse)
    if split is None:
        ax.scatter(x, y, s=size, c=FIRST, lw=0, zorder=3, clip_on=False)
    else:
        ax.scatter(x[:split], y[:split], s=size, c=FIRST, lw=0, zorder=3, clip_on=False,
                   label=f"samples 0..{split - 1}")
        ax.scatter(x[split:], y[split:], s=size, c=SECOND, marker="D", lw=0, zorder=3, clip_on=False,
                   label=f"samples {split}..{len(x) - 1}")
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), fontsize=7.5, ncol=2,
                  frameon=False, handletextpad=0.2, columnspacing=0.8)
    ax.set_title(title, fontsize=9.5)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=str(REPO / "docs" / "results" / "faure-projections.png"),
                    help="PNG to write (default: docs/results/faure-projections.png)")
    ap.add_argument("--base", type=int, default=5, help="prime base b, at most 13 for a legible figure (default 5)")
    ap.add_argument("--pair", type=int, nargs=2, default=(2, 4), metavar=("J", "K"),
                    help="the second pair of dimensions, both < base (default 2 4)")
    ap.add_argument("--seed", type=int, default=0, help="sampler seed (default 0)")
    ap.add_argument("--pixel", type=int, default=0, help="pixel (default 0)")
    ap.add_argument("--no-bose", action="store_true", help="leave out the bose comparison column")
    ap.add_argument("--width", type=int, default=1700, help="figure width in pixels (default 1700)")
    args = ap.parse_args(argv)

    b = args.base
    if b not in BASES or b > 13:
        ap.error(f"--base must be a prime in [2, 13] (a figure of b^3 points), got {b}")
    j, k = args.pair
    if not (0 <= j < b and 0 <= k < b and j != k):
        ap.error(f"--pair must be two different dimensions in [0, {b}), got {j} {k}")
    if not args.out.lower().endswith(".png"):
        ap.error(f"--out must end in .png, got {args.out}")
    check_writable(args.out)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n2, n3 = b**2, b**3
    # progressive: the b^3 prefix holds the b^2 and 2 b^2 prefixes (checked)
    full = points("faure", n3, b, args.seed, args.pixel, base=b)
    for n in (n2, 2 * n2):
        assert np.array_equal(points("faure", n, b, args.seed, args.pixel, base=b), full[:n]), \
            "faure's samples depend on spp"
    bose = None if args.no_bose else points("bose", n2, b, args.seed, args.pixel)

    cols = 4 + (bose is not None)
    width = args.width * cols / 5
    fig, axes = plt.subplots(2, cols, figsize=(width / 100, 8.2), dpi=100, squeeze=False)
    checks = []
    for row, (d0, d1) in enumerate([(0, 1), (j, k)]):
        pair = f"dims ({d0},{d1})"
        specs = [  # (points, nx, ny, per box, title, split)
            (full[:n2], b, b, 1, f"faure b={b}, N = b² = {n2}, {pair}\n{b}×{b} cells, 1 point each", None),
            (full[:2 * n2], b, b, 2,
             f"faure, N = 2b² = {2 * n2}, {pair}\n{b}×{b} cells, 2 each (1 per block of {n2})", n2),
            (full, b * b, b, 1, f"faure, N = b³ = {n3}, {pair}\n{b * b}×{b} boxes, 1 point each", None),
            (full, b, b * b, 1, f"faure, N = b³ = {n3}, {pair}\n{b}×{b * b} boxes, 1 point each", None),
        ]
        if bose is not None:
            specs.append((bose, b, b, 1, f"bose s={b}, N = s² = {n2}, {pair}\n{b}×{b} cells, 1 point each", None))
        for ax, (pts, nx, ny, per, title, split) in zip(axes[row], specs, strict=True):
            counts = box_counts(pts[:, d0], pts[:, d1], nx, ny)
            if not (counts == per).all():
                raise SystemExit(f"check failed: {title.splitlines()[0]}: {nx}x{ny} counts "
                                 f"{np.unique(counts).tolist()}, want {per}")
            if split is not None:  # each aligned block alone is a net
                for blk in (pts[:split], pts[split:]):
                    if not (box_counts(blk[:, d0], blk[:, d1], nx, ny) == 1).all():
                        raise SystemExit(f"check failed: a block of {split} of {title.splitlines()[0]}")
            checks.append(f"{title.splitlines()[0]}: {nx}x{ny} boxes, {per} each")
            panel(ax, pts[:, d0], pts[:, d1], nx=nx, ny=ny, coarse=b, title=title, split=split,
                  size=16 if len(pts) <= 2 * n2 else 9)
            ax.set_xlabel(f"x{d0}", fontsize=8, labelpad=1)
            ax.set_ylabel(f"x{d1}", fontsize=8, labelpad=1)
    fig.suptitle(f"Owen-scrambled Faure sequence in base {b} (one pixel, seed {args.seed}): every aligned block "
                 f"of $b^m$ samples is a (0,m,{b})-net; darker lines: the {b}×{b} cells, light lines: the finer "
                 "elementary intervals", fontsize=10.5)
    fig.tight_layout(rect=(0, 0, 1, 0.96), h_pad=2.2)
    with atomic_path(args.out) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)
    for line in checks:
        print("ok:", line)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
