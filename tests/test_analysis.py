"""Tests of pyoa.analysis: stratification checks, discrepancy, integrands, convergence."""

from __future__ import annotations

import itertools
import math
from fractions import Fraction

import numpy as np
import pytest
from scipy import integrate
from scipy.stats import qmc

import pyoa
from pyoa import analysis as A

BACKEND = "numpy"  # the bits are the same on every backend; NumPy needs no device


def grid(m: int, d: int) -> np.ndarray:
    """The m^d cell centres of a regular grid, (m^d, d) float64."""
    idx = np.stack(np.meshgrid(*[np.arange(m)] * d, indexing="ij"), -1).reshape(-1, d)
    return (idx + 0.5) / m


# ============================================================================ cells

def test_cells_exact_for_float64_and_float32():
    # 0.3 (float64) is just below 3/10, but 0.3 * 10 rounds to 3.0
    assert float(np.float64(0.3) * 10) == 3.0
    assert A.cells(np.array([0.3]), 10)[0] == 2
    rng = np.random.default_rng(1)
    x = np.concatenate([rng.random(2000), np.arange(1, 1000) / 1000, np.arange(1, 97) / 97])
    for s in (3, 7, 10, 97, 1000, 2**24 - 3):
        want = np.array([math.floor(Fraction(float(v)) * s) for v in x])
        np.testing.assert_array_equal(A.cells(x, s), want)
        x32 = x.astype(np.float32)
        want32 = np.array([math.floor(Fraction(float(v)) * s) for v in x32])
        np.testing.assert_array_equal(A.cells(x32, s), want32)


# ============================================================================ stratification

def test_regular_grid_is_stratified():
    g = grid(4, 2)
    r = A.stratification(g, 4, 2)
    assert r.passed and bool(r) and r.failing == [] and r.max_deviation == 0
    assert (r.n_subsets, r.per_cell, r.n_points, r.n_sets) == (1, 1, 16, 1)
    g3 = grid(3, 3)
    assert A.stratification(g3, 3, 3).passed
    assert A.stratification(g3, 3, 2).passed and A.stratification(g3, 3, 1).passed
    assert "stratified" in str(A.stratification(g3, 3, 2))
    # a grid is not a Latin hypercube: each axis has only m distinct values
    lh = A.latin_hypercube(g)
    assert not lh and lh.failing == [(0,), (1,)] and lh.failing_dims == [0, 1]
    assert lh.max_deviation == 3  # 4 points in one of the 16 cells


def test_points_in_one_cell_fail_and_name_the_pairs():
    x = np.full((16, 3), 0.1)
    r = A.stratification(x, 2, 2)
    assert not r.passed
    assert r.failing == [(0, 1), (0, 2), (1, 2)]
    assert r.max_deviation == 16 - 4
    assert "NOT stratified" in str(r) and "(0, 2)" in str(r)


def test_only_the_coupled_pair_fails():
    g = grid(5, 2)
    x = np.column_stack([g, g[:, 0]])  # dim 2 repeats dim 0: pair (0, 2) lies on the diagonal
    r = A.stratification(x, 5, 2)
    assert r.failing == [(0, 2)] and r.failing_dims == [0, 2]
    assert A.stratification(x, 5, 2, dims=[1, 2]).passed
    assert A.stratification(x, 5, 2, dims=[2, 0]).failing == [(0, 2)]  # dims are sorted


def test_bose_strength_2_not_3():
    # jitter 0: points sit at fine-cell centres, far from every edge
    smp = pyoa.sampler("bose", spp=64, dims=9, seed=3, jitter=0.0, backend=BACKEND)  # s = 8, one block
    x = smp.generate(pixels=range(32))
    r = A.stratification(x, smp.s, 2, dims=range(smp.block_dims))
    assert r.passed and r.n_subsets == 36 and r.n_sets == 32
    # strength 3 at 4 levels (4^3 = N): an OA of strength 2 is not one of strength 3
    r3 = A.stratification(x, 4, 3)
    assert not r3 and len(r3.failing) == r3.n_subsets == 84
    # the default jittered points are stratified in pairs too
    xj = pyoa.sampler("bose", spp=121, dims=12, seed=5, backend=BACKEND).generate(pixels=range(64))
    assert A.stratification(xj, 11, 2).passed
    # Bush of strength 3 with the same N is
    bush = pyoa.sampler("bush", spp=64, dims=5, strength=3, seed=3, jitter=0.0, backend=BACKEND)
    assert A.stratification(bush.generate(pixels=range(32)), 4, 3).passed


