"""The compiled shading (pyoa.render.compiled) against the NumPy reference:
the BSDFs function by function, the renders within the noise they predict,
determinism over packet widths, batches and threads, and the choice of
shading (argument, PYOA_SHADING, the fallback when numba is missing)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from pyoa.render import bsdfs
from pyoa.render.compiled import bsdfs as cb
from pyoa.render.compiled import integrator as ci
from pyoa.render.render import render
from pyoa.render.scene import load

DIFFUSE, MIRROR, GGX, DIELECTRIC = (bsdfs.KINDS[k] for k in ("diffuse", "mirror", "ggx", "dielectric"))


def _directions(rng, n):
    wo = rng.normal(size=(n, 3))
    wo[:, 2] = np.abs(wo[:, 2])
    wo[: n // 20, 2] = 1e-9  # grazing
    wo /= np.linalg.norm(wo, axis=1)[:, None]
    return wo


@pytest.mark.parametrize("alpha", [1e-4, 0.05, 0.3, 1.0])
def test_bsdf_sample_and_evaluate_mirror_the_reference(alpha):
    """The compiled per-point dispatch (a chain built from the registry) gives
    each kind's NumPy values: to rounding (the warps' polynomial sines), and
    to the bit for the mirror and the glass, from either side."""
    rng = np.random.default_rng(int(alpha * 1e4))
    n = 600
    color = (0.9, 0.5, 0.2)
    mats = bsdfs.Materials.build([("d", "diffuse", {"reflectance": color}), ("m", "mirror", {"tint": color}),
                                  ("g", "ggx", {"specular": color, "roughness": alpha}),
                                  ("glass", "dielectric", {"int_ior": 1.0 + alpha})])
    wo = _directions(rng, n)
    wi_any = rng.normal(size=(n, 3))
    wi_any /= np.linalg.norm(wi_any, axis=1)[:, None]
    u = rng.random((n, 2))
    u[:5] = [[0.5, 0.5], [0.0, 0.0], [0.5, 0.0], [0.0, 0.5], [np.nextafter(1, 0)] * 2]  # warp corners
    front = rng.random(n) < 0.5
    for mat, kind in enumerate(mats.kind):
        ids = np.full(n, mat)
        wi, weight, pdf, delta = bsdfs.sample(mats, ids, wo, u, front)
        f_cos, pdf_e = bsdfs.evaluate(mats, ids, wo, wi_any, front)
        exact = kind in (MIRROR, DIELECTRIC)
        for i in range(n):
            got = cb.sample(kind, *mats.params[mat], front[i], *wo[i], *u[i])
            ev = cb.evaluate(kind, *mats.params[mat], front[i], *wo[i], *wi_any[i])
            want, want_ev = (*wi[i], *weight[i], pdf[i]), (*f_cos[i], pdf_e[i])
            if exact:
                assert got[:7] == want and ev == want_ev, (kind, i)
            np.testing.assert_allclose(got[:7], want, rtol=1e-12, atol=1e-15)
            np.testing.assert_allclose(ev, want_ev, rtol=1e-12, atol=1e-15)
            assert got[7] == delta[i]


def _noise_check(scene, **kw):
    """Render ``scene`` with both shadings over independent seeds and check the
    difference of the two means against the noise both predict, per pixel
    (a t statistic from the spread over seeds) and for the image mean."""
    seeds = 8
    means = {}
    for shading, base in (("numba", 0), ("numpy", 1000)):
        imgs = np.stack([render(scene, seed=base + k, shading=shading, **kw).image.astype(np.float64)
                         for k in range(seeds)])
        means[shading] = (imgs.mean(axis=0), imgs.var(axis=0, ddof=1) / seeds)
    (ma, va), (mb, vb) = means["numba"], means["numpy"]
    var = va + vb
    lit = var > 0
    z = np.abs(ma - mb)[lit] / np.sqrt(var[lit])
    assert np.all(ma[~lit] == mb[~lit]), "pixels without noise must agree exactly (both black, or constant)"
    # t with 2 x 7 degrees of freedom: P(|t| > 5) is about 2e-4 per pixel
    assert np.mean(z > 5) < 0.005, f"{np.mean(z > 5):.4f} of the pixels differ by more than 5 sigma"
    for c in range(3):
        se = np.sqrt(var[..., c].sum()) / var[..., c].size
        diff = abs(ma[..., c].mean() - mb[..., c].mean())
        assert diff <= 5 * se + 1e-7, f"channel {c}: image means differ by {diff:.3g}, standard error {se:.3g}"


@pytest.mark.parametrize("name", ["cornell", "dof7d", "deep", "cornell-glass"])
def test_compiled_and_numpy_agree_within_their_noise(name):
    _noise_check(load(name), sampler="bose", spp=25, width=24, height=24)


def test_packet_widths_batches_wavefronts_and_threads_give_the_same_bits(monkeypatch):
    sc = load("deep")  # GGX, mirror, long paths, Russian roulette
    kw = dict(sampler="bose", spp=9, seed=4, width=16, height=16, shading="numba")
    ref = render(sc, **kw, threads=1).image.tobytes()
    for width, wavefront in ((1, 512), (4, 7), (8, 1), (16, 4096)):
        monkeypatch.setattr(ci, "packet_width", lambda w=width: w)
        monkeypatch.setattr(ci, "WAVEFRONT", wavefront)
        for batch_paths, threads in ((9 * 7, 2), (1 << 16, 2), (1, 1)):
            res = render(sc, **kw, batch_paths=batch_paths, threads=threads)
            assert res.integrator[0].wavefront == wavefront and res.integrator[0].packet == width
            assert res.image.tobytes() == ref, (f"packet {width}, wavefront {wavefront}, batch_paths={batch_paths}, "
                                                f"threads={threads}")


def test_timings_cover_the_stages():
    res = render(load("cornell"), sampler="bose", spp=4, width=16, height=16, shading="numba")
    assert set(res.timings) == {"camera", "embree", "shading", "host"}
    assert all(v >= 0 for v in res.timings.values()) and res.timings["embree"] > 0
    assert render(load("cornell"), sampler="bose", spp=4, width=8, height=8, shading="numpy").timings == {}


def test_shading_argument_and_environment(monkeypatch):
    sc = load("cornell")
    with pytest.raises(ValueError, match=r"unknown shading 'gpu'; valid: numba, numpy"):
        render(sc, sampler="bose", spp=4, width=4, height=4, shading="gpu")
    with pytest.raises(TypeError, match="shading must be a str"):
        render(sc, sampler="bose", spp=4, width=4, height=4, shading=1)
    monkeypatch.setenv("PYOA_SHADING", "bogus")
    with pytest.raises(ValueError, match=r"unknown \$PYOA_SHADING 'bogus'"):
        render(sc, sampler="bose", spp=4, width=4, height=4)
    monkeypatch.setenv("PYOA_SHADING", " NumPy ")
    assert render(sc, sampler="bose", spp=4, width=4, height=4).shading == "numpy"
    monkeypatch.delenv("PYOA_SHADING")
    assert render(sc, sampler="bose", spp=4, width=4, height=4).shading == "numba"


SCRIPT = textwrap.dedent("""
    import warnings
    warnings.simplefilter("always")
    from pyoa.render.render import render
    from pyoa.render.scene import load
    with warnings.catch_warnings(record=True) as rec:
        res = render(load("cornell"), sampler="bose", spp=4, width=8, height=8, backend="numpy")
    print("SHADING", res.shading)
    for w in rec:
        print("WARNING", w.category.__name__, str(w.message).replace("\\n", " | "))
    try:
        render(load("cornell"), sampler="bose", spp=4, width=8, height=8, backend="numpy", shading="numba")
    except RuntimeError as exc:
        print("RAISED", exc)
