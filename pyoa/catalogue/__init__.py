"""The catalogue: every sampler pyoa has, registered once.

:data:`SAMPLERS` maps each name to its entry (:mod:`pyoa.catalogue.entries`):
the orthogonal-array constructions of :mod:`pyoa.catalogue.constructions`, then the
comparison samplers of :mod:`pyoa.catalogue.baselines` and the progressive orthogonal
arrays of :mod:`pyoa.catalogue.faure`. Everything that lists, looks
up or dispatches samplers reads it: :func:`pyoa.samplers`, the backends, the
kernel dispatch (:func:`pyoa._opencl.program.dispatch_source`), the CLI and
the test suites.
"""

from __future__ import annotations

from . import baselines, constructions, faure  # noqa: F401  (importing them registers their entries)
from .entries import FAMILIES, MAX_DIMS, Construction, SppChoice, check_int

#: The families of :attr:`Construction.family`, in the order the catalogue lists them.
FAMILY_ORDER = ("oa", "baseline", "progressive")

#: Every sampler: the OA constructions, then the comparison samplers, then faure.
SAMPLERS: dict[str, Construction] = {n: c for group in FAMILY_ORDER for n, c in FAMILIES[group].items()}


#: Names that users of pbrt-v4 and Mitsuba 3 type, each for the pyoa sampler that does the same job
#: (alias -> (pyoa name, where the name comes from)). :func:`get` accepts them; :func:`pyoa.samplers`
#: lists them in their sampler's description. A sampler built by an alias carries the pyoa name.
ALIASES: dict[str, tuple[str, str]] = {
    "independent": ("random", "pbrt-v4, Mitsuba 3"),
    "stratified": ("jittered2d", "pbrt-v4, Mitsuba 3"),
    "multijitter": ("cmj2d", "Mitsuba 3"),
    "orthogonal": ("bose", "Mitsuba 3, Jarosz et al. 2019"),
    "paddedsobol": ("sobol02", "pbrt-v4"),
    "ldsampler": ("sobol02", "Mitsuba 3"),
}


def aliases_of(name: str) -> list[str]:
    """The :data:`ALIASES` of the pyoa sampler ``name``."""
    return [a for a, (n, _) in ALIASES.items() if n == name]


def names(family: str | None = None) -> list[str]:
    """The sampler names, of one family (``"oa"``, ``"baseline"`` or
    ``"progressive"``, :data:`FAMILY_ORDER`) or all."""
    return list(SAMPLERS if family is None else FAMILIES.get(family, ()))


#: The samplers of ``pyoa compare`` and ``pyoa study`` given no ``--samplers``: bose first (their ratios
#: are to the first sampler) and every comparison sampler.
DEFAULT_SAMPLERS: tuple[str, ...] = ("bose", *names("baseline"))


def shown(name: str) -> str:
    """How a table names the sampler typed as ``name``: the catalogue's name, with ``name`` beside it
    when that is an alias (``bose (orthogonal)``; ``BOSE`` is just ``bose``). Files store the catalogue's
    name alone."""
    canonical = get(name).name
    return canonical if name.lower() == canonical else f"{canonical} ({name})"


def labels(typed) -> dict[str, str]:
    """The samplers named in ``typed``, each once (its first spelling wins), as ``{catalogue name: what a
    table shows}`` (:func:`shown`): the names a command's files store, with its tables' labels. An
    unknown name fails, listing the valid ones."""
    out: dict[str, str] = {}
    for name in typed:
        out.setdefault(get(name).name, shown(name))
    return out


def get(name: str) -> Construction:
    """Look up a construction by name (or a pbrt/Mitsuba name in :data:`ALIASES`), with an error that
    lists the valid ones."""
    if not isinstance(name, str):
        raise TypeError(f"sampler name must be a str, got {type(name).__name__}")
    key = name.lower()
    key = ALIASES[key][0] if key in ALIASES else key
    try:
        return SAMPLERS[key]
    except KeyError:
        raise ValueError(f"unknown sampler {name!r}; valid: {', '.join(SAMPLERS)} (or the pbrt/Mitsuba names "
                         f"{', '.join(ALIASES)})") from None


def valid_spp(name: str, near: int | None = None, dims: int | None = None, strength: int | None = None) -> list[SppChoice]:
    """List the valid sample counts of a sampler.

    Parameters
    ----------
    name : str
        Sampler name, see :func:`pyoa.samplers`.
    near : int, optional
        If given, only the counts nearest it on both sides: the largest below
        ``near``, ``near`` itself if it is valid, and the smallest above.
    dims : int, optional
        Number of dimensions the sampler will be asked for; for ``cmjnd``
        without ``strength`` it bounds the strengths considered (2..dims).
    strength : int, optional
        Restrict to one strength t.

    Returns
    -------
    sequence of SppChoice
        ``(spp, s, strength, block_dims, detail)`` tuples in increasing
        ``spp``. For ``random``, ``cmj2d`` and ``halton``, which accept every
        count in ``[1, 2**24]``, a lazy sequence of all 16.7 million.

    Examples
    --------
    >>> [c.label() for c in valid_spp("bose", near=120)]
    ['81 (s=9)', '121 (s=11)']
    >>> [c.label() for c in valid_spp("sobol", near=120)]
    ['64 (2^6)', '128 (2^7)']

    Raises
    ------
    ValueError
        An unknown sampler; a negative ``near``; ``dims`` outside
        ``[1, 2**20]``; a ``strength`` the sampler does not have (as
        :func:`pyoa.sampler` refuses it: ``bose`` has strength 2 only,
        ``bush`` 2..8...), rather than an empty list.
    TypeError
        A name that is not a str, or a count that is not an int.
    """
    construction = get(name)
    near = None if near is None else check_int("near", near, 0)
    dims = None if dims is None else check_int("dims", dims, 1, MAX_DIMS)
    strength = None if strength is None else check_int("strength", strength, 1)
    construction.solve(1, dims, strength)  # raises for a strength (or dims) this sampler cannot have
    return _listing(construction, near, dims, strength)


def _listing(construction: Construction, near: int | None, dims: int | None, strength: int | None):
    """:func:`valid_spp` of arguments already checked (or to be taken as they are)."""
    if near is None:
        return construction.choices(dims=dims, strength=strength)
    return construction.nearest(int(near), dims=dims, strength=strength)


def nearest_spp(name: str, spp: int, dims: int | None = None, strength: int | None = None) -> int | None:
    """The valid sample count of ``name`` closest to ``spp`` (``spp`` itself if
    valid; ties go to fewer samples), or None if there is none for these
    ``dims`` and ``strength``. Used wherever a requested count is replaced by
    a sampler's nearest one (``pyoa compare``, convergence studies, the qmc
    engine's default)."""
    # Unlike valid_spp, a strength the sampler cannot have means "none" here
    # (convergence studies skip such a sampler instead of failing).
    choices = _listing(get(name), spp, dims, strength)
    return min((c.spp for c in choices), key=lambda n: (abs(n - spp), n)) if choices else None
