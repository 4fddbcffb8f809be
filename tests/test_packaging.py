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
