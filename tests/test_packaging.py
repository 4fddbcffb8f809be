"""What a plain ``pip install .`` (a wheel) ships: every package of the
source tree. setup.cfg lists the packages by hand (kernels/ and scenes/ are
mapped into pyoa), so a new subpackage missing from the list would work in
an editable install and be absent from a wheel: ``pyoa._drjit`` was, and
``import pyoa.mitsuba`` failed in a regular install."""

from __future__ import annotations

import configparser
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_every_subpackage_of_pyoa_is_in_setup_cfg():
    cfg = configparser.ConfigParser()
    cfg.read(ROOT / "setup.cfg")
    listed = {line.strip() for line in cfg["options"]["packages"].splitlines() if line.strip()}
    found = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "pyoa").rglob("__init__.py")
             if "__pycache__" not in p.parts}
    assert found, "no packages found under pyoa/"
    assert found <= listed, f"packages missing from setup.cfg [options] packages: {sorted(found - listed)}"
    mapped = {line.split("=")[0].strip() for line in cfg["options"]["package_dir"].splitlines() if "=" in line}
    assert listed - found <= mapped, f"setup.cfg lists packages that do not exist: {sorted(listed - found - mapped)}"


def test_the_wheel_ships_every_header_and_get_include_finds_them(tmp_path):
    """issue 50's promise: a regular install (the wheel, not this source
    tree) has every portable header, get_include() names their folder there,
    and a C program built with only that folder on its include path
    compiles. A header missing from setup.cfg's package_data fails here."""
    import os
    import shutil
    import subprocess
    import sys

    import pytest

    if shutil.which("gcc") is None:
        if os.environ.get("PYOA_REQUIRE_C") == "1":
            pytest.fail("gcc not found and PYOA_REQUIRE_C=1")
        pytest.skip("gcc not found")
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", str(ROOT), "-w", str(tmp_path)],
                          capture_output=True, text=True)
    if proc.returncode != 0 and "bdist_wheel" not in proc.stderr and "Could not" in proc.stderr:
        pytest.skip(f"pip could not fetch the build backend: {proc.stderr.strip()[-200:]}")
    assert proc.returncode == 0, proc.stderr
    (wheel,) = tmp_path.glob("pyoa-*.whl")
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(site), str(wheel)],
                   check=True, capture_output=True)
    include = subprocess.run([sys.executable, "-c", "import pyoa; print(pyoa.get_include())"], check=True,
                             capture_output=True, text=True, cwd=tmp_path,
                             env={**os.environ, "PYTHONPATH": str(site)}).stdout.strip()
    assert include.startswith(str(site)), include
    shipped = sorted(p.name for p in (Path(include) / "pyoa").iterdir())
    assert shipped == sorted(p.name for p in (ROOT / "kernels" / "include" / "pyoa").iterdir()), shipped
    src = tmp_path / "use.c"
    src.write_text('#include <pyoa/sampler.h>\nint main(void) { pyoa_options o = pyoa_options_default("bose", 49);'
                   ' pyoa_sampler s; return pyoa_sampler_make(&s, &o, 0, 0) != PYOA_OK; }\n')
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Werror", f"-I{include}", str(src), "-o", str(tmp_path / "use"),
                    "-lm"], check=True)
    assert subprocess.run([str(tmp_path / "use")]).returncode == 0
