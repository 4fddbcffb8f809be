"""Images in and out with OpenImageIO; every write is atomic; relative MSE."""

from __future__ import annotations

import os

import numpy as np

from ..atomic import atomic_path


def _oiio():
    try:
        import OpenImageIO as oiio
    except ImportError as exc:  # pragma: no cover - install problem
        raise RuntimeError("writing images needs OpenImageIO: pip install OpenImageIO") from exc
    return oiio


def _write(path, pixels: np.ndarray, fmt: str) -> None:
    oiio = _oiio()
    h, w, c = pixels.shape
    with atomic_path(path) as tmp:
        out = oiio.ImageOutput.create(str(tmp))
        if out is None:
            raise ValueError(f"OpenImageIO cannot write {str(path)!r}: {oiio.geterror()}")
        spec = oiio.ImageSpec(w, h, c, fmt)
        if not (out.open(str(tmp), spec) and out.write_image(pixels) and out.close()):
            raise OSError(f"writing {str(path)!r} failed: {out.geterror()}")


def write_exr(path: str | os.PathLike, image: np.ndarray) -> None:
    """Write a linear float32 RGB image (``(H, W, 3)``) as OpenEXR, atomically."""
    _write(path, np.ascontiguousarray(image, dtype=np.float32), "float")


def to_srgb8(image: np.ndarray) -> np.ndarray:
    """Linear RGB to 8-bit sRGB (IEC 61966-2-1 transfer curve), clipped to [0, 1]."""
    x = np.clip(np.nan_to_num(image.astype(np.float64)), 0.0, 1.0)
    x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return np.round(x * 255.0).astype(np.uint8)


def write_png(path: str | os.PathLike, image: np.ndarray) -> None:
    """Write a linear RGB image as an 8-bit sRGB PNG, atomically."""
    _write(path, to_srgb8(image), "uint8")


def read_image(path: str | os.PathLike) -> np.ndarray:
    """Read an image (EXR, PNG, ...) as float32 ``(H, W, channels)``."""
    oiio = _oiio()
    if not os.path.exists(path):
        raise FileNotFoundError(f"no such image: {str(path)!r}")
    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise ValueError(f"OpenImageIO cannot read {str(path)!r}: {oiio.geterror()}")
    try:
        spec = inp.spec()
        pixels = inp.read_image("float")
    finally:
        inp.close()
    if pixels is None:
        raise ValueError(f"reading {str(path)!r} failed")
    return np.asarray(pixels, dtype=np.float32).reshape(spec.height, spec.width, -1)


def rel_mse(image: np.ndarray, reference: np.ndarray, crop=None) -> float:
    """Relative mean squared error, the paper's error measure:
    mean over pixels and channels of ``(image - ref)^2 / (ref^2 + 1e-2)``.

    ``crop = (x, y, w, h)`` restricts it to a window of the image.
    """
    if image.shape != reference.shape:
        raise ValueError(f"image {image.shape} and reference {reference.shape} differ in size")
    if crop is not None:
        x, y, w, h = crop
        H, W = image.shape[:2]
        if w <= 0 or h <= 0 or x < 0 or y < 0 or x + w > W or y + h > H:
            raise ValueError(f"crop {x} {y} {w} {h} does not fit in the {W} x {H} image")
        image, reference = image[y:y + h, x:x + w], reference[y:y + h, x:x + w]
    a, r = image.astype(np.float64), reference.astype(np.float64)
    return float(np.mean((a - r) ** 2 / (r**2 + 1e-2)))