""")


def test_without_numba_the_reference_renders_with_one_warning(tmp_path):
    """numba hidden for real (an import that fails) in a subprocess."""
    (tmp_path / "numba.py").write_text("raise ImportError('numba hidden by the test suite')\n")
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYOA_")}
    env["PYTHONPATH"] = os.pathsep.join([str(tmp_path)] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    res = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, timeout=300)
    assert res.returncode == 0, res.stderr
    assert "SHADING numpy" in res.stdout
    warns = [ln for ln in res.stdout.splitlines() if ln.startswith("WARNING")]
    assert len(warns) == 1 and "ShadingFallbackWarning" in warns[0] and "numba hidden" in warns[0], res.stdout
    assert "PYOA_SHADING=numpy" in warns[0]
    assert "RAISED compiled shading is not usable here" in res.stdout


def _with_tracing(tmp_path, name, value):
    """A copy of a bundled scene with ``integrator.robust_tracing`` set."""
    import json

    from pyoa.render.scene import bundled

    data = json.loads(open(bundled()[name]).read())
    data.setdefault("integrator", {})["robust_tracing"] = value
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize("name", ["cornell", "deep"])
def test_fast_tracing_changes_only_rays_at_seams(tmp_path, name):
    """``integrator.robust_tracing: false`` traces without Embree's robust
    mode: the same hits but for the rare ray through a shared edge, at
    distances that differ in their last float32 bits, so the same image to
    rounding (a relative 1e-5 here) but for a few pixels at most."""
    robust = load(name)
    fast = load(_with_tracing(tmp_path, name, False))
    assert robust.robust_tracing and not fast.robust_tracing
    kw = dict(sampler="bose", spp=49, seed=7, width=32, height=32, shading="numba")
    a, b = render(robust, **kw).image, render(fast, **kw).image
    assert not np.array_equal(a, b)  # two tracers really ran
    differ = np.any(np.abs(a - b) > 1e-5 * np.maximum(np.abs(a), 1e-3), axis=2)
    assert differ.sum() <= 2, f"{differ.sum()} of {differ.size} pixels differ beyond rounding"
    assert render(load(_with_tracing(tmp_path, name, True)), **kw).image.tobytes() == a.tobytes()


def test_robust_tracing_must_be_a_boolean(tmp_path):
    with pytest.raises(ValueError, match=r"integrator\.robust_tracing"):
        load(_with_tracing(tmp_path, "cornell", "yes"))


def test_numba_cache_follows_every_source_the_compiled_code_comes_from(tmp_path):
    """numba's cache knows a function only by its own file: pyoa keeps the
    compiled package's cache in a folder named after a digest of every
    source its functions compile from, so editing any of them (a git pull
    into an editable install) compiles again instead of reusing old code."""
    import ast
    import shutil
    from pathlib import Path

    import pyoa.render.compiled as pkg

    root = Path(pkg.__file__).resolve().parent.parent.parent  # the pyoa package
    # every module of pyoa that the compiled package imports is a source, with its package's __init__
    imported = set()
    for path in (root / "render" / "compiled").glob("*.py"):
        imported.add(f"render/compiled/{path.name}")
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level in (2, 3):
                where = "render/" if node.level == 2 else ""
                names = [node.module] if node.module else [a.name for a in node.names]
                for n in names:
                    rel = where + n.replace(".", "/")
                    imported.add(rel + "/__init__.py" if (root / rel).is_dir() else rel + ".py")
                    if "." in n:
                        imported.add(where + n.rsplit(".", 1)[0].replace(".", "/") + "/__init__.py")
    assert any(name.startswith("_numba/") for name in imported)  # the hashes are followed too
    assert "render/bsdfs/__init__.py" in imported  # the registry the dispatch is built from
    assert imported <= set(pkg.SOURCES), imported - set(pkg.SOURCES)
    # every BSDF module is compiled in (its one-point forms): all are sources, a new one without a line
    assert {f"render/bsdfs/{p.name}" for p in (root / "render" / "bsdfs").glob("*.py")} <= set(pkg.SOURCES)
    # the digest changes with any byte of any source
    for rel in pkg.SOURCES:
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(root / rel, tmp_path / rel)
    base = pkg.sources_digest(tmp_path)
    assert base == pkg.sources_digest()
    seen = {base}
    for rel in pkg.SOURCES:
        data = (tmp_path / rel).read_bytes()
        (tmp_path / rel).write_bytes(data + b"\n")
        seen.add(pkg.sources_digest(tmp_path))
        (tmp_path / rel).write_bytes(data)
    assert len(seen) == len(pkg.SOURCES) + 1
    # the functions are cached under that folder, and numba's setting is restored for everyone else
    code = textwrap.dedent("""
        import os, pathlib
        import numba.core.config as config
        import pyoa.render.compiled as pkg
        from pyoa.render.render import render
        from pyoa.render.scene import load
        assert config.CACHE_DIR == os.environ["NUMBA_CACHE_DIR"], config.CACHE_DIR
        render(load("cornell"), sampler="bose", spp=4, width=4, height=4, shading="numba")
        salted = pathlib.Path(pkg.cache_dir())
        assert salted.name == "pyoa-render-" + pkg.sources_digest()[:16], salted
        assert salted.parent == pathlib.Path(os.environ["NUMBA_CACHE_DIR"])
        print(len(list(salted.rglob("integrator.render_paths-*.nbi"))))
    """)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip() == "1"


def test_lane_loops_vectorize():
    """The lane loops of the shading and the camera
    (pyoa.render.compiled.shading, pyoa.render.compiled.camera) are written so
    that LLVM vectorizes them: the assembly of each holds packed
    double-precision arithmetic. A change that stops the vectorizer (a
    branch on a lane's value, a second written array, rows a run-time
    stride apart) fails here instead of silently costing a third of the
    shading's speed."""
    import re

    from numba import njit

    from pyoa.render.compiled import camera as cam
    from pyoa.render.compiled import shading as sh

    rng = np.random.default_rng(0)
    F = rng.random(sh.SCRATCH) + 0.5
    C = rng.random(cam.SCRATCH)
    calls = {"head": (sh.head, sh.CHUNK, 2, True, F), "light_directions": (sh.light_directions, sh.CHUNK, F),
             "shadow_rays": (sh.shadow_rays, sh.CHUNK, True, F), "sample_lobes": (sh.sample_lobes, sh.CHUNK, F),
             "new_rays": (sh.new_rays, sh.CHUNK, F),
             "_rays": (cam._rays, cam.LANES, True, True, 64, 48, 0.5, 0.4, tuple(rng.random(9)), (1.0, 2.0, 3.0), 0.1,
                       2.0, (0.1, 0.2, 0.3), C)}
    for kind, loops in sh.LANE_LOOPS.items():  # each BSDF's lane form (GGX, glass)
        name = bsdfs.BSDFS[kind].NAME
        calls[f"{name} evaluate"], calls[f"{name} sample"] = (loops[0], sh.CHUNK, F), (loops[1], sh.CHUNK, F)
    assert {"ggx sample", "dielectric sample"} <= set(calls)
    for name, (fn, *args) in calls.items():
        if name == "dielectric evaluate":
            continue  # two delta lobes: their value is 0, nothing to multiply
        # a copy compiled here: numba does not keep the assembly of cached code
        f = njit(nogil=True, error_model="numpy")(fn.py_func)
        f(*args)
        asm = f.inspect_asm(f.signatures[0])
        packed = len(re.findall(r"\bv?mulpd\b", asm))
        assert packed >= 4, f"{name}: {packed} packed multiplications, the lane loop did not vectorize"


