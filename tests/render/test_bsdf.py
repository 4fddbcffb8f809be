"""Tests of :mod:`pyoa.render.bsdfs` (the diffuse, mirror and GGX modules and
the registry's dispatch; the glass: test_dielectric.py): sample/evaluate
consistency, chi-square goodness of fit of the sampled directions against the
reported pdf, pdf normalization against an independent visible-normal
integral, energy conservation, reciprocity, the mirror delta lobe, the
material table built from the modules' keys and finiteness at extreme
inputs."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from pyoa.render.bsdfs import BSDFS, KINDS, Materials, evaluate, pdf, sample

DIFFUSE, MIRROR, GGX = KINDS["diffuse"], KINDS["mirror"], KINDS["ggx"]

N_CHI2 = 200_000


# --------------------------------------------------------------------------- helpers


def _wo(cos_theta: float, phi: float = 0.0) -> np.ndarray:
    s = np.sqrt(1.0 - cos_theta**2)
    return np.array([s * np.cos(phi), s * np.sin(phi), cos_theta])


def _random_dirs(rng, n, zmin=0.05):
    """Uniform directions on the upper hemisphere with z >= zmin."""
    z = rng.uniform(zmin, 1.0, n)
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    s = np.sqrt(1.0 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)


#: Each reflective kind's colour key
_COLOUR = {"diffuse": "reflectance", "mirror": "tint", "ggx": "specular"}


def _spec(name, kind, color, alpha=0.5):
    """A ``Materials.build`` spec of a reflective kind from its colour (and GGX roughness)."""
    values = {_COLOUR[kind]: color}
    if kind == "ggx":
        values["roughness"] = alpha
    return name, kind, values


def _mats(*specs) -> Materials:
    return Materials.build([_spec(*s) for s in specs])


def _one(kind: str, color=(1.0, 1.0, 1.0), alpha=0.5) -> Materials:
    return _mats(("m", kind, color, alpha))


class _Grid:
    """Hemisphere cells uniform in theta (edges in cos theta) and phi, with
    Gauss-Legendre nodes in (cos theta, phi) inside each cell, so that
    ``cell_integrals(values)`` integrates a function w.r.t. solid angle
    (d omega = d cos(theta) d phi) over every cell."""

    def __init__(self, n_theta=40, n_phi=64, order=6):
        self.n_theta, self.n_phi = n_theta, n_phi
        self.mu_edges = np.cos(np.linspace(0.0, np.pi / 2, n_theta + 1))[::-1]  # ascending in cos
        self.mu_edges[0] = 0.0
        self.phi_edges = np.linspace(0.0, 2.0 * np.pi, n_phi + 1)
        x, w = np.polynomial.legendre.leggauss(order)
        lo, hi = self.mu_edges[:-1], self.mu_edges[1:]
        mu = (0.5 * (hi - lo))[:, None] * x[None, :] + (0.5 * (hi + lo))[:, None]  # (T, k)
        wmu = (0.5 * (hi - lo))[:, None] * w[None, :]
        plo, phi_hi = self.phi_edges[:-1], self.phi_edges[1:]
        ph = (0.5 * (phi_hi - plo))[:, None] * x[None, :] + (0.5 * (phi_hi + plo))[:, None]  # (P, k)
        wph = (0.5 * (phi_hi - plo))[:, None] * w[None, :]
        # full node grid, shape (T, k, P, k)
        MU = np.broadcast_to(mu[:, :, None, None], (n_theta, order, n_phi, order))
        PH = np.broadcast_to(ph[None, None, :, :], (n_theta, order, n_phi, order))
        self.weights = wmu[:, :, None, None] * wph[None, None, :, :]
        self.shape = MU.shape
        s = np.sqrt(np.maximum(0.0, 1.0 - MU**2))
        self.dirs = np.stack([s * np.cos(PH), s * np.sin(PH), MU], axis=-1).reshape(-1, 3)

    def cell_integrals(self, values: np.ndarray) -> np.ndarray:
        """(n_theta, n_phi) integrals of ``values`` (one per node, trailing dims allowed)."""
        v = values.reshape(self.shape + values.shape[1:])
        w = self.weights.reshape(self.shape + (1,) * (values.ndim - 1))
        return (v * w).sum(axis=(1, 3))

    def histogram(self, wi: np.ndarray) -> np.ndarray:
        mu = np.clip(wi[:, 2], 0.0, 1.0)
        phi = np.mod(np.arctan2(wi[:, 1], wi[:, 0]), 2.0 * np.pi)
        it = np.clip(np.searchsorted(self.mu_edges, mu, side="right") - 1, 0, self.n_theta - 1)
        ip = np.clip(np.searchsorted(self.phi_edges, phi, side="right") - 1, 0, self.n_phi - 1)
        out = np.zeros((self.n_theta, self.n_phi))
        np.add.at(out, (it, ip), 1.0)
        return out


_GRID = None


def _grid() -> _Grid:
    global _GRID
    if _GRID is None:
        _GRID = _Grid()
    return _GRID


def _integrate(mats, wo, which):
    """Per-cell integrals of evaluate()'s f_cos (which=0, (T,P,3)) or pdf (which=1, (T,P))."""
    g = _grid()
    n = g.dirs.shape[0]
    out = evaluate(mats, np.zeros(n, dtype=np.int64), np.broadcast_to(wo, (n, 3)), g.dirs)[which]
    return g.cell_integrals(out)


