"""Rendering a scene with one of pyoa's samplers: batching, threads, progress.

The image is the per-pixel mean of ``spp`` camera paths. Pixels are processed
in batches of whole pixels (every sample of a pixel in one batch): the
sampler produces the values of :data:`SAMPLE_GROUP` consecutive batches in
one bulk call, on threads of its own that run ahead of the render workers,
the integrator traces each batch, and batches run on a thread pool (Embree
and NumPy release the GIL). The result does not depend on the batch size,
the grouping or the number of threads: a value depends only on its pixel,
sample and dimension.
"""

from __future__ import annotations

import numbers
import os
import sys
import time
import warnings
from collections import deque
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import dataclass, field

import numpy as np

from .. import catalogue
from ..catalogue.entries import MAX_UINT32, check_choice
from ..samplers import ENV_MAX_BYTES, default_max_bytes, parse_bytes
from ..samplers import sampler as make_sampler
from ..util.units import format_bytes
from .camera import check_filter
from .integrator import RENDERER_VERSION, Integrator, Stats
from .layout import MAX_DEPTH, Layout
from .settings import BATCH_PATHS, RenderSettings
from .state import scene_digest

#: Working memory of one camera path in flight, besides its row of sampler
#: values: measured peaks are ~0.3 KiB (compiled shading) and ~1.1 KiB (NumPy
#: shading, 46 dimensions, sampler row included), so 1 KiB plus 8 bytes per
#: dimension (the float32 row and float64 copies of its columns) bounds both.
PATH_BYTES = 1024
#: Bytes of the image per pixel (float32 RGB) and of one batch's bookkeeping
#: (its entry in the list of batches and the tuple in it).
PIXEL_BYTES = 12
BATCH_BYTES = 128
#: Batches whose sampler values one sampler call makes, and how many such
#: calls run ahead of the render workers (``SAMPLE_AHEAD`` per worker, on as
#: many sampling threads as workers). Larger calls cost PoCL less per value,
#: and samples made before a worker needs them fill the time a worker used
#: to wait for PoCL's threads: on two cores, renders of the four bundled
#: scenes took 0.93-0.97 of the time of each worker sampling its own batch
#: (docs/performance.md, "Where sampling runs"; groups of 4 were no faster).
#: The price is memory: the values of up to ``_queue_bounds(threads)[1]``
#: batches (12 on two threads) are alive at once, which :func:`render_bytes`
#: charges.
SAMPLE_GROUP = 2
SAMPLE_AHEAD = 1
#: Most pixels in one image: pixel indices are uint32 (the sampler's pixel seeds).
MAX_PIXELS = MAX_UINT32 + 1
#: Memory of a loaded scene per triangle while it is traced: its own arrays
#: (100 bytes: float32 vertices, float64 normals, areas and emission, ids)
#: and, at the peak of building them, the tracer's float64 copies and
#: Embree's buffers and BVH: 202 to 297 bytes more. Measured as VmHWM above
#: the process before the render (after the load's garbage was freed), for
#: 1M-triangle meshes with numba and NumPy shading; 512 with a margin. (The
#: load's own peak is pyoa.render.scene.MESH_TRIANGLE_BYTES.)
SCENE_TRIANGLE_BYTES = 512
#: What the first render with numba's cache empty says before numba compiles the renderer: the one
#: statement of how long that takes, which the README and docs repeat (tests/test_figures_docs.py
#: checks them against this line; docs/rendering.md, "First use", says when the cache is empty).
COMPILING = "compiling the renderer with numba (once per installed version of pyoa, 15-60 s) ..."
#: Shading implementations: numba-compiled with Embree called from it (the
#: default), or the NumPy reference.
SHADINGS = ("numba", "numpy")
ENV_SHADING = "PYOA_SHADING"


