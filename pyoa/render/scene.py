"""Scene files: a small JSON format modelled on Mitsuba 3's scene dictionaries.

A scene file is one JSON object::

    {
      "description": "optional free text",
      "camera": {"to_world": [[-1,0,0,0],[0,1,0,0],[0,0,-1,3.9],[0,0,0,1]], "fov": 39.3077,
                 "aperture": 0.0, "focus_distance": 3.9, "motion": [0, 0, 0]},
      "film": {"width": 256, "height": 256},
      "integrator": {"max_depth": 5, "mis": true, "robust_tracing": true},
      "materials": {"white": {"type": "diffuse", "reflectance": [0.885809, 0.698859, 0.666422]},
                    "steel": {"type": "ggx", "specular": [0.9, 0.9, 0.9], "roughness": 0.2},
                    "glass-mirror": {"type": "mirror", "tint": [1, 1, 1]}},
      "shapes": [
        {"type": "rectangle", "id": "floor", "to_world": [[...]], "material": "white"},
        {"type": "cube", "to_world": [[...]], "material": "white"},
        {"type": "mesh", "file": "meshes/thing.obj", "material": "white"},
        {"type": "rectangle", "to_world": [[...]], "material": "white", "emission": [18.387, 13.9873, 6.75357]}
      ]
    }

Conventions are Mitsuba's:

* ``rectangle`` is the square [-1, 1]^2 in the z = 0 plane with normal +z (two
  triangles, counter-clockwise seen from +z); ``cube`` is [-1, 1]^3 with
  outward normals (12 triangles); ``mesh`` is every triangle of a file trimesh
  can load (``file`` is relative to the scene file).
* ``to_world`` is a row-major 4x4 affine matrix applied to column vectors
  (default: identity). A triangle's geometric normal is
  ``cross(v1 - v0, v2 - v0)`` of its world-space vertices as stored and
  traced, in float32 (:func:`triangle_geometry`); where
  ``det(to_world[:3, :3]) < 0`` the winding of every triangle is reversed so
  that normals keep pointing to the front (outwards). A mesh's triangles
  that are flat in float32 (``FLAT_RATIO``) are dropped; a ``rectangle`` or
  ``cube`` whose ``to_world`` makes them flat is refused.
* ``emission`` (RGB radiance, in [0, 3.4e38], what a float32 image can hold) turns a shape into an area light that emits
  on its front side only. A scene needs at least one emitter.
* ``camera.fov`` is in degrees along the smaller image axis; ``aperture`` is
  the thin-lens radius (0: pinhole); ``focus_distance`` > 0; ``motion`` is a
  world-space translation of the camera over the shutter interval [0, 1).
  The camera looks along its local +z with local +y up.
* ``integrator.max_depth`` counts path segments (1: only emitters seen
  directly, 2: direct lighting); ``integrator.mis`` (default true) false
  means the last path vertex samples the lights only, no BSDF sample.
  ``integrator.robust_tracing`` (default true) traces with Embree's robust
  mode, watertight at the edges that triangles share; false traces without
  it, as Mitsuba 3 does by default (its ``embree_use_robust_intersections``),
  1.4-1.6x faster, but 1 to 2.5 % of the rays aimed exactly at a shared edge
  pass through it (docs/rendering.md, "Tracing"). The compiled shading
  follows it; the NumPy reference always traces robustly (embreex).
* Materials: one per BSDF of :mod:`pyoa.render.bsdfs`, whose module declares
  its keys: ``diffuse`` (``reflectance``, default 0.5 grey), ``ggx`` (a
  rough conductor: ``specular`` colour, default white, and ``roughness``, the
  GGX alpha as Mitsuba's ``alpha``, in (0, 1], default 0.1), ``mirror``
  (``tint``, default white) and ``dielectric`` (smooth glass, as Mitsuba's:
  ``int_ior``, default 1.5046, and ``ext_ior``, default 1.000277). Colours
  are RGB in [0, 1].
* Embree traces in float32, so the scene must be one float32 resolves
  (:func:`_check_float32_precision`): its largest coordinate (vertices and
  camera) at most ``MAX_POSITION_RATIO`` = 2^15 times its extent (the scene
  spans at least 256 float32 steps), and its extent at most ``MAX_EXTENT`` =
  1e12 (the products of Embree's ray-triangle test stay within float32) and
  at least ``MIN_EXTENT`` = 1e-9.

Every error found on load is a :class:`ValueError` whose message names the
file and the field (``cornell.json: shapes[3].material: unknown material
'whte'; valid: white, red, green``); a missing scene or mesh file raises
:class:`FileNotFoundError`. Bundled scenes (the ``scenes/`` folder, shipped
as ``pyoa.scenes``) load by name: ``load("cornell")``.
"""

from __future__ import annotations

