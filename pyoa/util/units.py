"""Human-readable quantities for messages, progress lines and reports: byte
sizes, rates, and estimates with their intervals."""

from __future__ import annotations

import math


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


def format_interval(mean: float, low: float, high: float) -> str:
    """A mean with the half-width of its (symmetric) interval, three
    significant digits: ``(0.0123, 0.0113, 0.0133)`` -> ``"0.0123 ± 0.001"``;
    the mean alone when the interval is unknown (NaN ends)."""
    if not (math.isfinite(low) and math.isfinite(high)):
        return f"{mean:.3g}"
    return f"{mean:.3g} ± {(high - low) / 2:.2g}"


def format_ratio(ratio: float, low: float, high: float) -> str:
    """A ratio with its (asymmetric) interval: ``"0.86 [0.80, 0.93]"``;
    ``"n/a"`` for a NaN ratio, the ratio alone without an interval, and
    ``∞`` for an unbounded upper end."""
    if not math.isfinite(ratio):
        return "n/a"
    if not math.isfinite(low):
        return f"{ratio:.2f}"
    return f"{ratio:.2f} [{low:.2f}, {high:.2f}]" if math.isfinite(high) else f"{ratio:.2f} [{low:.2f}, ∞)"
