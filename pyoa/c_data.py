"""Static data of pyoa's portable C headers: the generated ``sobol_data.h``.

``kernels/include/pyoa/tables.h`` builds, on the host, every table pyoa's
samplers read (GF(q), the Addelman-Kempthorne constants, Halton's primes,
Sobol's direction numbers), bit for bit the arrays the OpenCL backend
uploads. All but one are computed from a few lines of arithmetic; the
exception is Sobol's, whose primitive polynomials and initial direction
numbers are *data*: the Joe-Kuo ``new-joe-kuo-6.21201`` table [1]_ exactly as
SciPy ships it (``scipy/stats/_sobol_direction_numbers.npz``, the arrays
``poly`` and ``vinit`` that :func:`pyoa.tables.sequences.sobol_matrices` reads).
:func:`sobol_data_header` writes them into ``sobol_data.h``, compactly;
``tests/test_c_tables.py`` fails when the checked-in file and this function
differ. Regenerate it (with ``keys.h``) by ``python -m pyoa.c_headers``.

References
----------
.. [1] S. Joe and F. Y. Kuo, "Constructing Sobol sequences with better
   two-dimensional projections", SIAM J. Sci. Comput. 30, 2635-2654, 2008.
"""

from __future__ import annotations


SOBOL_DATA_FILE = "sobol_data.h"

#: Compile cost, measured (best of three) on the development machine (x86-64,
#: a shared 2-core VM; gcc/g++ 12.2, nvcc 13.0) and written into the header's
#: comment: translation units that include tables.h (hence this file), against
#: one that includes config.h only (0.07 s with gcc, 0.09 s with g++, 1.1 s with nvcc).
COMPILE_NOTE = [
    "parsing it costs about 0.25 s (gcc -std=c99 -O2 -c: 0.32 s for a TU that includes",
    "tables.h and calls nothing, against 0.07 s for one that includes config.h only; g++",
    "-std=c++14 -O2: 0.37 s against 0.09 s); a TU that calls pyoa_sobol_fill, and so emits",
    "the arrays, takes 0.38 s with gcc, 0.69 s with g++, and 2.1 s with nvcc -c against 1.1 s",
]


def _words(values: list[int], per_line: int, fmt: str) -> list[str]:
    return ["    " + " ".join(f"{v:{fmt}}u," for v in values[i:i + per_line])
            for i in range(0, len(values), per_line)]


def sobol_packed() -> tuple[list[int], list[int], int]:
    """The Joe-Kuo parameters as ``sobol_data.h`` stores them.

    Returns
    -------
    poly : list of int
        SciPy's ``poly`` for every dimension (21201 of them): the primitive
        polynomial of dimension ``d >= 1``, its degree ``s = bit_length - 1``,
        the coefficients ``a_1 .. a_(s-1)`` in bits ``s-1 .. 1`` and the
        constant term 1 in bit 0 (``poly[0] = 1``: dimension 0 is van der
        Corput's and has no polynomial).
    m_words : list of int
        uint32 words of one bit stream, bit ``t`` of the stream being bit
        ``t % 32`` of word ``t // 32``: for ``d = 1, 2, ...`` in order and
        ``k = 1 .. s`` (Joe-Kuo's 1-based index; SciPy's ``vinit[d, k-1]``),
        the initial direction number ``m_k`` as ``(m_k - 1) / 2`` in
        ``k - 1`` bits, least significant bit first. Every ``m_k`` is odd
        and below ``2**k`` (checked here), so no bit is lost and ``m_1 = 1``
        takes none: 2.82 million bits instead of 354,613 words.
    bits : int
        The length of the stream in bits.

    Raises
    ------
    ValueError
        If SciPy's table breaks the assumptions above (then the layout must change).
    """
    from .tables.sequences import SOBOL_BITS, _joe_kuo

    poly, vinit = _joe_kuo()
    poly = [int(p) for p in poly]
    if poly[0] != 1:
        raise ValueError(f"dimension 0 should have poly 1, got {poly[0]}")
    words: list[int] = []
    acc = nacc = bits = 0  # acc holds the nacc stream bits not yet in a word
    for d in range(1, len(poly)):
        s = poly[d].bit_length() - 1
        if not 1 <= s < SOBOL_BITS or not poly[d] & 1:
            raise ValueError(f"dimension {d}: poly {poly[d]} is not a polynomial of degree 1..31 with constant term 1")
        for k in range(1, s + 1):
            m = int(vinit[d, k - 1])
            if m % 2 == 0 or not 0 < m < 2**k:
                raise ValueError(f"dimension {d}: m_{k} = {m} is not odd and below 2**{k}")
            acc |= (m >> 1) << nacc
            nacc += k - 1
            bits += k - 1
            while nacc >= 32:
                words.append(acc & 0xFFFFFFFF)
                acc >>= 32
                nacc -= 32
    if nacc:
        words.append(acc)
    return poly, words, bits


