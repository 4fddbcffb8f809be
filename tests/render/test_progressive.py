"""Progressive rendering (:mod:`pyoa.render.progressive`, ``pyoa render --progressive``):
an image after every doubling, a time budget, and resuming to more samples."""

from __future__ import annotations

import os

import numpy as np
import pytest

from pyoa import catalogue
from pyoa.commands import main
from pyoa.render import progressive
from pyoa.render.image import read_image
from pyoa.render.progressive import block_ends, render_progressive, state_path
from pyoa.render.render import render
from pyoa.render.scene import load
from pyoa.samplers import Sampler

SIZE = dict(width=12, height=10)


@pytest.fixture(scope="module")
def cornell():
    return load("cornell")


def bits(a):
    return np.ascontiguousarray(a, np.float32).view(np.uint32)


def test_block_ends_double_and_end_at_spp():
    assert block_ends(0, 1) == [1]
    assert block_ends(0, 100) == [1, 2, 4, 8, 16, 32, 64, 100]
    assert block_ends(0, 64) == [1, 2, 4, 8, 16, 32, 64]
    assert block_ends(8, 20) == [16, 20]
    assert block_ends(20, 20) == []
    assert block_ends(5, 6) == [6]


def test_images_after_every_doubling_and_the_mean_of_all(cornell, tmp_path):
    out = tmp_path / "p.exr"
    res = render_progressive(cornell, out=out, sampler="faure", spp=20, base=5, **SIZE)
    assert res.written == [1, 2, 4, 8, 16, 20] and res.samples == 20 and not res.stopped_by_time
    assert res.base == 5 and res.resumed_from == 0
    img = read_image(out)
    np.testing.assert_array_equal(bits(img), bits(res.image))
    # the same estimate as one render of all 20 samples (sums grouped by block:
    # float64 rounding differs, a float32 ulp at most)
    whole = render(cornell, sampler="faure", spp=20, base=5, **SIZE).image
    np.testing.assert_allclose(img, whole, rtol=2e-7, atol=1e-12)
    assert sorted(os.listdir(tmp_path)) == ["p.exr", "p.exr.state.npz"]  # no temporary files left


def test_a_block_is_the_samples_it_names(cornell):
    """render(samples=range(a, c)) is the mean of exactly those samples: its
    sums plus the other blocks' give the whole render's sums."""
    full, a, b = (np.empty((10, 12, 3)) for _ in range(3))
    render(cornell, sampler="sobol", spp=16, sums=full, **SIZE)
    render(cornell, sampler="sobol", spp=16, samples=range(0, 5), sums=a, **SIZE)
    img = render(cornell, sampler="sobol", spp=16, samples=range(5, 16), sums=b, **SIZE).image
    np.testing.assert_allclose(a + b, full, rtol=1e-12)
    np.testing.assert_array_equal(img, (b / 11).astype(np.float32))
    for bad, err in ((range(0, 17), ValueError), (range(3, 3), TypeError), (range(0, 8, 2), TypeError),
                     ([0, 1], TypeError)):
        with pytest.raises(err, match="samples"):
            render(cornell, sampler="sobol", spp=16, samples=bad, **SIZE)


def _traced(monkeypatch) -> list:
    """Record the sample ranges every Sampler.generate call of a render asks for."""
    seen = []
    real = Sampler.generate

    def spy(self, pixels=None, samples=None, dims=None, **kw):
        seen.append(samples)
        return real(self, pixels=pixels, samples=samples, dims=dims, **kw)

    monkeypatch.setattr(Sampler, "generate", spy)
    return seen


def test_resume_to_more_samples_traces_only_new_ones_and_equals_an_uninterrupted_run(cornell, tmp_path,
                                                                                      monkeypatch):
    a, b = tmp_path / "a.exr", tmp_path / "b.exr"
    whole = render_progressive(cornell, out=a, sampler="faure", spp=40, base=3, **SIZE)
    first = render_progressive(cornell, out=b, sampler="faure", spp=8, base=3, **SIZE)
    assert first.samples == 8
    seen = _traced(monkeypatch)
    more = render_progressive(cornell, out=b, sampler="faure", spp=40, base=3, resume=True, **SIZE)
    assert more.resumed_from == 8 and more.written == [16, 32, 40]
    assert seen and min(r.start for r in seen) == 8  # no sample below 8 traced again
    np.testing.assert_array_equal(bits(read_image(b)), bits(read_image(a)))
    np.testing.assert_array_equal(bits(more.image), bits(whole.image))


