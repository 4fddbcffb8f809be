"""Embree 4 called from numba-compiled code: the scene, and closest-hit and
occlusion queries over whole wavefronts without returning to Python.

The ``embreex`` wheel ships Embree 4 (``embreex.libs/libembree4-*.so.4``) with
its whole C API, but binds only the single-ray queries behind one Python call
per wavefront (``EmbreeScene.run``). Here the *same* library (the one
``embreex`` loaded, found in the process's memory map) is opened with
:mod:`ctypes`; the scene is built with Embree's own calls, and the compiled
tracing loops call ``rtcIntersect{1,4,8,16}`` / ``rtcOccluded{1,4,8,16}``
through their addresses, which are passed in as integers so that numba's
on-disk cache stays valid across processes (addresses baked into compiled
code would not).

Ray layout (Embree 4's ``rtcore_ray.h``): a ray is the 12 four-byte fields
``org_x org_y org_z tnear dir_x dir_y dir_z time tfar mask id flags``, a hit
the fields ``Ng_x Ng_y Ng_z u v primID geomID instID[1] instPrimID[1]``; a
packet of width W stores each field as an array of W (structure of arrays),
aligned to 4 W bytes. A miss leaves ``geomID`` at ``RTC_INVALID_GEOMETRY_ID``
(0xFFFFFFFF); an occluded ray gets ``tfar = -inf``. ``tests/render/test_embree.py``
checks this layout against ``embreex.run``.

References
----------
.. [1] Intel, "Embree API reference", version 4 (rtcIntersect1/4/8/16,
   rtcOccluded1/4/8/16, RTCRayHit, RTCRayHitN).
"""

from __future__ import annotations

import ctypes
import functools
import glob
import os
import threading

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

#: Packet widths Embree offers, and the four-byte fields of a ray and of a hit.
WIDTHS = (1, 4, 8, 16)
RAY_FIELDS = 12
HIT_FIELDS = 9  # Ng_x Ng_y Ng_z u v primID geomID instID[1] instPrimID[1]
#: Field indices (in units of W four-byte words from the start of a packet).
ORG_X, ORG_Y, ORG_Z, TNEAR, DIR_X, DIR_Y, DIR_Z, TIME, TFAR, MASK, ID, FLAGS = range(12)
PRIM_ID, GEOM_ID = RAY_FIELDS + 5, RAY_FIELDS + 6
INVALID_ID = 0xFFFFFFFF

# Embree enums (rtcore_device.h, rtcore_geometry.h, rtcore_buffer.h).
_GEOMETRY_TYPE_TRIANGLE = 0
_BUFFER_TYPE_INDEX, _BUFFER_TYPE_VERTEX = 0, 1
_FORMAT_UINT3, _FORMAT_FLOAT3 = 0x5003, 0x9003
_SCENE_FLAG_ROBUST = 1 << 2
#: RTCError of an allocation that failed: a MemoryError, not a missing Embree
#: (which would fall back to the NumPy shading, whose embreex crashes then).
_ERROR_OUT_OF_MEMORY = 4


class EmbreeUnavailable(RuntimeError):
    """The Embree library that embreex ships cannot be used from compiled code."""


@functools.lru_cache(maxsize=1)
def library_path() -> str:
    """Path of the Embree 4 library that ``embreex`` loaded into this process.

    Raises
    ------
    EmbreeUnavailable
        If embreex is not installed or its Embree library is not found.
    """
    try:
        import embreex.rtcore_scene  # noqa: F401 - loads libembree4
    except ImportError as exc:
        raise EmbreeUnavailable(f"embreex is not installed ({exc}); pip install embreex") from exc
    try:
        with open("/proc/self/maps", encoding="utf-8", errors="replace") as fh:
            for line in fh:
                path = line.split(maxsplit=5)[-1].strip()
                if "libembree4" in os.path.basename(path) and os.path.exists(path):
                    return path
    except OSError:
        pass
    import embreex

    found = sorted(glob.glob(os.path.join(os.path.dirname(os.path.dirname(embreex.__file__)), "embreex.libs",
                                          "libembree4*")))
    if not found:
        raise EmbreeUnavailable("embreex's Embree 4 library (libembree4) was not found in memory or beside it")
    return found[0]


