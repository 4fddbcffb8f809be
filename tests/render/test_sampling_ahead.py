"""How :func:`pyoa.render.render.render` feeds its workers: the sampler makes
the values of ``SAMPLE_GROUP`` consecutive batches in one call, on threads of
its own, ahead of the tracing (docs/performance.md, "Where sampling runs").

The promises tested: the grouping changes no bit; the sampler is called once
per group, with consecutive pixel ranges that cover the image once; sampling
does run ahead of tracing, and never holds more batches of values alive than
``_queue_bounds`` (which ``render_bytes`` charges); an error in either stage
ends the render with that error and leaves no thread behind.
"""

from __future__ import annotations

import dataclasses
import threading
import time
import weakref

import numpy as np
import pytest

from pyoa.render import render as render_mod
from pyoa.render.render import _queue_bounds, plan, render, render_bytes
from pyoa.render.scene import load

SPP = 4
KW = dict(sampler="bose", spp=SPP, seed=3, width=16, height=16, batch_paths=2 * SPP)  # 2 pixels a batch
BATCHES = 16 * 16 // 2


@pytest.fixture(scope="module")
def cornell():
    return load("cornell")


class Recorder:
    """Wraps the sampler that ``render`` builds: records each ``generate``
    call's pixels, how many generated arrays are alive when it returns, and
    can fail on a chosen call."""

    def __init__(self, monkeypatch, fail_at=None):
        self.pixels, self.alive_max, self.fail_at = [], 0, fail_at
        self._alive, self._lock = [], threading.Lock()
        real_plan = render_mod.plan

        recorder = self

        class Sampler:
            """The real sampler (samplers are immutable), its generate recorded."""

            def __init__(self, real):
                self.real = real

            def __getattr__(self, name):
                return getattr(self.real, name)

            def generate(self, pixels, samples):
                return recorder.generate(self.real, pixels, samples)

        def recording_plan(*args, **kw):
            p = real_plan(*args, **kw)
            return dataclasses.replace(p, sampler=Sampler(p.sampler))

        monkeypatch.setattr(render_mod, "plan", recording_plan)

    def generate(self, sampler, pixels, samples):
        with self._lock:
            self.pixels.append(pixels)
            if self.fail_at is not None and len(self.pixels) == self.fail_at:
                raise RuntimeError("sampler failed on purpose")
        x = sampler.generate(pixels=pixels, samples=samples)
        with self._lock:
            self._alive = [r for r in self._alive if r() is not None] + [weakref.ref(x)]
            self.alive_max = max(self.alive_max, len(self._alive))
        return x


def no_pipeline_threads():
    return not [t for t in threading.enumerate() if t.name.startswith(("pyoa-sample", "pyoa-trace"))]


