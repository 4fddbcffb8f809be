"""The settings of a render as one value: :class:`RenderSettings`.

A render's image depends on its scene and on these settings only (the
sampler, its count and seed, the film, the path length, the filter, the
layout of the dimensions, the shading); how it runs (threads, the engine,
progress bars) does not change a bit of it. Every part of the renderer that
hands a render on (:func:`pyoa.render.render.render` and
:func:`~pyoa.render.render.plan`, the cluster's tiles, reference passes,
study renders, progressive blocks, the command line) passes this value, so a
new setting is one field here and its use, not a keyword threaded by hand
through every module (Mitsuba 3's scene dictionaries and pbrt-v4's
``ParameterDictionary`` play the same part).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ..catalogue.entries import MAX_UINT32, check_int

#: Camera paths per batch (bounds the working set: ~1 KiB per path).
BATCH_PATHS = 1 << 16


@dataclass(frozen=True)
class RenderSettings:
    """What a render computes, as one immutable value.

    Parameters
    ----------
    sampler : str
        Any name of :func:`pyoa.samplers` (pbrt-v4's and Mitsuba 3's names
        included); ``spp`` must be one of its valid counts
        (:func:`pyoa.valid_spp`), else :func:`~pyoa.render.render.plan`
        raises a ValueError naming the nearest.
    spp : int
        Samples per pixel.
    seed : int
        User seed of the sampler (uint32).
    width, height, max_depth : int, optional
        The film size and the path length (segments, as Mitsuba); integers
        >= 1, None for the scene's (0 is refused, not read as None).
    filter : {"box", "gaussian"}
        Pixel filter (see :class:`pyoa.render.integrator.Integrator`).
    first : sequence of str, optional
        Integrand dimensions to map to the first sampler dimensions (see
        :mod:`pyoa.render.layout`); kept as a tuple.
    base : int, optional
        The digit base of ``faure`` (refused by the other samplers).
    backend : str, optional
        Sampler backend (``"opencl"``, ``"numpy"``; None: automatic). Every
        backend gives the same bits.
    device : str, optional
        OpenCL device selector of the sampler (:func:`pyoa.sampler`'s
        ``device``; None: ``$PYOA_OPENCL_DEVICE``, else automatic). Every
        device gives the same bits.
    shading : {"numba", "numpy"}, optional
        The compiled shading or the NumPy reference; None: ``$PYOA_SHADING``,
        else ``"numba"`` (:func:`pyoa.render.render.resolve_shading`).
    batch_paths : int
        Camera paths per batch, rounded down to whole pixels (the working
        set; the image does not depend on it).
    max_bytes : int or str, optional
        Memory limit (bytes, ``"4G"``, a fraction of RAM; None:
        ``$PYOA_MAX_BYTES``, else half of the memory).

    Nothing is checked here but the names: :func:`pyoa.render.render.plan`
    checks the values against the scene (a film size, a count valid for the
    sampler) and says what is valid.

    Examples
    --------
    >>> from pyoa.render.settings import RenderSettings
    >>> s = RenderSettings(sampler="bose", spp=121, width=64, height=64)
    >>> s.replace(seed=3).seed
    3
    """

    sampler: str = "bose"
    spp: int = 121
    seed: int = 0
    width: int | None = None
    height: int | None = None
    max_depth: int | None = None
    filter: str = "box"
    first: tuple[str, ...] | None = None
    base: int | None = None
    backend: str | None = None
    device: str | None = None
    shading: str | None = None
    batch_paths: int = BATCH_PATHS
    max_bytes: int | str | None = None

    def __post_init__(self):
        # a list would make the value unhashable; other types are left for
        # the layout to refuse with its own message
        if isinstance(self.first, list):
            object.__setattr__(self, "first", tuple(self.first))

    @classmethod
    def of(cls, settings: RenderSettings | None = None, **changes) -> RenderSettings:
        """``settings`` (None: the defaults) with the fields ``changes``
        replaced: how :func:`~pyoa.render.render.render` and the functions
        beside it accept either a value or keyword arguments."""
        if settings is None:
            settings = cls()
        elif not isinstance(settings, cls):
            raise TypeError(f"settings must be a RenderSettings, got {type(settings).__name__}")
        return settings.replace(**changes) if changes else settings

    def replace(self, **changes) -> RenderSettings:
        """A copy with ``changes``; an unknown name is a TypeError listing the valid ones."""
        bad = sorted(set(changes) - set(names()))
        if bad:
            raise TypeError(f"unknown render setting{'s' if len(bad) > 1 else ''} {', '.join(map(repr, bad))}; "
                            f"valid: {', '.join(names())}")
        return dataclasses.replace(self, **changes)

    def integrator_key(self) -> tuple:
        """What an integrator built for these settings depends on (with the
        scene): the film, the path length, the layout, the filter and the
        shading; not the sampler, its count or seed, which a reused
        integrator renders with any of."""
        return (self.width, self.height, self.max_depth, self.filter, self.first or (), self.shading)


def names() -> tuple[str, ...]:
    """The fields of :class:`RenderSettings`, in order."""
    return tuple(f.name for f in dataclasses.fields(RenderSettings))


#: Most seeds per sampler of ``pyoa compare --seeds`` and ``pyoa study --seeds``: a typo guard.
MAX_SEEDS = 1 << 16


def check_seeds(seed, seeds) -> list[int]:
    """The seeds of ``--seed S --seeds N``: S, S+1, ..., S+N-1, all uint32 (``pyoa compare`` and
    ``pyoa study``)."""
    n = check_int("--seeds", seeds, 1, MAX_SEEDS)
    first = check_int("--seed", seed, 0, MAX_UINT32 - n + 1, " (the first of --seeds uint32 seeds)")
    return list(range(first, first + n))
