#!/usr/bin/env python3
"""The compute ceiling of the OpenCL vector path: the rate the cores allow.

``bench_generate.py`` divides every rate by NumPy's ``ndarray.fill`` into
the same array, the rate at which the machine writes float32 values at all.
That ceiling differs 5x between CPUs, and a rate far below it does not say
whether the kernels are compute-bound. This script states the other bound:
how many values per second the cores could compute, from the machine code
PoCL emits for the kernel that computes the values.

What is measured
----------------
For one case (sampler name, spp, dims, offset; the default is the required
workload ``bose``, 121 spp, 10 dims, ``cmj``):

1. One ``Sampler.generate(pixels=range(P))`` (``--pixels``, 4,096 by
   default: the kernel's code depends on the request's shape, not on P) runs
   in a subprocess with ``POCL_CACHE_DIR`` set to a fresh temporary
   directory and ``PYOA_OPENCL_PATH=vector``, so that directory holds
   exactly the kernels PoCL compiled for that run
   (``<cache>/XX/<hash>/<kernel>/<local size...>/<kernel>.so``). Of the
   ``vector_values`` objects (kernels/vector.cl; one per local size the
   launches used) the one with the largest work-group is taken: the bulk of
   the launches.
2. The object is disassembled (``llvm-objdump-15``, else ``objdump``; both
   in AT&T syntax) and PoCL's work-group function is taken
   (``_pocl_kernel_vector_values_workgroup``, the launcher with the kernel
   and PoCL's work-item loops inlined; the object's two other functions,
   the kernel itself and ``..._workgroup_fast``, hold the same loop, give
   or take an instruction). Its basic blocks, control-flow graph and
   dominators give the natural loops (a branch to a block that dominates
   it closes a loop; backward jumps by address alone would also count the
   out-of-line ``if`` bodies that jump back into the loop, and miss the
   rotated loop's latch, which jumps forward to its header). PoCL wraps
   the kernel in one loop per local dimension larger than 1, the last
   dimension outermost, so the *work-item loop*, the one over local
   dimension 0, is the loop at that nesting depth (2 for ``16-4-1``); it
   must hold at least half of the function's SIMD instructions. A loop
   nested in it is the kernel's own: the groups of 8 dimensions above 16
   dimensions (VGROUPED in kernels/vector.cl), ``dims // 8`` times per
   work-item.
3. One iteration of the work-item loop is one work-item: 8 sample positions
   x ``dims`` dimensions of one pixel, ``8 * dims`` values (the last block
   of a pixel when spp is not a multiple of 8 computes 8 positions but
   stores fewer: ignored, see Caveats). Its path is the longest path
   through the loop's body from the header to the back edge (a conditional
   branch inside the body is an ``if``: the seed-is-zero test of each
   dimension's jitter and the tail block's store are the short sides, taken
   with probability 2^-32 and 1 / (spp / 8)), with a nested loop's path
   repeated its trip count. On that path are counted: instructions, SIMD
   (xmm/ymm/zmm/mask registers) vs general-purpose ones, loads and stores
   (and those addressed from ``%rsp``/``%rbp``: spills and private arrays),
   gathers and divisions (``vdivps``: the correctly rounded float divisions
   of docs/spec.md section 7, four per dimension, one per 5 cycles in
   LLVM's Skylake-server model: the block-throughput bound of 10 and 12
   dimensions; llvm-mca's simulation, which also waits for operands, and
   the probes of docs/performance.md, "What bounds generation", say the
   dependency chains bind first).
4. ``llvm-mca-15 -mcpu=<cpu>`` runs on the path (branches kept, aimed at
   the path's start) for the host CPU's model in LLVM 15's naming
   (``host_mcpu``: e.g. Intel family 6 model 207, Emerald Rapids, is
   ``sapphirerapids``; AMD family 25 and 26 are ``znver3``, LLVM 15 having
   no ``znver4``), or PoCL's target CPU when the model is not in the map.
   Its "Block RThroughput" is the cycles one iteration needs when only the
   execution ports bound it (no dependency chains, every load an L1 hit,
   no front-end limit): the cycles per work-item. "Total Cycles" /
   iterations, llvm-mca's simulation with the dependencies, is reported
   beside it.
5. The compute ceiling is ``cores x clock x 8 x dims / cycles per
   iteration``: the values per second if every core ran only this loop at
   llvm-mca's throughput (also given with the simulated cycles). ``cores`` is the CPUs this process may run on
   (``os.sched_getaffinity``; PoCL's pthread driver starts one thread per
   CPU), ``clock`` the ``cpu MHz`` of ``/proc/cpuinfo``: the nominal clock
   the VM reports, not a measured one (this VM exposes no hardware
   counters, so neither the real clock nor the IPC can be measured; a
   turbo clock above it would raise the ceiling in proportion). A second,
   cruder ceiling counts instructions only: 4 instructions per cycle.

The ceiling is a bound on the kernel alone: generate also runs the tables
kernel (one work-item per 8 (pixel, dimension) pairs), the host's chunking
and launches, and waits for the memory system, none of which is in it. A
measured rate close to the compute ceiling and far from ``fill`` means the
cores' arithmetic bounds it; close to ``fill``, memory bounds it.

Caveats
-------
- The clock is nominal; the cores may run faster (turbo) or slower
  (shared host), and nothing here can tell.
- LLVM 15 has no scheduling model of its own for ``sapphirerapids``: it
  uses Skylake-server's (the resource names in the output say which,
  ``SKX...``), older than the Golden Cove / Raptor Cove cores of Sapphire
  and Emerald Rapids (wider, with a larger window). The Block RThroughput
  assumes ideal port assignment, L1 hits and no front-end limit: a lower
  bound on cycles, so the ceiling is an upper bound; the simulated cycles
  add the dependency chains in Skylake-server's scheduler window.
- Padding: for spp not a multiple of 8 the last work-item of a pixel
  computes 8 positions and stores spp % 8; in values the caller gets,
  every ceiling is ``spp / (8 ceil(spp / 8))`` of the one stated (0.945
  at 121 spp; reported as ``padding``).
- A path through the loop is static: the ``if`` sides chosen are the long
  ones, which is the common case for this kernel (see 3) but not a
  measurement.

Output
------
The CLI prints a short Markdown section (``--json`` for the dictionary).
``ceiling(...)`` returns the dictionary (``bench_generate.py`` imports it);
it never raises: a step that fails gives ``status`` ``"not measured"`` and
a ``reason``.

Usage::

    python benchmarks/compute_ceiling.py                     # bose 121 spp x 10 dims, cmj
    python benchmarks/compute_ceiling.py --dims 36           # blocks 0-2
    python benchmarks/compute_ceiling.py --mcpu skylake-avx512 --show-loop
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
KERNEL = "vector_values"
#: Values per work-item and dimension: the 8 lanes of kernels/vector.cl.
LANES = 8
#: Up to this many dimensions the kernel holds one vector per dimension
#: (pyoa._opencl.vector.MAX_WHOLE_ROWS); more are computed in a loop over
#: groups of 8 (VGROUPED), the one loop of the kernel itself.
MAX_WHOLE_ROWS = 16
#: The instruction-count ceiling's instructions per cycle.
IPC_BOUND = 4
DEFAULT_PIXELS = 4096
CHILD_TIMEOUT_S = 300

#: (vendor, family) -> [(first model, last model, LLVM 15 -mcpu)]; None: every model.
_MCPU = {
    ("GenuineIntel", 6): [
        (63, 63, "haswell"), (69, 70, "haswell"), (60, 60, "haswell"), (61, 61, "broadwell"),
        (71, 71, "broadwell"), (79, 79, "broadwell"), (86, 86, "broadwell"),
        (78, 78, "skylake"), (94, 94, "skylake"), (142, 142, "skylake"), (158, 158, "skylake"),
        (165, 166, "skylake"), (85, 85, "skylake-avx512"), (102, 102, "cannonlake"),
        (125, 126, "icelake-client"), (106, 106, "icelake-server"), (108, 108, "icelake-server"),
        (140, 141, "tigerlake"), (167, 167, "rocketlake"),
        (151, 151, "alderlake"), (154, 154, "alderlake"), (183, 183, "alderlake"), (186, 186, "alderlake"),
        (191, 191, "alderlake"),
        # Sapphire Rapids (143), Emerald Rapids (207), Granite Rapids (173, 174): LLVM 15's newest server core
        (143, 143, "sapphirerapids"), (207, 207, "sapphirerapids"), (173, 174, "sapphirerapids"),
    ],
    ("AuthenticAMD", 23): [(0, 47, "znver1"), (48, 255, "znver2")],
    ("AuthenticAMD", 25): [(0, 255, "znver3")],  # Zen 3 and Zen 4: LLVM 15 has no znver4
    ("AuthenticAMD", 26): [(0, 255, "znver3")],  # Zen 5: nearest model LLVM 15 knows
}


# ---------------------------------------------------------------------------
# the machine


def _cpuinfo() -> dict:
    fields: dict[str, str] = {}
    try:
        text = Path("/proc/cpuinfo").read_text(errors="replace")
    except OSError:
        return fields
    for line in text.splitlines():
        if not line.strip():
            if fields:
                break
            continue
        key, _, value = line.partition(":")
        fields.setdefault(key.strip().lower(), value.strip())
    return fields


def host_cpu() -> dict:
    """Vendor, family, model, name and the nominal clock (``cpu MHz``) of the first CPU."""
    f = _cpuinfo()

    def num(key, cast=int):
        try:
            return cast(f[key])
        except (KeyError, ValueError):
            return None

    return {"vendor": f.get("vendor_id", ""), "family": num("cpu family"), "model": num("model"),
            "name": f.get("model name", "unknown CPU"), "mhz": num("cpu mhz", float)}


def usable_cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _tool(*names: str) -> str | None:
    return next((shutil.which(n) for n in names if shutil.which(n)), None)


def _known_mcpus(mca: str) -> set[str]:
    try:
        res = subprocess.run([mca, "-mcpu=help"], capture_output=True, text=True, timeout=30,
                             stdin=subprocess.DEVNULL)
    except (OSError, subprocess.SubprocessError):
        return set()
    return {m.group(1) for m in re.finditer(r"^\s+(\S+)\s+- Select the", res.stdout + res.stderr, re.M)}


def host_mcpu(cpu: dict, pocl_target: str | None, known: set[str]) -> tuple[str | None, str]:
    """The llvm-mca ``-mcpu`` for the host CPU and why that one."""
    for lo, hi, name in _MCPU.get((cpu["vendor"], cpu["family"]), []):
        if cpu["model"] is not None and lo <= cpu["model"] <= hi and (not known or name in known):
            return name, f"{cpu['vendor']} family {cpu['family']} model {cpu['model']}"
    if pocl_target and (not known or pocl_target in known):
        return pocl_target, "PoCL's target CPU (host model not in the map)"
    return None, f"no LLVM 15 CPU model for {cpu['vendor']} family {cpu['family']} model {cpu['model']}"


def pocl_target(device: str, known: set[str]) -> str | None:
    """PoCL's target CPU from its device name (``pthread-skylake-avx512-Intel(R) ...``)."""
    rest = device.split("pthread-", 1)[1] if "pthread-" in device else device
    hits = [k for k in known if rest.startswith(k + "-")]
    return max(hits, key=len) if hits else None


