"""Owen-scrambled Faure (0, s)-sequences in a prime base: progressive orthogonal arrays.

A (0, s)-sequence in base ``b`` [1]_ is a sequence of points in ``[0, 1)^s``
whose every aligned block of ``b**m`` consecutive points,
``[c b**m, (c+1) b**m)``, is a (0, m, s)-net in base ``b``: every elementary
box of volume ``b**-m`` (a product of ``b``-adic intervals
``[a_k b**-e_k, (a_k + 1) b**-e_k)`` with ``e_1 + ... + e_s = m``) holds
exactly one point. So

- the first ``b**2`` points are an orthogonal array of strength 2 with ``b``
  levels over all ``s`` dimensions (what ``bose`` gives at ``N = b**2``), the
  first ``b**3`` one of strength 3, and so on;
- at ``N = b**m`` every projection onto ``k <= m`` dimensions is stratified
  into all of its elementary boxes (``b**2 x b`` and ``b x b**2`` grids as
  well as ``b x b x b`` cubes for ``m = 3``): a strong orthogonal array [4]_;
- a prefix of ``lam * b**m`` points (``1 <= lam < b``) has exactly ``lam``
  points in every elementary box of volume ``b**-m``: the sequence can stop
  at any count and continue later.

**Faure's construction** [1]_, for ``s <= b`` dimensions: with ``a_0, a_1,
...`` the base-``b`` digits of the index ``i`` (``a_0`` least significant)
and ``A(x) = sum_r a_r x**r``, coordinate ``c`` (``0 <= c < b``) has the
fraction digits ``y_0, y_1, ...`` (``y_0`` most significant) given by the
generator matrix ``P**c``, the ``c``-th power of the Pascal matrix mod ``b``::

    y_k = sum_{r >= k} C(r, k) c**(r - k) a_r  (mod b)

which are the coefficients of the Taylor shift ``A(x + c)`` mod ``b``,
computed by repeated synthetic division (``O(n**2)`` for ``n`` digits).
Coordinate 0 (``P**0 = I``) is the van der Corput sequence.

**Owen's nested uniform scrambling** in base ``b`` [2]_: each output digit is
permuted by a random permutation of ``Z_b`` that depends on the dimension and
on every digit above it. It maps every elementary box onto one of the same
shape, so every net stays a net, and makes each point uniform in
``[0, 1)^s``; for smooth integrands the variance is
``O(N**-3 (log N)**(s-1))`` [3]_. pyoa draws the permutations from Kensler's
hash-based ``permute`` keyed by the prefix, so a value needs only ``i``'s
digits (stateless, like every pyoa sampler)::

    q   = hash_pair(block_seed(p, j // b), j mod b, FAURE_KEY)      (0 if that seed is 0)
    y'_k = permute(y_k, b, hash_pair(q, b**k + (y_0 ... y_{k-1})_b, FAURE_DIGIT_KEY))

(the key ``b**k + prefix`` names the digit position and the digits above it
at once). ``K`` digits are made, the fewest with ``b**K >= 2**24``; with
``F = (y'_0 ... y'_{K-1})_b`` the value is the 24-bit
``x = floor(2**24 F / b**K) * 2**-24``, then clamped into its finest cell
(docs/spec.md section 7): with ``L`` the most digits with ``b**L <= 2**24``
and ``c = floor(F / b**(K - L))`` the cell of ``b**-L``, ``x`` is raised to
``ceil(2**24 c / b**L) * 2**-24`` if the truncation put it below
``c / b**L``. Every cell of width ``b**-L >= 2**-24`` holds a multiple of
``2**-24``, so every elementary box of every net of at most ``2**24``
points keeps its points exactly, in float32.

**Dimensions beyond ``b``** come from independently scrambled copies, as for
the orthogonal arrays (docs/spec.md section 6): dimension ``j`` is
coordinate ``j mod b`` of the copy with seed ``block_seed(p, j // b)``, and
a copy reads the sequence in its own nested order of the samples
(:func:`index_scramble`): were it to read sample ``i`` as the first block
does, dimension ``c + b`` would share every digit with dimension ``c`` and
be a fixed function of it.

``p == 0`` gives the unscrambled Faure sequence in its first ``b``
dimensions (the other blocks are scrambled: no coordinate repeats).

References
----------
.. [1] H. Faure, "Discrépance de suites associées à un système de
   numération (en dimension s)", Acta Arithmetica 41, 1982.
.. [2] A. B. Owen, "Randomly permuted (t,m,s)-nets and (t,s)-sequences",
   Monte Carlo and Quasi-Monte Carlo Methods, 1995.
.. [3] A. B. Owen, "Scrambled net variance for integrals of smooth
   functions", Annals of Statistics 25(4), 1997.
.. [4] Y. He, B. Tang, "Strong orthogonal arrays and associated Latin
   hypercubes for computer experiments", Biometrika 100(1), 2013.
"""

from __future__ import annotations

import functools

from ..tables import sequences
from .baselines import UNIT24, derived_seed
from .hashes import MASK, block_seed, hash_pair, permute

#: Keys of the per-dimension and per-digit seeds (pyoa's choice).
FAURE_KEY = 0x3C6EF372
FAURE_DIGIT_KEY = 0xA54FF53A
FAURE_INDEX_KEY = 0x1F83D9AB

#: Largest base: the largest prime ``b`` with ``b**2 <= 2**24``, so that
#: every base reaches strength 2 within the samplers' limit of ``2**24``.
MAX_BASE = 4093
#: Largest sample index + 1 (the samplers' limit).
MAX_INDEX = 1 << 24


