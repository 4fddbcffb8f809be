"""Images in and out with OpenImageIO; every write is atomic; relative MSE.

Writes refuse an image with a non-finite pixel (NaN or inf), and refuse an
output path that cannot be written, naming the user's path (never the
temporary file beside it). A reference image must hold linear radiance: a
float or half image (EXR, HDR), not 8- or 16-bit integer data such as a PNG,
which is sRGB-encoded display data.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numpy as np

from ..util import atomic
from ..util.atomic import atomic_path

#: Output formats by extension (what pyoa writes: linear float EXR, 8-bit sRGB PNG).
EXR, PNG = (".exr",), (".png",)
#: Pixel formats of linear radiance (OpenImageIO base types).
LINEAR_FORMATS = ("half", "float", "double")
#: Prefix of pyoa's attributes in an image header (what they hold: :mod:`pyoa.render.provenance`).
PREFIX = "pyoa:"


def _oiio():
    try:
        import OpenImageIO as oiio
    except ImportError as exc:  # pragma: no cover - install problem
        raise RuntimeError("writing images needs OpenImageIO: pip install OpenImageIO") from exc
    return oiio


def check_output(path, option: str, suffixes: tuple[str, ...]) -> None:
    """Refuse (ValueError, one line naming ``option`` and ``path``) an image
    output that could not be written at the end of a long job: a wrong
    extension, a directory, a missing parent directory, one where no file can
    be created, a format OpenImageIO cannot write."""
    p = Path(path)
    if p.suffix.lower() not in suffixes:
        raise ValueError(f"{option} {str(path)!r}: the file name must end in {' or '.join(suffixes)}")
    check_writable(path, option)
    out = _oiio().ImageOutput.create(str(p))
    if out is None:  # pragma: no cover - an OpenImageIO built without EXR or PNG
        raise ValueError(f"{option} {str(path)!r}: OpenImageIO cannot write {p.suffix} files here")


def check_writable(path, option: str) -> None:
    """Refuse a ``path`` that :func:`pyoa.util.atomic.atomic_path` could not write
    (see :func:`pyoa.util.atomic.check_writable`: a directory, a missing parent, a
    place where no file can be created), the message led by ``option``."""
    try:
        atomic.check_writable(path)
    except OSError as exc:
        raise type(exc)(f"{option}: {exc}") from None


def check_finite(image: np.ndarray, what: str) -> None:
    """Refuse (ValueError) an image with NaN or inf pixels: the message starts
    with ``what`` and gives their count and the first few (x, y)."""
    bad = ~np.isfinite(image)
    if bad.ndim == 3:
        bad = bad.any(axis=2)
    if bad.any():
        ys, xs = np.nonzero(bad)
        first = ", ".join(f"({x}, {y})" for x, y in zip(xs[:3].tolist(), ys[:3].tolist()))
        raise ValueError(f"{what}: {len(xs)} of {bad.size} pixels are not finite (NaN or inf, e.g. radiance over "
                         f"the float32 range), first at (x, y) {first}{', ...' if len(xs) > 3 else ''}")


def _write(path, pixels: np.ndarray, fmt: str, metadata: dict | None = None) -> None:
    oiio = _oiio()
    attrs = header_attributes(metadata)  # a bad value is refused before anything is written
    h, w, c = pixels.shape

    def failed(message: str) -> str:
        # OpenImageIO names the temporary file; the user knows only `path`
        first = (message.strip().splitlines() or ["unknown error"])[0]
        return f"OpenImageIO: {first.replace(str(tmp), str(path))}"

    # atomic_path refuses a directory or a missing parent before the body, and
    # re-raises an OSError of the body as "cannot write 'PATH': ..."
    with atomic_path(path) as tmp:
        out = oiio.ImageOutput.create(str(tmp))
        if out is None:
            raise ValueError(f"cannot write {str(path)!r}: {failed(oiio.geterror())}")
        spec = oiio.ImageSpec(w, h, c, fmt)
        for name, value in attrs:
            spec.attribute(name, value)
        if not (out.open(str(tmp), spec) and out.write_image(pixels) and out.close()):
            raise OSError(failed(out.geterror()))


def write_exr(path: str | os.PathLike, image: np.ndarray, metadata: dict | None = None) -> None:
    """Write a linear float32 RGB image (``(H, W, 3)``) as OpenEXR, atomically,
    with ``metadata`` (str or int values, :func:`pyoa.render.provenance.describe`)
    in its header as ``pyoa:KEY`` attributes (:func:`read_attributes`).

    A non-finite pixel, or one a float32 cannot hold, is refused (ValueError)."""
    with np.errstate(over="ignore"):  # a value over the float32 range becomes inf, refused just below
        pixels = np.ascontiguousarray(image, dtype=np.float32)
    check_finite(pixels, f"{str(path)!r} not written")
    _write(path, pixels, "float", metadata)


def to_srgb8(image: np.ndarray) -> np.ndarray:
    """Linear RGB to 8-bit sRGB (IEC 61966-2-1 transfer curve), clipped to [0, 1]."""
    x = np.clip(np.nan_to_num(image.astype(np.float64)), 0.0, 1.0)
    x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return np.round(x * 255.0).astype(np.uint8)


def write_png(path: str | os.PathLike, image: np.ndarray) -> None:
    """Write a linear RGB image as an 8-bit sRGB PNG, atomically (a
    non-finite pixel is refused, not drawn black)."""
    check_finite(image, f"{str(path)!r} not written")
    _write(path, to_srgb8(image), "uint8")


def open_image(path, what: str = "an image pyoa reads"):
    """``path`` opened by OpenImageIO, after the regular-file check every
    file pyoa reads gets (:func:`pyoa.render.state.check_state_file`): a
    FIFO would block OpenImageIO's open for ever, a device be read for ever.
    ``what`` says whose file it is in a refusal."""
    from .state import check_state_file

    oiio = _oiio()
    if not os.path.exists(path):
        raise FileNotFoundError(f"no such image: {str(path)!r}")
    if os.path.isdir(path):
        raise ValueError(f"{str(path)!r} is a directory, not an image")
    check_state_file(path, what, "give an image file")
    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        first = (oiio.geterror().strip().splitlines() or ["unknown format"])[0]
        raise ValueError(f"OpenImageIO cannot read {str(path)!r}: {first}")
    return inp


def image_info(path: str | os.PathLike, what: str = "an image pyoa reads") -> tuple[int, int, int, str]:
    """``(width, height, channels, pixel format)`` of an image file, from its
    header only (nothing is decoded); ``what`` names the file in a refusal."""
    inp = open_image(path, what)
    try:
        spec = inp.spec()
        return spec.width, spec.height, spec.nchannels, str(spec.format)
    finally:
        inp.close()


def read_image(path: str | os.PathLike, what: str = "an image pyoa reads") -> np.ndarray:
    """Read an image (EXR, PNG, ...) as float32 ``(H, W, channels)``; ``what``
    names the file in a refusal. A file whose pixels cannot all be read (cut
    short, damaged) is refused with OpenImageIO's reason."""
    inp = open_image(path, what)
    try:
        spec = inp.spec()
        pixels = inp.read_image("float")
        # read_image's error is kept by the ImageInput (geterror), not globally
        why = inp.geterror() if pixels is None else ""
    finally:
        inp.close()
    if pixels is None:
        first = (why.strip().splitlines() or ["no reason given"])[0]
        raise ValueError(f"reading {str(path)!r} failed: it is truncated or damaged (OpenImageIO: {first})")
    return np.asarray(pixels, dtype=np.float32).reshape(spec.height, spec.width, -1)


