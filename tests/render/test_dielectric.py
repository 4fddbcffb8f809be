"""Tests of the smooth dielectric (:mod:`pyoa.render.bsdfs.dielectric`): its
Fresnel term against the textbook formulas, normal incidence, total internal
reflection, the choice of lobe with probability F and the radiance scaling
of refraction, Snell's law and reversibility, the NumPy and compiled forms
alike to the bit, and the glass Cornell box against Mitsuba 3 (skipped
without Mitsuba, a failure under ``PYOA_REQUIRE_MITSUBA=1``)."""

from __future__ import annotations

import numpy as np
import pytest

from pyoa.render import bsdfs
from pyoa.render.bsdfs import dielectric as D

from ..mitsuba_support import need

GLASS = 1.5046 / 1.000277  # Mitsuba's default int_ior / ext_ior (bk7 in air)
ETAS = (1.0001, 1.33, GLASS, 2.4)


def _wo(theta, phi=0.3):
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1)


def _glass(eta=GLASS):
    return bsdfs.Materials.build([("glass", "dielectric", {"int_ior": eta, "ext_ior": 1.0})])


def _textbook(theta_i, n1, n2):
    """Unpolarized Fresnel reflectance from n1 into n2 at incidence theta_i
    (Born and Wolf 1.5.2, in angles), and cos theta_t (0 beyond the critical angle)."""
    sin_t = n1 / n2 * np.sin(theta_i)
    tir = sin_t >= 1.0
    cos_t = np.sqrt(np.clip(1.0 - sin_t**2, 0.0, None))
    ci = np.cos(theta_i)
    rs = ((n1 * ci - n2 * cos_t) / (n1 * ci + n2 * cos_t)) ** 2
    rp = ((n1 * cos_t - n2 * ci) / (n1 * cos_t + n2 * ci)) ** 2
    return np.where(tir, 1.0, 0.5 * (rs + rp)), np.where(tir, 0.0, cos_t)


