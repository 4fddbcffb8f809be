"""pbrt-v4's ``ZSobolSampler``, one value at a time: Sobol' points ordered
along a Morton (Z) curve of the image, with hash-permuted base-4 digits.

Ahmed and Wonka [1]_ give every pixel its own consecutive block of a single
(0,2)-sequence, handed out along a hierarchically permuted Z-order curve of
the image: neighbouring pixels get blocks that together form larger nets, so
the per-pixel errors are negatively correlated and the error image is blue
noise, while each pixel alone keeps a (0,k,2)-net. pbrt-v4 [2]_ computes the
sample index of a (pixel, sample) pair without any table; this module is that
computation with pyoa's hashes (the NumPy mirror is
:mod:`pyoa._numpy.zsobol`, the C one ``kernels/include/pyoa/zsobol.h``).

**The Morton index.** A ``W x H`` image (``1 <= W, H <= 2**16``) numbers its
pixels row-major, ``pixel = y W + x``. Each pixel has ``N = 2**k`` samples
(``k = log2n``, ``0 <= k <= 24``). With ``res`` the smallest power of two
``>= max(W, H)`` and ``log2res = log2(res)`` (:func:`resolution_log2`),
sample ``i`` of pixel ``(x, y)`` has the Morton index::

    m = (morton2(x, y) << k) | i

where :func:`morton2` interleaves the bits of ``x`` (even bits) and ``y``
(odd bits), pbrt's ``EncodeMorton2``. ``x, y < 2**16``, so ``m < 2**56``.

**The permuted index.** ``m`` is read as ``D = log2res + ceil(k / 2)`` base-4
digits; for odd ``k`` the digits sit at bit pairs ``(1, 2), (3, 4), ...`` and
bit 0 is a lone binary digit. Pair ``b`` of dimensions has the key
``q = hash_pair(seed, b, ZSOBOL_KEY)`` (never 0). Each digit, from the most
significant down, is replaced by its image under one of the 24 permutations
of ``{0, 1, 2, 3}``, chosen by a hash of the digits above it (unpermuted) and
the key; the lone bit is flipped by such a hash::

    odd = k & 1
    K = (0x55555555 q) mod 2**64
    g = 0
    for d = D-1 down to odd:
        s = 2 d - odd
        higher = m >> (s + 2)
        g |= PERMS[(mix64(higher ^ K) >> 24) mod 24][(m >> s) & 3] << s
    if odd:
        g |= (m & 1) ^ (mix64((m >> 1) ^ K) & 1)

(:func:`sample_index`; ``mix64`` is pbrt's ``MixBits``, :func:`mix64`;
``PERMS`` is :data:`PERMS`). This is a nested (Owen-style) scrambling of the
digits of ``m``: a bijection of ``[0, 4**D)`` (or ``[0, 2 4**(D-1))`` for
odd ``k``) that maps every aligned block of the digit tree onto an aligned
block of the same size.

**The values.** Dimension ``j`` is coordinate ``c = j & 1`` of pair
``b = j >> 1`` (padded pairs, as :func:`~.baselines.sobol02`)::

    x = unit24(owen_scramble(sobol_bits(g mod 2**32, c), hash_pair(q, 1 + c, OWEN_KEY)))

with the first two Sobol' dimensions (:func:`~.baselines.sobol_bits`) and
Burley's hash-based Owen scrambling [3]_ (:func:`~.baselines.owen_scramble`).
Only the low 32 bits of ``g`` matter: dimensions 0 and 1 of the Sobol'
sequence have 32-bit direction numbers ``v_0 .. v_31``, and index bits 32 and
above would only contribute direction numbers whose bits are all below
``2**-32`` (zero in a 32-bit fraction), so the index is taken modulo
``2**32`` and the digits at bit 32 and above need not be computed (their
hashes still see the whole ``m``).

**Per-pixel nets.** The digit boundaries never straddle bit ``k`` (for even
``k`` the digits are the pairs ``(0, 1), (2, 3), ...``; for odd ``k`` bit 0
is alone and the pairs ``(1, 2), (3, 4), ...`` end at bit ``k - 1``), and a
digit's permutation depends only on the digits above it. So the low ``k``
bits of ``m`` (the sample ``i``) are permuted among themselves by a
permutation that depends only on the pixel, and the high bits are mapped by
a function of the high bits alone: the ``N`` indices ``g`` of one pixel are
an aligned block ``[c N, (c + 1) N)``, and distinct pixels of the ``res x
res`` square get disjoint blocks (for even ``k`` and a square power-of-two
image, ``(pixel, i) -> g`` is a bijection onto ``[0, res**2 N)``). An aligned
block of ``2**k`` points of the (0,2)-sequence is a (0,k,2)-net and Owen
scrambling keeps nets nets, so **every pixel's N samples of every pair are a
(0,k,2)-net**: one point in each elementary interval ``2**-u x 2**-v``,
``u + v = k``; in particular each coordinate is stratified into ``N``
intervals. The 24-bit truncation keeps every point in its interval (whose
sides are at least ``2**-24``).

**Differences from pbrt-v4.**

* Hashes: pyoa's :func:`~.hashes.hash_pair` and Burley's Owen scrambling [3]_
  (``FastOwen`` in pbrt's terms) replace pbrt's MurmurHash-based seeds
  ``MixBits(dimension ^ seed)``.
* Seed: the user seed enters the per-pair key ``q``, and hence the digit
  permutations; in pbrt it only changes the coordinate scrambles, and the
  key of the digit permutations is the bare dimension counter.
* Permutation table: :data:`PERMS` lists the 24 permutations in
  lexicographic order; pbrt's ``permutations`` table holds the same 24 in a
  different order (the two agree at 10 of the 24 positions), so the same
  hash may select a different permutation. Either way the choice is among
  all 24.
* Pixels are numbered row-major, ``pixel = y W + x``; the row
  ``y = pixel // W`` is taken modulo ``2**16`` (the largest image) so that
  every uint32 pixel is defined; pixels of the image never wrap.
* Values are 24-bit (``k 2**-24``, exact in float32, always below 1) like
  pyoa's other Sobol' samplers, not pbrt's ``min(v 2**-32, OneMinusEpsilon)``.
* Dimensions come in padded pairs ``b = j >> 1`` (pyoa's ``sobol02``
  convention); pbrt increments a dimension counter by 1 per ``Get1D`` and by
  2 per ``Get2D``, so a 1D request shifts the pairs after it.

References
----------
.. [1] A. G. M. Ahmed, P. Wonka, "Screen-Space Blue-Noise Diffusion of Monte
   Carlo Sampling Error via Hierarchical Ordering of Pixels", ACM
   Transactions on Graphics 39(6) (SIGGRAPH Asia 2020).
.. [2] M. Pharr, W. Jakob, G. Humphreys, "Physically Based Rendering: From
   Theory to Implementation", 4th ed., 2023 (the Z-Sobol' sampler); pbrt-v4
   ``src/pbrt/samplers.h``, ``ZSobolSampler::GetSampleIndex``.
.. [3] B. Burley, "Practical Hash-based Owen Scrambling", Journal of
   Computer Graphics Techniques 9(4), 2020.
"""

