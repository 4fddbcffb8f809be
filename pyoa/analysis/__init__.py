"""Analysis of point sets and samplers: stratification, discrepancy, convergence.

Tools to check what a sampler promises and to measure what it delivers, one
subject per submodule (every public name is re-exported here, so
``from pyoa.analysis import X`` works for all of them):

* :mod:`pyoa.analysis.pointsets`: :func:`stratification` and
  :func:`latin_hypercube` check, exactly, whether every t-dimensional
  projection of a point set is stratified (the defining property of an
  orthogonal array of strength t [1]_, [2]_); :func:`cells`;
  :func:`discrepancy` wraps :func:`scipy.stats.qmc.discrepancy` [4]_;
* :mod:`pyoa.analysis.integrands`: :data:`INTEGRANDS` are test integrands on
  ``[0, 1)^d`` with exact integrals, smooth and discontinuous, with and
  without interactions between dimensions (:class:`Integrand`);
* :mod:`pyoa.analysis.rates`: :func:`convergence` estimates the variance of a
  sampler's per-pixel estimator over independent randomizations as the
  sample count grows, and fits its convergence rate [3]_
  (:class:`ConvergenceResult`, with a Markdown table and a log-log plot);
* :mod:`pyoa.analysis.spectra`: :func:`error_spectrum`, the screen-space
  power spectrum of per-pixel error (:class:`ErrorSpectrum`,
  :func:`radial_mean`);
* :mod:`pyoa.analysis.statistics`: :func:`mean_ci` (Student-t confidence
  intervals), :func:`fit_loglog` (convergence rates), :func:`pass_variance`,
  :func:`relmse_noise` and :func:`corrected` (a reference image's noise in a
  relative MSE measured against it), shared by convergence and render
  studies.

Why the interactions matter: padded samplers (``jittered2d``, ``cmj2d``,
``sobol02``) stratify the pairs (0, 1), (2, 3), ... jointly but pair each
dimension with one of another pair only as two independent 1D Latin
hypercubes (at best), while a strength-2 orthogonal array stratifies every
pair of the dimensions in a block [1]_. The two differ only on integrands
whose ANOVA decomposition has terms coupling dimensions of different pairs;
each integrand documents which terms it has (its ``coupling``).

References
----------
.. [1] W. Jarosz, A. Enayet, A. Kensler, C. Kilpatrick, P. Christensen,
   "Orthogonal Array Sampling for Monte Carlo Rendering", Computer Graphics
   Forum 38(4) (EGSR 2019).
.. [2] A. S. Hedayat, N. J. A. Sloane, J. Stufken, *Orthogonal Arrays:
   Theory and Applications*, Springer, 1999.
.. [3] A. B. Owen, "Orthogonal arrays for computer experiments, integration
   and visualization", Statistica Sinica 2 (1992), 439-452.
.. [4] F. J. Hickernell, "A generalized discrepancy and quadrature error
   bound", Mathematics of Computation 67 (1998), 299-322.

Examples
--------
>>> import pyoa
>>> from pyoa import analysis
>>> x = pyoa.sampler("bose", spp=49, dims=8, seed=1, jitter=0.0, backend="numpy").generate()[0]
>>> analysis.stratification(x, s=7, t=2).passed
True
>>> f, exact = analysis.INTEGRANDS["gaussian"](2)
>>> round(exact, 6)
0.141129
>>> bool(abs(f(x[:, :2]).mean() - exact) < 0.01 * exact)   # 49 points: within 1%
True
"""

from __future__ import annotations

from .integrands import (
    HALFSPACE_MAX_D,
    INTEGRANDS,
    Integrand,
    additive,
    anisotropic_gaussian,
    ball,
    diagonal_halfspace,
    gaussian,
    halfspace,
    integrand,
    lagged_pairs,
    oscillatory,
    pairwise,
)
from .pointsets import (
    MAX_SUBSETS,
    StratificationReport,
    cells,
    discrepancy,
    latin_hypercube,
    stratification,
)
from .rates import ConvergenceResult, convergence
from .spectra import ErrorSpectrum, error_spectrum, radial_mean
from .statistics import corrected, fit_loglog, mean_ci, pass_variance, ratio_ci, relmse_noise

__all__ = [
    "HALFSPACE_MAX_D",
    "INTEGRANDS",
    "MAX_SUBSETS",
    "ConvergenceResult",
    "ErrorSpectrum",
    "Integrand",
    "StratificationReport",
    "additive",
    "anisotropic_gaussian",
    "ball",
    "cells",
    "convergence",
    "corrected",
    "diagonal_halfspace",
    "discrepancy",
    "error_spectrum",
    "fit_loglog",
    "gaussian",
    "halfspace",
    "integrand",
    "latin_hypercube",
    "mean_ci",
    "oscillatory",
    "lagged_pairs",
    "pairwise",
    "pass_variance",
    "radial_mean",
    "ratio_ci",
    "relmse_noise",
    "stratification",
]
