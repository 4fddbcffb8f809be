"""Which backend computes a request: OpenCL when usable, NumPy otherwise.

Order of choice for :func:`pyoa.sampler`:

1. the ``backend=`` argument (``"opencl"`` or ``"numpy"``);
2. else the ``PYOA_BACKEND`` environment variable (same names);
3. else OpenCL if a device builds the kernels (PoCL's CPU device by default;
   ``device=`` or ``PYOA_OPENCL_DEVICE`` picks another, see
   :mod:`pyoa._opencl.device`);
4. else NumPy, with one :class:`PyoaFallbackWarning` saying why.

An explicit ``"opencl"`` that cannot be used raises instead of falling back.
All backends give the same float32 bits for the same request.
"""

from __future__ import annotations

import os
import threading
import warnings

from ._numpy.backend import NumpyBackend

BACKENDS = ("opencl", "numpy")
ENV_BACKEND = "PYOA_BACKEND"


class PyoaFallbackWarning(RuntimeWarning):
    """OpenCL was not usable and pyoa fell back to NumPy."""


class BackendUnavailable(RuntimeError):
    """An explicitly requested backend cannot be used here."""


_lock = threading.Lock()
_opencl: dict[str | None, object] = {}
_warned = False


def _opencl_backend(device: str | None):
    """The (cached) OpenCL backend for a device selector; raises BackendUnavailable."""
    from ._opencl.backend import OpenCLBackend

    with _lock:
        if device not in _opencl:
            try:
                _opencl[device] = OpenCLBackend(device)
            except ValueError:
                raise
            except Exception as exc:  # ImportError, RuntimeError, pyopencl errors
                _opencl[device] = BackendUnavailable(str(exc))
        got = _opencl[device]
    if isinstance(got, BackendUnavailable):
        raise got
    return got


def choose(backend: str | None = None, device: str | None = None):
    """Return the backend object for ``backend`` (see the module docstring)."""
    global _warned
    if backend is None:
        backend = os.environ.get(ENV_BACKEND) or None
        origin = f"${ENV_BACKEND}"
    else:
        origin = "backend"
    if backend is not None:
        if not isinstance(backend, str):
            raise TypeError(f"backend must be a str or None, got {type(backend).__name__}")
        backend = backend.strip().lower()
        if backend not in BACKENDS:
            raise ValueError(f"unknown {origin} {backend!r}; valid: {', '.join(BACKENDS)} (or None for automatic)")
    if backend == "numpy":
        return NumpyBackend()
    if backend == "opencl":
        return _opencl_backend(device)
    try:
        return _opencl_backend(device)
    except BackendUnavailable as exc:
        with _lock:
            first, _warned = not _warned, True
        if first:
            warnings.warn(
                f"pyoa: OpenCL is not usable ({exc}); using the NumPy backend "
                f"(slower, same bits). Set {ENV_BACKEND}=numpy to silence this.",
                PyoaFallbackWarning,
                stacklevel=3,
            )
        return NumpyBackend()


def backends() -> list[dict]:
    """Report what is usable here.

    Returns
    -------
    list of dict
        One dict per backend with keys ``name``, ``usable`` (bool), ``device``
        (what it runs on, or None), ``default`` (bool: what
        ``backend=None`` picks now) and ``reason`` (why not usable, or None);
        the OpenCL entry also has ``devices``: every OpenCL device with its
        selector ``"P:D"``.
    """
    from ._opencl.device import list_devices

    report = []
    try:
        ocl = _opencl_backend(None)
        entry = {"name": "opencl", "usable": True, "device": ocl.describe(), "reason": None}
    except (BackendUnavailable, ValueError) as exc:
        entry = {"name": "opencl", "usable": False, "device": None, "reason": str(exc)}
    try:
        entry["devices"] = [f"{d.platform_index}:{d.device_index} {d.describe()}" for d in list_devices()]
    except RuntimeError:
        entry["devices"] = []
    report.append(entry)
    report.append({"name": "numpy", "usable": True, "device": NumpyBackend().describe(), "reason": None})
    env = (os.environ.get(ENV_BACKEND) or "").strip().lower()
    default = env if env in BACKENDS else ("opencl" if report[0]["usable"] else "numpy")
    for e in report:
        e["default"] = e["name"] == default
    return report
