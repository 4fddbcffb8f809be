"""The block rule of docs/spec.md section 6 over an array namespace (:mod:`pyoa._arrays`).

Dimension ``j`` of an array of ``B`` columns is column ``j % B`` of copy
(block) ``j // B``. A block has its own seed and its own order of the rows:

```
P   = block_seed(p, block)               p for block 0
r   = block_order_seed(P, block, N)      0 for block 0
row = block_row(i, N, r)                 permute(permute(i, N, r), N, mix32(r)); i for block 0
```

(:func:`pyoa.reference.hashes.locate`; ``pyoa_oa_locate`` in
``kernels/include/pyoa/oa.h``). ``B`` and ``N`` are Python ints.
"""

from __future__ import annotations

from ..reference.hashes import BLOCK_KEY, BLOCK_ORDER_KEY
from .hashes import hash_pair, mix32, permute


def block_seed(xp, p, block):
    """The seed of block ``block`` (block 0 keeps ``p``; :func:`pyoa.reference.block_seed`)."""
    p, block = xp.as_uint32(p, block)
    return xp.select(block == 0, p, hash_pair(xp, p, block, BLOCK_KEY))


def block_order_seed(xp, P, block, N: int):
    """The seed of block ``block``'s order of the rows (:func:`pyoa.reference.hashes.block_order_seed`):
    0 for block 0, else ``hash_pair(P, N, BLOCK_ORDER_KEY)`` (never 0)."""
    P, block = xp.as_uint32(P, block)
    return xp.select(block == 0, 0, hash_pair(xp, P, N, BLOCK_ORDER_KEY))


def block_row(xp, i, N: int, r):
    """The row sample ``i`` reads in a block whose order seed is ``r``
    (:func:`pyoa.reference.hashes.block_row`): ``permute(permute(i, N, r), N,
    mix32(r))``, and ``i`` itself where ``r == 0`` (block 0).

    The two permutations run in a loop of at most one step whose lanes are
    those with ``r != 0``. NumPy then skips block 0 (a table path's later
    blocks have no such lane and run the step on their arrays as they are).
    Inside Mitsuba the dimension is the same in every lane of a draw, so in
    block 0 (most draws of a short path) Dr.Jit's loop finds no active lane
    and skips both permutations instead of computing and discarding them.
    """
    i, r = xp.as_uint32(i, r)
    if N == 1:
        return xp.zeros(i, r)

    def rows(x, r, todo):
        return permute(xp, permute(xp, x, N, r), N, mix32(xp, r)), r, todo & False

    loop = ((i, r, r != 0), lambda x, r, todo: todo, rows)
    return xp.while_loops([loop], "pyoa_block_row")[0][0]


def locate_block(xp, p, i, block, N: int):
    """``(P, row)``: the seed of block ``block`` and the row sample ``i`` reads
    in it. A caller that draws a block's dimensions one by one keeps these
    per lane and calls this once per block (:mod:`pyoa.mitsuba`)."""
    P = block_seed(xp, p, block)
    return P, block_row(xp, i, N, block_order_seed(xp, P, block, N))


def locate(xp, p, i, j, B: int, N: int):
    """``(P, row, col)`` of dimension ``j`` of sample ``i`` in an array of
    ``N`` rows and ``B`` columns with seed ``p`` (:func:`pyoa.reference.hashes.locate`).

    Dr.Jit compiles the integer division by the constant ``B`` to an exact
    multiply-and-shift (a float32 one would not be exact, :mod:`.floats`)."""
    i, j, p = xp.as_uint32(i, j, p)
    P, row = locate_block(xp, p, i, j // B, N)
    return P, row, j % B
