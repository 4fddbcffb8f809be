#!/usr/bin/env python3
"""Probe: what tracing shadow rays straight from the shading's scratch would save.

The compiled renderer (``pyoa.render.compiled.integrator.render_paths``)
shades a bounce :data:`~pyoa.render.compiled.shading.CHUNK` lanes at a time;
each chunk's shadow rays are copied out of the scratch into the wavefront
(``shading.emit_shadows``: 11 values a ray), all the wavefront's shadow rays
are traced at once (``embree.occluded``, which loads its packets from those
copies), and ``add_visible`` adds what the unblocked ones carry. The
redesign that docs/performance.md weighs for issue 32 ("persistent
structure-of-arrays wavefronts") would trace each chunk's shadow rays from
the scratch rows themselves and add their contributions from there, with no
copy. This probe measures that one piece before anyone builds it: the
compiled driver of ``benchmarks/probe_shading_stages.py`` runs the
renderer's own steps with the shadow rays either as shipped or traced from
the scratch (its ``shadows_from_rows``), alternated in one process, one
thread, 64 x 64, Bose 121 spp. It checks that both give the renderer's image
bit for bit (each path adds its light in the same order) and prints ns per
camera path of each, min and median over the rounds.

Usage: python benchmarks/probe_shadow_rows.py [SCENE:R|F ...] [--rounds N]
(default: cornell:R dof7d:F bounce9d:F, 7 rounds)
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402
from probe_shading_stages import STEPS, check_image, drive, inputs  # noqa: E402


def probe(name: str, robust: bool, rounds: int) -> str:
    want, smp, pixel, sample, x, rr_key = inputs(name, robust)
    integ = want.integrator[0]
    radiance = np.zeros((len(pixel), 3))  # one array, zeroed in place (probe_shading_stages.py says why)
    args = (integ._tracer, integ._scene, integ._camera, integ._settings, pixel, sample, x, np.zeros((0, 2)))
    times = {False: [], True: []}
    for r in range(rounds + 1):
        for rows in ((False, True) if r % 2 == 0 else (True, False)):
            radiance.fill(0.0)
            t0 = time.perf_counter()
            drive(*args, radiance, np.zeros(len(STEPS)), integ._clock, rr_key, integ.wavefront, rows)
            if r:  # round 0 compiles and warms
                times[rows].append(time.perf_counter() - t0)
            check_image(radiance, smp, want, "shadow rays from the scratch" if rows else "as shipped")
    paths = len(pixel)
    ns = {k: np.array(v) / paths * 1e9 for k, v in times.items()}
    gain = np.median(ns[False]) - np.median(ns[True])
    return (f"{name} {'robust' if robust else 'fast'}: shipped {ns[False].min():.1f}-{np.median(ns[False]):.1f}, "
            f"from the scratch {ns[True].min():.1f}-{np.median(ns[True]):.1f} ns per path (min-median of {rounds} "
            f"alternated rounds; the same image): {gain:.1f} ns a path less, "
            f"{gain / np.median(ns[False]):.1%} of the path")


def main(argv: list[str]) -> int:
    from pyoa.util.hostcpu import host_cpu

    rounds = 7
    if "--rounds" in argv:
        i = argv.index("--rounds")
        rounds = int(argv[i + 1])
        argv = argv[:i] + argv[i + 2:]
    specs = argv or ["cornell:R", "dof7d:F", "bounce9d:F"]
    print(f"CPU: {host_cpu().describe()}")
    for spec in specs:
        name, _, mode = spec.partition(":")
        print(probe(name, mode.upper() != "F", rounds), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
