"""``zfaure`` inside Mitsuba 3 (:mod:`pyoa.mitsuba`): the plugin finds the film,
and each pixel gets its own samples of ``pyoa.sampler("zfaure", ...,
resolution=film size)``, bit for bit.

- A render (``mi.render``, Mitsuba's C++ render loop) of a probe integrator
  that records the values its lanes draw: lane ``l`` of the film's window
  (its crop) is the film's pixel ``(crop_x + p % crop_width, crop_y + p //
  crop_width)``, ``p = l // n``, sample ``k n + l % n`` in pass ``k``. On a
  film that is not square nor a power of the base, on a crop, in passes and
  with a base given.
- A render by a Python integrator (``prb``, which seeds a clone of the
  sampler) is the C++ ``path`` integrator's image.
- Seeded by hand with ``set_film``: the same values, inside a symbolic loop
  and from a clone.
- What cannot be mapped to the film's pixels is refused, saying why.
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
#: values the probe records per lane, after the two of the pixel position: across block 0 and 1 of base 5
D = 6


@pytest.fixture(scope="module", autouse=True)
def variant():
    old = mi.variant()
    mi.set_variant(VARIANT)

    class Probe(mi.SamplingIntegrator):
        """Draws ``D`` values per lane after the sensor's own two and records them (one list per pass)."""

        def __init__(self, props):
            super().__init__(props)
            self.passes = []

        def sample(self, scene, sampler, ray, medium=None, active=True):
            self.passes.append([sampler.next_1d() for _ in range(D)])
            return mi.Spectrum(0.0), mi.Bool(True), []

        def aov_names(self):
            return []

    mi.register_integrator("pyoa_probe", lambda props: Probe(props))
    yield
    if old is not None and old != VARIANT:
        mi.set_variant(old)


def film(width, height, **extra):
    return {"type": "hdrfilm", "width": width, "height": height, "rfilter": {"type": "box"}, **extra}


def cornell(film_dict, sampler, integrator):
    d = mi.cornell_box()
    d["sensor"]["film"] = film_dict
    d["sensor"]["sampler"] = {"type": "pyoa", "sampler": "zfaure", **sampler}
    d["integrator"] = integrator
    return mi.load_dict(d)


def bits(x) -> np.ndarray:
    return np.asarray(x, dtype=np.float32).view(np.uint32)


def cause_of(info) -> BaseException:
    """pyoa's error inside ``mi.render``: Dr.Jit's custom operation wraps it in a RuntimeError."""
    e = info.value
    while e.__cause__ is not None:
        e = e.__cause__
    return e


# (id, film, sampler options, integrator's samples per pass, seed): the film's window as rendered
RENDERS = [
    ("7x5", film(7, 5), {"sample_count": 25}, None, 7),
    ("crop", film(10, 6, crop_offset_x=3, crop_offset_y=2, crop_width=5, crop_height=3), {"sample_count": 16}, None, 1),
    ("passes", film(6, 4), {"sample_count": 27, "samples_per_pass": 9}, 9, 2**32 - 1),
    ("base", film(5, 6), {"sample_count": 125, "base": 5}, None, 3),
]


@pytest.mark.parametrize("film_dict,sampler,per_pass,seed", [r[1:] for r in RENDERS], ids=[r[0] for r in RENDERS])
def test_a_render_gives_each_pixel_of_the_film_its_zfaure_samples(film_dict, sampler, per_pass, seed):
    integrator = {"type": "pyoa_probe", **({"samples_per_pass": per_pass} if per_pass else {})}
    scene = cornell(film_dict, sampler, integrator)
    mi.render(scene, seed=seed)
    spp = sampler["sample_count"]
    n = per_pass or spp
    W, H = film_dict["width"], film_dict["height"]
    x0, y0 = film_dict.get("crop_offset_x", 0), film_dict.get("crop_offset_y", 0)
    cw, ch = film_dict.get("crop_width", W), film_dict.get("crop_height", H)
    passes = scene.integrator().passes
    assert len(passes) == spp // n
    # pass k, lane l: window pixel l // n, sample k n + l % n
    got = np.concatenate([np.stack([bits(v) for v in p], -1).reshape(cw * ch, n, D) for p in passes], axis=1)
    smp = pyoa.sampler("zfaure", spp=spp, dims=2 + D, seed=seed, resolution=(W, H), backend="numpy",
                       base=sampler.get("base"))
    pixels = [(y0 + y) * W + x0 + x for y in range(ch) for x in range(cw)]
    want = smp.generate(pixels=pixels).view(np.uint32)[:, :, 2:]  # after the sensor's pixel position (dims 0, 1)
    assert scene.sensors()[0].sampler().pyoa_sampler.resolution == (W, H)
    bad = got != want
    assert not bad.any(), f"{bad.sum()} of {bad.size} values differ, first at {np.argwhere(bad)[0]}"


