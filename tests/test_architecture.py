"""The architecture of docs/architecture.md, checked against the code.

Every ``import`` of pyoa's modules, the ones inside functions included, is
read with :mod:`ast` (nothing is imported). The page's layer table (the
fenced ``layers`` block) assigns every module a layer; a module may import
modules of its own layer and of the layers below it, never above, and no
set of modules may import one another in a circle.
"""

from __future__ import annotations

import ast
import fnmatch
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: Packages that live outside pyoa/ (setup.cfg's package_dir).
MAPPED = {"pyoa.kernels": ROOT / "kernels", "pyoa.scenes": ROOT / "scenes"}


def modules() -> dict[str, tuple[Path, list[str]]]:
    """``{dotted name: (file, its package as parts)}`` of every module of pyoa."""
    out = {}
    for path in sorted((ROOT / "pyoa").rglob("*.py")):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
            package = parts
        else:
            package = parts[:-1]
        out[".".join(parts)] = (path, package)
    for name, folder in MAPPED.items():
        out[name] = (folder / "__init__.py", name.split("."))
    return out


def import_graph() -> dict[str, set[str]]:
    """``{module: the pyoa modules it imports}``, imports inside functions included."""
    mods = modules()

    def resolve(name: str) -> str | None:
        while name and name not in mods:
            name = name.rpartition(".")[0]
        return name or None

    graph = {}
    for name, (path, package) in mods.items():
        found = set()
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = package[:len(package) - node.level + 1] if node.level else []
                module = ".".join(base + ([node.module] if node.module else [])) if node.level else node.module
                # `from pkg import sub` imports the module pkg.sub; `from mod import name`, the module mod
                targets = [f"{module}.{a.name}" if f"{module}.{a.name}" in mods else module for a in node.names]
            else:
                continue
            found |= {resolve(t) for t in targets if t and (t == "pyoa" or t.startswith("pyoa."))}
        graph[name] = found - {None, name}
    return graph


def layers() -> list[tuple[str, list[str]]]:
    """The layers of docs/architecture.md, bottom first: ``[(name, module patterns)]``."""
    text = (ROOT / "docs" / "architecture.md").read_text()
    block = re.search(r"```layers\n(.*?)```", text, re.S)
    assert block, "docs/architecture.md has no ```layers block"
    out = []
    for line in block.group(1).splitlines():
        if line.strip() and not line.lstrip().startswith("#"):
            name, _, patterns = line.partition(":")
            out.append((name.strip(), patterns.split()))
    return out[::-1]  # the page lists the top layer first, as a reader meets the code


def layer_of(module: str, table) -> int | None:
    """The layer that names ``module`` itself, else the lowest whose pattern matches it."""
    for k, (_, patterns) in enumerate(table):
        if module in patterns:
            return k
    for k, (_, patterns) in enumerate(table):
        if any(fnmatch.fnmatchcase(module, p) for p in patterns):
            return k
    return None


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            v, children = work[-1]
            for w in children:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return out


def test_no_import_cycle():
    graph = import_graph()
    found = cycles(graph)
    assert not found, "import cycles (imports inside functions count): " + "; ".join(
        " <-> ".join(c) for c in found)


def test_the_cycle_finder_finds_a_cycle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


def test_every_module_has_a_layer():
    table = layers()
    missing = [m for m in import_graph() if layer_of(m, table) is None]
    assert not missing, f"modules in no layer of docs/architecture.md: {missing}"


def test_every_import_points_down():
    table = layers()
    graph = import_graph()
    up = [f"{m} ({table[layer_of(m, table)][0]}) imports {d} ({table[layer_of(d, table)][0]})"
          for m, deps in sorted(graph.items()) for d in sorted(deps)
          if layer_of(d, table) > layer_of(m, table)]
    assert not up, "imports that point up a layer:\n" + "\n".join(up)


def test_imports_inside_functions_are_read():
    # the check would pass vacuously if it missed the imports most likely to point up
    graph = import_graph()
    assert "pyoa.render.state" in graph["pyoa.render.image"]  # `from .state import ...` inside open_image
