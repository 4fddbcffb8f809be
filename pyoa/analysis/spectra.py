"""Screen-space error spectra: how a sampler's per-pixel errors are laid out.

:func:`error_spectrum` integrates a ``d``-dimensional integrand in every pixel of an image,
Fourier transforms the error image and averages its periodogram over seeds,
normalized so that independent per-pixel errors (white noise) are flat at 1;
:class:`ErrorSpectrum` holds it, its radial mean (:func:`radial_mean`) and a
one-number summary of its low frequencies. Blue-noise error (little energy at
low frequencies, as Ahmed and Wonka's ``zsobol`` [1]_ gives) reads below 1.

References
----------
.. [1] A. G. M. Ahmed, P. Wonka, "Screen-space blue-noise diffusion of
   Monte Carlo sampling error via hierarchical ordering of pixels",
   ACM Transactions on Graphics 39(6), SIGGRAPH Asia 2020.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..samplers import _int as _checked_int
from ._display import Markdown, field_table
from .integrands import _lookup

__all__ = ["ErrorSpectrum", "error_spectrum", "radial_mean"]


def radial_mean(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean of a centred square spectrum (DC at index ``n // 2`` of each axis,
    as ``np.fft.fftshift`` and :func:`pyoa.plots.power_spectrum` lay it out)
    over rings ``r <= |k| < r + 1`` up to ``n // 2``; DC excluded. Returns
    ``(radii, means)`` of the non-empty rings."""
    n = p.shape[0]
    c = n // 2
    ky, kx = np.mgrid[-c:n - c, -c:n - c]
    r = np.hypot(kx, ky)
    ring = np.floor(r).astype(int)
    keep = (r > 0) & (ring <= c)
    sums = np.bincount(ring[keep], weights=p[keep], minlength=c + 1)
    counts = np.bincount(ring[keep], minlength=c + 1)
    ok = counts > 0
    return np.arange(c + 1)[ok], sums[ok] / counts[ok]


@dataclass(frozen=True)
class ErrorSpectrum:
    """The screen-space power spectrum of per-pixel integration error
    (:func:`error_spectrum`).

    Attributes
    ----------
    sampler, integrand : str
        What was measured.
    dims : int
        The integrand's dimensions (the sampler's dimensions ``0 .. dims-1``).
    spp, size, seeds : int
        Samples per pixel, image side (``size x size`` pixels) and how many
        seeds (independent images) were averaged.
    power : numpy.ndarray
        ``(size, size)`` mean periodogram of the error image, centred (DC in
        the middle), divided by the error variance: white noise is 1 at
        every frequency.
    radii, radial : numpy.ndarray
        Its mean over rings ``r <= |k| < r + 1`` (DC excluded).
    low : float
        The mean of ``power`` over ``1 <= |k| <= size / 8``: 1 for white
        noise (pixels' errors independent), below 1 for blue noise
        (neighbouring pixels' errors cancel).
    rmse : float
        Root mean squared per-pixel error.

    A REPL and a notebook show it as a table of the numbers (:meth:`table`).
    """

    sampler: str
    integrand: str
    spp: int
    dims: int
    size: int
    seeds: int
    power: np.ndarray = field(repr=False)
    radii: np.ndarray = field(repr=False)
    radial: np.ndarray = field(repr=False)
    low: float
    rmse: float

    def table(self) -> Markdown:
        """Markdown: what was measured and its summary numbers, a field per row."""
        return field_table(f"Error spectrum of `{self.sampler}` on `{self.integrand}`", [
            ("spp", self.spp), ("dimensions", self.dims), ("image", f"{self.size} x {self.size}"), ("seeds", self.seeds),
            ("low-frequency power (white noise = 1)", f"{self.low:.4g}"), ("RMSE per pixel", f"{self.rmse:.4g}")])

    def __repr__(self) -> str:
        return repr(self.table())

    def _repr_markdown_(self) -> str:
        return str(self.table())


