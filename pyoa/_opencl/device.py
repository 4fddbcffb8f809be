"""Choosing an OpenCL device, deterministically.

Default: PoCL's CPU device (pyoa's reference platform). When a host has PoCL
twice (pip's ``pocl-binary-distribution`` and Debian's ``pocl-opencl-icd``
both show a platform named "Portable Computing Language"), the one with the
highest version string wins, so the choice never depends on ICD load order.
Without PoCL, the first device of the first platform in (name, version) order.

A *selector* (the ``device=`` argument of :func:`pyoa.sampler` or the
``PYOA_OPENCL_DEVICE`` environment variable) picks another device:

- ``"P:D"``: device D of platform P in :func:`list_devices` order;
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

    def describe(self) -> str:
        return (
            f"{self.device.name.strip()} ({self.kind}) on "
            f"{self.platform.name.strip()} [{' '.join(self.platform.version.split()[:4])}]"
        )


def _natural(text: str):
    return [int(tok) if tok.isdigit() else tok for tok in re.split(r"(\d+)", text)]


def list_devices() -> list[DeviceInfo]:
    """Every OpenCL device, platforms ordered PoCL first (newest version first),
    then the others by (name, version); devices CPU first within a platform.

    Raises
    ------
    RuntimeError
        If pyopencl is not installed or no OpenCL platform is found.
    """
    try:
        import pyopencl as cl
    except ImportError as exc:  # pragma: no cover - depends on the install
        raise RuntimeError(f"pyopencl is not installed ({exc}); pip install 'pyoa[pocl]'") from exc
    try:
        platforms = cl.get_platforms()
    except cl.Error as exc:
        raise RuntimeError(f"no OpenCL platform found ({exc}); pip install 'pyoa[pocl]' brings PoCL") from exc

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
        raise RuntimeError("OpenCL platforms exist but expose no device")
    return out


def select_device(selector: str | None = None) -> DeviceInfo:
    """The device named by ``selector`` (or ``$PYOA_OPENCL_DEVICE``), else the default.

    Raises
    ------
    ValueError
        If the selector matches no device (the message lists them).
    RuntimeError
        If there is no OpenCL device at all.
    """
    if selector is None:
        selector = os.environ.get(ENV_DEVICE) or None
    devices = list_devices()
    if selector is None:
        return devices[0]
    sel = selector.strip().lower()
    m = re.fullmatch(r"(\d+):(\d+)", sel)
    for info in devices:
        if m and (info.platform_index, info.device_index) == (int(m[1]), int(m[2])):
            return info
        if not m and (sel == info.kind or sel in f"{info.platform.name} {info.platform.version} / {info.device.name}".lower()):
            return info
    listing = "; ".join(f"{d.platform_index}:{d.device_index} {d.describe()}" for d in devices)
    raise ValueError(f"no OpenCL device matches {selector!r}; devices: {listing}")
