"""Test integrands on ``[0, 1)^d`` with exact integrals.

:data:`INTEGRANDS` maps a name to a factory ``f(d)`` returning an
:class:`Integrand` (which unpacks as ``f, exact``); :func:`integrand` looks a
name up with a clear error. They are smooth (:func:`gaussian`,
:func:`anisotropic_gaussian`, :func:`oscillatory` [2]_, :func:`pairwise`,
:func:`lagged_pairs`, :func:`additive`) and discontinuous (:func:`halfspace`,
:func:`diagonal_halfspace`, :func:`ball`), with and without interactions
between dimensions; every exact integral is a closed form (the half-space
volume in exact rational arithmetic, by inclusion-exclusion [3]_, [4]_).

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
.. [2] A. Genz, "Testing multidimensional integration routines", in *Tools,
   Methods and Languages for Scientific and Engineering Computation*, 1984,
   81-94.
.. [3] D. L. Barrow, P. W. Smith, "Spline notation applied to a volume
   problem", The American Mathematical Monthly 86(1) (1979), 50-51.
.. [4] P. Hall, "The distribution of means for samples of size N drawn from
   a population in which the variate takes values between 0 and 1, all such
   values being equally probable", Biometrika 19 (1927), 240-245.

Examples
--------
>>> from pyoa.analysis.integrands import INTEGRANDS
>>> f, exact = INTEGRANDS["ball"](2)
>>> round(exact, 6)   # pi r^2, r = 0.45
0.636173
>>> f([[0.5, 0.5], [0.0, 0.0]])
array([1., 0.])
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from ._checks import _dim, _int

__all__ = [
    "HALFSPACE_MAX_D", "INTEGRANDS", "Integrand", "additive", "anisotropic_gaussian", "ball",
    "diagonal_halfspace", "gaussian", "halfspace", "integrand", "lagged_pairs", "oscillatory", "pairwise",
]


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
    """Genz's oscillatory integrand [2]_: a plane wave along a tilted direction,
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


def lagged_pairs(d: int, lag: int | None = None, sigma: float = 0.15) -> Integrand:
    r"""Mean of products of dimensions ``lag`` apart,
    :math:`f(x) = \frac{1}{d - L} \sum_{k=0}^{d-L-1} g(x_k)\,g(x_{k+L})` (``g``
    as in :func:`pairwise`, ``L = lag``, default ``d // 2``).

    Exact integral :math:`I_1^2`. Smooth. Coupling ``"pairs"``: its only
    interactions are between dimensions ``lag`` apart. With ``lag`` equal to
    an orthogonal array's block size B (``Sampler.block_dims``) it couples
    each dimension with the same column of the next block: pairs no single
    array can stratify, which pyoa's block rule pairs at random
    (docs/spec.md section 6). Under the rule before that one, dimension
    k + B was a function of dimension k, and the variance of this
    integrand's estimate fell only as about :math:`N^{-1/2}` for a strength-2
    array (the pixel's strata permutation stays a random pairing of the
    column's s bump means), slower than independent points' :math:`N^{-1}`.
    Needs ``1 <= lag < d``.
    """
    d = _int("d", d, 2, 2**20)
    lag = d // 2 if lag is None else _int("lag", lag, 1, d - 1)
    sigma = float(sigma)
    if not sigma > 0:
        raise ValueError(f"sigma must be > 0, got {sigma}")
    g, i1 = _bump(sigma)

    def f(x):
        v = g(x)
        return (v[..., : d - lag] * v[..., lag:]).mean(axis=-1)

    return Integrand("lagged-pairs", d, i1 * i1, f, True, "pairs",
                     f"mean over k < d - {lag} of g(x_k) g(x_(k+{lag})), g(u) = exp(-(u-1/2)^2/(2 sigma^2)); "
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
    every :math:`w_k > 0` [3]_):

    .. math::

        \\int_{[0,1]^d} f = \\frac{1}{d!\\,\\prod_k w_k}
        \\sum_{v \\in \\{0,1\\}^d} (-1)^{|v|} \\max(c - w \\cdot v, 0)^d ;

    for equal weights this is the Irwin-Hall CDF [4]_
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
    "lagged-pairs": lagged_pairs,
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
