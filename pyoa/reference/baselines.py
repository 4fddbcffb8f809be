"""The comparison samplers of the paper's tables, one value at a time.

Jarosz et al. [1]_ compare orthogonal arrays against Random, 2D padding of
jittered, correlated multi-jittered and (0,2)-sequence points, Halton and
Sobol. pyoa evaluates each of them, like its OA samplers, as a stateless
function ``x(i, j)`` of the sample index ``i`` and dimension ``j`` of the
point set with seed ``p`` (one pixel's set; :func:`~.hashes.pixel_seed`), so
that any value can be computed alone and every backend gives the same bits.
``p == 0`` is the unrandomized set where one exists (cell centres in natural
order, plain Halton and Sobol), as for the OAs (docs/spec.md section 3).

**Padding** (``jittered2d``, ``cmj2d``, ``sobol02``): dimensions ``(0, 1),
(2, 3), ...`` are pairs ``b = j // 2``, each an independent 2D point set with
its own seed ``q_b = hash_pair(p, b, PAD_KEY)`` that also shuffles the order
of its samples, so different pairs are independent (Kensler's "padding").

**Float rule.** Values of ``random``, ``sobol02``, ``halton`` and ``sobol``
are ``k * 2**-24`` for an integer ``k < 2**24``: the 24 leading bits of the
scrambled 32-bit (or base-``b``) fraction, exact in float32 and always below
1. ``jittered2d`` and ``cmj2d`` use the OA samplers' float path
(:func:`~.floats.sample_value`, docs/spec.md section 7).

References
----------
.. [1] W. Jarosz, A. Enayet, A. Kensler, C. Kilpatrick, P. Christensen,
   "Orthogonal Array Sampling for Monte Carlo Rendering", EGSR 2019.
.. [2] A. Kensler, "Correlated Multi-Jittered Sampling", Pixar Technical
   Memo 13-01, 2013.
.. [3] B. Burley, "Practical Hash-based Owen Scrambling", Journal of
   Computer Graphics Techniques 9(4), 2020.
.. [4] A. B. Owen, "Randomly permuted (t,m,s)-nets and (t,s)-sequences",
   Monte Carlo and Quasi-Monte Carlo Methods, 1995.
"""

from __future__ import annotations

from ..tables import sequences
from .floats import f32, jitter_value, sample_value
from .hashes import MASK, hash_pair, mix32, permute, randfloat

#: Keys of the per-pair, per-dimension and per-digit seeds (pyoa's choice).
RANDOM_KEY = 0xC2B2AE35
PAD_KEY = 0x85EBCA6B
HALTON_KEY = 0x27D4EB2F
DIGIT_KEY = 0x165667B1
SOBOL_KEY = 0x9E3779B9
OWEN_KEY = 0xCC9E2D51
#: Multipliers of Kensler's CMJ [2]_: sample shuffle, x and y sub-strata
#: permutations, x and y jitter (the same constants as SPEC's OA seeds).
SHUFFLE_KEY = 0x51633E2D
SUBX_KEY = 0x68BC21EB
SUBY_KEY = 0x02E5BE93
JITX_KEY = 0x967A889B
JITY_KEY = 0x368CC8B7

#: ``2**-24``: the grid of the 24-bit values.
UNIT24 = 2.0**-24


def unit24(h: int) -> float:
    """``(h >> 8) * 2**-24``: the top 24 bits of a uint32 as a float32 in [0, 1), exactly."""
    return (h >> 8) * UNIT24


def derived_seed(p: int, index: int, key: int) -> int:
    """``hash_pair(p, index, key)``, or 0 for the unrandomized set ``p == 0``."""
    return hash_pair(p, index, key) if p else 0


def reverse_bits(x: int) -> int:
    """The 32 bits of ``x`` in reverse order."""
    return int(f"{x:032b}"[::-1], 2)


def laine_karras(x: int, seed: int) -> int:
    """Burley's hash in the style of Laine and Karras [3]_: each output bit
    depends only on the same and lower input bits (the multipliers are even),
    so on reversed bits it is a nested (Owen) permutation."""
    x = (x + seed) & MASK
    x ^= (x * 0x6C50B47C) & MASK
    x ^= (x * 0xB82F1E52) & MASK
    x ^= (x * 0xC7AFE638) & MASK
    x ^= (x * 0x8D22F6E6) & MASK
    return x


