"""``zfaure``: one Owen-scrambled Faure sequence handed out to the pixels along
a scrambled base-``b`` Morton order, so that the error image is blue noise in
every dimension of a block (docs/spec.md section 5.12).

Ahmed and Wonka [1]_ give every pixel its own consecutive block of one
(0,2)-sequence, handed out along a Z (Morton) curve of the image: the blocks of
neighbouring pixels together form larger nets, their errors cancel, and the
error image has little low-frequency energy (blue noise). pbrt-v4's
``ZSobolSampler`` [2]_ (pyoa's ``zsobol``) pads (0,2)-sequences, so only its
first pair of dimensions has the property. A scrambled Faure (0,s)-sequence in
a prime base ``b`` (:mod:`pyoa.reference.faure`, Faure [3]_, Owen [4]_) is a
(0, m, b)-net in every aligned block of ``b**m`` samples, in all ``b``
dimensions of a block at once. ``zfaure`` hands it out the same way.

**The order of the pixels.** A ``W x H`` image (pixels row-major, ``pixel =
y W + x``, ``1 <= W, H <= 2**16``) sits in the ``b**k x b**k`` grid with
``k`` the fewest digits with ``b**k >= max(W, H)`` (:func:`grid_digits`).
The user seed gives the sequence's seed ``S = hash_pair(seed, b,
ZFAURE_ORDER_KEY)`` (:func:`sequence_seed`; never 0, so every seed, 0
included, is scrambled). With ``x_l, y_l`` the base-``b`` digits of ``x, y``
(``l = 0`` the most significant of ``k``), the position of the pixel on the
order is::

    z = sum over l of child_l b**(2 (k-1-l))                     (a base-b**2 number)
    child_l = gy b + gx,  or  gx b + gy when swap_l              (gx, gy: the permuted digits)
    gx = axis_permute(x_l, b, hash_pair(t_l, 0, ZFAURE_AXIS_KEY))
    gy = axis_permute(y_l, b, hash_pair(t_l, 1, ZFAURE_AXIS_KEY))
    swap_l = hash_pair(t_l, 2, ZFAURE_AXIS_KEY) >> 31
    t_0 = S,  t_(l+1) = hash_pair(t_l, y_l b + x_l, ZFAURE_TILE_KEY)

(:func:`pixel_code`), where ``axis_permute(d, b, h) = permute(permute(d, b,
h), b, mix32(h))``: two of Kensler's permutations composed, as the block
rule composes them (docs/spec.md section 6), because one alone reaches few
of the ``b!`` orders of a small ``b`` (896 of the 5040 for ``b = 7``). ``t_l``
is a hash of the seed and of every digit above level ``l``: each ``b x b``
tile of every level permutes its columns and its rows by its own random
permutations and is transposed or not at random, a nested (Owen-style)
scramble of the axes' digits. Every ``b**(2u)`` consecutive positions are
one ``b**u x b**u`` tile of the grid, and every ``b`` consecutive positions
one row (or column) of a ``b x b`` tile.

**The samples.** Pixel ``(x, y)``'s sample ``i`` (``0 <= i < N``, ``N =
b**m``) is index ``T = z N + i`` of the Faure sequence with seed ``S``
(``T < b**(2k) N <= 2**64``), read as its ``D = max(K, 2k + m)`` lowest
base-``b`` digits (:func:`total_digits`; ``K`` the output digits of
:func:`pyoa.reference.faure.out_digits`). Dimension ``j`` is coordinate
``j mod b`` of the block ``j // b``, with ``P = block_seed(S, j // b)``:
block 0 takes the digits as they are, a copy scrambles all ``D`` of them by
:func:`chained_scramble` (its own order of pixels and samples, as
``faure``'s copies), and :func:`pyoa.reference.faure.digits_value` makes the
value with the output seed ``derived_seed(P, j mod b, FAURE_KEY)``. In block
0, while ``T < 2**24``, the value is ``faure(T, j, b, K, S)``.

**What it gives.** ``N = b**m`` with ``m >= 2``. Then a pixel's samples
are one aligned block of ``b**m`` indices, a (0,m,b)-net in every block of
dimensions (an orthogonal array of strength 2 and more): a digital shift of
``faure``'s first ``N``, so after the nested scramble its per-pixel error
has ``faure``'s distribution. A row of a ``b x b`` tile is an aligned block
of ``b**(m+1)`` and a tile one of ``b**(m+2)``, a (0,m+2,b)-net: in every
dimension of a block, neighbouring pixels' samples together are finer nets,
so their errors cancel. Any other count would either straddle the
sequence's blocks (a pixel's samples from two nets: its error grows, by 10-20
% at 100 = 4 x 25 samples) or leave gaps in the tiles (their errors cancel
less), so the count is a power of the base and fixes it. The nested index scramble of a copy maps aligned blocks onto aligned
blocks, so the copies keep all of it. No two pixels share a sample (``z`` is
injective), for any image size. The nested axis scramble is chosen by
measurement (``benchmarks/zfaure_order_study.py``): plain Morton puts the
same arrangement in every tile, a periodic pattern that shows as spectral
spikes of 100-900 times the white level; shuffling each tile's ``b**2``
children breaks the rows apart and loses a third of the blue noise; the axis
scramble keeps rows as rows (nets of ``b**3``) without a pattern.

References
----------
.. [1] A. G. M. Ahmed, P. Wonka, "Screen-space blue-noise diffusion of Monte
   Carlo sampling error via hierarchical ordering of pixels", ACM
   Transactions on Graphics 39(6), SIGGRAPH Asia 2020.
.. [2] M. Pharr, W. Jakob, G. Humphreys, *Physically Based Rendering*, 4th
   ed., 2023, section 8.7.7 (``ZSobolSampler``).
.. [3] H. Faure, "Discrépance de suites associées à un système de
   numération (en dimension s)", Acta Arithmetica 41, 1982.
.. [4] A. B. Owen, "Randomly permuted (t,m,s)-nets and (t,s)-sequences",
   Monte Carlo and Quasi-Monte Carlo Methods, 1995.
"""

