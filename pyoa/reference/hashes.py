"""Integer hashes of docs/spec.md sections 2 and 3, one uint32 at a time.

Every operation is on unsigned 32-bit integers with wrap-around; Python
integers are unbounded, so each product is reduced with ``& MASK``.

References
----------
.. [1] A. Kensler, "Correlated Multi-Jittered Sampling", Pixar Technical
   Memo 13-01, 2013 (``permute`` and ``randfloat``).
.. [2] C. Wellons, "Prospecting for Hash Functions", 2018, and the
   ``lowbias32`` function of github.com/skeeto/hash-prospector (``mix32``).
"""

from __future__ import annotations

from .floats import UNIT_SCALE, f32

MASK = 0xFFFFFFFF

#: Multipliers of the per-dimension seeds (docs/spec.md section 3).
STRATUM_KEY = 0x51633E2D
SUBSTRATUM_KEY = 0x68BC21EB
JITTER_KEY = 0x02E5BE93

#: Keys that separate the two uses of :func:`hash_pair` (pyoa's own choice,
#: docs/spec.md section 3 leaves the pixel and block hashes to the project).
PIXEL_KEY = 0x5BD1E995
BLOCK_KEY = 0x1B873593
#: Key of the sample order of each block past the first (docs/spec.md section 6).
BLOCK_ORDER_KEY = 0x94D049BB
#: Key of the seed of each frame of an animation past the first (docs/spec.md section 3.5).
FRAME_KEY = 0x7F4A7C15


def walk_mask(l: int) -> int:
    """The all-ones mask just covering ``l - 1``: the domain ``[0, w]`` of
    :func:`permute`'s cycle walk."""
    w = l - 1
    w |= w >> 1
    w |= w >> 2
    w |= w >> 4
    w |= w >> 8
    w |= w >> 16
    return w


def permute_round(i: int, p: int, w: int) -> int:
    """One round of Kensler's bijection on ``[0, w]`` with seed ``p``: the body
    of :func:`permute`'s cycle walk (``pyoa_permute_round`` of kernels/include/pyoa/hashes.h)."""
    i ^= p
    i = (i * 0xE170893D) & MASK
    i ^= p >> 16
    i ^= (i & w) >> 4
    i ^= p >> 8
    i = (i * 0x0929EB3F) & MASK
    i ^= p >> 23
    i ^= (i & w) >> 1
    i = (i * (1 | (p >> 27))) & MASK
    i = (i * 0x6935FA69) & MASK
    i ^= (i & w) >> 11
    i = (i * 0x74DCB303) & MASK
    i ^= (i & w) >> 2
    i = (i * 0x9E501CC3) & MASK
    i ^= (i & w) >> 2
    i = (i * 0xC860A3DF) & MASK
    i &= w
    i ^= i >> 5
    return i


def permute(i: int, l: int, p: int) -> int:
    """Element ``i`` of the ``p``-th pseudo-random permutation of ``0..l-1``.

    Kensler's hash-based permutation [1]_: a bijection on ``w+1`` values
    (the next power of two at least ``l``), applied repeatedly ("cycle
    walking") until the result falls below ``l``. ``p == 0`` is the identity.
    The final shift is ``(i + p % l) % l`` rather than Kensler's
    ``(i + p) % l``, which stops being a permutation when ``i + p`` wraps
    past ``2**32`` (docs/spec.md section 2).

    Parameters
    ----------
    i : int
        Index in ``[0, l)``.
    l : int
        Length of the permutation, ``1 <= l <= 2**31`` (so that the final
        ``i + p % l`` cannot wrap in uint32).
    p : int
        Permutation seed, uint32.
    """
    if not 1 <= l <= 2**31 or not 0 <= i < l:
        raise ValueError(f"permute needs 1 <= l <= 2**31 and 0 <= i < l, got i={i}, l={l}")
    if p == 0:
        return i
    w = walk_mask(l)
    while True:
        i = permute_round(i, p, w)
        if i < l:
            break
    return (i + p % l) % l


def randfloat(i: int, p: int) -> float:
    """A float32 in ``[0, 1)`` hashed from ``(i, p)`` (Kensler [1]_).

    ``p == 0`` gives 0.5 (the centre: the canonical, unjittered array).
    The hashed uint32 is rounded to float32 (nearest even) and multiplied, as
    one float32 multiply, by the float32 whose bits are ``0x2f7ffffe``
    (``(1 - 2**-23) * 2**-32``), so the largest result is ``1 - 2**-23``.
    """
    if p == 0:
        return 0.5
    i ^= p
    i ^= i >> 17
    i ^= i >> 10
    i = (i * 0xB36534E5) & MASK
    i ^= i >> 12
    i ^= i >> 21
    i = (i * 0x93FC4795) & MASK
    i ^= 0xDF6E307F
    i ^= i >> 17
    i = (i * (1 | (p >> 18))) & MASK
    return f32(f32(i) * UNIT_SCALE)