def test_cmjnd_strength_3():
    smp = pyoa.sampler("cmjnd", spp=125, dims=3, seed=11, backend=BACKEND)
    assert (smp.s, smp.strength) == (5, 3)
    x = smp.generate(pixels=range(64))
    r = A.stratification(x, 5, 3)
    assert r.passed and r.n_subsets == 1
    # beyond its block (t dims), the next copy is independent: (2, 3) is not stratified jointly
    x6 = pyoa.sampler("cmjnd", spp=125, dims=6, seed=11, jitter=0.0, backend=BACKEND).generate(pixels=range(16))
    assert A.stratification(x6, 5, 3, dims=[0, 1, 2]).passed
    assert (0, 1, 3) in A.stratification(x6, 5, 3).failing


def test_latin_hypercube_cmj_vs_centered():
    cmj = pyoa.sampler("bose", spp=121, dims=12, seed=2, jitter=0.0, backend=BACKEND).generate(pixels=range(16))
    assert A.latin_hypercube(cmj).passed
    cen = pyoa.sampler("bose", spp=121, dims=12, seed=2, offset="centered", backend=BACKEND)
    r = A.latin_hypercube(cen.generate(pixels=range(4)))
    assert not r and r.failing_dims == list(range(12))
    assert r.max_deviation == 10  # 11 points of a stratum share its middle fine cell


def test_stratification_rejects_bad_input():
    g = grid(4, 2)
    with pytest.raises(ValueError, match="must divide N"):
        A.stratification(g, 3, 2)
    with pytest.raises(ValueError, match=r"\[0, 1\)"):
        A.stratification(np.ones((4, 2)), 2, 2)
    with pytest.raises(ValueError, match=r"\[0, 1\)"):
        A.stratification(-g, 4, 2)
    with pytest.raises(ValueError, match="finite"):
        A.stratification(np.full((4, 2), np.nan), 2, 2)
    with pytest.raises(ValueError, match="shape"):
        A.stratification(np.zeros(4), 2, 1)
    with pytest.raises(ValueError, match="t must be"):
        A.stratification(g, 2, 3)
    with pytest.raises(ValueError, match="distinct"):
        A.stratification(g, 2, 1, dims=[0, 0])
    with pytest.raises(ValueError, match="dims entry"):
        A.stratification(g, 2, 1, dims=[2])
    with pytest.raises(ValueError, match="s must be"):
        A.stratification(g, 0, 1)
    with pytest.raises(ValueError, match="real"):
        A.stratification(np.zeros((4, 2), dtype=complex), 2, 1)
    with pytest.raises(ValueError, match="over the limit"):
        A.stratification(np.zeros((1, 200)), 1, 4)  # C(200, 4) = 64.7 million subsets


# ============================================================================ discrepancy

def test_discrepancy_matches_scipy_and_ranks_sets():
    rng = np.random.default_rng(0)
    g = grid(8, 2)
    r = rng.random((64, 2))
    for method in ("CD", "WD", "MD", "L2-star"):
        assert A.discrepancy(g, method) == pytest.approx(qmc.discrepancy(g, method=method), rel=1e-12)
    assert A.discrepancy(g) < A.discrepancy(r)
    x = pyoa.sampler("bose", spp=64, dims=2, backend=BACKEND).generate(pixels=range(3))
    many = A.discrepancy(x)
    assert many.shape == (3,)
    assert many[1] == pytest.approx(qmc.discrepancy(x[1].astype(np.float64)), rel=1e-12)
    with pytest.raises(ValueError, match="method"):
        A.discrepancy(g, "XX")
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        A.discrepancy(g + 1)
    assert A.discrepancy(np.ones((4, 2))) >= 0  # the closed cube is accepted