from __future__ import annotations

import itertools

from .baselines import OWEN_KEY, owen_scramble, sobol_bits, unit24
from .hashes import MASK, hash_pair

#: Key of the per-pair hash ``q = hash_pair(seed, b, ZSOBOL_KEY)`` (pyoa's
#: choice: odd, distinct from every other key; also the kernels' define).
ZSOBOL_KEY = 0xB5297A4D

#: The 24 permutations of ``(0, 1, 2, 3)`` in lexicographic order
#: (``itertools.permutations``); ``PERMS[p][digit]`` is the image of a digit.
PERMS: tuple[tuple[int, ...], ...] = tuple(itertools.permutations(range(4)))

#: ``0x55555555``: multiplies the key ``q`` into the digit hashes (pbrt's
#: ``0x55555555 * dimension``).
DIGIT_MULT = 0x55555555
MASK64 = (1 << 64) - 1
#: The largest image side, ``2**16``: ``log2res <= 16``.
MAX_LOG2RES = 16
MAX_LOG2N = 24


def mix64(v: int) -> int:
    """pbrt-v4's ``MixBits``: a bijective avalanche hash of a uint64::

        v ^= v >> 31; v *= 0x7fb5d329728ea185
        v ^= v >> 27; v *= 0x81dadef4bc2dd44d
        v ^= v >> 33

    all modulo ``2**64``.
    """
    v ^= v >> 31
    v = (v * 0x7FB5D329728EA185) & MASK64
    v ^= v >> 27
    v = (v * 0x81DADEF4BC2DD44D) & MASK64
    v ^= v >> 33
    return v