from __future__ import annotations

from .baselines import derived_seed
from .faure import FAURE_KEY, bases, digits_value, index_digits, out_digits
from .hashes import MASK, block_seed, hash_pair, mix32, permute

#: Keys of the order's hashes (pyoa's choice: words of SHA-256's initial hash value).
ZFAURE_ORDER_KEY = 0x6A09E667
ZFAURE_AXIS_KEY = 0xBB67AE85
ZFAURE_TILE_KEY = 0x9B05688C
ZFAURE_INDEX_KEY = 0x5BE0CD19

#: Largest image side (as ``zsobol``).
MAX_RESOLUTION = 1 << 16
#: Largest sample count of a pixel (the samplers' limit).
MAX_SPP = 1 << 24
#: ``T = z N + i`` is a 64-bit index: ``b**(2k) N`` may be at most this.
MAX_TOTAL = 1 << 64


def grid_digits(b: int, width: int, height: int) -> int:
    """``k``: the fewest base-``b`` digits with ``b**k >= max(width, height)`` (0 for one pixel)."""
    k, power = 0, 1
    while power < max(width, height):
        power *= b
        k += 1
    return k


def total_digits(b: int, k: int, N: int) -> int:
    """``D = max(K, 2k + n)``: the digits the sequence is read with (``n`` the fewest with ``b**n >= N``)."""
    return max(out_digits(b), 2 * k + index_digits(b, N))


def power_of(N: int, b: int) -> int | None:
    """``m`` if ``N = b**m`` with ``m >= 2``, else None."""
    m, power = 0, 1
    while power < N:
        power, m = power * b, m + 1
    return m if power == N and m >= 2 else None


def check_shape(N: int, b: int, width: int, height: int) -> int:
    """Check a ``zfaure`` shape and return its ``k``; ValueError says what is valid."""
    if b not in bases():
        raise ValueError(f"zfaure: base b must be a prime in [2, 4093], got {b}")
    if not 1 <= N <= MAX_SPP or power_of(N, b) is None:
        raise ValueError(f"zfaure: the sample count must be a power b^m of the base b = {b} with m >= 2, up to "
                         f"2^24 (each pixel one (0,m,b)-net), got {N}")
    for name, v in (("width", width), ("height", height)):
        if not 1 <= v <= MAX_RESOLUTION:
            raise ValueError(f"zfaure: image {name} must be in [1, {MAX_RESOLUTION}], got {v}")
    k = grid_digits(b, width, height)
    if b ** (2 * k) * N > MAX_TOTAL:
        raise ValueError(f"zfaure: a {width} x {height} image in base {b} pads to a {b}^{k} x {b}^{k} grid, and "
                         f"{b}^{2 * k} pixels x {N} samples pass the 64-bit index (at most 2^64); use a smaller "
                         "base, image or count")
    return k


def sequence_seed(seed: int, b: int) -> int:
    """``S = hash_pair(seed, b, ZFAURE_ORDER_KEY)``: the seed of the sequence and
    of the order, never 0 (every user seed, 0 included, scrambles)."""
    return hash_pair(seed, b, ZFAURE_ORDER_KEY)


