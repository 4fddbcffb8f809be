"""pyoa's samplers written once over an array namespace, for NumPy and Dr.Jit.

The modules of this package hold the rules of docs/spec.md as array
operations, once: the integer hashes (:mod:`.hashes`), the block rule
(:mod:`.blocks`), the float tail (:mod:`.floats`), the orthogonal arrays'
cells and common frame (:mod:`.oa`) and the Faure sequence (:mod:`.faure`).
Every function takes an array namespace ``xp`` as its first argument;
:mod:`pyoa._numpy` and :mod:`pyoa._drjit` bind them (:func:`bind`) to
their namespaces, :mod:`pyoa._numpy.ops` and :mod:`pyoa._drjit.ops`. The
pure-Python :mod:`pyoa.reference` is written apart, on purpose: it is the
independent oracle both bindings are tested against.

Arithmetic is written with Python's operators. On uint32 arrays ``+ - * //
% << >> & | ^`` wrap modulo ``2**32`` in both namespaces, and a Python int
below ``2**32`` combines with an array as a uint32 constant; a Python float
combines with a float32 array as a float32 constant (every float constant
here is a float32 value, so nothing is rounded). Two Python ints never meet
(their arithmetic would not wrap): a function first makes its integer
arguments arrays with ``xp.as_uint32``. Float division is never written
``/``: Dr.Jit turns a division by a constant into a multiplication by its
rounded reciprocal, so ``xp.divide`` divides.

The namespace
-------------
Each name of :data:`OPERATIONS`; ``tests/_numpy/test_ops.py`` and
``tests/test_drjit.py`` check that both namespaces define them and agree.

``as_uint32(*values)``
    The values (arrays or Python ints) as uint32 arrays of one backend, a tuple.
``u32(x)``, ``u64(x)``, ``f32(x)``, ``f64(x)``
    An array cast: integers and floats convert (float to integer truncates,
    integer to float rounds to nearest even), a mask gives 0 or 1.
``bits(x)``, ``from_bits(u)``
    The IEEE bits of a float32 array as uint32, and back.
``zeros(*like)``
    uint32 zeros that broadcast against the arrays ``like``.
``select(mask, a, b)``, ``minimum(a, b)``, ``maximum(a, b)``
    Lane by lane.
``gather(table, index)``
    ``table[index]``: ``table`` a host uint32 NumPy array (a constant).
``divide(x, n)``
    The float32 ``x / n``, correctly rounded, for a Python number ``n``.
``power(base, e)``
    ``base ** e`` modulo ``2**32`` for a Python int base, exponents ``e < 32``.
``may_any(mask)``
    False only if no lane of ``mask`` is set: NumPy looks, a traced
    namespace (Dr.Jit) cannot and answers True.
``while_loops(loops, label)``
    Independent loops ``(state, cond, body)``: in every lane, ``state =
    body(*state)`` while ``cond(*state)``; the final states, one tuple per
    loop. NumPy runs them one by one on the lanes still looping; Dr.Jit runs
    them in one symbolic loop (``label`` names it), so that their chains of
    dependent operations overlap. A body returns the state values it does
    not change as the same objects.
``where_needed(needed, f, x, *rest)``
    ``f(x, *rest)``, for ``f`` that leaves ``x`` unchanged wherever
    ``needed`` is not set (``None``: set everywhere). NumPy computes ``f``
    on the needed lanes only (and may write into ``x``, which must be the
    caller's own array); Dr.Jit computes it everywhere, without a branch,
    and drops the unused mask.
``wrapping()``
    A context in which wrapping integer arithmetic raises no warning
    (NumPy warns on uint32 *scalars* that overflow): :func:`bind` enters it.
"""

from __future__ import annotations

import functools
import inspect

#: The operations every namespace defines (see the module docstring).
OPERATIONS = ("as_uint32", "u32", "u64", "f32", "f64", "bits", "from_bits", "zeros", "select", "minimum",
              "maximum", "gather", "divide", "power", "may_any", "while_loops", "where_needed", "wrapping")


def bind(xp, f):
    """``f`` (a function or class of this package) with ``xp`` as its first argument.

    The result has ``f``'s name and docstring and its signature without
    ``xp``, and runs ``f`` inside ``xp.wrapping()``.
    """
    @functools.wraps(f)
    def bound(*args, **kwargs):
        with xp.wrapping():
            return f(xp, *args, **kwargs)

    sig = inspect.signature(f)
    bound.__signature__ = sig.replace(parameters=list(sig.parameters.values())[1:])
    return bound