def test_a_python_integrator_renders_the_image_of_the_cxx_one():
    """``prb`` seeds a clone of the sensor's sampler from Python (``ADIntegrator.prepare``): the clone
    finds the film too, so its image is ``path``'s (equal up to float rounding; ``faure``'s differs
    by 0.86)."""
    images = [np.asarray(mi.render(cornell(film(8, 8), {"sample_count": 16}, {"type": t, "max_depth": 3}), seed=1))
              for t in ("prb", "path")]
    assert np.abs(images[0] - images[1]).max() <= 1e-6 * np.abs(images[1]).max()


def seeded(W, H, spp, seed, lanes=None):
    smp = mi.load_dict({"type": "pyoa", "sampler": "zfaure", "sample_count": spp})
    smp.set_film(mi.load_dict(film(W, H)))
    smp.seed(seed, lanes or W * H * spp)
    return smp


def test_seeded_by_hand_with_its_film_inside_a_symbolic_loop_and_from_a_clone():
    """The dimension counter is loop state; a clone continues with the film and the dimension."""
    W, H, spp, seed = 4, 3, 9, 11
    smp = seeded(W, H, spp, seed)
    want = pyoa.sampler("zfaure", spp=spp, dims=2 * D, seed=seed, resolution=(W, H),
                        backend="numpy").generate(pixels=range(W * H)).reshape(W * H * spp, 2 * D)

    def body(k, acc, s):  # acc = sum_k (k + 1) * x_k: a value drawn in the wrong dimension changes it
        return k + 1, acc + mi.Float(k + 1) * s.next_1d(), s

    _, acc, smp = dr.while_loop(state=(mi.UInt32(0), dr.zeros(mi.Float, W * H * spp), smp),
                                cond=lambda k, acc, s: k < D, body=body)
    ref = np.zeros(W * H * spp, np.float32)
    for k in range(D):
        ref = ref + np.float32(k + 1) * want[:, k]
    assert (bits(acc) == ref.view(np.uint32)).all()
    twin = smp.clone()
    for k in range(D, 2 * D):
        assert (bits(twin.next_1d()) == want[:, k].view(np.uint32)).all()


def test_seeded_by_hand_without_a_film_or_with_another_film_is_refused():
    smp = mi.load_dict({"type": "pyoa", "sampler": "zfaure", "sample_count": 25})
    with pytest.raises(ValueError, match=r"zfaure orders the film's pixels, and no film was found.*set_film"):
        smp.seed(1, 6 * 25)
    with pytest.raises(RuntimeError, match="seed"):
        smp.next_1d()
    smp.set_film(mi.load_dict(film(7, 5)))
    with pytest.raises(ValueError, match=r"seeded with 6 pixels of lanes, but the film renders 7 x 5 pixels"):
        smp.seed(1, 6 * 25)


@pytest.mark.parametrize("props,match", [
    ({"sample_count": 30}, r"zfaure: 30 is not a power b\^m of a prime b with m >= 2"),
    ({"sample_count": 25, "base": 3}, r"zfaure: 25 samples are 5\^2, base 5; base 3 takes 9, 27"),
])
def test_a_count_zfaure_does_not_take_fails_at_load(props, match):
    with pytest.raises(Exception, match=match):
        mi.load_dict({"type": "pyoa", "sampler": "zfaure", **props})


@pytest.mark.parametrize("film_extra,integrator,match", [
    ({"sample_border": True, "rfilter": {"type": "gaussian"}}, {"type": "path", "max_depth": 2},
     r"samples a border of 2 pixels around its image \(hdrfilm sample_border=true\)"),
    ({}, {"type": "ptracer", "max_depth": 2}, r"adjoint one \(mi.AdjointIntegrator: ptracer\).*lanes are no pixels"),
], ids=["sample_border", "ptracer"])
def test_renders_whose_lanes_are_not_the_film_s_pixels_are_refused(film_extra, integrator, match):
    scene = cornell(film(6, 6, **film_extra), {"sample_count": 4}, integrator)
    with pytest.raises(RuntimeError) as info:
        mi.render(scene, seed=1)
    error = cause_of(info)
    assert isinstance(error, ValueError) and __import__("re").search(match, str(error)), repr(error)


def test_the_name_in_any_case_is_zfaure():
    smp = mi.load_dict({"type": "pyoa", "sampler": "ZFaure", "sample_count": 25})
    assert smp.pyoa_sampler.name == "zfaure" and "PyoaSampler[zfaure, sample_count=25 (b=5)" in repr(smp)
