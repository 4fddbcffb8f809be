"""A render's settings as one value (pyoa.render.settings.RenderSettings):
every part of the renderer that hands a render on takes it, keyword
arguments replace its fields, and nothing outside it changes an image."""

from __future__ import annotations

import dataclasses
import pickle

import pytest

from pyoa.render import tiles
from pyoa.render.progressive import DEFAULTS, render_progressive
from pyoa.render.provenance import describe
from pyoa.render.render import plan, render
from pyoa.render.scene import load
from pyoa.render.settings import RenderSettings, names

SMALL = dict(width=12, height=8, spp=4)


@pytest.fixture(scope="module")
def cornell():
    return load("cornell")


def test_a_value_and_its_keywords_render_the_same_bits(cornell):
    s = RenderSettings(sampler="sobol", seed=7, max_depth=3, shading="numpy", **SMALL)
    by_value = render(cornell, s)
    by_keywords = render(cornell, **dataclasses.asdict(s))
    assert by_value.image.tobytes() == by_keywords.image.tobytes()
    assert by_value.settings == s
    # a keyword replaces the value's field, the rest stay
    other = render(cornell, s, seed=8)
    assert other.settings == s.replace(seed=8) and other.image.tobytes() != by_value.image.tobytes()
    assert other.image.tobytes() == render(cornell, s.replace(seed=8)).image.tobytes()


def test_unknown_and_misplaced_settings_are_refused_with_the_valid_names(cornell):
    with pytest.raises(TypeError, match=r"unknown render setting 'sampeler'; valid: sampler, spp, seed, width"):
        render(cornell, sampeler="bose", **SMALL)
    with pytest.raises(TypeError, match=r"unknown render settings 'bar', 'foo'"):
        RenderSettings().replace(foo=1, bar=2)
    with pytest.raises(TypeError, match="settings must be a RenderSettings, got dict"):
        render(cornell, dict(SMALL))
    with pytest.raises(TypeError, match="settings must be a RenderSettings"):
        plan(cornell, "bose")
    # the values are checked by plan(), against the scene, with its own messages
    with pytest.raises(ValueError, match="shading"):
        plan(cornell, RenderSettings(shading="cuda", **SMALL))
    with pytest.raises(ValueError, match="nearest"):
        plan(cornell, RenderSettings(sampler="bose", spp=120))


def test_the_value_is_immutable_hashable_and_travels_to_workers():
    s = RenderSettings(first=["lens", "light1"], **SMALL)
    assert s.first == ("lens", "light1")  # a list would make it unhashable
    assert hash(s) == hash(RenderSettings(first=("lens", "light1"), **SMALL))
    assert pickle.loads(pickle.dumps(s)) == s
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.spp = 9
    assert names()[:3] == ("sampler", "spp", "seed") and set(names()) == set(dataclasses.asdict(s))


def test_the_integrator_key_leaves_out_what_a_reused_integrator_renders_with_any_of():
    s = RenderSettings(**SMALL)
    for field in ("sampler", "spp", "seed", "base", "backend", "batch_paths", "max_bytes"):
        changed = {"sampler": "sobol", "spp": 16, "seed": 3, "base": 5, "backend": "numpy", "batch_paths": 64,
                   "max_bytes": "1G"}[field]
        assert s.replace(**{field: changed}).integrator_key() == s.integrator_key(), field
    for field, changed in (("width", 16), ("height", 16), ("max_depth", 2), ("filter", "gaussian"),
                           ("first", ("lens",)), ("shading", "numpy")):
        assert s.replace(**{field: changed}).integrator_key() != s.integrator_key(), field


def test_a_worker_keeps_one_integrator_per_key_and_renders_what_render_does(cornell):
    tiles._INTEGRATORS.clear()
    s = RenderSettings(shading="numpy", **SMALL)
    images = [tiles.worker_render(cornell, s.replace(seed=k)).image for k in range(3)]
    assert len(tiles._INTEGRATORS) == 1  # three seeds, one integrator
    for k, img in enumerate(images):
        assert img.tobytes() == render(cornell, s, seed=k).image.tobytes()
    tiles.worker_render(cornell, s.replace(filter="gaussian"))
    assert len(tiles._INTEGRATORS) == 2


def test_the_plan_holds_the_settings_and_the_header_reads_them(cornell):
    s = RenderSettings(sampler="sobol", seed=5, filter="gaussian", shading="numpy", **SMALL)
    p = plan(cornell, s)
    assert p.settings == s and p.shading == "numpy"
    meta = describe(cornell, p, kind="render")
    assert (meta["seed"], meta["filter"], meta["shading"], meta["sampler"]) == (5, "gaussian", "numpy", "sobol")
    # the shading that rendered, where a fallback made it differ
    assert describe(cornell, p, kind="render", shading="numba")["shading"] == "numba"


def test_a_progressive_render_takes_the_value_and_its_defaults(cornell, tmp_path):
    assert (DEFAULTS.sampler, DEFAULTS.spp) == ("faure", 1024)
    s = RenderSettings(sampler="faure", spp=8, base=2, width=12, height=8, shading="numpy")
    a = render_progressive(cornell, s, out=tmp_path / "a.exr")
    b = render_progressive(cornell, out=tmp_path / "b.exr", **dataclasses.asdict(s))
    assert a.image.tobytes() == b.image.tobytes() and a.samples == 8