def _chi2_pvalue(observed, expected, min_expected=5.0):
    """Pearson chi-square p-value, pooling cells whose expected count is < min_expected."""
    observed, expected = observed.ravel(), expected.ravel()
    small = expected < min_expected
    obs = np.append(observed[~small], observed[small].sum())
    exp = np.append(expected[~small], expected[small].sum())
    keep = exp > 0
    assert np.all(obs[~keep] == 0), "samples landed in cells of zero probability"
    obs, exp = obs[keep], exp[keep]
    stat = np.sum((obs - exp) ** 2 / exp)
    return stats.chi2.sf(stat, len(obs) - 1)


# reference GGX formulas in the classic tan-theta form (independent of the module's)
def _ref_d(h, alpha):
    cos2 = h[..., 2] ** 2
    tan2 = (1.0 - cos2) / cos2
    return 1.0 / (np.pi * alpha**2 * cos2**2 * (1.0 + tan2 / alpha**2) ** 2)


def _ref_g1(w, alpha):
    cos2 = w[..., 2] ** 2
    tan2 = (1.0 - cos2) / cos2
    return 2.0 / (1.0 + np.sqrt(1.0 + alpha**2 * tan2))


CASES = [("diffuse", None, 1.0), ("diffuse", None, 0.2)] + [
    ("ggx", a, c) for a in (0.1, 0.3, 0.8) for c in (1.0, 0.6, 0.2)
]
CASE_IDS = [f"{k}-a{a}-cos{c}" for k, a, c in CASES]


def _case_mats(kind, alpha, color=(1.0, 1.0, 1.0)):
    return _one(kind, color, 0.5 if alpha is None else alpha)


# --------------------------------------------------------------------------- consistency


@pytest.mark.parametrize("kind,alpha", [("diffuse", None), ("ggx", 1e-3), ("ggx", 0.05), ("ggx", 0.3), ("ggx", 1.0)])
def test_sample_agrees_with_evaluate(kind, alpha):
    rng = np.random.default_rng(1)
    n = 20_000
    mats = _case_mats(kind, alpha, (0.9, 0.5, 0.1))
    mat = np.zeros(n, dtype=np.int64)
    wo = _random_dirs(rng, n, zmin=0.01)
    wi, weight, pdf, delta = sample(mats, mat, wo, rng.random((n, 2)))
    assert not delta.any()
    np.testing.assert_allclose(np.linalg.norm(wi, axis=1), 1.0, atol=1e-12)
    f_cos, pdf_e = evaluate(mats, mat, wo, wi)
    np.testing.assert_allclose(pdf, pdf_e, rtol=1e-10, atol=0)
    pos = pdf > 0
    assert pos.mean() > 0.5
    np.testing.assert_allclose(weight[pos], f_cos[pos] / pdf[pos, None], rtol=1e-10, atol=1e-300)
    # below the surface: weight 0, pdf 0
    assert np.all(pos == (wi[:, 2] > 0))
    assert np.all(weight[~pos] == 0)
    assert np.all(weight >= 0)