def morton2(x: int, y: int) -> int:
    """The Morton (Z-order) code of ``(x, y)``: bit ``t`` of ``x`` becomes bit
    ``2t``, bit ``t`` of ``y`` bit ``2t + 1`` (pbrt's ``EncodeMorton2``).

    >>> [morton2(x, y) for y in range(2) for x in range(2)]
    [0, 1, 2, 3]
    >>> morton2(3, 5)
    39
    """
    if x < 0 or y < 0:
        raise ValueError(f"morton2 needs non-negative coordinates, got ({x}, {y})")
    code, t = 0, 0
    while x or y:
        code |= ((x & 1) << (2 * t)) | ((y & 1) << (2 * t + 1))
        x >>= 1
        y >>= 1
        t += 1
    return code


def resolution_log2(width: int, height: int) -> int:
    """``log2res``: the base-2 log of the smallest power of two ``>= max(width,
    height)`` (0 for a 1 x 1 image; 11 for 1920 x 1080).

    >>> resolution_log2(1920, 1080), resolution_log2(1, 1), resolution_log2(65536, 3)
    (11, 0, 16)
    """
    for name, v in (("width", width), ("height", height)):
        if not 1 <= v <= 1 << MAX_LOG2RES:
            raise ValueError(f"{name} must be in [1, 2**{MAX_LOG2RES}], got {v}")
    return (max(width, height) - 1).bit_length()


def digit_count(log2n: int, log2res: int) -> int:
    """``D = log2res + ceil(log2n / 2)``: the base-4 digits of the Morton index
    (the lone low bit of an odd ``log2n`` counted as one)."""
    return log2res + (log2n + 1) // 2


def _check(i: int, log2n: int, log2res: int, width: int, pixel: int, seed: int) -> None:
    if not 0 <= log2n <= MAX_LOG2N:
        raise ValueError(f"log2n must be in [0, {MAX_LOG2N}], got {log2n}")
    if not 0 <= i < 1 << log2n:
        raise ValueError(f"sample index i must be in [0, 2**{log2n}), got {i}")
    if not 0 <= log2res <= MAX_LOG2RES:
        raise ValueError(f"log2res must be in [0, {MAX_LOG2RES}], got {log2res}")
    if not 1 <= width <= 1 << log2res:
        raise ValueError(f"width must be in [1, 2**log2res = {1 << log2res}], got {width}")
    if not 0 <= pixel <= MASK:
        raise ValueError(f"pixel must be a uint32 in [0, 2**32), got {pixel}")
    if not 0 <= seed <= MASK:
        raise ValueError(f"seed must be a uint32 in [0, 2**32), got {seed}")


def pair_key(seed: int, b: int) -> int:
    """``q = hash_pair(seed, b, ZSOBOL_KEY)``: the key of dimension pair ``b``."""
    return hash_pair(seed, b, ZSOBOL_KEY)


