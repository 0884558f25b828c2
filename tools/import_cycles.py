"""List the import cycles among the package's modules, from their AST (nothing is imported).

An edge ``a -> b`` is an ``import`` or ``from .. import`` in ``a`` that names module ``b`` of the package (a name
imported from a package counts as its submodule when there is one).  ``--module-level`` keeps the imports at the
top of a module only; by default imports inside functions count too: a deferred import that exists to break a
cycle is still a cycle.  An edge from a module to the package that contains it (``from .. import errors``) is
dropped: every module imports its parents first anyway.  The cycles are printed as the strongly connected
components of the graph with more than one module (Tarjan's algorithm).

    python tools/import_cycles.py [--module-level] [--under nambu_bch.algebra]
"""

from __future__ import annotations

import argparse
import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def modules(package: Path) -> dict:
    """``{dotted name: (path, is_package)}`` of every module under ``package``."""
    out = {}
    for path in sorted(package.rglob("*.py")):
        parts = list(path.relative_to(package.parent).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        if is_package:
            parts = parts[:-1]
        out[".".join(parts)] = (path, is_package)
    return out


def _targets(name: str, is_package: bool, node, known) -> list:
    if isinstance(node, ast.Import):
        names = [a.name for a in node.names]
    else:
        if node.level:
            base = name.split(".")
            if not is_package:
                base = base[:-1]
            base = base[:len(base) - (node.level - 1)]
            prefix = ".".join(base + ([node.module] if node.module else []))
        else:
            prefix = node.module or ""
        names = [prefix] + [f"{prefix}.{a.name}" for a in node.names]
    return [t for t in names if t in known]


def graph(package: Path, deferred: bool = True, trees: dict | None = None) -> dict:
    """``{module: set of modules it imports}`` (module-level imports only unless ``deferred``); ``trees`` may hold
    the modules' ASTs already parsed (``{path: ast.Module}``)."""
    known = modules(package)
    edges = {}
    for name, (path, is_package) in known.items():
        tree = (trees or {}).get(path) or ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        nodes = ast.walk(tree) if deferred else tree.body
        targets = set()
        for node in nodes:
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                targets.update(_targets(name, is_package, node, known))
        edges[name] = {t for t in targets if t != name and not name.startswith(t + ".")}
    return edges


def cycles(edges: dict) -> list:
    """The strongly connected components with more than one module, each sorted, in a stable order."""
    index, low, stack, on_stack, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):  # Tarjan; the package's import graph is shallow enough for recursion
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(edges[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return sorted(out)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--module-level", action="store_true", help="ignore imports inside functions")
    parser.add_argument("--under", default="nambu_bch", help="report only the cycles through a module under this name")
    args = parser.parse_args(argv)
    found = [c for c in cycles(graph(ROOT / "nambu_bch", deferred=not args.module_level))
             if any(m == args.under or m.startswith(args.under + ".") for m in c)]
    for component in found:
        print(" <-> ".join(component))
    print(f"{len(found)} cycle(s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