import gc
import io
import json
import math
import os
import weakref
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from pyoa.render.bsdfs import BSDFS, KINDS, Materials
from pyoa.render.geometry import dot
from pyoa.render.layout import MAX_DEPTH
from pyoa.render.state import NotRegularFile, check_state_file, open_regular

__all__ = ["Camera", "Scene", "SceneError", "UnknownSceneError", "load", "bundled", "rectangle", "cube"]


class SceneError(ValueError):
    """An invalid scene file (message: ``file: field: problem``)."""


class UnknownSceneError(FileNotFoundError, ValueError):
    """A scene name that is neither a file nor a bundled scene (both a
    :class:`FileNotFoundError` and a :class:`ValueError`)."""


# -- data ---------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Camera:
    """A perspective (thin-lens) camera, Mitsuba's conventions."""

    to_world: np.ndarray  # (4, 4) float64
    fov: float  # degrees, along the smaller image axis
    aperture: float  # lens radius, 0 = pinhole
    focus_distance: float
    motion: np.ndarray  # (3,) float64, world-space translation over the shutter

    @property
    def position(self) -> np.ndarray:
        """Camera position at time 0."""
        return self.to_world[:3, 3].copy()


@dataclass(frozen=True, eq=False)
class Scene:
    """A loaded scene: world-space triangles and everything needed to render them."""

    path: str  # the file it came from
    name: str  # file stem
    triangles: np.ndarray  # (T, 3, 3) float32, world space
    normals: np.ndarray  # (T, 3) float64 unit geometric normals of the float32 triangles (triangle_geometry)
    areas: np.ndarray  # (T,) float64, of the float32 triangles
    material: np.ndarray  # (T,) int32 material id per triangle
    emission: np.ndarray  # (T, 3) float64, 0 for non-emitters
    materials: Materials
    camera: Camera
    width: int
    height: int
    max_depth: int
    mis: bool
    robust_tracing: bool = True  # Embree's robust mode (integrator.robust_tracing)
    description: str = ""
    shape_index: np.ndarray = field(default=None)  # (T,) int32: which entry of "shapes" made each triangle

    @property
    def emitters(self) -> np.ndarray:
        """Indices of the emissive triangles."""
        return np.flatnonzero(self.emission.max(axis=1) > 0)

    def __repr__(self) -> str:
        return (f"Scene({self.name!r}, {len(self.triangles)} triangles, {len(self.emitters)} emissive, "
                f"{len(self.materials.names)} materials, {self.width}x{self.height}, "
                f"max_depth={self.max_depth}, mis={self.mis})")


# -- canonical shapes ------------------------------------------------------------


def rectangle() -> np.ndarray:
    """Mitsuba's rectangle: [-1, 1]^2 at z = 0, normal +z; (2, 3, 3) float64."""
    v = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float64)
    return v[np.array([[0, 1, 2], [0, 2, 3]])]


def cube() -> np.ndarray:
    """Mitsuba's cube: [-1, 1]^3 with outward normals; (12, 3, 3) float64."""
    faces = []
    rect = rectangle()
    for axis in range(3):
        for sign in (1.0, -1.0):
            # Map the rectangle's (x, y, z=1) frame onto the face whose outward
            # normal is sign * e_axis, keeping the frame right-handed.
            n = np.zeros(3)
            n[axis] = sign
            a = np.zeros(3)
            a[(axis + 1) % 3] = 1.0
            b = np.cross(n, a)
            m = np.stack([a, b, n], axis=1)  # columns: local x, y, z
            faces.append(rect @ m.T + n)
    return np.concatenate(faces)


# -- validation helpers -----------------------------------------------------------


#: Largest value a float32 image holds (emission, world coordinates).
FLOAT32_MAX = float(np.finfo(np.float32).max)
#: A scene's largest coordinate may be at most this many times its extent:
#: float32 numbers near a coordinate C are up to 2^-23 C apart, so the scene
#: spans at least 2^23 / 2^15 = 256 float32 steps (see _check_float32_precision).
MAX_POSITION_RATIO = 2.0**15
#: Largest extent of a scene (the longest side of the bounding box of its
#: vertices and camera); see _check_float32_precision.
MAX_EXTENT = 1e12
#: Smallest extent of a scene; see _check_float32_precision.
MIN_EXTENT = 1e-9
#: Longest integer literal read from a scene file (Python's own limit on
#: int-from-string conversion is 4300 digits; no field needs more than a few).
MAX_INT_DIGITS = 100


class _HugeInt:
    """An integer literal too long to convert (see ``MAX_INT_DIGITS``): kept as
    text so that the field check holding it names the file and field."""

    def __init__(self, text: str):
        self.digits = len(text.lstrip("-"))

    def __repr__(self) -> str:
        return f"an integer of {self.digits} digits"


def _parse_int(text: str):
    return int(text) if len(text) <= MAX_INT_DIGITS else _HugeInt(text)