# ---------------------------------------------------------------------------
# the kernel object

_CHILD = r"""
import json, sys
import pyoa
from pyoa.samplers import trial_options
a = json.loads(sys.argv[1])
smp = pyoa.sampler(a["name"], spp=a["spp"], dims=a["dims"], seed=a["seed"],
                   **trial_options(a["name"], dict(offset=a["offset"], strength=a["strength"], backend="opencl")))
smp.generate(pixels=range(a["pixels"]))
print(json.dumps({"device": smp.device}))
"""


def build_kernels(case: dict, cache: Path, pixels: int, timeout: float = CHILD_TIMEOUT_S) -> str:
    """Run one generate of ``case`` in a subprocess with PoCL's cache in ``cache``; the device name."""
    env = dict(os.environ, POCL_CACHE_DIR=str(cache), PYOA_OPENCL_PATH="vector")
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO), env.get("PYTHONPATH")) if p)
    args = json.dumps({**case, "pixels": pixels})
    res = subprocess.run([sys.executable, "-c", _CHILD, args], capture_output=True, text=True, env=env,
                         timeout=timeout, stdin=subprocess.DEVNULL)
    if res.returncode != 0:
        tail = (res.stderr.strip().splitlines() or ["(no stderr)"])[-1]
        raise RuntimeError(f"generate failed (exit {res.returncode}): {tail}")
    return json.loads(res.stdout.strip().splitlines()[-1])["device"]


