"""The array namespace of :mod:`pyoa._arrays` in Dr.Jit operations (the contract
is that package's docstring).

Every operation derives the types it needs (``Float32``, ``Float64``,
``UInt64``) from its arguments' ``UInt32``, so one namespace serves every
backend (``drjit.llvm``, ``drjit.cuda``, with or without ``.ad``) and every
Mitsuba variant of a JIT backend. ``UInt32`` arithmetic wraps modulo
``2**32``; float32 ``+``, ``*`` and ``/`` are one correctly rounded IEEE
operation each, never contracted into an FMA unless ``dr.fma`` is called,
with one exception that :func:`divide` avoids. Nothing here branches on
array contents: the code is traced into one kernel, so the loops are
symbolic and masked work is computed in every lane.
"""

from __future__ import annotations

import contextlib
from functools import cache

import drjit as dr
import numpy as np


def as_uint32(*values) -> tuple:
    U = next((type(v) for v in values if dr.is_array_v(v)), None)
    if U is None:
        raise TypeError("pyoa's Dr.Jit samplers need at least one Dr.Jit array argument")
    U = dr.uint32_array_t(U)
    return tuple(U(v) for v in values)


def u32(x):
    return dr.uint32_array_t(type(x))(x)


def u64(x):
    return dr.uint64_array_t(type(x))(x)


def f32(x):
    return dr.float32_array_t(type(x))(x)


def f64(x):
    return dr.float64_array_t(type(x))(x)


def bits(x):
    return dr.reinterpret_array(dr.uint32_array_t(type(x)), x)


def from_bits(u):
    return dr.reinterpret_array(dr.float32_array_t(type(u)), u)


def zeros(*like):
    return as_uint32(0, *like)[0]


select = dr.select
minimum = dr.minimum
maximum = dr.maximum


#: (array type, id of a host table) -> (the table, its device copy); holding the table keeps its id its own
_DEVICE: dict = {}


def gather(table: np.ndarray, index):
    U = type(index)
    key = (U, id(table))
    if key not in _DEVICE:
        _DEVICE[key] = (table, U(table))
    return dr.gather(U, _DEVICE[key][1], index)


@cache
def _opaque(F, n: float):
    return dr.opaque(F, n)


def divide(x, n):
    """``x / n`` correctly rounded: ``n`` as an opaque array, never a literal
    (Dr.Jit rewrites ``x / literal`` as ``x * (1 / literal)``, which changes
    about half of the quotients by an ulp, measured)."""
    return x / _opaque(type(x), float(n))


def power(base: int, e):
    """``base ** e`` by square and multiply over the five bits of ``e < 32``
    (no per-lane power; the products wrap modulo ``2**32`` like NumPy's)."""
    r = type(e)(1)
    for k in range(5):
        r = dr.select(((e >> k) & 1) != 0, r * (base ** (1 << k) % 2**32), r)
    return r


def may_any(mask) -> bool:
    return True  # a traced array's contents are unknown until the kernel runs


def wrapping():
    return contextlib.nullcontext()


def while_loops(loops, label: str) -> list:
    """The loops in one ``dr.while_loop``: it runs while any loop's condition
    holds in a lane, and each step leaves the state of a loop that is done
    in that lane as it is (a select; a value its body returns unchanged
    needs none)."""
    if len(loops) <= 1:
        return [dr.while_loop(state=tuple(state), cond=cond, body=body, label=label) for state, cond, body in loops]
    sizes = [len(state) for state, _, _ in loops]

    def split(flat):
        out, k = [], 0
        for n in sizes:
            out.append(flat[k : k + n])
            k += n
        return out

    def cond(*flat):
        go = None
        for part, (_, c, _) in zip(split(flat), loops):
            go = c(*part) if go is None else go | c(*part)
        return go

    def body(*flat):
        out = []
        for part, (_, c, b) in zip(split(flat), loops):
            go = c(*part)
            out += [v if v is o else dr.select(go, v, o) for v, o in zip(b(*part), part)]
        return tuple(out)

    state = tuple(v for s, _, _ in loops for v in s)
    return [tuple(part) for part in split(dr.while_loop(state=state, cond=cond, body=body, label=label))]


def where_needed(needed, f, x, *rest):
    return f(x, *rest)  # every lane, branch-free; the mask is never used, so never computed
