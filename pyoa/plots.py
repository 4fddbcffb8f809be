"""Figures users judge samplers by: 2D projections and power spectra.

Both take a sampler by name, exactly as :func:`pyoa.sampler` does, and write
a PNG atomically (matplotlib, Agg backend). The figure is exactly ``size``
pixels wide, and ``size`` (projections) or ``size // 2`` (spectra) tall.

References
----------
.. [1] W. Jarosz et al., "Orthogonal Array Sampling for Monte Carlo
   Rendering", EGSR 2019 (projection figures; power spectra validation).
.. [2] R. L. Cook, "Stochastic sampling in computer graphics", ACM TOG 5(1),
   1986; and D. Heck, T. Schlömer, O. Deussen, "Blue noise sampling with
   controlled aliasing", ACM TOG 32(3), 2013 (expected power spectra and their
   radial means).
"""

from __future__ import annotations

import os
import warnings

import numpy as np

from .analysis import radial_mean  # noqa: F401  (pyoa.plots.radial_mean, as before)
from .util.atomic import atomic_path, check_writable
from .catalogue.entries import MAX_UINT32, check_int
from .samplers import sampler as make_sampler
from .samplers import trial_options

#: Largest number of dimensions in a projection matrix (D*(D-1)/2 panels).
MAX_PLOT_DIMS = 16
#: Figure sizes accepted, in pixels.
MIN_SIZE, MAX_SIZE = 64, 8192
#: The width in pixels of a figure given no ``size`` (``pyoa plot/spectrum --figure-width``).
FIGURE_WIDTH = 900


def _check_figure(out, size) -> None:
    """Refuse, before any sampling, a figure that cannot be written: ``out``
    must end in .png (the figure is written as PNG, whatever the name says)
    and be writable, ``size`` an int in [64, 8192]."""
    if isinstance(size, bool) or not isinstance(size, int) or not MIN_SIZE <= size <= MAX_SIZE:
        raise ValueError(f"figure size must be an integer in [{MIN_SIZE}, {MAX_SIZE}] pixels, got {size!r}")
    name = os.path.basename(str(out))
    if not name.lower().endswith(".png") or name.lower() == ".png":
        raise ValueError(f"out must end in .png (the figure is written as PNG), got {str(out)!r}")
    check_writable(out)


def _figure(size: int, height: int | None = None):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt, plt.figure(figsize=(size / 100, (height or size) / 100), dpi=100)


def _save(plt, fig, path) -> None:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)


def _strata(smp) -> int:
    """Coarse strata per axis worth drawing: ``s`` of a stratified sampler, else 0."""
    return smp.s if smp.strength >= 2 and smp.s > 1 else 0


def projections(name: str, *, spp: int, dims: int, seed: int = 0, pixel: int = 0, out: str,
                size: int = FIGURE_WIDTH, **options) -> np.ndarray:
    """Draw every 2D projection ``(i, j), i < j`` of one pixel's point set.

    Panel ``(j, i)`` of a lower-triangular matrix shows dimension ``i``
    (horizontal) against ``j`` (vertical); the sampler's coarse strata (``s``
    per axis, for stratified samplers) are drawn as a grid, so an
    orthogonal array's one-point-per-cell property is visible in every pair of
    a block and its absence across blocks or padded pairs too.

    Parameters
    ----------
    name, spp, dims, seed, **options
        As for :func:`pyoa.sampler` (``dims`` at most 16).
    pixel : int
        Which pixel's point set.
    out : str
        PNG path (must end in .png; checked, with ``size``, before sampling).
    size : int
        Figure width and height in pixels, 64 to 8192.

    Returns
    -------
    numpy.ndarray
        The plotted points, float32 ``(spp, dims)``.
    """
    dims = check_int("dims", dims)
    if not 2 <= dims <= MAX_PLOT_DIMS:
        raise ValueError(f"a projection matrix needs 2 <= dims <= {MAX_PLOT_DIMS}, got {dims}")
    pixel = check_int("pixel", pixel, 0, MAX_UINT32)
    _check_figure(out, size)
    smp = make_sampler(name, spp=spp, dims=dims, seed=seed, **trial_options(name, options))
    x = smp.generate(pixels=[pixel])[0]
    s = _strata(smp)
    plt, fig = _figure(size)
    n = dims - 1
    axes = fig.subplots(n, n, squeeze=False)
    marker = max(0.5, min(8.0, 3000.0 / spp)) * (size / 900) ** 2
    for r in range(n):
        for c in range(n):
            ax = axes[r][c]
            i, j = c, r + 1
            if i >= j:
                ax.axis("off")
                continue
            if s and s <= 64:
                for k in range(1, s):
                    ax.axhline(k / s, lw=0.3, color="0.8", zorder=0)
                    ax.axvline(k / s, lw=0.3, color="0.8", zorder=0)
            ax.scatter(x[:, i], x[:, j], s=marker, c="k", linewidths=0)
            ax.set_xlim(0, 1)
            ax.set_ylim(0, 1)
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_aspect("equal")
            if r == n - 1:
                ax.set_xlabel(str(i), fontsize=7)
            if c == 0:
                ax.set_ylabel(str(j), fontsize=7)
    grid = f", s={smp.s}" if s else ""
    fig.suptitle(f"{smp.name}, {spp} spp, dims 0..{dims - 1}{grid} (pixel {pixel}, seed {seed})", fontsize=9)
    _save(plt, fig, out)
    return x