def test_resume_keeps_the_default_base_of_the_state(cornell, tmp_path):
    out = tmp_path / "f.exr"
    first = render_progressive(cornell, out=out, sampler="faure", spp=4, **SIZE)
    assert first.base == 2  # fewer than 4 samples... 4: the largest prime b with b^2 <= 4
    more = render_progressive(cornell, out=out, sampler="faure", spp=50, resume=True, **SIZE)
    assert more.base == 2  # not 7, the default at 50 samples: the first 4 samples stay valid
    same = render_progressive(cornell, out=tmp_path / "g.exr", sampler="faure", spp=50, base=2, **SIZE)
    np.testing.assert_array_equal(bits(more.image), bits(same.image))


def test_an_interrupted_render_leaves_its_last_block_and_resumes(cornell, tmp_path, monkeypatch):
    out = tmp_path / "i.exr"
    calls = []
    real = progressive.render

    def failing(*args, **kw):
        calls.append(kw["samples"])
        if len(calls) == 4:  # the block 8..15
            raise KeyboardInterrupt
        return real(*args, **kw)

    monkeypatch.setattr(progressive, "render", failing)
    with pytest.raises(KeyboardInterrupt):
        render_progressive(cornell, out=out, sampler="halton", spp=16, **SIZE)
    monkeypatch.setattr(progressive, "render", real)
    four = render_progressive(cornell, out=tmp_path / "four.exr", sampler="halton", spp=4, **SIZE)
    np.testing.assert_array_equal(bits(read_image(out)), bits(four.image))  # the image of 4 samples
    assert sorted(os.listdir(tmp_path)) == ["four.exr", "four.exr.state.npz", "i.exr", "i.exr.state.npz"]
    done = render_progressive(cornell, out=out, sampler="halton", spp=16, resume=True, **SIZE)
    assert done.resumed_from == 4 and done.written == [8, 16]
    whole = render_progressive(cornell, out=tmp_path / "w.exr", sampler="halton", spp=16, **SIZE)
    np.testing.assert_array_equal(bits(done.image), bits(whole.image))


def test_time_budget_stops_after_the_last_block_that_fits(cornell, tmp_path, monkeypatch):
    """A clock that advances 1 s per traced sample: with 10 s, blocks 1, 1, 2
    and 4 fit (t = 8); the next block of 8 would end at t = 16."""
    now = [0.0]
    real = progressive.render

    def timed(*args, **kw):
        now[0] += len(kw["samples"])
        return real(*args, **kw)

    monkeypatch.setattr(progressive, "render", timed)
    monkeypatch.setattr(progressive.time, "perf_counter", lambda: now[0])
    out = tmp_path / "t.exr"
    res = render_progressive(cornell, out=out, sampler="faure", spp=1024, time_budget=10, **SIZE)
    assert res.written == [1, 2, 4, 8] and res.samples == 8 and res.stopped_by_time
    base = res.base
    # the first block is always rendered, even over the budget
    now[0] = 0.0
    res = render_progressive(cornell, out=tmp_path / "u.exr", sampler="faure", spp=1024, time_budget=0.5, **SIZE)
    assert res.written == [1] and res.stopped_by_time
    # and the render continues from where the budget stopped it
    res = render_progressive(cornell, out=out, sampler="faure", spp=16, resume=True, **SIZE)
    assert res.resumed_from == 8 and res.samples == 16 and res.base == base  # the state's (chosen for 1024)


