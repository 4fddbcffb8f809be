"""The host CPU as reports name it (pyoa.util.hostcpu)."""

from __future__ import annotations

from pyoa.util.hostcpu import HostCPU, _parse_cpuinfo, host_cpu

ZEN5 = """processor\t: 0
vendor_id\t: AuthenticAMD
cpu family\t: 26
model\t\t: 2
model name\t: AMD EPYC 9R45
flags\t\t: fpu vme sse sse2 ssse3 sse4_1 sse4_2 avx avx2 avx512f avx512dq avx512_vp2intersect

processor\t: 1
vendor_id\t: SomethingElse
cpu family\t: 99
"""

ZEN3_AVX2 = """processor\t: 0
vendor_id\t: AuthenticAMD
cpu family\t: 25
model\t\t: 1
model name\t: AMD EPYC 7B13
flags\t\t: fpu sse sse2 sse4_2 avx avx2 fma
"""


def test_parse_names_vendor_family_model_and_widest_isa():
    cpu = _parse_cpuinfo(ZEN5)
    assert cpu == HostCPU("AuthenticAMD", 26, 2, "AMD EPYC 9R45", "AVX-512")
    assert cpu.describe() == "AMD EPYC 9R45, AuthenticAMD family 26 model 2, AVX-512"
    assert _parse_cpuinfo(ZEN3_AVX2).isa == "AVX2"


def test_missing_fields_do_not_break_the_description():
    cpu = _parse_cpuinfo("processor\t: 0\nFeatures\t: fp asimd\n")
    assert cpu.family is None and cpu.model is None and cpu.isa == "ASIMD"
    assert cpu.describe().endswith(", ASIMD") and "family" not in cpu.describe()


def test_this_host():
    cpu = host_cpu()
    assert cpu.name and cpu.isa and cpu.describe().count("\n") == 0
