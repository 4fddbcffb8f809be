"""``python -m pyoa.config``: the flags a C, C++ or CUDA build needs for
pyoa's headers (``--cflags``: ``-I`` and :func:`pyoa.get_include`, nothing
else), the bare folder (``--include``), and a pkg-config file with the same
Cflags (``--write-pkg-config DIR``). The module runs in a subprocess, as a
build script runs it; a tiny program built with nothing but the printed flags
gives the reference's bits. Set ``PYOA_REQUIRE_C=1`` (CI does) to fail
instead of skip without gcc (pkg-config, where installed, reads the file)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import pyoa
from pyoa import config
from pyoa.reference.hashes import permute

from .test_c_headers import need


def run(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "pyoa.config", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=60)


def test_cflags_is_the_include_folder_and_nothing_else():
    res = run("--cflags")
    assert res.returncode == 0, res.stderr
    assert res.stdout == f"-I{pyoa.get_include()}\n"
    assert (Path(pyoa.get_include()) / "pyoa" / "config.h").is_file()


def test_include_prints_the_folder():
    res = run("--include")
    assert res.returncode == 0, res.stderr
    assert res.stdout == pyoa.get_include() + "\n"


def test_no_option_is_a_usage_error():
    res = run()
    assert res.returncode == 2 and res.stdout == ""
    assert "one of the arguments --cflags --libs --include --pkg-config --write-pkg-config is required" in res.stderr


def test_two_options_are_a_usage_error():
    res = run("--cflags", "--include")
    assert res.returncode == 2 and "not allowed with argument" in res.stderr


def test_help_lists_the_flags_that_break_bit_exactness():
    res = run("--help")
    assert res.returncode == 0
    for flag in ("-ffast-math", "-Ofast", "-funsafe-math-optimizations", "-ffp-contract=fast (clang)", "/fp:fast",
                 "-mfpmath=387"):
        assert flag in res.stdout
    assert set(config.FORBIDDEN_FLAGS) and all(flag in res.stdout for flag in config.FORBIDDEN_FLAGS)


def _pc_fields(text: str) -> dict[str, str]:
    """The variables and keywords of a .pc file, ${var} expanded (pkg-config's rules, enough for pyoa.pc)."""
    fields: dict[str, str] = {}
    for line in text.splitlines():
        for sep in (":", "="):
            key, found, value = line.partition(sep)
            if found and key.strip().isidentifier():
                for name, val in fields.items():
                    value = value.replace("${%s}" % name, val)
                fields[key.strip()] = value.strip()
                break
    return fields


def test_write_pkg_config_writes_the_same_cflags(tmp_path):
    res = run("--write-pkg-config", str(tmp_path))
    assert res.returncode == 0, res.stderr
    pc = tmp_path / "pyoa.pc"
    assert res.stdout == f"{pc}\n"
    fields = _pc_fields(pc.read_text())
    assert fields["Name"] == "pyoa" and fields["Version"] == pyoa.__version__ and fields["Description"]
    assert fields["Cflags"] == run("--cflags").stdout.strip()
    assert fields["Libs"] == "-lm" == run("--libs").stdout.strip()  # header-only, but fmaf is libm's
    assert pc.read_text() == run("--pkg-config").stdout


def test_pkg_config_reads_the_file(tmp_path):
    """pkg-config itself, where installed, gives --cflags' flags and pyoa's version."""
    tool = shutil.which("pkg-config")
    if tool is None:  # not part of CI's set-up; the file's text is checked above without it
        pytest.skip("pkg-config not found")
    assert run("--write-pkg-config", str(tmp_path)).returncode == 0
    env = dict(os.environ, PKG_CONFIG_PATH=str(tmp_path))
    got = subprocess.run([tool, "--cflags", "pyoa"], env=env, capture_output=True, text=True)
    assert got.returncode == 0, got.stderr
    assert got.stdout.split() == run("--cflags").stdout.split()
    libs = subprocess.run([tool, "--libs", "pyoa"], env=env, capture_output=True, text=True)
    assert libs.stdout.split() == ["-lm"]
    version = subprocess.run([tool, "--modversion", "pyoa"], env=env, capture_output=True, text=True)
    assert version.stdout.strip() == pyoa.__version__


def test_write_pkg_config_into_a_missing_folder_fails_clearly(tmp_path):
    missing = tmp_path / "no" / "such"
    res = run("--write-pkg-config", str(missing))
    assert res.returncode == 2
    assert res.stderr == f"python -m pyoa.config: error: --write-pkg-config: {missing} is not a directory " \
                         "(create it first)\n"
    assert not missing.exists()


def test_a_folder_with_spaces_is_quoted_in_the_pc_file(monkeypatch):
    """pkg-config splits Cflags as a shell does; an unquoted folder with a space would become two flags."""
    monkeypatch.setattr(config, "get_include", lambda: "/opt/my tools/include")
    text = config.pkg_config_text()
    assert 'includedir="/opt/my tools/include"' in text.splitlines()
    monkeypatch.setattr(config, "get_include", lambda: "/opt/tools/include")
    assert "includedir=/opt/tools/include" in config.pkg_config_text().splitlines()


PROGRAM = r"""#include <stdio.h>
#include <pyoa/sampler.h>
int main(void)
{
    pyoa_options o = pyoa_options_default("bose", 49);
    pyoa_sampler s;
    char message[1024];
    o.dims = 3;
    o.seed = 7;
    if (pyoa_sampler_make(&s, &o, message, sizeof message) != PYOA_OK) { puts(message); return 1; }
    printf("%u %.9g %.9g\n", pyoa_permute(5u, 121u, 7u), pyoa_sampler_value(&s, 5u, 11u, 2u),
           pyoa_sampler_value(&s, 1000u, 48u, 0u));
    return 0;
}
"""


@pytest.mark.parametrize("compiler,suffix,std", [("gcc", ".c", "-std=c99"), ("g++", ".cpp", "-std=c++14")])
def test_a_program_built_with_the_printed_flags_gives_the_python_apis_bits(tmp_path, compiler, suffix, std):
    """--cflags and --libs are all a build needs: a program that makes a sampler with the C API (compiled
    at -O0, where GCC leaves fmaf to libm, in a folder far from the repository, as a renderer's is)
    prints the Python API's values and the reference's permutation."""
    cc = need(compiler, "PYOA_REQUIRE_C")
    src = tmp_path / f"tiny{suffix}"
    src.write_text(PROGRAM)
    build = subprocess.run([cc, std, "-O0", "-Wall", "-Wextra", "-Werror", "-pedantic", *run("--cflags").stdout.split(),
                            str(src), "-o", str(tmp_path / "tiny"), *run("--libs").stdout.split()],
                           capture_output=True, text=True, cwd=tmp_path)
    assert build.returncode == 0, build.stderr
    out = subprocess.run([str(tmp_path / "tiny")], capture_output=True, text=True).stdout
    s = pyoa.sampler("bose", spp=49, dims=3, seed=7, backend="numpy")
    values = s.generate(pixels=[5], samples=[11], dims=[2])[0, 0, 0], s.generate(pixels=[1000], samples=[48],
                                                                                   dims=[0])[0, 0, 0]
    assert out == f"{permute(5, 121, 7)} {values[0]:.9g} {values[1]:.9g}\n"


def test_a_build_without_the_flags_does_not_find_the_headers(tmp_path):
    """The previous test can fail: without the printed flags the header is not found."""
    cc = need("gcc", "PYOA_REQUIRE_C")
    src = tmp_path / "tiny.c"
    src.write_text("#include <pyoa/hashes.h>\nint main(void) { return 0; }\n")
    build = subprocess.run([cc, "-std=c99", str(src), "-o", str(tmp_path / "tiny")], capture_output=True, text=True,
                           cwd=tmp_path)
    assert build.returncode != 0 and "pyoa/hashes.h" in build.stderr