def test_grouping_changes_no_bit_and_groups_the_calls(monkeypatch, cornell):
    ref = render(cornell, **KW, threads=1).image.tobytes()
    for group in (1, 3, 4, 7):
        for threads in (1, 2):
            monkeypatch.setattr(render_mod, "SAMPLE_GROUP", group)
            rec = Recorder(monkeypatch)
            img = render(cornell, **KW, threads=threads).image
            assert img.tobytes() == ref, f"SAMPLE_GROUP={group} threads={threads}"
            # one call per group of consecutive batches, covering every pixel once (two sampling threads
            # may record their calls in either order)
            calls = sorted(rec.pixels, key=lambda r: r.start)
            assert len(calls) == -(-BATCHES // group) and calls[0].start == 0 and calls[-1].stop == 256
            assert [r.stop for r in calls[:-1]] == [r.start for r in calls[1:]]
            assert all(len(r) == 2 * group for r in calls[:-1]), (group, calls)
            monkeypatch.undo()


def test_progress_renders_the_first_batch_alone_then_groups(monkeypatch, cornell):
    ref = render(cornell, **KW).image.tobytes()
    rec = Recorder(monkeypatch)
    bars = []

    class Bar:
        def update(self, n):
            bars.append(n)

    img = render(cornell, **KW, threads=2, progress=Bar()).image
    assert img.tobytes() == ref
    first, *rest = rec.pixels  # the first batch is sampled and traced alone, before the bar and the pools
    rest.sort(key=lambda r: r.start)
    assert first == range(0, 2) and rest[0].start == 2 and rest[-1].stop == 256
    assert all(len(r) == 2 * render_mod.SAMPLE_GROUP for r in rest[:-1])
    assert sum(bars) == pytest.approx(SPP)


class SlowIntegrator:
    """The render's own integrator, a little slower per batch, so that
    sampling can run ahead of it (or would pile up, were it unbounded)."""

    def __init__(self, integ, delay, fail_at=None):
        self.integ, self.delay, self.fail_at, self.calls = integ, delay, fail_at, 0
        self.width, self.height = integ.width, integ.height
        self._lock = threading.Lock()

    def radiance(self, *args, **kw):
        with self._lock:  # two workers call this at once
            self.calls += 1
            call = self.calls
        if call == self.fail_at:
            raise ValueError("tracing failed on purpose")
        time.sleep(self.delay)
        return self.integ.radiance(*args, **kw)


def compiled_integrator(cornell):
    from pyoa.render.compiled.integrator import CompiledIntegrator

    p = plan(cornell, **KW)
    return CompiledIntegrator(cornell, p.layout, 16, 16)


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_sampling_runs_ahead_within_the_bound_render_bytes_charges(monkeypatch, cornell, threads):
    ref = render(cornell, **KW).image.tobytes()
    rec = Recorder(monkeypatch)
    slow = SlowIntegrator(compiled_integrator(cornell), delay=0.004)
    img = render(cornell, **KW, threads=threads, integrator=(slow, "numba")).image
    assert img.tobytes() == ref
    group = render_mod.SAMPLE_GROUP
    samples = _queue_bounds(threads)[1]
    # ahead: more arrays of values alive than a worker sampling its own batch could hold (one per worker);
    # bounded: never more batches of them than render_bytes charges
    assert threads < rec.alive_max and rec.alive_max * group <= samples, (rec.alive_max, samples)
    # render_bytes charges those batches' float32 values beside the workers' paths
    p = plan(cornell, **KW)
    without = render_bytes(16, 16, SPP, p.sampler.dims, batch_paths=KW["batch_paths"], threads=threads) \
        - min(BATCHES, samples) * 2 * SPP * 4 * p.sampler.dims
    monkeypatch.setattr(render_mod, "_queue_bounds", lambda workers: (2 * workers, 0))
    assert render_bytes(16, 16, SPP, p.sampler.dims, batch_paths=KW["batch_paths"], threads=threads) == without


def test_an_error_in_sampling_ends_the_render_with_it(monkeypatch, cornell):
    Recorder(monkeypatch, fail_at=5)
    with pytest.raises(RuntimeError, match="sampler failed on purpose"):
        render(cornell, **KW, threads=2)
    assert no_pipeline_threads()


def test_an_error_in_tracing_ends_the_render_with_it(cornell):
    slow = SlowIntegrator(compiled_integrator(cornell), delay=0.0, fail_at=7)
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match="tracing failed on purpose"):
        render(cornell, **KW, threads=2, integrator=(slow, "numba"))
    assert no_pipeline_threads()
    # the batches not yet started were dropped: far fewer than all of them were traced
    assert slow.calls < BATCHES // 2 and time.perf_counter() - t0 < 60
    assert np.isfinite(render(cornell, **KW, threads=2).image).all()


def test_nothing_ahead_still_samples_every_batch(monkeypatch, cornell):
    """SAMPLE_AHEAD = 0 (no call ahead per worker) still makes one call at a time, not an empty image."""
    ref = render(cornell, **KW).image.tobytes()
    monkeypatch.setattr(render_mod, "SAMPLE_AHEAD", 0)
    rec = Recorder(monkeypatch)
    assert render(cornell, **KW, threads=2).image.tobytes() == ref
    assert len(rec.pixels) == -(-BATCHES // render_mod.SAMPLE_GROUP)


def test_a_slow_batch_does_not_hold_up_the_others(cornell):
    """Batches are counted as they finish, not oldest first: while the first batch waits, the other worker
    traces far more batches than the render hands out at once (_queue_bounds' first number). Counted
    oldest-first, the render would stop handing out batches behind the first one, and it would time out."""
    integ = compiled_integrator(cornell)
    others_done, lock = threading.Event(), threading.Lock()
    need = _queue_bounds(2)[0] + 3
    count = {"calls": 0, "others": 0}

    class FirstWaits:
        width, height = integ.width, integ.height

        def radiance(self, *args, **kw):
            with lock:
                count["calls"] += 1
                first = count["calls"] == 1
            if first:
                if not others_done.wait(60):
                    raise TimeoutError("the other batches were not handed out while the first one ran")
                return integ.radiance(*args, **kw)
            res = integ.radiance(*args, **kw)
            with lock:
                count["others"] += 1
                if count["others"] >= need:
                    others_done.set()
            return res

    img = render(cornell, **KW, threads=2, integrator=(FirstWaits(), "numba")).image
    assert img.tobytes() == render(cornell, **KW).image.tobytes()
