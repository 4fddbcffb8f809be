"""Which OpenCL device pyoa uses (pyoa._opencl.choice): a device whose build
fails is skipped, the reason is kept in plain words, an explicit selector is
never swapped for another device, and the fallback warning is two lines.

Builds fail for real here: a program with an ``#error`` on a real device, or
pyoa's own program broken by a macro PoCL adds to every build
(``POCL_EXTRA_BUILD_FLAGS``) in a subprocess that sees only pip's PoCL.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import pyoa
from pyoa._opencl import choice, program
from pyoa._opencl.device import NoUsableDevice, candidates, list_devices
from pyoa.backends import BackendUnavailable, fallback_message
from pyoa.util.hostcpu import host_cpu

pytestmark = pytest.mark.opencl

#: pyoa's program with a compile error appended: it fails on every compiler.
BROKEN_MARK = "pyoa test: this program must not build"


def broken_program() -> str:
    return program.source() + f'\n#error "{BROKEN_MARK}"\n'


def breaking_first(n_broken: int = 1):
    """A builder whose first ``n_broken`` builds compile the broken program
    (a real compile failure on a real device) and the rest pyoa's own."""
    calls = []

    def build(info):
        calls.append(info)
        return program.build(info, text=broken_program() if len(calls) <= n_broken else None)

    build.calls = calls
    return build


def working_candidates():
    """The candidates that build pyoa's own program here, in candidate order
    (on AMD Zen 5, pip's PoCL 3.0 is listed but never builds)."""
    return [info for info in candidates() if choice.probe(info).works]


def test_failing_device_is_skipped_and_its_reason_kept():
    first = working_candidates()[0]
    # The same device twice: its first build fails for real, the second
    # candidate (the device again, now with pyoa's own program) is used.
    build = breaking_first()
    info, (ctx, queue, prg) = choice.first_working([first, first], build=build)
    assert info is first and len(build.calls) == 2
    assert "generate_cells" in {k.function_name for k in prg.all_kernels()}


def test_next_distinct_device_is_used_when_the_first_fails():
    devices = working_candidates()
    if len(devices) < 2:
        pytest.skip("one working OpenCL device here: the skip to a second one needs two (CI installs a second "
                    "PoCL; both work on the AVX2 and Zen 4 EPYC)")
    info, _ = choice.first_working(devices, build=breaking_first())
    assert info.device.int_ptr == devices[1].device.int_ptr


def test_no_device_builds_names_the_first_and_counts_the_rest():
    devices = working_candidates()
    with pytest.raises(NoUsableDevice) as exc:
        choice.first_working(devices + devices, build=breaking_first(n_broken=10**6))
    err = exc.value
    assert len(err.statuses) == 2 * len(devices)
    assert all(not st.works and BROKEN_MARK in st.reason and BROKEN_MARK in st.log for st in err.statuses)
    assert err.cause.startswith(f"{devices[0].short()} cannot build pyoa's kernels: its compiler stops with error:")
    assert f"(and {2 * len(devices) - 1} other device" in err.cause
    assert "\n" not in err.cause and "\n" not in err.fix


def test_explicit_selector_is_never_swapped(monkeypatch):
    first = working_candidates()[-1]
    build = breaking_first()
    with pytest.raises(NoUsableDevice) as exc:
        choice.open_device(first.selector, build=build)
    assert [i.device.int_ptr for i in build.calls] == [first.device.int_ptr]  # no other device tried
    assert BROKEN_MARK in exc.value.cause
    # the environment's selector means exactly that device too
    monkeypatch.setenv("PYOA_OPENCL_DEVICE", first.selector)
    build = breaking_first()
    with pytest.raises(NoUsableDevice):
        choice.open_device(None, build=build)
    assert len(build.calls) == 1


def test_probe_all_covers_every_device_and_the_default_works():
    statuses = choice.probe_all()
    assert [st.info.selector for st in statuses] == [d.selector for d in list_devices()]
    assert any(st.works for st in statuses)
    info, _ = choice.open_device()
    assert choice.probe(info).works


