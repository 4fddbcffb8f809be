"""The resolved parameters of a sampler: one type per family of the catalogue.

A catalogue entry (:mod:`pyoa.catalogue.entries`) turns a requested count into
one of these, and every backend reads it. Each field means one thing in
every entry of its type:

:class:`OAParams`
    an orthogonal array: ``bose``, ``bush``, ``cmjnd``,
    ``addelman-kempthorne``, ``bose-bush`` (docs/spec.md section 5);
:class:`PointSetParams`
    a padded 2D grid, stratified only at its full count: ``jittered2d``,
    ``cmj2d``;
:class:`SequenceParams`
    a sample sequence, or padded pairs of one, read at indices ``0..N-1``:
    ``random``, ``sobol02``, ``halton``, ``sobol``, ``zsobol``, ``pmj02``;
:class:`FaureParams`
    a Faure (0, s)-sequence in a prime base: ``faure`` (docs/spec.md
    section 5.11) and ``zfaure`` (section 5.12).

What a listing shows of them (the public :class:`pyoa.SppChoice` and the
sampler attributes ``s``, ``strength`` and ``block_dims``) is the entry's
:meth:`~pyoa.catalogue.entries.Construction.choice`. The types are frozen and
compare by type and value: the backends key their uploads on them.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class OAParams:
    """An orthogonal array of strength ``t`` with ``N`` rows, ``B`` columns
    and ``s`` levels, OA(N, B, s, t), and its ``M`` sub-strata.

    Attributes
    ----------
    N : int
        Rows: samples per pixel.
    B : int
        Columns: dimensions per independently randomized block; dimension
        ``j`` reads column ``j mod B`` of block ``j // B`` (docs/spec.md
        section 6).
    s : int
        Levels: coarse strata per axis.
    M : int
        Sub-strata per coarse stratum, ``N / s`` (the ``cmj`` and ``mj``
        offsets make every dimension a Latin hypercube of ``s * M = N``
        strata, docs/spec.md section 4).
    t : int
        Strength: every ``t``-dimensional projection of a block is
        stratified into ``s**t`` cells, each holding ``N / s**t`` points.
    """

    N: int
    B: int
    s: int
    M: int
    t: int


@dataclass(frozen=True)
class PointSetParams:
    """A padded 2D grid point set: every pair of dimensions ``(2k, 2k + 1)``
    holds one point in each cell of an ``a x c`` grid, ``N = a * c``.

    Attributes
    ----------
    N : int
        Samples per pixel.
    a, c : int
        The grid: ``a`` cells along the pair's first axis, ``c`` along its
        second (``jittered2d``: ``a = c = sqrt(N)``; ``cmj2d``: ``a`` the
        largest divisor of ``N`` not above its square root).
    dims : int
        The sampler's number of dimensions (0 where unknown, as in
        :func:`pyoa.valid_spp`): an odd count leaves a lone last dimension
        (``jittered2d`` stratifies it into ``N`` strata).
    """

    N: int
    a: int
    c: int
    dims: int = 0


@dataclass(frozen=True)
class SequenceParams:
    """A sample sequence, or padded pairs of one, read at indices ``0..N-1``.

    Attributes
    ----------
    N : int
        Samples per pixel.
    dims : int
        The sampler's number of dimensions (0 where unknown): ``sobol``
        uploads the direction numbers of these dimensions only.
    resolution : (int, int) or None
        ``(width, height)`` of the image for a sampler whose values depend on
        where a pixel lies in it (``zsobol``), else None.
    """

    N: int
    dims: int = 0
    resolution: tuple[int, int] | None = None


@dataclass(frozen=True)
class FaureParams:
    """A Faure (0, b)-sequence in the prime base ``b``, read at indices ``0..N-1``.

    Attributes
    ----------
    N : int
        Samples per pixel.
    b : int
        The prime base: dimensions per block, each block one scrambled copy
        of the sequence.
    m : int
        Full nets: the largest ``m`` with ``b**m <= N`` (the first ``b**m``
        samples are a (0, m, b)-net; 0 below ``b`` samples).
    resolution : (int, int) or None
        ``(width, height)`` of the image for ``zfaure``, whose pixels read
        the sequence along an order of the image; None for ``faure``.
    """

    N: int
    b: int
    m: int
    resolution: tuple[int, int] | None = None