def _local_size(path: Path) -> int:
    """Work-items of the local size directory ``16-4-1-goffs0-smallgrid``."""
    nums = [int(t) for t in path.parent.name.split("-")[:3] if t.isdigit()]
    size = 1
    for n in nums:
        size *= n
    return size


def find_object(cache: Path, kernel: str = KERNEL) -> tuple[Path, list[str]]:
    """The kernel's .so with the largest local size, and every local size found."""
    found = sorted(cache.glob(f"**/{kernel}/*/{kernel}.so"))
    if not found:
        raise RuntimeError(f"no {kernel}.so in PoCL's cache: the vector path did not run")
    best = max(found, key=_local_size)
    return best, [p.parent.name for p in found]


# ---------------------------------------------------------------------------
# disassembly and loops


@dataclass
class Insn:
    addr: int
    mnemonic: str
    operands: str
    text: str  # mnemonic and operands as the disassembler wrote them, no comment
    target: int | None = None  # a direct jump's target

    @property
    def is_jump(self) -> bool:
        return self.mnemonic.startswith("j")

    @property
    def is_cond(self) -> bool:
        return self.is_jump and not self.mnemonic.startswith("jmp")

    @property
    def ends_flow(self) -> bool:
        return self.mnemonic.startswith(("ret", "ud2")) or (self.mnemonic.startswith("jmp") and self.target is None)


_LINE = re.compile(r"^\s*([0-9a-f]+):\s+(.*)$")
_SYMBOL = re.compile(r"^([0-9a-f]+) <(.+)>:$")
_TARGET = re.compile(r"^(?:0x)?([0-9a-f]+)(?:\s+<.*>)?$")


def disassemble(so: Path) -> tuple[dict[str, list[Insn]], str]:
    """Function name -> instructions (AT&T syntax), and the tool used."""
    tool = _tool("llvm-objdump-15", "llvm-objdump", "objdump")
    if tool is None:
        raise RuntimeError("no disassembler (llvm-objdump-15 or objdump) on PATH")
    res = subprocess.run([tool, "-d", "--no-show-raw-insn", str(so)], capture_output=True, text=True, timeout=60,
                         stdin=subprocess.DEVNULL)
    if res.returncode != 0:
        raise RuntimeError(f"{Path(tool).name} failed: {res.stderr.strip()[:200]}")
    funcs: dict[str, list[Insn]] = {}
    cur: list[Insn] | None = None
    for line in res.stdout.splitlines():
        m = _SYMBOL.match(line.strip())
        if m:
            cur = funcs.setdefault(m.group(2), [])
            continue
        m = _LINE.match(line)
        if not m or cur is None:
            continue
        text = m.group(2).split("#", 1)[0].strip()
        text = re.sub(r"\s+", " ", text)
        if not text or text.startswith("(bad)"):
            continue
        mnem, _, ops = text.partition(" ")
        if mnem in ("cs", "ds", "rep", "repz", "repnz", "lock", "notrack", "data16") and ops:
            pre = mnem
            mnem, _, ops = ops.partition(" ")
            mnem = mnem if pre in ("cs", "ds", "data16") else f"{pre} {mnem}"
        insn = Insn(int(m.group(1), 16), mnem, ops.strip(), text)
        if insn.is_jump:
            t = _TARGET.match(insn.operands.strip())
            insn.target = int(t.group(1), 16) if t and not insn.operands.startswith("*") else None
        cur.append(insn)
    return funcs, Path(tool).name