# Verbatim shape of pyopencl's error for pip's PoCL 3.0 (LLVM 14) on AMD Zen 5.
ZEN5_LOG = """clBuildProgram failed: BUILD_PROGRAM_FAILURE - clBuildProgram failed: BUILD_PROGRAM_FAILURE

Build on <pyopencl.Device 'pthread-AMD EPYC' on 'Portable Computing Language' at 0x55d0>:

error: unknown target CPU 'generic'
note: valid target CPU values are: nocona, core2, penryn, bonnell, atom, silvermont, slm, goldmont

(options: -cl-fp32-correctly-rounded-divide-sqrt -DOFFSET_CMJ=0 -DOFFSET_MJ=1 -DCONSTRUCTION_BOSE=0)
"""


def test_unknown_cpu_is_explained_in_plain_words():
    info = candidates()[0]
    reason, fix = choice.explain(info, program.BuildError(info, "build", ZEN5_LOG))
    llvm = info.llvm_version()
    if llvm:
        assert f"'s LLVM {llvm.split('.')[0]} does not know this CPU" in reason
    assert "does not know this CPU" in reason and "'generic'" in reason
    assert host_cpu().describe() in reason
    assert fix == "on Debian/Ubuntu: apt-get install pocl-opencl-icd (a PoCL with a newer LLVM)"
    assert "-D" not in reason and "\n" not in reason


def test_build_error_is_one_line_with_the_first_diagnostic():
    info = candidates()[0]
    err = program.BuildError(info, "build", ZEN5_LOG)
    assert str(err) == f"OpenCL build failed on {info.short()}: error: unknown target CPU 'generic'"
    assert err.log == ZEN5_LOG


def test_fallback_warning_is_two_lines_with_device_cause_and_fix():
    info = candidates()[0]
    status = choice._attempt(info, lambda i: (_ for _ in ()).throw(program.BuildError(i, "build", ZEN5_LOG)))[1]
    cause = f"{info.short()} cannot build pyoa's kernels: {status.reason}"
    msg = fallback_message(BackendUnavailable(cause, status.fix))
    lines = msg.splitlines()
    assert len(lines) == 2
    assert lines[0].startswith(f"pyoa: OpenCL is not usable: {info.short()} cannot build pyoa's kernels: ")
    assert "does not know this CPU" in lines[0] and "using NumPy instead" in lines[0]
    assert lines[1] == ("Fix: on Debian/Ubuntu: apt-get install pocl-opencl-icd (a PoCL with a newer LLVM); "
                        "or set PYOA_BACKEND=numpy to silence this. Details: pyoa backends --verbose")
    assert "note:" not in msg and "options" not in msg and "-DOFFSET" not in msg


# ----------------------------------------------------------------------------- subprocesses, builds broken for real

SCRIPT = textwrap.dedent("""
    import warnings
    warnings.simplefilter("always")
    with warnings.catch_warnings(record=True) as rec:
        import pyoa
        s = pyoa.sampler("bose", spp=9, dims=2)
        s.generate(pixels=range(2))
    print("BACKEND", s.backend)
    for w in rec:
        print("WARNING", w.category.__name__, repr(str(w.message)))
""")


@pytest.fixture
def only_pip_pocl_broken(tmp_path):
    """Environment for a subprocess that sees only pyopencl's bundled PoCL
    (an empty ICD directory hides every system ICD) and whose builds all fail
    (a macro that breaks OpenCL C's own headers, added by PoCL itself)."""
    if not any("PoCL 3.0" in d.platform.version for d in list_devices()):
        pytest.skip("pyopencl's bundled PoCL 3.0 is not installed here")
    vendors = tmp_path / "no-icds"
    vendors.mkdir()
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYOA_", "POCL_"))}
    env.update(OCL_ICD_VENDORS=str(vendors), POCL_EXTRA_BUILD_FLAGS="-Duint=@",
               POCL_CACHE_DIR=str(tmp_path / "pocl-cache"))
    probe = subprocess.run([sys.executable, "-c", "import pyopencl as cl; print(len(cl.get_platforms()))"],
                           capture_output=True, text=True, env=env, timeout=120)
    if probe.stdout.strip() != "1":
        pytest.skip(f"pyopencl here does not bundle its own PoCL ICD: {probe.stdout} {probe.stderr}")
    return env


