"""A scene as workers of a cluster load it: a bundled name, or its files' bytes.

The client has loaded and validated the scene (:func:`pyoa.render.scene.load`);
a worker must render the very same one. :class:`SceneSource` carries what a
worker needs to load it itself: the name of a bundled scene, or the scene
file's bytes and those of every mesh file it reads, with the files those
read in turn (a glTF's buffers and images, an OBJ's material library; sent
once to each worker, written to a private directory there and loaded from
it). Both carry the
client's :func:`~pyoa.render.state.scene_digest`, and a worker that loads
anything else (another pyoa version's bundled scene) refuses to render it.

Loaded scenes are kept per worker process (:func:`load_source`), so the tasks
of a job load their scene once per worker, not once per task.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

from .mesh_files import companions
from .scene import Scene, bundled, load
from .state import scene_digest


@dataclass(frozen=True)
class SceneSource:
    """What a worker needs to load a scene (see the module docstring)."""

    digest: str
    #: the bundled scene's name, or None when ``files`` carries it
    name: str | None = None
    #: relative path -> bytes of the scene file and its meshes (None for a bundled scene)
    files: tuple[tuple[str, bytes], ...] | None = None
    #: the scene file's relative path among ``files``
    main: str | None = None

    @property
    def label(self) -> str:
        return self.name or Path(self.main).stem


def _mesh_files(scene: Scene) -> list[Path]:
    """The files a scene file's meshes read, resolved as the loader resolves
    them: each mesh file and the files it names (:func:`pyoa.render.mesh_files.companions`)."""
    data = json.loads(Path(scene.path).read_text())
    base = Path(scene.path).parent
    out = []
    for shape in data.get("shapes", []):
        if isinstance(shape, dict) and shape.get("type") == "mesh" and isinstance(shape.get("file"), str):
            path = (base / shape["file"]).resolve()
            out += [path, *companions(path)]
    return out


def source_of(scene: Scene) -> SceneSource:
    """The :class:`SceneSource` of a scene loaded on the client."""
    digest = scene_digest(scene)
    path = Path(scene.path).resolve()
    names = bundled()
    if scene.name in names and Path(names[scene.name]).resolve() == path:
        return SceneSource(digest=digest, name=scene.name)
    paths = [path, *_mesh_files(scene)]
    root = Path(os.path.commonpath([p.parent for p in paths]))
    files = tuple((str(p.relative_to(root)), p.read_bytes()) for p in dict.fromkeys(paths))
    return SceneSource(digest=digest, files=files, main=str(path.relative_to(root)))


#: Scenes loaded in this process, by digest (a worker's cache).
_LOADED: dict[str, Scene] = {}


def load_source(src: SceneSource) -> Scene:
    """Load the scene of ``src`` in this process (once per digest)."""
    scene = _LOADED.get(src.digest)
    if scene is not None:
        return scene
    if src.name is not None:
        scene = load(src.name)
    else:
        # a private directory per scene, the files at their relative paths
        root = Path(tempfile.gettempdir()) / f"pyoa-scenes-{os.getuid() if hasattr(os, 'getuid') else 0}" / \
            hashlib.sha256(src.digest.encode()).hexdigest()[:16]
        for rel, data in src.files:
            p = root / rel
            p.parent.mkdir(parents=True, exist_ok=True)
            if not p.is_file() or p.read_bytes() != data:
                tmp = p.with_name(p.name + f".{os.getpid()}.tmp")
                tmp.write_bytes(data)
                os.replace(tmp, p)
        scene = load(root / src.main)
    got = scene_digest(scene)
    if got != src.digest:
        raise ValueError(f"scene {src.label!r} on this worker is not the client's (digest {got[:12]} vs "
                           f"{src.digest[:12]}): install the same pyoa version on every machine")
    _LOADED[src.digest] = scene
    return scene
