"""Progressive multi-jittered (0,2) sequences (pmj02), one value at a time.

The sampler
-----------
``pmj02`` is padded like :func:`~.baselines.sobol02`: dimensions ``(0, 1),
(2, 3), ...`` are pairs ``b = j >> 1``, coordinate ``c = j & 1``, and every
pair of every pixel reads its own randomized copy of one of ``SETS = 16``
precomputed pmj02 sequences of ``POINTS = 2**16`` points (:mod:`pyoa.tables.pmj02`)::

    h     = derived_seed(p, b, PMJ02_KEY)                    # 0 when p == 0
    set   = h >> 28                                          # one of the 16 sets
    shift = derived_seed(h, 1 + c, PMJ02_SHIFT_KEY) >> 8     # 24-bit digital shift
    x     = (table[set, i, c] ^ shift) * 2**-24

Table coordinates are 24-bit integers ``k`` (the value is ``k * 2**-24``), so
the float rule of :mod:`~.baselines` holds: every value is exact in float32
and below 1. ``p == 0`` (the unrandomized set) reads set 0 unshifted.

**Digital shift, not Cranley-Patterson.** XOR-ing the 24-bit binary fraction
with a constant maps every elementary interval ``[a 2**-u, (a+1) 2**-u) x
[c 2**-v, (c+1) 2**-v)`` onto the interval of the same shape with ``a``
and ``c`` XOR-ed by the shift's top ``u`` and ``v`` bits: a bijection of the
intervals of each shape [3]_. So every property of the table that is stated in
elementary intervals survives, for every pixel: each power-of-two prefix
``[0, 2**k)`` is a (0,k,2)-net, hence each coordinate of it is stratified
into ``2**k`` intervals. pbrt-v4's ``PMJ02BNSampler`` [2]_ instead adds a
random offset modulo 1 (a Cranley-Patterson rotation, a toroidal shift):
that moves interval boundaries, so a rotated (0,k,2)-net in general has two
points in some elementary intervals and none in others; the rotation keeps
only the coarse jittered structure.

**A nested index scramble over the whole sequence.** Sample ``i`` is point
``g = owen_scramble(i, ...) mod 2**16`` of the set: every prefix
``[0, 2**k)`` of the samples maps onto an aligned block of ``2**k`` points,
which is a (0,k,2)-net, whatever ``N``, so pmj02 stays progressive (the
first ``n`` samples of a pixel are as good as any ``n``), and each pair of
a pixel reads its set in its own order, so pairs are independent (padding).
pbrt-v4 shuffles the index within the pixel's sample count, which keeps the
full set but not its prefixes. ``log2n`` only bounds ``i``.

The table (Christensen, Kensler and Kilpatrick's pmj02 [1]_) and how it is
built: :mod:`pyoa.reference.pmj02_build`.

References
----------
.. [1] P. Christensen, A. Kensler, C. Kilpatrick, "Progressive Multi-Jittered
   Sample Sequences", Computer Graphics Forum 37(4) (EGSR 2018), 21-33.
.. [2] M. Pharr, W. Jakob, G. Humphreys, pbrt-v4 (``PMJ02BNSampler``), and
   "Physically Based Rendering", 4th ed., section 8.5.
.. [3] J. Dick, F. Pillichshammer, "Digital Nets and Sequences", Cambridge
   University Press, 2010 (digital shifts preserve (t,m,s)-nets).
"""

from __future__ import annotations

from ..tables.pmj02 import tables
from .baselines import UNIT24, derived_seed, owen_scramble
from .hashes import MASK
from .pmj02_build import POINTS, POINTS_LOG2

#: Key of the per-pair seed ``h`` (it picks the set and seeds the shifts).
PMJ02_KEY = 0x2545F491
#: Key of the per-coordinate digital shifts ``derived_seed(h, 1 + c, ...)``.
PMJ02_SHIFT_KEY = 0xD35A2D97
def pmj02(i: int, j: int, log2n: int, p: int) -> float:
    """Padded pmj02: value ``j`` of sample ``i`` of the point set with seed ``p``.

    With ``b = j >> 1``, ``c = j & 1`` and the table ``T`` of
    :func:`pyoa.tables.pmj02.tables`::

        h = derived_seed(p, b, PMJ02_KEY)
        g = owen_scramble(i, derived_seed(h, 0, PMJ02_SHIFT_KEY)) mod 2**16
        x = (T[h >> 28, g, c] ^ (derived_seed(h, 1 + c, PMJ02_SHIFT_KEY) >> 8)) * 2**-24

    For every ``p`` and pair, the first ``2**k`` samples (``k <= 16``) are a
    (0,k,2)-net: one point in each elementary interval of area ``2**-k``.
    The nested (Owen) scramble of the index maps the prefix ``[0, 2**k)``
    onto an aligned block ``[c 2**k, (c+1) 2**k)`` of the set, which is a
    (0,k,2)-net (every aligned block of the balanced construction is one,
    module docstring), whatever ``N``: the sequence stays progressive. It
    also gives each pair its own sample order, so that pairs of one pixel are
    independent (padding, as ``sobol02``): without it, sample ``i`` of every
    set sits in the same subquadrant pattern and the pairs' strata would be
    correlated. The digital shift maps intervals onto intervals.

    Parameters
    ----------
    i : int
        Sample index in ``[0, 2**log2n)``.
    j : int
        Dimension in ``[0, 2**32)``.
    log2n : int
        ``N = 2**log2n`` samples, ``0 <= log2n <= 16``.
    p : int
        Seed of the point set (uint32); 0 gives set 0 unshifted.

    Raises
    ------
    ValueError
        An argument is out of range.
    """
    if not 0 <= log2n <= POINTS_LOG2:
        raise ValueError(f"log2n must be in [0, {POINTS_LOG2}], got {log2n}")
    if not 0 <= i < 1 << log2n:
        raise ValueError(f"sample index i must be in [0, {1 << log2n}), got {i}")
    if not 0 <= j <= MASK:
        raise ValueError(f"dimension j must be in [0, 2**32), got {j}")
    if not 0 <= p <= MASK:
        raise ValueError(f"seed p must be a uint32 in [0, 2**32), got {p}")

    c = j & 1
    h = derived_seed(p, j >> 1, PMJ02_KEY)
    g = owen_scramble(i, derived_seed(h, 0, PMJ02_SHIFT_KEY)) & (POINTS - 1)
    shift = derived_seed(h, 1 + c, PMJ02_SHIFT_KEY) >> 8
    return (int(tables()[h >> 28, g, c]) ^ shift) * UNIT24
