"""Embree called from compiled code (pyoa.render.embree): the library is the
one embreex loaded, and the ray/hit layouts pyoa writes and reads give
exactly embreex's answers, for every packet width."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from pyoa.render import embree
from pyoa.render.scene import load


@pytest.fixture(scope="module")
def cornell_rays():
    """Rays from random points inside the Cornell box (some inside its boxes)
    in random directions, and the scene in both APIs."""
    from embreex import rtcore_scene as rtcs
    from embreex.mesh_construction import TriangleMesh

    tris = np.ascontiguousarray(load("cornell").triangles, dtype=np.float32)
    ex = rtcs.EmbreeScene()
    TriangleMesh(ex, tris)
    rng = np.random.default_rng(20261124)
    n = 50_000
    o = rng.uniform(-0.95, 0.95, (n, 3))
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    return ex, embree.Scene(tris), o, d


def test_library_is_the_one_embreex_loaded():
    path = embree.library_path()
    assert "libembree4" in path
    lo_hi = []
    with open("/proc/self/maps") as fh:
        for line in fh:
            if line.rstrip().endswith(path):
                lo, hi = (int(v, 16) for v in line.split()[0].split("-"))
                lo_hi.append((lo, hi))
    assert lo_hi, "the library is not mapped into this process"
    for width in embree.WIDTHS:
        for addr in embree.query_addresses(width):
            assert any(lo <= addr < hi for lo, hi in lo_hi), (width, hex(addr))
    assert ctypes.cast(embree.library().rtcIntersect1, ctypes.c_void_p).value == embree.query_addresses(1)[0]


@pytest.mark.parametrize("width", embree.WIDTHS)
def test_closest_hits_equal_embreex(cornell_rays, width):
    ex, scene, o, d = cornell_rays
    want = ex.run(o.astype(np.float32), d.astype(np.float32), output=1)
    prim, t = np.full(len(o), -7, np.int64), np.full(len(o), -7.0)
    embree.intersect(scene.handle, embree.query_addresses(width)[0], width, o, d, prim, t)
    assert np.array_equal(prim, want["primID"])
    hit = prim >= 0
    assert hit.mean() > 0.5 and (~hit).any()  # both cases exercised (the box is open at the front)
    assert np.array_equal(t[hit].astype(np.float32), want["tfar"][hit])  # the exact float32 distances
    assert np.all(np.isinf(t[~hit]))


@pytest.mark.parametrize("width", embree.WIDTHS)
def test_occlusion_equals_embreex(cornell_rays, width):
    ex, scene, o, d = cornell_rays
    dist = np.random.default_rng(5).uniform(0.0, 1.5, len(o))
    want = ex.run(o.astype(np.float32), d.astype(np.float32), dists=dist.astype(np.float32), query="OCCLUDED")
    free = np.zeros(len(o), np.bool_)
    embree.occluded(scene.handle, embree.query_addresses(width)[1], width, o, d, dist, free)
    assert np.array_equal(free, want == -1)
    assert free.any() and (~free).any()


def test_a_ray_answer_does_not_depend_on_its_packet(cornell_rays):
    ex, scene, o, d = cornell_rays
    n = 4099  # partial last packets
    perm = np.random.default_rng(3).permutation(n)
    fn = embree.query_addresses(16)[0]
    prim, t = np.empty(n, np.int64), np.empty(n)
    embree.intersect(scene.handle, fn, 16, o[:n], d[:n], prim, t)
    prim2, t2 = np.empty(n, np.int64), np.empty(n)
    embree.intersect(scene.handle, fn, 16, o[:n][perm], d[:n][perm], prim2, t2)
    assert np.array_equal(prim2, prim[perm]) and np.array_equal(t2, t[perm])


def test_bad_arguments():
    with pytest.raises(ValueError, match="packet width must be one of"):
        embree.query_addresses(3)
    with pytest.raises(ValueError, match="at least one triangle"):
        embree.Scene(np.zeros((0, 3, 3)))
    s = embree.Scene(load("cornell").triangles)
    s.close()
    s.close()  # idempotent
