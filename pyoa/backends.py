"""Which backend computes a request: OpenCL when usable, NumPy otherwise.

Order of choice for :func:`pyoa.sampler`:

1. the ``backend=`` argument (``"opencl"`` or ``"numpy"``);
2. else the ``PYOA_BACKEND`` environment variable (same names);
3. else OpenCL on the first device that builds the kernels (PoCL's CPU
   device first; a device whose compiler fails is skipped and the next one
   tried; ``device=`` or ``PYOA_OPENCL_DEVICE`` picks exactly one, see
   :mod:`pyoa._opencl.device` and :mod:`pyoa._opencl.choice`);
4. else NumPy, with one :class:`PyoaFallbackWarning` of at most two lines:
   which device failed, why in plain words, and what fixes it.

An explicit ``"opencl"`` that cannot be used raises instead of falling back.
All backends give the same float32 bits for the same request.
"""

from __future__ import annotations

import os
import sys
import threading
import warnings

from ._numpy.backend import NumpyBackend
from .catalogue.entries import check_choice

BACKENDS = ("opencl", "numpy")
ENV_BACKEND = "PYOA_BACKEND"


class PyoaFallbackWarning(RuntimeWarning):
    """OpenCL was not usable and pyoa fell back to NumPy."""


class BackendUnavailable(RuntimeError):
    """An explicitly requested backend cannot be used here.

    ``cause`` and ``fix`` are one line each (``fix`` may be None).
    """

    def __init__(self, cause: str, fix: str | None = None):
        super().__init__(f"{cause}. Fix: {fix}" if fix else cause)
        self.cause, self.fix = cause, fix


_lock = threading.Lock()
_opencl: dict[str | None, object] = {}
_warned = False


def _opencl_backend(device: str | None):
    """The (cached) OpenCL backend for a device selector; raises BackendUnavailable."""
    from ._opencl.backend import OpenCLBackend
    from ._opencl.device import ENV_DEVICE

    if device is None:  # the environment's selector, read now: the cache follows it
        device = os.environ.get(ENV_DEVICE) or None
    with _lock:
        if device not in _opencl:
            try:
                _opencl[device] = OpenCLBackend(device)
            except ValueError:
                raise
            except Exception as exc:  # NoUsableDevice, ImportError, a driver's own errors
                cause = getattr(exc, "cause", None) or (str(exc).strip().splitlines() or [type(exc).__name__])[0]
                _opencl[device] = BackendUnavailable(cause, getattr(exc, "fix", None))
        got = _opencl[device]
    if isinstance(got, BackendUnavailable):
        raise got
    return got


def choose(backend: str | None = None, device: str | None = None):
    """Return the backend object for ``backend`` (see the module docstring).

    Raises
    ------
    TypeError
        A ``backend`` or ``device`` that is not a str or None.
    ValueError
        An unknown backend name, an empty device selector, or one that
        matches no OpenCL device.
    BackendUnavailable
        ``"opencl"`` named explicitly but not usable.
    """
    global _warned
    _check_selector(device)
    backend = backend_name(backend)
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
            warnings.warn(fallback_message(exc), PyoaFallbackWarning, stacklevel=_first_frame_outside_pyoa())
        return NumpyBackend()


def backend_name(backend: str | None = None) -> str | None:
    """The backend that ``backend`` names: the argument, else
    ``$PYOA_BACKEND``, else None (automatic), checked and in lower case.

    Raises
    ------
    TypeError
        A ``backend`` that is not a str or None.
    ValueError
        A name (of the argument or of the environment variable, which the
        message names) that is not one of :data:`BACKENDS`.
    """
    return check_choice(backend, ENV_BACKEND, BACKENDS, None)