@dataclass
class Block:
    start: int
    insns: list[Insn]
    succs: list[int] = field(default_factory=list)


def blocks(insns: list[Insn]) -> dict[int, Block]:
    """The basic blocks of one function, keyed by start address, with their successors."""
    addrs = {i.addr for i in insns}
    leaders = {insns[0].addr}
    for k, i in enumerate(insns):
        if i.is_jump or i.ends_flow:
            if i.target in addrs:
                leaders.add(i.target)
            if k + 1 < len(insns):
                leaders.add(insns[k + 1].addr)
    out: dict[int, Block] = {}
    cur: Block | None = None
    for i in insns:
        if i.addr in leaders:
            cur = out[i.addr] = Block(i.addr, [])
        cur.insns.append(i)
    starts = sorted(out)
    for n, s in enumerate(starts):
        last = out[s].insns[-1]
        nxt = starts[n + 1] if n + 1 < len(starts) else None
        if last.is_jump and last.target in out:
            out[s].succs.append(last.target)
        if not last.ends_flow and not (last.is_jump and not last.is_cond) and nxt is not None:
            out[s].succs.append(nxt)
    return out


def post_order(start: int, succs) -> list[int]:
    """The nodes reachable from ``start`` in depth-first post-order (successors before their
    predecessors, back edges aside), iteratively: ``succs(n)`` lists the successors of ``n``."""
    order, seen, stack = [], {start}, [(start, iter(succs(start)))]
    while stack:
        node, it = stack[-1]
        nxt = next((s for s in it if s not in seen), None)
        if nxt is None:
            order.append(node)
            stack.pop()
        else:
            seen.add(nxt)
            stack.append((nxt, iter(succs(nxt))))
    return order


def dominators(bl: dict[int, Block], entry: int) -> dict[int, set[int]]:
    """Each reachable block's dominators (iterative data flow; a few hundred blocks)."""
    rpo = post_order(entry, lambda b: bl[b].succs)[::-1]
    preds: dict[int, list[int]] = {b: [] for b in rpo}
    for b in rpo:
        for s in bl[b].succs:
            if s in preds:
                preds[s].append(b)
    dom = {b: set(rpo) for b in rpo}
    dom[entry] = {entry}
    changed = True
    while changed:
        changed = False
        for b in rpo[1:]:
            ps = [dom[p] for p in preds[b]]
            new = set.intersection(*ps) | {b} if ps else {b}
            if new != dom[b]:
                dom[b], changed = new, True
    return dom


@dataclass
class Loop:
    header: int
    body: set[int]
    latches: list[int]
    children: list["Loop"] = field(default_factory=list)
    parent: "Loop | None" = None


def natural_loops(bl: dict[int, Block], dom: dict[int, set[int]]) -> list[Loop]:
    """Natural loops (back edge u -> h with h dominating u), one per header, nested."""
    by_header: dict[int, Loop] = {}
    for u in dom:
        for h in bl[u].succs:
            if h in dom[u]:
                loop = by_header.setdefault(h, Loop(h, {h}, []))
                loop.latches.append(u)
                stack = [u]
                while stack:
                    n = stack.pop()
                    if n not in loop.body:
                        loop.body.add(n)
                        stack += [p for p in dom if n in bl[p].succs]
    loops = sorted(by_header.values(), key=lambda lp: len(lp.body))
    for k, lp in enumerate(loops):
        lp.parent = next((o for o in loops[k + 1:] if lp.body < o.body), None)
        if lp.parent:
            lp.parent.children.append(lp)
    return loops


# ---------------------------------------------------------------------------
# instruction classes

_SIMD_REG = re.compile(r"%[xyz]mm\d+|%k[0-7]\b")


def is_simd(i: Insn) -> bool:
    return bool(_SIMD_REG.search(i.operands)) or i.mnemonic.startswith(("vzeroupper", "k"))


def _split_operands(ops: str) -> list[str]:
    out, depth, cur = [], 0, ""
    for ch in ops:
        if ch == "," and depth == 0:
            out.append(cur.strip())
            cur = ""
            continue
        depth += ch == "("
        depth -= ch == ")"
        cur += ch
    if cur.strip():
        out.append(cur.strip())
    return out