# ============================================================================ integrands

def _gauss_legendre(f, d: int, n: int) -> float:
    """Tensor Gauss-Legendre rule with n nodes per axis on [0, 1]^d."""
    t, w = np.polynomial.legendre.leggauss(n)
    t, w = (t + 1) / 2, w / 2
    pts = np.stack(np.meshgrid(*[t] * d, indexing="ij"), -1).reshape(-1, d)
    wts = np.prod(np.stack(np.meshgrid(*[w] * d, indexing="ij"), -1).reshape(-1, d), axis=-1)
    return float(np.sum(wts * f(pts)))


SMOOTH = ["gaussian", "anisotropic-gaussian", "oscillatory", "pairwise", "lagged-pairs", "additive"]
DISCONTINUOUS = ["halfspace", "diagonal-halfspace", "ball"]


def test_registry():
    assert set(A.INTEGRANDS) == set(SMOOTH + DISCONTINUOUS)
    for name in A.INTEGRANDS:
        f = A.INTEGRANDS[name](3)
        g, exact = f  # unpacks as (f, exact)
        assert g is f and exact == f.exact and f.d == 3 and f.name == name
        assert f.smooth == (name in SMOOTH)
        assert f.coupling == {"pairwise": "pairs", "lagged-pairs": "pairs", "additive": "none"}.get(name, "all")
        assert f(np.full((5, 3), 0.25)).shape == (5,)
        assert f(np.full(3, 0.25)).shape == ()
    with pytest.raises(ValueError, match="unknown integrand"):
        A.integrand("nope", 2)


@pytest.mark.parametrize("name", SMOOTH)
def test_smooth_exact_values(name):
    for d in (1, 2, 3, 4):
        if name in ("pairwise", "lagged-pairs") and d == 1:
            continue
        f = A.INTEGRANDS[name](d)
        assert _gauss_legendre(f, d, 40 if d < 4 else 24) == pytest.approx(f.exact, rel=1e-10, abs=1e-13)
    # and through scipy.integrate in 2D
    f = A.INTEGRANDS[name](2)
    val, err = integrate.dblquad(lambda y, x: float(f(np.array([x, y]))), 0, 1, 0, 1, epsabs=1e-12, epsrel=1e-11)
    assert val == pytest.approx(f.exact, rel=1e-9, abs=1e-12)


def test_lagged_pairs_couples_only_dimensions_lag_apart():
    """Its mixed second difference is zero for every pair except those ``lag``
    apart; the default lag is d // 2; a bad lag is refused."""
    f = A.lagged_pairs(6, 4)
    x0 = np.full(6, 0.3)

    def mixed(a, b, h=0.2):
        e_a, e_b = np.eye(6)[a] * h, np.eye(6)[b] * h
        return float(f(x0 + e_a + e_b) - f(x0 + e_a) - f(x0 + e_b) + f(x0))

    for a, b in itertools.combinations(range(6), 2):
        assert (abs(mixed(a, b)) > 1e-6) == (b - a == 4), (a, b)
    assert "x_(k+3)" in A.lagged_pairs(7).formula
    with pytest.raises(ValueError, match="lag"):
        A.lagged_pairs(4, 4)


