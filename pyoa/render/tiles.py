"""Renders split into tasks: tiles of whole pixels, run by an engine (:mod:`pyoa.cluster`).

A render on a cluster is the in-process render cut into tiles of whole pixels
(every sample of a pixel in one task). Each task loads the scene on its worker
(:mod:`.scene_source`), generates its own sampler values and returns the
tile's float32 pixel means; the client only places them. A pixel's value does
not depend on which other pixels share its batch or its tile (the
integrator's estimate of a pixel reads only that pixel's samples, and its
mean is summed along one axis in a fixed order), so the assembled image is
bit-identical to :func:`pyoa.render.render.render` with the same arguments.

Tasks also run a whole render (:func:`render_task`, one study render) and
reference passes (:mod:`pyoa.render.reference`); all of them go through
:func:`worker_render`, which keeps the integrator of a scene and its
settings per worker process, so its setup and compilation are paid once per
worker rather than once per task.
"""

from __future__ import annotations

import time
import weakref
from contextlib import closing

import numpy as np

from .integrator import Stats
from .provenance import printable
from .render import BATCH_PATHS, RenderResult, plan, render
from .scene_source import SceneSource, load_source, source_of
from .settings import RenderSettings
from .state import scene_digest

#: Tiles per task slot of the engine: enough that slots finishing early find work.
TILES_PER_SLOT = 4

#: Integrators kept in this (worker) process: settings -> RenderResult.integrator.
_INTEGRATORS: dict[tuple, tuple] = {}
#: Digests of the Scene objects rendered in this process (freed with them).
_DIGESTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
#: Most integrators kept (a study visits a few scenes and settings).
_MAX_INTEGRATORS = 16


def worker_render(src, settings: RenderSettings, *, pixels: range | None = None,
                  threads: int | None = None) -> RenderResult:
    """:func:`render` of the scene ``src`` (a :class:`SceneSource` on a
    worker, the :class:`~pyoa.render.scene.Scene` itself in-process) with
    ``settings`` in this process, reusing this process's integrator for the
    same scene and :meth:`~RenderSettings.integrator_key`."""
    if isinstance(src, SceneSource):
        scene, digest = load_source(src), src.digest
    else:  # in-process: the Scene itself, hashed once (a study renders it hundreds of times)
        scene, digest = src, _DIGESTS.get(src) or _DIGESTS.setdefault(src, scene_digest(src))
    key = (digest, *settings.integrator_key())
    res = render(scene, settings, pixels=pixels, threads=threads, integrator=_INTEGRATORS.get(key))
    if key not in _INTEGRATORS:
        if len(_INTEGRATORS) >= _MAX_INTEGRATORS:
            _INTEGRATORS.pop(next(iter(_INTEGRATORS)))
        _INTEGRATORS[key] = res.integrator
    res.integrator = None  # it stays on the worker: never pickled back to the client
    return res


def tile_task(src: SceneSource, settings: RenderSettings, pixels: range, threads: int | None):
    """One tile: ``(pixels.start, float32 means (len(pixels), 3), Stats)``."""
    res = worker_render(src, settings, pixels=pixels, threads=threads)
    return pixels.start, res.image, res.stats


def tile_ranges(n_pixels: int, spp: int, slots: int) -> list[range]:
    """Contiguous tiles covering ``[0, n_pixels)``: about
    :data:`TILES_PER_SLOT` per slot, none smaller than a batch of camera paths
    (:data:`~pyoa.render.render.BATCH_PATHS`) unless the image is."""
    smallest = max(1, BATCH_PATHS // max(spp, 1))
    count = max(1, min(TILES_PER_SLOT * slots, -(-n_pixels // smallest)))
    size = -(-n_pixels // count)
    return [range(a, min(a + size, n_pixels)) for a in range(0, n_pixels, size)]


def render_on(eng, scene, settings: RenderSettings | None = None, /, *, progress: bool = False,
              **changes) -> RenderResult:
    """Render ``scene`` with ``settings`` (a :class:`RenderSettings`, or its
    fields as keyword arguments, as :func:`render` takes them) on the engine
    ``eng``: in-process, :func:`render` itself; on a cluster, in tiles whose
    assembled image is bit-identical to it.

    Every setting is checked on the client first (:func:`plan`), before any
    task is submitted."""
    settings = RenderSettings.of(settings, **changes)
    if eng.client is None:
        return render(scene, settings, progress=progress)
    p = plan(scene, settings)
    settings = p.worker_settings()
    src = source_of(scene)
    tiles = tile_ranges(p.width * p.height, p.sampler.spp, eng.slots)
    threads = eng.task_threads()
    out = np.empty((p.width * p.height, 3), dtype=np.float32)
    stats = Stats()
    from ..cluster import progress_over

    t0 = time.perf_counter()
    src = eng.share(src)
    with closing(eng.run(tile_task, [(src, settings, t, threads) for t in tiles], key="pyoa-tile")) as results:
        for _, (start, means, st) in progress_over(results, len(tiles), f"{printable(scene.name)} {p.sampler.name} "
                                                   f"{p.sampler.spp} spp", not progress, unit="tile"):
            out[start:start + len(means)] = means
            stats.add(st)
    seconds = time.perf_counter() - t0
    return RenderResult(image=out.reshape(p.height, p.width, 3), sampler=p.sampler.name, spp=p.sampler.spp,
                        seed=p.sampler.seed, dims=p.layout.dims, layout=p.layout.describe(), seconds=seconds,
                        stats=stats, shading=settings.shading, settings=settings)
