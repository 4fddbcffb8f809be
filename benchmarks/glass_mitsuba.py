#!/usr/bin/env python3
"""The glass Cornell box (``cornell-glass``: the large box of smooth glass,
``dielectric``) against Mitsuba 3's: the image's mean per channel, both
renderers, with its standard error over independent renders.

What is measured
----------------
For each scene of ``--scenes`` (default: ``cornell-glass`` and, as a
control whose agreement is known, ``cornell``), ``--seeds`` independent
renders of ``--size`` x ``--size`` pixels at ``--spp`` samples per pixel, max
depth 5, box filter:

- pyoa, sampler ``random`` (independent samples), seeds 0 .. seeds - 1, with
  each ``--shading`` (numba: compiled; numpy: the reference);
- Mitsuba 3 (``llvm_ad_rgb``) on its own ``cornell_box()`` with the
  integrator ``path`` at ``max_depth`` 5 and a box filter (pyoa's settings),
  for ``cornell-glass`` with the large box's BSDF ``{"type": "dielectric"}``
  (Mitsuba's defaults: ``int_ior`` 1.5046, ``ext_ior`` 1.000277, as the
  scene's), sampler ``independent``, seeds 0 .. seeds - 1, in a subprocess
  (a Dr.Jit/LLVM failure must not take the benchmark down;
  ``peers.run_json_script``, which points Dr.Jit at an LLVM >= 16).

Each render's image mean per channel is one sample: reported are their mean,
its standard error (sample standard deviation / sqrt(seeds)) and, for each
pyoa shading, the difference to Mitsuba in units of the combined standard
error ``z = (pyoa - mitsuba) / sqrt(se_pyoa^2 + se_mitsuba^2)``; and the
largest ``|z|`` of the same over the means of a 4 x 4 grid of blocks of the
image per channel (48 values), which sees where the light goes (a box of
water instead of glass differs by up to 24 standard errors there at 32 x 32
pixels, 512 spp, 8 renders each, where the image means differ by 3.5). The surfaces
differ in one way (docs/rendering.md, "Scenes"): pyoa shades them two-sided,
Mitsuba one-sided, which in this box changes the mean by 0.004 % (the top of
the light, seen through a 1 cm gap).

Output: ``benchmarks/results/cornell-glass-mitsuba.json`` and ``.md``
(``--out``), written atomically.

Usage::

    python benchmarks/glass_mitsuba.py                         # 64 x 64, 1024 spp, 8 seeds, both scenes
    python benchmarks/glass_mitsuba.py --size 32 --spp 256 --seeds 4 --scenes cornell-glass --shading numba
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))  # peers.py and common.py, shared with the other benchmarks

import numpy as np  # noqa: E402
import peers  # noqa: E402
from common import log, machine, write_text  # noqa: E402

from pyoa.render.render import render  # noqa: E402
from pyoa.render.scene import load  # noqa: E402

MAX_DEPTH = 5

_MITSUBA = """
import json, sys
import numpy as np
import mitsuba as mi
scene, size, spp, seeds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
mi.set_variant("llvm_ad_rgb")
d = mi.cornell_box()
if scene == "cornell-glass":
    d["large-box"]["bsdf"] = {"type": "dielectric"}
