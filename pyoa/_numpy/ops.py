"""The array namespace of :mod:`pyoa._arrays` over NumPy arrays (the contract is
that package's docstring).

NumPy's uint32 arithmetic wraps modulo ``2**32`` as the spec requires, and
its float32 arithmetic is one correctly rounded operation at a time. The
loops and the masked work run on the lanes that need them only: an array
operation costs per lane, so lanes left out are time saved.
"""

from __future__ import annotations

import numpy as np

U32 = np.uint32
F32 = np.float32


def as_uint32(*values) -> tuple:
    return tuple(np.asarray(v, dtype=U32) for v in values)


def u32(x):
    return np.asarray(x).astype(U32, copy=False)


def u64(x):
    return np.asarray(x).astype(np.uint64, copy=False)


def f32(x):
    return np.asarray(x).astype(F32, copy=False)


def f64(x):
    return np.asarray(x).astype(np.float64, copy=False)


def bits(x):
    return np.asarray(x, dtype=F32).view(U32)


def from_bits(u):
    return np.asarray(u, dtype=U32).view(F32)


def zeros(*like):
    return np.zeros(np.broadcast_shapes(*(np.shape(v) for v in like)), dtype=U32)


select = np.where
minimum = np.minimum
maximum = np.maximum


def gather(table: np.ndarray, index):
    return table[index]


def divide(x, n):
    return x / F32(n)


def power(base: int, e):
    return U32(base) ** np.asarray(e, dtype=U32)


def may_any(mask) -> bool:
    return bool(np.any(mask))


def wrapping():
    return np.errstate(over="ignore")


def while_loops(loops, label: str = "") -> list:
    """Each loop by itself (:func:`while_loop`); ``label`` names Dr.Jit's loop and is unused here."""
    return [while_loop(*loop) for loop in loops]


def while_loop(state, cond, body) -> tuple:
    """``state = body(*state)`` in every lane while ``cond(*state)``, on the lanes still looping only.

    When every lane loops, the first step runs on the arrays as they are
    (no broadcast, no gather): a table path's loop of one step (the later
    blocks' rows) costs nothing more. After it, the state is broadcast to
    one flat shape, and each step gathers the lanes still looping, runs on
    them, and scatters the state of the lanes that are done; a value the
    body returns unchanged (the same object, a loop invariant such as a
    seed) is not scattered back.
    """
    state = tuple(state)
    go = np.asarray(cond(*state))
    if go.all():
        state = tuple(body(*state))
        go = np.asarray(cond(*state))
    if not go.any():
        return state
    shape = np.broadcast_shapes(go.shape, *(np.shape(v) for v in state))
    flat = [(v if np.shape(v) == shape else np.broadcast_to(v, shape)).reshape(-1) for v in state]
    # a view of an array the loop was given is copied before the first write into it
    owned = [not np.may_share_memory(f, v) for f, v in zip(flat, state)]
    todo = np.flatnonzero(np.broadcast_to(go, shape))
    cur = [v[todo] for v in flat]
    while todo.size:
        new = tuple(body(*cur))
        go = np.asarray(cond(*new))
        if not go.all():
            done = todo[~go]
            for k, (v, c) in enumerate(zip(new, cur)):
                if v is not c:
                    if not owned[k]:
                        flat[k], owned[k] = flat[k].copy(), True
                    flat[k][done] = v[~go]
            todo = todo[go]
            new = tuple(v[go] for v in new)
        cur = new
    return tuple(v.reshape(shape) for v in flat)


def where_needed(needed, f, x, *rest):
    """``f(x, *rest)`` on the lanes ``needed`` only, written into ``x`` (which the caller owns).

    The lanes are found in ``needed``'s own memory order (the operands'
    layouts differ: the table path's gathers put pixels fastest, the hashes
    do not), since a copy into another order would cost more than the work
    saved; only the few needed lanes are then gathered from, and scattered
    into, ``x``'s layout.
    """
    if needed is None:
        return f(x, *rest)
    x = np.asarray(x)
    if x.ndim == 0:
        return f(x, *rest) if np.any(needed) else x
    needed = np.broadcast_to(needed, x.shape)
    order = np.argsort(needed.strides, kind="stable")[::-1]
    needed = needed.transpose(order)
    at = np.flatnonzero(needed)
    if not at.size:
        return x
    idx = np.unravel_index(at, needed.shape)
    xv = x.transpose(order)  # a view: writes through it land in x
    xv[idx] = f(xv[idx], *(np.broadcast_to(r, x.shape).transpose(order)[idx] for r in rest))
    return x
