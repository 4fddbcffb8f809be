"""Orthogonal-array samplers of docs/spec.md section 5, one value at a time.

Each function returns ``x(i, j)``: dimension ``j`` of sample ``i`` of the
array with seed ``p``, as a Python float holding a float32 value in
``[0, 1)``. A value is built from one OA entry (docs/spec.md section 1)::

    x = (stratum + (sub + jitter) / M) / s

with ``stratum = permute(A_ij, s, P1_j)``, ``sub`` chosen by the offset style
(docs/spec.md section 4) and ``jitter = 0.5 + J * (randfloat(i, P3_j) - 0.5)``.
Dimensions past a block of ``B`` columns come from independently
randomized copies of the array, each read in its own sample order
(docs/spec.md section 6, :func:`~.hashes.locate`).

Each sampler is split like ``pyoa._numpy.oa`` and ``kernels/include/pyoa/oa.h``: a
``*_cell`` function gives the integer cell of row ``row`` in column ``col``
(``A_ij`` and the sub-stratum index ``u``; for Bose the partner entry
``A_ik``), and one shared frame, :func:`oa_value`, applies the block rule
and turns a cell into ``x``.

References
----------
.. [1] W. Jarosz, A. Enayet, A. Kensler, C. Kilpatrick, P. Christensen,
   "Orthogonal Array Sampling for Monte Carlo Rendering", Computer Graphics
   Forum (EGSR) 38(4), 2019.
.. [2] R. C. Bose, "On the application of the properties of Galois fields to
   the problem of construction of hyper-Graeco-Latin squares", Sankhya 3, 1938.
"""

from __future__ import annotations

from typing import NamedTuple

from ..tables import gf
from .floats import f32, jitter_value, sample_value
from .hashes import MASK, dimension_seeds, locate, permute, randfloat

#: Offset styles of docs/spec.md section 4, in the order of their kernel codes.
OFFSETS = ("centered", "j", "mj", "cmj")


def _check_common(i: int, N: int, j: int, p: int, offset: str, jitter: float) -> float:
    if not 0 <= i < N:
        raise ValueError(f"sample index i must be in [0, {N}), got {i}")
    if j < 0:
        raise ValueError(f"dimension j must be >= 0, got {j}")
    if not 0 <= p <= MASK:
        raise ValueError(f"seed p must be a uint32 in [0, 2**32), got {p}")
    if offset not in OFFSETS:
        raise ValueError(f"unknown offset {offset!r}; valid: {', '.join(OFFSETS)}")
    if not 0.0 <= jitter <= 1.0:  # also rejects NaN
        raise ValueError(f"jitter must be in [0, 1], got {jitter}")
    return f32(jitter)


def _centered(M: int) -> float:
    # (M-1)/2 is an integer or a half-integer below 2**23: exact in float32.
    return (M - 1) / 2


def _offset_sub(offset: str, u: int, M: int, cell_key: int, aij: int, P2: int) -> float:
    """The sub-stratum of docs/spec.md section 4: ``u`` (the point's index inside its
    coarse stratum, in ``[0, M)``) permuted with a seed per cell (``j``:
    ``cell_key * P2``), per stratum (``mj``: ``(A_ij + 1) * P2``) or per
    column (``cmj``: ``P2``); ``centered`` is ``(M - 1) / 2``. ``cell_key`` is
    ``A_ik s + A_ij + 1`` for Bose and ``row + 1`` for the other constructions."""
    if offset == "centered":
        return _centered(M)
    seed = {"j": cell_key * P2, "mj": (aij + 1) * P2, "cmj": P2}[offset]
    return permute(u, M, seed & MASK)