def test_old_block_rule_fails_lagged_pairs():
    """The cross-block integrand at lag B (Bose 121, B = 12): the block rule
    pairs blocks at random and estimates it with about the variance of
    independent points or less (measured: 0.24x); the old rule (block 1 read
    at row i, made here by undoing block 1's order of the rows) has more than
    independent points (2.9x) and 12x the block rule's."""
    from pyoa._numpy.oa import block_order_seed, block_row
    from pyoa.hashes import block_seed, pixel_seed

    smp = pyoa.sampler("bose", spp=121, dims=24, seed=3, backend=BACKEND)
    B, N, pixels = smp.block_dims, smp.spp, np.arange(256)
    f = A.lagged_pairs(24, B)
    x = smp.generate(pixels=pixels).astype(np.float64)
    r = block_order_seed(block_seed(pixel_seed(3, pixels), 1), 1, N)  # block 1's order, per pixel
    rows = block_row(np.arange(N, dtype=np.uint32)[None, :], N, r[:, None])
    old = x.copy()
    old[np.arange(len(pixels))[:, None], rows, B:] = x[:, :, B:]  # sample rows[i] of the old rule is sample i now
    rnd = pyoa.sampler("random", spp=N, dims=24, seed=3, backend=BACKEND).generate(pixels=pixels)
    v_new, v_old, v_rnd = (f(p).mean(axis=1).var() for p in (x, old, rnd))
    assert v_new < v_rnd < v_old / 2 and v_old > 8 * v_new, (v_new, v_old, v_rnd)


def test_closed_forms():
    s = 0.15
    i1 = s * math.sqrt(2 * math.pi) * math.erf(1 / (2 * math.sqrt(2) * s))
    assert A.gaussian(2).exact == pytest.approx(i1**2, rel=1e-14)
    # Irwin-Hall values, and the symmetric half-space
    assert A.diagonal_halfspace(2, 1.0).exact == 0.5
    assert A.diagonal_halfspace(3, 1.0).exact == pytest.approx(1 / 6, rel=1e-15)
    assert A.diagonal_halfspace(3, 1.5).exact == 0.5
    assert A.diagonal_halfspace(3, 2.0).exact == pytest.approx(5 / 6, rel=1e-15)
    w = np.linspace(1, 2, 5)
    assert A.halfspace(5, w, 0.5 * w.sum()).exact == pytest.approx(0.5, rel=1e-15)
    assert A.halfspace(4, c=-1.0).exact == 0.0 and A.halfspace(4, c=100.0).exact == 1.0
    # unequal weights through the vertex sum, equal ones through Irwin-Hall: the same volume
    assert A.halfspace(4, [1, 1, 1, 1 + 2**-40], 1.7).exact == pytest.approx(A.diagonal_halfspace(4, 1.7).exact,
                                                                             rel=1e-9)
    assert A.ball(2, 0.4).exact == pytest.approx(math.pi * 0.16, rel=1e-14)
    assert A.ball(3, 0.5).exact == pytest.approx(math.pi / 6, rel=1e-14)


def test_discontinuous_exact_values_by_quadrature():
    # 1D and 2D: integrate the exact 1D sections with scipy.integrate.quad
    for name in DISCONTINUOUS:
        f = A.INTEGRANDS[name](1)
        val, _ = integrate.quad(lambda x: float(f(np.array([x]))), 0, 1, points=[0.05, 0.4, 0.95], limit=200)
        assert val == pytest.approx(f.exact, abs=1e-10)
    h = A.halfspace(2)  # w = (1, 2), c = 1.2
    w, c = np.array([1.0, 2.0]), 1.2
    val, _ = integrate.quad(lambda x: min(max((c - w[0] * x) / w[1], 0.0), 1.0), 0, 1, epsabs=1e-13)
    assert val == pytest.approx(h.exact, rel=1e-12)
    dh = A.diagonal_halfspace(2)  # x + y < 0.8
    val, _ = integrate.quad(lambda x: min(max(0.8 - x, 0.0), 1.0), 0, 1, points=[0.8], epsabs=1e-13)
    assert val == pytest.approx(dh.exact, rel=1e-12)
    b = A.ball(3)  # slices are discs of radius sqrt(r^2 - (x - 1/2)^2)
    val, _ = integrate.quad(lambda x: math.pi * max(0.45**2 - (x - 0.5) ** 2, 0.0), 0, 1, points=[0.05, 0.95])
    assert val == pytest.approx(b.exact, rel=1e-12)


