"""Progressive rendering: an image after every doubling of the sample count,
a time budget, and resuming a stopped render to more samples.

A progressive render traces samples ``[0, 1)``, ``[1, 2)``, ``[2, 4)``,
``[4, 8)``, ... ``[2**k, spp)`` of every pixel in turn (one *block* per
doubling, the last one cut at ``spp``) and, after each block, writes the
mean of all samples so far to the output image (atomically) and the running
sum to ``OUT.state.npz``. So

- stopping at any moment (Ctrl-C, a killed job) leaves the image of the last
  complete block;
- ``time_budget`` stops after the last block that fits: before a block, its
  time is predicted from the previous block's (time per sample) and the
  block is skipped, and the render ends, if it would overrun the budget;
- ``resume=True`` continues from the state: the samples already taken are
  not traced again, and ``spp`` may be larger than the stopped render's,
  for a sampler whose ``i``-th sample does not depend on ``spp``
  (``spp_invariant``: ``faure`` with its base, ``sobol``, ``halton``,
  ``pmj02``, ``random``).

Doublings rather than powers of ``b`` (``faure``) or of 2 only: they suit
every progressive sampler, give ``log2(spp)`` images, and a block is never
more than the samples before it, so a time budget wastes at most half of
itself.

Only samplers whose every prefix keeps its stratification are accepted
(``Construction.progressive``): the sequences (``faure``, ``sobol``,
``halton``, ``sobol02``, ``pmj02``, ``zsobol``) and ``random``. An
orthogonal array (``bose``...) or a jittered grid is stratified only as a
whole: its first ``n`` samples are not a smaller array, so its intermediate
images would be worse than random ones, and it is refused.
"""

from __future__ import annotations

import contextlib
import math
import signal
import sys
import threading
import time
from dataclasses import dataclass, field

import numpy as np

from .. import catalogue
from .image import check_finite, write_exr, write_png
from .integrator import Stats
from .provenance import describe, printable
from .render import plan, render
from .settings import RenderSettings
from .state import (
    BadState,
    check_state_file,
    describe_size,
    read_state,
    saved_key,
    state_path,
    write_state,
)

#: Version of the progressive state's layout and key.
STATE_VERSION = 1
#: Settings of the key, and how the user sets them (for the refusal to resume).
_KEY_FIELDS = {"version": "another pyoa version",
               "renderer": "another version of pyoa's renderer (its images differ)",
               "scene": "another scene file (or scene contents)",
               "width": "--size", "height": "--size", "max_depth": "--max-depth", "sampler": "--sampler",
               "base": "--base", "seed": "--seed", "filter": "--filter", "first": "--first",
               "shading": "--shading", "spp": "--spp"}


def block_ends(done: int, spp: int) -> list[int]:
    """The sample counts after ``done`` at which the image is written: every
    power of two above ``done`` and below ``spp``, then ``spp``.

    >>> block_ends(0, 100)
    [1, 2, 4, 8, 16, 32, 64, 100]
    >>> block_ends(64, 256)
    [128, 256]
    """
    ends = []
    k = 1
    while k < spp:
        if k > done:
            ends.append(k)
        k *= 2
    return ends + ([spp] if spp > done else [])


def check_progressive(name: str) -> None:
    """Refuse (ValueError) a sampler whose prefixes are not stratified, saying why."""
    entry = catalogue.get(name)
    if entry.progressive:
        return
    ok = ", ".join(n for n, c in catalogue.SAMPLERS.items() if c.progressive)
    raise ValueError(f"{entry.name} cannot render progressively: {entry.why_not_progressive}; progressive "
                     f"samplers: {ok}")


def _describe_change(saved: dict, key: dict) -> str:
    for fld, option in _KEY_FIELDS.items():
        if saved.get(fld) != key.get(fld):
            if fld in ("scene", "first", "version", "renderer"):
                return f"it was made with {option}"
            if fld in ("width", "height"):
                return describe_size(saved, key)
            if fld == "spp":
                return (f"it was made with --spp {saved.get('spp')}, and {key['sampler']}'s samples depend on "
                        f"--spp (continue it at --spp {saved.get('spp')})")
            return f"it was made with {option} {saved.get(fld)}, not {key.get(fld)}"
    return "it was made with other settings"  # pragma: no cover - keys differ in a field not listed


@contextlib.contextmanager
def _held_interrupt():
    """Hold a SIGINT (Ctrl-C) that arrives in the block until it ends, then
    raise KeyboardInterrupt: the files written in it then hold the same
    doubling (each file is written atomically, but an interrupt between two
    would leave the image one doubling ahead of the state). Only in the main
    thread with Python's default handler: elsewhere a handler cannot be set,
    or another one is in charge."""
    if threading.current_thread() is not threading.main_thread() or \
            signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        yield
        return
    held = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: held.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if held:
        raise KeyboardInterrupt