def test_subprocess_falls_back_with_a_two_line_warning(only_pip_pocl_broken):
    res = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True,
                         env=only_pip_pocl_broken, timeout=300)
    assert res.returncode == 0, res.stderr
    assert "BACKEND numpy" in res.stdout
    warns = [ln for ln in res.stdout.splitlines() if ln.startswith("WARNING")]
    assert len(warns) == 1 and "PyoaFallbackWarning" in warns[0], res.stdout
    msg = eval(warns[0].split(" ", 2)[2])  # the repr printed above
    lines = msg.splitlines()
    assert len(lines) == 2, msg
    assert "pthread" in lines[0] and "PoCL 3.0" in lines[0] and "cannot build pyoa's kernels" in lines[0]
    # the broken macro, or (on a CPU newer than LLVM 14, e.g. AMD Zen 5) the real cause
    assert "its compiler stops with error:" in lines[0] or "LLVM 14 does not know this CPU" in lines[0]
    assert "PYOA_BACKEND=numpy" in lines[1] and "pyoa backends --verbose" in lines[1]
    assert "clBuildProgram" not in msg and "-DOFFSET" not in msg
    # PoCL's own compiler output went into the build log, not to the user's terminal
    assert "errors generated" not in res.stderr and "expected identifier" not in res.stderr, res.stderr


def test_cli_backends_names_the_failing_device_in_one_line(only_pip_pocl_broken):
    exe = Path(sys.executable).with_name("pyoa")
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "pyoa"]
    res = subprocess.run(cmd + ["backends"], capture_output=True, text=True, env=only_pip_pocl_broken, timeout=300)
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    dev = [ln for ln in lines if ln.strip().startswith("device 0:0")]
    assert len(dev) == 1 and "PoCL 3.0" in dev[0] and ": fails: " in dev[0], res.stdout
    assert "its compiler stops with error:" in dev[0] or "LLVM 14 does not know this CPU" in dev[0]
    assert any(ln.startswith("  opencl  not usable:") for ln in lines)
    assert any(ln.startswith("* numpy") for ln in lines)
    assert lines[0].startswith("CPU: ") and "clBuildProgram" not in res.stdout
    verbose = subprocess.run(cmd + ["backends", "--verbose"], capture_output=True, text=True,
                             env=only_pip_pocl_broken, timeout=300)
    assert "clBuildProgram failed" in verbose.stdout
    if "its compiler stops with error:" in dev[0]:  # what the compiler printed is in the log
        assert "errors generated" in verbose.stdout
    # the CLI prints the fallback warning as its two plain lines
    points = subprocess.run(cmd + ["points", "--spp", "9", "--dims", "2", "--out", str(Path(only_pip_pocl_broken[
        "POCL_CACHE_DIR"]).parent / "p.npy"), "-q"], capture_output=True, text=True, env=only_pip_pocl_broken,
        timeout=300)
    assert points.returncode == 0, points.stderr
    assert points.stderr.count("\n") == 2 and points.stderr.startswith("pyoa: OpenCL is not usable: "), points.stderr


def test_device_under_test_is_what_pyoa_uses(opencl_device, opencl):
    """The harness of PYOA_TEST_DEVICES: inside a test, pyoa's default OpenCL
    backend, the ``opencl`` fixture and the ``backend`` tests all run on the
    device under test (without the switch: on pyoa's default device)."""
    smp = pyoa.sampler("bose", spp=9, dims=2, backend="opencl")
    assert smp._backend is opencl
    if opencl_device is not None:
        assert opencl.info.selector == opencl_device
    else:
        assert opencl.info.device.int_ptr == choice.open_device()[0].device.int_ptr
