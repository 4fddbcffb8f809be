"""Tables of the low-discrepancy sequences: Halton's prime bases and Sobol's
direction numbers.

Both are built once per process and shared by every implementation (the
pure-Python reference reads them as Python ints, NumPy and Dr.Jit as uint32
arrays, the C headers and OpenCL kernels from a buffer), so the
implementations cannot disagree on them.

Sobol direction numbers are never invented here: the primitive polynomials and
initial direction numbers are the Joe-Kuo ``new-joe-kuo-6.21201`` table [1]_
exactly as SciPy ships it (``scipy/stats/_sobol_direction_numbers.npz``, the
file behind :class:`scipy.stats.qmc.Sobol`); this module only runs the
Bratley-Fox recurrence [2]_ on them to get 32-bit direction numbers, and the
tests check the result against ``qmc.Sobol(d, scramble=False)`` point for point.

References
----------
.. [1] S. Joe and F. Y. Kuo, "Constructing Sobol sequences with better
   two-dimensional projections", SIAM J. Sci. Comput. 30, 2635-2654, 2008.
.. [2] P. Bratley and B. L. Fox, "Algorithm 659: Implementing Sobol's
   quasirandom sequence generator", ACM TOMS 14(1), 88-100, 1988.
"""

from __future__ import annotations

from functools import lru_cache
from importlib import resources

import numpy as np

#: Bits of each Sobol direction number (uint32 arithmetic).
SOBOL_BITS = 32
#: Dimensions of the Joe-Kuo table SciPy ships.
SOBOL_MAX_DIMS = 21201
#: Halton uses the primes below 2**16 as bases: the kernels' 64-bit digit
#: arithmetic (:mod:`pyoa.reference.baselines`) needs ``b < 2**16``.
HALTON_MAX_BASE = 2**16


@lru_cache(maxsize=None)
def primes() -> np.ndarray:
    """Every prime below :data:`HALTON_MAX_BASE` (6542 of them), as uint32,
    by the sieve of Eratosthenes."""
    n = HALTON_MAX_BASE
    sieve = np.ones(n, dtype=bool)
    sieve[:2] = False
    for k in range(2, int(n**0.5) + 1):
        if sieve[k]:
            sieve[k * k :: k] = False
    out = np.flatnonzero(sieve).astype(np.uint32)
    out.flags.writeable = False
    return out


#: Largest number of Halton dimensions: one prime base each.
HALTON_MAX_DIMS = 6542


def _joe_kuo() -> tuple[np.ndarray, np.ndarray]:
    """``(poly, vinit)`` of SciPy's copy of the Joe-Kuo table."""
    try:
        path = resources.files("scipy.stats") / "_sobol_direction_numbers.npz"
        with resources.as_file(path) as f, np.load(f) as data:
            return data["poly"].astype(np.int64), data["vinit"].astype(np.int64)
    except (ModuleNotFoundError, FileNotFoundError, KeyError) as exc:  # pragma: no cover - install problem
        raise RuntimeError(
            "the Sobol samplers need SciPy's Joe-Kuo direction numbers "
            "(scipy/stats/_sobol_direction_numbers.npz); install scipy >= 1.7"
        ) from exc


@lru_cache(maxsize=None)
def sobol_matrices() -> np.ndarray:
    """The 32-bit Sobol direction numbers of all 21201 dimensions.

    Returns
    -------
    numpy.ndarray
        Read-only uint32 array ``V`` of shape ``(21201, 32)``: the unscrambled
        Sobol point with index ``g`` has coordinate ``j`` equal to the XOR of
        ``V[j, k]`` over the set bits ``k`` of ``g``, divided by ``2**32``.

    Notes
    -----
    Dimension 0 is van der Corput's (``m_k = 1``). For dimension ``j`` with
    primitive polynomial ``x**s + a_1 x**(s-1) + ... + a_(s-1) x + 1`` (SciPy
    stores the coefficients ``a`` as the bits of ``poly[j]``, its degree as
    ``bit_length - 1``) the odd integers ``m_k`` continue the initial
    ``vinit[j, :s]`` by the recurrence [2]_

        m_k = 2 a_1 m_(k-1) ^ 4 a_2 m_(k-2) ^ ... ^ 2**(s-1) a_(s-1) m_(k-s+1) ^ 2**s m_(k-s) ^ m_(k-s),

    and ``V[j, k] = m_k << (31 - k)``. This is the computation of SciPy's
    ``_initialize_v``, vectorized over dimensions.
    """
    poly, vinit = _joe_kuo()
    dims = len(poly)
    m = np.zeros((dims, SOBOL_BITS), dtype=np.uint64)
    m[0, :] = 1
    degree = np.array([int(p).bit_length() - 1 for p in poly])
    for deg in range(1, int(degree.max()) + 1):
        rows = np.flatnonzero(degree == deg)
        rows = rows[rows > 0]
        if rows.size == 0:
            continue
        p = poly[rows].astype(np.uint64)
        m[rows, :deg] = vinit[rows, :deg].astype(np.uint64)
        for k in range(deg, SOBOL_BITS):
            new = m[rows, k - deg].copy()
            for a in range(1, deg + 1):  # bit (deg - a) of poly: a_a, and 1 for a = deg
                bit = (p >> np.uint64(deg - a)) & np.uint64(1)
                new ^= bit * (m[rows, k - a] << np.uint64(a))
            m[rows, k] = new
    shifts = np.uint64(SOBOL_BITS - 1) - np.arange(SOBOL_BITS, dtype=np.uint64)
    v = ((m << shifts[None, :]) & np.uint64(0xFFFFFFFF)).astype(np.uint32)
    v.flags.writeable = False
    return v