def pixel_digest(pixels: np.ndarray) -> str:
    """SHA-256 (hex) of an image's shape and float32 pixels (little-endian):
    what ties a reference's variance file to it (written by ``pyoa reference``,
    checked by :func:`pyoa.render.reference.reference_noise`) and a study's
    reference to its rows. Not of the file: the same pixels written again
    (an EXR carries the time it was written) keep the digest."""
    a = np.ascontiguousarray(pixels, dtype="<f4")
    h = hashlib.sha256(repr(a.shape).encode())
    h.update(a.tobytes())
    return h.hexdigest()


def check_reference(path, option: str, width: int, height: int) -> None:
    """Refuse (ValueError/FileNotFoundError) a reference image that is not
    linear radiance of ``width`` x ``height`` with RGB channels, from its
    header alone: checked before a render, not after it."""
    w, h, c, fmt = image_info(path, option)
    if fmt not in LINEAR_FORMATS:
        raise ValueError(f"{option} {str(path)!r} holds {fmt} pixels (display-encoded, e.g. an sRGB PNG), not linear "
                         "radiance; give a float or half image such as EXR or HDR (pyoa reference writes one)")
    if c < 3:
        raise ValueError(f"{option} {str(path)!r} has {c} channel{'s' if c != 1 else ''}; it needs RGB (3 or more)")
    if (w, h) != (width, height):
        raise ValueError(f"reference {str(path)!r} is {w} x {h}, the render is {width} x {height}; "
                         f"render with --size {w} {h}")


