"""The files a mesh file brings with it: what trimesh reads besides the mesh.

The scene loader (:mod:`pyoa.render.scene`) checks each of them before trimesh
opens it (a FIFO would block trimesh for ever), and a scene sent to a
cluster's workers (:mod:`pyoa.render.scene_source`) carries them, since a
worker that received only a glTF file could not load its separate buffers.
"""

from __future__ import annotations

import json
import os
from pathlib import Path


def companions(mesh: Path) -> list[Path]:
    """The files that trimesh reads along with the mesh file ``mesh``: a
    glTF's (``.gltf``, ``.glb``) buffers and images given by ``uri`` (not
    those embedded as base64), an OBJ's material library (its first
    ``mtllib``, as trimesh reads it). Each is found as trimesh's resolver
    finds it (:func:`_resolve`); one that is not there is left out, as
    trimesh leaves it out (a glTF missing a buffer failed to load on the
    client already). Without them a worker that received only the mesh
    file could not load a glTF whose buffers are separate files."""
    suffix = mesh.suffix.lower()
    if suffix in (".gltf", ".glb"):
        try:
            tree = json.loads(_gltf_json(mesh, suffix == ".glb"))
        except ValueError:  # not JSON: trimesh refused it on the client already
            return []
        lists = [tree.get(key) for key in ("buffers", "images")] if isinstance(tree, dict) else []
        items = [item for found in lists if isinstance(found, list) for item in found if isinstance(item, dict)]
        names = [item["uri"] for item in items if isinstance(item.get("uri"), str) and "base64," not in item["uri"]]
    elif suffix == ".obj":
        text = mesh.read_bytes().decode("utf-8", errors="replace")
        at = text.find("mtllib")  # as trimesh.exchange.obj.load_obj finds it
        end = text.find("\n", at)
        names = [text[at + 6:end if end >= 0 else len(text)].strip()] if at >= 0 else []
    else:
        return []
    found = (_resolve(mesh.parent, name) for name in names)
    return [p for p in found if p is not None]


def _gltf_json(path: Path, binary: bool) -> bytes:
    """The JSON of a glTF file: the whole ``.gltf``, or the first chunk of a
    ``.glb`` (a 12-byte header, then the chunk's length and type ``JSON``)."""
    data = path.read_bytes()
    if not binary:
        return data
    if len(data) < 20 or data[:4] != b"glTF" or data[16:20] != b"JSON":
        raise ValueError("not a glTF binary")
    return data[20:20 + int.from_bytes(data[12:16], "little")]


def _resolve(parent: Path, name: str) -> Path | None:
    """The file ``name`` names for trimesh's ``FilePathResolver`` rooted at
    ``parent``: the first of the name, the name without leading slashes
    and its last component that exists inside ``parent`` (trimesh opens it
    whatever it is; :func:`pyoa.render.scene.load` refuses one that is not a
    regular file); else None."""
    root = parent.resolve()
    for candidate in (name.strip(), name.strip().lstrip("/"), os.path.split(name)[-1]):
        path = (root / candidate).resolve()
        if candidate and path.is_relative_to(root) and path.exists():  # trimesh opens what exists (a FIFO too)
            return path
    return None
