"""The host CPU, named the way diagnostics and benchmark reports need it.

The same OpenCL kernel runs at very different speeds on two CPUs of one
machine kind (an AVX2 AMD EPYC and an AVX-512 Zen 5 EPYC differ by 2.5-3.5x on
the same workload), and whether a PoCL build can compile for the CPU at all
depends on its LLVM knowing the CPU's family. So every report names the
vendor, family, model and widest vector ISA, read from ``/proc/cpuinfo`` on
Linux (``platform`` elsewhere).
"""

from __future__ import annotations

import functools
import platform
from dataclasses import dataclass
from pathlib import Path

#: Vector ISAs from widest to narrowest, with the ``/proc/cpuinfo`` flag that
#: proves each (AVX-512 is named by its foundation subset).
_ISAS = (("AVX-512", "avx512f"), ("AVX2", "avx2"), ("AVX", "avx"), ("SSE4.2", "sse4_2"), ("NEON", "neon"),
         ("ASIMD", "asimd"))


@dataclass(frozen=True)
class HostCPU:
    """What the host CPU is: ``vendor`` (e.g. ``"AuthenticAMD"``), ``family``
    and ``model`` (decimal, as ``lscpu`` prints them; None where not reported),
    ``name`` (the marketing name) and ``isa`` (its widest vector ISA)."""

    vendor: str
    family: int | None
    model: int | None
    name: str
    isa: str

    def describe(self) -> str:
        """One line, e.g. ``"AMD EPYC, AuthenticAMD family 26 model 2, AVX-512"``."""
        ids = [self.vendor] if self.vendor else []
        if self.family is not None:
            ids.append(f"family {self.family}")
        if self.model is not None:
            ids.append(f"model {self.model}")
        return ", ".join([self.name] + ([" ".join(ids)] if ids else []) + [self.isa])


def _parse_cpuinfo(text: str) -> HostCPU:
    """The first processor's fields of a ``/proc/cpuinfo`` text."""
    fields: dict[str, str] = {}
    for line in text.splitlines():
        if not line.strip():
            if fields:
                break  # end of the first processor's block
            continue
        key, _, value = line.partition(":")
        fields.setdefault(key.strip().lower(), value.strip())
    flags = set((fields.get("flags") or fields.get("features") or "").split())
    isa = next((name for name, flag in _ISAS if flag in flags), "no vector ISA reported")

    def number(key):
        try:
            return int(fields[key])
        except (KeyError, ValueError):
            return None

    return HostCPU(
        vendor=fields.get("vendor_id", ""),
        family=number("cpu family"),
        model=number("model"),
        name=fields.get("model name") or platform.processor() or platform.machine() or "unknown CPU",
        isa=isa,
    )


@functools.lru_cache(maxsize=1)
def host_cpu() -> HostCPU:
    """The host CPU (read once per process)."""
    try:
        return _parse_cpuinfo(Path("/proc/cpuinfo").read_text(errors="replace"))
    except OSError:
        return HostCPU(vendor="", family=None, model=None,
                       name=platform.processor() or platform.machine() or "unknown CPU", isa="unknown ISA")
