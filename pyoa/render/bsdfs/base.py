"""What a BSDF module is built from: its scene keys, the marker of its
one-point (scalar) forms, and the guards its NumPy forms share.

A BSDF module (:mod:`pyoa.render.bsdfs`) declares its scene keys as
:class:`Key` values, writes its NumPy forms over lanes, and writes its
one-point forms as plain Python marked with :func:`scalar`. Nothing here
imports numba: :mod:`pyoa.render.compiled` compiles the marked functions
(``numba.extending.register_jitable``, inlined into its loops, IEEE
divisions) when the compiled shading is first used, so a scene loads, and the
NumPy reference renders, where numba cannot be imported.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Key", "TINY", "SCALAR", "scalar", "lanes"]

#: Floor of the denominators of the NumPy and one-point forms (keeps 0 / 0 out).
TINY = 1e-300

#: Every function marked by :func:`scalar`, in the order marked (the
#: compiled package registers them with numba before compiling its loops).
SCALAR: list = []


def scalar(fn):
    """Mark ``fn`` as a one-point form that numba compiles (returns ``fn``).

    The function stays plain Python: it is meant to run compiled, where a
    division by zero gives an infinity or a NaN as in NumPy (numba's
    ``error_model="numpy"``), whereas plain Python raises. It may call other
    marked functions and use ``math`` and module-level constants, which numba
    freezes when it compiles. A form that a lane loop of the compiled
    shading calls must be free of branches that depend on its arguments
    (write ``a if c else b`` selects) for that loop to vectorize.
    """
    SCALAR.append(fn)
    return fn


@dataclass(frozen=True)
class Key:
    """A scene key of a material: its name, its default, and the range of its
    values (each component's, for a colour).

    ``default`` is a number, or a tuple of numbers for a vector key (a
    colour: three numbers). ``lo``/``hi`` bound every value, open at
    ``lo_open``/``hi_open``; a value must be finite. The scene parser
    (:mod:`pyoa.render.scene`) reads these to check a scene file's values with
    its own messages; :meth:`check` checks a value given in Python
    (:meth:`pyoa.render.bsdfs.Materials.build`).
    """

    name: str
    default: float | tuple[float, ...]
    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    hi_open: bool = False

    @property
    def size(self) -> int | None:
        """The number of components of a vector key, None for a number."""
        return len(self.default) if isinstance(self.default, tuple) else None

    def describe(self) -> str:
        """What a value must be, in words (``a number in (0, 1]``)."""
        lb, rb = ("(" if self.lo_open else "["), (")" if self.hi_open else "]")
        if math.isinf(self.lo) and math.isinf(self.hi):
            where = "finite"
        elif math.isinf(self.hi):
            where = f"{'>' if self.lo_open else '>='} {self.lo:g}"
        else:
            where = f"in {lb}{self.lo:g}, {self.hi:g}{rb}"
        if self.size is not None:
            return f"{self.size} numbers, each {where}"
        return "a finite number" if where == "finite" else f"a number {where}"

    def admits(self, x: float) -> bool:
        """Whether the number ``x`` is finite and within the key's range."""
        return bool(math.isfinite(x) and not (x < self.lo or x > self.hi or (self.lo_open and x == self.lo)
                                               or (self.hi_open and x == self.hi)))

    def check(self, value) -> float | tuple[float, ...]:
        """``value`` as a float (a tuple of floats for a vector key), or a
        :class:`ValueError` that names the key and the range."""
        try:
            arr = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            arr = None
        shape = () if self.size is None else (self.size,)
        if arr is None or arr.shape != shape or not all(self.admits(float(x)) for x in arr.reshape(-1)):
            raise ValueError(f"{self.name} must be {self.describe()}, got {value!r}")
        return float(arr) if self.size is None else tuple(float(x) for x in arr)


def lanes(m: np.ndarray):
    """An index for the lanes where ``m`` holds, or None if none: a slice when
    all do (a scene of one material kind, such as the Cornell box), which
    makes every ``a[i]`` a view and every ``a[i] = v`` a plain copy instead
    of a boolean gather or scatter (docs/performance.md)."""
    if m.all():
        return slice(None)
    idx = np.flatnonzero(m)
    return idx if idx.size else None