def read_reference(path, option: str, width: int, height: int) -> np.ndarray:
    """A reference image as float32 ``(height, width, 3)``: checked as
    :func:`check_reference`, and every pixel finite."""
    check_reference(path, option, width, height)
    ref = read_image(path, option)[..., :3]
    check_finite(ref, f"{option} {str(path)!r}")
    return np.ascontiguousarray(ref)


def default_crop(shape):
    """The crop window of compare and study without ``--crop``: the quarter-size window at (W/4, H/4)."""
    h, w = shape[:2]
    return (w // 4, h // 4, max(1, w // 4), max(1, h // 4))


def check_crop(crop, width: int, height: int) -> None:
    """Refuse (ValueError) a crop window ``(x, y, w, h)`` that is empty or not
    inside a ``width`` x ``height`` image."""
    x, y, w, h = crop
    if w <= 0 or h <= 0 or x < 0 or y < 0 or x + w > width or y + h > height:
        raise ValueError(f"crop {x} {y} {w} {h} does not fit in the {width} x {height} image")


def rel_mse(image: np.ndarray, reference: np.ndarray, crop=None) -> float:
    """Relative mean squared error, the paper's error measure:
    mean over pixels and channels of ``(image - ref)^2 / (ref^2 + 1e-2)``.

    ``crop = (x, y, w, h)`` restricts it to a window of the image.
    """
    if image.shape != reference.shape:
        raise ValueError(f"image {image.shape} and reference {reference.shape} differ in size")
    if crop is not None:
        check_crop(crop, image.shape[1], image.shape[0])
        x, y, w, h = crop
        image, reference = image[y:y + h, x:x + w], reference[y:y + h, x:x + w]
    a, r = image.astype(np.float64), reference.astype(np.float64)
    return float(np.mean((a - r) ** 2 / (r**2 + 1e-2)))


def header_attributes(meta: dict | None) -> list[tuple[str, str | int]]:
    """``meta`` as (header name, value) pairs: names prefixed, values str or int (others refused)."""
    out = []
    for key, value in (meta or {}).items():
        if isinstance(value, bool) or not isinstance(value, (str, int)):
            raise TypeError(f"image metadata {key!r} must be a str or an int, got {type(value).__name__}")
        out.append((PREFIX + key, value))
    return out


def read_attributes(path) -> dict:
    """The ``pyoa:`` attributes of an image's header as ``{key: value}`` (empty for an image pyoa did not
    write, or wrote before it kept them)."""
    inp = open_image(path)
    try:
        spec = inp.spec()
        return {a.name[len(PREFIX):]: a.value for a in spec.extra_attribs if a.name.startswith(PREFIX)}
    finally:
        inp.close()