@dataclass
class ProgressiveResult:
    """What a progressive render did: the image of ``samples`` samples per
    pixel (written to ``out``), of the ``spp`` asked for."""

    image: np.ndarray
    samples: int
    spp: int
    sampler: str
    base: int | None
    #: samples per pixel already in the state when the run started
    resumed_from: int
    #: sample counts at which this run wrote an image
    written: list = field(default_factory=list)
    seconds: float = 0.0
    #: whether the time budget ended the render before ``spp``
    stopped_by_time: bool = False
    stats: Stats = field(default_factory=Stats)


class _Bar:
    """The progress bar of a progressive render (:func:`pyoa.util.progress.bar`): one bar for the whole render,
    in whole samples per pixel. A batch of pixels adds a fraction of a sample, so the bar moves inside a
    block too (the last block holds half the samples), and shows the samples every pixel has. With a
    time budget, its time left is the budget's when that ends first (the render stops at the last
    doubling predicted to fit in it), not the time to ``spp``."""

    def __init__(self, name: str, smp, done: int, time_budget: float | None, t_start: float):
        from ..util.progress import bar

        self.exact, self.start, self.budget, self.t_start = float(done), done, time_budget, t_start
        self.bar = bar(total=smp.spp, initial=done, unit="spp", desc=f"{name} {smp.name}",
                       bar_format=self._format(smp.spp))

    def _format(self, total: int) -> str:
        head = "{desc}: {percentage:3.0f}%|{bar}| {n}/{total} spp "
        if self.budget is None:
            return head + "[{elapsed}<{remaining}]"
        from tqdm.std import tqdm

        elapsed = time.perf_counter() - self.t_start
        left = max(0.0, self.budget - elapsed)
        if self.exact > self.start:  # the time to spp at this run's rate, when that is sooner
            left = min(left, (total - self.exact) * elapsed / (self.exact - self.start))
        return head + f"[{{elapsed}}<{tqdm.format_interval(left)}, --time {self.budget:g} s]"

    def update(self, n: float) -> None:
        """Advance by ``n`` samples per pixel (a fraction: a batch of the image's pixels)."""
        self.exact += n
        whole = min(int(self.exact + 1e-9), self.bar.total)
        if whole > self.bar.n:
            self.bar.bar_format = self._format(self.bar.total)
            self.bar.update(whole - self.bar.n)

    def reached(self, done: int) -> None:
        """Every pixel has ``done`` samples (a block is complete)."""
        self.exact = float(done)
        self.bar.bar_format = self._format(self.bar.total)
        self.bar.n = done  # whole again: the batches' fractions add up to the block but for rounding
        self.bar.refresh()

    def write(self, line: str) -> None:
        self.bar.write(line)

    def close(self) -> None:
        self.bar.close()


#: The settings of a progressive render that are not given: ``faure`` to 1,024 samples per pixel.
DEFAULTS = RenderSettings(sampler="faure", spp=1024)