def error_spectrum(sampler: str, *, spp: int, size: int = 64, seeds: int = 8, integrand: str = "ball",
                   dims: int = 2, seed: int = 0, base: int | None = None,
                   backend: str | None = None) -> ErrorSpectrum:
    """How a sampler's per-pixel errors are distributed across the image.

    Each pixel of a ``size x size`` image estimates the integral of the
    ``dims``-dimensional ``integrand`` with its own ``spp`` samples
    (dimensions ``0 .. dims-1``, pixels numbered row-major); the error image ``e(x, y) = estimate - exact`` is
    Fourier transformed and its periodogram ``|E(k)|^2 / size^2`` averaged
    over ``seeds`` seeds, then divided by the error variance (the mean over
    all non-zero frequencies), so that independent per-pixel errors give a
    flat spectrum at 1. Ahmed and Wonka's ``zsobol`` [1]_ distributes the
    error as blue noise: little energy at low frequencies, so the error looks
    finer-grained and is removed by a blur or a denoiser. The measure here is
    theirs (their Fig. 1); ``low`` summarizes it in one number.

    Parameters
    ----------
    sampler : str
        A sampler name (:func:`pyoa.samplers`). One that needs the image
        (``zsobol``) gets ``resolution=(size, size)``.
    spp : int
        Samples per pixel (valid for the sampler).
    size : int
        Image side, 8 to 1024.
    seeds : int
        Independent images averaged, 1 to 1024.
    integrand : str
        An integrand of :data:`INTEGRANDS` (default ``"ball"``: a disk,
        discontinuous like a shadow edge).
    dims : int
        Its dimensions, 1 to 64 (default 2). ``zsobol``'s blue noise lives
        in its first pair of dimensions; ``zfaure``'s in every dimension of
        a block.
    seed : int
        First user seed; images use ``seed, seed + 1, ...``.
    base : int, optional
        The digit base of a sampler that has one (``faure``, ``zfaure``);
        its default otherwise.
    backend : str, optional
        As :func:`pyoa.sampler`.

    Returns
    -------
    ErrorSpectrum

    References
    ----------
    .. [1] A. G. M. Ahmed, P. Wonka, "Screen-space blue-noise diffusion of
       Monte Carlo sampling error via hierarchical ordering of pixels",
       ACM Transactions on Graphics 39(6), SIGGRAPH Asia 2020.

    Examples
    --------
    >>> z = error_spectrum("zsobol", spp=16, size=32, seeds=2, backend="numpy")
    >>> w = error_spectrum("sobol02", spp=16, size=32, seeds=2, backend="numpy")
    >>> bool(z.low < w.low)
    True
    """
    import pyoa

    size = _checked_int("size", size, 8, 1024)
    seeds = _checked_int("seeds", seeds, 1, 1024)
    seed = _checked_int("seed", seed, 0, 2**32 - seeds)
    dims = _checked_int("dims", dims, 1, 64)
    f = _lookup(integrand, dims)
    entry = pyoa.catalogue.get(sampler)
    options = {"backend": backend}
    if entry.needs_resolution:
        options["resolution"] = (size, size)
    if base is not None:
        options["base"] = base  # the sampler refuses a base it does not have, naming those that do
    acc = np.zeros((size, size))
    sq = 0.0
    for k in range(seeds):
        smp = pyoa.sampler(sampler, spp=spp, dims=dims, seed=seed + k, **options)
        err = f(smp.generate(pixels=range(size * size))).mean(axis=1) - f.exact
        sq += float(np.mean(err**2))
        acc += np.abs(np.fft.fft2(err.reshape(size, size))) ** 2 / (size * size)
    power = np.fft.fftshift(acc / seeds)
    c = size // 2
    power[c, c] = 0.0  # DC: the mean error, not its distribution
    power /= power.sum() / (size * size - 1)  # white noise: 1 everywhere
    radii, radial = radial_mean(power)
    ky, kx = np.mgrid[-c:size - c, -c:size - c]
    r = np.hypot(kx, ky)
    low = float(power[(r >= 1) & (r <= size / 8)].mean())
    return ErrorSpectrum(sampler=entry.name, integrand=f.name, spp=smp.spp, dims=dims, size=size,
                         seeds=seeds, power=power, radii=radii, radial=radial, low=low,
                         rmse=math.sqrt(sq / seeds))
