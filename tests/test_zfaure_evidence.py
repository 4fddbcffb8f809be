"""benchmarks/zfaure_evidence.py: its quick mode writes the results the docs section is made from.

The figures' values are the benchmark's to measure; what is checked here is that the quick run writes
every file with the structure :func:`zfaure_evidence.section_text` and ``update_docs`` read, and that the
per-seed spectrum (bootstrapped over seeds) is :func:`pyoa.analysis.error_spectrum`'s arithmetic.
"""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parent.parent / "benchmarks"
sys.path.insert(0, str(BENCH))

import zfaure_evidence as ze  # noqa: E402

from pyoa.analysis import error_spectrum  # noqa: E402


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("zfaure-evidence")
    assert ze.main(["--quick", "--out", str(out), "--backend", "numpy"]) == 0
    return out, json.loads((out / "zfaure-evidence.json").read_text())


def test_spectrum_is_error_spectrums_measure():
    """low and RMSE from the per-seed error images equal error_spectrum's on the same seeds."""
    errs, _ = ze.measure("zfaure", 25, None, 4, 3, 16, "numpy", [("gaussian", 4)])
    mine = ze.spectrum(errs[("gaussian", 4)], np.random.default_rng(0))
    ref = error_spectrum("zfaure", spp=25, size=16, seeds=3, integrand="gaussian", dims=4, backend="numpy")
    assert mine["low"] == pytest.approx(ref.low, rel=1e-12)
    assert mine["rmse"] == pytest.approx(ref.rmse, rel=1e-12)
    assert mine["radial"] == pytest.approx(ref.radial.tolist(), abs=1e-4)
    assert mine["low_se"] > 0 and mine["rmse_se"] > 0


def test_quick_writes_every_file(quick):
    out, _ = quick
    for name in ("zfaure-evidence.json", "zfaure-evidence.md", "errors.png", "spectra.png"):
        assert (out / name).stat().st_size > 0, name
    for png in ("errors.png", "spectra.png"):
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_quick_json_structure(quick):
    _, rep = quick
    assert rep["machine"]["cpu_model"] and rep["settings"]["size"] == 16 and rep["runs"]
    assert rep["zfaure_counts"] == [25, 49]
    # every integrand at 49 (7D too), the 2D and 4D ones at 25, each against faure at the same count and base
    got = {(r["integrand"], r["count"]) for r in rep["comparisons"]}
    want = {(f"{f}-{d}d", n) for f, d in ze.INTEGRANDS for n in (25, 49) if d < 7 or n in ze.SEVEN_D_COUNTS}
    assert got == want
    for r in rep["comparisons"]:
        assert r["base"] == {25: 5, 49: 7}[r["count"]] and r["one_block"] == (r["base"] >= r["dims"])
        for s in ("zfaure", "faure", *ze.OTHERS):
            assert {"seeds", "low", "low_se", "rmse", "rmse_se"} <= set(r[s]), (r["integrand"], s)
        assert r["rmse_ratio"] == pytest.approx(r["zfaure"]["rmse"] / r["faure"]["rmse"])
        assert r["rmse_ratio_se"] > 0
    renders = rep["renders"]
    assert [(r["scene"], r["sampler"]) for r in renders] == [("dof7d", s) for s in ze.RENDER_SAMPLERS]
    for r in renders:
        assert r["seeds"] == 2 and len(r["radii"]) == len(r["radial"])
        for key in ("relmse", "mse", *(f"blur{s}_{m}" for s in ze.SIGMAS for m in ("mse", "relmse"))):
            assert r[key] > 0 and r[f"{key}_se"] is not None, key
        # a blur averages the error away: less of it remains (the measure, not a claim about zfaure)
        assert r["blur2_mse"] < r["blur1_mse"] < r["mse"]


def test_quick_markdown_has_every_table(quick):
    out, rep = quick
    md = (out / "zfaure-evidence.md").read_text()
    for f, d in ze.INTEGRANDS:
        assert f"`{f}-{d}d`:" in md
    assert "| dof7d | zfaure (b 7) | 49 |" in md
    assert "errors.png" in md and "spectra.png" in md
    assert md == ze.section_text(rep, str(out)) + "\n"
