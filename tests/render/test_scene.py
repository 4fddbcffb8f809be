"""Scene files: geometry and orientation of the built-in shapes, the bundled
scenes (Cornell box as Mitsuba 3 defines it) and every validation error."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("trimesh")
from pyoa.render import scene as S  # noqa: E402
from pyoa.render.bsdfs import KINDS  # noqa: E402

DIFFUSE, MIRROR, GGX, DIELECTRIC = (KINDS[k] for k in ("diffuse", "mirror", "ggx", "dielectric"))

WHITE = [0.885809, 0.698859, 0.666422]
RADIANCE = [18.387, 13.9873, 6.75357]


def minimal() -> dict:
    """A small valid scene: a floor and a light above it."""
    return {
        "camera": {"to_world": [[-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, 3.9], [0, 0, 0, 1]], "fov": 40},
        "materials": {"white": {"type": "diffuse", "reflectance": [0.5, 0.5, 0.5]},
                      "steel": {"type": "ggx", "specular": [0.9, 0.9, 0.9], "roughness": 0.2},
                      "glass": {"type": "mirror", "tint": [1, 1, 1]}},
        "shapes": [
            {"type": "rectangle", "to_world": [[1, 0, 0, 0], [0, 0, 1, -1], [0, -1, 0, 0], [0, 0, 0, 1]],
             "material": "white"},
            {"type": "rectangle", "to_world": [[0.2, 0, 0, 0], [0, 0, -0.2, 0.9], [0, 0.2, 0, 0], [0, 0, 0, 1]],
             "material": "white", "emission": [1, 2, 3]},
        ],
    }


def write(tmp_path: Path, data, name="x.json") -> Path:
    p = tmp_path / name
    p.write_text(data if isinstance(data, str) else json.dumps(data))
    return p


def edited(edit):
    d = minimal()
    edit(d)
    return d


# -- shapes ---------------------------------------------------------------------------


def normals_of(tris):
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    return n / np.linalg.norm(n, axis=1)[:, None]


def test_rectangle_is_mitsubas():
    r = S.rectangle()
    assert r.shape == (2, 3, 3)
    assert np.all(r[..., 2] == 0) and np.all(np.abs(r[..., :2]) == 1)
    np.testing.assert_allclose(normals_of(r), [[0, 0, 1], [0, 0, 1]])
    assert 0.5 * np.linalg.norm(np.cross(r[:, 1] - r[:, 0], r[:, 2] - r[:, 0]), axis=1).sum() == pytest.approx(4)


def test_cube_is_closed_with_outward_normals():
    c = S.cube()
    assert c.shape == (12, 3, 3)
    assert np.all(np.abs(c) == 1)
    n = normals_of(c)
    centroid = c.mean(axis=1)
    assert np.all(np.einsum("ij,ij->i", n, centroid) > 0)  # outward
    np.testing.assert_allclose(np.abs(n).max(axis=1), 1)  # axis aligned
    # each of the 6 faces has 2 triangles of area 2
    faces = [tuple(np.round(x).astype(int)) for x in n]
    assert sorted(set(faces)) == sorted({(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)})
    assert all(faces.count(f) == 2 for f in set(faces))


@pytest.mark.parametrize("kind", ["rectangle", "cube"])
def test_mirroring_transform_keeps_normals_front(tmp_path, kind):
    flip = [[2, 0, 0, 1], [0, 1, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]]  # det < 0
    d = minimal()
    d["shapes"].insert(0, {"type": kind, "to_world": flip, "material": "steel"})
    sc = S.load(write(tmp_path, d))
    t = sc.triangles[sc.shape_index == 0].astype(np.float64)
    n = sc.normals[sc.shape_index == 0]
    np.testing.assert_allclose(n, normals_of(t), atol=1e-6)
    m = np.array(flip, dtype=np.float64)
    if kind == "rectangle":
        # the front is where the transformed +z normal points: M^-T (0,0,1) = -z
        assert t.shape == (2, 3, 3)
        np.testing.assert_allclose(n, [[0, 0, -1]] * 2, atol=1e-12)
        np.testing.assert_allclose(sc.areas[sc.shape_index == 0].sum(), 4 * 2)
    else:
        assert t.shape == (12, 3, 3)
        centre = m[:3, 3]
        assert np.all(np.einsum("ij,ij->i", n, t.mean(axis=1) - centre) > 0)  # still outward
        np.testing.assert_allclose(sc.areas[sc.shape_index == 0].sum(), 2 * (4 * 2 + 4 * 2 + 4 * 1))
    np.testing.assert_allclose(t.min(axis=(0, 1)), [-1, -1, -1 if kind == "cube" else 0], atol=1e-6)
    np.testing.assert_allclose(t.max(axis=(0, 1)), [3, 1, 1 if kind == "cube" else 0], atol=1e-6)


def test_identity_is_default_transform(tmp_path):
    d = minimal()
    d["shapes"].insert(0, {"type": "cube", "material": "white"})
    sc = S.load(write(tmp_path, d))
    np.testing.assert_array_equal(sc.triangles[:12], S.cube().astype(np.float32))


# -- the Cornell box --------------------------------------------------------------------


@pytest.fixture(scope="module")
def cornell():
    return S.load("cornell")


def test_cornell_counts_and_light(cornell):
    sc = cornell
    assert sc.name == "cornell" and Path(sc.path).name == "cornell.json"
    assert sc.triangles.shape == (36, 3, 3) and sc.triangles.dtype == np.float32
    assert sc.normals.shape == (36, 3) and sc.normals.dtype == np.float64
    assert sc.areas.shape == (36,) and sc.material.dtype == np.int32 and sc.emission.shape == (36, 3)
    np.testing.assert_allclose(np.linalg.norm(sc.normals, axis=1), 1)
    em = sc.emitters
    assert len(em) == 2
    np.testing.assert_allclose(sc.normals[em], [[0, -1, 0]] * 2, atol=1e-12)
    np.testing.assert_array_equal(sc.emission[em], [RADIANCE] * 2)
    assert sc.areas[em].sum() == pytest.approx((0.23 * 2) * (0.19 * 2))
    assert np.all(sc.emission[np.setdiff1d(np.arange(36), em)] == 0)
    np.testing.assert_allclose(sc.triangles[em][..., 1], 0.99, atol=1e-6)


def test_cornell_camera_film_integrator(cornell):
    c = cornell.camera
    np.testing.assert_array_equal(c.to_world, [[-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, 3.9], [0, 0, 0, 1]])
    assert c.fov == pytest.approx(39.3077) and c.aperture == 0 and c.focus_distance == pytest.approx(3.9)
    np.testing.assert_array_equal(c.motion, [0, 0, 0])
    assert (cornell.width, cornell.height, cornell.max_depth, cornell.mis) == (256, 256, 5, True)


def test_cornell_materials_and_walls(cornell):
    m = cornell.materials
    assert m.names == ("white", "red", "green")
    assert np.all(m.kind == DIFFUSE)
    np.testing.assert_allclose(m.params[0, :3], WHITE)
    np.testing.assert_allclose(m.params[1, :3], [0.570068, 0.0430135, 0.0443706])
    np.testing.assert_allclose(m.params[2, :3], [0.105421, 0.37798, 0.076425])
    idx = cornell.shape_index
    expect = {0: [0, 1, 0], 1: [0, -1, 0], 2: [0, 0, 1], 3: [-1, 0, 0], 4: [1, 0, 0]}  # floor ceiling back green red
    for shape, normal in expect.items():
        np.testing.assert_allclose(cornell.normals[idx == shape], [normal] * 2, atol=1e-12)
    assert list(cornell.material[idx == 3]) == [2, 2] and list(cornell.material[idx == 4]) == [1, 1]
    # the red wall is at x = -1 and the green one at x = +1; walls face the box's centre
    for shape in range(5):
        centre = cornell.triangles[idx == shape].mean(axis=(0, 1))
        assert np.dot(cornell.normals[idx == shape][0], -centre) > 0
    # boxes: outward normals, sitting on the floor
    for shape in (5, 6):
        t = cornell.triangles[idx == shape].astype(np.float64)
        assert len(t) == 12
        c = t.reshape(-1, 3).mean(axis=0)
        assert np.all(np.einsum("ij,ij->i", cornell.normals[idx == shape], t.mean(axis=1) - c) > 0)
        assert t[..., 1].min() == pytest.approx(-1, abs=0.0101)  # Mitsuba sinks the large box 1 cm
    assert cornell.areas[idx == 0].sum() == pytest.approx(4)


def test_bundled_scenes_all_load():
    names = S.bundled()
    assert {"cornell", "dof7d", "bounce9d", "deep"} <= set(names)
    for name, path in names.items():
        sc = S.load(name)
        assert sc.name == name and Path(path).is_file()
        assert len(sc.emitters) > 0 and sc.description
        assert S.load(path).triangles.shape == sc.triangles.shape
        assert S.load(Path(path)).name == name
        np.testing.assert_allclose(np.linalg.norm(sc.normals, axis=1), 1)
        assert np.all(sc.areas > 0)
    dof = S.load("dof7d")
    assert dof.camera.aperture > 0 and np.any(dof.camera.motion != 0)
    assert (dof.max_depth, dof.mis) == (2, False) and GGX in dof.materials.kind
    b = S.load("bounce9d")
    assert b.camera.aperture == 0 and np.any(b.camera.motion) and (b.max_depth, b.mis) == (3, False)
    deep = S.load("deep")
    assert (deep.max_depth, deep.mis) == (12, True)
    assert GGX in deep.materials.kind and MIRROR in deep.materials.kind


def test_scene_is_immutable(cornell):
    with pytest.raises(ValueError):
        cornell.triangles[0, 0, 0] = 5
    with pytest.raises(AttributeError):
        cornell.width = 3


def test_unknown_bundled_name_lists_names():
    with pytest.raises(FileNotFoundError, match="bundled: .*cornell") as e:
        S.load("cornel")
    assert isinstance(e.value, ValueError)


def test_missing_scene_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.json"):
        S.load(tmp_path / "nope.json")
    with pytest.raises(FileNotFoundError, match="nope.json"):
        S.load(str(tmp_path / "nope.json"))


# -- meshes ---------------------------------------------------------------------------------

OBJ = """# a unit square pyramid: 4 + 2 triangles (the base is a quad)
v 0 0 0
v 1 0 0
v 1 0 1
v 0 0 1
v 0.5 1 0.5
f 1 5 2
f 2 5 3
f 3 5 4
f 4 5 1
f 1 2 3 4
"""


def test_mesh_from_obj(tmp_path):
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "pyramid.obj").write_text(OBJ)
    d = minimal()
    d["shapes"].insert(0, {"type": "mesh", "file": "meshes/pyramid.obj", "material": "steel",
                           "to_world": [[2, 0, 0, 10], [0, 2, 0, 0], [0, 0, 2, 0], [0, 0, 0, 1]]})
    sc = S.load(write(tmp_path, d))
    mine = sc.shape_index == 0
    assert mine.sum() == 6
    t = sc.triangles[mine].astype(np.float64)
    np.testing.assert_allclose(t.reshape(-1, 3).min(axis=0), [10, 0, 0])
    np.testing.assert_allclose(t.reshape(-1, 3).max(axis=0), [12, 2, 2])
    assert np.all(sc.material[mine] == sc.materials.names.index("steel"))
    assert sc.areas[mine].sum() == pytest.approx(4 * (4 * 0.5 * np.sqrt(1.25) + 1))
    # the base (y = 0) faces down, the sides outwards
    centre = np.array([11, 0.5, 1])
    assert np.all(np.einsum("ij,ij->i", sc.normals[mine], t.mean(axis=1) - centre) > 0)


def test_mesh_written_by_trimesh(tmp_path):
    import trimesh

    trimesh.creation.icosphere(subdivisions=1).export(tmp_path / "ball.obj")
    d = minimal()
    d["shapes"].append({"type": "mesh", "file": "ball.obj", "material": "white"})
    sc = S.load(write(tmp_path, d))
    assert (sc.shape_index == 2).sum() == 80


# -- validation ---------------------------------------------------------------------------


def raises(tmp_path, data, *fragments, exc=ValueError, name="x.json"):
    with pytest.raises(exc) as e:
        S.load(write(tmp_path, data, name))
    msg = str(e.value)
    assert msg.startswith(name + ": "), msg
    for f in fragments:
        assert f in msg, (f, msg)
    return msg


def test_the_valid_minimal_scene_loads(tmp_path):
    sc = S.load(write(tmp_path, minimal()))
    assert sc.name == "x" and len(sc.triangles) == 4 and list(sc.emitters) == [2, 3]
    assert (sc.width, sc.height, sc.max_depth, sc.mis) == (256, 256, 5, True)  # defaults
    assert list(sc.materials.kind) == [DIFFUSE, GGX, MIRROR]
    np.testing.assert_array_equal(sc.materials.params, [[0.5, 0.5, 0.5, 0], [0.9, 0.9, 0.9, 0.2], [1, 1, 1, 0]])


def test_material_keys_come_from_the_bsdf_modules(tmp_path):
    """A material's keys are its BSDF module's (pyoa.render.bsdfs): a key left
    out takes the module's default, and the glass keys are Mitsuba's."""
    d = minimal()
    d["materials"] = {"white": {"type": "diffuse"}, "steel": {"type": "ggx"}, "glass": {"type": "dielectric"},
                      "water": {"type": "dielectric", "int_ior": 1.333, "ext_ior": 1.0}}
    sc = S.load(write(tmp_path, d))
    assert list(sc.materials.kind) == [DIFFUSE, GGX, DIELECTRIC, DIELECTRIC]
    np.testing.assert_array_equal(sc.materials.params[:2], [[0.5, 0.5, 0.5, 0], [1, 1, 1, 0.1]])
    np.testing.assert_array_equal(sc.materials.params[2:, 0], [1.5046 / 1.000277, 1.333])
    for edit, fragment in (
            ({"int_ior": 0}, "materials.glass.int_ior: expected a number > 0, got 0"),
            ({"ext_ior": -1.0}, "materials.glass.ext_ior: expected a number > 0, got -1"),
            ({"int_ior": "bk7"}, "materials.glass.int_ior: expected a number > 0, got \"bk7\""),
            ({"tint": [1, 1, 1]}, "materials.glass.tint: unknown key; valid: type, int_ior, ext_ior")):
        bad = copy.deepcopy(d)
        bad["materials"]["glass"].update(edit)
        raises(tmp_path, bad, fragment)


def test_the_glass_cornell_box_is_cornell_with_a_glass_large_box():
    glass, cornell = S.load("cornell-glass"), S.load("cornell")
    assert glass.triangles.tobytes() == cornell.triangles.tobytes()
    assert glass.materials.names == cornell.materials.names + ("glass",)
    large = glass.shape_index == 6  # the large box, the seventh shape
    assert np.all(glass.material[large] == 3) and np.array_equal(glass.material[~large], cornell.material[~large])
    assert glass.materials.kind[3] == DIELECTRIC and glass.materials.params[3, 0] == 1.5046 / 1.000277
    assert (glass.max_depth, glass.mis, glass.width, glass.height) == (5, True, 256, 256)


def test_unknown_material(tmp_path):
    d = edited(lambda d: d["shapes"][1].update(material="whte"))
    raises(tmp_path, d, "shapes[1].material: unknown material 'whte'; valid: white, steel, glass", name="cornell.json")


@pytest.mark.parametrize("where, edit, fragments", [
    ("fov string", lambda d: d["camera"].update(fov="40"), ['camera.fov: expected a number in (0, 180), got "40"']),
    ("fov 180", lambda d: d["camera"].update(fov=180), ["camera.fov:", "got 180"]),
    ("fov bool", lambda d: d["camera"].update(fov=True), ["camera.fov:", "got true"]),
    ("fov missing", lambda d: d["camera"].pop("fov"), ["camera.fov: missing"]),
    ("aperture", lambda d: d["camera"].update(aperture=-1), ["camera.aperture:"]),
    ("focus", lambda d: d["camera"].update(aperture=0.1, focus_distance=0), ["camera.focus_distance:"]),
    ("focus missing", lambda d: d["camera"].update(aperture=0.1), ["camera.focus_distance: missing"]),
    ("motion", lambda d: d["camera"].update(motion=[0, 0]), ["camera.motion: expected a list of 3 numbers"]),
    ("motion bool", lambda d: d["camera"].update(motion=[0, False, 0]), ["camera.motion[1]:"]),
    ("camera scale", lambda d: d["camera"].update(to_world=[[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
     ["camera.to_world:", "rotation"]),
    ("camera key", lambda d: d["camera"].update(fovy=3), ["camera.fovy: unknown key; valid: to_world, fov"]),
    ("top key", lambda d: d.update(lights=[]), ["lights: unknown key; valid: description, camera"]),
    ("description", lambda d: d.update(description=3), ["description: expected a string"]),
    ("no camera", lambda d: d.pop("camera"), ["camera: missing"]),
    ("film width", lambda d: d.update(film={"width": 0}), ["film.width: expected an integer >= 1"]),
    ("film height", lambda d: d.update(film={"height": 2.5}), ["film.height: expected an integer >= 1"]),
    ("film key", lambda d: d.update(film={"size": 3}), ["film.size: unknown key; valid: width, height"]),
    ("max_depth", lambda d: d.update(integrator={"max_depth": 0}), ["integrator.max_depth: expected an integer in [1, 262143], got 0"]),
    ("max_depth bool", lambda d: d.update(integrator={"max_depth": True}), ["integrator.max_depth:", "got true"]),
    ("mis", lambda d: d.update(integrator={"mis": 1}), ["integrator.mis: expected true or false, got 1"]),
    ("shape key", lambda d: d["shapes"][0].update(colour=[1, 1, 1]),
     ["shapes[0].colour: unknown key; valid: type, id, to_world, material, emission, file"]),
    ("shape type", lambda d: d["shapes"][0].update(type="disk"), ["shapes[0].type: unknown shape type \"disk\""]),
    ("shape not object", lambda d: d["shapes"].append(3), ["shapes[2]: expected an object"]),
    ("no material", lambda d: d["shapes"][0].pop("material"), ["shapes[0].material: missing"]),
    ("material not string", lambda d: d["shapes"][0].update(material=0), ["shapes[0].material: expected a material name"]),
    ("file on a cube", lambda d: d["shapes"][0].update(type="cube", file="a.obj"), ["shapes[0].file: only a mesh"]),
    ("mesh without file", lambda d: d["shapes"][0].update(type="mesh"), ["shapes[0].file: missing"]),
    ("matrix shape", lambda d: d["shapes"][0].update(to_world=[[1, 0, 0], [0, 1, 0], [0, 0, 1]]),
     ["shapes[0].to_world: expected a 4x4 matrix"]),
    ("matrix entry", lambda d: d["shapes"][0].update(to_world=[[1, 0, 0, 0], [0, 1, "0", 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
     ["shapes[0].to_world[1][2]: expected a finite number"]),
    ("singular", lambda d: d["shapes"][1].update(to_world=[[1, 0, 0, 0], [0, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
     ["shapes[1].to_world: singular"]),
    ("projective", lambda d: d["shapes"][1].update(to_world=[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]),
     ["shapes[1].to_world: last row must be [0, 0, 0, 1]"]),
    ("negative emission", lambda d: d["shapes"][1].update(emission=[1, -1, 1]), ["shapes[1].emission[1]: expected a number in [0, 3.40282e+38], got -1"]),
    ("emission shape", lambda d: d["shapes"][1].update(emission=5), ["shapes[1].emission: expected a list of 3 numbers"]),
    ("no emitter", lambda d: d["shapes"].pop(), ["shapes: no shape has a nonzero emission: nothing would be lit"]),
    ("zero emitter", lambda d: d["shapes"][1].update(emission=[0, 0, 0]), ["nothing would be lit"]),
    ("no shapes", lambda d: d.update(shapes=[]), ["shapes: no shapes"]),
    ("shapes not list", lambda d: d.update(shapes={}), ["shapes: expected a list"]),
    ("material type", lambda d: d["materials"]["white"].update(type="plastic"),
     ["materials.white.type: unknown material type \"plastic\"; valid: dielectric, diffuse, ggx, mirror"]),
    ("material no type", lambda d: d["materials"]["white"].pop("type"), ["materials.white.type: missing"]),
    ("material key", lambda d: d["materials"]["white"].update(roughness=0.1),
     ["materials.white.roughness: unknown key; valid: type, reflectance"]),
    ("colour range", lambda d: d["materials"]["white"].update(reflectance=[0.5, 1.5, 0.5]),
     ["materials.white.reflectance[1]: expected a number in [0, 1], got 1.5"]),
    ("roughness", lambda d: d["materials"]["steel"].update(roughness=0), ["materials.steel.roughness: expected a number in (0, 1]"]),
    ("no materials", lambda d: d.update(materials={}), ["materials: no materials"]),
])
def test_validation_errors(tmp_path, where, edit, fragments):
    raises(tmp_path, edited(edit), *fragments)


def test_invalid_json_names_line_and_column(tmp_path):
    text = '{\n  "camera": {\n    "fov": 40,,\n  }\n}\n'
    raises(tmp_path, text, "x.json: invalid JSON at line 3, column 15: Expecting property name")


@pytest.mark.parametrize("text, fragment", [
    ('{"camera": {"fov": NaN}}', "NaN"),
    ('[1, 2]', "expected a JSON object"),
    ('{"camera": {}, "camera": {}}', "duplicate key 'camera'"),
])
def test_bad_json_documents(tmp_path, text, fragment):
    raises(tmp_path, text, fragment)


def test_missing_mesh_file(tmp_path):
    d = edited(lambda d: d["shapes"].append({"type": "mesh", "file": "gone.obj", "material": "white"}))
    msg = raises(tmp_path, d, "shapes[2].file: mesh file not found", "gone.obj", exc=FileNotFoundError)
    assert str(tmp_path) in msg


def test_mesh_trimesh_cannot_load(tmp_path):
    (tmp_path / "bad.xyz123").write_text("not a mesh")
    d = edited(lambda d: d["shapes"].append({"type": "mesh", "file": "bad.xyz123", "material": "white"}))
    raises(tmp_path, d, "shapes[2].file: trimesh cannot load 'bad.xyz123'")


def test_mesh_without_triangles(tmp_path):
    (tmp_path / "points.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    d = edited(lambda d: d["shapes"].append({"type": "mesh", "file": "points.obj", "material": "white"}))
    raises(tmp_path, d, "shapes[2].file: mesh 'points.obj' has no triangles")


def test_mesh_only_degenerate(tmp_path):
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
    d = edited(lambda d: d["shapes"].append({"type": "mesh", "file": "flat.obj", "material": "white"}))
    raises(tmp_path, d, "shapes[2].file:", "degenerate")


def test_minimal_is_not_mutated_by_edits():
    # guard for the parametrised edits above: each gets a fresh copy
    a, b = minimal(), copy.deepcopy(minimal())
    assert a == b