class Geometry(NamedTuple):
    """The shape of one construction's array (docs/spec.md section 1.4): ``N``
    rows, ``B`` columns per block, ``s`` symbols, ``M = N / s`` sub-strata.
    Each construction's ``*_geometry`` function below is its only definition:
    the NumPy and Dr.Jit implementations and the catalogue
    (:mod:`pyoa.catalogue.constructions`, whose ``Params`` carry ``block_dims = B`` and
    ``M`` to the OpenCL kernels) read it from here."""

    N: int
    B: int
    s: int
    M: int


def bose_geometry(s: int, t: int = 2) -> Geometry:
    """Bose: ``N = s**2``, ``s + 1`` columns, ``M = s``."""
    return Geometry(s * s, s + 1, s, s)


def bush_geometry(s: int, t: int) -> Geometry:
    """Bush: ``N = s**t``, ``s + 1`` columns, ``M = s**(t-1)``."""
    return Geometry(s**t, s + 1, s, s ** (t - 1))


def cmjnd_geometry(s: int, t: int) -> Geometry:
    """CMJND: ``N = s**t``, ``t`` columns, ``M = s**(t-1)``."""
    return Geometry(s**t, t, s, s ** (t - 1))


def addelman_kempthorne_geometry(q: int, t: int = 2) -> Geometry:
    """Addelman-Kempthorne: ``N = 2 q**2``, ``2q + 1`` columns, ``M = 2q``."""
    return Geometry(2 * q * q, 2 * q + 1, q, 2 * q)


def bose_bush_geometry(s: int, t: int = 2) -> Geometry:
    """Bose-Bush: ``N = 2 s**2``, ``2s + 1`` columns, ``M = 2s``."""
    return Geometry(2 * s * s, 2 * s + 1, s, 2 * s)


def oa_value(i: int, j: int, p: int, offset: str, jitter: float, geometry: Geometry, cell) -> float:
    """``x(i, j)`` of an orthogonal array of shape ``geometry`` (``N`` rows,
    ``B`` columns per block, ``s`` symbols, ``M = N / s`` sub-strata), seed
    ``p``: the frame every construction shares.

    The block rule (:func:`~.hashes.locate`, docs/spec.md section 6) gives
    the copy's seed ``P``, the row and the column; ``cell(row, col)`` (the
    construction's only part) gives ``(A_ij, u, cell_key)``; then the common
    tail of docs/spec.md section 5.2::

        stratum = permute(A_ij, s, P1)
        sub     = section 4's offset (from u, M, cell_key, A_ij, P2)
        x       = (stratum + (sub + jitter(randfloat(row, P3))) / M) / s

    with ``(P1, P2, P3)`` the column's seeds (:func:`~.hashes.dimension_seeds`).
    """
    N, B, s, M = geometry
    J = _check_common(i, N, j, p, offset, jitter)
    P, row, col = locate(p, i, j, B, N)
    aij, u, cell_key = cell(row, col)
    P1, P2, P3 = dimension_seeds(P, col)
    stratum = permute(aij, s, P1)
    sub = _offset_sub(offset, u, M, cell_key, aij, P2)
    return sample_value(stratum, sub, jitter_value(randfloat(row, P3), J), M, s)


def bose(i: int, j: int, s: int, p: int, offset: str = "cmj", jitter: float = 1.0) -> float:
    """Bose OA sample, strength 2: ``s`` a prime power, ``N = s**2``, ``s + 1`` columns per block.

    The integer array is ``A_i0 = i // s``, ``A_i1 = i % s`` and
    ``A_ij = A_i0 + (j-1) A_i1`` in GF(s) for ``2 <= j <= s`` (the multiplier
    is the field element with code ``j-1``; mod-s arithmetic for prime s). Column ``j`` is
    paired with column ``k`` (1 for 0, 0 for 1, ``j-1`` for odd ``j``, ``j+1``
    for even ``j``, with ``k-1`` taken mod s), whose entry places the point
    inside its coarse stratum: ``M = s`` sub-strata.

    Parameters
    ----------
    i : int
        Sample index in ``[0, s**2)``.
    j : int
        Dimension, any ``j >= 0`` (blocks of ``s + 1``).
    s : int
        Strata per axis: a prime, or a prime power up to 256 (:mod:`pyoa.tables.gf`).
    p : int
        Array seed (uint32); 0 is the canonical array.
    offset : {"cmj", "mj", "j", "centered"}
        Offset style (docs/spec.md section 4).
    jitter : float
        Jitter amount J in [0, 1].
    """
    if not gf.is_supported(s):
        raise ValueError(f"bose needs s prime or a prime power <= {gf.MAX_TABLE_Q}, got s={s}")
    def cell(row, col):
        aij, aik = bose_cell(row, col, s)
        return aij, aik, aik * s + aij + 1  # the 'j' offset's key is the (A_ij, A_ik) cell

    return oa_value(i, j, p, offset, jitter, bose_geometry(s), cell)