def owen_scramble(x: int, seed: int) -> int:
    """Hash-based Owen scrambling of a 32-bit fraction [3]_ [4]_: bit ``k`` of
    the result is bit ``k`` of ``x`` flipped by a hash of ``seed`` and the
    bits above ``k``. Every elementary dyadic interval of a point set is
    mapped onto one of the same size, so nets stay nets. ``seed == 0`` is the
    identity (the unscrambled set)."""
    if seed == 0:
        return x
    return reverse_bits(laine_karras(reverse_bits(x), seed))


def sobol_bits(g: int, dim: int) -> int:
    """The 32-bit unscrambled Sobol coordinate ``dim`` of index ``g``: the XOR
    of the direction numbers :func:`pyoa.tables.sequences.sobol_matrices` over the
    set bits of ``g``."""
    v = sequences.sobol_matrices()[dim]
    x = 0
    k = 0
    while g:
        if g & 1:
            x ^= int(v[k])
        g >>= 1
        k += 1
    return x


def _check(i: int, N: int, j: int, p: int, max_dims: int | None = None) -> None:
    if not 0 <= i < N:
        raise ValueError(f"sample index i must be in [0, {N}), got {i}")
    if j < 0 or (max_dims is not None and j >= max_dims):
        raise ValueError(f"dimension j must be in [0, {max_dims}), got {j}" if max_dims else
                         f"dimension j must be >= 0, got {j}")
    if not 0 <= p <= MASK:
        raise ValueError(f"seed p must be a uint32 in [0, 2**32), got {p}")


def _jitter(jitter: float) -> float:
    if not 0.0 <= jitter <= 1.0:  # also rejects NaN
        raise ValueError(f"jitter must be in [0, 1], got {jitter}")
    return f32(jitter)


def random(i: int, j: int, p: int) -> float:
    """Independent uniform random values: ``unit24(mix32(i ^ hash_pair(p, j, RANDOM_KEY)))``.

    No stratification at all: the paper's "Random". For one ``(p, j)`` the
    map ``i -> value`` is injective on the top 24 bits' preimages (``mix32``
    is a bijection), and ``hash_pair`` decorrelates dimensions and pixels.
    ``p == 0`` is not special here: there is no unrandomized random set.

    Parameters
    ----------
    i : int
        Sample index, any uint32.
    j : int
        Dimension, ``j >= 0``.
    p : int
        Seed of the point set (uint32).
    """
    _check(i, 2**32, j, p)
    return unit24(mix32(i ^ hash_pair(p, j & MASK, RANDOM_KEY)))


