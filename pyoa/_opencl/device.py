"""Listing OpenCL devices and resolving selectors, deterministically.

Default candidates (:func:`candidates`): PoCL's CPU device (pyoa's reference
platform) first. When a host has PoCL twice (pip's ``pocl-binary-distribution``
and Debian's ``pocl-opencl-icd`` both show a platform named "Portable Computing
Language"), the one with the highest version string comes first, so the order
never depends on ICD load order; then other CPU devices, then the rest. The
first candidate that builds pyoa's program is used; the others are tried in
turn when it does not (:mod:`pyoa._opencl.choice`), since a PoCL whose LLVM is
older than the CPU cannot build anything (pip's PoCL 3.0 with LLVM 14 on AMD
Zen 5).

A *selector* (the ``device=`` argument of :func:`pyoa.sampler` or the
``PYOA_OPENCL_DEVICE`` environment variable) picks another device:

- ``"P:D"``: device D of platform P in :func:`list_devices` order;
- ``"P"`` (a bare integer): device 0 of platform P, as in PyOpenCL's
  ``PYOPENCL_CTX`` (never a substring of a name: ``"0"`` would otherwise
  pick whichever device happens to have a 0 in its description);
- ``"gpu"``, ``"cpu"`` or ``"accelerator"``: the first device of that type;
- any other text: the first device whose ``"platform version / device"``
  description contains it, case-insensitively (e.g. ``"nvidia"``, ``"pocl"``).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass

ENV_DEVICE = "PYOA_OPENCL_DEVICE"
POCL_NAME = "Portable Computing Language"


class NoUsableDevice(RuntimeError):
    """No OpenCL device can run pyoa here.

    ``cause`` says why in plain words and ``fix`` what to do, each one line;
    ``statuses`` holds a :class:`pyoa._opencl.choice.DeviceStatus` per device
    tried (empty when there was none to try).
    """

    def __init__(self, cause: str, fix: str, statuses=()):
        super().__init__(f"{cause}. Fix: {fix}")
        self.cause, self.fix, self.statuses = cause, fix, tuple(statuses)


@dataclass(frozen=True)
class DeviceInfo:
    """One OpenCL device and where it sits in :func:`list_devices` order."""

    platform_index: int
    device_index: int
    platform: object  # pyopencl.Platform
    device: object  # pyopencl.Device

    @property
    def kind(self) -> str:
        import pyopencl as cl

        t = self.device.type
        for name in ("GPU", "CPU", "ACCELERATOR"):
            if t & getattr(cl.device_type, name):
                return name.lower()
        return "other"

    @property
    def selector(self) -> str:
        """``"P:D"``: the selector that names exactly this device."""
        return f"{self.platform_index}:{self.device_index}"

    @property
    def is_pocl(self) -> bool:
        return POCL_NAME in self.platform.name

    def platform_label(self) -> str:
        """``"PoCL 3.0-rc2"`` for PoCL, else the platform's name."""
        m = re.search(r"PoCL\s+(\S+)", self.platform.version)
        return f"PoCL {m[1]}" if m else self.platform.name.strip()

    def target_cpu(self) -> str | None:
        """The CPU PoCL compiles for (LLVM's name, e.g. ``"znver3"``), else None.

        PoCL's device version ends with its "HSTR", the host triple and the
        LLVM CPU name: ``pthread-x86_64-unknown-linux-gnu-znver3``.
        """
        m = re.search(r"HSTR:\s*\S*?-gnu-(\S+)", self.device.version or "")
        return m[1] if m else None

    def compiler(self) -> str:
        """Platform, LLVM version and target CPU where the platform names them,
        e.g. ``"PoCL 3.0-rc2, LLVM 14.0.6, target znver3"``."""
        parts = [self.platform_label()]
        if self.llvm_version():
            parts.append(f"LLVM {self.llvm_version()}")
        if self.target_cpu():
            parts.append(f"target {self.target_cpu()}")
        return ", ".join(parts)

    def llvm_version(self) -> str | None:
        """The LLVM version in the platform version string (PoCL names it), else None."""
        m = re.search(r"LLVM\s+(\d+(?:\.\d+)*)", self.platform.version)
        return m[1] if m else None

    def describe(self) -> str:
        return (
            f"{self.device.name.strip()} ({self.kind}) on "
            f"{self.platform.name.strip()} [{' '.join(self.platform.version.split()[:4])}]"
        )

    def short(self) -> str:
        """Device name and compiler, e.g. ``"pthread-AMD EPYC (PoCL 3.0-rc2, LLVM 14.0.6)"``."""
        llvm = self.llvm_version()
        return f"{self.device.name.strip()} ({self.platform_label()}{f', LLVM {llvm}' if llvm else ''})"