def memory_access(i: Insn) -> tuple[bool, bool]:
    """(loads, stores) of one AT&T instruction, from its explicit memory operand."""
    if i.mnemonic.startswith(("lea", "nop", "prefetch")) or i.is_jump:
        return False, False
    ops = _split_operands(i.operands)
    mem = [k for k, o in enumerate(ops) if "(" in o]
    if not mem:
        return i.mnemonic.startswith(("pop", "ret")), i.mnemonic.startswith(("push", "call"))
    last = len(ops) - 1
    reads_dest = i.mnemonic.startswith(("cmp", "test", "bt", "ucomi", "comi", "vucomi", "vcomi", "vptest"))
    store = last in mem and not reads_dest
    load = any(k != last for k in mem) or reads_dest or (
        store and not i.mnemonic.startswith(("mov", "vmov", "vextract", "vpextr", "vpmov", "vcvtps2ph", "vscatter",
                                             "vpscatter", "stos", "movnt", "vmovnt", "set", "vpcompress",
                                             "vcompress")))
    return load, store


def classify(trace: list[Insn]) -> dict:
    """Counts on one iteration's path."""
    c = {"instructions": len(trace), "simd": 0, "general_purpose": 0, "loads": 0, "stores": 0,
         "stack_loads": 0, "stack_stores": 0, "gathers": 0,
         "scatters": 0, "divisions": 0, "vdivps": 0, "branches": 0, "calls": 0, "zmm": 0, "ymm": 0, "xmm": 0}
    for i in trace:
        simd = is_simd(i)
        c["simd" if simd else "general_purpose"] += 1
        for w in ("zmm", "ymm", "xmm"):
            if f"%{w}" in i.operands:
                c[w] += 1
                break
        load, store = memory_access(i)
        c["loads"] += load
        c["stores"] += store
        stack = bool(re.search(r"\(%(?:rsp|rbp)[,)]", i.operands))  # spills and private arrays
        c["stack_loads"] += load and stack
        c["stack_stores"] += store and stack
        c["gathers"] += i.mnemonic.startswith(("vgather", "vpgather"))
        c["scatters"] += i.mnemonic.startswith(("vscatter", "vpscatter"))
        c["divisions"] += i.mnemonic.startswith(("div", "idiv", "vdiv", "sqrt", "vsqrt"))
        c["vdivps"] += i.mnemonic.startswith("vdivps")
        c["branches"] += i.is_jump
        c["calls"] += i.mnemonic.startswith("call")
    return c


# ---------------------------------------------------------------------------
# the work-item loop and its path


def _path(bl: dict[int, Block], loop: Loop, trips: dict[int, int]) -> list[Insn]:
    """One iteration of ``loop``: the longest path (in instructions) from its header to a latch.

    Nested loops count as one node each: their own path, repeated ``trips[header]`` times."""
    inner = {b: c for c in loop.children for b in c.body}  # block -> the child loop holding it
    sub = {c.header: _path(bl, c, trips) * trips.get(c.header, 1) for c in loop.children}

    def node(b: int) -> int:
        return inner[b].header if b in inner else b

    def cost(n: int) -> list[Insn]:
        return sub[n] if n in sub else bl[n].insns

    def succs(n: int) -> list[int]:
        members = inner[n].body if n in inner else {n}
        out = []
        for m in members:
            for s in bl[m].succs:
                if s in loop.body and s not in members and s != loop.header and node(s) not in out:
                    out.append(node(s))
        return out

    # longest path in the DAG of the body without the back edges (topological order by DFS)
    order = post_order(loop.header, succs)
    best: dict[int, tuple[int, int | None]] = {}  # node -> (length of the longest path from it, next node)
    latches = {node(u) for u in loop.latches}
    for n in order:  # successors first
        tails = [(best[s][0], s) for s in succs(n) if s in best and (best[s][0] > 0 or s in latches)]
        length, nxt = max(tails, default=(0, None))
        if nxt is None and n not in latches:
            best[n] = (0, None)  # leaves the loop without reaching a latch
            continue
        best[n] = (length + len(cost(n)), nxt)
    path, n = [], loop.header
    while n is not None:
        path += cost(n)
        n = best[n][1]
    return path


def work_item_loop(insns: list[Insn], wi_loops: int | None) -> tuple[Loop, dict[int, Block], list[Loop]]:
    """The work-item loop of a work-group function and its blocks and loops.

    PoCL wraps the kernel's body in one loop per dimension of the local size
    larger than 1 (outermost: the last dimension), so the innermost of them,
    the one over local dimension 0 (``b``, the 8-position blocks of a
    pixel), is at nesting depth ``wi_loops``; of the loops at that depth the
    one with the most SIMD instructions. It must hold at least half of the
    function's SIMD instructions (static count, nested loops included). With
    ``wi_loops`` None: the innermost loop that does."""
    bl = blocks(insns)
    dom = dominators(bl, insns[0].addr)
    loops = natural_loops(bl, dom)
    if not loops:
        raise RuntimeError("no loop in the work-group function")
    total = sum(is_simd(i) for i in insns)

    def simd(lp: Loop) -> int:
        return sum(is_simd(i) for b in lp.body for i in bl[b].insns)

    def depth(lp: Loop) -> int:
        return 1 + (depth(lp.parent) if lp.parent else 0)

    if wi_loops:
        at = [lp for lp in loops if depth(lp) == wi_loops]
        if not at:
            raise RuntimeError(f"no loop at nesting depth {wi_loops} (the work-item loops of the local size)")
        loop = max(at, key=simd)
        if simd(loop) < total / 2:
            raise RuntimeError(f"the work-item loop at 0x{loop.header:x} holds {simd(loop)} of {total} SIMD "
                               "instructions: not the hot loop")
        return loop, bl, loops
    hot = [lp for lp in loops if simd(lp) >= total / 2]
    if not hot:
        raise RuntimeError("no loop holds half of the SIMD instructions")
    return min(hot, key=lambda lp: len(lp.body)), bl, loops