def resolve_shading(shading: str | None) -> str:
    """The shading to use: ``shading``, else ``$PYOA_SHADING``, else ``"numba"``."""
    return check_choice(shading, ENV_SHADING, SHADINGS, "numba")


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
    #: (seconds, paths) of the first batch when it compiled the renderer (numba's cache was empty; only
    #: measured with a progress bar); part of ``seconds``, which :meth:`steady_paths_per_second` leaves out
    compiled: tuple | None = None
    #: (integrator, shading) that rendered it, for a later render of the same
    #: scene and settings to reuse (``render(..., integrator=)``)
    integrator: tuple | None = field(default=None, repr=False, compare=False)
    #: the settings it was rendered with, as asked (None where the scene's value applied)
    settings: RenderSettings | None = None

    @property
    def paths_per_second(self) -> float:
        return self.stats.paths / max(self.seconds, 1e-9)

    @property
    def rays_per_second(self) -> float:
        return self.stats.rays / max(self.seconds, 1e-9)

    def steady_paths_per_second(self) -> float:
        """Paths per second without the batch that compiled the renderer (all of them when none did)."""
        if self.compiled is None:
            return self.paths_per_second
        return (self.stats.paths - self.compiled[1]) / max(self.seconds - self.compiled[0], 1e-9)


def _count(name: str, value, default: int | None = None, hi: int | None = None) -> int:
    """``value`` as an int in ``[1, hi]``; None means ``default`` (the scene's).

    Zero is refused rather than read as "the scene's": a size of 0 is a
    mistake, and only None (not given) means the default."""
    if value is None and default is not None:
        return default
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        also = " or None (the scene's)" if default is not None else ""
        raise TypeError(f"{name} must be an integer{also}, got {type(value).__name__} {value!r}")
    value = int(value)
    if value < 1 or (hi is not None and value > hi):
        rng = f"in [1, {hi}]" if hi is not None else ">= 1"
        raise ValueError(f"{name} must be {rng}, got {value}")
    return value


def resolve_max_bytes(max_bytes: int | str | None) -> int:
    """The memory limit in bytes: ``max_bytes`` (any form
    :func:`pyoa.samplers.parse_bytes` accepts: bytes, ``"4G"``, a fraction of RAM), else ``$PYOA_MAX_BYTES``, else half of the physical memory (the
    samplers' limit, :func:`pyoa.samplers.default_max_bytes`)."""
    return default_max_bytes() if max_bytes is None else parse_bytes(max_bytes)


def render_bytes(width: int, height: int, spp: int, dims: int, *, batch_paths: int = BATCH_PATHS,
                 threads: int | None = None) -> int:
    """Bytes :func:`render` needs at its peak: the image, the list of batches,
    each worker's batch of camera paths in flight (every sample of a pixel
    is in one batch, so a batch holds at least ``spp`` paths), and the
    float32 sampler values made ahead of the workers (:func:`_queue_bounds`)."""
    n_pixels = width * height
    per_batch, n_batches, workers = batch_layout(n_pixels, spp, batch_paths=batch_paths, threads=threads)
    in_flight = workers * per_batch * spp * (PATH_BYTES + 8 * dims)
    queued = values_ahead_bytes(n_batches, per_batch * spp, dims, workers)
    return n_pixels * PIXEL_BYTES + n_batches * BATCH_BYTES + in_flight + queued


