"""SHA-256 fingerprints of every catalogue sampler's bits and every bundled scene's image.

A refactor that must change no output (issue 51) runs this before and after
and compares the two files::

    python benchmarks/fingerprints.py --out before.json
    ... change the code ...
    python benchmarks/fingerprints.py --out after.json --compare before.json

Samplers: every catalogue entry's own test cases (``test_cases()``), drawn
through the NumPy backend (every backend gives the same bits, which the
conformance suites prove). Scenes: each bundled scene rendered at 32 x 32,
16 spp (``faure``: base 2 default) with bose and faure, with both shadings.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys

import numpy as np


def sampler_prints() -> dict[str, str]:
    """Per catalogue sampler: SHA-256 over its test cases x seeds x offsets, first and last pixels, samples, dims."""
    import pyoa
    from pyoa import catalogue

    prints = {}
    for name, entry in catalogue.SAMPLERS.items():
        h = hashlib.sha256()
        for case in entry.test_cases():
            case = dict(case)
            spp, dims = case.pop("spp"), case.pop("dims")
            for seed in (0, 2**32 - 1):
                for offset in (None, *pyoa.OFFSETS):
                    try:
                        s = pyoa.sampler(name, spp=spp, dims=dims, seed=seed, offset=offset, backend="numpy", **case)
                    except ValueError:  # an offset this sampler refuses
                        continue
                    n = s.n_pixels if s.resolution else 12346
                    pixels = sorted({*range(min(n, 4)), n - 1})
                    h.update(repr((case, spp, dims, seed, offset)).encode())
                    # first and last samples and dimensions: the largest cases have s**t x 2**20 values per pixel
                    samples = sorted({*range(min(spp, 64)), spp // 2, spp - 1})
                    dim_ids = sorted({*range(min(dims, 16)), dims // 2, dims - 1})
                    h.update(s.generate(pixels, samples, dim_ids).tobytes())
        prints[name] = h.hexdigest()
    return prints


def scene_prints(shadings=("numba", "numpy")) -> dict[str, str]:
    from pyoa.render.render import render
    from pyoa.render.scene import bundled, load

    prints = {}
    for scene_name in sorted(bundled()):
        scene = load(scene_name)
        for sampler, spp in (("bose", 16), ("faure", 16)):
            for shading in shadings:
                r = render(scene, sampler=sampler, spp=spp, seed=3, width=32, height=32,
                           backend="numpy", shading=shading)
                image = np.ascontiguousarray(r.image)
                prints[f"{scene_name}/{sampler}/{shading}"] = hashlib.sha256(image.tobytes()).hexdigest()
    return prints


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True)
    p.add_argument("--compare", help="an earlier output; exit 1 if any fingerprint differs")
    p.add_argument("--skip-scenes", action="store_true")
    a = p.parse_args(argv)
    prints = {"samplers": sampler_prints()}
    if not a.skip_scenes:
        prints["scenes"] = scene_prints()
    with open(a.out, "w") as f:
        json.dump(prints, f, indent=1, sort_keys=True)
    if a.compare:
        with open(a.compare) as f:
            old = json.load(f)
        known = [(part, k) for part in prints for k in prints[part] if k in old.get(part, {})]
        diff = [f"{part}/{k}" for part, k in known if old[part][k] != prints[part][k]]
        new = [f"{part}/{k}" for part in prints for k in prints[part] if k not in old.get(part, {})]
        gone = [f"{part}/{k}" for part in old for k in old[part] if k not in prints.get(part, {})]
        print("differ:" if diff or gone else "all fingerprints equal", *diff, *(f"{g} (gone)" for g in gone))
        if new:
            print("new (no earlier fingerprint):", *new)
        return 1 if diff or gone else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
