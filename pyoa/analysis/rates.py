"""Convergence rates: the variance of a sampler's estimator as N grows.

:func:`convergence` integrates an :class:`~pyoa.analysis.integrands.Integrand`
with ``trials`` independent randomizations of each sampler at each sample
count, records the variance and MSE of the estimates, and fits the rate, the
least-squares slope of log variance against log N
(:func:`pyoa.analysis.statistics.fit_loglog`): -1 for independent random
points, steeper for stratified ones [1]_, the comparison of the paper's
convergence plots [2]_. :class:`ConvergenceResult` holds the measurements,
with a Markdown table and a log-log plot.

(The module is ``rates``, not ``convergence``: a submodule of that name would
be shadowed by the function :func:`convergence` that the package re-exports.)

References
----------
.. [1] A. B. Owen, "Orthogonal arrays for computer experiments, integration
   and visualization", Statistica Sinica 2 (1992), 439-452.
.. [2] W. Jarosz, A. Enayet, A. Kensler, C. Kilpatrick, P. Christensen,
   "Orthogonal Array Sampling for Monte Carlo Rendering", Computer Graphics
   Forum 38(4) (EGSR 2019).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..catalogue import nearest_spp
from ..samplers import trial_options
from ._checks import _dim, _int
from ._display import Markdown
from .integrands import Integrand, _lookup
from .statistics import fit_loglog

__all__ = ["ConvergenceResult", "convergence"]

#: Samplers whose strength decides the valid counts; :func:`convergence` asks them for strength d.
_STRENGTH_SAMPLERS = ("bush", "cmjnd")


@dataclass
class ConvergenceResult:
    """Result of :func:`convergence`.

    Attributes
    ----------
    integrand : Integrand
        What was integrated (``integrand.exact`` is the reference value).
    d : int
        Dimension.
    trials : int
        Independent randomizations (pixels) per sampler and count.
    seed : int
        Sampler seed.
    spp : dict of str to numpy.ndarray of int
        Per sampler, the distinct valid sample counts used, increasing.
    mean, variance, mse : dict of str to numpy.ndarray of float
        Per sampler and count: the mean of the ``trials`` estimates, their
        unbiased sample variance, and their mean squared error against the
        exact integral.
    slope, intercept : dict of str to float
        Least-squares fit :math:`\\log V = \\text{slope} \\cdot \\log N + \\text{intercept}`
        of the variance (natural logs; NaN with fewer than two counts of
        positive variance).
    mse_slope : dict of str to float
        The same fit's slope for the MSE.
    strength : dict of str to int or None
        Strength asked of ``bush``/``cmjnd`` (None for the others).
    skipped : dict of str to str
        Samplers left out, with the reason (e.g. no valid count for d dimensions).

    A REPL and a notebook show the result as its :meth:`table`.
    """

    integrand: Integrand
    d: int
    trials: int
    seed: int
    spp: dict = field(default_factory=dict)
    mean: dict = field(default_factory=dict)
    variance: dict = field(default_factory=dict)
    mse: dict = field(default_factory=dict)
    slope: dict = field(default_factory=dict)
    intercept: dict = field(default_factory=dict)
    mse_slope: dict = field(default_factory=dict)
    strength: dict = field(default_factory=dict)
    skipped: dict = field(default_factory=dict)

    @property
    def samplers(self) -> list[str]:
        """The samplers measured (in the order given)."""
        return list(self.spp)

    def table(self) -> Markdown:
        """Markdown: one row per sampler and count (mean, variance, MSE), then
        one per sampler with the fitted slopes, then the skipped samplers. A
        ``str`` that a REPL shows as the table itself (:class:`Markdown`)."""
        f = self.integrand
        lines = [(f"Integrand `{f.name}` (d={self.d}, exact {f.exact:.10g}, coupling {f.coupling}), "
                  f"{self.trials} trials, seed {self.seed}"), "",
                 "| sampler | spp | mean | variance | MSE |", "|---|---:|---:|---:|---:|"]
        for name in self.samplers:
            for k, n in enumerate(self.spp[name]):
                lines.append(f"| {name} | {int(n)} | {self.mean[name][k]:.8g} | {self.variance[name][k]:.4e} "
                             f"| {self.mse[name][k]:.4e} |")
        lines += ["", "| sampler | variance slope | MSE slope |", "|---|---:|---:|"]
        for name in self.samplers:
            lines.append(f"| {name} | {self.slope[name]:.3f} | {self.mse_slope[name]:.3f} |")
        if self.skipped:
            lines += ["", "| skipped | reason |", "|---|---|"]
            lines += [f"| {name} | {why} |" for name, why in self.skipped.items()]
        return Markdown("\n".join(lines) + "\n")

    def __repr__(self) -> str:
        # a REPL shows the result as its table, not as a constructor call with every array in it
        return repr(self.table())

    def _repr_markdown_(self) -> str:
        return str(self.table())

    def plot(self, path, *, metric: str = "variance", dpi: int = 100) -> Path:
        """Write a log-log plot of variance (or MSE) against N, one line per
        sampler with its fitted slope in the legend.

        Uses Matplotlib's Agg canvas directly (no pyplot state, no backend
        switch) and writes atomically (:func:`pyoa.util.atomic.atomic_path`); the
        format follows the suffix (``.png`` by default when there is none).

        Parameters
        ----------
        path : str or os.PathLike
            Output file; its directory must exist.
        metric : {"variance", "mse"}
        dpi : int

        Returns
        -------
        pathlib.Path
        """
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        from ..util.atomic import atomic_path

        if metric not in ("variance", "mse"):
            raise ValueError(f"metric must be 'variance' or 'mse', got {metric!r}")
        path = Path(path)
        fig = Figure(figsize=(6.4, 4.8), dpi=dpi)
        canvas = FigureCanvasAgg(fig)
        fmt = path.suffix[1:].lower() or "png"
        if fmt not in canvas.get_supported_filetypes():
            raise ValueError(f"cannot write a plot as {fmt!r}; use one of "
                             f"{', '.join(sorted(canvas.get_supported_filetypes()))}")
        ax = fig.add_subplot()
        values = self.variance if metric == "variance" else self.mse
        for name in self.samplers:
            n = self.spp[name].astype(np.float64)
            v = values[name]
            keep = v > 0
            slope, icpt = fit_loglog(n, v)
            label = f"{name} (slope {slope:.2f})" if math.isfinite(slope) else name
            (line,) = ax.loglog(n[keep], v[keep], "o-", ms=4, lw=1, label=label)
            if math.isfinite(slope):
                ax.loglog(n[keep], np.exp(icpt) * n[keep] ** slope, "--", lw=0.8, color=line.get_color())
        f = self.integrand
        ax.set_xlabel("samples per pixel N")
        ax.set_ylabel("variance of the estimate" if metric == "variance" else "mean squared error")
        ax.set_title(f"{f.name}, d={self.d}, {self.trials} trials")
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
        if self.samplers:
            ax.legend(fontsize="small")
        fig.tight_layout()
        with atomic_path(path) as tmp, open(tmp, "wb") as fh:
            fig.savefig(fh, format=fmt)
        return path


def _strength_for(name: str, d: int, strength) -> int | None:
    if name not in _STRENGTH_SAMPLERS:
        return None
    if isinstance(strength, dict):
        strength = strength.get(name)
    if strength is None:
        return max(d, 2)
    return _int(f"strength of {name}", strength, 2)


def convergence(samplers, integrand, d: int, spp_targets, *, trials: int = 64, seed: int = 0, backend=None,
                strength=None, max_ratio: float = 2.0, max_bytes: int = 256 << 20) -> ConvergenceResult:
    """Variance of each sampler's estimator as the sample count grows.

    For each sampler and target count n the nearest valid count N is used
    (:func:`pyoa.valid_spp`, ties towards fewer samples), provided it lies
    within a factor ``max_ratio`` of n (else that target is left out for
    that sampler); targets that map to the same N are measured once. ``trials`` independent randomizations
    (pixels ``0 .. trials-1``, one point set each) give the estimates

    .. math::

        \\hat I_p = \\frac1N \\sum_{i=0}^{N-1} f(x_{p,i}), \\qquad p = 0, \\dots, P-1,

    whose sample variance :math:`V(N)` (and MSE against the exact integral)
    is recorded. The convergence rate is the least-squares slope of
    :math:`\\log V` against :math:`\\log N`
    (:func:`~pyoa.analysis.statistics.fit_loglog`): -1 for independent random
    points, -(1 + 2/d) for jittered sampling of smooth integrands, -(1 + 1/d)
    for discontinuous ones [1]_.

    Parameters
    ----------
    samplers : str or iterable of str
        Sampler names (:func:`pyoa.samplers`).
    integrand : str or Integrand
        A name in :data:`INTEGRANDS` (built for ``d``) or an :class:`Integrand`
        of dimension ``d``.
    d : int
        Dimensions per sample.
    spp_targets : iterable of int
        Desired sample counts (>= 1).
    trials : int
        Independent point sets per sampler and count (>= 2).
    seed : int
        Sampler seed (the same for every sampler and count).
    backend : str, optional
        Passed to :func:`pyoa.sampler`.
    strength : int or dict, optional
        Strength t of ``bush`` and ``cmjnd`` (a dict: per sampler name).
        Default ``max(d, 2)``: all d dimensions jointly stratified (``cmjnd``
        N = s^d; ``bush`` N = s^d with s >= d a prime power, and since s^d
        <= 2^24 no ``bush`` count exists beyond d = 8, and at d = 8 only
        8^8 = 2^24). The other samplers take any d (the OA samplers through
        independently randomized blocks).
    max_ratio : float
        Largest factor between a target and the count used for it (>= 1).
    max_bytes : int
        Largest block of points generated at once (pixels are generated in
        chunks below it).

    Returns
    -------
    ConvergenceResult
        A sampler with no valid count for ``d`` dimensions (and the given
        strength) within ``max_ratio`` of a target is skipped and listed in
        ``skipped`` with the reason.

    Raises
    ------
    ValueError
        An unknown sampler or integrand, an integrand of another dimension,
        ``trials < 2``, no targets, a target < 1 or ``max_ratio < 1``.

    Examples
    --------
    Random points converge as N^-1, jittered ones in 2D as N^-2 on a smooth
    integrand:

    >>> r = convergence(["random", "jittered2d"], "gaussian", 2, [16, 64, 256], trials=32, backend="numpy")
    >>> {name: round(slope, 1) for name, slope in r.slope.items()}
    {'random': -1.0, 'jittered2d': -2.2}
    """
    import pyoa

    d = _dim(d)
    trials = _int("trials", trials, 2, 2**32)
    seed = _int("seed", seed, 0, 2**32 - 1)
    max_bytes = _int("max_bytes", max_bytes, 1)
    if isinstance(max_ratio, bool) or not isinstance(max_ratio, numbers.Real) or not float(max_ratio) >= 1:
        raise ValueError(f"max_ratio must be a number >= 1, got {max_ratio!r}")
    max_ratio = float(max_ratio)
    if isinstance(samplers, str):
        samplers = [samplers]
    samplers = list(samplers)
    known = pyoa.samplers()
    for name in samplers:
        if name not in known:
            raise ValueError(f"unknown sampler {name!r}; valid: {', '.join(known)}")
    if len(set(samplers)) != len(samplers):
        raise ValueError(f"samplers must be distinct, got {samplers}")
    if isinstance(integrand, str):
        f = _lookup(integrand, d)
    elif isinstance(integrand, Integrand):
        f = integrand
        if f.d != d:
            raise ValueError(f"integrand {f.name!r} is {f.d}-dimensional, but d={d}")
    else:
        raise ValueError(  # noqa: TRY004 - bad input is a ValueError throughout pyoa.analysis
            f"integrand must be a name in INTEGRANDS or an Integrand, got {type(integrand).__name__}")
    if isinstance(spp_targets, numbers.Integral):
        spp_targets = [spp_targets]
    targets = [_int("spp target", n, 1) for n in spp_targets]
    if not targets:
        raise ValueError("spp_targets must hold at least one count")

    res = ConvergenceResult(integrand=f, d=d, trials=trials, seed=seed)
    for name in samplers:
        t = _strength_for(name, d, strength)
        res.strength[name] = t
        counts, far = set(), set()
        for n in targets:
            best = nearest_spp(name, n, dims=d, strength=t)
            if best is not None:
                (counts if n / max_ratio <= best <= n * max_ratio else far).add(best)
        if not counts:
            at = f" at strength {t}" if t else ""
            res.skipped[name] = (f"no valid sample count for d={d}{at} within a factor {max_ratio:g} of the targets"
                                 + (f" (nearest: {', '.join(map(str, sorted(far)))})" if far else ""))
            continue
        spp = np.array(sorted(counts), dtype=np.int64)
        mean, var, mse = (np.empty(len(spp)) for _ in range(3))
        for k, n in enumerate(spp):
            smp = pyoa.sampler(name, spp=int(n), dims=d, seed=seed,
                               **trial_options(name, {"strength": t, "backend": backend}))
            est = np.empty(trials)
            step = max(1, max_bytes // (4 * int(n) * d))
            for p0 in range(0, trials, step):
                p1 = min(p0 + step, trials)
                est[p0:p1] = f(smp.generate(pixels=range(p0, p1))).mean(axis=-1)
            mean[k] = est.mean()
            var[k] = est.var(ddof=1)
            mse[k] = np.mean((est - f.exact) ** 2)
        res.spp[name], res.mean[name], res.variance[name], res.mse[name] = spp, mean, var, mse
        res.slope[name], res.intercept[name] = fit_loglog(spp.astype(np.float64), var)
        res.mse_slope[name] = fit_loglog(spp.astype(np.float64), mse)[0]
    return res
