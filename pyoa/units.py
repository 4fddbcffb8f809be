"""Human-readable quantities for messages and progress lines: byte sizes and rates."""

from __future__ import annotations


def format_rate(per_s: float) -> str:
    """A rate with an SI prefix and three significant digits, to be followed by
    the unit: ``1234567.0`` -> ``"1.23 M"`` (``"1.23 M values/s"``)."""
    for unit, scale in (("G", 1e9), ("M", 1e6), ("k", 1e3)):
        if per_s >= scale:
            return f"{per_s / scale:.3g} {unit}"
    return f"{per_s:.3g}"


def format_bytes(n: float) -> str:
    """``1536`` -> ``"1.5 KiB"`` (binary units, for memory-limit messages)."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{int(n)} B" if unit == "B" else f"{n:.1f} {unit}" if n < 1e6 else f"{n:.3g} {unit}"
        n /= 1024
    return f"{n} B"  # pragma: no cover