def test_mixed_lanes_match_single_kind_calls():
    rng = np.random.default_rng(2)
    specs = [("d", "diffuse", (0.8, 0.2, 0.1)), ("m", "mirror", (0.9, 0.9, 0.5)),
             ("g", "ggx", (0.95, 0.64, 0.54), 0.25)]
    mats = _mats(*specs)
    n = 3000
    mat = rng.integers(0, 3, n)
    wo = _random_dirs(rng, n)
    u = rng.random((n, 2))
    wi_e = _random_dirs(rng, n)
    wi, weight, pdf, delta = sample(mats, mat, wo, u)
    f_cos, pdf_e = evaluate(mats, mat, wo, wi_e)
    for m in range(3):
        sel = mat == m
        single = _mats(specs[m])
        z = np.zeros(sel.sum(), dtype=np.int64)
        r = sample(single, z, wo[sel], u[sel])
        for a, b in zip((wi, weight, pdf, delta), r):
            np.testing.assert_array_equal(a[sel], b)
        r = evaluate(single, z, wo[sel], wi_e[sel])
        np.testing.assert_array_equal(f_cos[sel], r[0])
        np.testing.assert_array_equal(pdf_e[sel], r[1])
    assert np.array_equal(delta, mat == 1)


# --------------------------------------------------------------------------- chi-square


@pytest.mark.parametrize("kind,alpha,cos_o", CASES, ids=CASE_IDS)
def test_chi_square_sampled_directions_match_pdf(kind, alpha, cos_o):
    mats = _case_mats(kind, alpha)
    wo = _wo(cos_o)
    cells = _integrate(mats, wo, 1)
    total = cells.sum()
    assert total <= 1.0 + 1e-6
    rng = np.random.default_rng(12345)
    n = N_CHI2
    wi, _, pdf, _ = sample(mats, np.zeros(n, dtype=np.int64), np.broadcast_to(wo, (n, 3)), rng.random((n, 2)))
    above = pdf > 0
    observed = np.append(_grid().histogram(wi[above]).ravel(), np.count_nonzero(~above))
    expected = np.append(n * cells.ravel(), n * max(0.0, 1.0 - total))  # last cell: discarded samples
    p = _chi2_pvalue(observed, expected)
    assert p > 1e-3, f"chi-square p-value {p:.3g}"


# --------------------------------------------------------------------------- normalization


def test_diffuse_pdf_integrates_to_one():
    for cos_o in (1.0, 0.5, 1e-3):
        assert _integrate(_one("diffuse"), _wo(cos_o), 1).sum() == pytest.approx(1.0, abs=1e-9)


def _vndf_fraction_above(wo, alpha, n_theta=400, n_phi=512, order=4):
    """Independent reference: integral over microfacet normals h of the visible
    normal density D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z, in total and
    restricted to normals whose reflection of wo stays above the surface."""
    x, w = np.polynomial.legendre.leggauss(order)
    te = np.linspace(0.0, np.pi / 2, n_theta + 1)
    th = (0.5 * np.diff(te))[:, None] * x + (0.5 * (te[1:] + te[:-1]))[:, None]
    wt = (0.5 * np.diff(te))[:, None] * w * np.sin(th)
    pe = np.linspace(0.0, 2 * np.pi, n_phi + 1)
    ph = (0.5 * np.diff(pe))[:, None] * x + (0.5 * (pe[1:] + pe[:-1]))[:, None]
    wp = (0.5 * np.diff(pe))[:, None] * w
    th, wt, ph, wp = th.ravel(), wt.ravel(), ph.ravel(), wp.ravel()
    T, P = np.meshgrid(th, ph, indexing="ij")
    W = np.outer(wt, wp)
    h = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1)
    cos_oh = h @ wo
    dwo = _ref_g1(wo, alpha) * np.maximum(0.0, cos_oh) * _ref_d(h, alpha) / wo[2]
    wi_z = 2.0 * cos_oh * h[..., 2] - wo[2]
    return np.sum(dwo * W), np.sum(dwo * W * (wi_z > 0))