@functools.cache
def bases() -> tuple[int, ...]:
    """Every valid base: the primes up to :data:`MAX_BASE`, in increasing order
    (from :func:`pyoa.tables.sequences.primes`)."""
    return tuple(int(q) for q in sequences.primes() if q <= MAX_BASE)


def out_digits(b: int) -> int:
    """``K``: the fewest base-``b`` digits with ``b**K >= 2**24``."""
    K, power = 0, 1
    while power < MAX_INDEX:
        power *= b
        K += 1
    return K


def cell_digits(b: int) -> int:
    """``L``: the most base-``b`` digits with ``b**L <= 2**24`` (the finest cells kept exactly)."""
    L, power = 0, 1
    while power * b <= MAX_INDEX:
        power *= b
        L += 1
    return L


def index_digits(b: int, n: int) -> int:
    """How many base-``b`` digits the indices ``[0, n)`` have (at least 1)."""
    digits, power = 1, b
    while power < n:
        power *= b
        digits += 1
    return digits


def index_scramble(a: list[int], b: int, s: int) -> list[int]:
    """The digits ``a`` (least significant first) of an index, each permuted
    by a hash of ``s`` and of every digit above it (a nested scramble, from
    the most significant digit down)::

        a'_r = permute(a_r, b, hash_pair(s, b**(D-1-r) + (a_(D-1) ... a_(r+1))_b, FAURE_DIGIT_KEY))

    with ``D = len(a)``. It maps every aligned block of ``b**m`` indices onto
    an aligned block of ``b**m`` indices, so a copy of the sequence read in
    this order keeps every net (and every prefix) of the sequence, while its
    samples are paired with the first copy's at random: dimension ``c + b``
    is no function of dimension ``c``, as it would be if both read sample
    ``i`` of the same sequence (they then share every digit).
    """
    D = len(a)
    out = list(a)
    high, power = 0, 1  # high = (a_(D-1) ... a_(r+1)) in base b, power = b**(D-1-r)
    for r in range(D - 1, -1, -1):
        out[r] = permute(a[r], b, hash_pair(s, power + high, FAURE_DIGIT_KEY))
        high = high * b + a[r]
        power *= b
    return out


def faure(i: int, j: int, b: int, n: int, p: int) -> float:
    """Value of sample ``i``, dimension ``j`` of the Owen-scrambled Faure
    sequence in base ``b`` with seed ``p`` (module docstring).

    Parameters
    ----------
    i : int
        Sample index in ``[0, b**n)`` and ``[0, 2**24)``.
    j : int
        Dimension, ``>= 0``.
    b : int
        Prime base, ``2 <= b <= MAX_BASE``.
    n : int
        Digits of the index the Taylor shift runs over: any ``n`` with
        ``i < b**n`` gives the same value (the higher digits are zero), so
        the value never depends on the sample count; the backends pass the
        digits of their largest index (:func:`index_digits`) to bound the work.
    p : int
        Seed of the point set (uint32).
    """
    if b not in bases():
        raise ValueError(f"base b must be a prime in [2, {MAX_BASE}], got {b}")
    if not 0 <= i < min(MAX_INDEX, b**n):
        raise ValueError(f"sample index i must be in [0, min(2**24, b**n)), got i={i}, b={b}, n={n}")
    if j < 0:
        raise ValueError(f"dimension j must be >= 0, got {j}")
    if not 0 <= p <= MASK:
        raise ValueError(f"seed p must be a uint32 in [0, 2**32), got {p}")
    col, block = j % b, j // b
    P = block_seed(p, block)
    q = derived_seed(P, col, FAURE_KEY)
    a = []
    rest = i
    for _ in range(out_digits(b) if block else n):
        a.append(rest % b)
        rest //= b
    if block:
        # every copy past the first reads the sequence in its own nested order
        a = index_scramble(a, b, hash_pair(P, b, FAURE_INDEX_KEY))
    return digits_value(a, b, col, q)


def digits_value(a: list[int], b: int, col: int, q: int) -> float:
    """Coordinate ``col`` of the index with base-``b`` digits ``a`` (least
    significant first), Owen-scrambled with seed ``q`` (0: unscrambled): the
    Taylor shift, the nested digit scramble and the float rule of the module
    docstring. Only the first ``K`` output digits are made, so the shift
    stops once ``y_0 .. y_(K-1)`` are final (step ``k`` fixes ``y_k``)."""
    n = len(a)
    a = list(a)
    K = out_digits(b)
    # Taylor shift: a becomes the coefficients of A(x + col) mod b, y_k = a[k]
    for k in range(min(n - 1, K)):
        for r in range(n - 2, k - 1, -1):
            a[r] = (a[r] + col * a[r + 1]) % b
    numer, prefix, power = 0, 0, 1  # power = b**k, prefix = (y_0 ... y_{k-1})_b
    for k in range(K):
        y = a[k] if k < n else 0
        numer = numer * b + (permute(y, b, hash_pair(q, power + prefix, FAURE_DIGIT_KEY)) if q else y)
        prefix = prefix * b + y
        power *= b
    x24 = (numer << 24) // power
    # the cell clamp (docs/spec.md section 7): keep x in its cell of b**-L
    fine = b ** cell_digits(b)
    cell = numer // (power // fine)
    return max(x24, ((cell << 24) + fine - 1) // fine) * UNIT24
