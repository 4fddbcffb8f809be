"""Analysis of point sets and samplers: stratification, discrepancy, convergence.

Tools to check what a sampler promises and to measure what it delivers:

* :func:`stratification` and :func:`latin_hypercube` check, exactly, whether
  every t-dimensional projection of a point set is stratified (the defining
  property of an orthogonal array of strength t [1]_, [2]_);
* :func:`discrepancy` wraps :func:`scipy.stats.qmc.discrepancy`;
* :data:`INTEGRANDS` are test integrands on ``[0, 1)^d`` with exact integrals,
  smooth and discontinuous, with and without interactions between dimensions;
* :func:`convergence` estimates the variance of a sampler's per-pixel
  estimator over independent randomizations as the sample count grows, and
  fits its convergence rate (:class:`ConvergenceResult`, with a Markdown
  table and a log-log plot).

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
.. [5] A. Genz, "Testing multidimensional integration routines", in *Tools,
   Methods and Languages for Scientific and Engineering Computation*, 1984,
   81-94.

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

import itertools
import math
import numbers
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

import numpy as np

from .catalogue import nearest_spp
from .samplers import _int as _checked_int
from .samplers import trial_options

__all__ = [
    "StratificationReport", "stratification", "latin_hypercube", "cells", "discrepancy",
    "Integrand", "INTEGRANDS", "integrand", "gaussian", "anisotropic_gaussian", "oscillatory",
    "pairwise", "additive", "halfspace", "diagonal_halfspace", "ball",
    "ConvergenceResult", "convergence", "MAX_SUBSETS", "HALFSPACE_MAX_D", "ErrorSpectrum", "error_spectrum",
]

#: Largest number of t-subsets :func:`stratification` agrees to check.
MAX_SUBSETS = 1_000_000


# ============================================================================ helpers

def _int(name: str, value, lo: int | None = None, hi: int | None = None) -> int:
    """:func:`pyoa.samplers._int`, but every bad value is a ValueError here."""
    try:
        return _checked_int(name, value, lo, hi)
    except TypeError as exc:
        raise ValueError(str(exc)) from None


def _points(points, what: str = "points", closed: bool = False) -> np.ndarray:
    """``points`` as a real array of shape (..., N, d) with every value in [0, 1)
    (or [0, 1] when ``closed``); float32 stays float32, the rest becomes float64."""
    x = _unit_values(points, what, closed)
    if x.ndim < 2:
        raise ValueError(f"{what} must have shape (N, d) (or (..., N, d)), got shape {x.shape}")
    if x.shape[-2] == 0 or x.shape[-1] == 0:
        raise ValueError(f"{what} must hold at least one point of at least one dimension, got shape {x.shape}")
    return x


def _unit_values(values, what: str, closed: bool = False) -> np.ndarray:
    """``values`` (any shape) as a real array with every value finite and in
    [0, 1) (or [0, 1] when ``closed``); float32 stays float32, the rest
    becomes float64."""
    try:
        x = np.asarray(values)
    except ValueError:  # ragged nested sequences
        raise ValueError(f"{what} must be a real array (a regular, not ragged, nested sequence)") from None
    # "m" (timedelta64) counts as an integer subtype to NumPy
    if x.dtype.kind not in "iuf":
        raise ValueError(f"{what} must be a real array, got dtype {x.dtype}")
    if x.dtype not in (np.float32, np.float64):
        x = x.astype(np.float64)
    if x.size == 0:
        return x
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{what} must be finite (found NaN or infinity)")
    lo, hi = float(x.min()), float(x.max())
    if lo < 0 or hi > 1 or (hi == 1 and not closed):
        bad = lo if lo < 0 else hi
        raise ValueError(f"{what} must lie in [0, 1{']' if closed else ')'}, found {bad!r}")
    return x


def cells(x, s: int) -> np.ndarray:
    """The cell ``floor(x * s)`` of every value, computed exactly.

    Parameters
    ----------
    x : array_like of float
        Values in ``[0, 1)``.
    s : int
        Number of cells of ``[0, 1)``, ``1 <= s <= 2**24``.

    Returns
    -------
    numpy.ndarray of int64
        ``k`` with ``k/s <= x < (k+1)/s`` for the value ``x`` as stored (no
        tolerance: a value on a cell edge belongs to the cell above it).

    Raises
    ------
    ValueError
        Values that are not real numbers, not finite (NaN has no cell), or
        outside ``[0, 1)``, as for the other functions of this module.

    Notes
    -----
    A float32 value times an integer ``s <= 2**24`` is exact in float64 (24 +
    25 significant bits), so there ``floor`` is exact, as in the test suite's
    ``strata_exact``. For float64 values the product ``p = fl(x s)`` may round
    up onto an integer; the rounding error ``e = x s - p`` is recovered
    exactly by Dekker's product [1]_ (Veltkamp's split of ``x``), and the cell
    is ``floor(p) - 1`` where ``p`` is an integer and ``e < 0``. (Rounding is
    monotonic, so ``p`` can cross an integer only by landing on it.)

    pyoa's samplers clamp every value into its own fine cell exactly (SPEC
    section 7), so their points need no tolerance here, jittered or not. Points
    from elsewhere computed as ``(k + u)/s`` in float32 can round onto
    ``(k+1)/s`` when ``u`` is just below 1; they then belong to the next cell.

    References
    ----------
    .. [1] T. J. Dekker, "A floating-point technique for extending the
       available precision", Numerische Mathematik 18 (1971), 224-242.
    """
    s = _int("s", s, 1, 2**24)
    return _cells(_unit_values(x, "x"), s)


def _cells(x: np.ndarray, s: int) -> np.ndarray:
    """:func:`cells` of values already checked (finite, in [0, 1), float32 or float64)."""
    if x.dtype == np.float32:
        return np.floor(x.astype(np.float64) * s).astype(np.int64)
    x = x.astype(np.float64)
    p = x * s
    k = np.floor(p)
    c = x * 134217729.0  # 2**27 + 1: Veltkamp's split into two 26-bit halves
    hi = c - (c - x)
    lo = x - hi
    err = (hi * s - p) + lo * s  # exact: s has at most 25 significant bits
    k -= (p == k) & (err < 0)
    return k.astype(np.int64)


# ============================================================================ stratification

@dataclass(frozen=True)
class StratificationReport:
    """Result of :func:`stratification` (or :func:`latin_hypercube`).

    Attributes
    ----------
    s, t : int
        Cells per axis and subset size: each t-subset of ``dims`` was checked
        for ``N / s**t`` points in each of its ``s**t`` cells.
    n_points : int
        Points per set, N.
    n_sets : int
        Number of point sets checked (1 for an (N, d) array; P for (P, N, d)).
    dims : tuple of int
        The dimensions whose t-subsets were checked.
    n_subsets : int
        Number of t-subsets checked, ``comb(len(dims), t)``.
    failing : list of tuple of int
        The t-subsets (increasing dimension indices) that are not stratified
        in at least one set, in lexicographic order.
    max_deviation : int
        ``max |count - N/s**t|`` over every cell of every subset and set (0
        when every subset is stratified).

    A report is true (``bool(report)``) exactly when :attr:`passed`.
    """

    s: int
    t: int
    n_points: int
    n_sets: int
    dims: tuple
    n_subsets: int
    failing: list = field(default_factory=list)
    max_deviation: int = 0

    @property
    def passed(self) -> bool:
        """Whether every checked subset is stratified in every set."""
        return not self.failing

    @property
    def per_cell(self) -> int:
        """Points each cell must hold, ``N / s**t``."""
        return self.n_points // self.s**self.t

    @property
    def failing_dims(self) -> list[int]:
        """The dimensions that appear in a failing subset (for t = 1: the
        dimensions that are not stratified)."""
        return sorted({j for sub in self.failing for j in sub})

    def __bool__(self) -> bool:
        return self.passed

    def __str__(self) -> str:
        head = (f"{self.n_subsets} subset(s) of {self.t} of {len(self.dims)} dimension(s), {self.s}^{self.t} cells, "
                f"N={self.n_points}, {self.n_sets} set(s)")
        if self.passed:
            return f"stratified: {head}"
        shown = ", ".join(map(str, self.failing[:8])) + (", ..." if len(self.failing) > 8 else "")
        return f"NOT stratified: {len(self.failing)} of {head} fail (max deviation {self.max_deviation}): {shown}"


def stratification(points, s: int, t: int, *, dims: Iterable[int] | None = None) -> StratificationReport:
    """Check that every t-dimensional projection of a point set is stratified.

    A set of N points is stratified in the dimensions ``(j_1, ..., j_t)`` at
    ``s`` levels when each of the ``s**t`` cells

    .. math::

        \\prod_{m=1}^{t} \\left[\\frac{k_m}{s}, \\frac{k_m + 1}{s}\\right),
        \\qquad k_m \\in \\{0, \\dots, s-1\\},

    holds exactly :math:`\\lambda = N / s^t` points. A randomized orthogonal
    array OA(N, d, s, t) of index :math:`\\lambda` has this property for every
    t-subset of its d columns [2]_, [3]_; a 1D Latin hypercube is the case
    ``s = N``, ``t = 1`` (:func:`latin_hypercube`).

    Parameters
    ----------
    points : array_like, shape (N, d) or (..., N, d)
        Points in ``[0, 1)``. With leading axes (``Sampler.generate``'s
        (pixels, N, d)), every set is checked and a subset fails if it fails
        in any set.
    s : int
        Levels per axis, ``1 <= s <= 2**24``.
    t : int
        Subset size (strength), ``1 <= t <= len(dims)``. ``s**t`` must divide N.
    dims : iterable of int, optional
        Distinct dimensions to check (default all d); e.g. one block,
        ``range(smp.block_dims)``.

    Returns
    -------
    StratificationReport
        Which subsets fail, and the largest deviation of a cell count from
        ``N / s**t``.

    Raises
    ------
    ValueError
        Points that are not finite or outside ``[0, 1)``; ``s**t`` not
        dividing N; bad ``t`` or ``dims``; more than :data:`MAX_SUBSETS`
        (10^6) subsets to check.

    Notes
    -----
    Cells are computed exactly (:func:`cells`, no tolerance). For each subset
    the cell indices combine into one code :math:`\\sum_m k_m s^{t-m}` (plus
    an offset per set) counted by one :func:`numpy.bincount`: the cost is
    :math:`O(\\binom{|dims|}{t} \\cdot P N t)`.

    Examples
    --------
    >>> import numpy as np
    >>> g = (np.stack(np.meshgrid(np.arange(4), np.arange(4)), -1).reshape(-1, 2) + 0.5) / 4
    >>> stratification(g, s=4, t=2).passed
    True
    >>> stratification(np.full((16, 3), 0.1), s=2, t=2).failing
    [(0, 1), (0, 2), (1, 2)]
    """
    x = _points(points)
    s = _int("s", s, 1, 2**24)
    N, d = x.shape[-2:]
    dims = _dims(dims, d)
    t = _int("t", t, 1, len(dims))
    n_subsets = math.comb(len(dims), t)
    if n_subsets > MAX_SUBSETS:
        raise ValueError(f"{n_subsets} subsets of {t} of {len(dims)} dimensions to check, over the limit of "
                         f"{MAX_SUBSETS}; pass fewer dims= (e.g. one block) or a smaller t")
    n_cells = s**t
    lam, rem = divmod(N, n_cells)
    if rem or lam == 0:
        raise ValueError(f"N={N} points cannot be stratified into s^t = {s}^{t} = {n_cells} cells: "
                         f"s^t must divide N")
    sets = x.reshape(-1, N, d)
    n_sets = len(sets)
    k = _cells(sets[:, :, list(dims)], s)  # (n_sets, N, len(dims)), only the dims checked
    base = (np.arange(n_sets, dtype=np.int64) * n_cells)[:, None]
    failing, worst = [], 0
    for sub in itertools.combinations(range(len(dims)), t):
        code = base.copy()
        mult = 1
        for c in reversed(sub):
            code = code + k[:, :, c] * mult
            mult *= s
        counts = np.bincount(code.ravel(), minlength=n_sets * n_cells)
        dev = int(np.abs(counts - lam).max())
        if dev:
            failing.append(tuple(dims[c] for c in sub))
            worst = max(worst, dev)
    return StratificationReport(s=s, t=t, n_points=N, n_sets=n_sets, dims=tuple(dims), n_subsets=n_subsets,
                                failing=failing, max_deviation=worst)


def _dims(dims, d: int) -> list[int]:
    if dims is None:
        return list(range(d))
    if isinstance(dims, (str, bytes)) or not isinstance(dims, Iterable):
        raise ValueError(f"dims must be an iterable of ints, got {type(dims).__name__}")
    out = [_int("dims entry", j, 0, d - 1) for j in dims]
    if not out:
        raise ValueError("dims must name at least one dimension")
    if len(set(out)) != len(out):
        raise ValueError(f"dims must be distinct, got {out}")
    return sorted(out)


def latin_hypercube(points, *, dims: Iterable[int] | None = None) -> StratificationReport:
    """Check that every dimension is a 1D Latin hypercube: one point per cell
    :math:`[k/N, (k+1)/N)`, :math:`k = 0, \\dots, N-1`.

    This is :func:`stratification` with ``s = N`` and ``t = 1``: the
    multi-jittered (``mj``) and correlated multi-jittered (``cmj``) offsets
    of the OA samplers promise it in every dimension [1]_, exactly (their
    values are clamped into their cells; see :func:`cells`).

    Parameters
    ----------
    points : array_like, shape (N, d) or (..., N, d)
        Points in ``[0, 1)``, N <= 2**24.
    dims : iterable of int, optional
        Dimensions to check (default all).

    Returns
    -------
    StratificationReport
        ``failing`` holds 1-tuples ``(j,)``; :attr:`StratificationReport.failing_dims`
        lists the dimensions that are not Latin hypercubes.
    """
    x = _points(points)
    N = x.shape[-2]
    if N > 2**24:
        raise ValueError(f"latin_hypercube supports N <= 2^24 points, got {N}")
    return stratification(x, N, 1, dims=dims)


# ============================================================================ discrepancy

_DISCREPANCY_METHODS = ("CD", "WD", "MD", "L2-star")


def discrepancy(points, method: str = "CD", *, workers: int = 1):
    """Discrepancy of a point set, by :func:`scipy.stats.qmc.discrepancy`.

    Parameters
    ----------
    points : array_like, shape (N, d) or (..., N, d)
        Points in ``[0, 1]``; cast to float64.
    method : {"CD", "WD", "MD", "L2-star"}
        Centered (default), wrap-around, mixture or L2-star discrepancy
        (Hickernell [4]_). The squared centered L2 discrepancy is

        .. math::

            CD^2 = \\left(\\tfrac{13}{12}\\right)^d
            - \\frac{2}{N} \\sum_{i} \\prod_k \\left(1 + \\tfrac12 |x_{ik} - \\tfrac12|
            - \\tfrac12 |x_{ik} - \\tfrac12|^2\\right)
            + \\frac{1}{N^2} \\sum_{i,j} \\prod_k \\left(1 + \\tfrac12 |x_{ik} - \\tfrac12|
            + \\tfrac12 |x_{jk} - \\tfrac12| - \\tfrac12 |x_{ik} - x_{jk}|\\right);

        SciPy returns the squared value (as here).
    workers : int
        Threads SciPy may use (``-1``: all).

    Returns
    -------
    float or numpy.ndarray
        One value for an (N, d) array; an array of shape ``points.shape[:-2]``
        otherwise.

    Raises
    ------
    ValueError
        Points outside ``[0, 1]`` or not finite; an unknown method.
    """
    from scipy.stats import qmc

    if method not in _DISCREPANCY_METHODS:
        raise ValueError(f"unknown discrepancy method {method!r}; valid: {', '.join(_DISCREPANCY_METHODS)}")
    x = _points(points, closed=True).astype(np.float64)
    if x.ndim == 2:
        return float(qmc.discrepancy(x, method=method, workers=workers))
    flat = x.reshape(-1, *x.shape[-2:])
    out = np.array([qmc.discrepancy(a, method=method, workers=workers) for a in flat])
    return out.reshape(x.shape[:-2])


# ============================================================================ integrands

@dataclass(frozen=True, eq=False)
class Integrand:
    """A function on ``[0, 1)^d`` with its exact integral.

    Call it on an array of shape (..., d) to get float64 values of shape
    (...). It also unpacks as ``f, exact = integrand``, so a registry entry
    reads ``f, exact = INTEGRANDS["gaussian"](d)``.

    Attributes
    ----------
    name : str
        Registry name (:data:`INTEGRANDS`).
    d : int
        Dimension.
    exact : float
        :math:`\\int_{[0,1]^d} f(x)\\,dx`, from a closed form.
    smooth : bool
        Whether ``f`` is infinitely differentiable (False: discontinuous).
    coupling : str
        Which interactions between dimensions ``f`` has (its ANOVA terms):
        ``"none"`` (additive), ``"pairs"`` (second order only, every pair) or
        ``"all"`` (terms of every order).
    formula : str
        The function and its exact integral, in words.
    """

    name: str
    d: int
    exact: float
    func: Callable = field(repr=False)
    smooth: bool = True
    coupling: str = "all"
    formula: str = ""

    def __call__(self, x) -> np.ndarray:
        x = np.asarray(x, dtype=np.float64)
        if x.ndim < 1 or x.shape[-1] != self.d:
            raise ValueError(f"integrand {self.name!r} is {self.d}-dimensional; got points of shape {x.shape}")
        return self.func(x)

    def __iter__(self):
        return iter((self, self.exact))


def _dim(d) -> int:
    return _int("d", d, 1, 2**20)


def _bump_1d_integral(sigma: float, center: float) -> float:
    """:math:`\\int_0^1 e^{-(u-c)^2/(2\\sigma^2)} du
    = \\sigma\\sqrt{\\pi/2}\\,[\\mathrm{erf}((1-c)/(\\sigma\\sqrt2)) + \\mathrm{erf}(c/(\\sigma\\sqrt2))]`."""
    r = sigma * math.sqrt(2.0)
    return sigma * math.sqrt(math.pi / 2.0) * (math.erf((1.0 - center) / r) + math.erf(center / r))


def _per_dim(name: str, value, d: int) -> np.ndarray:
    a = np.broadcast_to(np.asarray(value, dtype=np.float64), (d,)).copy() if np.ndim(value) == 0 else \
        np.asarray(value, dtype=np.float64)
    if a.shape != (d,):
        raise ValueError(f"{name} must be a number or {d} numbers, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite")
    return a


def gaussian(d: int, sigma=0.15, center=0.5) -> Integrand:
    """Gaussian bump :math:`f(x) = \\exp(-\\sum_k (x_k - c_k)^2 / (2\\sigma_k^2))`.

    Exact integral, a product of 1D integrals:

    .. math::

        \\int_{[0,1]^d} f = \\prod_{k=1}^{d} \\sigma_k \\sqrt{\\pi/2}
        \\left[\\operatorname{erf}\\frac{1 - c_k}{\\sigma_k\\sqrt2}
        + \\operatorname{erf}\\frac{c_k}{\\sigma_k\\sqrt2}\\right],

    which for the isotropic default (:math:`\\sigma = 0.15`, :math:`c = 0.5`)
    is :math:`(\\sigma\\sqrt{2\\pi}\\,\\operatorname{erf}(1/(2\\sqrt2\\sigma)))^d`.

    Smooth. Coupling ``"all"``: a product of non-constant 1D factors has ANOVA
    terms of every order, pairs included, so it rewards stratifying pairs
    across padded pairs (see the module notes).

    Parameters
    ----------
    d : int
        Dimension.
    sigma : float or sequence of d floats
        Widths, > 0.
    center : float or sequence of d floats
        Centre, in [0, 1].
    """
    d = _dim(d)
    sig, cen = _per_dim("sigma", sigma, d), _per_dim("center", center, d)
    if np.any(sig <= 0) or np.any(cen < 0) or np.any(cen > 1):
        raise ValueError("gaussian needs sigma > 0 and center in [0, 1]")
    exact = math.prod(_bump_1d_integral(float(a), float(c)) for a, c in zip(sig, cen))
    inv = 1.0 / (2.0 * sig**2)

    def f(x):
        return np.exp(-np.sum((x - cen) ** 2 * inv, axis=-1))

    iso = bool(np.all(sig == sig[0]) and np.all(cen == cen[0]))
    return Integrand("gaussian" if iso else "anisotropic-gaussian", d, exact, f, True, "all",
                     "exp(-sum_k (x_k - c_k)^2 / (2 sigma_k^2)); exact = prod_k sigma_k sqrt(pi/2) "
                     "[erf((1-c_k)/(sigma_k sqrt 2)) + erf(c_k/(sigma_k sqrt 2))]")


def anisotropic_gaussian(d: int) -> Integrand:
    """Axis-aligned anisotropic, off-centre Gaussian: :func:`gaussian` with
    widths :math:`\\sigma_k` evenly from 0.1 to 0.3 and centres :math:`c_k`
    evenly from 0.35 to 0.65 (both constant 0.2 and 0.5 when d = 1). Smooth,
    coupling ``"all"``."""
    d = _dim(d)
    sig = np.linspace(0.1, 0.3, d) if d > 1 else np.array([0.2])
    cen = np.linspace(0.35, 0.65, d) if d > 1 else np.array([0.5])
    g = gaussian(d, sig, cen)
    return Integrand("anisotropic-gaussian", d, g.exact, g.func, True, "all", g.formula)


def oscillatory(d: int, a=None, u: float = 0.3) -> Integrand:
    """Genz's oscillatory integrand [5]_: a plane wave along a tilted direction,
    :math:`f(x) = \\cos(2\\pi u + a \\cdot x)`.

    Exact integral, from :math:`\\int_0^1 e^{i a_k x} dx = (e^{i a_k} - 1)/(i a_k)`
    (1 when :math:`a_k = 0`):

    .. math::

        \\int_{[0,1]^d} f = \\operatorname{Re}\\left[e^{2\\pi i u}
        \\prod_{k=1}^{d} \\frac{e^{i a_k} - 1}{i a_k}\\right].

    Smooth. Coupling ``"all"``: the wave is rotated relative to the axes
    (:math:`\\cos(\\alpha + \\beta) = \\cos\\alpha\\cos\\beta - \\sin\\alpha\\sin\\beta`
    expands into products of every subset of dimensions).

    Parameters
    ----------
    d : int
        Dimension.
    a : float or sequence of d floats, optional
        Frequencies; default :math:`a_k` evenly from 3 to 6 (4.5 when d = 1).
    u : float
        Phase, in turns.
    """
    d = _dim(d)
    if a is None:
        a = np.linspace(3.0, 6.0, d) if d > 1 else 4.5
    a = _per_dim("a", a, d)
    u = float(u)
    phase = 2.0 * math.pi * u
    terms = [1.0 + 0j if ak == 0 else (np.exp(1j * ak) - 1.0) / (1j * ak) for ak in a]
    exact = float((np.exp(1j * phase) * np.prod(terms)).real)

    def f(x):
        return np.cos(phase + x @ a)

    return Integrand("oscillatory", d, exact, f, True, "all",
                     "cos(2 pi u + a.x); exact = Re[exp(2 pi i u) prod_k (exp(i a_k) - 1)/(i a_k)]")


def _bump(sigma: float):
    inv = 1.0 / (2.0 * sigma**2)
    return (lambda x: np.exp(-((x - 0.5) ** 2) * inv)), _bump_1d_integral(sigma, 0.5)


def pairwise(d: int, sigma: float = 0.15) -> Integrand:
    """Mean of products over every pair of dimensions,
    :math:`f(x) = \\binom{d}{2}^{-1} \\sum_{j<k} g(x_j)\\,g(x_k)` with the 1D bump
    :math:`g(u) = e^{-(u - 1/2)^2/(2\\sigma^2)}`.

    Exact integral :math:`I_1^2`, :math:`I_1 = \\int_0^1 g = \\sigma\\sqrt{2\\pi}
    \\operatorname{erf}(1/(2\\sqrt2\\sigma))`.

    Smooth. Coupling ``"pairs"``: ANOVA terms of order 1 and 2 only, for every
    pair, including the pairs across padded pairs ((1, 2), (0, 3), ...) that
    padding leaves unstratified and a strength-2 OA stratifies; the cleanest
    test of the paper's claim [1]_. Needs d >= 2.
    """
    d = _int("d", d, 2, 2**20)
    sigma = float(sigma)
    if not sigma > 0:
        raise ValueError(f"sigma must be > 0, got {sigma}")
    g, i1 = _bump(sigma)
    norm = 2.0 / (d * (d - 1))

    def f(x):
        v = g(x)
        s1 = v.sum(axis=-1)
        return norm * 0.5 * (s1 * s1 - (v * v).sum(axis=-1))

    return Integrand("pairwise", d, i1 * i1, f, True, "pairs",
                     "mean over pairs j<k of g(x_j) g(x_k), g(u) = exp(-(u-1/2)^2/(2 sigma^2)); "
                     "exact = (sigma sqrt(2 pi) erf(1/(2 sqrt 2 sigma)))^2")


def additive(d: int, sigma: float = 0.15) -> Integrand:
    """Mean of 1D bumps, :math:`f(x) = \\frac1d \\sum_k g(x_k)` (``g`` as in
    :func:`pairwise`); exact integral :math:`I_1`.

    Smooth. Coupling ``"none"``: no interactions, so any sampler that is a 1D
    Latin hypercube (or stratified) in every dimension integrates it equally
    well; a control case where orthogonal arrays cannot beat padding.
    """
    d = _dim(d)
    sigma = float(sigma)
    if not sigma > 0:
        raise ValueError(f"sigma must be > 0, got {sigma}")
    g, i1 = _bump(sigma)

    def f(x):
        return g(x).mean(axis=-1)

    return Integrand("additive", d, i1, f, True, "none",
                     "(1/d) sum_k g(x_k); exact = sigma sqrt(2 pi) erf(1/(2 sqrt 2 sigma))")


def _halfspace_volume(w: Sequence[Fraction], c: Fraction) -> Fraction:
    """Exact volume of ``{x in [0,1]^d : w.x < c}`` for w_k > 0, by
    inclusion-exclusion over the cube's vertices (equal weights: the
    Irwin-Hall CDF with d+1 terms)."""
    d = len(w)
    den = math.factorial(d) * math.prod(w)
    if all(wk == w[0] for wk in w):  # Irwin-Hall: sum over |v| = k
        terms = (math.comb(d, k) * (-1) ** k * max(c - k * w[0], 0) ** d for k in range(d + 1))
        return Fraction(sum(terms)) / den
    total = Fraction(0)
    for v in itertools.product((0, 1), repeat=d):
        r = c - sum((wk for wk, vk in zip(w, v) if vk), Fraction(0))
        if r > 0:
            total += (-1) ** sum(v) * r**d
    return total / den


#: Largest d of a halfspace with unequal weights (the exact volume sums 2^d terms).
HALFSPACE_MAX_D = 18


def halfspace(d: int, weights=None, c=None) -> Integrand:
    """Oriented Heaviside: the indicator of the half-space :math:`w \\cdot x < c`.

    Exact integral, the volume of the cube below the hyperplane
    (inclusion-exclusion over the vertices :math:`v \\in \\{0,1\\}^d`, valid for
    every :math:`w_k > 0`):

    .. math::

        \\int_{[0,1]^d} f = \\frac{1}{d!\\,\\prod_k w_k}
        \\sum_{v \\in \\{0,1\\}^d} (-1)^{|v|} \\max(c - w \\cdot v, 0)^d ;

    for equal weights this is the Irwin-Hall CDF
    :math:`\\frac{1}{d!}\\sum_{k=0}^{\\lfloor c \\rfloor} (-1)^k \\binom{d}{k}(c-k)^d`
    (at :math:`w = 1`). Evaluated in exact rational arithmetic from the float
    values of ``weights`` and ``c``, then rounded once.

    Discontinuous. Coupling ``"all"``: the edge is a tilted hyperplane, so the
    function is not a sum of lower-dimensional parts.

    Parameters
    ----------
    d : int
        Dimension (at most 18 for unequal weights: the sum has :math:`2^d`
        terms).
    weights : float or sequence of d floats, optional
        Positive normal; default :math:`w_k` evenly from 1 to 2 (tilted, not
        the diagonal).
    c : float, optional
        Offset; default :math:`0.4 \\sum_k w_k` (volume below 1/2; at
        :math:`0.5 \\sum_k w_k` the volume is exactly 1/2 by the symmetry
        :math:`x \\mapsto 1 - x`).
    """
    d = _dim(d)
    if weights is None:
        weights = np.linspace(1.0, 2.0, d) if d > 1 else 1.0
    w = _per_dim("weights", weights, d)
    if np.any(w <= 0):
        raise ValueError("halfspace weights must be > 0")
    if not np.all(w == w[0]) and d > HALFSPACE_MAX_D:
        raise ValueError(f"halfspace with unequal weights supports d <= {HALFSPACE_MAX_D} (the exact volume "
                         f"sums 2^d terms), got d={d}")
    c = 0.4 * float(w.sum()) if c is None else float(c)
    if not math.isfinite(c):
        raise ValueError(f"c must be finite, got {c}")
    exact = float(_halfspace_volume([Fraction(float(v)) for v in w], Fraction(c)))
    name = "diagonal-halfspace" if np.all(w == 1.0) else "halfspace"

    def f(x):
        return (x @ w < c).astype(np.float64)

    return Integrand(name, d, exact, f, False, "all",
                     "1[w.x < c]; exact = sum_{v in {0,1}^d} (-1)^|v| max(c - w.v, 0)^d / (d! prod w)")


def diagonal_halfspace(d: int, c=None) -> Integrand:
    """The simplex-like corner :math:`\\sum_k x_k < c`: :func:`halfspace` with
    unit weights, exact integral the Irwin-Hall CDF
    :math:`F_d(c) = \\frac{1}{d!}\\sum_{k=0}^{\\lfloor c\\rfloor}(-1)^k\\binom{d}{k}(c-k)^d`.
    Default :math:`c = 0.4 d`. Discontinuous, coupling ``"all"``; any d."""
    d = _dim(d)
    return halfspace(d, 1.0, 0.4 * d if c is None else c)


def ball(d: int, r: float = 0.45) -> Integrand:
    """Indicator of the ball :math:`|x - \\tfrac12| < r` centred in the cube.

    Exact integral, for :math:`r \\le 1/2` (the ball lies inside the cube):

    .. math::

        \\int_{[0,1]^d} f = \\frac{\\pi^{d/2}}{\\Gamma(d/2 + 1)}\\, r^d .

    Discontinuous. Coupling ``"all"`` (:math:`\\sum_k (x_k - 1/2)^2 < r^2`
    under a step).

    Parameters
    ----------
    d : int
        Dimension.
    r : float
        Radius, ``0 < r <= 0.5``.
    """
    d = _dim(d)
    r = float(r)
    if not 0 < r <= 0.5:
        raise ValueError(f"ball radius must be in (0, 0.5] (the ball must lie inside the cube), got {r}")
    exact = math.exp(0.5 * d * math.log(math.pi) - math.lgamma(0.5 * d + 1) + d * math.log(r))
    r2 = r * r

    def f(x):
        return (np.sum((x - 0.5) ** 2, axis=-1) < r2).astype(np.float64)

    return Integrand("ball", d, exact, f, False, "all",
                     "1[|x - 1/2| < r]; exact = pi^(d/2) r^d / Gamma(d/2 + 1)")


#: name -> factory(d) returning an :class:`Integrand` (which unpacks as ``(f, exact)``).
INTEGRANDS: dict[str, Callable[[int], Integrand]] = {
    "gaussian": gaussian,
    "anisotropic-gaussian": anisotropic_gaussian,
    "oscillatory": oscillatory,
    "pairwise": pairwise,
    "additive": additive,
    "halfspace": halfspace,
    "diagonal-halfspace": diagonal_halfspace,
    "ball": ball,
}


def integrand(name: str, d: int) -> Integrand:
    """``INTEGRANDS[name](d)``, with a clear error for an unknown name."""
    return _lookup(name, d)


def _lookup(name: str, d: int) -> Integrand:
    if not isinstance(name, str) or name not in INTEGRANDS:
        raise ValueError(f"unknown integrand {name!r}; valid: {', '.join(INTEGRANDS)}")
    return INTEGRANDS[name](d)


# ============================================================================ convergence

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

    def table(self) -> str:
        """Markdown: one row per sampler and count (mean, variance, MSE), then
        one per sampler with the fitted slopes, then the skipped samplers."""
        f = self.integrand
        lines = [f"Integrand `{f.name}` (d={self.d}, exact {f.exact:.10g}, coupling {f.coupling}), "
                 f"{self.trials} trials, seed {self.seed}", "",
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
        return "\n".join(lines) + "\n"

    def plot(self, path, *, metric: str = "variance", dpi: int = 100) -> Path:
        """Write a log-log plot of variance (or MSE) against N, one line per
        sampler with its fitted slope in the legend.

        Uses Matplotlib's Agg canvas directly (no pyplot state, no backend
        switch) and writes atomically (:func:`pyoa.atomic.atomic_path`); the
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

        from .atomic import atomic_path

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
            slope, icpt = _fit(n, v)
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


