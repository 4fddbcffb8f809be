"""Known-answer tests of the path tracer (:mod:`pyoa.render.integrator` through
:func:`pyoa.render.render.render`).

Every check compares an image against a radiance known in closed form (or by
an independent numerical integral written here) with a tolerance taken from
the Monte Carlo standard error of the image mean: pixels are independent
estimates (every pixel's samples are randomized independently), so the
standard error of the mean over pixels is ``std(pixel values) / sqrt(pixels)``
and a correct renderer lands within a few of them. The scenes are tiny
(16 x 16 to 32 x 32 pixels, 16 to 32 spp) and seeds are fixed, so the tests are
deterministic.

Scenes are written as JSON (the format of :mod:`pyoa.render.scene`) into
``tmp_path`` and loaded like any scene file. Every test runs on both shading
implementations: the numba-compiled one with Embree called from it (the
default) and the NumPy reference (``PYOA_SHADING``).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from pyoa.render import integrator as integrator_mod
from pyoa.render import render as render_mod
from pyoa.render.layout import Layout
from pyoa.render.render import render
from pyoa.render.scene import load

#: Allowed deviation of an image mean from its expectation, in standard errors.
Z = 5.0
#: Relative floor of the tolerance (renders whose pixels barely vary, e.g. a
#: stratified sampler on a smooth integrand, must not fail on float32 rounding
#: or the sub-pixel variation of the integrand over a narrow field of view).
REL_FLOOR = 2e-3


@pytest.fixture(autouse=True, params=["numba", "numpy"])
def shading(request, monkeypatch):
    """The shading implementation under test (through ``PYOA_SHADING``, as a user picks it)."""
    monkeypatch.setenv("PYOA_SHADING", request.param)
    return request.param


# -- helpers -----------------------------------------------------------------------


def write_scene(tmp_path, data: dict, name: str = "scene"):
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(data))
    return load(path)


def affine(R, t=(0.0, 0.0, 0.0)) -> list:
    m = np.eye(4)
    m[:3, :3] = np.asarray(R, dtype=np.float64)
    m[:3, 3] = t
    return m.tolist()


def mean_se(image: np.ndarray):
    """Per-channel mean over pixels and its standard error."""
    px = image.reshape(-1, 3).astype(np.float64)
    return px.mean(axis=0), px.std(axis=0, ddof=1) / math.sqrt(len(px))


def assert_mean(image, expected, what: str = "", z: float = Z, rel_floor: float = REL_FLOOR):
    """The image mean (per channel) equals ``expected`` within ``z`` standard
    errors (or ``rel_floor`` relative, whichever is larger)."""
    expected = np.broadcast_to(np.asarray(expected, dtype=np.float64), (3,))
    m, se = mean_se(image)
    tol = np.maximum(z * se, rel_floor * np.abs(expected))
    assert np.all(np.isfinite(image)), f"{what}: non-finite pixels"
    assert np.all(np.abs(m - expected) <= tol), (
        f"{what}: image mean {m} != expected {expected} (standard error {se}, "
        f"deviation {(m - expected) / np.maximum(se, 1e-300)} sigma)")


def assert_same_mean(a, b, what: str = "", z: float = Z, rel_floor: float = REL_FLOOR):
    """Two independent renders of the same scene agree within their errors."""
    ma, sa = mean_se(a)
    mb, sb = mean_se(b)
    tol = np.maximum(z * np.hypot(sa, sb), rel_floor * np.abs(ma + mb) / 2)
    assert np.all(np.abs(ma - mb) <= tol), (
        f"{what}: means {ma} and {mb} differ by {(ma - mb) / np.hypot(sa, sb)} sigma")


# -- the furnace: a closed, uniformly emitting, uniformly diffuse enclosure --------


def face_rotation(n) -> np.ndarray:
    """A rotation (det +1) taking +z to the unit axis vector ``n``."""
    n = np.asarray(n, dtype=np.float64)
    a = np.zeros(3)
    a[(int(np.argmax(np.abs(n))) + 1) % 3] = 1.0
    return np.stack([a, np.cross(n, a), n], axis=1)


RHO = (0.5, 0.3, 0.7)
EMIT = (1.0, 2.0, 0.5)


def furnace_scene(tmp_path, *, mis: bool, rho=RHO, emission=EMIT, size=32):
    """The box [-1, 1]^3 made of six rectangles whose fronts (normals) face
    inwards, every one diffuse with albedo ``rho`` and emitting ``emission``
    towards the inside; the camera sits inside, off-centre and tilted."""
    shapes = []
    for axis in range(3):
        for sign in (1.0, -1.0):
            n = np.zeros(3)
            n[axis] = sign  # inward normal of the face at coordinate -sign
            shapes.append({"type": "rectangle", "to_world": affine(face_rotation(n), -n),
                           "material": "wall", "emission": list(emission)})
    c, s = math.cos(0.4), math.sin(0.4)
    cam = affine([[c, 0, s], [0, 1, 0], [-s, 0, c]], (0.2, -0.3, 0.1))
    return write_scene(tmp_path, {
        "camera": {"to_world": cam, "fov": 80},
        "film": {"width": size, "height": size},
        "integrator": {"max_depth": 3, "mis": mis},
        "materials": {"wall": {"type": "diffuse", "reflectance": list(rho)}},
        "shapes": shapes,
    }, "furnace")


def furnace_radiance(depth: int, rho=RHO, emission=EMIT) -> np.ndarray:
    """E * sum_{k < depth} rho^k: emission reflected up to depth - 1 times."""
    rho = np.asarray(rho)
    return np.asarray(emission) * sum(rho**k for k in range(depth))


def test_furnace_scene_faces_inwards(tmp_path):
    sc = furnace_scene(tmp_path, mis=True)
    centroids = sc.triangles.astype(np.float64).mean(axis=1)
    assert len(sc.triangles) == 12 and len(sc.emitters) == 12
    assert np.all(np.einsum("ij,ij->i", sc.normals, centroids) < 0)
    np.testing.assert_allclose(sc.areas.sum(), 24.0)


@pytest.mark.parametrize("mis", [True, False], ids=["mis", "nomis"])
def test_furnace_depth1_sees_emission_exactly(tmp_path, mis):
    """max_depth 1: only emitters seen directly, every pixel exactly E."""
    sc = furnace_scene(tmp_path, mis=mis)
    res = render(sc, sampler="random", spp=4, seed=3, max_depth=1)
    assert res.dims == 2
    np.testing.assert_array_equal(res.image, np.broadcast_to(np.float32(EMIT), res.image.shape))


@pytest.mark.parametrize("depth", [2, 3, 6, 9])
@pytest.mark.parametrize("mis", [True, False], ids=["mis", "nomis"])
def test_furnace(tmp_path, mis, depth):
    """Radiance E * sum_{k<D} rho^k everywhere (D = 6, 9: Russian roulette,
    which starts at depth 5, must keep it unbiased)."""
    sc = furnace_scene(tmp_path, mis=mis)
    res = render(sc, sampler="random", spp=16, seed=depth, max_depth=depth)
    assert res.dims == 2 + 4 * (depth - 1) - (0 if mis else 2)
    assert_mean(res.image, furnace_radiance(depth), f"furnace mis={mis} max_depth={depth}")


@pytest.mark.parametrize("mis", [True, False], ids=["mis", "nomis"])
def test_furnace_russian_roulette_from_the_first_bounce(tmp_path, monkeypatch, mis):
    """With Russian roulette from depth 1 (paths are killed with probability
    1 - max(throughput) at every bounce) the estimate stays unbiased, and
    roulette does kill paths: fewer rays than without it."""
    sc = furnace_scene(tmp_path, mis=mis)
    depth = 8
    monkeypatch.setattr(integrator_mod, "RR_DEPTH", 100)
    full = render(sc, sampler="random", spp=16, seed=11, max_depth=depth)
    monkeypatch.setattr(integrator_mod, "RR_DEPTH", 1)
    rr = render(sc, sampler="random", spp=16, seed=11, max_depth=depth)
    assert rr.stats.rays < 0.6 * full.stats.rays
    assert full.stats.paths == rr.stats.paths == 32 * 32 * 16
    expected = furnace_radiance(depth)
    assert_mean(full.image, expected, "furnace without roulette")
    assert_mean(rr.image, expected, "furnace with roulette from depth 1")


def test_furnace_samplers(tmp_path):
    """Every sampler (its values feed every dimension) gives the furnace answer."""
    sc = furnace_scene(tmp_path, mis=True)
    for name, spp in (("bose", 16), ("sobol", 16), ("halton", 16)):
        res = render(sc, sampler=name, spp=spp, seed=5, max_depth=4)
        assert_mean(res.image, furnace_radiance(4), f"furnace {name}")


# -- direct lighting from a rectangular area light ------------------------------------

LIGHT_A, LIGHT_B, LIGHT_H = 0.6, 0.3, 1.0  # light size along x, y; height above the plane
LE = (4.0, 2.0, 1.0)
FLOOR_RHO = (0.6, 0.5, 0.4)


def irradiance_closed_form(a, b, h, le=1.0):
    """Irradiance at the point below the centre of a parallel a x b
    rectangle of radiance ``le`` at height ``h`` (four corner view factors)."""
    x, y = a / 2, b / 2
    rx, ry = math.hypot(h, x), math.hypot(h, y)
    return 2.0 * le * (x / rx * math.atan(y / rx) + y / ry * math.atan(x / ry))


def irradiance_numerical(a, b, h, n=1000):
    """The same by the midpoint rule: integral of cos cos / r^2 over the light."""
    xs = (np.arange(n) + 0.5) / n * a - a / 2
    ys = (np.arange(n) + 0.5) / n * b - b / 2
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    r2 = X**2 + Y**2 + h**2
    return float(np.sum(h * h / r2**2) * (a / n) * (b / n))


def test_irradiance_formula():
    for a, b, h in ((LIGHT_A, LIGHT_B, LIGHT_H), (1.0, 1.0, 0.5), (0.2, 2.0, 1.5)):
        assert irradiance_closed_form(a, b, h) == pytest.approx(irradiance_numerical(a, b, h), rel=1e-6)
    # a tiny light: Le * A / h^2; an infinite one: pi Le
    assert irradiance_closed_form(1e-3, 1e-3, 1.0) == pytest.approx(1e-6, rel=1e-5)
    assert irradiance_closed_form(1e6, 1e6, 1.0) == pytest.approx(math.pi, rel=1e-5)


def light_scene(tmp_path, *, floor: dict, mis: bool = True, max_depth: int = 2, a=LIGHT_A, b=LIGHT_B,
                h=LIGHT_H, le=LE, size=16, fov=0.5, floor_size=2.0, scale=1.0):
    """A plane z = 0 (material ``floor``, the square of half-side
    ``floor_size``), an a x b rectangular light at height h facing down
    (centred above the origin, its back black), and a pinhole camera at
    (0, 0, h/2) looking straight down at the origin through a narrow field of
    view. ``scale`` multiplies every length (radiance does not change)."""
    down = np.diag([1.0, -1.0, -1.0])  # +z -> -z
    a, b, h, floor_size = a * scale, b * scale, h * scale, floor_size * scale
    return write_scene(tmp_path, {
        "camera": {"to_world": affine(np.diag([-1.0, 1.0, -1.0]), (0, 0, h / 2)), "fov": fov},
        "film": {"width": size, "height": size},
        "integrator": {"max_depth": max_depth, "mis": mis},
        "materials": {"floor": floor, "black": {"type": "diffuse", "reflectance": [0, 0, 0]}},
        "shapes": [
            {"type": "rectangle", "id": "floor", "to_world": affine(np.eye(3) * floor_size), "material": "floor"},
            {"type": "rectangle", "id": "light", "to_world": affine(down @ np.diag([a / 2, b / 2, 1]), (0, 0, h)),
             "material": "black", "emission": list(le)},
        ],
    }, "light")


def direct_diffuse(rho=FLOOR_RHO, le=LE, a=LIGHT_A, b=LIGHT_B, h=LIGHT_H):
    """rho / pi * E."""
    return np.asarray(rho) / math.pi * irradiance_closed_form(a, b, h) * np.asarray(le)


def test_light_scene_geometry(tmp_path):
    sc = light_scene(tmp_path, floor={"type": "diffuse", "reflectance": list(FLOOR_RHO)})
    em = sc.emitters
    np.testing.assert_allclose(sc.normals[em], [[0, 0, -1]] * 2, atol=1e-12)
    np.testing.assert_allclose(sc.areas[em].sum(), LIGHT_A * LIGHT_B)
    np.testing.assert_allclose(sc.triangles[em][..., 2], LIGHT_H)


@pytest.mark.parametrize("sampler", ["random", "bose", "sobol"])
@pytest.mark.parametrize("mis", [True, False], ids=["mis", "nomis"])
def test_direct_lighting_diffuse(tmp_path, mis, sampler):
    sc = light_scene(tmp_path, floor={"type": "diffuse", "reflectance": list(FLOOR_RHO)}, mis=mis)
    res = render(sc, sampler=sampler, spp=16, seed=7)
    assert res.dims == (6 if mis else 4)
    assert_mean(res.image, direct_diffuse(), f"direct lighting mis={mis} {sampler}")


def test_direct_lighting_square_light_and_depth(tmp_path):
    """A square light, nearer: and max_depth 1 (the floor is no emitter) is black."""
    sc = light_scene(tmp_path, floor={"type": "diffuse", "reflectance": [0.9, 0.9, 0.9]}, a=1.0, b=1.0, h=0.5)
    res = render(sc, sampler="random", spp=16, seed=1)
    assert_mean(res.image, direct_diffuse(rho=0.9, a=1.0, b=1.0, h=0.5), "square light")
    assert not np.any(render(sc, sampler="random", spp=4, max_depth=1).image)


def irradiance_offset(x0, x1, y0, y1, h, n=1000):
    """Irradiance at the origin from the parallel rectangle [x0, x1] x [y0, y1]
    at height h (unit radiance), by the midpoint rule."""
    xs = x0 + (np.arange(n) + 0.5) / n * (x1 - x0)
    ys = y0 + (np.arange(n) + 0.5) / n * (y1 - y0)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    return float(np.sum(h * h / (X**2 + Y**2 + h**2) ** 2) * (x1 - x0) / n * (y1 - y0) / n)


@pytest.mark.parametrize("mis", [True, False], ids=["mis", "nomis"])
def test_direct_lighting_two_unequal_lights(tmp_path, mis):
    """Two lights of different size and radiance (emitter triangles are picked
    in proportion to power): the irradiances add."""
    sc = light_scene(tmp_path, floor={"type": "diffuse", "reflectance": list(FLOOR_RHO)}, mis=mis)
    data = json.loads((tmp_path / "light.json").read_text())
    le2 = [1.0, 3.0, 9.0]
    data["shapes"].append({"type": "rectangle", "id": "light2", "material": "black", "emission": le2,
                           "to_world": affine(np.diag([0.2, -0.4, -1.0]), (0.7, 0.1, 0.8))})
    sc = write_scene(tmp_path, data, "two")
    assert len(sc.emitters) == 4
    e2 = irradiance_offset(0.5, 0.9, -0.3, 0.5, 0.8)
    want = direct_diffuse() + np.asarray(FLOOR_RHO) / math.pi * e2 * np.asarray(le2)
    res = render(sc, sampler="random", spp=32, seed=8)
    assert_mean(res.image, want, f"two lights mis={mis}")


@pytest.mark.parametrize("floor_size", [2.0, 20.0, 200.0])
@pytest.mark.parametrize("mis", [True, False], ids=["mis", "nomis"])
def test_direct_lighting_does_not_depend_on_the_floor_extent(tmp_path, mis, floor_size):
    """Direct light at the origin does not depend on how far the floor
    extends (the floor is lit, it casts no shadow). It does change the scene's
    size, and with it the integrator's ray offsets, which must not make a
    light shadow its own shadow rays."""
    floor = {"type": "diffuse", "reflectance": [0.9, 0.9, 0.9]}
    sc = light_scene(tmp_path, floor=floor, mis=mis, a=1.0, b=1.0, h=1.0, floor_size=floor_size)
    res = render(sc, sampler="random", spp=16, seed=3)
    assert_mean(res.image, direct_diffuse(rho=0.9, a=1.0, b=1.0, h=1.0), f"floor of half-side {floor_size}")


def test_direct_lighting_first_light1(tmp_path):
    """``first=['light1']`` moves the light sample to sampler dims 0, 1: other
    bits, same expectation."""
    sc = light_scene(tmp_path, floor={"type": "diffuse", "reflectance": list(FLOOR_RHO)}, mis=False)
    base = render(sc, sampler="bose", spp=16, seed=2)
    moved = render(sc, sampler="bose", spp=16, seed=2, first=["light1"])
    assert base.layout == "0:pixel.x, 1:pixel.y, 2:light1.u, 3:light1.v"
    assert moved.layout == "0:light1.u, 1:light1.v, 2:pixel.x, 3:pixel.y"
    assert base.dims == moved.dims == 4
    assert base.image.tobytes() != moved.image.tobytes()
    assert_mean(base.image, direct_diffuse(), "default layout")
    assert_mean(moved.image, direct_diffuse(), "light1 first")


# -- GGX: an independent evaluation, and MIS against light sampling alone --------------


def ggx_reflected_radiance(f0, alpha, le=LE, a=LIGHT_A, b=LIGHT_B, h=LIGHT_H, n=1500):
    """Radiance reflected straight up (wo = +z) by a GGX conductor at the
    origin lit by the light of :func:`light_scene`: the integral over the light
    of f(wo, wi) cos(theta_i) Le cos(theta_l) / r^2, with f the Cook-Torrance
    BRDF (GGX D, Smith height-correlated G2, Schlick F), written here
    independently of :mod:`pyoa.render.bsdfs`."""
    xs = (np.arange(n) + 0.5) / n * a - a / 2
    ys = (np.arange(n) + 0.5) / n * b - b / 2
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    r = np.sqrt(X**2 + Y**2 + h**2)
    wi = np.stack([X / r, Y / r, h / r], axis=-1)
    cos_i = wi[..., 2]
    hv = wi + np.array([0.0, 0.0, 1.0])
    hv /= np.linalg.norm(hv, axis=-1, keepdims=True)
    a2 = alpha * alpha
    D = 1.0 / (math.pi * a2 * ((hv[..., 0] ** 2 + hv[..., 1] ** 2) / a2 + hv[..., 2] ** 2) ** 2)
    tan2 = (1.0 - cos_i**2) / cos_i**2
    lam_i = (-1.0 + np.sqrt(1.0 + a2 * tan2)) / 2.0  # Lambda(wo) = 0 at normal incidence
    G2 = 1.0 / (1.0 + lam_i)
    cos_h = hv[..., 2]  # wo . h
    f0 = np.asarray(f0, dtype=np.float64)
    F = f0 + (1.0 - f0) * ((1.0 - cos_h) ** 5)[..., None]
    f_cos = F * (D * G2 / 4.0)[..., None]  # f cos_i with cos_o = 1
    cos_l = h / r
    w = (cos_l / r**2) * (a / n) * (b / n)
    return np.asarray(le) * np.einsum("ijk,ij->k", f_cos, w)


@pytest.mark.parametrize("alpha", [0.4, 0.08])
def test_ggx_known_answer_and_mis_consistency(tmp_path, alpha):
    """A GGX floor: MIS and light sampling alone are both unbiased, so they
    agree with each other and with the independently integrated answer."""
    floor = {"type": "ggx", "specular": [0.9, 0.6, 0.3], "roughness": alpha}
    expected = ggx_reflected_radiance([0.9, 0.6, 0.3], alpha)
    images = {}
    for mis in (True, False):
        sc = light_scene(tmp_path, floor=floor, mis=mis, fov=0.2)
        images[mis] = render(sc, sampler="random", spp=32, seed=4 + mis).image
        assert_mean(images[mis], expected, f"ggx alpha={alpha} mis={mis}", rel_floor=5e-3)
    assert_same_mean(images[True], images[False], f"ggx alpha={alpha}: mis vs light sampling")


def test_mis_reduces_variance_for_a_smooth_ggx(tmp_path):
    """For a fairly smooth lobe BSDF sampling does better than light sampling;
    MIS must not be worse than light sampling alone (a sanity check of the weights)."""
    floor = {"type": "ggx", "specular": [0.9, 0.9, 0.9], "roughness": 0.03}
    sds = {}
    for mis in (True, False):
        sc = light_scene(tmp_path, floor=floor, mis=mis, fov=0.2)
        sds[mis] = mean_se(render(sc, sampler="random", spp=16, seed=9).image)[1]
    assert np.all(sds[True] < sds[False])


def test_mis_weights_sum_to_one_at_a_light_corner(tmp_path):
    """The GGX lobe straddles the light's edge (light offset so that the
    mirror direction hits its corner): both strategies contribute in
    comparable proportions, where wrong MIS weights show most."""
    alpha = 0.15
    floor = {"type": "ggx", "specular": [1.0, 1.0, 1.0], "roughness": alpha}
    a = b = 0.6
    results = {}
    for mis in (True, False):
        sc = light_scene(tmp_path, floor=floor, mis=mis, a=a, b=b, fov=0.2)
        # move the light so that its corner is above the origin
        data = json.loads((tmp_path / "light.json").read_text())
        data["shapes"][1]["to_world"][0][3] = a / 2
        data["shapes"][1]["to_world"][1][3] = b / 2
        sc = write_scene(tmp_path, data, "corner")
        results[mis] = render(sc, sampler="random", spp=32, seed=21 + mis).image
    # reference: the full-light integral over the quarter [0, a] x [0, b]
    # equals, by symmetry, a quarter of the centred 2a x 2b light's
    expected = ggx_reflected_radiance([1, 1, 1], alpha, a=2 * a, b=2 * b, n=2000) / 4
    for mis, img in results.items():
        assert_mean(img, expected, f"corner light mis={mis}", rel_floor=5e-3)
    assert_same_mean(results[True], results[False], "corner light: mis vs light sampling")


# -- a mirror ----------------------------------------------------------------------------


@pytest.mark.parametrize("mis, depth", [(True, 2), (True, 3), (False, 3), (True, 6)])
def test_mirror_reflects_the_emitter(tmp_path, mis, depth):
    """A mirror floor seen from below the light shows tint * Le exactly (a
    delta BSDF: no noise, no light sampling, MIS weight 1)."""
    tint = [0.9, 0.6, 0.3]
    sc = light_scene(tmp_path, floor={"type": "mirror", "tint": tint}, mis=mis, max_depth=depth, fov=2.0)
    res = render(sc, sampler="random", spp=8, seed=1)
    np.testing.assert_allclose(res.image, np.broadcast_to(np.multiply(tint, LE), res.image.shape), rtol=1e-6)


def test_emitters_are_one_sided(tmp_path):
    """Emitters are one-sided: a camera below the light looking up sees Le,
    one above it looking down at its (black) back sees nothing."""
    light_scene(tmp_path, floor={"type": "diffuse"}, max_depth=4)
    data = json.loads((tmp_path / "light.json").read_text())
    data["camera"]["to_world"] = affine(np.eye(3), (0, 0, 0.5))  # below the light, looking up (+z)
    res = render(write_scene(tmp_path, data, "front"), sampler="random", spp=4, max_depth=1)
    np.testing.assert_array_equal(res.image, np.broadcast_to(np.float32(LE), res.image.shape))
    data["camera"]["to_world"] = affine(np.diag([-1.0, 1.0, -1.0]), (0, 0, 1.5))  # above, looking down
    res = render(write_scene(tmp_path, data, "back"), sampler="random", spp=4)
    assert not np.any(res.image)


# -- determinism --------------------------------------------------------------------------


@pytest.fixture(scope="module")
def cornell():
    return load("cornell")


def test_same_render_same_bits(cornell, shading):
    kw = dict(sampler="bose", spp=4, seed=3, width=16, height=12)
    a = render(cornell, **kw)
    assert a.shading == shading
    b = render(cornell, **kw)
    assert a.image.shape == (12, 16, 3) and a.image.dtype == np.float32
    assert a.image.tobytes() == b.image.tobytes()
    assert a.stats.paths == 16 * 12 * 4 and a.stats.rays == b.stats.rays


@pytest.mark.parametrize("sampler, spp", [("bose", 4), ("sobol", 4), ("random", 3)])
def test_batches_and_threads_do_not_change_bits(cornell, sampler, spp):
    kw = dict(sampler=sampler, spp=spp, seed=1, width=16, height=16)
    ref = render(cornell, **kw, threads=1).image.tobytes()
    for batch_paths, threads in ((64, 2), (1000, 1), (1000, 2), (1 << 16, 2), (1, 2)):
        img = render(cornell, **kw, batch_paths=batch_paths, threads=threads).image
        assert img.tobytes() == ref, f"batch_paths={batch_paths} threads={threads}"


@pytest.mark.parametrize("n", [1, 2, 7, 8, 9, 16, 17, 121, 128, 129, 255, 256, 1000, 1089, 4096, 4097, 8193, 16385])
def test_pixel_sums_are_each_pixel_s_contiguous_sums(n):
    """A pixel's sum is NumPy's sum of its n samples laid out contiguously (pairwise, in an order that depends
    on n alone), whether it is summed alone or with other pixels: the same bits in any batch."""
    rng = np.random.default_rng(n)
    pixels = 5
    rad = rng.standard_normal((pixels * n, 3)) * rng.choice([1e-9, 1.0, 1e9], (pixels * n, 3))
    rad[rng.random((pixels * n, 3)) < 0.1] = -0.0
    rad[-n:, 0] = -0.0  # a pixel whose samples are all -0 (NumPy's sum gives +0 or -0 depending on n)
    want = np.array([[np.ascontiguousarray(rad[p * n:(p + 1) * n, c]).sum() for c in range(3)] for p in range(pixels)])
    got = render_mod.pixel_sums(rad, n)
    assert got.shape == (pixels, 3) and got.dtype == np.float64
    assert got.tobytes() == want.tobytes()
    alone = np.concatenate([render_mod.pixel_sums(rad[p * n:(p + 1) * n], n) for p in range(pixels)])
    assert alone.tobytes() == got.tobytes()


def test_seeds_change_the_image_not_its_expectation(tmp_path, cornell):
    a = render(cornell, sampler="bose", spp=4, seed=0, width=16, height=16).image
    b = render(cornell, sampler="bose", spp=4, seed=1, width=16, height=16).image
    assert a.tobytes() != b.tobytes()
    assert np.mean(a != b) > 0.5
    sc = furnace_scene(tmp_path, mis=True, size=16)
    x = render(sc, sampler="random", spp=16, seed=100, max_depth=3).image
    y = render(sc, sampler="random", spp=16, seed=101, max_depth=3).image
    assert x.tobytes() != y.tobytes()
    assert_same_mean(x, y, "furnace seeds 100 and 101")


# -- the dimension layout ---------------------------------------------------------------------


def test_layout_names_and_counts():
    L = Layout(max_depth=3, mis=True, lens=True, time=True)
    assert L.names == ("pixel.x", "pixel.y", "lens.u", "lens.v", "time", "light1.u", "light1.v", "bsdf1.u",
                       "bsdf1.v", "light2.u", "light2.v", "bsdf2.u", "bsdf2.v")
    assert Layout(max_depth=3, mis=False, lens=False, time=False).names == (
        "pixel.x", "pixel.y", "light1.u", "light1.v", "bsdf1.u", "bsdf1.v", "light2.u", "light2.v")
    assert Layout(max_depth=1, mis=True, lens=False, time=False).dims == 2
    for depth in range(1, 15):
        for mis in (True, False):
            for lens in (True, False):
                for time in (True, False):
                    L = Layout(max_depth=depth, mis=mis, lens=lens, time=time)
                    want = 2 + 2 * lens + time + 4 * (depth - 1) - (2 if (depth > 1 and not mis) else 0)
                    assert L.dims == want == len(set(L.names))
    with pytest.raises(ValueError, match="max_depth"):
        Layout(max_depth=0, mis=True, lens=False, time=False)


def test_layout_first():
    L = Layout(max_depth=3, mis=False, lens=True, time=True, first=["light1", "time"])
    assert L.names[:3] == ("light1.u", "light1.v", "time")
    assert L.index("light1.u") == 0 and L.index("light1.v") == 1 and L.pair("light1") == (0, 1)
    assert L.pair("pixel") == (3, 4) and L.index("lens.u") == 5
    assert sorted(L.names) == sorted(Layout(max_depth=3, mis=False, lens=True, time=True).names)
    assert "bsdf2.u" not in L and "bsdf1.u" in L
    # a full name, repeats and overlaps are fine
    L = Layout(max_depth=2, mis=True, lens=False, time=False, first=["bsdf1.v", "bsdf1", "light1.u"])
    assert L.names == ("bsdf1.v", "bsdf1.u", "light1.u", "pixel.x", "pixel.y", "light1.v")
    assert L.describe().startswith("0:bsdf1.v, 1:bsdf1.u, 2:light1.u, 3:pixel.x")
    for bad in (["light2"], ["lens"], ["nonsense"], ["light"]):
        with pytest.raises(ValueError, match=r"valid: pixel\.x, pixel\.y, light1\.u, light1\.v"):
            Layout(max_depth=2, mis=True, lens=False, time=False, first=bad)


@pytest.mark.parametrize("name, dims, depth, mis, lens, time", [
    ("cornell", 18, 5, True, False, False),
    ("dof7d", 7, 2, False, True, True),
    ("bounce9d", 9, 3, False, False, True),
    ("deep", 46, 12, True, False, False),
])
def test_bundled_scene_dims(name, dims, depth, mis, lens, time):
    sc = load(name)
    assert (sc.max_depth, sc.mis, sc.camera.aperture > 0, bool(np.any(sc.camera.motion != 0))) == (depth, mis, lens,
                                                                                                 time)
    assert Layout(max_depth=depth, mis=mis, lens=lens, time=time).dims == dims
    res = render(sc, sampler="random", spp=1, width=4, height=4, max_depth=min(depth, 5))
    assert res.dims == Layout(max_depth=min(depth, 5), mis=mis, lens=lens, time=time).dims
    assert res.image.shape == (4, 4, 3) and np.all(np.isfinite(res.image)) and np.all(res.image >= 0)


def test_dof7d_renders_with_seven_dims():
    res = render(load("dof7d"), sampler="bose", spp=9, width=8, height=8)
    assert res.dims == 7
    assert res.layout == "0:pixel.x, 1:pixel.y, 2:lens.u, 3:lens.v, 4:time, 5:light1.u, 6:light1.v"
    assert res.image.mean() > 0


def test_render_rejects_bad_arguments(cornell):
    with pytest.raises(ValueError, match=r"unknown integrand dimension 'light9'; valid: pixel\.x"):
        render(cornell, spp=4, width=4, height=4, first=["light9"])
    with pytest.raises(ValueError, match=r"bose: 10 is not .*nearest: 9 \(s=3\), 16 \(s=4\)"):
        render(cornell, sampler="bose", spp=10, width=4, height=4)
    with pytest.raises(ValueError, match="filter"):
        render(cornell, spp=4, width=4, height=4, filter="tent")
    with pytest.raises(ValueError, match="max_depth"):
        render(cornell, spp=4, width=4, height=4, max_depth=0)
    with pytest.raises(ValueError, match=r"width must be >= 1, got -1"):
        render(cornell, spp=4, width=-1, height=4)


def test_gaussian_filter_keeps_the_furnace(tmp_path):
    """The Gaussian pixel filter only moves samples: a constant image stays constant."""
    sc = furnace_scene(tmp_path, mis=True, size=8)
    res = render(sc, sampler="random", spp=4, max_depth=1, filter="gaussian")
    np.testing.assert_array_equal(res.image, np.broadcast_to(np.float32(EMIT), res.image.shape))


# -- relative MSE ------------------------------------------------------------------------------


def test_rel_mse_by_hand():
    from pyoa.render.image import rel_mse

    ref = np.zeros((1, 2, 3), dtype=np.float32)
    ref[0, 0] = [1.0, 0.0, 0.1]
    ref[0, 1] = [2.0, 0.5, 0.0]
    img = ref.copy()
    assert rel_mse(img, ref) == 0.0
    img[0, 0, 0] = 2.0  # (2-1)^2 / (1 + 0.01)
    img[0, 1, 2] = 0.1  # (0.1-0)^2 / (0 + 0.01) = 1
    want = (1 / 1.01 + 0.01 / 0.01) / 6
    assert rel_mse(img, ref) == pytest.approx(want, rel=1e-6)
    # crop (x, y, w, h): only pixel (x=1, y=0)
    assert rel_mse(img, ref, (1, 0, 1, 1)) == pytest.approx(1.0 / 3, rel=1e-6)
    assert rel_mse(img, ref, (0, 0, 1, 1)) == pytest.approx(1 / 1.01 / 3, rel=1e-6)
    with pytest.raises(ValueError, match="does not fit"):
        rel_mse(img, ref, (1, 0, 2, 1))
    with pytest.raises(ValueError, match="does not fit"):
        rel_mse(img, ref, (0, 0, 0, 1))
    with pytest.raises(ValueError, match="differ in size"):
        rel_mse(img[:, :1], ref)
    # it is not symmetric: the reference sets the scale
    a = np.full((1, 1, 3), 1.0, dtype=np.float32)
    b = np.full((1, 1, 3), 3.0, dtype=np.float32)
    assert rel_mse(a, b) == pytest.approx(4 / 9.01, rel=1e-6)
    assert rel_mse(b, a) == pytest.approx(4 / 1.01, rel=1e-6)