def bose_cell(i: int, col: int, s: int) -> tuple[int, int]:
    """``(A_ij, A_ik)`` of Bose column ``col < s + 1`` and its partner column
    ``k``, over GF(s) (see :func:`bose`)."""
    a0, a1 = i // s, i % s
    if col == 0:
        return a0, a1
    if col == 1:
        return a1, a0
    k = col - 1 if col % 2 else col + 1
    return gf.add(a0, gf.mul(col - 1, a1, s), s), gf.add(a0, gf.mul((k - 1) % s, a1, s), s)


def cmjnd(i: int, j: int, s: int, t: int, p: int, offset: str = "cmj", jitter: float = 1.0) -> float:
    """High-dimensional correlated multi-jittered sample [1]_: any ``s >= 2``, ``N = s**t``.

    ``A_ij`` is the ``j``-th base-``s`` digit of ``i`` (least significant
    first), so the ``t`` columns form a full ``t``-dimensional grid of
    ``s**t`` coarse cells (strength ``t``). The other ``t - 1`` digits, read
    as a base-``s`` number ``v = i mod s**j + (i // s**(j+1)) s**j``, pick one
    of ``M = s**(t-1)`` sub-strata, which makes every dimension a 1D Latin
    hypercube for ``mj`` and ``cmj``.

    Parameters
    ----------
    i : int
        Sample index in ``[0, s**t)``.
    j : int
        Dimension, any ``j >= 0`` (blocks of ``t``).
    s : int
        Strata per axis, ``s >= 2``.
    t : int
        Strength: dimensions per block, ``t >= 1``.
    p, offset, jitter
        As for :func:`bose`.
    """
    if s < 2 or t < 1:
        raise ValueError(f"cmjnd needs s >= 2 and t >= 1, got s={s}, t={t}")
    return oa_value(i, j, p, offset, jitter, cmjnd_geometry(s, t), lambda row, col: (*cmjnd_cell(row, col, s), row + 1))