class _Ctx:
    """Formats error messages as ``file: field: problem``."""

    def __init__(self, filename: str):
        self.filename = filename

    def error(self, where: str, msg: str) -> SceneError:
        return SceneError(f"{self.filename}: {where}: {msg}" if where else f"{self.filename}: {msg}")


def _show(value) -> str:
    try:
        s = json.dumps(value)
    except (TypeError, ValueError, RecursionError):  # a _HugeInt, or deeply nested lists
        s = repr(value) if not isinstance(value, (list, dict)) else type(value).__name__
    return s if len(s) <= 60 else s[:57] + "..."


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _check_keys(ctx: _Ctx, where: str, obj, valid: tuple[str, ...], required: tuple[str, ...] = ()):
    if not isinstance(obj, dict):
        raise ctx.error(where, f"expected an object, got {_show(obj)}")
    for k in obj:
        if k not in valid:
            raise ctx.error(_join(where, k), f"unknown key; valid: {', '.join(valid)}")
    for k in required:
        if k not in obj:
            raise ctx.error(_join(where, k), "missing (required)")


def _join(where: str, key) -> str:
    if isinstance(key, int):
        return f"{where}[{key}]"
    return f"{where}.{key}" if where else key


def _number(ctx, where, v, lo=-math.inf, hi=math.inf, lo_open=False, hi_open=False) -> float:
    lb, rb = ("(" if lo_open else "["), (")" if hi_open else "]")
    if math.isinf(lo) and math.isinf(hi):
        want = "a finite number"
    elif math.isinf(hi):
        want = f"a number {'>' if lo_open else '>='} {lo:g}"
    else:
        want = f"a number in {lb}{lo:g}, {hi:g}{rb}"
    if not _is_number(v) or not math.isfinite(v):
        raise ctx.error(where, f"expected {want}, got {_show(v)}")
    if v < lo or v > hi or (lo_open and v == lo) or (hi_open and v == hi):
        raise ctx.error(where, f"expected {want}, got {_show(v)}")
    return float(v)


def _integer(ctx, where, v, lo: int, hi: int | None = None) -> int:
    """An integer literal in [lo, hi]; a float (even 256.0 or 1e9) is refused:
    JSON writes counts without a fraction or exponent."""
    want = f"an integer >= {lo}" if hi is None else f"an integer in [{lo}, {hi}]"
    if isinstance(v, bool) or not isinstance(v, int):
        raise ctx.error(where, f"expected {want}, got {_show(v)}")
    if v < lo or (hi is not None and v > hi):
        raise ctx.error(where, f"expected {want}, got {_show(v)}")
    return v


def _boolean(ctx, where, v) -> bool:
    if not isinstance(v, bool):
        raise ctx.error(where, f"expected true or false, got {_show(v)}")
    return v


def _string(ctx, where, v) -> str:
    if not isinstance(v, str):
        raise ctx.error(where, f"expected a string, got {_show(v)}")
    return v


def _vector(ctx, where, v, n=3, lo=-math.inf, hi=math.inf) -> np.ndarray:
    """A list of n numbers, each in [lo, hi]."""
    if not isinstance(v, list) or len(v) != n:
        raise ctx.error(where, f"expected a list of {n} numbers, got {_show(v)}")
    for i, x in enumerate(v):
        _number(ctx, _join(where, i), x, lo, hi)
    return np.array(v, dtype=np.float64)


def _matrix(ctx, where, v) -> np.ndarray:
    """A row-major 4x4 affine, invertible matrix."""
    ok = isinstance(v, list) and len(v) == 4 and all(isinstance(r, list) and len(r) == 4 for r in v)
    if not ok:
        raise ctx.error(where, f"expected a 4x4 matrix (a list of 4 rows of 4 numbers), got {_show(v)}")
    for i, row in enumerate(v):
        for j, x in enumerate(row):
            _number(ctx, f"{where}[{i}][{j}]", x)
    m = np.array(v, dtype=np.float64)
    if not np.allclose(m[3], [0, 0, 0, 1], rtol=0, atol=1e-9):
        raise ctx.error(where, f"last row must be [0, 0, 0, 1] (an affine transform), got {_show(v[3])}")
    m[3] = [0, 0, 0, 1]
    a = m[:3, :3]
    scale = np.abs(a).max()
    # det of the matrix scaled to entries <= 1: scale**3 would overflow for large entries
    if scale == 0 or abs(np.linalg.det(a / scale)) <= 1e-12:
        raise ctx.error(where, "singular matrix (det of the upper-left 3x3 is 0)")
    return m


