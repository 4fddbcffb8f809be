"""Hardening of the Mitsuba plugin (:mod:`pyoa.mitsuba`): a render whose
samples per pass differ from the sampler's is refused with pyoa's message
(never a biased image), and a refused ``mi.render(spp=N)`` leaves the sampler
exactly as it was (the next render is the scene's fresh image, bit for bit).

Renders are 8 x 8 on one Dr.Jit thread: the film's float sums then have one
order, so two renders of the same samples are equal bit for bit (on two
threads, two renders of ``faure`` in passes of 5 measured differed by up to
5e-7). The refused-count renders use the ``aov`` integrator (depth: only the
pixel's two draws), whose kernels build in about a second where those of a
``path`` render with ``faure`` in passes took 7 s each.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from .mitsuba_support import need

pm = need("pyoa.mitsuba")
import drjit as dr
import mitsuba as mi

VARIANT = "llvm_ad_rgb"
SIZE = 8


@pytest.fixture(scope="module", autouse=True)
def variant():
    old, threads, level = mi.variant(), dr.thread_count(), mi.log_level()
    mi.set_variant(VARIANT)
    dr.set_thread_count(1)
    mi.set_log_level(mi.LogLevel.Error)  # Mitsuba warns that an integrator's samples_per_pass is deprecated
    yield
    mi.set_log_level(level)
    dr.set_thread_count(threads)
    if old is not None and old != VARIANT:
        mi.set_variant(old)


def passes(per_pass: int | None) -> dict:
    return {"samples_per_pass": per_pass} if per_pass else {}


def scene(name: str, spp: int, sampler_pass: int | None, integrator: dict):
    d = mi.cornell_box()
    d["sensor"]["film"]["width"] = d["sensor"]["film"]["height"] = SIZE
    d["sensor"]["sampler"] = {"type": "pyoa", "sampler": name, "sample_count": spp, **passes(sampler_pass)}
    d["integrator"] = integrator
    return mi.load_dict(d)


def bits(image) -> np.ndarray:
    return np.asarray(image, dtype=np.float32).view(np.uint32)


def refused_by_pyoa(render, match: str) -> None:
    """``render()`` (an ``mi.render``) is refused by pyoa. Dr.Jit's custom operation wraps every exception
    raised inside ``mi.render`` in a RuntimeError ("... (see above)"): pyoa's ValueError is its cause."""
    with pytest.raises(RuntimeError, match="custom differentiable operation") as info:
        render()
    cause = info.value.__cause__
    assert isinstance(cause, ValueError), repr(cause)
    assert re.search(match, str(cause)), str(cause)


@pytest.fixture(scope="module")
def bose_16():
    """Cornell boxes with bose at 16 spp, by the sampler's samples_per_pass (loaded once)."""
    return {per_pass: scene("bose", 16, per_pass, {"type": "path", "max_depth": 4}) for per_pass in (2, 4)}


# (sampler's samples_per_pass, integrator's; None: one pass of 16): each maps Mitsuba's lanes to other
# pixels and samples than the sampler's, and rendered a biased image before
MISMATCHES = [(4, None), (4, 8), (2, 16)]


@pytest.mark.parametrize("sampler_pass,integrator_pass", MISMATCHES, ids=[f"{a}-{b}" for a, b in MISMATCHES])
def test_passes_unlike_the_sampler_s_are_refused(bose_16, sampler_pass, integrator_pass):
    sc = bose_16[sampler_pass]
    integrator = mi.load_dict({"type": "path", "max_depth": 4, **passes(integrator_pass)})
    match = (rf"Mitsuba renders {integrator_pass or 16} samples per pixel per pass here .* set up for passes of "
             rf"{sampler_pass} \(samples_per_pass\): give the pyoa sampler and the integrator the same "
             "samples_per_pass")
    refused_by_pyoa(lambda: mi.render(sc, integrator=integrator, seed=2), match)
    with pytest.raises(ValueError, match=match):  # where Mitsuba lets it through: pyoa's ValueError itself
        integrator.render(sc, sc.sensors()[0], seed=2)


#: (sampler, sample_count, samples_per_pass of the sampler and the integrator)
CONFIGURED = {"bose": ("bose", 16, 4), "faure": ("faure", 25, 5), "zfaure": ("zfaure", 25, 5)}