# ---------------------------------------------------------------------------
# llvm-mca


def mca_input(trace: list[Insn]) -> str:
    """The path as llvm-mca input: AT&T text; direct branches aimed at the path's start."""
    lines = [".text", ".Lhot:"]
    for i in trace:
        if i.is_jump:
            lines.append(f"{i.mnemonic} .Lhot")
        else:
            lines.append(i.text)
    return "\n".join(lines) + "\n"


def run_mca(trace: list[Insn], mcpu: str, iterations: int = 100) -> dict:
    mca = _tool("llvm-mca-15", "llvm-mca")
    if mca is None:
        raise RuntimeError("llvm-mca-15 is not installed")
    res = subprocess.run([mca, f"-mcpu={mcpu}", f"-iterations={iterations}", "-bottleneck-analysis"],
                         input=mca_input(trace), capture_output=True, text=True, timeout=120)
    if res.returncode != 0:
        first = next((ln for ln in res.stderr.splitlines() if "error" in ln), res.stderr.strip()[:200])
        raise RuntimeError(f"llvm-mca failed: {first}")
    out = res.stdout

    def grab(label: str, cast=float):
        m = re.search(rf"^{re.escape(label)}:\s+([0-9.]+)", out, re.M)
        return cast(m.group(1)) if m else None

    rt = grab("Block RThroughput")
    if rt is None:
        raise RuntimeError("llvm-mca printed no Block RThroughput")
    r = {"tool": Path(mca).name, "mcpu": mcpu, "iterations": grab("Iterations", int),
         "instructions_per_iteration": (grab("Instructions", int) or 0) // max(1, grab("Iterations", int) or 1),
         "block_rthroughput": rt, "total_cycles": grab("Total Cycles", int), "ipc": grab("IPC"),
         "uops_per_cycle": grab("uOps Per Cycle")}
    if r["total_cycles"] and r["iterations"]:
        r["simulated_cycles_per_iteration"] = r["total_cycles"] / r["iterations"]
    r["pressure"] = _port_pressure(out)
    # the scheduling model actually used: LLVM 15 has none of its own for some CPUs it knows (it models
    # sapphirerapids with Skylake-server's), seen in the resource names (SKXPort0, ICXPort0, Zn3ALU0, ...)
    prefixes = {m.group(1) for m in (re.match(r"([A-Za-z]+?\d*)(?:Port|ALU|FP|Divider|AGU|Load|Store)", k)
                                     for k in r["pressure"]) if m}
    r["model_resources"] = ", ".join(sorted(prefixes)) or None
    return r


def _port_pressure(out: str) -> dict[str, float]:
    """Resource pressure per iteration: resource name -> cycles (llvm-mca's table)."""
    lines = out.splitlines()
    try:
        k = next(n for n, ln in enumerate(lines) if ln.startswith("Resource pressure per iteration:"))
    except StopIteration:
        return {}
    names, resources = lines[k + 1].split(), {}
    for m in re.finditer(r"^\[(\d+(?:\.\d+)?)\]\s+-\s+(\S+)", out, re.M):
        resources[f"[{m.group(1)}]"] = m.group(2)
    values = lines[k + 2].split()
    return {resources.get(n, n): float(v) for n, v in zip(names, values) if v != "-"}


# ---------------------------------------------------------------------------
# the ceiling


def _not_measured(result: dict, reason: str) -> dict:
    result.update(status="not measured", reason=reason)
    return result