def _natural(text: str):
    return [int(tok) if tok.isdigit() else tok for tok in re.split(r"(\d+)", text)]


def list_devices() -> list[DeviceInfo]:
    """Every OpenCL device, platforms ordered PoCL first (newest version first),
    then the others by (name, version); devices CPU first within a platform.

    Raises
    ------
    NoUsableDevice
        If pyopencl is not installed or no OpenCL platform or device is found.
    """
    try:
        import pyopencl as cl
    except ImportError as exc:  # pragma: no cover - depends on the install
        raise NoUsableDevice(f"pyopencl is not installed ({exc})", "pip install 'pyoa[pocl]'") from exc
    try:
        platforms = cl.get_platforms()
    except cl.Error as exc:
        raise NoUsableDevice(f"no OpenCL platform found ({str(exc).strip().splitlines()[0]})",
                             "pip install 'pyoa[pocl]' (it brings PoCL, a CPU OpenCL platform)") from exc

    def platform_key(pl):
        is_pocl = POCL_NAME in pl.name
        return (not is_pocl, [] if not is_pocl else [-x if isinstance(x, int) else x for x in _natural(pl.version)],
                pl.name, pl.version)

    out = []
    for pi, pl in enumerate(sorted(platforms, key=platform_key)):
        try:
            devices = pl.get_devices()
        except cl.Error:
            continue
        devices = sorted(devices, key=lambda d: (not (d.type & cl.device_type.CPU), d.name))
        out.extend(DeviceInfo(pi, di, pl, d) for di, d in enumerate(devices))
    if not out:
        raise NoUsableDevice("OpenCL platforms exist but expose no device",
                             "pip install 'pyoa[pocl]' (it brings PoCL, a CPU OpenCL platform)")
    return out


def candidates() -> list[DeviceInfo]:
    """The devices pyoa tries, in order, when no selector is given: PoCL's
    (newest version first, as :func:`list_devices` orders them), then other
    CPU devices, then the rest. The first that builds pyoa's program is used
    (:mod:`pyoa._opencl.choice`).

    Raises
    ------
    NoUsableDevice
        If there is no OpenCL device at all.
    """
    devices = list_devices()
    return sorted(devices, key=lambda d: (not d.is_pocl, d.kind != "cpu"))  # stable: keeps list order within


def select_device(selector: str | None = None) -> DeviceInfo:
    """The device named by ``selector`` (or ``$PYOA_OPENCL_DEVICE``), else the
    first of :func:`candidates` (whether or not it builds pyoa's program: see
    :func:`pyoa._opencl.choice.open_device` for the device pyoa really uses).

    Raises
    ------
    ValueError
        If the selector matches no device (the message lists them).
    NoUsableDevice
        If there is no OpenCL device at all.
    """
    if selector is None:
        selector = os.environ.get(ENV_DEVICE) or None
    if selector is None:
        return candidates()[0]
    devices = list_devices()
    sel = selector.strip().lower()
    m = re.fullmatch(r"(\d+)(?::(\d+))?", sel)
    if m:  # "P" is "P:0"
        m = (int(m[1]), int(m[2] or 0))
    for info in devices:
        if m and (info.platform_index, info.device_index) == m:
            return info
        if not m and (sel == info.kind or sel in f"{info.platform.name} {info.platform.version} / {info.device.name}".lower()):
            return info
    listing = "; ".join(f"{d.platform_index}:{d.device_index} {d.describe()}" for d in devices)
    raise ValueError(f"no OpenCL device matches {selector!r}; devices: {listing}")