@functools.lru_cache(maxsize=1)
def library() -> ctypes.CDLL:
    """The Embree library (the one ``embreex`` loaded) with the signatures pyoa uses."""
    lib = ctypes.CDLL(library_path())
    vp, u32, sz = ctypes.c_void_p, ctypes.c_uint, ctypes.c_size_t
    for name, res, args in (
        ("rtcNewDevice", vp, [ctypes.c_char_p]),
        ("rtcReleaseDevice", None, [vp]),
        ("rtcGetDeviceError", ctypes.c_int, [vp]),
        ("rtcNewScene", vp, [vp]),
        ("rtcReleaseScene", None, [vp]),
        ("rtcCommitScene", None, [vp]),
        ("rtcSetSceneFlags", None, [vp, ctypes.c_int]),
        ("rtcNewGeometry", vp, [vp, ctypes.c_int]),
        ("rtcSetNewGeometryBuffer", vp, [vp, ctypes.c_int, u32, ctypes.c_int, sz, sz]),
        ("rtcCommitGeometry", None, [vp]),
        ("rtcAttachGeometry", u32, [vp, vp]),
        ("rtcReleaseGeometry", None, [vp]),
    ):
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = res, args
    return lib


def query_addresses(width: int) -> tuple[int, int]:
    """Addresses of ``rtcIntersect<W>`` and ``rtcOccluded<W>`` for a packet width."""
    if width not in WIDTHS:
        raise ValueError(f"Embree packet width must be one of {WIDTHS}, got {width!r}")
    lib = library()
    return (ctypes.cast(getattr(lib, f"rtcIntersect{width}"), ctypes.c_void_p).value,
            ctypes.cast(getattr(lib, f"rtcOccluded{width}"), ctypes.c_void_p).value)


_device_lock = threading.Lock()
_device = None


def device() -> int:
    """The process's Embree device (an ``RTCDevice`` handle), made on first use
    with ``threads=1`` and kept until the process ends.

    One device serves every :class:`Scene`, because a device per scene made
    a render after the first one cost a core: releasing a device while
    another lives makes Embree reconfigure TBB's ``global_control``, after
    which one TBB worker thread spun in ``sched_yield`` for as long as the
    next render ran (measured on Intel Xeon 6/207: a one-thread render used
    1.9 cores of CPU time, a two-thread one ran about 1.2x slower;
    ``tests/render/test_embree.py`` checks that a render leaves no core
    busy)."""
    global _device
    with _device_lock:  # render threads may build their first scenes at once: one device, never two
        if _device is None:
            lib = library()
            dev = lib.rtcNewDevice(b"threads=1")
            if not dev:
                raise EmbreeUnavailable(f"rtcNewDevice failed (Embree error {lib.rtcGetDeviceError(None)})")
            _device = dev
        return _device