def ceiling(name: str = "bose", spp: int = 121, dims: int = 10, offset: str | None = "cmj", *,
            strength: int | None = None, seed: int = 0, pixels: int = DEFAULT_PIXELS, mcpu: str | None = None,
            keep_trace: bool = False) -> dict:
    """The compute ceiling of the vector path for one case (see the module docstring); never raises.

    Returns a dict with ``status`` ("ok" or "not measured", then ``reason``),
    ``ceiling_values_per_s`` (cores x clock x values per iteration / llvm-mca's
    block throughput), ``ipc_ceiling_values_per_s`` (the same at 4 instructions
    per cycle), the counts of one iteration's path, llvm-mca's figures, the CPU,
    clock and cores."""
    cpu = host_cpu()
    result: dict = {"case": {"name": name, "spp": spp, "dims": dims, "offset": offset, "strength": strength},
                    "kernel": KERNEL, "status": "ok", "reason": None, "cpu": cpu, "cores": usable_cores(),
                    "clock_mhz": cpu["mhz"],
                    "clock_note": "nominal clock the VM reports (/proc/cpuinfo 'cpu MHz'), not measured",
                    "values_per_iteration": LANES * dims, "ipc_bound": IPC_BOUND}
    missing = [what for what, names in (("llvm-mca-15", ("llvm-mca-15", "llvm-mca")),
                                        ("a disassembler (llvm-objdump-15 or objdump)",
                                         ("llvm-objdump-15", "llvm-objdump", "objdump"))) if not _tool(*names)]
    if missing:  # before the subprocess: nothing to measure with
        return _not_measured(result, f"{' and '.join(missing)} not installed")
    try:
        with tempfile.TemporaryDirectory(prefix="pyoa-ceiling-") as tmp:
            device = build_kernels({"name": name, "spp": spp, "dims": dims, "offset": offset,
                                    "strength": strength, "seed": seed}, Path(tmp), pixels)
            result["device"] = device
            so, sizes = find_object(Path(tmp))
            result["local_sizes"] = sizes
            result["local_size"] = so_name = so.parent.name
            funcs, dis = disassemble(so)
        result["disassembler"] = dis
        fname = next((f for f in (f"_pocl_kernel_{KERNEL}_workgroup", f"_pocl_kernel_{KERNEL}_workgroup_fast",
                                  f"_pocl_kernel_{KERNEL}") if funcs.get(f)), None)
        if fname is None:
            return _not_measured(result, f"no PoCL work-group function for {KERNEL} in the object "
                                         f"(functions: {', '.join(funcs) or 'none'})")
        result["function"] = fname
        insns = funcs[fname]
        sizes = [int(t) for t in so_name.split("-")[:3] if t.isdigit()]
        loop, bl, loops = work_item_loop(insns, sum(n > 1 for n in sizes) or None)
        grouped = dims > MAX_WHOLE_ROWS
        trips = {c.header: dims // LANES for c in loop.children} if grouped else {}
        if len(loop.children) != (1 if grouped else 0):
            result["loop_warning"] = (f"{len(loop.children)} loop(s) nested in the work-item loop, expected "
                                      f"{1 if grouped else 0}; each counted once")
        trace = _path(bl, loop, trips)
        result["loop"] = {
            "header": f"0x{loop.header:x}", "blocks": len(loop.body), "loops_in_function": len(loops),
            "static_instructions": sum(len(bl[b].insns) for b in loop.body),
            "function_instructions": len(insns),
            "nested": [{"header": f"0x{c.header:x}", "blocks": len(c.body), "trips": trips.get(c.header, 1)}
                       for c in loop.children],
        }
        counts = classify(trace)
        result["counts"] = counts
        vpi = result["values_per_iteration"]
        result["instructions_per_value"] = counts["instructions"] / vpi
        if keep_trace:
            result["trace"] = [f"{i.addr:x}: {i.text}" for i in trace]
        known = _known_mcpus(_tool("llvm-mca-15", "llvm-mca") or "llvm-mca-15")
        target = pocl_target(device, known)
        result["pocl_target"] = target
        why = "--mcpu"
        if mcpu is None:
            mcpu, why = host_mcpu(cpu, target, known)
            if mcpu is None:
                return _not_measured(result, why)
        result["mcpu_from"] = why
        mca = run_mca(trace, mcpu)
        result["mca"] = mca
        if target and target != mcpu:
            try:
                result["mca_pocl_target"] = {k: v for k, v in run_mca(trace, target).items() if k != "pressure"}
            except Exception as exc:  # noqa: BLE001 - a cross-check only
                result["mca_pocl_target"] = {"mcpu": target, "error": str(exc)}
        cycles = mca["block_rthroughput"]
        result["cycles_per_iteration"] = cycles
        result["cycles_per_value"] = cycles / vpi
        if not cpu["mhz"]:
            return _not_measured(result, "no 'cpu MHz' in /proc/cpuinfo")
        hz = cpu["mhz"] * 1e6
        result["ceiling_values_per_s"] = result["cores"] * hz * vpi / cycles
        result["ipc_ceiling_values_per_s"] = result["cores"] * hz * IPC_BOUND / counts["instructions"] * vpi
        sim = mca.get("simulated_cycles_per_iteration")
        if sim:
            result["simulated_ceiling_values_per_s"] = result["cores"] * hz * vpi / sim
        result["padding"] = {"positions_per_pixel": -(-spp // LANES) * LANES, "spp": spp,
                             "useful_fraction": spp / (-(-spp // LANES) * LANES)}
    except subprocess.TimeoutExpired as exc:
        return _not_measured(result, f"timed out: {exc.cmd[0] if exc.cmd else 'a tool'}")
    except Exception as exc:  # noqa: BLE001 - reported, never fatal
        return _not_measured(result, f"{type(exc).__name__}: {exc}")
    return result


def case_label(r: dict) -> str:
    c = r["case"]
    return f"{c['name']}-{c['offset'] or 'default'}-{c['spp']}x{c['dims']}"


def _local(name: str) -> str:
    return "-".join(t for t in name.split("-")[:3])


def markdown(results: list[dict]) -> str:
    """A short Markdown section for one or more cases."""
    ok = [r for r in results if r["status"] == "ok"]
    lines = ["## Compute ceiling (vector path, `vector_values`)", ""]
    if ok:
        r0 = ok[0]
        cpu = r0["cpu"]
        lines += [
            f"CPU: {cpu['name']} ({cpu['vendor']} family {cpu['family']} model {cpu['model']}), "
            f"{r0['cores']} usable cores at {cpu['mhz']:,.0f} MHz: the nominal clock the VM reports in "
            f"/proc/cpuinfo, not a measured one (no hardware counters here). llvm-mca `-mcpu={r0['mca']['mcpu']}` "
            f"({r0['mcpu_from']}; scheduling model: {r0['mca'].get('model_resources') or '?'} resources); "
            f"PoCL compiled for `{r0.get('pocl_target') or 'unknown'}`. "
            "One iteration = one work-item = 8 sample positions x dims values. Ceiling = cores x clock x values "
            "per iteration / cycles per iteration: llvm-mca's Block RThroughput (ports only), then its "
            "simulation (dependencies, scheduler window); the 4-IPC ceiling counts instructions only.",
            "",
        ]
    lines += [
        "| case | local size | instr / iter | SIMD / GP | loads (stack) / stores (stack) | gathers | vdivps "
        "| instr / value | cycles / iter | cycles / value | ceiling M values/s | sim. cycles / iter "
        "| sim. ceiling | 4-IPC ceiling |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in results:
        if r["status"] != "ok":
            lines.append(f"| {case_label(r)} | not measured: {r['reason']} |" + " |" * 12)
            continue
        c, m = r["counts"], r["mca"]
        sim = m.get("simulated_cycles_per_iteration")
        sim_cap = r.get("simulated_ceiling_values_per_s")
        lines.append(
            f"| {case_label(r)} | {_local(r['local_size'])} | {c['instructions']:,} | "
            f"{c['simd']:,} / {c['general_purpose']:,} | {c['loads']} ({c['stack_loads']}) / "
            f"{c['stores']} ({c['stack_stores']}) | {c['gathers']} | {c['vdivps']} | "
            f"{r['instructions_per_value']:.2f} | {r['cycles_per_iteration']:,.1f} | {r['cycles_per_value']:.3f} | "
            f"{r['ceiling_values_per_s'] / 1e6:,.0f} | {f'{sim:,.1f}' if sim else ''} | "
            f"{f'{sim_cap / 1e6:,.0f}' if sim_cap else ''} | {r['ipc_ceiling_values_per_s'] / 1e6:,.0f} |")
    notes = []
    for r in ok:
        p = r["mca"].get("pressure") or {}
        top = sorted(p.items(), key=lambda kv: -kv[1])[:4]
        nested = "".join(f", with the loop at {n['header']} nested, {n['trips']} times" for n in r["loop"]["nested"])
        notes.append(f"- {case_label(r)}: work-item loop at {r['loop']['header']} of `{r['function']}` "
                     f"({r['loop']['blocks']} blocks{nested})"
                     + (f"; busiest resources per iteration (llvm-mca): "
                        + ", ".join(f"{k} {v:,.1f}" for k, v in top) if top else "")
                     + (f"; WARNING: {r['loop_warning']}" if r.get("loop_warning") else ""))
        x = r.get("mca_pocl_target")
        if x and "block_rthroughput" in x:
            notes.append(f"  with `-mcpu={x['mcpu']}` (PoCL's target): {x['block_rthroughput']:,.1f} cycles / "
                         f"iteration, simulated {x.get('simulated_cycles_per_iteration', 0):,.1f}")
        pad = r.get("padding")
        if pad and pad["useful_fraction"] < 1:
            notes.append(f"  {pad['positions_per_pixel']} positions are computed per pixel for {pad['spp']} spp: "
                         f"in values the caller gets, every ceiling is x {pad['useful_fraction']:.3f}")
    if notes:
        lines += ["", *notes]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Compute ceiling of pyoa's OpenCL vector path from PoCL's machine "
                                             "code (llvm-mca) beside the memory one.")
    ap.add_argument("--name", default="bose", help="sampler (default: bose)")
    ap.add_argument("--spp", type=int, default=121, help="samples per pixel (default: 121)")
    ap.add_argument("--dims", type=str, default="10", help="dimensions, comma-separated for several (default: 10)")
    ap.add_argument("--offset", default="cmj", help="offset (default: cmj)")
    ap.add_argument("--strength", type=int, default=None, help="strength (default: the sampler's)")
    ap.add_argument("--pixels", type=int, default=DEFAULT_PIXELS,
                    help=f"pixels of the one generate that builds the kernels (default: {DEFAULT_PIXELS})")
    ap.add_argument("--mcpu", default=None, help="llvm-mca CPU (default: the host's model, see host_mcpu)")
    ap.add_argument("--json", action="store_true", help="print the dictionaries as JSON instead")
    ap.add_argument("--show-loop", action="store_true", help="also print the path of one iteration")
    args = ap.parse_args(argv)
    results = []
    for d in (int(t) for t in args.dims.split(",") if t.strip()):
        results.append(ceiling(args.name, args.spp, d, args.offset, strength=args.strength, pixels=args.pixels,
                               mcpu=args.mcpu, keep_trace=args.show_loop))
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        print(markdown(results), end="")
        if args.show_loop:
            for r in results:
                print(f"\n{case_label(r)}: one iteration's path\n")
                print("\n".join(r.get("trace", [])))
    return 0 if all(r["status"] == "ok" for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