@pytest.fixture(scope="module")
def fresh():
    """Per sampler: a scene, its first image (seed 5) and its sampler's repr, before any refusal."""
    out = {}
    for key, (name, spp, per_pass) in CONFIGURED.items():
        sc = scene(name, spp, per_pass, {"type": "aov", "aovs": "dd:depth", **passes(per_pass)})
        out[key] = sc, bits(mi.render(sc, seed=5)), repr(sc.sensors()[0].sampler())
    return out


# (sampler, refused spp, pyoa's message)
REFUSED = [
    ("bose", 9, r"samples_per_pass \(4\) must divide sample_count \(9\)"),
    ("bose", 32, r"bose: 32 is not s\^2 .*nearest: 25 \(s=5\), 49 \(s=7\)"),
    ("faure", 4, r"samples_per_pass \(5\) must divide sample_count \(4\)"),
    ("faure", 32, r"samples_per_pass \(5\) must divide sample_count \(32\)"),
    ("zfaure", 10, r"zfaure: 10 is not a power b\^m of a prime b with m >= 2"),
    ("zfaure", 49, r"samples_per_pass \(5\) must divide sample_count \(49\)"),
]


@pytest.mark.parametrize("key,refused,match", REFUSED, ids=[f"{k}-{n}" for k, n, _ in REFUSED])
def test_a_refused_spp_leaves_the_sampler_as_it_was(fresh, key, refused, match):
    sc, image, description = fresh[key]
    name, spp, per_pass = CONFIGURED[key]
    refused_by_pyoa(lambda: mi.render(sc, spp=refused, seed=5), match)
    smp = sc.sensors()[0].sampler()
    # where Mitsuba lets it through: pyoa's ValueError itself
    with pytest.raises(ValueError, match=match):
        sc.integrator().render(sc, sc.sensors()[0], spp=refused)
    with pytest.raises(ValueError, match=match):
        smp.set_sample_count(refused)
    # checked before rendering: a half-configured sampler drew sample indices its construction does not
    # have (bose: the render never ended) or another base (faure: base 2 after a refused spp=4)
    assert (smp.sample_count(), smp.pyoa_sampler.spp, repr(smp)) == (spp, spp, description)
    if name in ("faure", "zfaure"):
        assert smp.pyoa_sampler.params.b == 5  # the base of 25 (faure: the largest prime b with b^2 <= 25)
    if name == "zfaure":  # still the image of the film its renders found
        assert smp.pyoa_sampler.resolution == (SIZE, SIZE)
    assert (bits(mi.render(sc, seed=5)) == image).all()


# (what the scene names, the pyoa sampler it is): pbrt/Mitsuba names and any case, as everywhere a
# sampler is named (the plugin used to refuse them: "orthogonal has no Dr.Jit implementation")
SPELLINGS = [("orthogonal", "bose"), ("independent", "random"), ("BOSE", "bose"), ("Faure", "faure")]


@pytest.mark.parametrize("spelled,name", SPELLINGS, ids=[s for s, _ in SPELLINGS])
def test_aliases_and_case_resolve_through_the_catalogue(spelled, name):
    import pyoa

    assert pm._drjit.implementation(spelled) is pm._drjit.implementation(name) and pm._drjit.supports(spelled)
    smp = mi.load_dict({"type": "pyoa", "sampler": spelled, "sample_count": 25})
    assert smp.pyoa_sampler.name == name and f"PyoaSampler[{name}," in repr(smp)
    P, D, seed = 3, 6, 7
    smp.set_samples_per_wavefront(25)
    smp.seed(seed, P * 25)
    got = np.stack([np.asarray(smp.next_1d()) for _ in range(D)], -1).reshape(P, 25, D)
    want = pyoa.sampler(name, spp=25, dims=D, seed=seed, backend="numpy").generate(pixels=range(P))
    assert (got.view(np.uint32) == want.view(np.uint32)).all()


def test_an_alias_without_a_dr_jit_implementation_names_both():
    """``ldsampler`` is pyoa's sobol02, which reads tables: refused naming the alias and what it is."""
    with pytest.raises(Exception) as info:
        mi.load_dict({"type": "pyoa", "sampler": "ldsampler", "sample_count": 16})
    assert "ldsampler (sobol02) has no Dr.Jit implementation" in str(info.value), str(info.value)
    assert not pm._drjit.supports("ldsampler") and not pm._drjit.supports("nonsense")