def morton_index(i: int, log2n: int, width: int, pixel: int) -> int:
    """``m = (morton2(x, y) << log2n) | i`` with ``x = pixel mod width`` and
    ``y = (pixel // width) mod 2**16``."""
    x, y = pixel % width, (pixel // width) & 0xFFFF
    return (morton2(x, y) << log2n) | i


def permute_digits(m: int, log2n: int, log2res: int, q: int) -> int:
    """The permuted index ``g`` of Morton index ``m`` with key ``q`` (the loop of
    the module docstring), every digit included."""
    odd = log2n & 1
    key = (DIGIT_MULT * q) & MASK64
    g = 0
    for d in range(digit_count(log2n, log2res) - 1, odd - 1, -1):
        shift = 2 * d - odd
        digit = (m >> shift) & 3
        higher = m >> (shift + 2)  # the unpermuted digits above this one
        perm = (mix64(higher ^ key) >> 24) % 24
        g |= PERMS[perm][digit] << shift
    if odd:
        g |= (m & 1) ^ (mix64((m >> 1) ^ key) & 1)
    return g


def sample_index(i: int, b: int, log2n: int, log2res: int, width: int, pixel: int, seed: int) -> int:
    """The permuted Sobol' index ``g`` of sample ``i`` of ``pixel`` for
    dimension pair ``b``: pbrt's ``GetSampleIndex`` (module docstring), all
    of it (``g < 2**56``; :func:`zsobol` uses ``g mod 2**32``).

    For a fixed pixel the ``2**log2n`` values are the aligned block
    ``[c 2**log2n, (c + 1) 2**log2n)``; pixels of the ``res x res`` square get
    disjoint blocks.

    Parameters
    ----------
    i : int
        Sample index in ``[0, 2**log2n)``.
    b : int
        Dimension pair ``j >> 1``, a uint32.
    log2n, log2res, width, pixel, seed : int
        As for :func:`zsobol`.

    Returns
    -------
    int
        ``g`` as a Python int.
    """
    _check(i, log2n, log2res, width, pixel, seed)
    if not 0 <= b <= MASK:
        raise ValueError(f"dimension pair b must be a uint32, got {b}")
    return permute_digits(morton_index(i, log2n, width, pixel), log2n, log2res, pair_key(seed, b))


def zsobol(i: int, j: int, log2n: int, log2res: int, width: int, pixel: int, seed: int) -> float:
    """Dimension ``j`` of sample ``i`` of ``pixel``: pbrt-v4's ZSobol sampler
    with pyoa's hashes (module docstring)::

        q = hash_pair(seed, j >> 1, ZSOBOL_KEY)
        g = sample_index(i, j >> 1, ...) mod 2**32
        x = unit24(owen_scramble(sobol_bits(g, j & 1), hash_pair(q, 1 + (j & 1), OWEN_KEY)))

    Every pixel's ``2**log2n`` samples of every pair ``(2b, 2b + 1)`` are a
    (0, log2n, 2)-net, and the nets of neighbouring pixels together form the
    larger nets of the Z-order (Ahmed and Wonka [1]_).

    Parameters
    ----------
    i : int
        Sample index in ``[0, 2**log2n)``.
    j : int
        Dimension, a uint32 (``0 <= j < 2**32``).
    log2n : int
        ``N = 2**log2n`` samples per pixel, ``0 <= log2n <= 24``.
    log2res : int
        ``log2`` of the image's power-of-two side, ``0 <= log2res <= 16``:
        :func:`resolution_log2` of the image's width and height.
    width : int
        Image width, ``1 <= width <= 2**log2res``.
    pixel : int
        Row-major pixel index ``y * width + x``, a uint32.
    seed : int
        User seed, a uint32.

    Returns
    -------
    float
        A float32 value ``k * 2**-24`` in ``[0, 1)``, as a Python float.
    """
    if not 0 <= j <= MASK:
        raise ValueError(f"dimension j must be a uint32 in [0, 2**32), got {j}")
    _check(i, log2n, log2res, width, pixel, seed)
    b, c = j >> 1, j & 1
    q = pair_key(seed, b)
    g = permute_digits(morton_index(i, log2n, width, pixel), log2n, log2res, q) & MASK
    return unit24(owen_scramble(sobol_bits(g, c), hash_pair(q, 1 + c, OWEN_KEY)))