def _check_selector(device) -> None:
    """Refuse a device selector that is not a str (or None) whichever backend
    is chosen: ``device=0`` is not an index, it would only fail later or
    nowhere (see :mod:`pyoa._opencl.device` for the forms)."""
    if device is not None and not isinstance(device, str):
        raise TypeError(f"device must be an OpenCL device selector string ('P:D' such as '0:1', 'P' such as "
                        f"'0', 'gpu', 'cpu' or part of a device name) or None, got {type(device).__name__} "
                        f"{device!r}")
    if isinstance(device, str) and not device.strip():
        raise ValueError("device must not be empty; valid: 'P:D', 'P', 'gpu', 'cpu', 'accelerator' or part "
                         "of a device name (list: pyoa backends), or None for the default")


def _first_frame_outside_pyoa() -> int:
    """The ``stacklevel`` (1 = the caller of this function) of the first frame
    outside the pyoa package: the warning then names the user's line, whichever
    of pyoa's entry points (``pyoa.sampler``, ``Sampler``, the renderer) led here."""
    package = os.path.dirname(os.path.abspath(__file__))
    frame, level = sys._getframe(1), 1
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(package + os.sep):
        frame, level = frame.f_back, level + 1
    return level


def fallback_message(exc: BackendUnavailable) -> str:
    """The two lines of the fallback warning: what failed and why, then the fix.

    The whole build log is never in it: ``pyoa backends --verbose`` shows it.
    """
    fix = f"Fix: {exc.fix}; or" if exc.fix else "Or"
    return (f"pyoa: OpenCL is not usable: {exc.cause}; using NumPy instead (same bits, several times slower).\n"
            f"{fix} set {ENV_BACKEND}=numpy to silence this. Details: pyoa backends --verbose")


def backends() -> list[dict]:
    """Report what is usable here, trying pyoa's program on every OpenCL device.

    Returns
    -------
    list of dict
        One dict per backend with keys ``name``, ``usable`` (bool), ``device``
        (what it runs on, or None), ``default`` (bool: what
        ``backend=None`` picks now) and ``reason`` (why not usable, or None).
        The OpenCL entry also has ``fix`` (what to do when not usable, or
        None) and ``devices``: one dict per OpenCL device, in selector
        order, with ``selector`` (``"P:D"``), ``name``, ``kind``, ``description``, ``compiler``
        (platform, LLVM version and target CPU where known), ``works``
        (bool), ``used`` (bool: the device OpenCL runs on), ``reason`` and
        ``fix`` (one line each, None when it works) and ``log`` (the whole
        build log of a failure, else None).

    Raises
    ------
    ValueError
        ``$PYOA_BACKEND`` names no backend (as :func:`choose` raises).
    """
    from ._opencl.choice import probe_all

    env = backend_name(None)  # a bad $PYOA_BACKEND is refused here as by every command, not reported as the default
    report = []
    try:
        ocl = _opencl_backend(None)
        entry = {"name": "opencl", "usable": True, "device": ocl.describe(), "reason": None, "fix": None}
        used = ocl.info.device.int_ptr
    except (BackendUnavailable, ValueError) as exc:
        entry = {"name": "opencl", "usable": False, "device": None, "fix": getattr(exc, "fix", None),
                 "reason": getattr(exc, "cause", None) or str(exc)}
        used = None
    try:
        statuses = probe_all()
    except RuntimeError:  # no platform, or pyopencl missing: the reason above says so
        statuses = []
    entry["devices"] = [
        {"selector": st.info.selector, "name": st.info.device.name.strip(), "kind": st.info.kind,
         "description": st.info.describe(),
         "compiler": st.info.compiler(),
         "works": st.works, "used": st.info.device.int_ptr == used, "reason": st.reason, "fix": st.fix,
         "log": st.log}
        for st in statuses
    ]
    report.append(entry)
    report.append({"name": "numpy", "usable": True, "device": NumpyBackend().describe(), "reason": None})
    default = env or ("opencl" if report[0]["usable"] else "numpy")
    for e in report:
        e["default"] = e["name"] == default
    return report
