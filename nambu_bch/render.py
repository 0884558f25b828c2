"""Rendering of results as text, LaTeX or JSON, and atomic output files.

JSON convention (DESIGN.md, "Public surface"): every symbolic expression is a
string that ``sympy.sympify`` reads back with the system's symbol names, e.g.
``sympify(data["H_S"], locals={"x1": Symbol("x1"), ..., "h": Symbol("h")})``
(``str`` of a sympy expression; no floats appear in symbolic output); numbers
of numeric diagnostics are JSON numbers; absent quantities are ``null``.

The text format is the JSON content laid out one ``key: value`` per line, for
reading in a terminal and for ``grep``.
"""

from __future__ import annotations

import json
import math
import os
import tempfile

import numpy as np
import sympy

__all__ = ["expression", "jsonable", "to_json", "to_text", "system_dict", "write_output", "latex_document"]


def expression(value):
    """A sympy expression as a sympify-able string (``None`` stays ``None``)."""
    if value is None:
        return None
    return str(sympy.sympify(value))


def jsonable(obj):
    """``obj`` with sympy objects turned into strings and numpy numbers into Python numbers."""
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, (int,)) and not isinstance(obj, bool):
        return obj
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else str(obj)
    if isinstance(obj, np.generic):
        return jsonable(obj.item())
    if isinstance(obj, np.ndarray):
        return [jsonable(v) for v in obj.tolist()]
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, sympy.Basic):
        return expression(obj)
    return str(obj)


def to_json(data) -> str:
    """Pretty JSON text of ``data`` (see :func:`jsonable`), with a final newline."""
    return json.dumps(jsonable(data), indent=2) + "\n"


def to_text(data, indent: str = "") -> str:
    """``key: value`` lines; nested dicts are indented, lists of dicts numbered."""
    data = jsonable(data)
    lines = []
    if isinstance(data, list):
        for i, item in enumerate(data, 1):
            if isinstance(item, dict):
                lines.append(f"{indent}[{i}]")
                lines.append(to_text(item, indent + "  ").rstrip("\n"))
            else:
                lines.append(f"{indent}- {item}")
        return "\n".join(lines) + "\n"
    for key, value in data.items():
        if isinstance(value, dict):
            lines.append(f"{indent}{key}:")
            lines.append(to_text(value, indent + "  ").rstrip("\n"))
        elif isinstance(value, list) and any(isinstance(v, (dict, list)) for v in value):
            lines.append(f"{indent}{key}:")
            lines.append(to_text(value, indent + "  ").rstrip("\n"))
        elif isinstance(value, list):
            lines.append(f"{indent}{key}: {', '.join(map(str, value)) if value else '(none)'}")
        else:
            lines.append(f"{indent}{key}: {'null' if value is None else value}")
    return "\n".join(line for line in lines if line) + "\n"


def system_dict(system) -> dict:
    """The system part of every JSON result: name, coordinates, parameters, ``H``, ``G``."""
    hams = system.hamiltonians
    data = {
        "model": system.name,
        "coordinates": [str(x) for x in system.coordinates],
        "parameters": [str(p) for p in system.parameters],
        "H": expression(hams[0]),
        "G": expression(hams[1]) if len(hams) > 1 else None,
    }
    if len(hams) > 2:
        data["hamiltonians"] = [expression(H) for H in hams]
    return data


def latex_document(body: str) -> str:
    """Display math, one result per ``equation*``-free line (ready for ``\\[ ... \\]`` or Jupyter)."""
    return body.rstrip("\n") + "\n"


def write_output(text: str, path) -> None:
    """Write ``text`` to ``path`` atomically: a temporary file in the same directory, then ``os.replace``.

    A reader never sees a half-written file, and an existing file is replaced
    only once the new content is complete.
    """
    path = os.fspath(path)
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".tmp-" + os.path.basename(path) + "-", dir=directory)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
