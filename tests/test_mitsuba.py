"""pyoa inside Mitsuba 3 (:mod:`pyoa.mitsuba`): the mapping, refusals and renders.

- Drawn from a seeded Mitsuba sampler on P x N lanes, the k-th 1D value
  (``next_2d`` draws two) is exactly ``pyoa.sampler(...).generate(pixels=
  range(P))[pixel, i, k]``: in a plain sequence of calls, inside a symbolic
  ``dr.while_loop`` (as Mitsuba's integrators draw), and over several passes.
- Invalid parameters fail at scene load with pyoa's own message.
- Renders of Mitsuba's Cornell box: unbiased against a high-spp render of
  Mitsuba's ``independent`` sampler, lower error than ``independent`` at the
  same count, and the same image with symbolic loops on and off.
"""

from __future__ import annotations

import numpy as np
import pytest

import pyoa

from .mitsuba_support import need

pm = need("pyoa.mitsuba")
import drjit as dr
import mitsuba as mi

VARIANT = "llvm_ad_rgb"

#: (name, spp, options): every sampler the plugin supports, at a small count
PLUGIN_CASES = [
    ("bose", 49, {}),
    ("bose", 16, {"offset": "centered", "jitter": 0.5}),  # GF(4): tabled field
    ("bush", 27, {"strength": 3}),
    ("cmjnd", 64, {"strength": 3, "offset": "j"}),
    ("addelman-kempthorne", 18, {"offset": "mj"}),
    ("bose-bush", 32, {}),
    ("faure", 30, {}),
    ("faure", 27, {"base": 3}),
    ("random", 10, {}),
]


@pytest.fixture(scope="module", autouse=True)
def variant():
    old = mi.variant()
    mi.set_variant(VARIANT)
    yield
    if old is not None and old != VARIANT:
        mi.set_variant(old)


def load(name, spp, **opts):
    return mi.load_dict({"type": "pyoa", "sampler": name, "sample_count": spp, **opts})


def expected(name, spp, opts, pixels, dims, seed):
    kw = {k: v for k, v in opts.items() if k not in ("seed",)}
    return pyoa.sampler(name, spp=spp, dims=dims, seed=seed, backend="numpy", **kw).generate(pixels=range(pixels))


def draws(smp, dims):
    """``dims`` values per lane: next_1d and next_2d alternately, as an integrator mixes them."""
    out = []
    while len(out) < dims:
        if len(out) % 3 == 0 and len(out) + 2 <= dims:
            p = smp.next_2d()
            out += [p.x, p.y]
        else:
            out.append(smp.next_1d())
    return np.stack([np.asarray(v) for v in out], -1)


@pytest.mark.parametrize("name,spp,opts", PLUGIN_CASES, ids=[f"{c[0]}-{c[1]}" for c in PLUGIN_CASES])
def test_lane_l_is_pixel_l_div_n_sample_l_mod_n(name, spp, opts):
    P, D, seed = 6, 40, 1234
    smp = load(name, spp, **opts)
    smp.set_samples_per_wavefront(spp)
    smp.seed(seed, P * spp)
    got = draws(smp, D).reshape(P, spp, D)
    want = expected(name, spp, opts, P, D, seed)
    assert (got.view(np.uint32) == want.view(np.uint32)).all()


@pytest.mark.parametrize("name,spp,opts", [PLUGIN_CASES[0], PLUGIN_CASES[6]], ids=["bose", "faure"])
def test_the_same_values_drawn_inside_a_symbolic_loop(name, spp, opts):
    """The dimension counter is loop state: each iteration draws the next dimension."""
    P, D = 5, 23
    smp = load(name, spp, **opts)
    smp.set_samples_per_wavefront(spp)
    smp.seed(9, P * spp)
    want = expected(name, spp, opts, P, D, 9).reshape(P * spp, D)
    weights = np.arange(1, D + 1, dtype=np.float32)

    def body(k, acc, s):  # acc = sum_k (k + 1) * x_k: any value drawn in the wrong dimension changes it
        return k + 1, acc + mi.Float(k + 1) * s.next_1d(), s

    _, acc, _ = dr.while_loop(state=(mi.UInt32(0), dr.zeros(mi.Float, P * spp), smp),
                              cond=lambda k, acc, s: k < D, body=body)
    ref = np.zeros(P * spp, np.float32)
    for k in range(D):
        ref = ref + weights[k] * want[:, k]
    assert (np.asarray(acc) == ref).all()