@pytest.mark.parametrize("alpha,cos_o", [(a, c) for a in (0.1, 0.3, 0.8) for c in (1.0, 0.6, 0.2)])
def test_ggx_pdf_integrates_to_fraction_above(alpha, cos_o):
    wo = _wo(cos_o)
    integral = _integrate(_one("ggx", alpha=alpha), wo, 1).sum()
    full, above = _vndf_fraction_above(wo, alpha)
    assert full == pytest.approx(1.0, abs=2e-4)  # the visible-normal density is normalized
    assert integral <= 1.0 + 1e-6
    assert integral == pytest.approx(above, abs=2e-4)


# --------------------------------------------------------------------------- energy


@pytest.mark.parametrize("kind,alpha,cos_o", CASES, ids=CASE_IDS)
def test_albedo_quadrature_matches_sample_weights(kind, alpha, cos_o):
    color = (1.0, 0.7, 0.25)
    mats = _case_mats(kind, alpha, color)
    white = _case_mats(kind, alpha)
    wo = _wo(cos_o)
    quad = _integrate(mats, wo, 0).sum(axis=(0, 1))
    quad_white = _integrate(white, wo, 0).sum(axis=(0, 1))
    rng = np.random.default_rng(7)
    n = 100_000
    _, weight, _, _ = sample(mats, np.zeros(n, dtype=np.int64), np.broadcast_to(wo, (n, 3)), rng.random((n, 2)))
    mc = weight.mean(axis=0)
    err = weight.std(axis=0) / np.sqrt(n)
    assert np.all(np.abs(mc - quad) <= 5 * err + 2e-4), (mc, quad, err)
    assert np.all(quad_white <= 1.0 + 1e-4)
    if kind == "diffuse":
        np.testing.assert_allclose(quad, color, atol=1e-9)
        np.testing.assert_allclose(mc, color, rtol=1e-9)
        assert np.all(weight == np.asarray(color))  # Malley's method: weight is exactly the reflectance
    else:
        assert np.all(weight <= 1.0 + 1e-12)  # weight = F G2 / G1(wo) <= F <= 1
        if alpha <= 0.1 and cos_o >= 0.6:
            assert quad_white[0] > 0.97  # little single-scattering loss for smooth GGX


# --------------------------------------------------------------------------- reciprocity


@pytest.mark.parametrize("kind,alpha", [("diffuse", None), ("ggx", 0.02), ("ggx", 0.3), ("ggx", 0.9)])
def test_reciprocity(kind, alpha):
    rng = np.random.default_rng(3)
    n = 20_000
    mats = _case_mats(kind, alpha, (0.3, 0.6, 0.9))
    mat = np.zeros(n, dtype=np.int64)
    a, b = _random_dirs(rng, n), _random_dirs(rng, n)
    f_ab = evaluate(mats, mat, a, b)[0] / b[:, 2:3]
    f_ba = evaluate(mats, mat, b, a)[0] / a[:, 2:3]
    np.testing.assert_allclose(f_ab, f_ba, rtol=1e-10, atol=0)
    assert np.all(f_ab >= 0)


# --------------------------------------------------------------------------- mirror


def test_mirror_is_a_tinted_delta_reflection():
    rng = np.random.default_rng(4)
    n = 1000
    mats = _one("mirror", (0.9, 0.5, 0.25))
    mat = np.zeros(n, dtype=np.int64)
    wo = _random_dirs(rng, n, zmin=1e-4)
    wi, weight, pdf, delta = sample(mats, mat, wo, rng.random((n, 2)))
    np.testing.assert_array_equal(wi, wo * [-1.0, -1.0, 1.0])
    np.testing.assert_array_equal(weight, np.broadcast_to([0.9, 0.5, 0.25], (n, 3)))
    assert delta.all() and np.all(pdf == 0)
    f_cos, pdf_e = evaluate(mats, mat, wo, wi)
    assert np.all(f_cos == 0) and np.all(pdf_e == 0)