def axis_permute(d: int, b: int, h: int) -> int:
    """``permute(permute(d, b, h), b, mix32(h))``: element ``d`` of a random
    permutation of ``0..b-1`` drawn by ``h``."""
    return permute(permute(d, b, h), b, mix32(h))


def pixel_code(x: int, y: int, b: int, k: int, S: int) -> int:
    """``z``: the position of pixel ``(x, y)`` on the scrambled Morton order
    of the ``b**k x b**k`` grid for the sequence seed ``S`` (module docstring)."""
    code = 0
    t = S
    for level in range(k):  # the most significant digits first
        scale = b ** (k - 1 - level)
        dx, dy = x // scale % b, y // scale % b
        gx = axis_permute(dx, b, hash_pair(t, 0, ZFAURE_AXIS_KEY))
        gy = axis_permute(dy, b, hash_pair(t, 1, ZFAURE_AXIS_KEY))
        swap = hash_pair(t, 2, ZFAURE_AXIS_KEY) >> 31
        t = hash_pair(t, dy * b + dx, ZFAURE_TILE_KEY)
        code = code * b * b + (gx * b + gy if swap else gy * b + gx)
    return code


def zfaure(i: int, j: int, N: int, b: int, k: int, width: int, pixel: int, seed: int) -> float:
    """Sample ``i``, dimension ``j`` of pixel ``pixel`` (row-major in an image
    ``width`` wide) of ``zfaure`` in base ``b`` with ``N`` samples per pixel
    and seed ``seed`` (module docstring).

    Parameters
    ----------
    i : int
        Sample index in ``[0, N)``.
    j : int
        Dimension, ``>= 0``.
    N : int
        Samples per pixel, ``b**m`` with ``m >= 2``, up to ``2**24``.
    b : int
        Prime base in ``[2, 4093]``.
    k : int
        Digits of the padded grid, :func:`grid_digits` of the image.
    width : int
        Image width (``x = pixel % width``, ``y = pixel // width``).
    pixel : int
        Pixel index, ``y < b**k``.
    seed : int
        User seed (uint32): one sequence and one order for the whole image.
    """
    if b not in bases():
        raise ValueError(f"base b must be a prime in [2, 4093], got {b}")
    if not 1 <= N <= MAX_SPP or power_of(N, b) is None:
        raise ValueError(f"N must be b^m with m >= 2 (b = {b}), up to 2^24, got {N}")
    if not 1 <= width <= MAX_RESOLUTION or not b**k >= width or b ** (2 * k) * N > MAX_TOTAL:
        raise ValueError(f"need 1 <= width <= b^k, width <= {MAX_RESOLUTION} and b^(2k) N <= 2^64, got "
                         f"width={width}, b={b}, k={k}, N={N}")
    if not 0 <= i < N:
        raise ValueError(f"sample index i must be in [0, N), got i={i}, N={N}")
    if j < 0:
        raise ValueError(f"dimension j must be >= 0, got {j}")
    if not 0 <= pixel < width * b**k:
        raise ValueError(f"pixel must be in [0, width b^k), got {pixel}")
    if not 0 <= seed <= MASK:
        raise ValueError(f"seed must be a uint32 in [0, 2**32), got {seed}")
    S = sequence_seed(seed, b)
    T = pixel_code(pixel % width, pixel // width, b, k, S) * N + i
    col, block = j % b, j // b
    P = block_seed(S, block)
    a = []
    for _ in range(total_digits(b, k, N)):
        a.append(T % b)
        T //= b
    if block:
        # every copy past the first reads the sequence in its own nested order of pixels and samples
        a = chained_scramble(a, b, hash_pair(P, b, ZFAURE_INDEX_KEY))
    return digits_value(a, b, col, derived_seed(P, col, FAURE_KEY))


def chained_scramble(a: list[int], b: int, h: int) -> list[int]:
    """The digits ``a`` (least significant first) nested-scrambled from the
    most significant down, each permuted by a hash chained over the digits
    above it::

        a'_r = permute(a_r, b, h_r),   h_(D-1) = h,   h_(r-1) = hash_pair(h_r, a_r, ZFAURE_INDEX_KEY)

    Like :func:`pyoa.reference.faure.index_scramble` (which keys a digit by
    its position and the value of the digits above it, and so stops at
    ``2**32``), it maps every aligned block of ``b**m`` indices onto an
    aligned block of ``b**m``; the chain reaches any number of digits."""
    out = list(a)
    for r in range(len(a) - 1, -1, -1):
        out[r] = permute(a[r], b, h)
        h = hash_pair(h, a[r], ZFAURE_INDEX_KEY)
    return out