d["integrator"] = {"type": "path", "max_depth": %d}
d["sensor"]["film"]["width"] = d["sensor"]["film"]["height"] = size
d["sensor"]["film"]["rfilter"] = {"type": "box"}
d["sensor"]["sampler"] = {"type": "independent", "sample_count": spp}
sc = mi.load_dict(d)
images = [np.asarray(mi.render(sc, spp=spp, seed=seed), dtype=np.float64)[..., :3].tolist() for seed in range(seeds)]
print(json.dumps({"status": "ok", "version": mi.__version__, "images": images}))
""" % MAX_DEPTH
#: The image is also compared block by block: BLOCKS x BLOCKS block means per channel.
BLOCKS = 4


def summary(images) -> dict:
    """Per channel, the mean and standard error of the image means of
    independent renders ``(seeds, H, W, 3)``, and the same of their
    ``BLOCKS x BLOCKS`` block means."""
    imgs = np.asarray(images, dtype=np.float64)
    n, h, w, _ = imgs.shape
    means = imgs.mean(axis=(1, 2))
    blocks = imgs.reshape(n, BLOCKS, h // BLOCKS, BLOCKS, w // BLOCKS, 3).mean(axis=(2, 4))
    return {"mean": means.mean(axis=0).tolist(), "se": (means.std(axis=0, ddof=1) / math.sqrt(n)).tolist(),
            "renders": means.tolist(), "block_mean": blocks.mean(axis=0).tolist(),
            "block_se": (blocks.std(axis=0, ddof=1) / math.sqrt(n)).tolist()}


def z(a: dict, b: dict, key: str = "") -> np.ndarray:
    """(a - b) / the standard error of the difference, per channel (``key``: ``""`` or ``"block_"``)."""
    return ((np.asarray(a[key + "mean"]) - np.asarray(b[key + "mean"]))
            / np.hypot(np.asarray(a[key + "se"]), np.asarray(b[key + "se"])))


def pyoa_means(scene: str, shading: str, size: int, spp: int, seeds: int) -> dict:
    sc = load(scene)
    t0 = time.perf_counter()
    images = [render(sc, sampler="random", spp=spp, seed=k, width=size, height=size, max_depth=MAX_DEPTH,
                     shading=shading).image[..., :3] for k in range(seeds)]
    return {**summary(images), "seconds": time.perf_counter() - t0}


def mitsuba_means(scene: str, size: int, spp: int, seeds: int) -> dict:
    if not peers.mitsuba_available():
        return {"status": "skipped", "reason": "mitsuba is not installed (pip install mitsuba)"}
    t0 = time.perf_counter()
    res = peers.run_json_script(_MITSUBA, [scene, size, spp, seeds], env=peers.mitsuba_env(),
                                timeout=peers.MITSUBA_TIMEOUT_S)
    if res.get("status") != "ok":
        return res
    return {"status": "ok", "version": res["version"], **summary(res["images"]), "seconds": time.perf_counter() - t0}


def markdown(report: dict) -> str:
    cfg = report["config"]
    return "\n".join(["# The glass Cornell box against Mitsuba 3 (`benchmarks/glass_mitsuba.py`)", "",
                      f"{cfg['size']} x {cfg['size']} pixels, {cfg['spp']} spp, max depth {MAX_DEPTH}, box filter, "
                      f"{cfg['seeds']} independent renders each (pyoa `random`, Mitsuba `independent`); "
                      f"{report['machine'].get('cpu', 'CPU')}, {report['machine']['date_utc']}.", "",
                      table(report)])


def table(report: dict) -> str:
    """The comparison table alone (docs/rendering.md's marked section ``glass-mitsuba``)."""
    lines = ["| scene | renderer | red | green | blue | z (red, green, blue) | blocks: max abs z |",
             "|---|---|---|---|---|---|---:|"]
    for name, rows in report["scenes"].items():
        mit = rows["mitsuba"]
        for who, r in rows.items():
            if r.get("status", "ok") != "ok":
                lines.append(f"| `{name}` | {who} | {r.get('reason', r.get('status'))} | | | | |")
                continue
            cells = [f"{m:.5f} +- {s:.5f}" for m, s in zip(r["mean"], r["se"])]
            zs = zb = ""
            if who != "mitsuba" and mit.get("status", "ok") == "ok":
                zs = ", ".join(f"{v:+.2f}" for v in z(r, mit))
                zb = f"{np.abs(z(r, mit, 'block_')).max():.2f} of {BLOCKS * BLOCKS * 3}"
            label = f"Mitsuba {mit['version']}" if who == "mitsuba" else f"pyoa, {who} shading"
            lines.append(f"| `{name}` | {label} | {' | '.join(cells)} | {zs} | {zb} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenes", default="cornell-glass,cornell")
    p.add_argument("--shading", default="numba,numpy")
    p.add_argument("--size", type=int, default=64)
    p.add_argument("--spp", type=int, default=1024)
    p.add_argument("--seeds", type=int, default=8)
    p.add_argument("--out", default=str(REPO / "benchmarks" / "results" / "cornell-glass-mitsuba"))
    a = p.parse_args(argv)
    if a.seeds < 2:
        p.error("--seeds must be at least 2 (a standard error needs two renders)")
    report = {"machine": machine(), "config": {"size": a.size, "spp": a.spp, "seeds": a.seeds}, "scenes": {}}
    for scene in a.scenes.split(","):
        rows = {}
        log(f"{scene}: Mitsuba")
        rows["mitsuba"] = mitsuba_means(scene, a.size, a.spp, a.seeds)
        for shading in a.shading.split(","):
            log(f"{scene}: pyoa, {shading} shading")
            rows[shading] = pyoa_means(scene, shading, a.size, a.spp, a.seeds)
        report["scenes"][scene] = rows
    text = markdown(report)
    write_text(Path(a.out + ".json"), json.dumps(report, indent=1) + "\n")
    write_text(Path(a.out + ".md"), text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
