"""Which OpenCL device pyoa runs on, and why the others were passed over.

A device can be listed yet unable to build pyoa's program: pip's PoCL 3.0
compiles with LLVM 14, which does not know CPUs newer than itself (AMD Zen 5,
``lscpu`` family 26) and then fails every build with ``error: unknown target
CPU 'generic'``. So the default device is not the first one listed but the
first of :func:`pyoa._opencl.device.candidates` that *builds*; every other
outcome is remembered per device, in plain words, for the fallback warning
and for ``pyoa backends``. An explicit selector (``device=`` or
``PYOA_OPENCL_DEVICE``) still means exactly that device: it is never swapped
for another.
"""

from __future__ import annotations

import os
import re
import threading
from dataclasses import dataclass

from ..util.hostcpu import host_cpu
from . import program
from .device import (
    ENV_DEVICE,
    DeviceInfo,
    NoUsableDevice,
    candidates,
    list_devices,
    select_device,
)

#: What to do when a device's LLVM is older than the CPU: a PoCL built on a
#: newer LLVM (Debian's pocl-opencl-icd: PoCL 3.1 on LLVM 15, which works on
#: both CPUs of this machine kind, see docs/performance.md, lessons for PoCL).
FIX_NEWER_POCL = "on Debian/Ubuntu: apt-get install pocl-opencl-icd (a PoCL with a newer LLVM)"
FIX_OTHER_DEVICE = "choose another device with PYOA_OPENCL_DEVICE (list: pyoa backends)"


@dataclass(frozen=True)
class DeviceStatus:
    """Whether pyoa's program builds on one device.

    ``reason`` and ``fix`` are one line each (None when it works); ``log`` is
    the whole OpenCL error message, build log included, for ``pyoa backends
    --verbose``.
    """

    info: DeviceInfo
    works: bool
    reason: str | None = None
    fix: str | None = None
    log: str | None = None


def explain(info: DeviceInfo, exc: BaseException) -> tuple[str, str]:
    """``(reason, fix)`` for a device that failed, in plain words, one line each."""
    log = getattr(exc, "log", None) or str(exc)
    m = re.search(r"unknown target CPU '([^']*)'", log)
    if m:
        llvm = info.llvm_version()
        llvm = f"LLVM {llvm.split('.')[0]}" if llvm else "its LLVM"
        return (f"{info.platform_label()}'s {llvm} does not know this CPU ({host_cpu().describe()}: "
                f"it calls it '{m[1]}')", FIX_NEWER_POCL)
    first = program.first_error(log)[:160]
    if getattr(exc, "stage", None) == "build":
        return f"its compiler stops with {first}", FIX_OTHER_DEVICE
    return f"the device could not be opened ({first})", FIX_OTHER_DEVICE


_lock = threading.Lock()
#: Outcome of building pyoa's own program, per device (a build is slow: the
#: first failure can take seconds, so each device is tried once per process).
_status: dict[int, DeviceStatus] = {}


def _attempt(info: DeviceInfo, build):
    """``(built or None, DeviceStatus)`` of one build attempt."""
    try:
        return build(info), DeviceStatus(info, True)
    except Exception as exc:  # noqa: BLE001 - BuildError, or a driver's own error type
        reason, fix = explain(info, exc)
        return None, DeviceStatus(info, False, reason, fix, getattr(exc, "log", None) or str(exc))


def probe(info: DeviceInfo) -> DeviceStatus:
    """Whether pyoa's program builds on ``info``, tried once per device and process."""
    key = info.device.int_ptr
    with _lock:
        if key not in _status:
            _status[key] = _attempt(info, program.build)[1]
        return _status[key]


def probe_all() -> list[DeviceStatus]:
    """The status of every device, in :func:`~pyoa._opencl.device.list_devices`
    order (builds pyoa's program on each one not tried yet)."""
    return [probe(info) for info in list_devices()]


def first_working(devices, *, build=program.build):
    """The first of ``devices`` that builds, as ``(info, (context, queue,
    program))``, trying them in order.

    Raises
    ------
    NoUsableDevice
        If none builds; its ``statuses`` say why for each device, and its
        one-line ``cause`` names the first (the preferred) one.
    """
    statuses = []
    for info in devices:
        if build is program.build:
            status = probe(info)
            built = build(info) if status.works else None  # program.build caches the program
        else:
            built, status = _attempt(info, build)
        if built is not None:
            return info, built
        statuses.append(status)
    if not statuses:
        raise NoUsableDevice("no OpenCL device to try", FIX_OTHER_DEVICE)
    first = statuses[0]
    others = f" (and {len(statuses) - 1} other device{'s' * (len(statuses) > 2)} failed too)" if len(statuses) > 1 else ""
    raise NoUsableDevice(f"{first.info.short()} cannot build pyoa's kernels: {first.reason}{others}",
                         first.fix, statuses)


def open_device(selector: str | None = None, *, build=program.build):
    """The device pyoa uses and its built program: ``(info, (context, queue, program))``.

    With ``selector`` (or ``$PYOA_OPENCL_DEVICE``), exactly that device;
    without, the first of :func:`~pyoa._opencl.device.candidates` that builds.

    Raises
    ------
    ValueError
        If the selector matches no device.
    NoUsableDevice
        If the selected device, or every candidate, cannot build pyoa's
        program, or there is no OpenCL device at all.
    """
    if selector is None:
        selector = os.environ.get(ENV_DEVICE) or None
    devices = [select_device(selector)] if selector is not None else candidates()
    return first_working(devices, build=build)
