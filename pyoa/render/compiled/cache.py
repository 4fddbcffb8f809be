"""Where numba caches the compiled package's functions: a folder named
after a digest of every source they compile from (:mod:`pyoa.render.compiled`
says why).
"""

from __future__ import annotations

import contextlib
import hashlib
import os
from pathlib import Path

_PYOA = Path(__file__).resolve().parent.parent.parent
#: Files (relative to the ``pyoa`` package) whose code or constants the
#: compiled functions contain: the compiled package, every module of
#: ``pyoa.render`` that it imports, every module of the BSDFs' package (each
#: BSDF's forms are compiled in, so a new BSDF module is a source without a
#: line here) and the numba hashes it calls (:mod:`pyoa._numba`)
#: (``tests/render/test_compiled.py`` checks the list against the imports).
SOURCES = tuple(f"render/{name}" for name in (
    "compiled/__init__.py", "compiled/bsdfs.py", "compiled/cache.py", "compiled/camera.py", "compiled/emitters.py",
    "compiled/forms.py", "compiled/geometry.py", "compiled/integrator.py", "compiled/shading.py", "camera.py",
    "embree.py", "emitters.py", "integrator.py")) + tuple(
    sorted(f"render/bsdfs/{p.name}" for p in (_PYOA / "render" / "bsdfs").glob("*.py"))) + (
    "_numba/__init__.py", "_numba/hashes.py")


def sources_digest(root: Path = _PYOA) -> str:
    """SHA-256 of the names and bytes of :data:`SOURCES` under ``root``."""
    h = hashlib.sha256()
    for rel in SOURCES:
        h.update(rel.encode() + b"\0")
        h.update((root / rel).read_bytes())
    return h.hexdigest()


def cache_dir() -> str:
    """numba's cache folder for this package's functions: ``pyoa-render-`` and
    the first 16 hex digits of :func:`sources_digest`, under
    ``$NUMBA_CACHE_DIR`` when it is set, else under ``__pycache__`` beside
    the package's sources when that is writable, else under numba's user-wide cache
    folder (the places numba itself would choose, in that order)."""
    from numba.core import config

    base = config.CACHE_DIR
    if not base:
        here = Path(__file__).resolve().parent
        pycache = here / "__pycache__"
        if os.access(pycache if pycache.is_dir() else here, os.W_OK):
            base = str(pycache)
        else:
            from numba.misc.appdirs import AppDirs

            base = AppDirs(appname="numba", appauthor=False).user_cache_dir
    return os.path.join(base, f"pyoa-render-{sources_digest()[:16]}")


@contextlib.contextmanager
def salted_cache():
    """numba's cache folder set to :func:`cache_dir` while the functions of this
    package are decorated (numba picks a function's folder then), and restored
    after, so that no other numba user in the process is affected."""
    from numba.core import config

    old = config.CACHE_DIR
    config.CACHE_DIR = cache_dir()
    try:
        yield
    finally:
        config.CACHE_DIR = old