def test_refusals(cornell, tmp_path):
    out = tmp_path / "r.exr"
    for name in catalogue.SAMPLERS:
        if not catalogue.get(name).progressive:
            with pytest.raises(ValueError, match=f"{name} cannot render progressively"):
                render_progressive(cornell, out=out, sampler=name, spp=16, **SIZE)
    with pytest.raises(ValueError, match="time_budget must be a positive"):
        render_progressive(cornell, out=out, sampler="sobol", spp=16, time_budget=0, **SIZE)
    with pytest.raises(TypeError, match="time_budget"):
        render_progressive(cornell, out=out, sampler="sobol", spp=16, time_budget="10", **SIZE)
    render_progressive(cornell, out=out, sampler="sobol", spp=16, seed=1, **SIZE)
    with pytest.raises(ValueError, match="made with --seed 1, not 2"):
        render_progressive(cornell, out=out, sampler="sobol", spp=32, seed=2, resume=True, **SIZE)
    with pytest.raises(ValueError, match="already holds 16 samples"):
        render_progressive(cornell, out=out, sampler="sobol", spp=8, seed=1, resume=True, **SIZE)
    with pytest.raises(ValueError, match="made with --sampler sobol, not halton"):
        render_progressive(cornell, out=out, sampler="halton", spp=32, seed=1, resume=True, **SIZE)
    # a sampler whose samples depend on spp resumes at its own spp only
    render_progressive(cornell, out=out, sampler="sobol02", spp=8, **SIZE)
    with pytest.raises(ValueError, match="sobol02's samples depend on --spp"):
        render_progressive(cornell, out=out, sampler="sobol02", spp=16, resume=True, **SIZE)
    state_path(out).write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="cannot resume .*unreadable"):
        render_progressive(cornell, out=out, sampler="sobol02", spp=8, resume=True, **SIZE)
    # without --resume a bad state is simply replaced
    res = render_progressive(cornell, out=out, sampler="sobol02", spp=8, **SIZE)
    assert res.samples == 8


def test_cli_progressive_time_and_resume(tmp_path, capsys):
    out = tmp_path / "c.exr"
    argv = ["render", "cornell", "--sampler", "faure", "--size", "12", "10", "--out", str(out)]
    assert main([*argv, "--progressive", "--time", "10", "--spp", "8"]) == 0
    text = capsys.readouterr().out
    assert "8 of 8 spp" in text and "base 2" in text and out.exists() and state_path(out).exists()
    assert main([*argv, "--progressive", "--resume", "--spp", "32", "--png", str(tmp_path / "c.png")]) == 0
    text = capsys.readouterr().out
    assert "resuming" in text and "32 of 32 spp" in text and "this run 24 samples" in text
    assert (tmp_path / "c.png").exists()
    for extra, msg in ((["--time", "5"], "--time needs --progressive"),
                       (["--resume"], "--resume needs --progressive"),
                       (["--progressive", "--time", "-1"], "--time must be a positive"),
                       (["--progressive", "--sampler", "bose"], "bose cannot render progressively"),
                       (["--base", "4"], "base must be a prime")):
        with pytest.raises(SystemExit):
            main([*argv, *extra])
        assert msg in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["render", "cornell", "--sampler", "sobol", "--base", "5", "--out", str(out)])
    assert "sobol takes no base" in capsys.readouterr().err


def test_progress_moves_inside_a_block_in_samples_per_pixel(cornell, tmp_path, capsys):
    """The progressive bar counts samples per pixel and advances with every batch of a block, not only
    when a block ends (the last block holds half the samples: it used to run minutes in silence)."""

    class Bar:
        def __init__(self):
            self.steps = []

        def update(self, n):
            self.steps.append(n)

    bar = Bar()
    ref = render(cornell, sampler="faure", spp=8, width=12, height=10, samples=range(4, 8), batch_paths=40)
    res = render(cornell, sampler="faure", spp=8, width=12, height=10, samples=range(4, 8), batch_paths=40,
                 progress=bar)
    np.testing.assert_array_equal(res.image, ref.image)  # the same bits with a bar
    assert len(bar.steps) == 12  # 40 paths = 10 pixels of 4 samples: 12 batches of the 120 pixels
    assert sum(bar.steps) == pytest.approx(4)  # the block's 4 samples per pixel
    render_progressive(cornell, out=tmp_path / "p.exr", sampler="faure", spp=8, width=12, height=10,
                       quiet=False, time_budget=1e6)
    err = capsys.readouterr().err
    assert "8/8 spp" in err and "--time 1e+06 s]" in err  # whole samples; the time left against --time