def render_progressive(scene, settings: RenderSettings | None = None, /, *, out, png=None,
                       time_budget: float | None = None, resume: bool = False, quiet: bool = True,
                       command: str | None = None, **changes) -> ProgressiveResult:
    """Render ``scene`` progressively to the EXR ``out`` (module docstring).

    Parameters
    ----------
    settings : RenderSettings, optional
        As for :func:`pyoa.render.render` (default :data:`DEFAULTS`), or
        its fields as keyword arguments, which replace those of
        ``settings``; the sampler must be progressive
        (:func:`check_progressive`). ``spp`` is the most samples rendered.
        Its ``batch_paths`` is not used: each block is one render.
    out : path
        EXR written after every block (atomically); the running sum is kept
        in ``OUT.state.npz`` (:func:`state_path`), which stays after the
        render so that it can be continued to more samples.
    png : path, optional
        Also write an sRGB PNG after every block.
    time_budget : float, optional
        Seconds: stop after the last block that is predicted to end within
        it (the first block, one sample, is always rendered).
    resume : bool
        Continue from ``OUT.state.npz``. A state of other settings is
        refused (ValueError saying which); without a state the render
        starts from the first sample. Without ``resume`` an existing state
        is replaced once the first block is done. A state path that is not a
        regular file (a device, a FIFO, a directory, or a symlink to one) is
        refused either way (:func:`.state.check_state_file`).
    quiet : bool
        No progress output.
    command : str, optional
        The command line that asked for it, written into the EXR's header
        with the render's settings (:mod:`pyoa.render.provenance`).

    Raises
    ------
    ValueError, TypeError
        A sampler that is not progressive, a state that cannot be resumed,
        one that holds more samples than ``spp``, a bad budget, or anything
        :func:`pyoa.render.plan` refuses; all before the first sample.
    """
    t_start = time.perf_counter()
    settings = RenderSettings.of(settings or DEFAULTS, **changes)
    sampler, base = settings.sampler, settings.base
    check_progressive(sampler)
    if time_budget is not None:
        if isinstance(time_budget, bool) or not isinstance(time_budget, (int, float)):
            raise TypeError(f"time_budget must be a number of seconds, got {type(time_budget).__name__}")
        if not (math.isfinite(time_budget) and time_budget > 0):
            raise ValueError(f"time_budget must be a positive number of seconds, got {time_budget}")
    state = state_path(out)
    check_state_file(state, "where a progressive render keeps its running sum")
    entry = catalogue.get(sampler)
    saved = saved_key(state) if resume and state.exists() else None
    if base is None and saved and saved.get("sampler") == entry.name and saved.get("base") is not None:
        base = saved["base"]  # the default base depends on spp: keep the stopped render's
    p = plan(scene, settings, base=base)
    smp = p.sampler
    # every block renders the whole film with the planned sampler (its base chosen once)
    settings = p.settings.replace(width=p.width, height=p.height, spp=smp.spp, base=smp.base)
    # the render's identity; a sampler whose values do not depend on spp continues at any count
    key = dict(version=STATE_VERSION, **p.identity(scene))
    if entry.spp_invariant:
        key["spp"] = None
    meta = describe(scene, p, kind="progressive render", command=command)
    total, done = None, 0
    if resume and state.exists():
        try:
            # the count is checked against spp below, with a clearer message
            total, done = read_state(state, key, "samples", 1 << 24, _describe_change)
        except BadState as why:
            raise ValueError(f"cannot resume {state}: {why}; run without --resume to start over") from None
        if done > smp.spp:
            raise ValueError(f"cannot resume {state} at --spp {smp.spp}: it already holds {done} samples per "
                             f"pixel; give --spp {done} or more")
    elif resume and not quiet:
        print(f"pyoa render: no {state} to resume; starting from the first sample", file=sys.stderr)
    elif state.exists() and not quiet:
        print(f"pyoa render: {state} exists; it is replaced (use --resume to continue it)", file=sys.stderr)
    if total is None:
        total = np.zeros((p.height, p.width, 3), np.float64)
    result = ProgressiveResult(image=(total / max(done, 1)).astype(np.float32), samples=done, spp=smp.spp,
                               sampler=smp.name, base=smp.base, resumed_from=done)
    if not quiet and done:
        print(f"resuming {state}: {done} of {smp.spp} samples per pixel done")
    integrator = None
    block = np.empty_like(total)
    last_rate = None  # seconds per sample of the previous block
    bar = None if quiet else _Bar(printable(scene.name), smp, done, time_budget, t_start)
    try:
        for end in block_ends(done, smp.spp):
            n = end - done
            elapsed = time.perf_counter() - t_start
            if time_budget is not None and last_rate is not None and elapsed + last_rate * n > time_budget:
                result.stopped_by_time = True
                if bar is not None:
                    bar.write(f"the next doubling, to {end} samples per pixel, would end past --time "
                              f"{time_budget:g} s (about {elapsed + last_rate * n:.0f} s): stopped")
                break
            t0 = time.perf_counter()
            res = render(scene, settings, samples=range(done, end), sums=block, integrator=integrator,
                         progress=bar if bar is not None else False)
            integrator = res.integrator
            last_rate = (time.perf_counter() - t0) / n
            check_finite(res.image, f"--out {str(out)!r} not updated past {done} samples")
            total += block
            done = end
            image = (total / done).astype(np.float32)
            with _held_interrupt():  # Ctrl-C waits until the image, the PNG and the state hold this doubling
                write_exr(out, image, dict(meta, samples=done))
                if png:
                    write_png(png, image)
                write_state(state, total, "samples", done, key)
            result.stats.add(res.stats)
            result.written.append(done)
            result.image, result.samples = image, done
            if bar is not None:
                bar.reached(done)
                bar.write(f"{done} of {smp.spp} samples per pixel -> {out} ({time.perf_counter() - t_start:.1f} s)")
    finally:
        if bar is not None:
            bar.close()
    result.seconds = time.perf_counter() - t_start
    if not result.written and done:  # resumed a finished render: write its image again
        write_exr(out, result.image, dict(meta, samples=done))
        if png:
            write_png(png, result.image)
    return result
