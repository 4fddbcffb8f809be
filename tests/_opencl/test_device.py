"""Choosing an OpenCL device (pyoa._opencl.device)."""

from __future__ import annotations

import pytest

import pyoa
from pyoa._opencl import device as dev

pytestmark = pytest.mark.opencl


def test_list_devices_and_selectors():
    devices = dev.list_devices()
    assert devices
    first = devices[0]
    assert dev.select_device(f"{first.platform_index}:{first.device_index}").device == first.device
    assert dev.select_device(f" {first.platform_index}:{first.device_index} ").device == first.device
    assert dev.select_device(first.kind).kind == first.kind
    assert first.kind in first.describe()


def test_default_is_pocl_when_present(monkeypatch):
    monkeypatch.delenv(dev.ENV_DEVICE, raising=False)
    devices = dev.list_devices()
    if any(dev.POCL_NAME in d.platform.name for d in devices):
        assert dev.POCL_NAME in dev.select_device(None).platform.name


def test_unknown_selector_lists_devices():
    with pytest.raises(ValueError) as exc:
        dev.select_device("nonexistent-device")
    msg = str(exc.value)
    assert "nonexistent-device" in msg and "devices:" in msg
    assert dev.list_devices()[0].describe() in msg


def test_sampler_with_unknown_device_raises_value_error():
    with pytest.raises(ValueError, match="no OpenCL device matches 'nonexistent-device'"):
        pyoa.sampler("bose", spp=9, dims=2, backend="opencl", device="nonexistent-device")