def test_evaluate_is_zero_below_the_surface():
    rng = np.random.default_rng(5)
    n = 1000
    mats = _mats(("d", "diffuse", (1, 1, 1)), ("g", "ggx", (1, 1, 1), 0.5))
    mat = rng.integers(0, 2, n)
    wo = _random_dirs(rng, n)
    wi = _random_dirs(rng, n, zmin=0.0) * [1.0, 1.0, -1.0]
    f_cos, pdf = evaluate(mats, mat, wo, wi)
    assert np.all(f_cos == 0) and np.all(pdf == 0)


# --------------------------------------------------------------------------- Materials.build


def test_build_arrays():
    mats = Materials.build([("a", "diffuse", {"reflectance": (0.1, 0.2, 0.3)}),
                            ("b", "ggx", {"specular": (1, 1, 1), "roughness": 0.2}),
                            ("c", "mirror", {"tint": (0, 0, 0)}), ("d", "ggx", {}), ("e", "diffuse", {})])
    assert mats.names == ("a", "b", "c", "d", "e")
    assert mats.kind.dtype == np.int32 and list(mats.kind) == [DIFFUSE, GGX, MIRROR, GGX, DIFFUSE]
    assert mats.params.dtype == np.float64 and mats.params.shape == (5, 4)
    np.testing.assert_array_equal(mats.params[:3], [[0.1, 0.2, 0.3, 0], [1, 1, 1, 0.2], [0, 0, 0, 0]])
    np.testing.assert_array_equal(mats.params[3:], [[1, 1, 1, 0.1], [0.5, 0.5, 0.5, 0]])  # the keys' defaults
    with pytest.raises(ValueError):
        mats.params[0, 0] = 0.5  # read-only


def test_the_registry_keeps_the_kinds_of_the_bundled_scenes():
    """The bundled scenes' images depend on the kind ids (the compiled
    shading's first kind is the Lambertian): the registry keeps them, a new
    BSDF goes at the end, and every module says what the renderer reads."""
    assert list(KINDS) == ["diffuse", "mirror", "ggx", "dielectric"]
    assert [m.NAME for m in BSDFS] == list(KINDS) and list(KINDS.values()) == [0, 1, 2, 3]
    for m in BSDFS:
        assert isinstance(m.DELTA, bool) and isinstance(m.LANES, bool) and m.KEYS
        assert all(callable(getattr(m, f)) for f in ("params", "sample", "evaluate", "pdf", "sample_point",
                                                    "evaluate_point"))
        assert m.__doc__ and "References" in m.__doc__


def test_build_unknown_kind_names_valid_kinds():
    with pytest.raises(ValueError) as exc:
        Materials.build([("a", "glass", {})])
    msg = str(exc.value)
    assert "glass" in msg and all(k in msg for k in KINDS)


def test_build_unknown_key_names_the_valid_ones():
    with pytest.raises(ValueError, match="diffuse has no key 'roughness'; valid: reflectance"):
        Materials.build([("a", "diffuse", {"roughness": 0.1})])


@pytest.mark.parametrize("color", [(1.5, 0, 0), (0, -0.1, 0), (0.5, 0.5), (0.5, 0.5, 0.5, 0.5), (np.nan, 0, 0), "red"])
def test_build_rejects_bad_color(color):
    with pytest.raises(ValueError, match=r"'a': diffuse reflectance must be 3 numbers, each in \[0, 1\]"):
        Materials.build([("a", "diffuse", {"reflectance": color})])


@pytest.mark.parametrize("alpha", [0.0, -0.1, 1.5, np.nan, np.inf, "rough"])
def test_build_rejects_bad_ggx_roughness(alpha):
    with pytest.raises(ValueError, match=r"ggx roughness must be a number in \(0, 1\]"):
        Materials.build([("a", "ggx", {"roughness": alpha})])


def test_build_rejects_duplicates():
    with pytest.raises(ValueError, match="duplicate"):
        Materials.build([("a", "diffuse", {}), ("a", "mirror", {})])