def test_passes_continue_the_sample_index():
    """Mitsuba splits a render into passes of n samples: pass k, lane l is sample k n + l % n."""
    name, spp, P, D = "bush", 27, 4, 9
    smp = load(name, spp, strength=3)
    smp.set_samples_per_wavefront(9)
    smp.seed(3, P * 9)
    got = []
    for _ in range(3):
        got.append(draws(smp, D).reshape(P, 9, D))
        smp.advance()
    want = expected(name, spp, {"strength": 3}, P, D, 3)
    assert (np.concatenate(got, axis=1).view(np.uint32) == want.view(np.uint32)).all()
    with pytest.raises(RuntimeError, match="past sample_count 27"):
        smp.next_1d()


def test_the_scene_seed_parameter_adds_to_the_render_seed():
    smp = load("bose", 16, seed=100)
    smp.set_samples_per_wavefront(16)
    smp.seed(5, 32)
    got = draws(smp, 4).reshape(2, 16, 4)
    assert (got == expected("bose", 16, {}, 2, 4, 105)).all()


def test_clone_and_fork_keep_the_parameters():
    smp = load("bush", 27, strength=3)
    smp.set_samples_per_wavefront(27)
    smp.seed(1, 54)
    first = draws(smp, 3)
    twin = smp.clone()
    assert twin.sample_count() == 27
    assert (draws(twin, 2) == draws(smp, 2)).all()  # the clone continues at the same dimension
    fresh = smp.fork()
    with pytest.raises(RuntimeError, match="seed"):
        fresh.next_1d()
    fresh.set_samples_per_wavefront(27)
    fresh.seed(1, 54)
    assert (draws(fresh, 3) == first).all()
    assert "bush" in repr(smp) and "sample_count=27" in repr(smp)


def test_a_clone_taken_inside_a_later_block_continues_its_values():
    """The block's seed and rows are sampler state (kept per lane): a clone made mid-block draws
    what the original draws, and both what pyoa generates."""
    smp = load("bush", 27, strength=3)  # 4 columns per block
    smp.set_samples_per_wavefront(27)
    smp.seed(2, 54)
    head = draws(smp, 6)  # into block 1
    twin = smp.clone()
    tail, twin_tail = draws(smp, 7), draws(twin, 7)  # through blocks 1-3
    want = expected("bush", 27, {"strength": 3}, 2, 13, 2).reshape(54, 13)
    assert (twin_tail.view(np.uint32) == tail.view(np.uint32)).all()
    assert (np.concatenate([head, tail], -1).view(np.uint32) == want.view(np.uint32)).all()


