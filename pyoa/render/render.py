"""Rendering a scene with one of pyoa's samplers: batching, threads, progress.

The image is the per-pixel mean of ``spp`` camera paths. Pixels are processed
in batches of whole pixels (every sample of a pixel in one batch): the
sampler produces the batch's values in one bulk call, the integrator traces
them, and batches run on a thread pool (Embree and NumPy release the GIL).
The result does not depend on the batch size or the number of threads.
"""

from __future__ import annotations

import os
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from ..samplers import sampler as make_sampler
from .integrator import Integrator, Stats
from .layout import Layout

#: Camera paths per batch (bounds the working set: ~1 KiB per path).
BATCH_PATHS = 1 << 16
#: Shading implementations: numba-compiled with Embree called from it (the
#: default), or the NumPy reference.
SHADINGS = ("numba", "numpy")
ENV_SHADING = "PYOA_SHADING"


def resolve_shading(shading: str | None) -> str:
    """The shading to use: ``shading``, else ``$PYOA_SHADING``, else ``"numba"``."""
    origin = "shading"
    if shading is None:
        shading, origin = os.environ.get(ENV_SHADING) or "numba", f"${ENV_SHADING}"
    if not isinstance(shading, str):
        raise TypeError(f"shading must be a str or None, got {type(shading).__name__}")
    name = shading.strip().lower()
    if name not in SHADINGS:
        raise ValueError(f"unknown {origin} {shading!r}; valid: {', '.join(SHADINGS)}")
    return name


@dataclass
class RenderResult:
    """A rendered image (linear RGB float32, ``(height, width, 3)``) and its figures."""

    image: np.ndarray
    sampler: str
    spp: int
    seed: int
    dims: int
    layout: str
    seconds: float
    stats: Stats = field(default_factory=Stats)
    shading: str = "numba"
    #: seconds per stage summed over the worker threads (compiled shading only)
    timings: dict = field(default_factory=dict)

    @property
    def paths_per_second(self) -> float:
        return self.stats.paths / max(self.seconds, 1e-9)

    @property
    def rays_per_second(self) -> float:
        return self.stats.rays / max(self.seconds, 1e-9)


class ShadingFallbackWarning(RuntimeWarning):
    """The compiled shading was not usable and the NumPy reference rendered instead."""


_warned = False


def _warn_fallback(exc: BaseException) -> None:
    global _warned
    if not _warned:
        _warned = True
        first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
        warnings.warn(f"pyoa: compiled shading is not usable ({type(exc).__name__}: {first}); rendering with the "
                      f"NumPy reference shading instead (same estimate, slower). Set {ENV_SHADING}=numpy to "
                      "silence this.", ShadingFallbackWarning, stacklevel=3)


def render(scene, *, sampler: str = "bose", spp: int = 121, seed: int = 0, width: int | None = None,
           height: int | None = None, max_depth: int | None = None, filter: str = "box", first=None,
           backend: str | None = None, batch_paths: int = BATCH_PATHS, threads: int | None = None,
           progress: bool = False, shading: str | None = None) -> RenderResult:
    """Render ``scene`` (a :class:`pyoa.render.scene.Scene`) with ``spp`` samples per pixel.

    Parameters
    ----------
    sampler : str
        Any name of :func:`pyoa.samplers`; ``spp`` must be one of its valid
        counts (:func:`pyoa.valid_spp`), else a ValueError names the nearest.
    seed : int
        User seed of the sampler (uint32).
    width, height, max_depth : int, optional
        Override the scene's film size and path length (segments, as Mitsuba).
    filter : {"box", "gaussian"}
        Pixel filter (see :class:`.integrator.Integrator`).
    first : sequence of str, optional
        Integrand dimensions to map to the first sampler dimensions (see
        :mod:`.layout`).
    backend : str, optional
        Sampler backend (``"opencl"``, ``"numpy"``; default automatic).
    batch_paths : int
        Camera paths per batch (rounded to whole pixels).
    threads : int, optional
        Worker threads (default: the number of CPUs).
    progress : bool
        Show a tqdm progress bar.
    shading : {"numba", "numpy"}, optional
        ``"numba"`` (default): shading compiled with numba, Embree called from
        it (:mod:`pyoa.render.compiled`); ``"numpy"``: the NumPy reference
        (:mod:`pyoa.render.integrator`). Default ``$PYOA_SHADING``, else numba.
        Both estimate the same image; each gives the same bits for any batch
        size and thread count.
    """
    explicit = shading is not None
    shading = resolve_shading(shading)
    width = int(width or scene.width)
    height = int(height or scene.height)
    if width < 1 or height < 1:
        raise ValueError(f"image size must be positive, got {width} x {height}")
    depth = int(max_depth if max_depth is not None else scene.max_depth)
    cam = scene.camera
    layout = Layout(max_depth=depth, mis=scene.mis, lens=cam.aperture > 0,
                    time=bool(np.any(np.asarray(cam.motion) != 0)), first=first)
    smp = make_sampler(sampler, spp=spp, dims=max(layout.dims, 1), seed=seed, backend=backend)
    integ = None
    if shading == "numba":
        try:
            from .compiled.integrator import CompiledIntegrator

            integ = CompiledIntegrator(scene, layout, width, height, filter=filter)
        except (ImportError, OSError, RuntimeError) as exc:  # numba missing, Embree library unusable
            if explicit:
                raise RuntimeError(f"compiled shading is not usable here: {exc}") from exc
            _warn_fallback(exc)
            shading = "numpy"
    if integ is None:
        integ = Integrator(scene, layout, width, height, filter=filter)
    n_pixels = width * height
    per_batch = max(1, batch_paths // spp)
    batches = [(p0, min(p0 + per_batch, n_pixels)) for p0 in range(0, n_pixels, per_batch)]
    out = np.empty((n_pixels, 3), dtype=np.float32)
    total = Stats()

    def run(batch):
        p0, p1 = batch
        x = smp.generate(pixels=range(p0, p1)).reshape((p1 - p0) * spp, smp.dims)
        pixel = np.repeat(np.arange(p0, p1), spp)
        sample = np.tile(np.arange(spp), p1 - p0)
        rad, st = integ.radiance(pixel, sample, x, seed=seed)
        # per-pixel mean, summed along a contiguous axis: the same bits for any batch size
        s = np.ascontiguousarray(rad.reshape(p1 - p0, spp, 3).transpose(0, 2, 1)).sum(axis=2)
        out[p0:p1] = (s / spp).astype(np.float32)
        return st

    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=n_pixels, unit="px", desc=f"{scene.name} {sampler} {spp} spp")
    t0 = time.perf_counter()
    workers = max(1, min(threads or os.cpu_count() or 1, len(batches)))
    try:
        with ThreadPoolExecutor(workers) as pool:
            for (p0, p1), st in zip(batches, pool.map(run, batches)):
                total.add(st)
                if bar is not None:
                    bar.update(p1 - p0)
    finally:
        if bar is not None:
            bar.close()
    seconds = time.perf_counter() - t0
    return RenderResult(image=out.reshape(height, width, 3), sampler=smp.name, spp=spp, seed=seed,
                        dims=layout.dims, layout=layout.describe(), seconds=seconds, stats=total, shading=shading,
                        timings=dict(getattr(integ, "timings", {})))