def test_pdf_is_evaluate_s():
    rng = np.random.default_rng(8)
    n = 2000
    mats = _mats(("d", "diffuse", (0.5, 0.5, 0.5)), ("m", "mirror", (1, 1, 1)), ("g", "ggx", (1, 1, 1), 0.3))
    mat = rng.integers(0, 3, n)
    wo = _random_dirs(rng, n)
    wi = rng.normal(size=(n, 3))
    wi /= np.linalg.norm(wi, axis=1)[:, None]
    np.testing.assert_array_equal(pdf(mats, mat, wo, wi), evaluate(mats, mat, wo, wi)[1])
    assert np.any(pdf(mats, mat, wo, wi) > 0) and np.all(pdf(mats, mat, wo, wi)[mat == MIRROR] == 0)


# --------------------------------------------------------------------------- finiteness


def test_outputs_finite_at_extremes():
    mats = _mats(
        ("d", "diffuse", (1, 1, 1)),
        ("m", "mirror", (1, 1, 1)),
        ("g0", "ggx", (1, 1, 1), 1e-9),  # clamped to 1e-3
        ("g1", "ggx", (0.5, 0.5, 0.5), 1e-3),
        ("g2", "ggx", (0.0, 0.0, 0.0), 0.5),
        ("g3", "ggx", (1, 1, 1), 1.0),
    )
    edge = [0.0, 2.0**-24, 0.5, 1.0 - 2.0**-24]
    us = np.array([(a, b) for a in edge for b in edge])
    wos = np.array([_wo(c, p) for c in (1e-4, 1e-2, 0.5, 1.0) for p in (0.0, 0.7, np.pi)])
    wos[-1] = (0.0, 0.0, 1.0)
    M, W, U = np.meshgrid(np.arange(6), np.arange(len(wos)), np.arange(len(us)), indexing="ij")
    mat, wo, u = M.ravel(), wos[W.ravel()], us[U.ravel()]
    wi, weight, pdf, delta = sample(mats, mat, wo, u)
    for a in (wi, weight, pdf):
        assert np.all(np.isfinite(a))
    assert np.all(weight >= 0) and np.all(pdf >= 0) and np.all(weight <= 1.0 + 1e-9)
    np.testing.assert_allclose(np.linalg.norm(wi, axis=1), 1.0, atol=1e-9)
    f_cos, pdf_e = evaluate(mats, mat, wo, wi)
    assert np.all(np.isfinite(f_cos)) and np.all(np.isfinite(pdf_e))
    np.testing.assert_allclose(pdf_e, pdf, rtol=1e-9)
    # evaluate at grazing and exact-mirror incident directions, and wi == wo
    for wi2 in (wo * [-1.0, -1.0, 1.0], wo, np.broadcast_to(_wo(1e-4, 2.0), wo.shape)):
        f_cos, pdf_e = evaluate(mats, mat, wo, wi2)
        assert np.all(np.isfinite(f_cos)) and np.all(np.isfinite(pdf_e))
        assert np.all(f_cos >= 0) and np.all(pdf_e >= 0)


def test_invalid_wo_lanes_are_zero_not_nan():
    mats = _mats(("d", "diffuse", (1, 1, 1)), ("g", "ggx", (1, 1, 1), 0.3), ("m", "mirror", (1, 1, 1)))
    wo = np.array([[1.0, 0.0, 0.0], [0.6, 0.0, -0.8], [1.0, 0.0, 0.0]])
    wi, weight, pdf, _ = sample(mats, np.array([0, 1, 2]), wo, np.full((3, 2), 0.3))
    assert np.all(np.isfinite(wi)) and np.all(weight == 0) and np.all(pdf == 0)


def test_empty_batch():
    mats = _one("ggx", alpha=0.3)
    wi, weight, pdf, delta = sample(mats, np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros((0, 2)))
    assert wi.shape == (0, 3) and weight.shape == (0, 3) and pdf.shape == (0,) and delta.shape == (0,)
    f_cos, pdf = evaluate(mats, np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros((0, 3)))
    assert f_cos.shape == (0, 3) and pdf.shape == (0,)