class Scene:
    """A triangle scene built with Embree's own calls (one geometry, static).

    Parameters
    ----------
    triangles : array_like
        ``(T, 3, 3)`` world-space vertices; they are converted to float32
        exactly as ``embreex`` does.
    robust : bool
        Embree's robust mode (``RTC_SCENE_FLAG_ROBUST``: a conservative
        traversal and watertight triangle test), as ``embreex`` builds its
        scenes: the default (a scene's ``integrator.robust_tracing``).
        Without it tracing is 1.4-1.6x faster (as Mitsuba 3 traces by
        default), but rays through a shared edge can pass between its two
        triangles: 1 to 2.5 % of the rays aimed exactly at the seams of the
        bundled scenes leak, against none in robust mode
        (``tests/render/test_embree.py``; docs/rendering.md, "Tracing").

    The BVH is built on one thread (the device's ``threads=1``), so the
    same triangles give the same BVH, and every ray the same hit, in every
    process (a multi-threaded build may split differently from run to run,
    and without robust mode a ray through a shared edge may then hit the
    other triangle). Every scene lives on the one device of the process
    (:func:`device`). ``handle`` is the ``RTCScene`` as an integer, for the
    compiled queries. The scene keeps its buffers alive until :meth:`close`
    (or garbage collection).
    """

    def __init__(self, triangles, *, robust: bool = True):
        lib = library()
        tris = np.ascontiguousarray(triangles, dtype=np.float32).reshape(-1, 3, 3)
        if len(tris) == 0:
            raise ValueError("an Embree scene needs at least one triangle")
        self._lib = lib
        dev = device()
        try:
            self._scene = lib.rtcNewScene(dev)
            lib.rtcSetSceneFlags(self._scene, _SCENE_FLAG_ROBUST if robust else 0)
            geom = lib.rtcNewGeometry(dev, _GEOMETRY_TYPE_TRIANGLE)
            vb = lib.rtcSetNewGeometryBuffer(geom, _BUFFER_TYPE_VERTEX, 0, _FORMAT_FLOAT3, 12, 3 * len(tris))
            ib = lib.rtcSetNewGeometryBuffer(geom, _BUFFER_TYPE_INDEX, 0, _FORMAT_UINT3, 12, len(tris))
            if not vb or not ib:
                err = lib.rtcGetDeviceError(dev)
                kind = MemoryError if err == _ERROR_OUT_OF_MEMORY else EmbreeUnavailable
                raise kind(f"Embree could not allocate the buffers of {len(tris)} triangles (error {err})")
            # Embree owns these buffers (and pads the vertex buffer as it needs).
            ctypes.memmove(vb, tris.ctypes.data, tris.nbytes)
            idx = np.arange(3 * len(tris), dtype=np.uint32)
            ctypes.memmove(ib, idx.ctypes.data, idx.nbytes)
            lib.rtcCommitGeometry(geom)
            lib.rtcAttachGeometry(self._scene, geom)
            lib.rtcReleaseGeometry(geom)
            lib.rtcCommitScene(self._scene)
            err = lib.rtcGetDeviceError(dev)
            if err:
                kind = MemoryError if err == _ERROR_OUT_OF_MEMORY else EmbreeUnavailable
                raise kind(f"Embree could not build the scene of {len(tris)} triangles (error {err})")
        except BaseException:
            self.close()
            raise
        self.handle = int(self._scene)
        self.triangles = len(tris)
        self.robust = bool(robust)

    def close(self) -> None:
        """Release the scene (idempotent); the process's device stays."""
        if getattr(self, "_scene", None):
            self._lib.rtcReleaseScene(self._scene)
            self._scene = None

    def __del__(self):
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass


# ----------------------------------------------------------------------------- compiled queries