def test_sin_cos_is_within_two_ulps_of_libm():
    """The compiled warps' sines and cosines (bsdfs.warps.sin_cos, polynomials
    on [-pi/4, pi/4]) are within 2 ulps of the C library's, as its docstring
    says: on a dense grid, at random points, at the ends and near zero."""
    import math

    from numba import njit

    from pyoa.render.bsdfs import warps
    from pyoa.render.compiled.forms import compiled

    sin_cos = compiled(warps.sin_cos)

    @njit
    def both(xs):
        s, c = np.empty_like(xs), np.empty_like(xs)
        for i in range(xs.size):
            s[i], c[i] = sin_cos(xs[i])
        return s, c

    q = math.pi / 4
    xs = np.concatenate([np.linspace(-q, q, 40001), np.random.default_rng(5).uniform(-q, q, 40000),
                         [0.0, -0.0, 5e-324, 1e-300, 1e-8, -1e-8, q, -q, np.nextafter(q, 0.0)]])
    s, c = both(xs)
    for got, want in ((s, [math.sin(v) for v in xs]), (c, [math.cos(v) for v in xs])):
        want = np.array(want)
        assert np.all(np.abs(got - want) <= 2 * np.spacing(np.abs(want))), np.max(np.abs(got - want))


@pytest.mark.parametrize("name", ["cornell", "bounce9d", "dof7d"])
@pytest.mark.parametrize("filter", ["box", "gaussian"])
def test_camera_rays_are_the_reference_s(name, filter):
    """The compiled camera (pyoa.render.compiled.camera) makes the reference
    camera's rays (Integrator.camera_rays): the same bits for a pinhole
    camera, moving (bounce9d) or not (cornell), with either filter; through a
    thin lens (dof7d) within 2 ulps of each ray's largest component, because
    its disk point takes its sine and cosine from bsdfs.warps.sin_cos instead of
    NumPy's."""
    from pyoa.render.camera import filter_offsets
    from pyoa.render.compiled import camera as cam
    from pyoa.render.integrator import Integrator
    from pyoa.render.render import plan

    scene, (w, h), spp = load(name), (23, 17), 9  # 3519 rays: several chunks of the camera's lanes, the last short
    p = plan(scene, sampler="bose", spp=spp, width=w, height=h)
    x = np.ascontiguousarray(p.sampler.generate(pixels=range(w * h)).reshape(w * h * spp, -1))
    pixel = np.repeat(np.arange(w * h), spp).astype(np.int64)
    want_o, want_d = Integrator(scene, p.layout, w, h, filter=filter).camera_rays(pixel, x)
    integ = ci.CompiledIntegrator(scene, p.layout, w, h, filter=filter)
    c, cols = integ._camera, integ._settings.camera_columns
    u = (np.zeros((0, 2)) if filter == "box"
         else np.ascontiguousarray(filter_offsets(x[:, list(p.layout.pair("pixel"))].astype(np.float64), filter)))
    o, d = np.empty((len(pixel), 3)), np.empty((len(pixel), 3))
    cam.camera_rays(pixel, x, u, cols, c.width, c.height, c.tan_x, c.tan_y, c.rot, c.pos, c.aperture, c.focus,
                    c.motion, np.empty(cam.SCRATCH), o, d)
    if not p.layout.lens:
        assert o.tobytes() == want_o.tobytes() and d.tobytes() == want_d.tobytes()
        return
    for got, want in ((o, want_o), (d, want_d)):
        ulp = np.spacing(np.abs(want).max(axis=1, keepdims=True))
        assert np.all(np.abs(got - want) <= 2 * ulp), np.max(np.abs(got - want) / ulp)