@pytest.mark.parametrize("eta", ETAS)
@pytest.mark.parametrize("front", [True, False])
def test_fresnel_is_the_textbook_s(eta, front):
    theta = np.linspace(1e-6, np.pi / 2 - 1e-6, 2001)
    n1, n2 = (1.0, eta) if front else (eta, 1.0)
    eta_it, eta_ti = D.etas(np.full(theta.size, eta), np.full(theta.size, front))
    np.testing.assert_allclose(eta_it, n2 / n1, rtol=1e-15)
    f, ct = D.fresnel(np.cos(theta), eta_it, eta_ti)
    want_f, want_ct = _textbook(theta, n1, n2)
    np.testing.assert_allclose(f, want_f, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(ct, want_ct, rtol=1e-9, atol=1e-7)
    assert np.all((f >= 0) & (f <= 1 + 1e-15))


@pytest.mark.parametrize("eta", ETAS)
def test_normal_incidence_reflects_the_square_of_eta_minus_one_over_eta_plus_one(eta):
    mats = _glass(eta)
    for front in (True, False):
        f, ct = D.fresnel(np.ones(1), *D.etas(np.array([eta]), np.array([front])))
        assert f[0] == pytest.approx(((eta - 1) / (eta + 1)) ** 2, rel=1e-12) and ct[0] == 1.0
        # sampled: a u just below F reflects straight back, just above it refracts straight through
        u = np.array([[np.nextafter(f[0], 0), 0.5], [np.nextafter(f[0], 1), 0.5]])
        wi, weight, pdf, delta = bsdfs.sample(mats, [0, 0], [[0, 0, 1.0]] * 2, u, [front] * 2)
        np.testing.assert_array_equal(wi, [[-0.0, -0.0, 1.0], [-0.0, -0.0, -1.0]])
        np.testing.assert_allclose(weight[1], (1 / eta if front else eta) ** 2, rtol=1e-15)
        assert np.all(weight[0] == 1) and np.all(pdf == 0) and np.all(delta)
    assert ((GLASS - 1) / (GLASS + 1)) ** 2 == pytest.approx(0.04054, abs=1e-5)  # bk7 in air reflects 4.05 %


@pytest.mark.parametrize("eta", [1.33, GLASS, 2.4])
def test_total_internal_reflection_beyond_the_critical_angle(eta):
    critical = np.arcsin(1 / eta)
    theta = np.linspace(critical + 1e-9, np.pi / 2 - 1e-6, 500)
    wo = _wo(theta)
    f, ct = D.fresnel(wo[:, 2], *D.etas(np.full(theta.size, eta), np.zeros(theta.size, bool)))
    assert np.all(f == 1.0) and np.all(ct == 0.0)
    u = np.stack([np.full(theta.size, np.nextafter(1, 0)), np.full(theta.size, 0.5)], axis=1)
    wi, weight, _, _ = bsdfs.sample(_glass(eta), np.zeros(theta.size, int), wo, u, np.zeros(theta.size, bool))
    np.testing.assert_array_equal(wi, wo * [-1, -1, 1])  # every u reflects, weight 1
    assert np.all(weight == 1)
    # just inside the critical angle light still leaves the glass; entering it, it always can
    below = _wo(np.array([critical - 1e-3]))
    assert D.fresnel(below[:, 2], *D.etas(np.array([eta]), np.array([False])))[0][0] < 1
    assert np.all(D.fresnel(wo[:, 2], *D.etas(np.full(theta.size, eta), np.ones(theta.size, bool)))[0] < 1)


@pytest.mark.parametrize("eta", ETAS)
@pytest.mark.parametrize("front", [True, False])
def test_lobes_are_chosen_with_probability_f_and_refraction_scales_radiance(eta, front):
    """On a stratified grid of u the reflected fraction is F; a reflection's
    weight is 1 and a refraction's (1 / eta_it)^2, the radiance's change
    across the interface (Mitsuba's radiance mode), so the mean weight is
    F + (1 - F) / eta_it^2 and, weighting each refraction back by eta_it^2,
    the energy F + T = 1."""
    n = 4096
    theta = 0.7
    wo = np.broadcast_to(_wo(np.array([theta])), (n, 3))
    u = np.stack([(np.arange(n) + 0.5) / n, np.full(n, 0.3)], axis=1)
    wi, weight, pdf, delta = bsdfs.sample(_glass(eta), np.zeros(n, int), wo, u, np.full(n, front))
    eta_it = eta if front else 1 / eta
    f, _ = _textbook(theta, *((1.0, eta) if front else (eta, 1.0)))
    reflected = wi[:, 2] > 0
    assert reflected.mean() == pytest.approx(f, abs=1.0 / n)
    assert np.all(weight[reflected] == 1)
    np.testing.assert_allclose(weight[~reflected], 1 / eta_it**2, rtol=1e-14)
    assert np.all(weight[:, 0] == weight[:, 1]) and np.all(weight[:, 1] == weight[:, 2])  # colourless
    assert weight[:, 0].mean() == pytest.approx(f + (1 - f) / eta_it**2, abs=2.0 / n)
    flux = np.where(reflected, weight[:, 0], weight[:, 0] * eta_it**2)
    np.testing.assert_allclose(flux, 1.0, rtol=1e-14)
    assert np.all(pdf == 0) and np.all(delta)


@pytest.mark.parametrize("eta", ETAS)
@pytest.mark.parametrize("front", [True, False])
def test_refraction_obeys_snell_and_reverses(eta, front):
    """The refracted direction is a unit vector on the other side, in the
    plane of incidence, at sin theta_t = sin theta_i / eta_it; the light
    going back (from the other side, along the refracted direction) is
    refracted onto wo again, reflected with the same F (Stokes), and the two
    crossings' radiance factors multiply to 1."""
    theta = np.linspace(0.01, np.pi / 2 - 0.01, 300)
    wo = _wo(theta, phi=1.1)
    n = len(theta)
    eta_arr, side = np.full(n, eta), np.full(n, front)
    f, _ = D.fresnel(wo[:, 2], *D.etas(eta_arr, side))
    ok = f < 1  # not totally reflected
    u = np.stack([np.full(n, np.nextafter(1, 0)), np.zeros(n)], axis=1)  # u >= F: refract where light can
    mats = _glass(eta)
    wt, w, _, _ = bsdfs.sample(mats, np.zeros(n, int), wo, u, side)
    wt, w, wo_ok = wt[ok], w[ok, 0], wo[ok]
    np.testing.assert_allclose(np.linalg.norm(wt, axis=1), 1.0, rtol=1e-14)
    assert np.all(wt[:, 2] < 0)
    eta_it = eta if front else 1 / eta
    sin_i, sin_t = np.linalg.norm(wo_ok[:, :2], axis=1), np.linalg.norm(wt[:, :2], axis=1)
    np.testing.assert_allclose(sin_t, sin_i / eta_it, rtol=1e-12)
    cross = wo_ok[:, 0] * wt[:, 1] - wo_ok[:, 1] * wt[:, 0]
    np.testing.assert_allclose(cross, 0.0, atol=1e-15)  # same plane, ...
    assert np.all(np.sum(wo_ok[:, :2] * wt[:, :2], axis=1) < 0)  # ... the other way
    # back from the other side: its frame's z turned over, and the glass seen from there
    back = wt * [1, 1, -1]
    m = len(back)
    f_back, _ = D.fresnel(back[:, 2], *D.etas(np.full(m, eta), np.full(m, not front)))
    np.testing.assert_allclose(f_back, f[ok], rtol=1e-9, atol=1e-12)
    wr, w_back, _, _ = bsdfs.sample(mats, np.zeros(m, int), back, u[ok], np.full(m, not front))
    np.testing.assert_allclose(wr * [1, 1, -1], wo_ok, atol=1e-12)
    np.testing.assert_allclose(w * w_back[:, 0], 1.0, rtol=1e-14)


def test_index_matched_glass_lets_light_through_unchanged():
    """Where the indices match, F is 0 (as Mitsuba's, not the formula's 1e-32), so even u = 0 refracts."""
    wo = _wo(np.linspace(0.0, 1.5, 50))
    for front in (True, False):
        wi, weight, _, _ = bsdfs.sample(_glass(1.0), np.zeros(50, int), wo, np.full((50, 2), 0.0), np.full(50, front))
        np.testing.assert_allclose(wi, -wo, atol=1e-12)
        assert np.all(weight == 1)


def test_glass_is_a_delta_bsdf_without_a_light_sample():
    rng = np.random.default_rng(1)
    n = 500
    wo, wi = _wo(rng.uniform(0, 1.5, n), rng.uniform(0, 6, n)), rng.normal(size=(n, 3))
    mats = _glass()
    f_cos, pd = bsdfs.evaluate(mats, np.zeros(n, int), wo, wi, rng.random(n) < 0.5)
    assert np.all(f_cos == 0) and np.all(pd == 0)
    assert np.all(bsdfs.pdf(mats, np.zeros(n, int), wo, wi) == 0)
    assert bsdfs.DELTA[bsdfs.KINDS["dielectric"]]  # the renderers take no light sample at glass
    from pyoa.render.compiled.shading import SMOOTH, V0X, ROW, hit_data
    from pyoa.render.scene import load

    sc = load("cornell-glass")
    data = hit_data(sc, np.zeros(len(sc.triangles)), np.zeros(len(sc.triangles)))
    smooth = data[:, (SMOOTH - V0X) // ROW]
    np.testing.assert_array_equal(smooth, sc.materials.kind[sc.material] != bsdfs.KINDS["dielectric"])


def test_compiled_forms_are_the_numpy_forms_to_the_bit():
    """The compiled one-point form (per-point dispatch) and the NumPy form do
    the same operations in the same order: the same bits, at every angle up
    to grazing, across the critical angle, from both sides, and for u on
    both sides of F."""
    from pyoa.render.compiled import bsdfs as cb

    theta = np.concatenate([np.linspace(0, np.pi / 2 - 1e-9, 400), np.arcsin(1 / np.array(ETAS)) + 1e-12])
    for eta in ETAS:
        mats = _glass(eta)
        for front in (True, False):
            wo = _wo(theta)
            n = len(wo)
            f, _ = D.fresnel(wo[:, 2], *D.etas(np.full(n, eta), np.full(n, front)))
            for u0 in (np.zeros(n), np.nextafter(f, 0), f, np.full(n, np.nextafter(1, 0))):
                u = np.stack([np.clip(u0, 0, np.nextafter(1, 0)), np.full(n, 0.5)], axis=1)
                wi, weight, pdf, delta = bsdfs.sample(mats, np.zeros(n, int), wo, u, np.full(n, front))
                want = np.column_stack([wi, weight, pdf, delta]).view(np.uint64)
                got = np.array([cb.sample(3, *mats.params[0], front, *wo[i], *u[i]) for i in range(n)],
                               dtype=np.float64).view(np.uint64)
                np.testing.assert_array_equal(got, want)


# --------------------------------------------------------------------------- against Mitsuba 3

#: The cross-check's renders: 8 independent renders of 32 x 32 pixels at 512
#: samples per pixel per renderer (about 15 s in all on 2 cores). The image's
#: mean per channel has a standard error of about 0.15 % of itself; a 4 x 4
#: grid of block means resolves what the glass does where (a box of water,
#: index 1.33 instead of 1.5046, differs by up to 24 standard errors there).
SIZE, SPP, SEEDS, BLOCKS = 32, 512, 8, 4


def _blocks(image):
    """The ``BLOCKS x BLOCKS`` block means per channel of an RGB image."""
    b = SIZE // BLOCKS
    return np.asarray(image, np.float64)[..., :3].reshape(BLOCKS, b, BLOCKS, b, 3).mean(axis=(1, 3))


def _z(a, b):
    """(mean a - mean b) / its standard error, from ``(seeds, ...)`` independent renders of each."""
    return (a.mean(0) - b.mean(0)) / np.sqrt(a.var(0, ddof=1) / len(a) + b.var(0, ddof=1) / len(b))


@pytest.fixture(scope="module")
def mitsuba_blocks():
    """A function rendering Mitsuba 3's ``cornell_box()`` at pyoa's settings
    (path integrator, max depth 5, box filter), its large box given ``bsdf``,
    ``SEEDS`` times with its ``independent`` sampler: ``(seeds, B, B, 3)``."""
    need("pyoa.mitsuba")
    import mitsuba as mi

    old = mi.variant()
    mi.set_variant("llvm_ad_rgb")

    def render(bsdf):
        d = mi.cornell_box()
        d["large-box"]["bsdf"] = bsdf
        d["integrator"] = {"type": "path", "max_depth": 5}
        d["sensor"]["film"]["width"] = d["sensor"]["film"]["height"] = SIZE
        d["sensor"]["film"]["rfilter"] = {"type": "box"}
        d["sensor"]["sampler"] = {"type": "independent", "sample_count": SPP}
        scene = mi.load_dict(d)
        return np.stack([_blocks(mi.render(scene, spp=SPP, seed=k)) for k in range(SEEDS)])

    yield render
    if old is not None and old != "llvm_ad_rgb":
        mi.set_variant(old)


def test_the_glass_cornell_box_matches_mitsuba(mitsuba_blocks):
    """pyoa's cornell-glass (compiled shading, independent samples) and
    Mitsuba 3.9's cornell_box() with a dielectric large box agree: the image
    mean per channel within 4 standard errors of the difference, and each
    block's mean within 5 (48 block-channels, 7 + 7 degrees of freedom). The
    check can fail: it tells the glass box from the white one, and Mitsuba's
    glass from Mitsuba's water."""
    from pyoa.render.render import render
    from pyoa.render.scene import load

    def pyoa_blocks(name, spp=SPP):
        sc = load(name)
        return np.stack([_blocks(render(sc, sampler="random", spp=spp, seed=k, width=SIZE, height=SIZE,
                                        shading="numba").image) for k in range(SEEDS)])

    glass = pyoa_blocks("cornell-glass")
    mit = mitsuba_blocks({"type": "dielectric"})
    z_mean = _z(glass.mean(axis=(1, 2)), mit.mean(axis=(1, 2)))
    z_blocks = _z(glass, mit)
    assert np.all(np.abs(z_mean) < 4), f"image means differ by {z_mean} standard errors"
    assert np.all(np.abs(z_blocks) < 5), f"block means differ by up to {np.abs(z_blocks).max():.1f} standard errors"
    # the power of the check
    white = pyoa_blocks("cornell", spp=SPP // 4)
    assert np.abs(_z(white, mit)).max() > 10 and abs(_z(white.mean(axis=(1, 2)), mit.mean(axis=(1, 2)))[0]) > 10
    water = mitsuba_blocks({"type": "dielectric", "int_ior": 1.33})
    assert np.abs(_z(glass, water)).max() > 10
