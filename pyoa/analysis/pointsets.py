"""What a point set promises: stratification, Latin hypercubes, discrepancy.

* :func:`cells` maps values in ``[0, 1)`` to their cells ``floor(x s)``
  exactly (no tolerance, float32 and float64);
* :func:`stratification` and :func:`latin_hypercube` check, exactly, whether
  every t-dimensional projection of a point set is stratified (the defining
  property of an orthogonal array of strength t [2]_, [3]_; the
  multi-jittered offsets of the OA samplers add 1D Latin hypercubes [1]_),
  and report which subsets fail (:class:`StratificationReport`);
* :func:`discrepancy` wraps :func:`scipy.stats.qmc.discrepancy` (Hickernell's
  L2 discrepancies [4]_).

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
.. [5] T. J. Dekker, "A floating-point technique for extending the
   available precision", Numerische Mathematik 18 (1971), 224-242.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from ._checks import _int, _points, _unit_values
from ._display import Markdown, field_table

__all__ = ["MAX_SUBSETS", "StratificationReport", "cells", "discrepancy", "latin_hypercube", "stratification"]

#: Largest number of t-subsets :func:`stratification` agrees to check.
MAX_SUBSETS = 1_000_000


# ============================================================================ cells

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
    exactly by Dekker's product [5]_ (Veltkamp's split of ``x``), and the cell
    is ``floor(p) - 1`` where ``p`` is an integer and ``e < 0``. (Rounding is
    monotonic, so ``p`` can cross an integer only by landing on it.)

    pyoa's samplers clamp every value into its own fine cell exactly (SPEC
    section 7), so their points need no tolerance here, jittered or not. Points
    from elsewhere computed as ``(k + u)/s`` in float32 can round onto
    ``(k+1)/s`` when ``u`` is just below 1; they then belong to the next cell.
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

    A report is true (``bool(report)``) exactly when :attr:`passed`; a REPL
    and a notebook show it as a table (:meth:`table`).
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

    def table(self) -> Markdown:
        """Markdown: :meth:`__str__`, then the checked values, a field per row."""
        shown = ", ".join(map(str, self.failing[:8])) + (", ..." if len(self.failing) > 8 else "")
        return field_table(str(self), [
            ("cells per axis, s", self.s), ("subset size, t", self.t), ("points per set, N", self.n_points),
            ("point sets", self.n_sets), ("dimensions", ", ".join(map(str, self.dims))),
            ("subsets checked", self.n_subsets), ("subsets failing", f"{len(self.failing)}: {shown}" if shown else 0),
            ("max deviation", self.max_deviation)])

    def __repr__(self) -> str:
        return repr(self.table())

    def _repr_markdown_(self) -> str:
        return str(self.table())


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
        raise ValueError(  # noqa: TRY004 - bad input is a ValueError throughout pyoa.analysis
            f"dims must be an iterable of ints, got {type(dims).__name__}")
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