def test_scratch_rows_do_not_overlap():
    """Every row of the shading's scratch is its own, one cache line apart
    from the next row's start, and the scratch holds them all."""
    from pyoa.render.compiled import shading as sh

    sizes_and_imports = ("CHUNK", "ROW", "SCRATCH", "HIT_FIELDS", "RR_KEY")
    rows = sorted(v for k, v in vars(sh).items()
                  if k.isupper() and not k.startswith("_") and isinstance(v, int) and k not in sizes_and_imports)
    assert rows == [k * sh.ROW for k in range(len(rows))]
    assert sh.ROW >= sh.CHUNK and (sh.ROW * 8) % 4096 != 0 and rows[-1] + sh.ROW <= sh.SCRATCH
    assert sh.M3 - sh.V0X == (sh.HIT_FIELDS - 1) * sh.ROW  # gather copies hit_data's row into V0X .. M3
    assert (sh.M3 - sh.M0) // sh.ROW + 1 == bsdfs.PARAMS  # a material's numbers


@pytest.mark.parametrize("n_emitters", [1, 2, 3, 7, 8, 33])
def test_emitter_choice_is_the_reference(n_emitters):
    """The compiled emitter sample (an inline binary search of the power
    CDF) picks the reference's triangle (NumPy's searchsorted) and point for
    every u, at the CDF's own values and their neighbours included, with
    emitters of equal and of very unequal power."""
    import types

    from pyoa.render.compiled.emitters import sample_emitter
    from pyoa.render.emitters import Emitters

    rng = np.random.default_rng(n_emitters)
    T = n_emitters + 3
    tris = rng.normal(size=(T, 3, 3)).astype(np.float32)
    normals = rng.normal(size=(T, 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    emission = np.zeros((T, 3))
    emitters = rng.permutation(T)[:n_emitters]
    emission[emitters] = rng.choice([1.0, 1.0, 1e-6, 40.0], size=(n_emitters, 1)) * rng.uniform(0.5, 1, (n_emitters, 3))
    scene = types.SimpleNamespace(emitters=np.sort(emitters), areas=rng.uniform(0.1, 2.0, T), emission=emission,
                                  triangles=tris, normals=normals)
    em = Emitters(scene)
    c = em.cdf
    u0 = np.concatenate([rng.random(500), c, np.nextafter(c, 0), np.nextafter(c, 2), [0.0, np.nextafter(1, 0)]])
    u0 = np.clip(u0, 0.0, np.nextafter(1, 0))
    u = np.stack([u0, rng.random(len(u0))], axis=1)
    tri, p, nrm, pdf = em.sample(u)
    verts = np.ascontiguousarray(tris, dtype=np.float64)
    for i in range(len(u)):
        got = sample_emitter(em.index, em.cdf, em.prob, verts, normals, scene.areas, u[i, 0], u[i, 1])
        assert got[0] == tri[i], (i, u[i])
        np.testing.assert_allclose(got[1:4], p[i], rtol=1e-15, atol=1e-15)
        assert list(got[4:7]) == list(nrm[i]) and got[7] == pdf[i]


@pytest.mark.parametrize("extend", [True, False])
def test_other_kinds_are_the_per_point_bsdf(extend):
    """other_kinds shades the lanes of every kind but the first, one kind
    after another: GGX and glass lanes packed into rows of their own, in
    vectorized loops (their lane forms), the mirror's one lane at a time.
    Each such lane gets, bit for bit, what the per-point evaluate and sample
    (which mirror the reference) give it, grazing and below-the-surface
    directions, both sides of the glass and the warps' corners included;
    the Lambertian lanes keep what light_directions and sample_lobes wrote,
    and so do the lanes of a kind the scene does not have (``kinds``)."""
    from pyoa.render.compiled import shading as sh

    rng = np.random.default_rng(11)
    h = sh.CHUNK
    F = np.full(sh.SCRATCH, np.nan)
    row = lambda r: F[r:r + h]  # noqa: E731
    kind = rng.choice([DIFFUSE, MIRROR, GGX, DIELECTRIC], size=h, p=[0.3, 0.2, 0.3, 0.2]).astype(np.float64)
    kind[:6] = GGX  # the warps' corners and the normal incidence below are GGX lanes
    kind[6:12] = DIELECTRIC
    row(sh.KIND)[:] = kind
    params = rng.random((h, 4))
    params[:, 3] = rng.choice([1e-4, 0.05, 0.3, 1.0], size=h)  # GGX roughness
    glass = kind == DIELECTRIC
    params[glass, 0] = rng.choice([1.0, 1.33, 1.5046 / 1.000277, 2.4], size=glass.sum())  # eta
    for r, v in zip((sh.M0, sh.M1, sh.M2, sh.M3), params.T):
        row(r)[:] = v
    row(sh.FRONT)[:] = rng.random(h) < 0.5
    wo = _directions(rng, h)
    wo[-8:, 2] = -np.abs(wo[-8:, 2])  # below the surface: the sample's guard
    wo[5] = [0.0, 0.0, 1.0]  # normal incidence: the visible-normal frame's fallback tangent
    wo[6:9] = [[0.99, 0.0, np.sqrt(1 - 0.99**2)]] * 3  # grazing: total internal reflection from inside the glass
    wi = rng.normal(size=(h, 3))
    wi /= np.linalg.norm(wi, axis=1)[:, None]
    for r, v in zip((sh.WOX, sh.WOY, sh.WOZ, sh.IX, sh.IY, sh.IZ), (*wo.T, *wi.T)):
        row(r)[:] = v
    u = rng.random((h, 2))
    u[:5] = [[0.5, 0.5], [0.0, 0.0], [0.5, 0.0], [0.0, 0.5], [np.nextafter(1, 0)] * 2]
    row(sh.BSDF_U)[:], row(sh.BSDF_V)[:] = u.T
    evaluated = (sh.FR, sh.FG, sh.FB, sh.PDF_B)
    sampled = (sh.NIX, sh.NIY, sh.NIZ, sh.WR, sh.WG, sh.WB, sh.PDF, sh.DELTA)
    for r in evaluated:
        row(r)[:] = rng.random(h)  # as light_directions would leave them
    sh.sample_lobes(h, F)
    before = F.copy()
    kinds = np.ones(len(bsdfs.BSDFS), dtype=bool)
    sh.other_kinds(h, extend, kinds, F)
    bits = lambda values: np.array(values, np.float64).view(np.uint64)  # noqa: E731 - -0.0 is not 0.0
    shaded = np.flatnonzero(kind != DIFFUSE)
    for k in shaded:
        args = (int(kind[k]), *params[k], F[sh.FRONT + k] != 0.0, *wo[k])
        assert np.array_equal(bits([F[r + k] for r in evaluated]), bits(cb.evaluate(*args, *wi[k]))), k
        ix, iy, iz, wr, wg, wb, pdf, delta = cb.sample(*args, *u[k])
        want = [ix, iy, iz, wr, wg, wb, pdf, float(delta)] if extend else [before[r + k] for r in sampled]
        assert np.array_equal(bits([F[r + k] for r in sampled]), bits(want)), k
    for which in (GGX, MIRROR, DIELECTRIC):
        assert np.count_nonzero(kind == which) > 30 and np.any(wo[kind == which, 2] < 0)
    reflected = (kind == DIELECTRIC) & (F[sh.NIZ:sh.NIZ + h] > 0)
    if extend:
        assert 0 < reflected.sum() < glass.sum()  # the glass lanes both reflect and refract
    others = np.flatnonzero(kind == DIFFUSE)
    for r in (*evaluated, *sampled):
        assert np.array_equal(F[r + others], before[r + others])
    # a kind the scene does not have is not shaded: its lanes keep the first kind's values
    for missing in (MIRROR, GGX, DIELECTRIC):
        G = before.copy()
        kinds[:] = True
        kinds[missing] = False
        sh.other_kinds(h, extend, kinds, G)
        lanes, rest = np.flatnonzero(kind == missing), np.flatnonzero((kind != missing) & (kind != DIFFUSE))
        for r in (*evaluated, *sampled):
            assert np.array_equal(G[r + lanes], before[r + lanes])
            assert np.array_equal(G[r + rest], F[r + rest])


@pytest.mark.parametrize("name", ["cornell", "deep"])
@pytest.mark.parametrize("mis", [True, False])
def test_the_last_bounce_adds_what_the_full_shading_would(name, mis):
    """emission_only (the last bounce: emission alone, one entry at a time)
    adds to every path the same bits as gathering the hits and running
    head and emit_and_choose on them: rays from inside the scene in every
    direction, some from emitters' backs, at depth 1 (a camera ray's state,
    shading.path_state) and deeper with random throughputs, previous pdfs
    and delta flags."""
    from pyoa.render import embree
    from pyoa.render.compiled import shading as sh
    from pyoa.render.layout import Layout

    scene = load(name)
    layout = Layout(max_depth=3, mis=mis, lens=False, time=False)
    integ = ci.CompiledIntegrator(scene, layout, 8, 8)
    sc, tr = integ._scene, integ._tracer
    ps = integ._settings._replace(mis=mis)
    rng = np.random.default_rng(5)
    n = 8000
    w = ci.new_wavefront(n)
    lo, hi = scene.triangles.reshape(-1, 3).min(axis=0), scene.triangles.reshape(-1, 3).max(axis=0)
    w.o[:] = lo + (hi - lo) * rng.uniform(0.02, 0.98, size=(n, 3))
    d = rng.normal(size=(n, 3))
    w.d[:] = d / np.linalg.norm(d, axis=1)[:, None]
    embree.intersect(tr.scene, tr.hit, tr.packet, w.o, w.d, w.prim, w.t)
    assert np.count_nonzero(sc.emission[w.prim[w.prim >= 0]].any(axis=1)) >= 10  # some rays see emitters
    w.lane[:] = rng.permutation(n)
    w.beta[:] = rng.uniform(0, 2, size=(n, 3))
    w.prev_pdf[:] = rng.uniform(0, 3, size=n)
    w.prev_delta[:] = rng.random(n) < 0.3
    x = np.zeros((n, layout.dims), np.float32)
    for depth in (1, 2, 3):
        fast = np.zeros((n, 3))
        sh.emission_only(n, depth, mis, sc, w, fast)
        full = np.zeros((n, 3))
        F, lanes = np.empty(sh.SCRATCH), np.empty(sh.CHUNK, np.int64)
        for start in range(0, n, sh.CHUNK):
            h = sh.gather(start, min(start + sh.CHUNK, n), depth, sc, ps, x, w, F, lanes)
            sh.head(h, depth, mis, F)
            for k in range(h):
                if F[sh.SEEN + k] != 0.0:
                    full[lanes[k]] += F[[sh.LE_R + k, sh.LE_G + k, sh.LE_B + k]]
        assert np.count_nonzero(full.any(axis=1)) >= 10
        assert fast.tobytes() == full.tobytes(), f"depth {depth}"