def cmjnd_cell(i: int, col: int, s: int) -> tuple[int, int]:
    """``(A_ij, v)`` of CMJND column ``col < t``: digit ``col`` of ``i`` in base
    ``s`` and the number formed by the other digits (see :func:`cmjnd`)."""
    sj = s**col
    return (i // sj) % s, i % sj + (i // (sj * s)) * sj


def bush(i: int, j: int, s: int, t: int, p: int, offset: str = "cmj", jitter: float = 1.0) -> float:
    """Bush OA sample of strength ``t``: ``s`` a prime power, ``t <= s``, ``N = s**t``, ``s + 1`` columns.

    Row ``i`` has base-``s`` digits ``c_0 .. c_{t-1}`` (``c_0`` least
    significant), the coefficients of ``f_i(x) = sum_l c_l x**l``. Column
    ``j < s`` is ``f_i(j)`` evaluated in GF(s); column ``s`` is the leading
    coefficient ``c_{t-1}``. Two polynomials of degree < t that agree at t
    points are equal, so every t columns show each t-tuple once: strength t.

    Sub-strata (``M = s**(t-1)``): in column ``j < s``, ``u = i // s`` (the
    digits ``c_1..c_{t-1}``): inside one coarse stratum ``c_0`` is fixed by the
    others, so ``u`` takes every value in ``[0, M)`` once. In column ``s`` the
    stratum *is* ``c_{t-1}``, the top digit of ``i // s``, so there
    ``u = i mod M`` (the digits ``c_0..c_{t-2}``) instead, which again takes
    every value once per stratum. With ``permute(u, M, .)`` per stratum
    (``mj``) or shared by all strata (``cmj``) every column is then a 1D
    Latin hypercube for every t (the authors' correlated variant kept that
    only for t = 3; SPEC's ``u = i // s`` for column s would repeat values).

    Parameters
    ----------
    i : int
        Sample index in ``[0, s**t)``.
    j : int
        Dimension, any ``j >= 0`` (blocks of ``s + 1``).
    s : int
        Strata per axis: a prime, or a prime power up to 256.
    t : int
        Strength, ``2 <= t <= s``.
    p, offset, jitter
        As for :func:`bose`.

    References
    ----------
    .. [1] K. A. Bush, "Orthogonal arrays of index unity", Ann. Math. Statist.
       23(3), 1952.
    """
    if not gf.is_supported(s) or not 2 <= t <= s:
        raise ValueError(f"bush needs s prime or a prime power <= {gf.MAX_TABLE_Q} and 2 <= t <= s, got s={s}, t={t}")
    return oa_value(i, j, p, offset, jitter, bush_geometry(s, t), lambda row, col: (*bush_cell(row, col, s, t), row + 1))


def bush_cell(i: int, col: int, s: int, t: int) -> tuple[int, int]:
    """``(A_ij, u)`` of Bush column ``col < s + 1``: the row polynomial at
    ``col`` in GF(s) (its leading coefficient for ``col == s``) and the
    sub-stratum index (see :func:`bush`)."""
    c = [(i // s**l) % s for l in range(t)]
    if col == s:
        return c[t - 1], i % s ** (t - 1)
    aij = 0
    for coeff in reversed(c):  # Horner: f(col) = (...(c_{t-1} col + c_{t-2}) col + ...) + c_0
        aij = gf.add(gf.mul(aij, col, s), coeff, s)
    return aij, i // s


def addelman_kempthorne(i: int, j: int, q: int, p: int, offset: str = "cmj", jitter: float = 1.0) -> float:
    """Addelman-Kempthorne OA sample: strength 2, index 2, ``q`` an odd prime
    power, ``N = 2 q**2``, ``2q + 1`` columns per block.

    Row ``i = h q**2 + x q + y`` (half ``h``, ``x, y`` in GF(q)); with the
    constants ``kappa, b, k, c`` of :func:`pyoa.tables.gf.ak_constants`:

    ============  =======================  ==================================
    column        first half (h = 0)       second half (h = 1)
    ============  =======================  ==================================
    0             y                        y
    m = 1..q-1    x + m y                  x + m y + b[m]
    q             y + x**2                 y + kappa x**2
    q + m         y + m x + x**2           y + k[m] x + kappa x**2 + c[m]
    2q            x                        x
    ============  =======================  ==================================

    All ``2q + 1`` columns, the full standard set (the last one adds a few
    triple coincidences between rows but keeps strength 2).

    Sub-strata (``M = 2q``): in columns 1..q-1 and 2q a stratum fixes ``x``
    given ``y`` and ``h``, so ``u = h q + y``; in columns 0 and q..2q-1 it
    fixes ``y``, so ``u = h q + x``. Either takes every value in ``[0, 2q)``
    once per stratum, so ``mj`` and ``cmj`` are 1D Latin hypercubes.

    References
    ----------
    .. [1] S. Addelman and O. Kempthorne, "Some main-effect plans and
       orthogonal arrays of strength two", Ann. Math. Statist. 32(4), 1961.
    .. [2] A. S. Hedayat, N. J. A. Sloane, J. Stufken, "Orthogonal Arrays",
       Springer, 1999, section 3.4.
    """
    pr = gf.prime_power(q)
    if pr is None or pr[0] == 2 or not gf.is_supported(q):
        raise ValueError(f"addelman-kempthorne needs q an odd prime, or odd prime power <= {gf.MAX_TABLE_Q}, got {q}")
    return oa_value(i, j, p, offset, jitter, addelman_kempthorne_geometry(q),
                    lambda row, col: (*addelman_kempthorne_cell(row, col, q), row + 1))


def addelman_kempthorne_cell(i: int, col: int, q: int) -> tuple[int, int]:
    """``(A_ij, u)`` of Addelman-Kempthorne column ``col < 2q + 1``, over GF(q)
    (see the table of :func:`addelman_kempthorne`)."""
    kappa, b, k, c = gf.ak_constants(q)
    h, x, y = i // (q * q), (i // q) % q, i % q
    add, mul = (lambda a, b_: gf.add(a, b_, q)), (lambda a, b_: gf.mul(a, b_, q))
    x2 = mul(x, x)
    if col == 0:
        return y, h * q + x
    if col < q:
        return add(add(x, mul(col, y)), b[col] if h else 0), h * q + y
    if col == q:
        return add(y, mul(kappa, x2) if h else x2), h * q + x
    if col < 2 * q:
        m = col - q
        if h:
            return add(add(add(y, mul(k[m], x)), mul(kappa, x2)), c[m]), h * q + x
        return add(add(y, mul(m, x)), x2), h * q + x
    return x, h * q + y


def bose_bush(i: int, j: int, s: int, p: int, offset: str = "cmj", jitter: float = 1.0) -> float:
    """Bose-Bush OA sample: strength 2, index 2, ``s = 2**r``, ``N = 2 s**2``,
    ``2s + 1`` columns per block.

    Computed in GF(2s) (elements are bit patterns, addition is XOR). Row
    ``i = x s + k`` with ``x`` in GF(2s) and ``k < s``; column ``j < 2s`` is
    ``low_r(x * j) XOR k`` (the low ``r`` bits of the field product), and
    column ``2s`` is ``x mod s``.

    Sub-strata (``M = 2s``): in a column ``j < 2s`` a stratum fixes ``k`` given
    ``x``, so ``u = x``; in column ``2s`` it fixes ``x mod s``, so
    ``u = (x // s) s + k``. Both take every value in ``[0, 2s)`` once per
    stratum: ``mj`` and ``cmj`` are 1D Latin hypercubes (the authors' version
    offered jittered offsets only).

    References
    ----------
    .. [1] R. C. Bose and K. A. Bush, "Orthogonal arrays of strength two and
       three", Ann. Math. Statist. 23(4), 1952.
    .. [2] A. S. Hedayat, N. J. A. Sloane, J. Stufken, "Orthogonal Arrays",
       Springer, 1999, section 3.5.
    """
    if s < 2 or s & (s - 1) or 2 * s > gf.MAX_TABLE_Q:
        raise ValueError(f"bose-bush needs s a power of two with 2 <= s <= {gf.MAX_TABLE_Q // 2}, got {s}")
    return oa_value(i, j, p, offset, jitter, bose_bush_geometry(s), lambda row, col: (*bose_bush_cell(row, col, s), row + 1))


def bose_bush_cell(i: int, col: int, s: int) -> tuple[int, int]:
    """``(A_ij, u)`` of Bose-Bush column ``col < 2s + 1``, computed in GF(2s)
    (see :func:`bose_bush`)."""
    x, k = i // s, i % s
    if col < 2 * s:
        return (gf.mul(x, col, 2 * s) % s) ^ k, x
    return x % s, (x // s) * s + k
