"""List the functions of the package whose cyclomatic complexity exceeds a threshold (radon is not a dependency).

The count is McCabe's as radon computes it: 1, plus one for each ``if``/``elif``, conditional expression, ``for``,
``while``, ``except``, ``assert``, comprehension ``for`` and its ``if`` clauses, and each extra operand of
``and``/``or``.  A function nested in another is counted on its own, not in its parent.

    python tools/complexity.py [THRESHOLD]      # default 25; prints "complexity  path:line  function"
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_FUNCTIONS = (ast.FunctionDef, ast.AsyncFunctionDef)


def complexity(function) -> int:
    """The cyclomatic complexity of one ``def`` (its nested ``def``s excluded)."""
    count, todo = 1, list(ast.iter_child_nodes(function))
    while todo:
        node = todo.pop()
        if isinstance(node, _FUNCTIONS):
            continue
        if isinstance(node, (ast.If, ast.IfExp, ast.For, ast.AsyncFor, ast.While, ast.ExceptHandler, ast.Assert)):
            count += 1
        elif isinstance(node, ast.comprehension):
            count += 1 + len(node.ifs)
        elif isinstance(node, ast.BoolOp):
            count += len(node.values) - 1
        todo.extend(ast.iter_child_nodes(node))
    return count


def main(argv) -> int:
    threshold = int(argv[0]) if argv else 25
    rows = []
    for path in sorted((ROOT / "nambu_bch").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, _FUNCTIONS) and (c := complexity(node)) > threshold:
                rows.append((c, f"{path.relative_to(ROOT)}:{node.lineno}", node.name))
    for c, where, name in sorted(rows, key=lambda r: (-r[0], r[1])):
        print(f"{c:4d}  {where}  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
