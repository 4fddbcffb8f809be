#!/usr/bin/env python3
"""Generation speed of two commits, measured in the same run.

``bench_generate.py`` measures one tree; speed drifts 15-40 % between runs
on a shared machine, so "no slower than before" needs both trees timed in
one run. This script checks the older commit out into a temporary git
worktree and runs ``bench_generate.py`` alternately from that tree and from
this one (old, new, old, new, ...: ``--pairs`` pairs, each process timing
the cases with its own kernels and its own ``pyoa`` package), then reports
per case the rate of each run, the per-pair ratios new / old and their
median, and whether every run produced the same bits (``bench_generate``'s
output digest)::

    python benchmarks/compare_commits.py HEAD~1 --cases default,blocks --pairs 5

The results go to ``results/compare-commits.{json,md}`` (``--out``), with
the CPU named. A process of the old tree imports its own ``pyoa`` (the
worktree is put first on ``sys.path``) and its own ``pyoa.kernels`` (the
editable install maps that package to this tree's ``kernels/``, so the
loader binds the worktree's folder in its place).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

#: Runs a script with the pyoa package and kernels of the tree in argv[1].
LOADER = """
import importlib.util, runpy, sys
tree = sys.argv[1]
sys.path.insert(0, tree)
spec = importlib.util.spec_from_file_location("pyoa.kernels", tree + "/kernels/__init__.py")
kernels = importlib.util.module_from_spec(spec)
spec.loader.exec_module(kernels)
import pyoa
sys.modules["pyoa.kernels"] = kernels
pyoa.kernels = kernels
if not pyoa.__file__.startswith(tree):
    raise SystemExit(f"imported pyoa from {pyoa.__file__}, not from {tree}")
sys.argv = sys.argv[2:]
runpy.run_path(sys.argv[0], run_name="__main__")
"""


def bench(tree: Path, args, out: Path) -> dict:
    cmd = [sys.executable, "-c", LOADER, str(tree), str(tree / "benchmarks" / "bench_generate.py"),
           "--backends", "opencl", "--cases", args.cases, "--no-peers", "--no-ceiling",
           "--repeats", str(args.repeats), "--out", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"bench_generate failed in {tree}:\n{proc.stderr[-2000:]}")
    return json.loads(out.read_text())


def rates(result: dict) -> dict[str, tuple[float, str]]:
    return {r["case"]: (r["median_values_per_s"] / 1e6, r["digest"]) for r in result["results"]
            if r.get("backend") == "opencl" and r.get("status") == "ok"}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("old", help="the older commit (any git revision)")
    ap.add_argument("--cases", default="default,blocks", help="bench_generate's --cases (default: default,blocks)")
    ap.add_argument("--pairs", type=int, default=5, help="old/new pairs of runs (default: 5)")
    ap.add_argument("--repeats", type=int, default=5, help="bench_generate's --repeats (default: 5)")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "compare-commits.json",
                    help="JSON result; the Markdown table goes beside it (default: results/compare-commits.json)")
    args = ap.parse_args(argv)
    if args.pairs < 1 or args.repeats < 1:
        ap.error("--pairs and --repeats must be >= 1")
    old_rev = subprocess.run(["git", "rev-parse", "--short", args.old], cwd=ROOT, capture_output=True, text=True)
    if old_rev.returncode != 0:
        ap.error(f"not a git revision: {args.old!r} ({old_rev.stderr.strip()})")
    new_rev = subprocess.run(["git", "describe", "--always", "--dirty"], cwd=ROOT, capture_output=True,
                             text=True).stdout.strip()
    runs: dict[str, list[dict]] = {"old": [], "new": []}
    with tempfile.TemporaryDirectory(prefix="pyoa-old-") as tmp:
        tree = Path(tmp) / "tree"
        subprocess.run(["git", "worktree", "add", "--detach", "-q", str(tree), args.old], cwd=ROOT, check=True)
        try:
            for k in range(args.pairs):
                for tag, src in (("old", tree), ("new", ROOT)):
                    res = bench(src, args, Path(tmp) / f"{tag}-{k}.json")
                    runs[tag].append(res)
                    print(f"pair {k + 1}/{args.pairs} {tag}: " + ", ".join(
                        f"{c} {v:.0f}" for c, (v, _) in rates(res).items()) + " M values/s", flush=True)
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(tree)], cwd=ROOT)
    cases = list(rates(runs["new"][0]))
    summary = []
    for case in cases:
        old = [rates(r)[case] for r in runs["old"]]
        new = [rates(r)[case] for r in runs["new"]]
        ratios = [n[0] / o[0] for o, n in zip(old, new)]
        summary.append({"case": case, "old_mvalues_per_s": [o[0] for o in old],
                        "new_mvalues_per_s": [n[0] for n in new], "ratios": ratios,
                        "median_ratio": statistics.median(ratios),
                        "same_bits": len({d for _, d in old + new}) == 1})
    machine = runs["new"][0]["machine"]
    out = {"old": old_rev.stdout.strip(), "new": new_rev, "cases": args.cases, "pairs": args.pairs,
           "repeats": args.repeats, "cpu": machine.get("cpu"), "date_utc": machine.get("date_utc"),
           "summary": summary}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(out, indent=2) + "\n")
    lines = [f"# Generation speed, {out['new']} against {out['old']} in one run", "",
             f"{out['cpu']}; {out['date_utc']}; `bench_generate.py --backends opencl --cases {args.cases} "
             f"--repeats {args.repeats}`, run alternately from each tree ({args.pairs} pairs). M values/s "
             "(median of each run); ratio = new / old of each pair.", "",
             "| case | old | new | per-pair new / old | median | same bits |", "|---|---|---|---|---:|---|"]
    for s in summary:
        lines.append(f"| `{s['case']}` | {', '.join(f'{v:.0f}' for v in s['old_mvalues_per_s'])} | "
                     f"{', '.join(f'{v:.0f}' for v in s['new_mvalues_per_s'])} | "
                     f"{', '.join(f'{r:.2f}' for r in s['ratios'])} | **{s['median_ratio']:.2f}** | "
                     f"{'yes' if s['same_bits'] else 'NO'} |")
    args.out.with_suffix(".md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    print(f"wrote {args.out} and {args.out.with_suffix('.md')}")
    return 0 if all(s["same_bits"] for s in summary) else 1


if __name__ == "__main__":
    sys.exit(main())