def jittered2d(i: int, j: int, m: int, dims: int, p: int, jitter: float = 1.0) -> float:
    """Padded 2D jittered sampling: ``N = m**2``, each pair of dimensions one
    ``m x m`` jittered grid (one point in every cell).

    Pair ``b = j // 2`` with seed ``q = hash_pair(p, b, PAD_KEY)``: sample
    ``i`` takes cell ``k = permute(i, N, q * SHUFFLE_KEY)`` (the shuffle that
    makes pairs independent), column ``k mod m`` and row ``k // m``, and is
    jittered inside it by ``randfloat(k, q * JITX_KEY)`` (x) or
    ``randfloat(k, q * JITY_KEY)`` (y)::

        x = (k mod m + jitter_x) / m,    y = (k // m + jitter_y) / m

    When ``dims`` is odd the last dimension is alone: it is a 1D jittered set
    of ``N`` strata, ``x = (k + jitter_x) / N``.

    Parameters
    ----------
    i : int
        Sample index in ``[0, m**2)``.
    j : int
        Dimension in ``[0, dims)``.
    m : int
        Strata per axis, ``1 <= m <= 4096``.
    dims : int
        Total number of dimensions of the sampler (decides whether ``j`` is a
        lone last dimension).
    p : int
        Seed of the point set; 0 gives the cell centres in natural order.
    jitter : float
        Jitter amount in [0, 1] (0: cell centres), as for the OA samplers.
    """
    N = m * m
    _check(i, N, j, p, dims)
    J = _jitter(jitter)
    q = derived_seed(p, j >> 1, PAD_KEY)
    k = permute(i, N, (q * SHUFFLE_KEY) & MASK)
    if j + 1 == dims and j % 2 == 0:  # a lone last dimension: 1D jittered, N strata
        return sample_value(k, 0.0, jitter_value(randfloat(k, (q * JITX_KEY) & MASK), J), 1, N)
    if j % 2 == 0:
        return sample_value(k % m, 0.0, jitter_value(randfloat(k, (q * JITX_KEY) & MASK), J), 1, m)
    return sample_value(k // m, 0.0, jitter_value(randfloat(k, (q * JITY_KEY) & MASK), J), 1, m)


def cmj2d(i: int, j: int, m: int, n: int, p: int, jitter: float = 1.0) -> float:
    """Padded correlated multi-jittered 2D sampling (Kensler [2]_): ``N = m n``.

    Pair ``b = j // 2`` with seed ``q = hash_pair(p, b, PAD_KEY)``. Kensler's
    construction with that seed::

        k  = permute(i, N, q * SHUFFLE_KEY)          # shuffled sample
        sx = permute(k mod m, m, q * SUBX_KEY)       # one permutation for all rows
        sy = permute(k // m, n, q * SUBY_KEY)        # one permutation for all columns
        x  = (k mod m + (sy + jitter_x) / n) / m
        y  = (k // m + (sx + jitter_y) / m) / n

    The coarse cell is ``(k mod m, k // m)``; the sub-cell permutations
    ``sx`` of the column and ``sy`` of the row place the point inside it
    (using ``sx`` also as x's column would tie x's column to y's sub-row and
    bias every estimate).

    Every pair is an ``m x n`` jittered grid (one point per cell) and both
    coordinates are 1D Latin hypercubes of ``N`` strata; a lone odd last
    dimension is the x of its pair, which is therefore still stratified into
    ``N`` strata.

    Parameters
    ----------
    i : int
        Sample index in ``[0, m n)``.
    j : int
        Dimension, ``j >= 0``.
    m, n : int
        Columns and rows of the grid (``m <= n``, chosen by the catalogue as
        the most nearly square factorization of ``N``).
    p : int
        Seed of the point set; 0 gives the canonical (unshuffled, centred) pattern.
    jitter : float
        Jitter amount in [0, 1].
    """
    N = m * n
    _check(i, N, j, p)
    J = _jitter(jitter)
    q = derived_seed(p, j >> 1, PAD_KEY)
    k = permute(i, N, (q * SHUFFLE_KEY) & MASK)
    sx = permute(k % m, m, (q * SUBX_KEY) & MASK)
    if j % 2 == 0:
        sy = permute(k // m, n, (q * SUBY_KEY) & MASK)
        return sample_value(k % m, float(sy), jitter_value(randfloat(k, (q * JITX_KEY) & MASK), J), n, m)
    return sample_value(k // m, float(sx), jitter_value(randfloat(k, (q * JITY_KEY) & MASK), J), m, n)


def sobol02(i: int, j: int, log2n: int, p: int) -> float:
    """Padded (0,2)-sequence: each pair of dimensions the first two Sobol
    dimensions, Owen-scrambled and shuffled per pair (Burley [3]_).

    Pair ``b = j // 2`` with seed ``q = hash_pair(p, b, PAD_KEY)``::

        g = owen_scramble(i, hash_pair(q, 0, OWEN_KEY)) mod N   # nested shuffle of the order
        x = unit24(owen_scramble(sobol_bits(g, 0), hash_pair(q, 1, OWEN_KEY)))
        y = unit24(owen_scramble(sobol_bits(g, 1), hash_pair(q, 2, OWEN_KEY)))

    The three scramble seeds are hashed, not ``q`` times constants: the top
    ``l`` levels of Burley's scramble depend only on the low ``l`` bits of
    its seed, and the low bits of ``q * A`` and ``q * B`` are tied, which
    would correlate x and y below the net's resolution.

    Owen scrambling the index maps every prefix ``[0, 2**k)`` onto an aligned
    block ``[c 2**k, (c+1) 2**k)`` of the sequence, which is a (0,k,2)-net;
    scrambling the coordinates keeps nets nets. So every power-of-two prefix
    of every pair has one point in each elementary interval of area
    ``2**-k``, exactly (the 24-bit truncation keeps each point in its
    interval, whose sides are at least ``2**-24``).

    Parameters
    ----------
    i : int
        Sample index in ``[0, 2**log2n)``.
    j : int
        Dimension, ``j >= 0``.
    log2n : int
        ``N = 2**log2n`` samples, ``0 <= log2n <= 24``.
    p : int
        Seed of the point set; 0 gives the plain first two Sobol dimensions.
    """
    N = 1 << log2n
    _check(i, N, j, p)
    q = derived_seed(p, j >> 1, PAD_KEY)
    g = owen_scramble(i, derived_seed(q, 0, OWEN_KEY)) & (N - 1)
    return unit24(owen_scramble(sobol_bits(g, j & 1), derived_seed(q, 1 + (j & 1), OWEN_KEY)))


def _halton_digits(b: int) -> int:
    """K: the number of base-``b`` digits produced, the least with ``b**K >= 2**24``
    (enough for every index below ``2**24`` and for 24-bit values)."""
    K, power = 0, 1
    while power < 1 << 24:
        power *= b
        K += 1
    return K


def halton(i: int, j: int, p: int) -> float:
    """Owen-scrambled Halton: dimension ``j`` is the radical inverse of ``i``
    in the ``j``-th prime base ``b``, with every digit permuted by a hash of
    the digits before it (Owen's nested scrambling in base ``b`` [4]_).

    With ``d_1, d_2, ...`` the base-``b`` digits of ``i`` (``d_1`` least
    significant) and ``q = hash_pair(p, j, HALTON_KEY)``, digit ``k`` of the
    fraction is::

        d'_k = permute(d_k, b, hash_pair(q, b**(k-1) + (i mod b**(k-1)), DIGIT_KEY))

    (the key ``b**(k-1) + prefix`` names the digit position and every digit
    before it at once). ``K`` digits are made, the least with
    ``b**K >= 2**24``, and the value is ``floor(2**24 F / b**K) * 2**-24``
    with ``F = sum d'_k b**(K-k)``, computed in 64-bit integers. ``p == 0``
    gives the plain radical inverse. In every dimension the first ``b**k``
    samples are stratified into ``b**k`` intervals (up to the 24-bit
    truncation at interval ends).

    Parameters
    ----------
    i : int
        Sample index in ``[0, 2**24)``.
    j : int
        Dimension in ``[0, 6542)`` (the primes below ``2**16``).
    p : int
        Seed of the point set.
    """
    _check(i, 1 << 24, j, p, sequences.HALTON_MAX_DIMS)
    b = int(sequences.primes()[j])
    q = derived_seed(p, j, HALTON_KEY)
    K = _halton_digits(b)
    rest, prefix, power, numer = i, 0, 1, 0
    for _ in range(K):
        d = rest % b
        rest //= b
        # power = b**(k-1) and prefix = i mod b**(k-1) (the original digits)
        numer = numer * b + (permute(d, b, hash_pair(q, power + prefix, DIGIT_KEY)) if q else d)
        prefix += d * power
        power *= b
    return ((numer << 24) // power) * UNIT24


def sobol(i: int, j: int, p: int) -> float:
    """Owen-scrambled Sobol sequence in up to 21201 dimensions (Joe-Kuo
    direction numbers, :mod:`pyoa.tables.sequences`), in SciPy's Gray-code order.

    Sample ``i`` is the Sobol point of index ``g = i ^ (i >> 1)``, the order
    :class:`scipy.stats.qmc.Sobol` produces (``p == 0`` equals
    ``qmc.Sobol(d, scramble=False)`` point for point, truncated to 24 bits);
    every dimension is then Owen-scrambled with its own seed
    ``hash_pair(p, j, SOBOL_KEY)`` [3]_::

        x = unit24(owen_scramble(sobol_bits(g, j), hash_pair(p, j, SOBOL_KEY)))

    Every power-of-two prefix is a (t,m,s)-net, scrambled or not: the first
    ``2**k`` samples of any one dimension are stratified into ``2**k``
    intervals, of dimensions 0 and 1 into every elementary interval of area
    ``2**-k``.

    Parameters
    ----------
    i : int
        Sample index in ``[0, 2**24)``.
    j : int
        Dimension in ``[0, 21201)``.
    p : int
        Seed of the point set.
    """
    _check(i, 1 << 24, j, p, sequences.SOBOL_MAX_DIMS)
    return unit24(owen_scramble(sobol_bits(i ^ (i >> 1), j), derived_seed(p, j, SOBOL_KEY)))