def _transform(tris: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Apply the affine ``m`` to (T, 3, 3) triangles, reversing the winding
    where it mirrors."""
    out = tris @ m[:3, :3].T + m[:3, 3]
    if np.linalg.det(m[:3, :3]) < 0:
        out = out[:, [0, 2, 1]]
    return out


#: A triangle is flat, and dropped from a mesh (a ``rectangle`` or ``cube``
#: made flat by its ``to_world`` is refused), when its float32 vertices, the
#: ones stored and traced, rise less than ``FLAT_RATIO`` of its longest edge
#: above it (twice its area under ``FLAT_RATIO`` times the edge squared):
#: the height of 16 float32 steps of the edge's length. Embree computes the
#: triangle's normal in float32, which turns by about 2^-24 of the edge over
#: the height for a triangle whose edges are all long (a cap): beyond 2^-4
#: radian below this ratio, and the ray offsets that keep new rays off such
#: a triangle (pyoa.render.integrator.triangle_reach) would exceed its size.
#: Triangles of zero area in float32 (``[[0,0,0],[1,1,1],[2,2,2+1e-7]]``)
#: have no normal at all.
FLAT_RATIO = 2.0**-20
_FLAT = "twice the area under 2^-20 times the longest edge squared"


def triangle_geometry(triangles: np.ndarray):
    """``(normals, areas, keep)`` of the ``(T, 3, 3)`` float32 triangles, as
    they are stored and traced: the unit geometric normals ``cross(v1 - v0,
    v2 - v0)`` and the areas (``(T, 3)`` and ``(T,)`` float64, computed in
    float64 from the float32 vertices, whose differences and products are
    then exact or nearly), and which triangles are not flat (``FLAT_RATIO``;
    a flat one's normal is 0). The one place where the normals that shading,
    light sampling and ray offsets use are computed."""
    v0 = triangles[:, 0].astype(np.float64)
    e1 = triangles[:, 1] - v0
    e2 = triangles[:, 2] - v0
    del v0
    cross = np.cross(e1, e2)
    longest2 = np.maximum(dot(e1, e1), dot(e2, e2))
    e2 -= e1
    np.maximum(longest2, dot(e2, e2), out=longest2)
    del e1, e2
    twice_area = np.sqrt(dot(cross, cross))
    keep = twice_area > FLAT_RATIO * longest2
    cross /= np.where(keep, twice_area, 1.0)[:, None]
    cross[~keep] = 0.0
    return cross, 0.5 * twice_area, keep


def _check_float32_precision(ctx: _Ctx, bounds, camera: Camera, shapes) -> None:
    """Refuse (:class:`SceneError`) a scene that Embree's float32 ray tracing
    cannot resolve. The rules look at the axis-aligned box around the
    vertices (``bounds``: ``(index, low corner, high corner)`` of each shape
    in world space) and the camera (its positions when the shutter opens and
    closes, widened by the lens radius); the extent ``E`` is the box's
    longest side, ``C`` the largest coordinate magnitude in it.

    * ``C <= MAX_POSITION_RATIO * E`` (2^15 E): float32 numbers near ``C``
      are up to ``2^-23 C`` apart, so the scene spans at least 256 float32
      steps. Beyond, storing the vertices as float32 moves them by a visible
      part of the scene (the cornell box translated by 1e5 along x, ``C / E``
      = 2e4, loses 1.5 % of its light's width and 0.9 % of the image mean; at
      1e13 float32 steps are 2e5 times the box). A scene far from the origin
      must be moved near it.
    * ``E <= MAX_EXTENT`` (1e12): Embree's ray-triangle test multiplies three
      coordinate differences (each up to the box's diagonal, ``sqrt(3) E``);
      beyond about 1e12 the products near float32's largest value, 3.4e38,
      and rays miss (the cornell box scaled by 3e12 loses 22 % of the image
      mean, by 1e13 99 %). Such a scene must be scaled down, or its camera
      brought closer.
    * ``E >= MIN_EXTENT`` (1e-9): below about 1e-11 the renderer's guards
      against zero lengths (1e-12) and Embree's float32 products (under
      1.2e-38, float32's smallest normal number, below about 2e-13) take
      over: the cornell box 4.9e-11 across renders as it does 4.9 across,
      4.9e-12 across 1.4 % darker, 9.8e-13 across 35 %. Such a scene must be
      scaled up. (Triangles are flat relative to their own size,
      ``FLAT_RATIO``: this rule, not that one, refuses a tiny scene.)

    Scaling alone keeps ``C / E``, and the renderer's ray offsets follow the
    size of the geometry (``pyoa.render.integrator.offset_distance``), so a
    scene renders the same at every scale between these limits.
    """
    pos = camera.to_world[:3, 3]
    cam = np.stack([pos, pos + camera.motion])
    cam = np.concatenate([cam - camera.aperture, cam + camera.aperture])
    lows = np.array([b[1] for b in bounds])
    highs = np.array([b[2] for b in bounds])
    lo = np.minimum(lows.min(axis=0), cam.min(axis=0))
    hi = np.maximum(highs.max(axis=0), cam.max(axis=0))
    extent = float((hi - lo).max())
    if extent > MAX_EXTENT:
        raise ctx.error("", f"the scene is {extent:.3g} across (vertices and camera), over the {MAX_EXTENT:.0e} "
                            f"that Embree's float32 ray tracing handles: its ray-triangle test multiplies three "
                            f"coordinate differences, which overflow float32 (3.4e38), and rays miss; "
                            f"scale the scene down or bring the camera closer")
    if extent < MIN_EXTENT:
        raise ctx.error("", f"the scene is {extent:.3g} across (vertices and camera), under the {MIN_EXTENT:.0e} "
                            f"that pyoa's renderer handles: its guards against zero lengths and Embree's float32 "
                            f"products of coordinate differences take over, and the image is wrong; "
                            f"scale the scene up")
    per_shape = np.maximum(np.abs(lows), np.abs(highs)).max(axis=1)
    k = int(per_shape.argmax())
    largest_cam = float(np.abs(cam).max())
    largest = max(float(per_shape[k]), largest_cam)
    if largest > MAX_POSITION_RATIO * extent:
        if largest_cam >= per_shape[k]:
            where = "camera"
        else:
            i = bounds[k][0]
            where = f"shapes[{i}].to_world" if "to_world" in shapes[i] else f"shapes[{i}].file"
        spacing = float(np.spacing(np.float32(largest)))
        raise ctx.error(where, f"coordinates up to {largest:.3g} with an extent of {extent:.3g} (vertices and "
                               f"camera): float32, which Embree traces in, is {spacing:.3g} apart there, "
                               f"{spacing / extent:.3g} times the scene's extent; a scene must span at least "
                               f"{2.0**23 / MAX_POSITION_RATIO:.0f} float32 steps (coordinates at most "
                               f"{MAX_POSITION_RATIO:.0f} times its extent): move the scene near the origin")


# -- loading -------------------------------------------------------------------------

_TOP = ("description", "camera", "film", "integrator", "materials", "shapes")
_CAMERA = ("to_world", "fov", "aperture", "focus_distance", "motion")
_FILM = ("width", "height")
_INTEGRATOR = ("max_depth", "mis", "robust_tracing")
_SHAPE = ("type", "id", "to_world", "material", "emission", "file")
_SHAPE_TYPES = ("rectangle", "cube", "mesh")
#: Material types (a material's ``type``): the BSDFs of pyoa.render.bsdfs, each with its keys.
_MATERIAL_TYPES = tuple(sorted(KINDS))


def _no_duplicates(ctx: _Ctx):
    def hook(pairs):
        out = {}
        for k, v in pairs:
            if k in out:
                raise ctx.error("", f"duplicate key {k!r} in one object")
            out[k] = v
        return out

    return hook


def _reject_constant(ctx: _Ctx):
    def hook(name):
        raise ctx.error("", f"invalid JSON: {name} is not a number JSON allows")

    return hook


def _parse(path: Path, ctx: _Ctx) -> dict:
    # read from the descriptor checked to be a regular file (a FIFO would block, a device be read for ever),
    # with universal newlines as Path.read_text
    try:
        with io.TextIOWrapper(open_regular(path, "a scene file", "give a scene .json file"), encoding="utf-8") as fh:
            text = fh.read()
    except UnicodeDecodeError as e:
        raise ctx.error("", f"not UTF-8 text ({e})") from None
    except NotRegularFile as e:
        raise ctx.error("", str(e)) from None
    try:
        data = json.loads(text, object_pairs_hook=_no_duplicates(ctx), parse_constant=_reject_constant(ctx),
                          parse_int=_parse_int)
    except json.JSONDecodeError as e:
        raise ctx.error("", f"invalid JSON at line {e.lineno}, column {e.colno}: {e.msg}") from None
    except RecursionError:  # the parser recurses once per nested list or object
        raise ctx.error("", "invalid scene: lists or objects nested too deeply") from None
    if not isinstance(data, dict):
        raise ctx.error("", f"expected a JSON object at the top level, got {type(data).__name__}")
    return data


def _camera(ctx: _Ctx, v) -> Camera:
    _check_keys(ctx, "camera", v, _CAMERA, required=("fov",))
    to_world = _matrix(ctx, "camera.to_world", v["to_world"]) if "to_world" in v else np.eye(4)
    r = to_world[:3, :3]
    if not np.allclose(r.T @ r, np.eye(3), rtol=0, atol=1e-4):
        raise ctx.error("camera.to_world", "the upper-left 3x3 must be a rotation (orthonormal columns, no scale)")
    fov = _number(ctx, "camera.fov", v["fov"], 0, 180, lo_open=True, hi_open=True)
    aperture = _number(ctx, "camera.aperture", v.get("aperture", 0.0), 0)
    if aperture > 0 and "focus_distance" not in v:
        raise ctx.error("camera.focus_distance", "missing (required when camera.aperture > 0)")
    focus = _number(ctx, "camera.focus_distance", v.get("focus_distance", 1.0), 0, lo_open=True)
    motion = _vector(ctx, "camera.motion", v.get("motion", [0.0, 0.0, 0.0]))
    return Camera(to_world=_frozen(to_world), fov=fov, aperture=aperture, focus_distance=focus,
                  motion=_frozen(motion))


def _materials(ctx: _Ctx, v) -> tuple[Materials, dict[str, int]]:
    if not isinstance(v, dict):
        raise ctx.error("materials", f"expected an object (name -> material), got {_show(v)}")
    if not v:
        raise ctx.error("materials", "no materials defined")
    specs = []
    for name, m in v.items():
        where = f"materials.{name}"
        if not name:
            raise ctx.error("materials", "empty material name")
        if not isinstance(m, dict):
            raise ctx.error(where, f"expected an object, got {_show(m)}")
        if "type" not in m:
            raise ctx.error(_join(where, "type"), f"missing (required); valid: {', '.join(_MATERIAL_TYPES)}")
        t = m["type"]
        if t not in _MATERIAL_TYPES:
            raise ctx.error(_join(where, "type"),
                            f"unknown material type {_show(t)}; valid: {', '.join(_MATERIAL_TYPES)}")
        keys = BSDFS[KINDS[t]].KEYS
        _check_keys(ctx, where, m, ("type",) + tuple(k.name for k in keys))
        values = {}
        for k in keys:  # each checked here, so that an error names its field
            path = _join(where, k.name)
            if k.size is None:
                values[k.name] = _number(ctx, path, m.get(k.name, k.default), k.lo, k.hi, lo_open=k.lo_open,
                                         hi_open=k.hi_open)
            else:
                values[k.name] = tuple(_vector(ctx, path, m.get(k.name, list(k.default)), n=k.size, lo=k.lo,
                                               hi=k.hi))
        specs.append((name, t, values))
    ids = {name: i for i, (name, *_rest) in enumerate(specs)}
    return Materials.build(specs), ids


#: Peak memory of trimesh's parse of a mesh file, per byte of the file:
#: measured (VmHWM above the process before it, 1M-triangle meshes, trimesh
#: 5.2) 6.7 (OBJ), 8.0 (GLB), 9.6 (binary STL) and 10.6 (binary PLY); 12
#: with a margin. Checked before the file is parsed.
MESH_FILE_FACTOR = 12
#: Peak memory of loading a mesh, per triangle: trimesh's arrays, the float64
#: world-space copies made here and the scene's own arrays. Measured the same
#: way: 236 bytes (GLB), 273 (binary PLY), 289 (OBJ) and 494 (binary STL,
#: which repeats every vertex); 1 KiB with a margin (440 to 718 while the
#: parsed mesh waited for the garbage collector). Checked once the file is
#: parsed, before the copies are made.
MESH_TRIANGLE_BYTES = 1024
#: Memory per triangle of the meshes loaded before one: their float64
#: world-space vertices (72 bytes) while it loads, then the scene's arrays
#: as they are built and joined (float32 vertices, float64 normals, areas
#: and emission, ids: 76 bytes, twice while they are joined). Measured as
#: the peak of scenes of 2, 4 and 8 binary PLY meshes of 250 000 triangles
#: less that of one, per triangle of the others: 130, 202 and 192 bytes;
#: 256 with a margin. A mesh is checked at MESH_TRIANGLE_BYTES per triangle
#: of its own plus this per triangle of the meshes before it: only one mesh
#: is parsed and copied at a time (ten meshes of 1M triangles: 3.1 GiB, not
#: the 9.5 GiB of 1 KiB each).
MESH_KEPT_BYTES = 256


class _MeshMemory:
    """The memory limit of a scene's meshes and the triangles of the meshes
    loaded so far (kept at ``MESH_KEPT_BYTES`` each while the next loads)."""

    def __init__(self, limit: int):
        self.limit, self.triangles = limit, 0

    def check(self, ctx: _Ctx, where: str, nbytes: int, what: str) -> None:
        from .render import check_memory

        try:
            check_memory(nbytes, what, self.limit, "use a mesh of fewer triangles")
        except ValueError as e:
            raise ctx.error(where, str(e)) from None


def _mesh(ctx: _Ctx, where: str, file, base: Path, memory: _MeshMemory) -> np.ndarray:
    import trimesh

    rel = _string(ctx, where, file)
    path = (base / rel).resolve()
    if not path.exists():
        raise FileNotFoundError(f"{ctx.filename}: {where}: mesh file not found: {path}")
    from .mesh_files import companions

    try:  # a FIFO would block trimesh for ever, a device be read for ever: the mesh and the files it names
        check_state_file(path, "a mesh file", "give a mesh file")
        size = path.stat().st_size
        memory.check(ctx, where, size * MESH_FILE_FACTOR, f"parsing mesh {rel!r} ({size} bytes)")
        for companion in companions(path):
            check_state_file(companion, f"a file that mesh {rel!r} names", "give a regular file")
    except NotRegularFile as exc:
        raise ctx.error(where, str(exc)) from None
    try:
        mesh = trimesh.load(str(path), force="mesh", process=False)
    except MemoryError:
        raise  # not a bad file: pyoa's command line says so in one line
    except Exception as e:  # noqa: BLE001 - trimesh raises anything from a bad file
        raise ctx.error(where, f"trimesh cannot load {rel!r}: {type(e).__name__}: {e}") from None
    faces = getattr(mesh, "faces", None)
    vertices = getattr(mesh, "vertices", None)
    if faces is None or vertices is None or len(faces) == 0:
        raise ctx.error(where, f"mesh {rel!r} has no triangles")
    kept = memory.triangles
    also = f" (and the {kept} triangles of the meshes before it)" if kept else ""
    memory.check(ctx, where, len(faces) * MESH_TRIANGLE_BYTES + kept * MESH_KEPT_BYTES,
                 f"loading mesh {rel!r} of {len(faces)} triangles{also}")
    memory.triangles += len(faces)
    tris = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)]
    # A trimesh mesh is a reference cycle: left to the garbage collector, its
    # arrays (about 180 bytes per triangle) stayed while the next meshes
    # loaded. Collecting the young generations is cheap (ms); the whole heap
    # (about 0.1 s) only if the mesh got older.
    gone = weakref.ref(mesh)
    del mesh, faces, vertices
    gc.collect(1)
    if gone() is not None:
        gc.collect()
    if tris.ndim != 3 or tris.shape[1:] != (3, 3) or not np.isfinite(tris).all():
        raise ctx.error(where, f"mesh {rel!r} has invalid vertex data")
    return tris


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


def _shapes(ctx: _Ctx, v, ids: dict[str, int], base: Path, camera: Camera, memory: _MeshMemory):
    if not isinstance(v, list):
        raise ctx.error("shapes", f"expected a list of shapes, got {_show(v)}")
    if not v:
        raise ctx.error("shapes", "no shapes")
    shapes = []  # (index, shape, world, material id, emission), checked for precision before flatness
    tris, normals, areas, mats, ems, owner = [], [], [], [], [], []
    valid_mats = ", ".join(ids)
    for i, s in enumerate(v):
        where = f"shapes[{i}]"
        _check_keys(ctx, where, s, _SHAPE, required=("type", "material"))
        t = s["type"]
        if t not in _SHAPE_TYPES:
            raise ctx.error(f"{where}.type", f"unknown shape type {_show(t)}; valid: {', '.join(_SHAPE_TYPES)}")
        if "id" in s:
            _string(ctx, f"{where}.id", s["id"])
        if t == "mesh":
            if "file" not in s:
                raise ctx.error(f"{where}.file", "missing (required for a mesh)")
            local = _mesh(ctx, f"{where}.file", s["file"], base, memory)
        elif "file" in s:
            raise ctx.error(f"{where}.file", f"only a mesh has a file, not a {t}")
        else:
            local = rectangle() if t == "rectangle" else cube()
        m = _matrix(ctx, f"{where}.to_world", s["to_world"]) if "to_world" in s else np.eye(4)
        name = s["material"]
        if not isinstance(name, str):
            raise ctx.error(f"{where}.material", f"expected a material name (string), got {_show(name)}")
        if name not in ids:
            raise ctx.error(f"{where}.material", f"unknown material {name!r}; valid: {valid_mats}")
        emission = np.zeros(3)
        if "emission" in s:
            # a larger radiance would be inf in the float32 image
            emission = _vector(ctx, f"{where}.emission", s["emission"], lo=0, hi=FLOAT32_MAX)
        world = _transform(local, m)
        del local  # not kept while the next mesh loads (MESH_KEPT_BYTES)
        if not np.all(np.abs(world) <= FLOAT32_MAX):  # triangles are stored (and traced) as float32
            field_ = f"{where}.to_world" if "to_world" in s else f"{where}.file"
            raise ctx.error(field_, f"vertices beyond the float32 range (|x| <= {FLOAT32_MAX:.4g}) in world space")
        shapes.append((i, s, world, ids[name], emission))
    # before the flatness test below, of the float32 vertices: a scene far
    # from the origin is refused as far, not as flat
    _check_float32_precision(ctx, [(i, w.min(axis=(0, 1)), w.max(axis=(0, 1))) for i, _s, w, _m, _e in shapes],
                             camera, v)
    for j, (i, s, world, mat, emission) in enumerate(shapes):
        shapes[j] = None  # the float64 copy goes once its float32 one replaces it
        where, t = f"shapes[{i}]", s["type"]
        world = world.astype(np.float32)  # as stored and traced
        normal, area, keep = triangle_geometry(world)
        if t == "mesh":
            if not keep.all():  # a mesh may carry degenerate faces: no area, no normal
                world, normal, area = world[keep], normal[keep], area[keep]
            if len(world) == 0:
                raise ctx.error(f"{where}.file", f"mesh {s['file']!r} has only degenerate triangles "
                                                 f"(flat in float32: {_FLAT})")
        elif not keep.all():
            raise ctx.error(f"{where}.to_world", f"the transform makes triangles flat in float32 ({_FLAT}); "
                                                 f"scale the shape less unevenly")
        tris.append(world)
        normals.append(normal)
        areas.append(area)
        mats.append(np.full(len(world), mat, dtype=np.int32))
        ems.append(np.tile(emission, (len(world), 1)))
        owner.append(np.full(len(world), i, dtype=np.int32))
    return tuple(np.concatenate(a) for a in (tris, normals, areas, mats, ems, owner))


def _load_file(path: Path, max_bytes: int) -> Scene:
    ctx = _Ctx(path.name)
    if not path.exists():
        raise FileNotFoundError(f"{path.name}: scene file not found: {path}")
    data = _parse(path, ctx)
    _check_keys(ctx, "", data, _TOP, required=("camera", "materials", "shapes"))
    description = _string(ctx, "description", data.get("description", ""))
    camera = _camera(ctx, data["camera"])
    film = data.get("film", {})
    _check_keys(ctx, "film", film, _FILM)
    width = _integer(ctx, "film.width", film.get("width", 256), 1)
    height = _integer(ctx, "film.height", film.get("height", 256), 1)
    integ = data.get("integrator", {})
    _check_keys(ctx, "integrator", integ, _INTEGRATOR)
    max_depth = _integer(ctx, "integrator.max_depth", integ.get("max_depth", 5), 1, MAX_DEPTH)
    mis = _boolean(ctx, "integrator.mis", integ.get("mis", True))
    robust = _boolean(ctx, "integrator.robust_tracing", integ.get("robust_tracing", True))
    materials, ids = _materials(ctx, data["materials"])
    memory = _MeshMemory(max_bytes)
    world, normals, areas, material, emission, owner = _shapes(ctx, data["shapes"], ids, path.parent, camera,
                                                               memory)
    if not (emission.max(axis=1) > 0).any():
        raise ctx.error("shapes", "no shape has a nonzero emission: nothing would be lit")
    return Scene(
        path=str(path),
        name=path.stem,
        triangles=_frozen(world),
        normals=_frozen(normals),
        areas=_frozen(areas),
        material=_frozen(material),
        emission=_frozen(emission),
        materials=materials,
        camera=camera,
        width=width,
        height=height,
        max_depth=max_depth,
        mis=mis,
        robust_tracing=robust,
        description=description,
        shape_index=_frozen(owner),
    )


def bundled() -> dict[str, str]:
    """Name -> path of every scene shipped in the package (``pyoa.scenes``)."""
    root = resources.files("pyoa.scenes")
    out = {}
    for entry in root.iterdir():
        if entry.name.endswith(".json") and entry.is_file():
            out[entry.name[: -len(".json")]] = str(entry)
    return dict(sorted(out.items()))


def load(scene: str | os.PathLike, max_bytes: int | str | None = None) -> Scene:
    """Load a scene: a path to a ``.json`` file, or the name of a bundled
    scene (``"cornell"``, see :func:`bundled`).

    Its meshes must load within the memory limit ``max_bytes`` (default
    ``$PYOA_MAX_BYTES``, else half the usable memory: :func:`pyoa.render.render.resolve_max_bytes`):
    a mesh file is refused before it is parsed if its size, and once parsed
    if its triangles with those of the meshes before it, need more
    (``MESH_FILE_FACTOR`` per byte, ``MESH_TRIANGLE_BYTES`` per triangle of
    the mesh, ``MESH_KEPT_BYTES`` per triangle before it); a
    :class:`SceneError`."""
    from .render import resolve_max_bytes

    limit = resolve_max_bytes(max_bytes)
    if isinstance(scene, os.PathLike):
        return _load_file(Path(scene), limit)
    if not isinstance(scene, str):
        raise TypeError(f"scene must be a path or a bundled scene name, got {type(scene).__name__}")
    p = Path(scene)
    if p.is_file() or scene.endswith(".json") or os.sep in scene or "/" in scene:
        return _load_file(p, limit)
    names = bundled()
    if scene not in names:
        raise UnknownSceneError(f"{scene}: no such scene file or bundled scene; bundled: {', '.join(names)}")
    return _load_file(Path(names[scene]), limit)
