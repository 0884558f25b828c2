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

from .atomic import write_atomic

import json
import math

import numpy as np
import sympy

__all__ = ["expression", "jsonable", "to_json", "to_text", "system_dict", "write_output", "latex_document"]


def expression(value):
    """A sympy expression as a sympify-able string (``None`` stays ``None``)."""
    if value is None:
        return None
    if not isinstance(value, sympy.Basic) and hasattr(value, "as_expr"):  # a sparse-ring element
        value = value.as_expr()
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
    if isinstance(obj, sympy.Basic) or hasattr(obj, "as_expr"):
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
        "bracket": getattr(system, "bracket", None),
    }
    if len(hams) > 2:
        data["hamiltonians"] = [expression(H) for H in hams]
    return data


def latex_document(body: str) -> str:
    """Display math, one result per ``equation*``-free line (ready for ``\\[ ... \\]`` or Jupyter)."""
    return body.rstrip("\n") + "\n"


def write_output(text: str, path) -> None:
    """Write ``text`` to ``path`` atomically (see :func:`nambu_bch.atomic.write_atomic`)."""
    write_atomic(path, text)


# --------------------------------------------------------------------------------------------
# the eight fundamental-identity forms, generically (Eqs. 1AX-2BY)
# --------------------------------------------------------------------------------------------
def _fi_commutator(left, right, way, sign):
    """``sign * [X_left, X_right]`` as ``[(sign, slots)]`` with slots as bracket strings (Eqs. CL2a, CL2b)."""
    base, other, s = (right, left, 1) if way == "a" else (left, right, -1)
    out = []
    for j in range(len(base)):
        slots = list(base)
        slots[j] = "{" + ",".join([base[j], *other]) + "}"
        out.append((sign * s, tuple(slots)))
    return out


def fi_form(label: str) -> list:
    """``[(sign, (slot1, slot2)), ...]`` of ``[X_{A,B}, [X_{C,D}, X_{E,F}]]`` in representation ``label``.

    ``label[0]``: ``1`` uses the fundamental identity on the first term of Eq. (CL2) (Eq. CL2a),
    ``2`` on the second (Eq. CL2b); ``label[1]`` (``A``/``B``) and ``label[2]`` (``X``/``Y``) make
    the same choice for Eqs. (CL3) and (CL4).  Slots are strings in the paper's bracket notation.

    >>> [(s, ",".join(t)) for s, t in fi_form("1AX")]     # Eq. (1AX)
    [(1, '{{E,C,D},A,B},F'), (1, '{E,C,D},{F,A,B}'), (1, '{E,A,B},{F,C,D}'), (1, 'E,{{F,C,D},A,B}')]
    """
    if len(label) != 3 or label[0] not in "12" or label[1] not in "AB" or label[2] not in "XY":
        raise ValueError(f"FI label must be one of 1AX..2BY, got {label!r}")
    inner = "a" if label[0] == "1" else "b"
    outer = ("a" if label[1] == "A" else "b", "a" if label[2] == "X" else "b")
    out = []
    for (sign, slots), way in zip(_fi_commutator(("C", "D"), ("E", "F"), inner, 1), outer):
        out.extend(_fi_commutator(("A", "B"), slots, way, sign))
    return out


def fi_form_text(label: str) -> str:
    terms = fi_form(label)
    body = " ".join(("+ " if s > 0 else "- ") + "X_{" + ",".join(slots) + "}" for s, slots in terms)
    return "[X_{A,B},[X_{C,D},X_{E,F}]] = " + body.lstrip("+ ")


def fi_form_latex(label: str) -> str:
    def lx(text):
        return text.replace("{", r"\{").replace("}", r"\}")

    terms = fi_form(label)
    body = " ".join(("+ " if s > 0 else "- ") + "X_{" + ",".join(lx(t) for t in slots) + "}" for s, slots in terms)
    return r"[X_{A,B},[X_{C,D},X_{E,F}]] \overset{\rm " + label + "}{=} " + body.lstrip("+ ")