def batch_layout(n_pixels: int, spp: int, *, batch_paths: int = BATCH_PATHS,
                 threads: int | None = None) -> tuple[int, int, int]:
    """``(pixels per batch, batches, workers)`` of a render of ``n_pixels``
    pixels at ``spp`` samples each: whole pixels per batch, at most
    ``batch_paths`` paths (at least one pixel), and one worker per thread
    (``threads`` None: every CPU), no more than there are batches."""
    per_batch = min(max(1, batch_paths // spp), n_pixels)
    n_batches = -(-n_pixels // per_batch)
    return per_batch, n_batches, max(1, min(threads or os.cpu_count() or 1, n_batches))


def values_ahead_bytes(n_batches: int, batch_paths: int, dims: int, workers: int) -> int:
    """Bytes of the float32 sampler values that :func:`render` holds beside
    its ``workers`` at most: ``_queue_bounds(workers)[1]`` batches of
    ``batch_paths`` rows (no more than the render's ``n_batches``)."""
    return min(n_batches, _queue_bounds(workers)[1]) * batch_paths * 4 * dims


def _queue_bounds(workers: int) -> tuple[int, int]:
    """``(tracing, samples)``: the most batches :func:`render` hands to its
    ``workers`` at once (running or waiting for one), and the most batches
    whose sampler values are alive at once. A batch's values are a view of
    its group's array, which lives until the last of its batches is traced.
    Batches finish in any order, so the unfinished ones may hold ``tracing``
    groups alive; with the group being handed out and the
    :func:`_groups_ahead` groups being sampled, that is ``tracing + 1 +
    ahead`` groups at most."""
    tracing = workers + 1
    return tracing, (tracing + 1 + _groups_ahead(workers)) * SAMPLE_GROUP


def _groups_ahead(workers: int) -> int:
    """Sampler calls in flight ahead of ``workers`` render workers (at least one: the values have to be made)."""
    return max(1, SAMPLE_AHEAD * workers)


#: Bytes per pixel that a command allocates besides the render, bounded: the
#: PNG's float64 sRGB conversion, the reference and the float64 copies of
#: relMSE (``pyoa render``, ``pyoa compare``), the float64 running sum, its
#: pass and the mean (``pyoa reference``).
POST_PIXEL_BYTES = 256


def check_memory(nbytes: int, what: str, limit: int, fix: str = "render fewer pixels or samples") -> None:
    """Refuse (ValueError) a job that needs more than ``limit`` bytes, before
    anything is allocated; ``fix`` says how to need less."""
    if nbytes > limit:
        raise ValueError(f"{what} needs {format_bytes(nbytes)}, over the memory limit of {format_bytes(limit)}; "
                         f"{fix}, or raise the limit with max_bytes= or ${ENV_MAX_BYTES}")


def scene_bytes(scene) -> int:
    """Bytes a loaded scene takes while it is traced (``SCENE_TRIANGLE_BYTES`` per triangle)."""
    return len(scene.triangles) * SCENE_TRIANGLE_BYTES


def image_size(scene, width: int | None = None, height: int | None = None,
               max_bytes: int | str | None = None) -> tuple[int, int]:
    """``(width, height)`` of a render of ``scene``: the given ones (integers
    >= 1) or the scene's film size, whose image fits in ``max_bytes`` (see
    :func:`resolve_max_bytes`) and has at most ``MAX_PIXELS`` pixels."""
    width = _count("width", width, scene.width)
    height = _count("height", height, scene.height)
    # the image alone first: a film of 1e9 x 1e9 is refused before the
    # sampler or the layout is even built
    check_memory(width * height * PIXEL_BYTES, f"a {width} x {height} image", resolve_max_bytes(max_bytes))
    if width * height > MAX_PIXELS:
        raise ValueError(f"image size {width} x {height} has {width * height} pixels; at most {MAX_PIXELS} "
                         "(pixel indices are uint32)")
    return width, height


@dataclass(frozen=True)
class Plan:
    """A validated render: everything :func:`render` checks before it allocates."""

    width: int
    height: int
    layout: Layout
    sampler: object  # pyoa.samplers.Sampler
    nbytes: int  # the render's peak with the scene's tracer (render_bytes + scene_bytes)
    max_bytes: int
    settings: RenderSettings  # as asked (None where the scene's value applies)
    shading: str  # the shading the render uses (resolve_shading of the settings')

    def worker_settings(self) -> RenderSettings:
        """The settings with the shading resolved here, for renders handed to
        other processes: every worker renders this process's shading, not
        its own ``$PYOA_SHADING`` (one image, whatever the workers' setup)."""
        return self.settings.replace(shading=self.shading)

    def identity(self, scene) -> dict:
        """What makes two renders of ``scene`` the same work: every input that changes a bit of the
        image (the renderer's version, the scene's digest, the film, the path length, the sampler with
        its count, base and seed, the filter, the layout of the dimensions, the shading), and nothing
        that does not (threads, backend, device, engine, batch size: each gives the same bits).

        The one definition that a progressive render's state, a reference's state and an image's
        header (:mod:`pyoa.render.provenance`) build on, so that they cannot disagree on what "the
        same render" means."""
        smp = self.sampler
        return dict(renderer=RENDERER_VERSION, scene=scene_digest(scene), width=self.width, height=self.height,
                    max_depth=self.layout.max_depth, sampler=smp.name, spp=smp.spp, base=smp.base, seed=smp.seed,
                    filter=self.settings.filter, first=list(self.layout.names), shading=self.shading)


def plan(scene, settings: RenderSettings | None = None, /, *, threads: int | None = None, **changes) -> Plan:
    """Check the settings of :func:`render` (a :class:`RenderSettings`, or
    its fields as keyword arguments, which replace those of ``settings``)
    and the memory the render needs on ``threads`` workers, without
    rendering: every error a render can raise on its arguments is raised
    here, before anything large is allocated."""
    s = RenderSettings.of(settings, **changes)
    shading = resolve_shading(s.shading)
    limit = resolve_max_bytes(s.max_bytes)
    width, height = image_size(scene, s.width, s.height, limit)
    depth = _count("max_depth", s.max_depth, scene.max_depth, MAX_DEPTH)
    check_filter(s.filter)
    batch_paths = _count("batch_paths", s.batch_paths)
    if threads is not None:
        threads = _count("threads", threads)
    cam = scene.camera
    layout = Layout(max_depth=depth, mis=scene.mis, lens=cam.aperture > 0,
                    time=bool(np.any(np.asarray(cam.motion) != 0)), first=s.first)
    # a sampler whose values depend on the image (zsobol) gets the film's
    # size; pixels are numbered row-major, y * width + x, as render() does
    image = {"resolution": (width, height)} if catalogue.get(s.sampler).needs_resolution else {}
    smp = make_sampler(s.sampler, spp=s.spp, dims=max(layout.dims, 1), seed=s.seed, backend=s.backend,
                       device=s.device, max_bytes=limit, base=s.base, **image)
    # the scene's tracer (Embree's BVH) counts too: it is built before the first sample
    traced = scene_bytes(scene)
    nbytes = traced + render_bytes(width, height, smp.spp, smp.dims, batch_paths=batch_paths, threads=threads)
    fix = (f"render a scene of fewer triangles (its {len(scene.triangles)} triangles take {format_bytes(traced)} "
           "to trace)" if 2 * traced > nbytes else "render fewer pixels or samples")
    check_memory(nbytes, f"a {width} x {height} render at {smp.spp} spp ({smp.dims} dims)", limit, fix)
    return Plan(width=width, height=height, layout=layout, sampler=smp, nbytes=nbytes, max_bytes=limit, settings=s,
                shading=shading)


def pixel_sums(radiance: np.ndarray, n: int) -> np.ndarray:
    """Per-pixel sums ``(P, 3)`` of the radiance ``(P n, 3)`` of ``P`` pixels' ``n`` consecutive samples each.

    Each channel's sum runs along the samples' axis (NumPy's pairwise summation over the ``n`` values, with
    their stride): the order of the additions depends only on ``n``, so a pixel's sum has the same bits in
    any batch. Summing the three channels' strided views directly is the same arithmetic as summing a
    transposed contiguous copy (``tests/render/test_integrator.py`` checks the bits), without the copy (1.5 against
    2.7 ns a path).
    """
    rows = radiance.reshape(-1, n, 3)
    s = np.empty((rows.shape[0], 3))
    for c in range(3):
        np.add.reduce(rows[:, :, c], axis=1, out=s[:, c])
    return s


def _sub_range(name: str, r, n: int, what: str) -> range:
    """``r`` checked as a non-empty ``range(a, c)`` with step 1 inside
    ``[0, n)`` (``what`` says what ``n`` counts); None means ``range(n)``.
    The samples and the pixels of a render are chosen this way."""
    if r is None:
        return range(n)
    if not isinstance(r, range) or r.step != 1 or not r:
        raise TypeError(f"{name} must be a non-empty range(a, c) with step 1, got {r!r}")
    if r.start < 0 or r.stop > n:
        raise ValueError(f"{name} {r} must lie in [0, {n}) ({what})")
    return r


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


def render(scene, settings: RenderSettings | None = None, /, *, threads: int | None = None,
           progress: bool = False, samples: range | None = None, sums: np.ndarray | None = None,
           integrator=None, pixels: range | None = None, **changes) -> RenderResult:
    """Render ``scene`` (a :class:`pyoa.render.scene.Scene`) with ``settings``.

    Parameters
    ----------
    settings : RenderSettings, optional
        What to render: the sampler, ``spp``, seed, film size, path length,
        filter, layout, base, backend, device, shading, batch size and memory limit
        (:class:`~pyoa.render.settings.RenderSettings`, whose docstring
        says what each means). Its fields may also be given as keyword
        arguments, which replace those of ``settings``:
        ``render(scene, sampler="bose", spp=121)``. Both shadings estimate
        the same image, and each gives the same bits for any batch size and
        thread count.
    threads : int, optional
        Worker threads (default: the number of CPUs).
    progress : bool or tqdm-like, optional
        True: show a tqdm progress bar of this render's pixels. An object
        with ``update(n)`` (an open tqdm bar): advance it by the samples per
        pixel each batch completes, as a fraction of the image
        (``samples x batch pixels / image pixels``), so that one bar can
        follow several renders of the same image in samples per pixel (a
        progressive render's blocks do).
    samples : range, optional
        Render only the samples ``samples`` (a contiguous ``range(a, c)``
        with step 1 inside ``[0, spp)``) of every pixel: the image is their
        mean. Default: all ``spp``. A progressive render
        (:mod:`pyoa.render.progressive`) renders its blocks this way.
    sums : numpy.ndarray, optional
        A float64 array of shape ``(height, width, 3)`` that receives the
        per-pixel *sums* of the samples' radiance (float64, exactly as the
        mean is formed); the image is still returned.
    integrator : optional
        ``RenderResult.integrator`` of an earlier render of the same scene
        with the same :meth:`~pyoa.render.settings.RenderSettings.integrator_key`
        (size, path length, layout, filter, shading), reused instead of
        built again (its setup, and the first call's compilation, are paid
        once: a progressive render's blocks share one).
    pixels : range, optional
        Render only these pixels (row-major indices ``y * width + x``, a
        non-empty ``range(a, c)`` with step 1): the result's ``image`` (and
        ``sums``) then has shape ``(len(pixels), 3)``, each pixel's value
        bit-identical to the full render's. A render on a cluster
        (:mod:`pyoa.render.tiles`) renders its tiles this way.

    Raises
    ------
    ValueError, TypeError
        Invalid arguments or a render over the memory limit, all checked by
        :func:`plan` before the first sample.
    """
    p = plan(scene, settings, threads=threads, **changes)
    width, height, layout, smp = p.width, p.height, p.layout, p.sampler
    explicit, shading, filter = p.settings.shading is not None, p.shading, p.settings.filter
    spp, seed = smp.spp, smp.seed
    samples = _sub_range("samples", samples, spp, "the sampler's spp")
    n = len(samples)
    tile = _sub_range("pixels", pixels, width * height, "the image's pixels, row-major")
    shape = (height, width, 3) if pixels is None else (len(tile), 3)
    if sums is not None and (not isinstance(sums, np.ndarray) or sums.dtype != np.float64
                             or sums.shape != shape or not sums.flags.c_contiguous):
        raise TypeError(f"sums must be a C-contiguous float64 array of shape {shape}")
    integ = None
    if integrator is not None:
        integ, shading = integrator
        if (getattr(integ, "width", width), getattr(integ, "height", height)) != (width, height):
            raise ValueError("integrator was built for another image size")
    elif shading == "numba":
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
    if integrator is None:
        integrator = (integ, shading)
    n_pixels = len(tile)
    per_batch = batch_layout(n_pixels, n, batch_paths=p.settings.batch_paths)[0]
    batches = [(p0, min(p0 + per_batch, tile.stop)) for p0 in range(tile.start, tile.stop, per_batch)]
    out = np.empty((n_pixels, 3), dtype=np.float32)
    flat_sums = None if sums is None else sums.reshape(n_pixels, 3)
    first = tile.start
    total = Stats()

    def sample(group):
        """The sampler values of consecutive batches, made in one call: a view for each batch."""
        p0, p1 = group[0][0], group[-1][1]
        x = smp.generate(pixels=range(p0, p1), samples=samples).reshape((p1 - p0) * n, smp.dims)
        return [x[(b0 - p0) * n:(b1 - p0) * n] for b0, b1 in group]

    # Every batch's paths in the same order (pixel-major, a pixel's samples consecutive): the pixels' offsets
    # in a batch and the samples' indices are made once for the largest batch (np.repeat and np.tile for each
    # batch took 4 ns a path, about 2 % of a 256 x 256 dof7d render)
    offsets = np.repeat(np.arange(per_batch), n)
    sample_indices = np.tile(np.arange(samples.start, samples.stop), per_batch)

    def trace(batch, holder):
        # the values come in a list emptied here, so that they die with this call: the pool's finished
        # work item, which keeps its arguments a moment longer, must not keep a group alive (_queue_bounds)
        x = holder.pop()
        p0, p1 = batch
        m = (p1 - p0) * n
        rad, st = integ.radiance(offsets[:m] + p0, sample_indices[:m], x, seed=seed)
        s = pixel_sums(rad, n)
        out[p0 - first:p1 - first] = (s / n).astype(np.float32)
        if flat_sums is not None:
            flat_sums[p0 - first:p1 - first] = s
        return st

    def run(batch):
        return trace(batch, sample([batch]))

    bar = None
    compiled = None
    t0 = time.perf_counter()
    outer = progress if hasattr(progress, "update") else None
    if progress:
        # The first batch runs before the bar starts: it pays the one-time costs (numba compiling the
        # renderer after an install, the sampler's OpenCL build, Embree's scene), which would otherwise
        # freeze the bar at its first step with an ETA of minutes. Said when it is the long one.
        compiling = getattr(integ, "needs_compiling", lambda: False)()
        if compiling:
            print(COMPILING, file=sys.stderr, flush=True)
        (p0, p1), batches = batches[0], batches[1:]
        total.add(run((p0, p1)))
        if compiling:
            compiled = (time.perf_counter() - t0, (p1 - p0) * n)
        if outer is not None:
            outer.update(n * (p1 - p0) / (width * height))
        else:
            from ..util.progress import bar as progress_bar

            what = f"{spp} spp" if n == spp else f"samples {samples.start}..{samples.stop - 1} of {spp}"
            bar = progress_bar(total=n_pixels, initial=p1 - p0, unit="px", desc=f"{scene.name} {smp.name} {what}")
    workers = max(1, min(threads or os.cpu_count() or 1, len(batches)))

    def done(batch, future):
        (p0, p1), st = batch, future.result()
        total.add(st)
        if bar is not None:
            bar.update(p1 - p0)
        if outer is not None:
            outer.update(n * (p1 - p0) / (width * height))

    # Sampling runs ahead of tracing, SAMPLE_GROUP batches per sampler call, on threads of its own; at most
    # _queue_bounds' batches of samples are alive at once (render_bytes counts them).
    groups = iter([batches[i:i + SAMPLE_GROUP] for i in range(0, len(batches), SAMPLE_GROUP)])
    most_tracing, ahead = _queue_bounds(workers)[0], _groups_ahead(workers)
    sampling_pool = ThreadPoolExecutor(workers, thread_name_prefix="pyoa-sample")
    pool = ThreadPoolExecutor(workers, thread_name_prefix="pyoa-trace")
    sampled, tracing = deque(), {}  # groups being sampled; the futures of batches handed out, and their batch

    def sample_ahead():
        while len(sampled) < ahead and (group := next(groups, None)) is not None:
            sampled.append((group, sampling_pool.submit(sample, group)))

    def retire():
        """Wait for the first of the batches handed out to finish (whichever it is: a slow batch must not keep
        the other workers idle), and count those that did."""
        finished, _ = wait(tracing, return_when=FIRST_COMPLETED)
        for future in finished:
            done(tracing.pop(future), future)

    try:
        sample_ahead()
        while sampled:
            group, future = sampled.popleft()
            views = future.result()
            sample_ahead()
            for batch in group:
                while len(tracing) >= most_tracing:
                    retire()
                tracing[pool.submit(trace, batch, [views.pop(0)])] = batch
        while tracing:
            retire()
    finally:
        # on an error or an interrupt: start nothing new in either pool first, then wait for what runs (it
        # writes into out), so that a second interrupt during the wait cannot leave a pool starting batches
        for executor in (sampling_pool, pool):
            executor.shutdown(wait=False, cancel_futures=True)
        for executor in (sampling_pool, pool):
            executor.shutdown(wait=True)
        if bar is not None:
            bar.close()
    seconds = time.perf_counter() - t0
    return RenderResult(image=out.reshape(shape), sampler=smp.name, spp=n, seed=seed,
                        dims=layout.dims, layout=layout.describe(), seconds=seconds, stats=total, shading=shading,
                        timings=dict(getattr(integ, "timings", {})), integrator=integrator, compiled=compiled,
                        settings=p.settings)


def check_job_memory(p, what: str) -> None:
    """The render's own need plus what the command allocates after it, against the same limit."""
    check_memory(p.nbytes + p.width * p.height * POST_PIXEL_BYTES, what, p.max_bytes)