def test_a_block_is_located_once_not_once_per_value(monkeypatch):
    """Issue 49: a draw that stays in its block reuses the block's seed and rows; only a draw
    that enters a new block (or the first of a pass) computes them."""
    calls = []
    locate_block = pm._drjit.hashes.locate_block

    def counted(*args):
        calls.append(1)
        return locate_block(*args)

    monkeypatch.setattr(pm._drjit.hashes, "locate_block", counted)
    smp = load("bose", 49, samples_per_pass=7)  # 8 columns per block; passes of 7 samples
    smp.set_samples_per_wavefront(7)
    smp.seed(4, 2 * 7)
    want = expected("bose", 49, {}, 2, 24, 4)
    # evaluated loops run a loop's body only while a lane is active (a symbolic loop traces it
    # every time and skips it when the kernel runs), so the calls count the blocks located
    with dr.scoped_set_flag(dr.JitFlag.SymbolicLoops, False):
        got = np.stack([np.asarray(smp.next_1d()) for _ in range(24)], -1)  # blocks 0, 1 and 2
        assert len(calls) == 3
        smp.advance()  # a new pass reads other sample indices: its rows are located again,
        again = np.asarray(smp.next_1d())
        assert len(calls) == 4
        smp.advance()  # even when the pass before ended in the same block (0)
        third = np.asarray(smp.next_1d())
        assert len(calls) == 5
    assert (got.view(np.uint32) == want[:, :7].reshape(14, 24).view(np.uint32)).all()
    assert (again.view(np.uint32) == want[:, 7:14, 0].ravel().view(np.uint32)).all()
    assert (third.view(np.uint32) == want[:, 14:21, 0].ravel().view(np.uint32)).all()


@pytest.mark.parametrize("props,error,match", [
    ({"sampler": "bose", "sample_count": 120}, ValueError, r"bose: .*nearest: 81 \(s=9\), 121 \(s=11\)"),
    ({"sampler": "sobol", "sample_count": 128}, ValueError, "no Dr.Jit implementation.*supported: bose"),
    ({"sampler": "bosee", "sample_count": 121}, ValueError, "bosee"),
    ({"sampler": "bose", "sample_count": 121, "offset": "cmjj"}, ValueError, "offset"),
    ({"sampler": "bose", "sample_count": 121, "jitter": 2.0}, ValueError, "jitter"),
    ({"sampler": "faure", "sample_count": 100, "base": 4}, ValueError, "base must be a prime"),
    ({"sampler": "bose", "sample_count": 121, "base": 5}, ValueError, "takes no base"),
    ({"sampler": "bose", "sample_count": 121, "colour": 1}, ValueError, "unknown parameter 'colour'"),
    ({"sampler": "bose", "sample_count": 121, "strength": "two"}, TypeError, "strength must be an int"),
    ({"sampler": "bose", "sample_count": 121, "seed": -1}, ValueError, "seed must be a uint32"),
])
def test_invalid_parameters_fail_at_load_with_pyoa_s_message(props, error, match):
    with pytest.raises(Exception) as info:
        mi.load_dict({"type": "pyoa", **props})
    text = str(info.value)
    assert isinstance(info.value, error) or error.__name__ in text, text
    assert __import__("re").search(match, text), text


def cornell(sampler: dict, size: int = 24, depth: int = 5):
    d = mi.cornell_box()
    d["sensor"]["film"]["width"] = d["sensor"]["film"]["height"] = size
    d["sensor"]["sampler"] = sampler
    d["integrator"] = {"type": "path", "max_depth": depth}
    return mi.load_dict(d)


def render(scene, **kw) -> np.ndarray:
    return np.asarray(mi.render(scene, **kw), dtype=np.float64)


def test_render_spp_changes_the_count_through_pyoa():
    scene = cornell({"type": "pyoa", "sampler": "bose", "sample_count": 121}, size=8)
    img = render(scene, spp=49)
    assert img.shape == (8, 8, 3) and np.isfinite(img).all()
    with pytest.raises(Exception) as info:  # mi.render wraps it; pyoa's ValueError is in the chain
        render(scene, spp=50)
    chain, e = [], info.value
    while e is not None:
        chain.append(e)
        e = e.__cause__ or e.__context__
    assert any(isinstance(c, ValueError) and "bose: 50 is not" in str(c) and "nearest: 49 (s=7), 64 (s=8)" in str(c)
               for c in chain), [str(c) for c in chain]