def power_spectrum(x: np.ndarray, freq: int) -> np.ndarray:
    """Periodogram ``P(k) = |sum_n exp(-2 pi i k . x_n)|^2 / N`` of 2D point
    sets on the integer frequencies ``k`` in ``[-freq, freq]^2``.

    ``x`` has shape ``(trials, N, 2)``; the result, averaged over the trials,
    has shape ``(2 freq + 1, 2 freq + 1)`` (rows: ``k_y``). The exponential is
    separable, so each trial is one complex matrix product.
    """
    x = np.asarray(x, dtype=np.float64)
    k = np.arange(-freq, freq + 1, dtype=np.float64)
    acc = np.zeros((len(k), len(k)))
    for pts in x:
        ex = np.exp(-2j * np.pi * np.outer(k, pts[:, 0]))
        ey = np.exp(-2j * np.pi * np.outer(k, pts[:, 1]))
        acc += np.abs(ey @ ex.T) ** 2
    return acc / (len(x) * x.shape[1])


def spectrum(name: str, *, spp: int, dims: tuple[int, int] = (0, 1), trials: int = 64, seed: int = 0,
             freq: int = 48, out: str, size: int = FIGURE_WIDTH,
             **options) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Expected power spectrum of one 2D projection, averaged over ``trials``
    independent randomizations (pixels ``0 .. trials-1``), and its radial mean.

    A flat spectrum at 1 is white noise (``random``); stratified sets push
    energy away from low frequencies (a dark centre, a radial mean below 1
    near 0). The figure shows the spectrum (DC removed) and the radial mean.

    ``out`` must end in .png; it, ``size``, ``trials`` and ``freq`` are
    checked before sampling.

    Returns
    -------
    (spectrum, radii, radial mean)
    """
    if not isinstance(dims, (tuple, list)) or len(dims) != 2:
        raise ValueError(f"dims must be two dimensions (i, j), got {dims!r}")
    i, j = (check_int("dims", k, 0) for k in dims)
    if i == j:
        raise ValueError(f"dims needs two different dimensions i,j >= 0, got {i},{j}")
    trials = check_int("trials", trials, 1, 100000)
    freq = check_int("freq", freq, 4, 512)
    _check_figure(out, size)
    smp = make_sampler(name, spp=spp, dims=max(i, j) + 1, seed=seed, **trial_options(name, options))
    x = smp.generate(pixels=range(trials), dims=[i, j])
    p = power_spectrum(x, freq)
    p[freq, freq] = 0.0  # DC: N, drawn as 0
    radii, mean = radial_mean(p)
    plt, fig = _figure(size, size // 2)
    ax0, ax1 = fig.subplots(1, 2)
    im = ax0.imshow(p, extent=(-freq, freq, -freq, freq), origin="lower", cmap="gray", vmin=0, vmax=2)
    ax0.set_title(f"{smp.name}, {spp} spp, dims {i},{j}\n{trials} randomizations", fontsize=8)
    fig.colorbar(im, ax=ax0, fraction=0.046)
    ax1.plot(radii, mean, lw=1)
    ax1.axhline(1.0, color="0.6", lw=0.5)
    ax1.set_xlabel("frequency |k|", fontsize=8)
    ax1.set_ylabel("radial mean power", fontsize=8)
    ax1.set_ylim(0, max(2.0, float(mean.max()) * 1.05))
    with warnings.catch_warnings():  # tiny figures cannot fit every label; that is fine
        warnings.simplefilter("ignore", UserWarning)
        fig.tight_layout()
    _save(plt, fig, out)
    return p, radii, mean


def error_spectra(results, *, out: str, size: int = 1200) -> None:
    """One figure of screen-space error spectra (:func:`pyoa.analysis.error_spectrum`):
    for each result its normalized periodogram (white noise = 1, a dark centre
    is blue noise), then all radial means on one plot.

    ``results`` is a sequence of :class:`pyoa.analysis.ErrorSpectrum`; ``out``
    must end in .png (written atomically).
    """
    results = list(results)
    if not results:
        raise ValueError("error_spectra needs at least one ErrorSpectrum")
    _check_figure(out, size)
    n = len(results)
    plt, fig = _figure(size, size * 2 // (n + 1) + 60)
    for k, res in enumerate(results):
        ax = fig.add_subplot(1, n + 1, k + 1)
        c = res.size // 2
        ax.imshow(res.power, extent=(-c, res.size - c, -c, res.size - c), origin="lower", cmap="gray", vmin=0,
                  vmax=2)
        ax.set_title(f"{res.sampler}, {res.spp} spp\nlow-freq. power {res.low:.2f}", fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
    ax = fig.add_subplot(1, n + 1, n + 1)
    for res in results:
        ax.plot(res.radii, res.radial, lw=1, label=res.sampler)
    ax.axhline(1.0, color="0.6", lw=0.5)
    ax.set_xlabel("frequency |k| (cycles per image)", fontsize=8)
    ax.set_ylabel("radial mean power", fontsize=8)
    ax.legend(fontsize=7)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        fig.tight_layout()
    _save(plt, fig, out)