def mix32(x: int) -> int:
    """Wellons' ``lowbias32`` [2]_: a bijective avalanche hash of a uint32."""
    x ^= x >> 16
    x = (x * 0x7FEB352D) & MASK
    x ^= x >> 15
    x = (x * 0x846CA68B) & MASK
    x ^= x >> 16
    return x


def hash_pair(a: int, b: int, key: int) -> int:
    """``mix32(b ^ mix32(a ^ key))``, never 0 (0 becomes ``key``).

    For a fixed ``a`` it is a bijection of ``b`` (up to that one remapped
    value), so different ``b`` never share a result by accident.
    """
    h = mix32(b ^ mix32(a ^ key))
    return h if h else key


def pixel_seed(seed: int, pixel: int) -> int:
    """The 32-bit array seed of one pixel: ``hash_pair(seed, pixel, 0x5bd1e995)``.

    Never 0, so every pixel of a sampler is randomized (docs/spec.md section 3); for
    one user seed, distinct pixels get distinct seeds.
    """
    return hash_pair(seed, pixel, PIXEL_KEY)


def frame_seed(seed: int, frame: int) -> int:
    """The user seed of frame ``frame`` of an animation rendered with user seed
    ``seed`` (docs/spec.md section 3.5): ``seed`` itself for frame 0, so a
    still image keeps its values, else ``hash_pair(seed, frame, 0x7f4a7c15)``,
    an independent randomization per frame. The C headers' twin is
    ``pyoa_frame_seed`` (pyoa/hashes.h), which renderers call."""
    return hash_pair(seed, frame, FRAME_KEY) if frame else seed


def block_seed(p: int, block: int) -> int:
    """Seed of the ``block``-th copy of an array with seed ``p`` (docs/spec.md section 6).

    Block 0 is the array itself (``p``); blocks 1, 2, ... get
    ``hash_pair(p, block, 0x1b873593)``: independent, never 0. Even the
    canonical array (``p == 0``) is randomized past its first block, so no
    column ever repeats with the same seed.
    """
    return p if block == 0 else hash_pair(p, block, BLOCK_KEY)


def block_order_seed(P: int, block: int, N: int) -> int:
    """Seed of the sample order of block ``block``, whose array seed is ``P``
    (docs/spec.md section 6): 0 for block 0 (``permute`` with seed 0 is the
    identity, so block 0 keeps its rows), else ``hash_pair(P, N, 0x94d049bb)``,
    which is never 0."""
    return 0 if block == 0 else hash_pair(P, N, BLOCK_ORDER_KEY)


def block_row(i: int, N: int, r: int) -> int:
    """Row of sample ``i`` in a block whose order seed is ``r`` (docs/spec.md
    section 6): ``permute(permute(i, N, r), N, mix32(r))``, the identity for
    ``r = 0`` (block 0; ``mix32(0) = 0``).

    Two permutations with independent seeds, not one: on a power-of-two
    ``N`` Kensler's permute is a single round of its hash and its family of
    permutations is small; one of them left some pairs of columns across
    blocks filling 8 % fewer coarse cells than a random pairing (Bose 16,
    columns 1 and 1: 10.8 of 11.6), two bring every pair tried within 1.3 %
    (docs/spec.md section 6).
    """
    return permute(permute(i, N, r), N, mix32(r))


def locate(p: int, i: int, j: int, B: int, N: int) -> tuple[int, int, int]:
    """The block rule (docs/spec.md section 6): the ``(P, row, col)`` that
    dimension ``j`` of sample ``i`` reads in an array of ``N`` rows and ``B``
    columns with seed ``p``.

    Dimension ``j`` is column ``col = j % B`` of copy ``block = j // B``, whose
    seed is ``P = block_seed(p, block)``, read at row
    ``block_row(i, N, block_order_seed(P, block, N))``: block 0 reads row
    ``i``, every later block its own seeded permutation of the rows. Without that
    permutation, sample ``i`` of dimension ``j + B`` would come from the same
    row as sample ``i`` of dimension ``j``: a fixed function of it.
    """
    block, col = divmod(j, B)
    P = block_seed(p, block)
    return P, block_row(i, N, block_order_seed(P, block, N)), col


def dimension_seeds(p: int, j: int) -> tuple[int, int, int]:
    """Seeds of column ``j`` of an array with seed ``p`` (docs/spec.md section 3):
    stratum permutation, sub-stratum permutation, jitter."""
    q = (p * (j + 1)) & MASK
    return (q * STRATUM_KEY) & MASK, (q * SUBSTRATUM_KEY) & MASK, (q * JITTER_KEY) & MASK