def sobol_data_header() -> str:
    """The text of ``pyoa/sobol_data.h``.

    Two ``static const`` uint32 arrays, each returned by a host-only
    accessor (``pyoa_sobol_poly()``, ``pyoa_sobol_m_bits()``; a function-local
    array is emitted only by a translation unit that calls it, and draws no
    unused-variable warning where it does not), in the layout of
    :func:`sobol_packed`, plus the counts as macros. ``pyoa_sobol_fill`` of
    ``tables.h`` runs the Bratley-Fox recurrence on them (docs/spec.md
    section 5.8).

    Returns
    -------
    str
        The header, deterministic: the same SciPy table gives the same text.
    """
    from .tables.sequences import SOBOL_MAX_DIMS

    poly, words, bits = sobol_packed()
    if len(poly) != SOBOL_MAX_DIMS:
        raise ValueError(f"SciPy's table has {len(poly)} dimensions, pyoa.tables.sequences expects {SOBOL_MAX_DIMS}")
    max_degree = max(p.bit_length() - 1 for p in poly)
    data_bytes = 4 * (len(poly) + len(words))
    head = [
        "/* pyoa/sobol_data.h: the Joe-Kuo parameters of Sobol's sequence, for pyoa_sobol_fill (tables.h).",
        " * Generated by `python -m pyoa.c_headers` (pyoa.c_data.sobol_data_header) from SciPy's copy of",
        " * new-joe-kuo-6.21201 (scipy/stats/_sobol_direction_numbers.npz: poly, vinit; S. Joe and",
        " * F. Y. Kuo, SIAM J. Sci. Comput. 30, 2635-2654, 2008), the table pyoa.tables.sequences reads;",
        " * do not edit (tests/test_c_tables.py fails when this file and the generator differ).",
        " *",
        f" * pyoa_sobol_poly()[d], d < {len(poly)}: SciPy's poly: the primitive polynomial of dimension d,",
        " *   degree s = bit_length - 1, a_1 .. a_(s-1) in bits s-1 .. 1, the constant term 1 in bit 0",
        " *   (poly[0] = 1: dimension 0, van der Corput's, has none).",
        f" * pyoa_sobol_m_bits(): {len(words)} words of one bit stream (bit t = bit t % 32 of word t / 32,",
        f" *   {bits} bits): for d = 1, 2, ... and k = 1 .. s, the initial direction number",
        " *   m_k = vinit[d][k-1] as (m_k - 1) / 2 in k - 1 bits, least significant first (each m_k is odd",
        " *   and below 2^k, so nothing is lost; m_1 = 1 takes no bit).",
        " *",
        f" * Size: {data_bytes} bytes of data ({data_bytes / 1024:.0f} KiB) in a TU that calls the accessors,",
        " * nothing in one that does not; the text is about 1.4 MB (355k plain initial numbers would",
        " * take 2 MB and three times as long to compile). Compile time, measured with gcc/g++ 12.2 and",
        " * nvcc 13.0 on x86-64 (python -m pyoa.c_headers does not re-measure):",
        *[f" * {line}" for line in COMPILE_NOTE[:-1]],
        f" * {COMPILE_NOTE[-1]}. */",
        "#ifndef PYOA_SOBOL_DATA_H",
        "#define PYOA_SOBOL_DATA_H",
        "",
        '#include "config.h"',
        "",
        f"#define PYOA_SOBOL_MAX_DIMS {len(poly)}u",
        f"#define PYOA_SOBOL_MAX_DEGREE {max_degree}u",
        f"#define PYOA_SOBOL_M_WORDS {len(words)}u",
        f"#define PYOA_SOBOL_M_BITS {bits}u",
        "",
        "#if !defined(__OPENCL_VERSION__)",
        "",
        "/* SciPy's poly of every dimension (host memory). */",
        "PYOA_HOST_FN const pyoa_u32 *pyoa_sobol_poly(void)",
        "{",
        f"    static const pyoa_u32 poly[{len(poly)}] = {{",
        *_words(poly, 12, "d"),
        "    };",
        "    return poly;",
        "}",
        "",
        "/* The initial direction numbers, packed (see the top of this file; host memory). */",
        "PYOA_HOST_FN const pyoa_u32 *pyoa_sobol_m_bits(void)",
        "{",
        f"    static const pyoa_u32 m_bits[{len(words)}] = {{",
        *_words(words, 8, "#010x"),
        "    };",
        "    return m_bits;",
        "}",
        "",
        "#endif /* !__OPENCL_VERSION__ */",
        "",
        "#endif /* PYOA_SOBOL_DATA_H */",
        "",
    ]
    return "\n".join(head)