@intrinsic
def _ccall3(typingctx, fn, a, b, c):
    """``((void (*)(void *, void *, void *)) fn)(a, b, c)`` with every argument a uint64 address."""
    sig = types.void(types.uint64, types.uint64, types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        ptr = ir.IntType(8).as_pointer()
        fnty = ir.FunctionType(ir.VoidType(), [ptr, ptr, ptr])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        builder.call(f, [builder.inttoptr(x, ptr) for x in args[1:]])
        return context.get_dummy_value()

    return sig, codegen


@intrinsic
def _ccall4(typingctx, fn, a, b, c, d):
    """``((void (*)(void *, void *, void *, void *)) fn)(a, b, c, d)``, uint64 addresses."""
    sig = types.void(types.uint64, types.uint64, types.uint64, types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        ptr = ir.IntType(8).as_pointer()
        fnty = ir.FunctionType(ir.VoidType(), [ptr, ptr, ptr, ptr])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        builder.call(f, [builder.inttoptr(x, ptr) for x in args[1:]])
        return context.get_dummy_value()

    return sig, codegen


@njit(nogil=True, cache=True)
def _packet_buffer(width):
    """A zeroed float32 packet of ``width`` rays with hits, aligned to 64
    bytes, and its uint32 view (Embree requires 4 W-byte alignment)."""
    words = (RAY_FIELDS + HIT_FIELDS) * width
    raw = np.zeros(words + 16, np.float32)
    skip = ((64 - (raw.ctypes.data & 63)) & 63) // 4
    buf = raw[skip:skip + words]
    return buf, buf.view(np.uint32)


@njit(nogil=True, cache=True, inline="always")
def _load_ray(buf, bits, width, k, ox, oy, oz, dx, dy, dz, tfar):
    """The ray ``o + s d``, ``0 <= s <= tfar``, into lane ``k`` of the packet
    (float32, as ``embreex``), its hit reset."""
    buf[ORG_X * width + k] = ox
    buf[ORG_Y * width + k] = oy
    buf[ORG_Z * width + k] = oz
    buf[TNEAR * width + k] = 0.0
    buf[DIR_X * width + k] = dx
    buf[DIR_Y * width + k] = dy
    buf[DIR_Z * width + k] = dz
    buf[TIME * width + k] = 0.0
    buf[TFAR * width + k] = tfar
    bits[MASK * width + k] = 0xFFFFFFFF
    bits[ID * width + k] = 0
    bits[FLAGS * width + k] = 0
    bits[GEOM_ID * width + k] = INVALID_ID
    bits[PRIM_ID * width + k] = INVALID_ID


@njit(nogil=True, cache=True, inline="always")
def _query(scene, fn, width, buf, valid):
    """Call the query ``fn`` (``rtcIntersect<width>`` or ``rtcOccluded<width>``)
    on the packet ``buf``, whose lanes ``valid`` marks (-1: a ray, 0: none)."""
    if width == 1:
        _ccall3(fn, np.uint64(scene), np.uint64(buf.ctypes.data), np.uint64(0))
    else:
        _ccall4(fn, np.uint64(valid.ctypes.data), np.uint64(scene), np.uint64(buf.ctypes.data), np.uint64(0))


@njit(nogil=True, cache=True)
def _trace_packet(scene, fn, width, o, d, dist, start, buf, bits, valid):
    """Load rays ``start ..`` (up to ``width``; ``tfar`` = ``dist`` or inf
    when ``dist`` is empty) into the packet, mark the rest invalid, and call
    the query ``fn``. Returns how many lanes hold rays."""
    m = min(width, o.shape[0] - start)
    for k in range(width):
        if k < m:
            i = start + k
            tfar = np.float32(dist[i]) if dist.shape[0] > 0 else np.float32(np.inf)
            _load_ray(buf, bits, width, k, o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2], tfar)
            valid[k] = -1
        else:
            valid[k] = 0
    _query(scene, fn, width, buf, valid)
    return m


@njit(nogil=True, cache=True)
def intersect(scene, fn, width, o, d, prim, t):
    """Closest hits of the rays ``o + s d`` (``(n, 3)`` float64, converted to
    float32 like ``embreex``): ``prim[i]`` the triangle (-1 for a miss) and
    ``t[i]`` the distance (inf for a miss). ``fn`` is the address of
    ``rtcIntersect<width>``. Every ray's answer depends on that ray alone."""
    buf, bits = _packet_buffer(width)
    valid = np.empty(width, np.int32)
    no_dist = np.empty(0)
    for start in range(0, o.shape[0], width):
        m = _trace_packet(scene, fn, width, o, d, no_dist, start, buf, bits, valid)
        for k in range(m):
            if bits[GEOM_ID * width + k] == INVALID_ID:
                prim[start + k] = -1
                t[start + k] = np.inf
            else:
                prim[start + k] = np.int64(bits[PRIM_ID * width + k])
                t[start + k] = np.float64(buf[TFAR * width + k])


@njit(nogil=True, cache=True)
def occluded(scene, fn, width, o, d, dist, free):
    """``free[i]`` is True where nothing blocks ``o + s d`` for ``0 <= s <=
    dist[i]`` (float32 as ``embreex``); ``fn`` is ``rtcOccluded<width>``.
    An occluded ray comes back with ``tfar = -inf``."""
    buf, bits = _packet_buffer(width)  # a ray packet is a prefix of a ray-hit packet
    valid = np.empty(width, np.int32)
    for start in range(0, o.shape[0], width):
        m = _trace_packet(scene, fn, width, o, d, dist, start, buf, bits, valid)
        for k in range(m):
            free[start + k] = buf[TFAR * width + k] >= 0.0