@pytest.mark.parametrize("name", DISCONTINUOUS)
@pytest.mark.parametrize("d", [3, 5, 6])
def test_discontinuous_exact_values_by_sobol(name, d):
    """16 independently scrambled Sobol sets of 2^15 points: the mean lies
    within 5 standard errors of the exact value, and the error is tiny."""
    f = A.INTEGRANDS[name](d)
    est = [f(qmc.Sobol(d, scramble=True, seed=k).random_base2(15)).mean() for k in range(16)]
    mean, se = np.mean(est), np.std(est, ddof=1) / 4
    assert abs(mean - f.exact) <= 5 * se + 1e-12
    assert abs(mean - f.exact) < 1e-3


def test_integrand_rejects_bad_input():
    with pytest.raises(ValueError, match="radius"):
        A.ball(2, 0.6)
    with pytest.raises(ValueError, match="> 0"):
        A.halfspace(2, [1.0, -1.0])
    with pytest.raises(ValueError, match="d must be"):
        A.pairwise(1)
    with pytest.raises(ValueError, match="d must be"):
        A.gaussian(0)
    with pytest.raises(ValueError, match="2 numbers"):
        A.gaussian(2, sigma=[0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match="supports d"):
        A.halfspace(A.HALFSPACE_MAX_D + 1)
    # equal weights: any d; Irwin-Hall(40) at 16 is near the normal CDF at (16 - 20) / sqrt(40/12)
    assert A.diagonal_halfspace(40).exact == pytest.approx(0.5 * math.erfc(4 / math.sqrt(40 / 12) / math.sqrt(2)),
                                                           abs=2e-3)
    with pytest.raises(ValueError, match="3-dimensional"):
        A.gaussian(3)(np.zeros((4, 2)))


# ============================================================================ convergence

TARGETS = [16, 64, 256, 1024, 4096]


@pytest.fixture(scope="module")
def smooth2d():
    return A.convergence(["random", "jittered2d", "bose", "bush", "cmjnd"], "gaussian", 2, TARGETS, trials=128,
                         seed=1, backend=BACKEND)


def test_convergence_slopes(smooth2d):
    r = smooth2d
    assert r.samplers == ["random", "jittered2d", "bose", "bush", "cmjnd"] and not r.skipped
    np.testing.assert_array_equal(r.spp["random"], TARGETS)
    np.testing.assert_array_equal(r.spp["bose"], [16, 64, 256, 1024, 4096])
    assert abs(r.slope["random"] + 1) <= 0.25
    assert r.slope["jittered2d"] < r.slope["random"] - 0.5  # about -2 (N^(-1-2/d))
    assert r.slope["bose"] < r.slope["random"] - 0.5
    assert r.slope["bose"] < r.slope["jittered2d"]  # the CMJ offsets make a 2D Bose set a scrambled-net-like set
    for name in r.samplers:
        assert r.variance[name].shape == r.mse[name].shape == r.mean[name].shape == r.spp[name].shape
        assert np.all(r.variance[name] > 0)
        assert abs(r.mean[name][-1] - r.integrand.exact) < 5 * math.sqrt(r.variance[name][-1] / r.trials) + 1e-12
        assert abs(r.mse_slope[name] - r.slope[name]) < 0.2  # unbiased: MSE ~ variance
    assert r.strength == {"random": None, "jittered2d": None, "bose": None, "bush": 2, "cmjnd": 2}


def test_convergence_table_and_plot(smooth2d, tmp_path):
    t = smooth2d.table()
    assert "| sampler | spp | mean | variance | MSE |" in t and "| random | 4096 |" in t
    assert f"| bose | {smooth2d.slope['bose']:.3f} |" in t
    out = smooth2d.plot(tmp_path / "conv.png")
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    import matplotlib.image

    img = matplotlib.image.imread(out)
    assert img.shape[0] >= 300 and img.shape[1] >= 400 and img.ndim == 3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["conv.png"]  # no temporary left behind
    smooth2d.plot(tmp_path / "conv.svg", metric="mse")
    assert b"<svg" in (tmp_path / "conv.svg").read_bytes()[:1000]
    with pytest.raises(ValueError, match="metric"):
        smooth2d.plot(tmp_path / "x.png", metric="bias")
    with pytest.raises(ValueError, match="cannot write"):
        smooth2d.plot(tmp_path / "x.xyz")
    with pytest.raises(FileNotFoundError):
        smooth2d.plot(tmp_path / "missing" / "x.png")


def test_convergence_cross_pair_coupling():
    """The paper's claim on an integrand made of pair terms only: a strength-2
    OA (every pair stratified) beats padding (pairs (0,1), (2,3) only)."""
    r = A.convergence(["jittered2d", "bose"], "pairwise", 4, [64, 256, 1024], trials=64, seed=2, backend=BACKEND)
    assert np.all(r.variance["bose"] < r.variance["jittered2d"] / 4)
    assert r.slope["bose"] < r.slope["jittered2d"] - 0.5


def test_convergence_nearest_counts_skips_and_errors():
    r = A.convergence(["bose", "bush", "cmjnd", "random"], A.ball(8), 8, [100, 101, 130, 1000], trials=4,
                      backend=BACKEND)
    # 100 and 101 -> 81 (a tie at 101 goes to fewer samples), 130 -> 121, 1000 -> 1024 (s = 32)
    np.testing.assert_array_equal(r.spp["bose"], [81, 121, 1024])
    assert r.strength["cmjnd"] == 8
    np.testing.assert_array_equal(r.spp["cmjnd"], [256])  # 2^8, the only s^8 within a factor 2 of a target (130)
    # bush at strength 8: only 8^8 = 2^24, far from every target
    assert r.skipped["bush"].startswith("no valid sample count for d=8 at strength 8 within a factor 2")
    assert "16777216" in r.skipped["bush"] and "bush" not in r.spp
    assert math.isnan(r.slope["cmjnd"])  # one count: no slope
    assert "| bush |" in r.table()
    r2 = A.convergence("cmjnd", "additive", 3, [30], trials=2, strength={"cmjnd": 2}, backend=BACKEND)
    assert r2.strength["cmjnd"] == 2 and r2.spp["cmjnd"].tolist() == [25]
    for kw, match in [
        (dict(samplers=["nope"]), "unknown sampler"),
        (dict(samplers=["random", "random"]), "distinct"),
        (dict(integrand="nope"), "unknown integrand"),
        (dict(integrand=A.gaussian(3)), "3-dimensional"),
        (dict(integrand=42), "INTEGRANDS"),
        (dict(trials=1), "trials"),
        (dict(spp_targets=[]), "at least one"),
        (dict(spp_targets=[0]), "spp target"),
        (dict(d=0), "d must be"),
        (dict(max_ratio=0.5), "max_ratio"),
    ]:
        args = dict(samplers=["random"], integrand="gaussian", d=2, spp_targets=[16], trials=4, backend=BACKEND)
        args.update(kw)
        with pytest.raises(ValueError, match=match):
            A.convergence(**args)


def test_convergence_chunks_pixels():
    """A small max_bytes splits the trials into chunks with the same estimates."""
    kw = dict(trials=10, seed=4, backend=BACKEND)
    a = A.convergence(["halton"], "oscillatory", 3, [64], **kw)
    b = A.convergence(["halton"], "oscillatory", 3, [64], max_bytes=3 * 4 * 64 * 3, **kw)
    np.testing.assert_array_equal(a.variance["halton"], b.variance["halton"])
    np.testing.assert_array_equal(a.mean["halton"], b.mean["halton"])


def test_every_sampler_runs():
    r = A.convergence(list(pyoa.samplers()), "halfspace", 3, [64, 128], trials=8, backend=BACKEND)
    assert not r.skipped and set(r.samplers) == set(pyoa.samplers())
    for name in r.samplers:
        assert np.all(np.isfinite(r.variance[name])) and np.all(np.abs(r.mean[name] - r.integrand.exact) < 0.2)
