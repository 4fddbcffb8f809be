#!/usr/bin/env python3
"""Speed-up of renders and studies on a local Dask cluster (``pyoa.cluster``).

Measures, in one process, interleaved over ``--rounds`` rounds:

* ``render``: one render of ``--scene`` (default ``dof7d``, 128 x 128,
  ``bose`` 256 spp) in-process (the renderer's threads on every core), and
  on local clusters of 1 and 2 worker processes (tiles of whole pixels; each
  task's threads share the host's cores). The clusters are started once,
  before the rounds, and warmed with one render (scene load, integrator
  setup and numba compilation happen once per worker process); their start
  is timed separately.
* ``study``: a small ``pyoa study`` task list (``--scene``, random and bose,
  spp 16 and 64, 4 seeds, 64 x 64) run through the same engines, the tasks
  (whole renders) being the unit of parallelism instead of tiles.

Every image is checked bit-identical to the in-process one. Results go to
``benchmarks/results/cluster.json`` and ``.md`` and into
``docs/distributed.md``'s marked section ``cluster-speedup``
(``benchmarks/marked.py``), made from ``cluster.json`` by :func:`section`. This machine's speed drifts 15-40 %
between processes, so only ratios measured in the same run are quoted.

Usage::

    python benchmarks/bench_cluster.py [--rounds 5] [--scene dof7d]
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from contextlib import ExitStack
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import marked  # noqa: E402
from common import REPO, machine, write_text  # noqa: E402

from pyoa import cluster  # noqa: E402
from pyoa.render.scene import load  # noqa: E402
from pyoa.render.scene_source import source_of  # noqa: E402
from pyoa.render.settings import RenderSettings  # noqa: E402
from pyoa.render.tiles import render_on  # noqa: E402
from pyoa.study import Job, study_task  # noqa: E402

OUT = REPO / "benchmarks" / "results"
DOC = REPO / "docs" / "distributed.md"
SECTION = "cluster-speedup"


def section(result: dict) -> str:
    """The section of docs/distributed.md, from ``cluster.json``'s contents."""
    meta, times, stimes = result["machine"], result["render_seconds"], result["study_seconds"]
    med = {k: statistics.median(v) for k, v in times.items()}
    smed = {k: statistics.median(v) for k, v in stimes.items()}
    paths = result["size"] * result["size"] * result["spp"]
    lines = [f"Measured by `python benchmarks/bench_cluster.py` on {meta['cpu']}, {meta['cpu_count']} cores, "
             f"{result['rounds']} interleaved rounds in one process, medians (`benchmarks/results/cluster.json`). "
             "Every cluster image and study row was checked bit-identical to the in-process one.", "",
             f"| engine | render: `{result['scene']}` {result['size']} x {result['size']}, bose {result['spp']} spp | "
             f"paths/s | speed-up | study: {result['study_renders']} renders of 64 x 64 | speed-up |",
             "|---|---:|---:|---:|---:|---:|"]
    for k in times:
        lines.append(f"| {k} | {med[k]:.2f} s | {paths / med[k] / 1e6:.2f} M | "
                     f"{med['1 worker'] / med[k]:.2f}x | {smed[k]:.2f} s | {smed['1 worker'] / smed[k]:.2f}x |")
    lines += ["", "Speed-up is against 1 worker. Starting a local cluster took "
              + ", ".join(f"{v:.1f} s ({k})" for k, v in result["cluster_start_seconds"].items())
              + "; the first render on it pays each worker's scene load, integrator setup and numba compilation "
                "(not in the table)."]
    return "\n".join(lines) + "\n"


def study_jobs(scene: str) -> list[Job]:
    return [Job(scene, s, n, n, k) for s in ("random", "bose") for n in (16, 64) for k in range(4)]


def run_study(eng, scene, reference, jobs) -> tuple[float, list]:
    from contextlib import closing

    src = eng.share(scene if eng.client is None else source_of(scene))
    ref = eng.share(reference)
    kw = RenderSettings(width=64, height=64, shading="numba")
    t0 = time.perf_counter()
    with closing(eng.run(study_task, [(src, ref, (16, 16, 16, 16), kw, j, eng.task_threads()) for j in jobs])) as r:
        rows = sorted((jobs[i].ident, row["relmse"]) for i, row in r)
    return time.perf_counter() - t0, rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--scene", default="dof7d")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=256)
    args = ap.parse_args(argv)
    scene = load(args.scene)
    kw = dict(sampler="bose", spp=args.spp, seed=1, width=args.size, height=args.size)
    reference = np.full((64, 64, 3), 0.5)
    jobs = study_jobs(args.scene)
    times = {"in-process": [], "1 worker": [], "2 workers": []}
    stimes = {k: [] for k in times}
    starts = {}
    with ExitStack() as stack:
        engines = {"in-process": stack.enter_context(cluster.engine())}
        for n, label in ((1, "1 worker"), (2, "2 workers")):
            t0 = time.perf_counter()
            engines[label] = stack.enter_context(cluster.engine(workers=n))
            starts[label] = time.perf_counter() - t0
        want = None
        for label, eng in engines.items():  # warm-up: scene, integrator, compilation per worker
            img = render_on(eng, scene, **kw).image
            want = img if want is None else want
            assert np.array_equal(img.view(np.uint32), want.view(np.uint32)), label
            run_study(eng, scene, reference, jobs)
        want_rows = None
        for r in range(args.rounds):
            order = list(engines) if r % 2 == 0 else list(reversed(engines))
            for label in order:
                eng = engines[label]
                t0 = time.perf_counter()
                img = render_on(eng, scene, **kw).image
                times[label].append(time.perf_counter() - t0)
                assert np.array_equal(img.view(np.uint32), want.view(np.uint32)), label
                dt, rows = run_study(eng, scene, reference, jobs)
                stimes[label].append(dt)
                want_rows = rows if want_rows is None else want_rows
                assert rows == want_rows, label
            print(f"round {r + 1}: " + ", ".join(f"{k} {v[-1]:.2f} s / {stimes[k][-1]:.2f} s"
                                                  for k, v in times.items()), flush=True)
    meta = machine()
    result = {"machine": meta, "scene": args.scene, "size": args.size, "spp": args.spp, "rounds": args.rounds,
              "render_seconds": times, "study_seconds": stimes, "cluster_start_seconds": starts,
              "study_renders": len(jobs)}
    OUT.mkdir(parents=True, exist_ok=True)
    write_text(OUT / "cluster.json", json.dumps(result, indent=1) + "\n")
    text = section(result)
    write_text(OUT / "cluster.md", text)
    marked.write(DOC, {SECTION: marked.block_body(text)})
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