def test_a_render_in_passes_equals_one_pass():
    """The integrator's samples_per_pass splits 121 samples into 11 passes of 11: given the same
    samples_per_pass, the sampler draws the same samples, so the image equals the one-pass image up to
    the order of the film's float32 sums; without it the render is refused at its first seed(), saying why."""
    def scene(sampler_pass, integrator_pass):
        m = mi.cornell_box()
        m["sensor"]["film"]["width"] = m["sensor"]["film"]["height"] = 12
        m["sensor"]["sampler"] = {"type": "pyoa", "sampler": "bose", "sample_count": 121,
                                  **({"samples_per_pass": sampler_pass} if sampler_pass else {})}
        m["integrator"] = {"type": "path", "max_depth": 5,
                           **({"samples_per_pass": integrator_pass} if integrator_pass else {})}
        return mi.load_dict(m)

    one = render(scene(0, 0), seed=4)
    passes = render(scene(11, 11), seed=4)
    assert np.abs(passes - one).max() <= 1e-5 * np.abs(one).max()
    other = render(cornell({"type": "pyoa", "sampler": "bose", "sample_count": 121, "seed": 1}, size=12), seed=4)
    assert np.abs(other - one).max() > 1e-3 * np.abs(one).max()  # another seed is another image
    with pytest.raises(Exception) as info:
        render(scene(0, 11), seed=4)
    chain, e = [], info.value
    while e is not None:
        chain.append(str(e))
        e = e.__cause__ or e.__context__
    assert any("samples_per_pass" in c for c in chain), chain
    with pytest.raises(Exception, match=r"samples_per_pass \(10\) must divide sample_count \(121\)"):
        scene(10, 0)


def test_symbolic_and_evaluated_loops_render_the_same_image():
    scene = cornell({"type": "pyoa", "sampler": "faure", "sample_count": 64}, size=16, depth=6)
    a = render(scene, seed=3)
    dr.set_flag(dr.JitFlag.SymbolicLoops, False)
    try:
        b = render(scene, seed=3)
    finally:
        dr.set_flag(dr.JitFlag.SymbolicLoops, True)
    assert np.abs(a - b).max() <= 1e-6 * max(1.0, np.abs(a).max())


def test_bose_render_agrees_with_a_high_spp_independent_render():
    """Unbiased within the noise the renders predict, and less noisy than independent sampling.

    The reference is Mitsuba's ``independent`` at 4096 spp. The noise of an
    image mean at 121 spp is estimated from 6 independent renders at 121 spp
    (Bose's is lower, so the bound is conservative): the Bose image's mean
    must lie within 4 standard errors of the reference's, channel by
    channel; and Bose's mean squared error per pixel must be below
    independent's at the same count (1.8x lower measured at 128 x 128 by the
    results page; a sampler with correlated dimensions would not be).
    """
    size = 24
    ref = render(cornell({"type": "independent", "sample_count": 4096}, size=size), seed=777)
    indep = np.stack([render(cornell({"type": "independent", "sample_count": 121}, size=size), seed=s)
                      for s in range(6)])
    bose = np.stack([render(cornell({"type": "pyoa", "sampler": "bose", "sample_count": 121}, size=size), seed=s)
                     for s in range(3)])
    se_121 = indep.mean(axis=(1, 2)).std(axis=0, ddof=1)  # per channel
    se_ref = se_121 * np.sqrt(121 / 4096)
    z = (bose.mean(axis=(1, 2)) - ref.mean(axis=(0, 1))) / np.sqrt(se_121**2 + se_ref**2)
    assert (np.abs(z) < 4).all(), z
    mse_bose = ((bose - ref) ** 2).mean()
    mse_indep = ((indep - ref) ** 2).mean()
    assert mse_bose < mse_indep, (mse_bose, mse_indep)


def test_scalar_variants_are_refused_with_the_reason():
    mi.set_variant("scalar_rgb")
    try:
        with pytest.raises(Exception, match="needs a JIT variant"):
            mi.load_dict({"type": "pyoa", "sampler": "bose", "sample_count": 4})
    finally:
        mi.set_variant(VARIANT)