def _fit(n: np.ndarray, v: np.ndarray) -> tuple[float, float]:
    keep = (v > 0) & np.isfinite(v)
    if len(np.unique(n[keep])) < 2:
        return math.nan, math.nan
    slope, icpt = np.polyfit(np.log(n[keep]), np.log(v[keep]), 1)
    return float(slope), float(icpt)


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
    :math:`\\log V` against :math:`\\log N` (:func:`numpy.polyfit`): -1 for
    independent random points, -(1 + 2/d) for jittered sampling of smooth
    integrands, -(1 + 1/d) for discontinuous ones [3]_.

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
        raise ValueError(f"integrand must be a name in INTEGRANDS or an Integrand, got {type(integrand).__name__}")
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
        res.slope[name], res.intercept[name] = _fit(spp.astype(np.float64), var)
        res.mse_slope[name] = _fit(spp.astype(np.float64), mse)[0]
    return res


# ============================================================================ screen-space error spectra

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
    """

    sampler: str
    integrand: str
    spp: int
    size: int
    seeds: int
    power: np.ndarray = field(repr=False)
    radii: np.ndarray = field(repr=False)
    radial: np.ndarray = field(repr=False)
    low: float
    rmse: float


def error_spectrum(sampler: str, *, spp: int, size: int = 64, seeds: int = 8, integrand: str = "ball",
                   seed: int = 0, backend: str | None = None) -> ErrorSpectrum:
    """How a sampler's per-pixel errors are distributed across the image.

    Each pixel of a ``size x size`` image estimates the integral of the 2D
    ``integrand`` with its own ``spp`` samples (dimensions 0 and 1, pixels
    numbered row-major); the error image ``e(x, y) = estimate - exact`` is
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
        A 2D integrand of :data:`INTEGRANDS` (default ``"ball"``: a disk,
        discontinuous like a shadow edge).
    seed : int
        First user seed; images use ``seed, seed + 1, ...``.
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
    f = _lookup(integrand, 2)
    options = {"backend": backend, "resolution": (size, size)} if pyoa.catalogue.get(sampler).needs_resolution \
        else {"backend": backend}
    acc = np.zeros((size, size))
    sq = 0.0
    for k in range(seeds):
        smp = pyoa.sampler(sampler, spp=spp, dims=2, seed=seed + k, **options)
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
    return ErrorSpectrum(sampler=pyoa.catalogue.get(sampler).name, integrand=f.name, spp=smp.spp, size=size,
                         seeds=seeds, power=power, radii=radii, radial=radial, low=low,
                         rmse=math.sqrt(sq / seeds))
