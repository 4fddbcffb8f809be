"""What made an image: the settings, software and machine written into every EXR pyoa renders.

A figure in a paper should lead back to the command that made it. Every EXR
that ``pyoa render``, ``pyoa reference`` (its image and its variance) and a
progressive render write carries, in its header, string and integer
attributes named ``pyoa:KEY`` (OpenImageIO's ``ImageSpec.attribute``; EXR
keeps any named attribute, as pbrt-v4 keeps its render metadata there too):

========================  =====================================================
``pyoa:kind``             ``render``, ``progressive render``, ``reference``,
                          ``reference variance``
``pyoa:scene``            the scene's name, ``pyoa:scene_file`` its file and
                          ``pyoa:scene_sha256`` the digest of its file and
                          world-space triangles (what a resumed job checks)
``pyoa:width/height``     the image size
``pyoa:sampler``          its catalogue name; ``pyoa:spp``, ``pyoa:seed``,
                          ``pyoa:base`` (faure), ``pyoa:samples`` (a
                          progressive render: samples so far)
``pyoa:passes``           a reference: passes and ``pyoa:pass_spp``; its
                          variance: ``pyoa:reference_pixels_sha256``, the
                          digest of the reference's pixels
                          (:func:`pyoa.render.image.pixel_digest`) that ties
                          it to them
``pyoa:max_depth``        path length, ``pyoa:filter``, ``pyoa:shading``,
                          ``pyoa:layout`` (the sampler dimension of each
                          integrand dimension, as ``pyoa render`` prints it)
``pyoa:renderer``         :data:`~pyoa.render.integrator.RENDERER_VERSION`
``pyoa:version``          pyoa's version; ``pyoa:git`` the revision of a
                          source checkout (``+dirty`` with local changes)
``pyoa:cpu``              the host CPU (:func:`pyoa.util.hostcpu.host_cpu`)
``pyoa:command``          the command line, when written by the CLI
========================  =====================================================

:func:`pyoa.render.image.read_attributes` gives them back as a dict (``pyoa info FILE`` prints them).
"""

from __future__ import annotations

import functools
import math
import shlex
import subprocess
import unicodedata
from pathlib import Path

@functools.lru_cache(maxsize=1)
def git_revision() -> str:
    """The git revision of pyoa's source checkout (``+dirty`` when tracked files differ from it), or
    ``""`` for an installed copy that is not a checkout, or when git is missing or slow."""
    root = Path(__file__).resolve().parents[2]
    if not (root / ".git").exists():
        return ""
    try:
        rev = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True, text=True,
                             timeout=5, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=5, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""
    return rev + ("+dirty" if dirty else "")


def command_line(argv) -> str:
    """``pyoa ARGS`` as a shell would take it back (quoted where needed)."""
    return shlex.join(["pyoa", *map(str, argv)])


def describe(scene, p, *, kind: str, command: str | None = None, shading: str | None = None, **extra) -> dict:
    """The attributes of an image of ``scene`` rendered as planned by ``p``
    (:func:`pyoa.render.render.plan`, whose settings give the seed, filter
    and shading; ``shading`` names the one that rendered where it differs,
    after a fallback to the NumPy reference); ``extra`` adds kind-specific
    ones (``samples``, ``passes``, ``pass_spp``) or replaces one (a
    reference's ``spp``). Values are str or int."""
    from .. import __version__
    from ..util.hostcpu import host_cpu

    ident = p.identity(scene)  # the render's identity (pyoa.render.render.Plan.identity), as header attributes
    meta = {"kind": kind, "scene": scene.name, "scene_file": str(scene.path), "scene_sha256": ident["scene"],
            "width": ident["width"], "height": ident["height"], "sampler": ident["sampler"], "spp": ident["spp"],
            "seed": int(ident["seed"])}
    if ident["base"] is not None:
        meta["base"] = int(ident["base"])
    meta.update({k: v for k, v in extra.items() if v is not None})
    meta.update({"max_depth": ident["max_depth"], "filter": ident["filter"], "shading": shading or ident["shading"],
                 "layout": p.layout.describe(), "renderer": ident["renderer"], "version": __version__,
                 "git": git_revision(), "cpu": host_cpu().describe()})
    if command:
        meta["command"] = command
    return {k: v for k, v in meta.items() if v != ""}


def printable(value) -> str:
    """``value`` as text safe to print on a terminal: control and format characters (newline, CR, ESC,
    bidirectional overrides, ...) written as their Python escapes (``\\n``, ``\\r``, ``\\x1b``,
    ``\\u202e``), so that a header string cannot forge a line of ``pyoa info`` or move the cursor.

    >>> printable("cornell\\nkind  render\\x1b[2J")
    'cornell\\\\nkind  render\\\\x1b[2J'
    """
    return "".join(ch.encode("unicode_escape").decode("ascii") if unicodedata.category(ch)[0] in "CZ" and ch != " "
                    else ch for ch in str(value))


def json_value(value):
    """``value`` (a header attribute) as strict JSON takes it: a float that is not finite (a foreign
    image's ``pyoa:spp = NaN``) as its string, ``"nan"``, ``"inf"`` or ``"-inf"``, since JSON has no
    such numbers (in an array attribute too); other values as they are."""
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, (tuple, list)):
        return [json_value(v) for v in value]
    return value
